/*
 * j288/bus.h - the half-duplex bus engine: one transaction at a time on one physical bus.
 *
 * A transaction sends one 20-byte command and, unless it is a broadcast (id 15), waits for
 * the addressed servo's 26-byte reply until a deadline: the wire time of command and reply
 * at the configured baud plus turnaround_us plus margin_us, counted from the start of
 * transmit. A pause inside a reply does not end it: a frame still incomplete at the deadline
 * is J288_ERR_TRUNCATED. The result is J288_OK or the most specific failure seen (wrong id >
 * line > crc > truncated > timeout; a differing echo is a collision; a line gone ends the
 * attempt at once, J288_ERR_OFFLINE). A failed attempt is re-sent up to config.retries times,
 * each attempt's result kept in the j288_txn_t. stats.crc_errors counts frames (each corrupt
 * one and each partial one given up); the scheduler's per-servo crc_errors counts
 * transactions.
 *
 * A quiet guard follows every transaction: guard_us after success; after a failure, one
 * reply budget after the later of the failure and the attempt's deadline, so that a late
 * reply dies out. A frame from another id, or bytes received outside the reply window, are
 * counted and never credited to a transaction. Bytes received before a poll are examined
 * before its deadline check: a late poll does not turn a good reply into a timeout.
 *
 * Clock: start, deadline and guard come from the now_us given to j288_bus_submit(),
 * j288_bus_poll() or j288_bus_estop() when that call advances the machine, and from
 * port->now_us() when an event call does (advance_in_isr) and in
 * j288_bus_transfer_blocking(): both must be the same clock (same epoch, microseconds).
 *
 * Contexts: the port's event calls (j288_bus_on_*) only record, lock-free, from any context
 * (32-bit loads and stores must be atomic, as on every Cortex-M). The machine advances in
 * j288_bus_poll() (thread), or inside the event calls when config.advance_in_isr is set; the
 * port's UART, DMA and timer interrupts must then share one priority, and thread-context
 * calls are wrapped in the port's lock/unlock.
 *
 * Zero allocation; the bus object is caller-allocated and must not move while in use.
 * Several buses are independent. The states and the path of a byte: docs/architecture.md.
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

/* Transmit attempts an emergency stop frame gets before it is given up (j288_bus_estop). */
#define J288_ESTOP_ATTEMPTS (J288_CONFIG_MAX_RETRIES + 1u)
#if J288_CONFIG_MAX_RETRIES < 1
#error "J288_CONFIG_MAX_RETRIES must be at least 1: the emergency stop frame is re-sent"
#endif

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

/* Bus-wide counters (per-servo ones live in the scheduler). Attempt outcomes and what was
 * seen on the wire are counted where they happen, whatever the transaction's final result.
 * Each accepted submit ends in exactly one of ok, failed and aborted, counted just before its
 * callback runs, so that at any time, seen from the thread or from a callback:
 *   transactions == ok + failed + aborted + (1 if a submit is in flight or queued, else 0).
 * The emergency stop frame is none of these (see estops). */
typedef struct {
    uint32_t transactions; /* submits accepted */
    uint32_t attempts;     /* frames handed to start_tx (stop frames included) */
    uint32_t ok;           /* user transactions that ended J288_OK */
    uint32_t failed;       /* user transactions that ended with any other result (after all
                              their retries), except J288_ERR_ABORTED */
    uint32_t timeouts;     /* attempts ended by the deadline (reply or tx done) */
    uint32_t crc_errors;   /* frames in a reply window: each corrupt one and each partial one
                              given up at the deadline (the slot's counts transactions) */
    uint32_t wrong_id;     /* good frames from another id in a reply window */
    uint32_t collisions;   /* attempts whose echo differed or never came back */
    uint32_t line_errors;  /* line error reports, any state */
    uint32_t port_errors;  /* start_tx failures */
    uint32_t aborted;      /* transactions ended J288_ERR_ABORTED by an estop */
    uint32_t stale_bytes;   /* discarded outside a reply window (late replies, noise) */
    uint32_t rx_overflows;  /* bytes lost because the ring was full */
    uint32_t estops;        /* stops started by j288_bus_estop() (re-sends of one stop count
                               in attempts, not here; not counted in transactions, ok or
                               aborted: the stop is not a user transaction) */
    uint32_t estop_failures; /* stops given up: every one of their J288_ESTOP_ATTEMPTS
                                transmits failed, or the line went away (j288_bus_estop) */
} j288_bus_stats_t;

