/*
 * fake_hal.h - a host-side model of what the STM32 port touches: the USART and DMA registers
 * of the F4 (the default) or of the G4 (-DJ288_STUB_G4), played as the silicon plays them,
 * plus the HAL slice (GPIO, CRC unit, timer macros) that the port still calls. The test plays
 * the rest of the hardware:
 *   transmit:  the port loads the TX stream and enables the UART's transmit complete; the
 *              test ends it with fake_hal_tx_complete(): the frame goes out, the line hears
 *              it back (the echo, unless the line is deaf), TC rises
 *   receive:   fake_hal_rx_bytes() puts bytes on the line: each one the receiver takes (when
 *              on) goes through the data register to the RX stream, which raises its half
 *              and complete flags; fake_hal_line_idle() raises IDLE after received bytes;
 *              fake_hal_rx_flagged() a byte with a noise, framing, parity flag or an overrun
 *   interrupts: the NVIC: after each step, the UART's and the RX stream's pending enabled
 *              flags call the application's handlers (fake_app_uart_irq,
 *              fake_app_dma_rx_irq, defined by the test), until none is pending; held
 *              (fake_hal_irq_hold) they wait for fake_hal_irq_service()
 *   timer:     fake_hal_tim_fire() / fake_hal_tim_run() / fake_hal_tim_advance_at()
 * F4 specifics modelled: SR's rc_w0 write, IDLE and the error flags cleared by SR then DR
 * (a DR read also takes a byte still waiting for the DMA: it is lost), the stream's enable
 * bit clearing at the end of a normal transfer. G4: ICR clears, a flagged byte not handed to
 * the DMA (DDRE = 0), the channel's enable bit staying set.
 */
#ifndef J288_FAKE_HAL_H
#define J288_FAKE_HAL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "stm32_hal_stub.h"

typedef enum {
    FAKE_GPIO_WRITE = 0,
    FAKE_CRC_CALCULATE,
    FAKE_CRC_ACCUMULATE,
    FAKE_CACHE_CLEAN,
    FAKE_CACHE_INVALIDATE,
    FAKE_FN_COUNT
} fake_hal_fn_t;

typedef struct {
    fake_hal_fn_t fn;
    const void *handle; /* GPIO port, hcrc or buffer address */
    uint32_t arg;       /* pin state, word count, size */
} fake_hal_call_t;

#define FAKE_HAL_LOG_SIZE 256u

/* Forget everything (log, counters, UART models, timer hooks). */
void fake_hal_reset(void);

/* The call log since the last reset or clear. */
size_t fake_hal_log_len(void);
const fake_hal_call_t *fake_hal_log_at(size_t i);
void fake_hal_log_clear(void);
/* Index of the first logged call of fn on handle at or after from, or -1. handle NULL: any. */
long fake_hal_log_find(fake_hal_fn_t fn, const void *handle, size_t from);
unsigned fake_hal_count(fake_hal_fn_t fn);

/* The application's IRQ handlers for huart's UART and RX stream (the test defines them). */
void fake_app_uart_irq(UART_HandleTypeDef *huart);
void fake_app_dma_rx_irq(UART_HandleTypeDef *huart);

/* Give huart a UART and two DMA streams (channels on the G4) as HAL_HalfDuplex_Init and
 * HAL_DMA_Init leave them: UART on in half-duplex mode, handles linked, flag addresses set. */
void fake_hal_uart_setup(UART_HandleTypeDef *huart);

/* The line does not hear our transmit (a transceiver with /RE tied to DE). */
void fake_hal_line_deaf(UART_HandleTypeDef *huart, bool deaf);

/* The last frame transmitted on huart, and whether a transmit is loaded and not finished. */
const uint8_t *fake_hal_tx_data(const UART_HandleTypeDef *huart, size_t *len);
bool fake_hal_tx_busy(const UART_HandleTypeDef *huart);
/* The TX stream sends what it was loaded with (the line hears it back unless deaf); TC rises;
 * then the line idles (then_idle), or the reply follows at once (false). false if nothing was
 * loaded. fake_hal_tx_complete: then_idle. */
