/*
 * board_stub.c - the board for the link check against the HAL stub (`make arm`, with
 * startup_stm32f4.c, stm32f407.ld and board_common.c): the same settings as a real board, no
 * clock tree or MSP (the stub has no RCC). The firmware to flash is nucleo_f446re/ (`make
 * firmware`); in a CubeMX project the generated code replaces both.
 */
#include "board_common.h"

static void uart_init(void)
{
    board_uart_settings(UART_OVERSAMPLING_8); /* at APB2 = 84 MHz: 84/8/1.75 = 6.0 Mbps */
    hdma_usart1_tx.Instance = DMA2_Stream7;
    hdma_usart1_rx.Instance = DMA2_Stream2;
    hdma_usart1_tx.Parent = &huart1;
    hdma_usart1_rx.Parent = &huart1;
    huart1.hdmatx = &hdma_usart1_tx;
    huart1.hdmarx = &hdma_usart1_rx;
    if (HAL_HalfDuplex_Init(&huart1) != HAL_OK) {
        board_fatal();
    }
}

void board_init(void)
{
    (void)HAL_Init();
    /* SystemClock_Config(): 168 MHz from the PLL, APB2 84 MHz, APB1 42 MHz (timers x2). */
    uart_init();
    board_tick_timer_init(84000000u); /* APB1 timers at 84 MHz */
    hcrc.Instance = CRC;
    if (HAL_CRC_Init(&hcrc) != HAL_OK) {
        board_fatal();
    }
    board_bus_irqs_enable(DMA2_Stream2_IRQn);
    board_timer_irq_enable();
}

bool board_estop_pressed(void)
{
    return HAL_GPIO_ReadPin(GPIOC, (uint16_t)0x2000u) == GPIO_PIN_RESET; /* PC13 */
}

/* The RX stream's interrupt handler (stm32f4xx_it.c in CubeMX; USART1's and TIM2's are in
 * board_common.c): the port's, not the HAL's. The TX stream's interrupt is not used. */
void DMA2_Stream2_IRQHandler(void);
void DMA2_Stream2_IRQHandler(void) { board_bus_dma_rx_irq(); }
