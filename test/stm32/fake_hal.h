/*
 * fake_hal.h - a host-side fake of the HAL slice in test/stm32/stub/: it records every
 * call the port makes and lets a test play the hardware, firing the HAL's callbacks in the
 * order the real HAL fires them:
 *   transmit:  HAL_UART_Transmit_DMA ... fake_hal_tx_complete() -> HAL_UART_TxCpltCallback
 *   receive:   HAL_UARTEx_ReceiveToIdle_DMA ... fake_hal_rx_bytes() (half-transfer and
 *              buffer-full events fire on their own as the buffer fills, with the fill level)
 *              ... fake_hal_rx_idle() -> HAL_UARTEx_RxEventCallback(fill level), reception ends
 *   error:     fake_hal_rx_error() -> reception aborted, ErrorCode set, HAL_UART_ErrorCallback
 *   timer:     fake_hal_tim_fire() -> HAL_TIM_OC_DelayElapsedCallback when the CC interrupt
 *              is enabled; fake_hal_tim_run() runs the counter with compare matches, and
 *              fake_hal_tim_advance_at() lets it run between any two register accesses
 *   DMA:       a stream whose handle is not READY does not start, and (as the F4 HAL does)
 *              the UART call still returns HAL_OK
 * The test defines the weak callbacks itself (as an application does) and forwards them to
 * the port. Bytes sent while the receiver is off (TX direction, or no reception armed) are
 * lost, as on the wire.
 */
#ifndef J288_FAKE_HAL_H
#define J288_FAKE_HAL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "stm32_hal_stub.h"

typedef enum {
    FAKE_HALFDUPLEX_TX = 0,
    FAKE_HALFDUPLEX_RX,
    FAKE_TRANSMIT_DMA,
    FAKE_RECEIVE_TO_IDLE_DMA,
    FAKE_ABORT_RECEIVE,
    FAKE_ABORT_TRANSMIT,
    FAKE_DMA_ABORT,
    FAKE_GPIO_WRITE,
    FAKE_CRC_CALCULATE,
    FAKE_CRC_ACCUMULATE,
    FAKE_CACHE_CLEAN,
    FAKE_CACHE_INVALIDATE,
    FAKE_FN_COUNT
} fake_hal_fn_t;

typedef struct {
    fake_hal_fn_t fn;
    const void *handle; /* huart, GPIO port, hcrc or buffer address */
    uint32_t arg;       /* size, pin state, word count */
} fake_hal_call_t;

#define FAKE_HAL_LOG_SIZE 256u

/* Forget everything (log, counters, armed transfers, failure injections). */
void fake_hal_reset(void);

/* The call log since the last reset or clear. */
size_t fake_hal_log_len(void);
const fake_hal_call_t *fake_hal_log_at(size_t i);
void fake_hal_log_clear(void);
/* Index of the first logged call of fn on handle at or after from, or -1. handle NULL: any. */
long fake_hal_log_find(fake_hal_fn_t fn, const void *handle, size_t from);
unsigned fake_hal_count(fake_hal_fn_t fn);

/* Make the next call of fn (TRANSMIT_DMA, RECEIVE_TO_IDLE_DMA, HALFDUPLEX_*, ABORT_*) return
 * HAL_ERROR. */
void fake_hal_fail_next(fake_hal_fn_t fn);

/* The last frame handed to HAL_UART_Transmit_DMA on huart (copied at the call), and whether
 * a transmit is in flight. */
const uint8_t *fake_hal_tx_data(const UART_HandleTypeDef *huart, size_t *len);
bool fake_hal_tx_busy(const UART_HandleTypeDef *huart);

/* The transmit finished: TxCpltCallback. Returns false if none was in flight. */
bool fake_hal_tx_complete(UART_HandleTypeDef *huart);

/* Bytes arrive on huart's pin. Stored only while a reception is armed and the receiver is
 * enabled; fires the half-transfer event at half the buffer and ends the reception when full.
 * Returns how many bytes were stored. */
size_t fake_hal_rx_bytes(UART_HandleTypeDef *huart, const uint8_t *data, size_t len);

/* Receive streams in circular mode (true) from now on: a full buffer wraps with an RxEvent of
 * the full size and an idle line reports the position; the reception never ends by itself. */
void fake_hal_rx_circular(bool on);

/* The line went idle: if the armed reception holds bytes, it ends with an RxEvent (circular:
 * it reports the position and goes on). */
bool fake_hal_rx_idle(UART_HandleTypeDef *huart);

/* A receive error (HAL_UART_ERROR_* bits) in DMA mode: the HAL aborts the reception, then
 * calls the error callback. */
void fake_hal_rx_error(UART_HandleTypeDef *huart, uint32_t error_code);

bool fake_hal_rx_armed(const UART_HandleTypeDef *huart);
bool fake_hal_receiver_on(const UART_HandleTypeDef *huart);
bool fake_hal_transmitter_on(const UART_HandleTypeDef *huart);

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

/* Interrupt mask state: current PRIMASK and how often interrupts were disabled. */
uint32_t fake_hal_primask(void);
unsigned fake_hal_irq_disables(void);

#endif /* J288_FAKE_HAL_H */
