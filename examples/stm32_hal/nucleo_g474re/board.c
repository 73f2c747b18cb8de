/*
 * board.c - NUCLEO-G474RE bring-up for the j288 example, against ST's real STM32G4 HAL: the
 * second family (a configurable CRC unit, DMAMUX, a USART with its own baud formula).
 *
 * Clock tree (exact 6 Mbps): HSE 24 MHz crystal (without it, or with -DBOARD_CLOCK_HSI=1, the
 * internal 16 MHz), PLL M=6 (HSI: 4), N=84, R=2 -> SYSCLK 168 MHz (range 1 boost, 4 flash
 * wait states; 168 rather than the 170 maximum because 170 MHz gives no exact 6 Mbps); AHB,
 * APB1, APB2 168 MHz.
 * USART1 on PCLK2 with 16x oversampling: USARTDIV = 168 MHz / 6 Mbps = 28 exactly (BRR 28),
 * checked at init. (The G4's USART reaches 6 Mbps with OVER16 where the F4's at 90 MHz
 * cannot, and 16x sampling tolerates more noise.)
 *
 * Bus: USART1 single-wire half-duplex on PA9 (Arduino D8, as on the F446RE board), AF7,
 * push-pull with pull-up; TX on DMA1 channel 1 (normal mode), RX on DMA1 channel 2
 * (circular mode), DMAMUX requests USART1_TX/RX, bytes. TIM2 (32 bits, 168 MHz) counts at
 * 1 MHz: tick and timeout on channel 1. USART1, both channels and TIM2 share NVIC priority
 * 5 (SysTick 15). CRC unit in its reset configuration, spelled out in the handle (the port
 * checks it).
 * The blue user button B1 (PC13, high when pressed on this board) is the emergency stop.
 */
#include "nucleo_common/board_nucleo.h"

/* The PLL from the 24 MHz crystal or from the 16 MHz HSI, to 4 MHz at its input, VCO
 * 336 MHz, 168 MHz out. */
static HAL_StatusTypeDef pll_start(bool hse)
{
    RCC_OscInitTypeDef osc = {0};
    osc.OscillatorType = RCC_OSCILLATORTYPE_HSE | RCC_OSCILLATORTYPE_HSI;
    osc.HSEState = hse ? RCC_HSE_ON : RCC_HSE_OFF;
    osc.HSIState = RCC_HSI_ON;
    osc.HSICalibrationValue = RCC_HSICALIBRATION_DEFAULT;
    osc.PLL.PLLState = RCC_PLL_ON;
    osc.PLL.PLLSource = hse ? RCC_PLLSOURCE_HSE : RCC_PLLSOURCE_HSI;
    osc.PLL.PLLM = hse ? RCC_PLLM_DIV6 : RCC_PLLM_DIV4;
    osc.PLL.PLLN = 84u;
    osc.PLL.PLLP = RCC_PLLP_DIV2;
    osc.PLL.PLLQ = RCC_PLLQ_DIV2;
    osc.PLL.PLLR = RCC_PLLR_DIV2;
    return HAL_RCC_OscConfig(&osc);
}

static void clock_init(void)
{
    if (HAL_PWREx_ControlVoltageScaling(PWR_REGULATOR_VOLTAGE_SCALE1_BOOST) != HAL_OK) {
        board_fatal();
    }
    board_pll_hse_else_hsi(pll_start); /* without the crystal: the HSI */
    board_sysclk_from_pll(RCC_HCLK_DIV1, RCC_HCLK_DIV1, FLASH_LATENCY_4);
}

/* ---- MSP: what the HAL's *_Init functions call back for the pins, clocks and channels --- */

void HAL_MspInit(void)
{
    __HAL_RCC_SYSCFG_CLK_ENABLE();
    __HAL_RCC_PWR_CLK_ENABLE();
    HAL_PWREx_DisableUCPDDeadBattery(); /* as CubeMX does: frees the UCPD pins' pull-downs */
}

static void dma_channel_init(DMA_HandleTypeDef *h, DMA_Channel_TypeDef *channel, uint32_t request,
                             uint32_t direction, uint32_t mode)
{
    h->Instance = channel;
    h->Init.Request = request;
    board_dma_init(h, direction, mode);
}

