/* board.h - what the example's main.c needs from a board: the HAL handles of the bus, the
 * emergency-stop button, board_init() and board_fatal(). Boards: nucleo_f446re/board.c and
 * nucleo_g474re/board.c (firmware against ST's HAL, `make firmware`, with
 * cortex_m/board_fault.c), board_stub.c (the link check against the HAL stub, `make arm`); all
 * with board_common.c. In a CubeMX project the generated code provides
 * the same handles. */
#ifndef J288_EXAMPLE_BOARD_H
#define J288_EXAMPLE_BOARD_H

#include <stdbool.h>
#include <stdint.h>

#include "main.h"

extern UART_HandleTypeDef huart1;
extern DMA_HandleTypeDef hdma_usart1_tx;
extern DMA_HandleTypeDef hdma_usart1_rx;
extern TIM_HandleTypeDef htim2;
extern CRC_HandleTypeDef hcrc;

/* What the fault handler records (read it with a debugger: `p board_fault`). */
typedef struct {
    uint32_t cfsr, hfsr, mmfar, bfar; /* SCB fault status and address registers */
    uint32_t pc, lr;                  /* where the fault happened */
    uint32_t count;
} board_fault_t;
extern volatile board_fault_t board_fault;
/* The system clock runs from the external clock (true) or fell back to the HSI (false). */
extern volatile bool board_clock_hse;

/* Clocks, pins, DMA, NVIC, UART, timer, CRC unit; board_fatal() on any failure. */
void board_init(void);
/* The emergency-stop button (the NUCLEO's blue button B1 on PC13) is pressed. */
bool board_estop_pressed(void);
/* Interrupts off, stop here (the servos lock themselves after their 1 s watchdog). Declared
 * noreturn so that the callers in other files need no code after the call. */
#if defined(__GNUC__)
__attribute__((noreturn))
#endif
void board_fatal(void);

/* ---- for the boards' board_init() (inline: each board calls them once) ----------------- */
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

#endif /* J288_EXAMPLE_BOARD_H */
