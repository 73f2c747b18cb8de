/*
 * j288/bus.h - the half-duplex bus engine: one transaction at a time on one physical bus.
 *
 * A transaction sends one 20-byte command and, unless it is a broadcast (id 15), waits for
 * the 26-byte reply of that servo:
 *
 *   IDLE -> TX -> [ECHO] -> WAIT_REPLY -> (done | timeout | crc | wrong id | collision |
 *   line error) -> GUARD -> IDLE
 *
 * - TX: the command is on the wire; the port reports the end with j288_bus_on_tx_done().
 * - ECHO (config.echo): a transceiver that hears itself returns our 20 bytes first; they are
 *   compared byte for byte, and a difference is a collision.
 * - WAIT_REPLY: bytes go through the reply parser; a good reply from the addressed id ends
 *   the transaction. A good reply from another id, or a corrupt frame, is recorded and the
 *   wait goes on until the deadline; the result then names the most specific failure
 *   (wrong id > crc > timeout). The deadline is the wire time of command and reply at the
 *   configured baud plus turnaround_us plus margin_us, counted from the start of transmit.
 * - GUARD: a quiet gap before the next transmit (guard_us after success; after a failure the
 *   full reply budget, so that a late reply dies out). Anything received during the guard,
 *   or before a transmit completes, is discarded and counted as stale: a late reply is
 *   never credited to a later transaction.
 * - Retries (config.retries): a failed attempt is re-sent after the guard; each attempt's
 *   reason is kept in the j288_txn_t.
 *
 * Events come from the port, usually in interrupt context, and only record (the receive path
 * copies into a ring inside the bus object). The machine advances in j288_bus_poll() (thread
 * context), or directly inside the event calls when config.advance_in_isr is set: then every
 * event call and j288_bus_on_timer() advance the machine, which lets sweeps run back to back
 * from interrupts; the port's UART, DMA and timer interrupts must then share one priority,
 * and thread-context calls are wrapped in the port's lock/unlock.
 *
 * Zero allocation; the bus object is caller-allocated and must not move while in use.
 * Several buses are independent.
 */
#ifndef J288_BUS_H
#define J288_BUS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "j288/config.h"
#include "j288/crc32.h"
#include "j288/error.h"
#include "j288/frame.h"
#include "j288/parser.h"
#include "j288/port.h"