void HAL_UART_MspInit(UART_HandleTypeDef *huart)
{
    RCC_PeriphCLKInitTypeDef pclk = {0};
    if (huart->Instance != USART1) {
        return;
    }
    pclk.PeriphClockSelection = RCC_PERIPHCLK_USART1;
    pclk.Usart1ClockSelection = RCC_USART1CLKSOURCE_PCLK2;
    if (HAL_RCCEx_PeriphCLKConfig(&pclk) != HAL_OK) {
        board_fatal();
    }
    __HAL_RCC_USART1_CLK_ENABLE();
    __HAL_RCC_DMAMUX1_CLK_ENABLE();
    __HAL_RCC_DMA1_CLK_ENABLE();
    board_bus_pin_init();

    dma_channel_init(&hdma_usart1_tx, DMA1_Channel1, DMA_REQUEST_USART1_TX, DMA_MEMORY_TO_PERIPH,
                     DMA_NORMAL);
    __HAL_LINKDMA(huart, hdmatx, hdma_usart1_tx);
    dma_channel_init(&hdma_usart1_rx, DMA1_Channel2, DMA_REQUEST_USART1_RX, DMA_PERIPH_TO_MEMORY,
                     DMA_CIRCULAR);
    __HAL_LINKDMA(huart, hdmarx, hdma_usart1_rx);

    board_bus_irqs_enable(DMA1_Channel2_IRQn);
}

/* ---- peripherals ------------------------------------------------------------------------ */

bool board_estop_pressed(void)
{
    return HAL_GPIO_ReadPin(GPIOC, GPIO_PIN_13) == GPIO_PIN_SET;
}

static void uart_init(void)
{
    board_uart_settings(UART_OVERSAMPLING_16);
    huart1.Init.OneBitSampling = UART_ONE_BIT_SAMPLE_DISABLE;
    huart1.Init.ClockPrescaler = UART_PRESCALER_DIV1;
    huart1.AdvancedInit.AdvFeatureInit = UART_ADVFEATURE_NO_INIT;
    if ((HAL_HalfDuplex_Init(&huart1) != HAL_OK) || (HAL_UARTEx_DisableFifoMode(&huart1) != HAL_OK)) {
        board_fatal();
    }
    /* 16x oversampling: baud = fck / BRR. */
    if ((huart1.Instance->BRR == 0u) || ((HAL_RCC_GetPCLK2Freq() % BOARD_BUS_BAUD) != 0u) ||
        ((HAL_RCC_GetPCLK2Freq() / huart1.Instance->BRR) != BOARD_BUS_BAUD)) {
        board_fatal(); /* the clock tree does not give 6 Mbps exactly */
    }
}

/* The servo's CRC is the unit's reset configuration; a CubeMX project must keep these
 * (j288_stm32_init refuses anything else). */
static void crc_init(void)
{
    hcrc.Instance = CRC;
    hcrc.Init.DefaultPolynomialUse = DEFAULT_POLYNOMIAL_ENABLE;
    hcrc.Init.DefaultInitValueUse = DEFAULT_INIT_VALUE_ENABLE;
    hcrc.Init.InputDataInversionMode = CRC_INPUTDATA_INVERSION_NONE;
    hcrc.Init.OutputDataInversionMode = CRC_OUTPUTDATA_INVERSION_DISABLE;
    hcrc.InputDataFormat = CRC_INPUTDATA_FORMAT_WORDS;
    if (HAL_CRC_Init(&hcrc) != HAL_OK) {
        board_fatal();
    }
}

void board_init(void)
{
    if (HAL_Init() != HAL_OK) {
        board_fatal();
    }
    clock_init();
    board_button_init(GPIO_PULLDOWN); /* B1 pulls PC13 high when pressed: never let it float */
    uart_init();
    board_tick_timer_init(HAL_RCC_GetPCLK1Freq()); /* APB1 undivided */
    crc_init();
}

/* ---- interrupt handlers (the names of ST's startup_stm32g474xx.s vector table; USART1's and
 * TIM2's are in board_common.c, SysTick's and HardFault's in nucleo_common/board_nucleo.c) - */

void DMA1_Channel2_IRQHandler(void) { board_bus_dma_rx_irq(); } /* TX channel: no interrupt */
