/* board.h - what the example's main.c needs from a board: the HAL handles of the bus, the
 * emergency-stop button, board_init() and board_fatal(). Boards: nucleo_f446re/board.c and
 * nucleo_g474re/board.c (firmware against ST's HAL, `make firmware`, with
 * nucleo_common/board_nucleo.c), board_stub.c (the link check against the HAL stub, `make
 * arm`); all with board_common.c and board_common.h. In a CubeMX project the generated code provides
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

/* The UART, its RX stream and the timer share one priority, so that none of the port's entries
 * preempts another (required with advance_in_isr); SysTick stays lowest. main.c gives it to
 * the port, whose bus lock masks up to it (BASEPRI). */
#define BOARD_BUS_IRQ_PRIORITY 5u

/* The bus's interrupt entries (main.c, to the port): USART1's and the RX stream's IRQ
 * handlers call them. */
void board_bus_uart_irq(void);
void board_bus_dma_rx_irq(void);

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

#endif /* J288_EXAMPLE_BOARD_H */