#ifdef __cplusplus
extern "C" {
#endif

#define J288_DEFAULT_BAUD 6000000u
#define J288_DEFAULT_TURNAROUND_US 50u /* servo's reply delay allowance        */
#define J288_DEFAULT_MARGIN_US 20u     /* host latency on an MCU                */
#define J288_DEFAULT_GUARD_US 2u       /* quiet gap between transactions        */

typedef enum {
    J288_BUS_IDLE = 0,
    J288_BUS_TX,
    J288_BUS_ECHO,
    J288_BUS_WAIT_REPLY,
    J288_BUS_GUARD
} j288_bus_state_t;

/* The outcome of one transaction, handed to the completion callback. */
typedef struct {
    uint8_t id;           /* the addressed id (15 = broadcast) */
    int result;           /* J288_OK or the final attempt's failure code */
    uint8_t attempts;     /* 1 + retries used */
    int attempt_result[J288_CONFIG_MAX_RETRIES + 1u]; /* each attempt's result, in order */
    j288_reply_raw_t reply;  /* the reply; valid only when result == J288_OK, id != 15 */
    uint32_t start_us;    /* when the successful (or last) attempt began transmitting */
    uint32_t latency_us;  /* from start_us to the reply being taken (or to the failure) */
} j288_txn_t;

/* Completion callback: called exactly once per accepted submit, from the context that
 * advances the bus (poll, or an ISR with advance_in_isr). txn is valid only during the call.
 * The callback may submit the next transaction. */
typedef void (*j288_bus_done_fn)(void *user, const j288_txn_t *txn);

/* All-zero means defaults. */
typedef struct {
    uint32_t baud;          /* bits per second for the deadline; 0: 6000000 */
    uint32_t turnaround_us; /* servo reply delay allowance; 0: J288_DEFAULT_TURNAROUND_US */
    uint32_t margin_us;     /* host latency margin; 0: J288_DEFAULT_MARGIN_US (an OS port
                               over USB wants milliseconds) */
    uint32_t guard_us;      /* quiet gap after success; 0: J288_DEFAULT_GUARD_US */
    uint8_t retries;        /* 0..J288_CONFIG_MAX_RETRIES */
    bool echo;              /* the receiver hears our own transmit */
    bool advance_in_isr;    /* event calls advance the machine (see above) */
} j288_bus_config_t;

/* Bus-wide counters (per-servo ones live in the scheduler). */
typedef struct {
    uint32_t transactions; /* submits accepted */
    uint32_t attempts;
    uint32_t ok;
    uint32_t timeouts;
    uint32_t crc_errors;
    uint32_t wrong_id;
    uint32_t collisions;
    uint32_t line_errors;
    uint32_t port_errors;
    uint32_t aborted;
    uint32_t stale_bytes;   /* discarded outside a reply window (late replies, noise) */
    uint32_t rx_overflows;  /* bytes lost because the ring was full */
    uint32_t estops;
} j288_bus_stats_t;

typedef struct j288_bus {
    /* Private: read through the functions below. */
    const j288_port_t *port;
    void *port_ctx;
    j288_crc_t crc;
    j288_bus_config_t cfg;
    uint32_t reply_budget_us;
    volatile uint8_t state;
    uint8_t tx_buf[J288_CMD_LEN];
    j288_parser_t parser;
    /* receive ring: written by on_rx (producer), read by the advancing context */
    uint8_t ring[J288_CONFIG_RX_RING_SIZE];
    volatile uint32_t ring_head;
    volatile uint32_t ring_tail;
    volatile uint32_t ev_flags;
    volatile uint32_t line_flags;
    uint8_t echo_pos;
    uint32_t t_start;
    uint32_t deadline;
    int attempt_fail;
    bool estop_pending;
    j288_txn_t txn;
    j288_bus_done_fn done;
    void *done_user;
    j288_bus_stats_t stats;
} j288_bus_t;

/* Set up a bus. cfg may be NULL (defaults). Errors: J288_ERR_NULL, J288_ERR_PORT_OPS
 * (start_tx or now_us missing, or only one of lock/unlock), J288_ERR_BAD_CONFIG (retries
 * above J288_CONFIG_MAX_RETRIES, baud below 9600). Thread only, before any event. */
int j288_bus_init(j288_bus_t *bus, const j288_port_t *port, void *port_ctx,
                  const j288_bus_config_t *cfg);

/* Start a transaction: encode cmd and transmit it. done may be NULL. Errors, nothing sent:
 * J288_ERR_NULL, the encoder's codes (J288_ERR_BAD_ID, ...), J288_ERR_BUSY (not idle, or an
 * estop is pending). Thread only, or ISR with advance_in_isr (e.g. from a done callback). */
int j288_bus_submit(j288_bus_t *bus, const j288_cmd_raw_t *cmd, uint32_t now_us,
                    j288_bus_done_fn done, void *user);

/* Advance the machine: take recorded events, check the deadline, start the next attempt or
 * finish. Cheap when nothing happened. Thread only (or the one ISR that owns the bus). */
void j288_bus_poll(j288_bus_t *bus, uint32_t now_us);

/* Port events. ISR-safe: they record and return (and advance the machine when
 * advance_in_isr). data is copied; it may be reused as soon as on_rx returns. */
void j288_bus_on_tx_done(j288_bus_t *bus);
void j288_bus_on_rx(j288_bus_t *bus, const uint8_t *data, size_t len);
void j288_bus_on_rx_idle(j288_bus_t *bus);
void j288_bus_on_error(j288_bus_t *bus, uint32_t line_flags);
void j288_bus_on_timer(j288_bus_t *bus);

/* Emergency stop: broadcast lock (id 15, status 0, watchdog on, all fields 0) as soon as the
 * line is free, ahead of anything else. A transaction in flight is not cut mid-frame; it ends
 * with J288_ERR_ABORTED once its transmit completes, and submits are refused until the stop
 * frame is out. Returns J288_OK or J288_ERR_NULL. Thread only (or the owning ISR). */
int j288_bus_estop(j288_bus_t *bus, uint32_t now_us);

/* Blocking transfer for OS ports: submit, then loop on port->wait() and j288_bus_poll()
 * until done. The same engine, not a second one. txn may be NULL. Returns the transaction's
 * result, or J288_ERR_PORT_OPS (no wait op), J288_ERR_BUSY, the encoder's codes, or
 * J288_ERR_OFFLINE. Thread only. */
int j288_bus_transfer_blocking(j288_bus_t *bus, const j288_cmd_raw_t *cmd, j288_txn_t *txn);

/* Inspection. Thread or ISR. */
j288_bus_state_t j288_bus_state(const j288_bus_t *bus);
bool j288_bus_is_idle(const j288_bus_t *bus);
const j288_bus_stats_t *j288_bus_stats(const j288_bus_t *bus);
const j288_parser_stats_t *j288_bus_parser_stats(const j288_bus_t *bus);

/* Wire time of nbytes at baud, 8N1 (10 bits per byte), rounded up to whole microseconds. */
uint32_t j288_wire_time_us(uint32_t baud, uint32_t nbytes);

/* The reply deadline budget this bus uses, in microseconds from the start of transmit. */
uint32_t j288_bus_reply_budget_us(const j288_bus_t *bus);

#ifdef __cplusplus
}
#endif

#endif /* J288_BUS_H */
