/*
 * board_nucleo.h - the bring-up steps both NUCLEO boards (nucleo_f446re, nucleo_g474re) take
 * alike against ST's HAL, whatever the family: the PLL from the external clock with the HSI as
 * fallback, the switch to the PLL, the DMA settings of the bus, the bus pin PA9, the user
 * button PC13. Inline: each board calls them once, so the images stay as small as with the
 * code written out. Each ends in board_fatal() when the HAL refuses.
 */
#ifndef J288_EXAMPLE_BOARD_NUCLEO_H
#define J288_EXAMPLE_BOARD_NUCLEO_H

#include "board_common.h"

/* -DBOARD_CLOCK_HSI=1: run from the internal RC even when the external clock is there. */
#ifndef BOARD_CLOCK_HSI
#define BOARD_CLOCK_HSI 0
#endif

/* The PLL from the external clock (pll_start(true)), else from the HSI (pll_start(false)):
 * a board without the external clock still boots, about 1 % accurate (enough for the bench,
 * see docs/stm32.md); board_clock_hse says which. */
static inline void board_pll_hse_else_hsi(HAL_StatusTypeDef (*pll_start)(bool hse))
{
    board_clock_hse = !BOARD_CLOCK_HSI && (pll_start(true) == HAL_OK);
    if (!board_clock_hse && (pll_start(false) != HAL_OK)) {
        board_fatal();
    }
}

/* SYSCLK from the PLL, AHB undivided, APB1 and APB2 divided as given, with the flash wait
 * states the new clock needs. */
static inline void board_sysclk_from_pll(uint32_t apb1_div, uint32_t apb2_div, uint32_t flash_latency)
{
    RCC_ClkInitTypeDef clk = {0};
    clk.ClockType = RCC_CLOCKTYPE_HCLK | RCC_CLOCKTYPE_SYSCLK | RCC_CLOCKTYPE_PCLK1 | RCC_CLOCKTYPE_PCLK2;
    clk.SYSCLKSource = RCC_SYSCLKSOURCE_PLLCLK;
    clk.AHBCLKDivider = RCC_SYSCLK_DIV1;
    clk.APB1CLKDivider = apb1_div;
    clk.APB2CLKDivider = apb2_div;
    if (HAL_RCC_ClockConfig(&clk, flash_latency) != HAL_OK) {
        board_fatal();
    }
}

/* The bus's DMA transfer: bytes, memory side incrementing, high priority, in the given
 * direction and mode (normal for TX, circular for RX); h->Instance and the family's request
 * fields are the board's to set first. */
static inline void board_dma_init(DMA_HandleTypeDef *h, uint32_t direction, uint32_t mode)
{
    h->Init.Direction = direction;
    h->Init.PeriphInc = DMA_PINC_DISABLE;
    h->Init.MemInc = DMA_MINC_ENABLE;
    h->Init.PeriphDataAlignment = DMA_PDATAALIGN_BYTE;
    h->Init.MemDataAlignment = DMA_MDATAALIGN_BYTE;
    h->Init.Mode = mode;
    h->Init.Priority = DMA_PRIORITY_HIGH;
    if (HAL_DMA_Init(h) != HAL_OK) {
        board_fatal();
    }
}

/* PA9 (Arduino D8) as USART1_TX, the single wire: AF7, push-pull, with the internal pull-up
 * (idle high while nobody drives; add 1-4.7k outside: see docs). */
static inline void board_bus_pin_init(void)
{
    GPIO_InitTypeDef pin = {0};
    __HAL_RCC_GPIOA_CLK_ENABLE();
    pin.Pin = GPIO_PIN_9;
    pin.Mode = GPIO_MODE_AF_PP;
    pin.Pull = GPIO_PULLUP;
    pin.Speed = GPIO_SPEED_FREQ_VERY_HIGH;
    pin.Alternate = GPIO_AF7_USART1;
    HAL_GPIO_Init(GPIOA, &pin);
}

/* The blue user button B1 on PC13 as an input with the given pull. */
static inline void board_button_init(uint32_t pull)
{
    GPIO_InitTypeDef pin = {0};
    __HAL_RCC_GPIOC_CLK_ENABLE();
    pin.Pin = GPIO_PIN_13;
    pin.Mode = GPIO_MODE_INPUT;
    pin.Pull = pull;
    HAL_GPIO_Init(GPIOC, &pin);
}

#endif /* J288_EXAMPLE_BOARD_NUCLEO_H */
