/*
 * fake_port.h - a scripted j288 port with a virtual clock, for host tests and benchmarks.
 *
 * Time is virtual: nothing happens until the test runs the clock (fake_port_run_until()),
 * and then every scheduled event is delivered to the attached bus in time order, exactly as
 * a UART/DMA driver would from its interrupts. What it models:
 *
 * - Transmit: every frame passed to start_tx is recorded with its start and end times. The
 *   transmit-complete event comes after the wire time of the frame at `baud`, 8N1 (TIMED,
 *   the default), from inside start_tx (INLINE: an OS write that completes at once), or
 *   when the test says so (MANUAL: fake_port_tx_done_at()).
 * - Echo (echo = true): each transmitted byte is received back one byte time later, as a
 *   transceiver that hears itself; echo_flip_at corrupts one echoed byte (a collision).
 * - Servos (servo[0..14]): a present servo answers each valid command addressed to it with
 *   its reply template, after turnaround_ns (+ extra_delay_ns), at the wire's byte rate,
 *   delivered in chunks of `chunk` bytes (0: the whole frame at its last byte, like a DMA
 *   transfer-complete), optionally preceded by garbage bytes, corrupted, from a wrong id,
 *   or followed by a twin (a second servo with the same id). A command with the watchdog
 *   bit 0 clears the servo's watchdog_tripped flag, as the manual says. Broadcasts (id 15)
 *   are obeyed by every present servo and answered by none.
 * - Script: bytes, idle, line errors and transmit-complete at any virtual time.
 * - Timer: arm_timeout() is honoured: at the deadline the fake calls j288_bus_on_timer().
 * - wait(): advances the clock to the next event (or until_us) and delivers it, so that
 *   j288_bus_transfer_blocking() runs entirely on the virtual clock.
 * - poll hook: after each delivered event (and at the end of a run) the fake calls
 *   poll_fn(poll_user, now_us) if set: the application's main loop in poll mode.
 *
 * Every op in `ops` is present after fake_port_init(); clear a field (e.g. ops.arm_timeout =
 * NULL) before j288_bus_init() to test a port without it. Not thread-safe; no allocation.
 */
#ifndef FAKE_PORT_H
#define FAKE_PORT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "j288/bus.h"
#include "j288/frame.h"
#include "j288/port.h"

#define FAKE_PORT_MAX_FRAMES 128u /* frames recorded in full; later ones are only counted */
#define FAKE_PORT_MAX_EVENTS 512u /* scheduled events pending at once */
#define FAKE_PORT_CHUNK_MAX  32u  /* bytes in one scheduled rx event */

typedef enum {
    FAKE_TXDONE_TIMED = 0, /* tx done after the frame's wire time (an MCU) */
    FAKE_TXDONE_INLINE,    /* tx done from inside start_tx (an OS write) */
    FAKE_TXDONE_MANUAL     /* only fake_port_tx_done_at() */
} fake_txdone_mode_t;

typedef struct {
    uint8_t data[J288_REPLY_LEN];
    size_t len;
    uint64_t start_ns; /* when start_tx was called */
    uint64_t end_ns;   /* when the last bit left */
    uint32_t start_us; /* now_us() at start_tx */
} fake_frame_t;

typedef struct {
    bool present;
    j288_reply_raw_t reply;  /* answer template; .id is set from the servo's id */
    int reply_id;            /* -1: its own id; else answer with this id (wrong id) */
    uint32_t turnaround_ns;  /* end of command to start of reply; 0: fake_port.turnaround_ns */
    uint32_t extra_delay_ns; /* added to the turnaround (a late reply) */
    uint8_t chunk;           /* 0: whole reply at its last byte; n: chunks of n bytes */
    uint8_t garbage;         /* noise bytes sent before the reply */
    bool corrupt;            /* flip a payload bit: a CRC error */
    bool truncate;           /* stop after 15 bytes (then idle, if idle is on) */
    bool twin;               /* a second servo with this id answers after the first */
    uint32_t twin_gap_ns;    /* from the end of the first reply to the twin's */
    uint32_t commands;       /* valid commands received (broadcasts included) */
    j288_cmd_raw_t last_cmd; /* the latest of them */
} fake_servo_t;

typedef void (*fake_poll_fn)(void *user, uint32_t now_us);

typedef struct fake_port fake_port_t;

struct fake_port {
    j288_port_t ops; /* hand &fp->ops and fp to j288_bus_init() */
    j288_bus_t *bus; /* events go here (fake_port_attach) */

    /* configuration: set after fake_port_init, before running */
    uint32_t baud;             /* byte timing, 8N1; default 6000000 */
    uint32_t origin_us;        /* now_us() at virtual time 0 (test wrap-around) */
    fake_txdone_mode_t txdone; /* default TIMED */
    bool echo;
    int echo_flip_at;       /* echoed byte index to corrupt, -1: none */
    uint32_t echo_delay_ns; /* receive path delay of the echo (e.g. a FIFO) */
    bool idle;              /* report rx idle one byte time after each reply; default on */
    uint32_t turnaround_ns; /* default servo turnaround: 10000 (10 us) */
    uint32_t rx_latency_ns; /* servo reply bytes reach the bus this much later (an
                               idle-line DMA interrupt, ISR latency); idle too */
    int start_tx_fail;      /* > 0: that many next start_tx calls return J288_ERR_PORT */
    bool gone;              /* wait() returns J288_ERR_OFFLINE */
    uint64_t gone_after_ns; /* and from this virtual time on, if not 0 (unplugged mid-run) */
    fake_poll_fn poll_fn;
    void *poll_user;
    fake_servo_t servo[J288_MAX_SERVOS];