bool fake_hal_tx_complete(UART_HandleTypeDef *huart);
bool fake_hal_tx_complete_ex(UART_HandleTypeDef *huart, bool then_idle);

/* Bytes on the line; returns how many the receiver took into the data register. */
size_t fake_hal_rx_bytes(UART_HandleTypeDef *huart, const uint8_t *data, size_t len);
/* One byte with line flags: FAKE_NOISE (right value, noise seen), FAKE_FRAMING (no stop
 * bit), FAKE_PARITY, or FAKE_OVERRUN (the byte is lost behind a full data register). */
#define FAKE_NOISE 0x1u
#define FAKE_FRAMING 0x2u
#define FAKE_PARITY 0x4u
#define FAKE_OVERRUN 0x8u
bool fake_hal_rx_flagged(UART_HandleTypeDef *huart, uint8_t byte, unsigned flags);
/* The line idles for a frame: IDLE rises if bytes came since the last idle. */
bool fake_hal_line_idle(UART_HandleTypeDef *huart);
/* The RX stream lags (true): a received byte waits in the data register (RXNE) through the
 * interrupt handlers taken meanwhile, and is taken after them or before the next byte. */
void fake_hal_dma_lag(UART_HandleTypeDef *huart, bool lag);
/* Received bytes lost to a DR read of the CPU while they waited for the DMA. */
unsigned fake_hal_bytes_stolen(const UART_HandleTypeDef *huart);

/* Interrupts held (true): pending ones wait; fake_hal_irq_service() runs the UART's handler
 * (uart = true) or the RX stream's, if its interrupt is pending, and says whether it was. */
void fake_hal_irq_hold(bool hold);
bool fake_hal_irq_service(UART_HandleTypeDef *huart, bool uart);
bool fake_hal_irq_pending(UART_HandleTypeDef *huart, bool uart);
/* A transfer error on the RX stream: the stream stops, TEIF rises. */
void fake_hal_dma_rx_error(UART_HandleTypeDef *huart);
/* The registers (for tests that look at them). */
USART_TypeDef *fake_hal_usart(const UART_HandleTypeDef *huart);
J288_STUB_DMA_INSTANCE *fake_hal_rx_stream(const UART_HandleTypeDef *huart);
J288_STUB_DMA_INSTANCE *fake_hal_tx_stream(const UART_HandleTypeDef *huart);

/* Capture/compare channel ch (TIM_CHANNEL_n) matched: fires the OC callback if its interrupt
 * is enabled. Returns whether it fired. */
bool fake_hal_tim_fire(TIM_HandleTypeDef *htim, uint32_t ch);

/* The timer as the silicon runs it: every register access the port makes goes through the
 * HAL macros (stub_tim_read/stub_tim_write); before access number `access` from now
 * (0 = the next one) the counter runs `ticks` ticks, raising the flag of each channel whose
 * compare value it reaches. One shot. */
void fake_hal_tim_advance_at(TIM_HandleTypeDef *htim, unsigned access, uint32_t ticks);
/* Timer register accesses since the last reset. */
unsigned fake_hal_tim_accesses(void);
/* Run the counter ticks ticks; whenever a compare flag is up with its interrupt enabled (also
 * before the first tick), do what HAL_TIM_IRQHandler does: clear it, call the OC callback.
 * Returns the callbacks made. */
unsigned fake_hal_tim_run(TIM_HandleTypeDef *htim, uint32_t ticks);

/* The CRC unit's clock off (true): it reads as zeros, as an unclocked peripheral does. */
void fake_hal_crc_unclocked(bool off);

/* Level last written to a GPIO pin (0/1), or -1 if never written. */
int fake_hal_gpio_level(const GPIO_TypeDef *port, uint16_t pin);

/* Interrupt mask state: current PRIMASK and how often interrupts were disabled; BASEPRI. */
uint32_t fake_hal_primask(void);
unsigned fake_hal_irq_disables(void);
uint32_t fake_hal_basepri(void);

#endif /* J288_FAKE_HAL_H */
