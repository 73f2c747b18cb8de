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

/* Interrupt handlers (stm32xxxx_it.c in CubeMX): the bus UART's goes to the port (main.c),
 * the timer's to the HAL, which calls the application's callback in main.c. The DMA one is
 * the board's: its name differs. */
void USART1_IRQHandler(void);
void TIM2_IRQHandler(void);
void USART1_IRQHandler(void) { board_bus_uart_irq(); }
void TIM2_IRQHandler(void) { HAL_TIM_IRQHandler(&htim2); }