    /* observation */
    uint64_t now_ns;
    fake_frame_t frame[FAKE_PORT_MAX_FRAMES];
    uint32_t nframes;  /* frames sent (may exceed FAKE_PORT_MAX_FRAMES) */
    fake_frame_t last; /* the latest frame sent */
    uint32_t set_dir_calls;
    j288_dir_t dir;
    uint32_t start_rx_calls;
    uint32_t timer_arms;
    uint32_t timer_fires;
    bool timer_armed;
    uint64_t timer_ns;
    int lock_depth;
    uint32_t lock_calls;
    int lock_errors;    /* unlock without lock, or nested lock */
    uint32_t crc_calls; /* when ops.crc32 is fake_port_crc32 */
    uint32_t wait_calls;
    bool tx_busy;          /* between start_tx and its tx done */
    int tx_overlap_errors; /* start_tx while a transmit was still running */

    /* private: the event queue */
    struct fake_event {
        uint64_t t_ns;
        uint32_t seq;
        uint8_t kind;
        uint8_t len;
        uint32_t flags;
        uint8_t data[FAKE_PORT_CHUNK_MAX];
    } ev[FAKE_PORT_MAX_EVENTS];
    uint32_t nev;
    uint32_t seq;
    int overflow_errors; /* events dropped because the queue was full */
};

/* Defaults as described above; every op present (crc32 is NULL: the default backend). */
void fake_port_init(fake_port_t *fp);

/* Where events go. Call after j288_bus_init(bus, &fp->ops, fp, ...). */
void fake_port_attach(fake_port_t *fp, j288_bus_t *bus);

/* A servo answering at id with reply (copied; id fields set). */
void fake_port_add_servo(fake_port_t *fp, uint8_t id, const j288_reply_raw_t *reply);

/* Current virtual time. */
uint32_t fake_port_now_us(const fake_port_t *fp);
/* One byte's wire time at fp->baud, 8N1, in ns (rounded down). */
uint64_t fake_port_byte_ns(const fake_port_t *fp);

/* Script events at absolute virtual times (ns). Data is copied, split into chunks of at
 * most FAKE_PORT_CHUNK_MAX bytes. */
void fake_port_rx_at(fake_port_t *fp, uint64_t t_ns, const uint8_t *data, size_t len);
/* Bytes at the wire's pace from t_ns: one event per byte (each at the end of its byte). */
void fake_port_rx_paced(fake_port_t *fp, uint64_t t_ns, const uint8_t *data, size_t len);
void fake_port_idle_at(fake_port_t *fp, uint64_t t_ns);
void fake_port_error_at(fake_port_t *fp, uint64_t t_ns, uint32_t line_flags);
void fake_port_tx_done_at(fake_port_t *fp, uint64_t t_ns);

/* Run the clock to t_ns (absolute) / for dt_ns, delivering every event due, calling the
 * poll hook after each and once at the end. */
void fake_port_run_until(fake_port_t *fp, uint64_t t_ns);
void fake_port_run_for(fake_port_t *fp, uint64_t dt_ns);
/* Run until the bus is idle (and no event is pending before it) or limit_ns passes.
 * Returns true when idle. */
bool fake_port_run_until_idle(fake_port_t *fp, uint64_t limit_ns);

/* Time of the next pending event (or armed timer); UINT64_MAX when none. */
uint64_t fake_port_next_event_ns(const fake_port_t *fp);

/* Recorded frame i (0 = first), or NULL beyond what was kept. */
const fake_frame_t *fake_port_frame(const fake_port_t *fp, uint32_t i);

/* A reply frame for tests, encoded with the default CRC (asserts nothing; the fields must be
 * valid for j288_reply_encode, else the frame is all zero). */
void fake_port_encode_reply(const j288_reply_raw_t *reply, uint8_t out[J288_REPLY_LEN]);

/* Ready-made poll hooks: poll_user is the j288_bus_t* (or the j288_sched_t*). */
void fake_port_poll_bus(void *bus, uint32_t now_us);
void fake_port_poll_sched(void *sched, uint32_t now_us);

/* The one place where the fake calls into the bus (kind: internal event kind; 0 = timer).
 * Exposed so that benchmarks can count the instructions spent inside the library. */
void fake_port_deliver(fake_port_t *fp, int kind, const uint8_t *data, size_t len, uint32_t flags);

/* A crc32 op (software, counting calls) to test the port's CRC hook. */
uint32_t fake_port_crc32(void *ctx, const uint8_t *data, size_t nwords);

#endif /* FAKE_PORT_H */
