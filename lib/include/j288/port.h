/*
 * j288/port.h - what a port (one OS or one HAL) provides to a bus.
 *
 * A port is a const table of operations plus a context pointer, both handed to
 * j288_bus_init(), so a fake port and a real one can live in one program and one program can
 * drive several buses. The table must outlive the bus. Required operations are checked at
 * init (J288_ERR_PORT_OPS). Every operation receives the ctx given at init.
 *
 * Calling contexts: the bus calls start_tx, set_dir and arm_timeout from wherever it advances
 * (poll in thread context, or the ISR when the bus is configured to advance there), and calls
 * set_dir(J288_DIR_RX) and start_rx from j288_bus_on_tx_done(), i.e. typically from the
 * transmit-complete interrupt, so that the receiver is listening before the servo answers.
 * Those operations must therefore be safe in interrupt context. now_us may be called from
 * any context. lock/unlock and wait are only called from thread context.
 *
 * See port/template/ for an annotated skeleton and docs/porting.md for the walk-through.
 */
#ifndef J288_PORT_H
#define J288_PORT_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef enum { J288_DIR_TX = 0, J288_DIR_RX = 1 } j288_dir_t;

/* Line error flags for j288_bus_on_error(). */
#define J288_LINE_FRAMING 0x01u
#define J288_LINE_NOISE 0x02u
#define J288_LINE_OVERRUN 0x04u
#define J288_LINE_PARITY 0x08u
#define J288_LINE_DMA 0x10u
#define J288_LINE_GONE 0x20u /* the device disappeared (unplugged adapter): fatal */

typedef struct j288_port {
    /* REQUIRED. Start sending len bytes. The buffer belongs to the bus and stays untouched
     * until the port reports j288_bus_on_tx_done(); the port may send from it directly (DMA).
     * May call j288_bus_on_tx_done() before returning (an OS write that completes at once).
     * Returns 0, or a negative code: the transaction then fails with J288_ERR_PORT. */
    int (*start_tx)(void *ctx, const uint8_t *data, size_t len);

    /* REQUIRED. Monotonic microseconds; wraps at 2^32 (the bus compares times modulo 2^32,
     * so intervals up to 35 minutes are handled). Any context. The bus reads it when it
     * advances inside an event call (advance_in_isr) and in j288_bus_transfer_blocking();
     * the now_us the application passes to submit, poll and estop must be this same clock. */
    uint32_t (*now_us)(void *ctx);

    /* Optional. (Re)arm reception after a transmit: e.g. start a ReceiveToIdle DMA into the
     * port's own buffer. Ports with an always-on receiver leave it NULL. Received bytes are
     * handed to the bus with j288_bus_on_rx(). */
    void (*start_rx)(void *ctx);

    /* Optional. Switch a half-duplex line or a DE/RE pin: J288_DIR_TX before start_tx,
     * J288_DIR_RX when the transmit completes. */
    void (*set_dir)(void *ctx, j288_dir_t dir);

    /* Optional. Arrange for j288_bus_on_timer() to be called at or soon after deadline_us
     * (an MCU one-shot timer). Re-arming replaces the previous deadline. Without it the
     * application must call j288_bus_poll() often enough. */
    void (*arm_timeout)(void *ctx, uint32_t deadline_us);

    /* Optional (required by j288_bus_transfer_blocking()). OS ports: block until the port
     * has delivered some event to the bus (bytes, idle, error) or until until_us, whichever
     * is first. Returns 0, or J288_ERR_OFFLINE when the device is gone. Thread only. */
    int (*wait)(void *ctx, uint32_t until_us);

    /* Optional. Hardware CRC: same contract as j288_crc_t.fn (crc32.h). NULL: the compile-
     * time default backend. */
    uint32_t (*crc32)(void *ctx, const uint8_t *data, size_t nwords);

    /* Optional, as a pair. Called around thread-context state changes so that an interrupt
     * which advances the same bus cannot interleave: mask the UART/DMA interrupts on an MCU,
     * a mutex on an OS. */
    void (*lock)(void *ctx);
    void (*unlock)(void *ctx);
} j288_port_t;

#ifdef __cplusplus
}
#endif

#endif /* J288_PORT_H */
