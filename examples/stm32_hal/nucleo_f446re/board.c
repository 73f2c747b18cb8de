/*
 * board.c - NUCLEO-F446RE bring-up for the j288 example, against ST's real STM32F4 HAL:
 * clock tree, MSP init (clocks, GPIO alternate function and pull-up, DMA streams, NVIC),
 * interrupt handlers, SysTick, and a fault handler that leaves its diagnosis in RAM.
 *
 * Clock tree (exact 6 Mbps): HSE 8 MHz from the ST-LINK's MCO (bypass; without it, or with
 * -DBOARD_CLOCK_HSI=1, the internal 16 MHz RC), PLL M=4 (HSI: 8), N=180, P=2 -> SYSCLK 180 MHz
 * (over-drive on, voltage scale 1, 5 flash wait states); AHB 180, APB1 45, APB2 90 MHz.
 * USART1 on APB2 with 8x oversampling: USARTDIV = 90 MHz / (8 x 6 Mbps) = 1.875 = 1 + 7/8,
 * which BRR holds exactly (mantissa 1, fraction 7: BRR 0x17), so the line runs at 6 000 000
 * bit/s with no rounding error; board_init() checks BRR against it.
 *
 * Bus: USART1 single-wire half-duplex on PA9 (Arduino D8), alternate function 7, push-pull
 * with the internal pull-up (the USART releases the pin whenever it is not transmitting);
 * TX DMA2 Stream7 channel 4 in normal mode, RX DMA2 Stream2 channel 4 in circular mode (a
 * pause inside a reply then loses nothing), bytes. TIM2 (32
 * bits, on APB1: 90 MHz timer clock) counts at 1 MHz: the tick and, on channel 1, the reply
 * timeout. USART1, both streams and TIM2 share NVIC priority 5 (SysTick 15). The blue user
 * button B1 (PC13, low when pressed) is the emergency stop.
 */
#include "nucleo_common/board_nucleo.h"

/* The PLL from the ST-LINK's 8 MHz (HSE bypass) or from the 16 MHz HSI, to 2 MHz at its
 * input, VCO 360 MHz, 180 MHz out. */
static HAL_StatusTypeDef pll_start(bool hse)
{
    RCC_OscInitTypeDef osc = {0};
    osc.OscillatorType = RCC_OSCILLATORTYPE_HSE | RCC_OSCILLATORTYPE_HSI;
    osc.HSEState = hse ? RCC_HSE_BYPASS : RCC_HSE_OFF;
    osc.HSIState = RCC_HSI_ON;
    osc.HSICalibrationValue = RCC_HSICALIBRATION_DEFAULT;
    osc.PLL.PLLState = RCC_PLL_ON;
    osc.PLL.PLLSource = hse ? RCC_PLLSOURCE_HSE : RCC_PLLSOURCE_HSI;
    osc.PLL.PLLM = hse ? 4u : 8u;
    osc.PLL.PLLN = 180u;
    osc.PLL.PLLP = RCC_PLLP_DIV2;
    osc.PLL.PLLQ = 8u;
    osc.PLL.PLLR = 2u;
    return HAL_RCC_OscConfig(&osc);
}

static void clock_init(void)
{
    __HAL_RCC_PWR_CLK_ENABLE();
    __HAL_PWR_VOLTAGESCALING_CONFIG(PWR_REGULATOR_VOLTAGE_SCALE1);
    board_pll_hse_else_hsi(pll_start); /* without the ST-LINK's MCO: the HSI */
    if (HAL_PWREx_EnableOverDrive() != HAL_OK) {
        board_fatal();
    }
    board_sysclk_from_pll(RCC_HCLK_DIV4, RCC_HCLK_DIV2, FLASH_LATENCY_5);
}

/* ---- MSP: what the HAL's *_Init functions call back for the pins, clocks and streams --- */

void HAL_MspInit(void)
{
    __HAL_RCC_SYSCFG_CLK_ENABLE();
    __HAL_RCC_PWR_CLK_ENABLE();
}

static void dma_stream_init(DMA_HandleTypeDef *h, DMA_Stream_TypeDef *stream, uint32_t direction, uint32_t mode)
{
    h->Instance = stream;
    h->Init.Channel = DMA_CHANNEL_4;
    h->Init.FIFOMode = DMA_FIFOMODE_DISABLE;
    board_dma_init(h, direction, mode);
}

void HAL_UART_MspInit(UART_HandleTypeDef *huart)
{
    if (huart->Instance != USART1) {
        return;
    }
    __HAL_RCC_USART1_CLK_ENABLE();
    __HAL_RCC_DMA2_CLK_ENABLE();
    board_bus_pin_init();

    dma_stream_init(&hdma_usart1_tx, DMA2_Stream7, DMA_MEMORY_TO_PERIPH, DMA_NORMAL);
    __HAL_LINKDMA(huart, hdmatx, hdma_usart1_tx);
    dma_stream_init(&hdma_usart1_rx, DMA2_Stream2, DMA_PERIPH_TO_MEMORY, DMA_CIRCULAR);
    __HAL_LINKDMA(huart, hdmarx, hdma_usart1_rx);

    board_bus_irqs_enable(DMA2_Stream2_IRQn);
}

/* ---- peripherals ------------------------------------------------------------------------ */

bool board_estop_pressed(void)
{
    return HAL_GPIO_ReadPin(GPIOC, GPIO_PIN_13) == GPIO_PIN_RESET;
}

/* The rate BRR gives with 8x oversampling: fck / (8 x USARTDIV), USARTDIV = BRR[15:4] +
 * BRR[2:0] / 8. */
static uint32_t uart_actual_baud(void)
{
    uint32_t brr = huart1.Instance->BRR;
    uint32_t div8 = ((brr >> 4) * 8u) + (brr & 7u);
    return (div8 != 0u) ? HAL_RCC_GetPCLK2Freq() / div8 : 0u;
}

static void uart_init(void)
{
    board_uart_settings(UART_OVERSAMPLING_8);
    if (HAL_HalfDuplex_Init(&huart1) != HAL_OK) {
        board_fatal();
    }
    if ((uart_actual_baud() != BOARD_BUS_BAUD) || ((HAL_RCC_GetPCLK2Freq() % BOARD_BUS_BAUD) != 0u)) {
        board_fatal(); /* the clock tree does not give 6 Mbps exactly */
    }
}

static void crc_init(void)
{
    hcrc.Instance = CRC; /* the F4's unit has one configuration: the servo's CRC */
    if (HAL_CRC_Init(&hcrc) != HAL_OK) {
        board_fatal();
    }
}

void board_init(void)
{
    if (HAL_Init() != HAL_OK) { /* flash prefetch and caches, NVIC groups, SysTick at 1 kHz */
        board_fatal();
    }
    clock_init();
    board_button_init(GPIO_NOPULL); /* B1 has its own pull-up */
    uart_init();
    /* APB1 runs at HCLK/4, so its timers get twice PCLK1: 90 MHz. */
    board_tick_timer_init(2u * HAL_RCC_GetPCLK1Freq());
    crc_init();
}

/* ---- interrupt handlers (the names of ST's startup_stm32f446xx.s vector table; USART1's and
 * TIM2's are in board_common.c, SysTick's and HardFault's in nucleo_common/board_nucleo.c) - */

void DMA2_Stream2_IRQHandler(void) { board_bus_dma_rx_irq(); } /* TX stream: no interrupt */
