/*
 * board_stub.c - the board for the link check against the HAL stub (`make arm`, with
 * startup_stm32f4.c and stm32f407.ld): the same handles and settings as a real board, no
 * clock tree or MSP (the stub has no RCC). The firmware to flash is nucleo_f446re/ (`make
 * firmware`); in a CubeMX project the generated code replaces both.
 */
#include "board.h"

UART_HandleTypeDef huart1;
DMA_HandleTypeDef hdma_usart1_tx;
DMA_HandleTypeDef hdma_usart1_rx;
TIM_HandleTypeDef htim2;
CRC_HandleTypeDef hcrc;

/* UART, both DMA streams and the timer share one priority, so that none of the port's
 * callbacks preempts another (required with advance_in_isr). */
#define BUS_IRQ_PRIORITY 5u

static void uart_init(void)
{
    huart1.Instance = USART1;
    huart1.Init.BaudRate = 6000000u; /* OVER8 at APB2 = 84 MHz gives 84/8/1.75 = 6.0 Mbps */
    huart1.Init.WordLength = UART_WORDLENGTH_8B;
    huart1.Init.StopBits = UART_STOPBITS_1;
    huart1.Init.Parity = UART_PARITY_NONE;
    huart1.Init.Mode = UART_MODE_TX_RX;
    huart1.Init.HwFlowCtl = UART_HWCONTROL_NONE;
    huart1.Init.OverSampling = UART_OVERSAMPLING_8;
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

static void timer_init(void)
{
    htim2.Instance = TIM2;
    htim2.Init.Prescaler = 84u - 1u; /* 84 MHz timer clock -> 1 MHz */
    htim2.Init.CounterMode = TIM_COUNTERMODE_UP;
    htim2.Init.Period = 0xFFFFFFFFu;
    if ((HAL_TIM_Base_Init(&htim2) != HAL_OK) || (HAL_TIM_Base_Start(&htim2) != HAL_OK)) {
        board_fatal();
    }
}

void board_init(void)
{
    (void)HAL_Init();
    /* SystemClock_Config(): 168 MHz from the PLL, APB2 84 MHz, APB1 42 MHz (timers x2). */
    uart_init();
    timer_init();
    hcrc.Instance = CRC;
    if (HAL_CRC_Init(&hcrc) != HAL_OK) {
        board_fatal();
    }
    HAL_NVIC_SetPriority(USART1_IRQn, BUS_IRQ_PRIORITY, 0u);
    HAL_NVIC_SetPriority(DMA2_Stream7_IRQn, BUS_IRQ_PRIORITY, 0u);
    HAL_NVIC_SetPriority(DMA2_Stream2_IRQn, BUS_IRQ_PRIORITY, 0u);
    HAL_NVIC_SetPriority(TIM2_IRQn, BUS_IRQ_PRIORITY, 0u);
    HAL_NVIC_EnableIRQ(USART1_IRQn);
    HAL_NVIC_EnableIRQ(DMA2_Stream7_IRQn);
    HAL_NVIC_EnableIRQ(DMA2_Stream2_IRQn);
    HAL_NVIC_EnableIRQ(TIM2_IRQn);
}

volatile board_fault_t board_fault;
volatile bool board_clock_hse;

bool board_estop_pressed(void)
{
    return HAL_GPIO_ReadPin(GPIOC, (uint16_t)0x2000u) == GPIO_PIN_RESET; /* PC13 */
}

void board_fatal(void)
{
    __disable_irq();
    for (;;) {
    }
}

/* Interrupt handlers (stm32f4xx_it.c in CubeMX): hand over to the HAL, which calls the
 * application's callbacks in main.c. */
void USART1_IRQHandler(void);
void DMA2_Stream7_IRQHandler(void);
void DMA2_Stream2_IRQHandler(void);
void TIM2_IRQHandler(void);

void USART1_IRQHandler(void) { HAL_UART_IRQHandler(&huart1); }
void DMA2_Stream7_IRQHandler(void) { HAL_DMA_IRQHandler(&hdma_usart1_tx); }
void DMA2_Stream2_IRQHandler(void) { HAL_DMA_IRQHandler(&hdma_usart1_rx); }
void TIM2_IRQHandler(void) { HAL_TIM_IRQHandler(&htim2); }