typedef struct j288_bus {
    /* Private: read through the functions below. Fields marked (ev) are written only by the
     * event calls (producer side), the rest only by the context that advances the machine,
     * so that recording needs no lock. */
    const j288_port_t *port;
    void *port_ctx;
    j288_crc_t crc;
    j288_bus_config_t cfg;
    uint32_t reply_budget_us;
    uint8_t state;                /* read from other contexts through j288_bus_state() */
    uint8_t tx_buf[J288_CMD_LEN]; /* a submitted command, encoded */
    uint8_t tx_id;                /* id addressed by tx_frame */
    const uint8_t *tx_frame;      /* the transaction's frame: tx_buf, or the scheduler's own
                                     (owned by the port from start_tx until tx done) */
    j288_parser_t parser;
    /* receive ring: free-running indexes, masked on use */
    uint8_t ring[J288_CONFIG_RX_RING_SIZE];
    volatile uint32_t ring_head;   /* (ev) */
    volatile uint32_t ring_tail;
    volatile uint32_t ev_tx_done;  /* (ev) event counters: compared with the seen_* copies */
    volatile uint32_t ev_line;     /* (ev) */
    volatile uint32_t ev_gone;     /* (ev) */
    volatile uint32_t txdone_mark; /* (ev) ring_head when the transmit completed */
    volatile uint32_t line_flags;  /* (ev) OR of every line flag reported (diagnostic) */
    volatile uint32_t ev_any;      /* (ev) +1 at every tx done, line report, on_rx into ring */
    uint32_t seen_tx_done, seen_line, seen_gone;
    uint32_t seen_any;             /* ev_any when the machine had last taken every event */
    const uint8_t *direct;         /* bytes of an on_rx taken in place (advance_in_isr), */
    uint32_t direct_pos;           /* at these ring positions, during that call only */
    uint32_t direct_len;
    uint8_t echo_pos;     /* echo bytes matched so far */
    uint8_t cur;          /* txn[cur] is the transaction in progress */
    bool tx_complete;     /* this attempt's transmit has completed */
    bool collided;        /* this attempt's echo differed */
    bool in_advance;      /* the machine is advancing (re-entry guard) */
    bool again;           /* advance once more: something changed */
    uint8_t flags;        /* what waits: a queued submit, a retry, an estop (bus.c) */
    int attempt_fail;     /* most specific failure seen in this attempt, or J288_OK */
    uint32_t deadline;    /* reply deadline of the attempt in flight */
    uint32_t guard_end;
    uint32_t timer_at;    /* the next time the machine needs to look (deadline/guard end) */
    j288_txn_t txn[2];    /* two, so a callback's txn survives a submit made inside it */
    j288_bus_done_fn done;
    void *done_user;
    j288_bus_stats_t stats;
} j288_bus_t;

/* Set up a bus. cfg may be NULL (defaults). Errors: J288_ERR_NULL, J288_ERR_PORT_OPS
 * (start_tx or now_us missing, or only one of lock/unlock), J288_ERR_BAD_CONFIG (retries
 * above J288_CONFIG_MAX_RETRIES, baud below 9600, turnaround, margin or guard above 60 s).
 * Thread only, before any event. */
int j288_bus_init(j288_bus_t *bus, const j288_port_t *port, void *port_ctx,
                  const j288_bus_config_t *cfg);

/* The library's build of the [layout] options (config.h). Calls to j288_bus_init() go
 * through this macro, which reads the object named after the caller's values: a program and
 * a library built with different values do not link. (j288_bus_init) or &j288_bus_init
 * bypasses it; the function keeps its name. */
extern const unsigned char J288_ABI_TAG;
#define j288_bus_init(bus, port, port_ctx, cfg)                                                   \
    ((void)*(const volatile unsigned char *)&J288_ABI_TAG,                                       \
     j288_bus_init((bus), (port), (port_ctx), (cfg)))

/* Start a transaction: encode cmd and transmit it. done may be NULL. Accepted while idle
 * (transmits at once) or during the guard after the previous transaction (transmits when
 * the guard ends; this is how a done callback submits the next one). Errors, nothing sent:
 * J288_ERR_NULL, the encoder's codes (J288_ERR_BAD_ID, ...), J288_ERR_BUSY (a transaction in
 * flight or already queued, or an estop pending). Thread only, or ISR with advance_in_isr
 * (e.g. from a done callback). */
int j288_bus_submit(j288_bus_t *bus, const j288_cmd_raw_t *cmd, uint32_t now_us,
                    j288_bus_done_fn done, void *user);

/* Advance the machine: take recorded events, check the deadline, start the next attempt or
 * finish. Cheap when nothing happened. Thread only (or the one ISR that owns the bus). */
