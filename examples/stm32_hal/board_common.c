/*
 * board_common.c - what every board shares, the HAL stub's included: the HAL handles, the
 * fault record, board_fatal(), and the two interrupt handlers whose names do not depend on
 * the family. (The bus UART's settings and the tick timer are inline in board.h.)
 */
#include "board_common.h"

UART_HandleTypeDef huart1;
DMA_HandleTypeDef hdma_usart1_tx;
DMA_HandleTypeDef hdma_usart1_rx;
TIM_HandleTypeDef htim2;
CRC_HandleTypeDef hcrc;

/* What the fault handler saw, for a debugger (volatile: kept however the code optimises). */
volatile board_fault_t board_fault;
volatile bool board_clock_hse;

void board_fatal(void)
{
    __disable_irq();
    for (;;) {
    }
}

/* Interrupt handlers (stm32xxxx_it.c in CubeMX): hand over to the HAL, which calls the
 * application's callbacks in main.c. The DMA ones are the board's: their names differ. */
void USART1_IRQHandler(void);
void TIM2_IRQHandler(void);
void USART1_IRQHandler(void) { HAL_UART_IRQHandler(&huart1); }
void TIM2_IRQHandler(void) { HAL_TIM_IRQHandler(&htim2); }
