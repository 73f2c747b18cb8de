/*
 * board_common.h - what the board files (each NUCLEO's board.c, board_stub.c) share for their
 * board_init(): the bus's rate and interrupt priority, the bus UART's line settings, the tick
 * timer, the bus interrupts. Inline: each board calls them once, so the images stay as small
 * as with the code written out. Not for main.c (board.h is its interface).
 */
#ifndef J288_EXAMPLE_BOARD_COMMON_H
#define J288_EXAMPLE_BOARD_COMMON_H

#include "board.h"

#define BOARD_BUS_BAUD 6000000u
#define BOARD_TICK_HZ 1000000u

/* huart1's bus line: USART1, BOARD_BUS_BAUD, 8N1, both directions, no flow control, with the
 * given oversampling (UART_OVERSAMPLING_8 or _16). Sets the handle only; the board adds its
 * family's fields and calls HAL_HalfDuplex_Init. */
static inline void board_uart_settings(uint32_t oversampling)
{
    huart1.Instance = USART1;
    huart1.Init.BaudRate = BOARD_BUS_BAUD;
    huart1.Init.WordLength = UART_WORDLENGTH_8B;
    huart1.Init.StopBits = UART_STOPBITS_1;
    huart1.Init.Parity = UART_PARITY_NONE;
    huart1.Init.Mode = UART_MODE_TX_RX;
    huart1.Init.HwFlowCtl = UART_HWCONTROL_NONE;
    huart1.Init.OverSampling = oversampling;
}

/* TIM2 free-running up to 0xFFFFFFFF at BOARD_TICK_HZ from a timer_clock_hz input clock,
 * started; board_fatal() if the HAL refuses. */
static inline void board_tick_timer_init(uint32_t timer_clock_hz)
{
    htim2.Instance = TIM2;
    htim2.Init.Prescaler = (timer_clock_hz / BOARD_TICK_HZ) - 1u;
    htim2.Init.CounterMode = TIM_COUNTERMODE_UP;
    htim2.Init.Period = 0xFFFFFFFFu;
    htim2.Init.ClockDivision = TIM_CLOCKDIVISION_DIV1;
    htim2.Init.AutoReloadPreload = TIM_AUTORELOAD_PRELOAD_DISABLE;
    if ((HAL_TIM_Base_Init(&htim2) != HAL_OK) || (HAL_TIM_Base_Start(&htim2) != HAL_OK)) {
        board_fatal();
    }
}

/* USART1's and the RX stream's interrupts at BOARD_BUS_IRQ_PRIORITY, enabled (the TX stream's
 * is not used: the UART's transmit complete ends a transmit). */
static inline void board_bus_irqs_enable(IRQn_Type rx_dma)
{
    HAL_NVIC_SetPriority(USART1_IRQn, BOARD_BUS_IRQ_PRIORITY, 0u);
    HAL_NVIC_SetPriority(rx_dma, BOARD_BUS_IRQ_PRIORITY, 0u);
    HAL_NVIC_EnableIRQ(USART1_IRQn);
    HAL_NVIC_EnableIRQ(rx_dma);
}

/* TIM2's interrupt at BOARD_BUS_IRQ_PRIORITY, enabled. */
static inline void board_timer_irq_enable(void)
{
    HAL_NVIC_SetPriority(TIM2_IRQn, BOARD_BUS_IRQ_PRIORITY, 0u);
    HAL_NVIC_EnableIRQ(TIM2_IRQn);
}

#endif /* J288_EXAMPLE_BOARD_COMMON_H */