void j288_bus_poll(j288_bus_t *bus, uint32_t now_us);

/* Port events. ISR-safe: they record and return (and advance the machine when
 * advance_in_isr). on_rx never keeps data: it is copied into the ring, or with advance_in_isr
 * taken during the call; data may be reused as soon as on_rx returns; bytes beyond the
 * ring's free space are dropped and counted (rx_overflows). on_tx_done also switches the port
 * to receive at once (set_dir(RX), then start_rx unless config.echo, whose receiver was
 * started before the transmit); it may be called from inside start_tx. on_timer only matters
 * with advance_in_isr (in poll mode the next poll looks at the clock itself). on_rx_idle does
 * nothing: a pause never ends a frame (see above); ports that see idle lines may still call
 * it. */
void j288_bus_on_tx_done(j288_bus_t *bus);
void j288_bus_on_rx(j288_bus_t *bus, const uint8_t *data, size_t len);
void j288_bus_on_rx_idle(j288_bus_t *bus);
void j288_bus_on_error(j288_bus_t *bus, uint32_t line_flags);
void j288_bus_on_timer(j288_bus_t *bus);

/* Emergency stop: broadcast lock (id 15, status 0, watchdog bit 0, all fields 0: no watchdog
 * left to trip, and a trip cleared) as soon as the
 * line is free, ahead of anything else. A transaction in flight is not cut mid-frame and its
 * reply is not talked over: it ends with J288_ERR_ABORTED when its attempt ends (reply taken,
 * deadline, collision; at most one reply budget), without retries, its real reason kept in
 * attempt_result[]; a submit queued behind a guard ends J288_ERR_ABORTED with 0 attempts.
 * The stop frame then goes out at once (skipping the guard).
 * A stop frame whose transmit fails (start_tx error, echo collision or incomplete echo, no tx
 * done by its deadline, a line error during it) is sent again when the guard after a failed
 * attempt has passed (the guard after a failure, above), whatever config.retries says, up to J288_ESTOP_ATTEMPTS transmits in all; J288_LINE_GONE
 * (during a transmit or while waiting to re-send) ends it at once. A stop given up this way
 * counts in stats.estop_failures (stats.estops counts every stop started); the port's own
 * errors are counted as usual (port_errors, collisions, timeouts, line_errors).
 * Submits are refused (J288_ERR_BUSY) until the stop frame is out or given up. An estop
 * meanwhile is merged into the stop in progress: nothing more is sent if that stop gets out,
 * and a new stop (J288_ESTOP_ATTEMPTS more transmits) starts at once if it is given up.
 * The stop has no completion callback and is not a transaction in the statistics.
 * Returns J288_OK or J288_ERR_NULL. Thread only (or the owning ISR). */
int j288_bus_estop(j288_bus_t *bus, uint32_t now_us);

/* Blocking transfer for OS ports: submit, then loop on port->wait() and j288_bus_poll()
 * until done. The same engine, not a second one. txn may be NULL. Returns the transaction's
 * result, or J288_ERR_PORT_OPS (no wait op), J288_ERR_BUSY (also when called from a done
 * callback), the encoder's codes, or J288_ERR_OFFLINE (wait failed: the transaction is
 * ended). Right after a previous transaction it first waits out the guard. Thread only. */
int j288_bus_transfer_blocking(j288_bus_t *bus, const j288_cmd_raw_t *cmd, j288_txn_t *txn);

/* Inspection. Thread or ISR. */
j288_bus_state_t j288_bus_state(const j288_bus_t *bus);
bool j288_bus_is_idle(const j288_bus_t *bus);
const j288_bus_stats_t *j288_bus_stats(const j288_bus_t *bus);
const j288_parser_stats_t *j288_bus_parser_stats(const j288_bus_t *bus);

/* Wire time of nbytes at baud (0: 6000000), 8N1 (10 bits per byte), rounded up to whole
 * microseconds. */
uint32_t j288_wire_time_us(uint32_t baud, uint32_t nbytes);

/* The reply deadline budget this bus uses, in microseconds from the start of transmit. */
uint32_t j288_bus_reply_budget_us(const j288_bus_t *bus);

/* The configuration the bus runs with: j288_bus_init()'s, defaults filled in (baud, guard,
 * ...), e.g. its retries. Valid as long as the bus; NULL for a NULL bus. Thread or ISR. */
const j288_bus_config_t *j288_bus_config(const j288_bus_t *bus);

#ifdef __cplusplus
}
#endif

#endif /* J288_BUS_H */
