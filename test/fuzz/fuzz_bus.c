/*
 * Fuzz target: the bus engine (bus.h) driven by an event-driven fake port whose every event
 * comes from the fuzzer: time steps, polls, transmit-complete, replies (good, for another
 * id, truncated, corrupted), line noise, idle, line errors, timer calls, submits, estops,
 * echoes and start_tx failures, in any order and in any chunking.
 *
 * Input: byte 0 = configuration (bit 0 echo, bit 1 advance_in_isr, bit 2 tx done from inside
 * start_tx, bits 3-4 retries, bit 5 port has arm_timeout, bit 6 the callback submits the next
 * transaction, bit 7 the final drain delivers tx done); byte 1 = turnaround (low nibble) and
 * margin (high nibble), x10 us; byte 2 = baud choice (low 2 bits) and guard_us (high bits);
 * then operations (one byte each, plus the bytes the operation reads; a reply operation
 * with bit 4 set hands its frame to on_rx in one call).
 *
 * Every injected reply carries a unique serial number in its pos field, so that a credited
 * reply can be traced back to the moment it was put on the wire. Invariants:
 * - a transaction credited J288_OK carries a reply that was injected for its id, complete,
 *   after its attempt's transmit had completed, and that no other transaction was credited
 *   with; a broadcast never carries a reply;
 * - the callback runs exactly once per accepted submit, in submit order, with attempts in
 *   1..retries+1, every attempt but the last a failure; once estop() is accepted, a
 *   transaction submitted before it ends J288_ERR_ABORTED and the next frame sent is the
 *   broadcast lock;
 * - every frame sent is a valid 20-byte command for the current transaction (or the stop),
 *   never while a transmit is still running;
 * - liveness: after a poll the bus is idle, or the port has a timer armed in the future
 *   (when it has arm_timeout); and once events stop, the bus returns to idle with time alone;
 * - statistics: transactions = callbacks + in flight (at most one) = ok + failed + aborted +
 *   in flight, checked after every operation and in every callback; ok, failed and aborted
 *   match the callbacks' results exactly (a stop frame counts in estops only),
 *   attempts and port errors equal those the callbacks report plus the stop frames (and
 *   those of them that failed), timeouts and collisions those the callbacks report plus at
 *   most the stop frames';
 * - a stop frame that fails is sent again (whatever the retries) before anything else, at
 *   most J288_ESTOP_ATTEMPTS times, and a stop given up had exactly that many transmits;
 * - the same input with every byte handed to on_rx on its own (so that the parser never sees a
 *   whole frame at once and, with advance_in_isr, the bus takes each byte as it comes) gives
 *   the same callbacks (id, result, each attempt's result, reply, times) and the same bus and
 *   parser statistics: the whole-frame fast paths and the byte paths agree; the byte-by-byte
 *   run submits each valid command as a frame encoded beforehand (the scheduler's way in,
 *   sent from where it lies), so that way is compared with j288_bus_submit() too. With the bus
 *   advanced in the event calls this is not compared after an estop, or when bytes came
 *   while a deadline or guard end had passed unseen (no arm_timeout): the machine then
 *   changes state in the middle of a delivery for a reason other than its bytes (the first
 *   advance notices the time; a stop frame goes out inside the advance that ended the
 *   attempt before it), so bytes that came in one piece were all taken before the change
 *   while the same bytes one by one fall on both sides of it: two different timelines, both
 *   handled right.
 */
#include "fuzz_common.h"

#include "j288/bus.h"
#include "j288/frame.h"

#include "../../lib/src/bus_priv.h" /* j288_bus_accepts(), j288_bus_accept_frame() */

#include <string.h>

#define MAX_SERIALS 2048u
#define MAX_OPS 3000u
#define MAX_LOG 4096u

/* What a run leaves behind, compared between the chunked and the byte-by-byte runs. */
typedef struct {
    uint8_t id;
    uint8_t attempts;
    int result;
    int attempt_result[J288_CONFIG_MAX_RETRIES + 1u];
    int32_t reply_pos;
    uint32_t start_us;
    uint32_t latency_us;
} done_log_t;

typedef struct {
    done_log_t log[MAX_LOG];
    uint32_t nlog;
    j288_bus_stats_t bus;
    j288_parser_stats_t parser;
    bool incomparable; /* the comparison does not apply (see above) */
} outcome_t;

static bool bytewise;     /* hand on_rx one byte at a time */
static outcome_t *record; /* where the callbacks are logged */

typedef struct {
    /* port state */
    uint32_t now;
    bool tx_pending;
    uint32_t tx_start; /* now at the latest start_tx */
    bool tx_inline;
    int fail_next;
    uint8_t last_tx[J288_CMD_LEN];
    bool have_tx;
    bool timer_armed;
    uint32_t timer_at;
    uint64_t event_no;
    uint64_t tx_done_event; /* event number of the current attempt's tx done */
    uint64_t echo_done_event; /* event number when its echo was heard whole */
    /* expectations */
    uint8_t fifo_id[8];
    bool fifo_pre_estop[8];
    unsigned fifo_n;
    bool estop_expected;
    uint32_t accepted, callbacks, cb_ok, cb_aborted, cb_attempts, cb_timeouts, cb_collisions;
    uint32_t cb_port_errors;
    uint32_t estops;
    uint32_t stop_frames;      /* start_tx calls with the stop frame (failed ones included) */
    uint32_t stop_port_errors; /* of them, failed here */
    uint32_t series_seen;      /* stats.estops at the latest stop frame */
    uint32_t series_attempts;  /* stop frames of that stop so far */
    uint32_t chain_budget;
    bool chain;
    int serial_next;
    uint64_t serial_done_event[MAX_SERIALS]; /* event at which the frame was complete; 0: not */
    uint8_t serial_id[MAX_SERIALS];
    bool serial_credited[MAX_SERIALS];
    uint8_t retries;
    bool overdue_delivery; /* bytes came while the bus had a deadline or guard end unseen */
} world_t;

static world_t w;
static j288_bus_t bus;
static j288_port_t port;

static int port_start_tx(void *ctx, const uint8_t *data, size_t len)
{
    FUZZ_CHECK(ctx == &w);
    FUZZ_CHECK(len == J288_CMD_LEN);
    if (w.tx_pending) {
        /* Only after giving up on a transmit whose completion never came (TX_TIMEOUT):
         * a new frame never cuts into one the bus still waits for. */
        FUZZ_CHECK((uint32_t)(w.now - w.tx_start) >= j288_bus_reply_budget_us(&bus));
    }
    FUZZ_CHECK(fuzz_cmd_valid(data));
    static const uint8_t stop_body[13] = {0}; /* bytes 3-15 of the stop */
    bool is_stop = (data[2] == 0x0Fu) && (memcmp(&data[3], stop_body, sizeof stop_body) == 0);
    if (w.estop_expected) {
        /* The stop goes out before anything else: broadcast, lock, watchdog bit 0, all zero. */
        FUZZ_CHECK(is_stop);
        w.estop_expected = false;
    } else if (is_stop && w.estops > 0u) {
        /* a re-send of the stop, or a stop merged into one that was then given up */
    } else {
        FUZZ_CHECK(w.fifo_n > 0u);
        FUZZ_CHECK((data[2] & 0x0Fu) == w.fifo_id[0]);
    }
    if (is_stop) {
        const j288_bus_stats_t *st = j288_bus_stats(&bus);
        if (st->estops != w.series_seen) { /* counted when a stop starts */
            w.series_seen = st->estops;
            w.series_attempts = 0u;
        }
        w.series_attempts++;
        w.stop_frames++;
        FUZZ_CHECK(w.series_attempts <= J288_ESTOP_ATTEMPTS); /* bounded on a dead port */
    }
    if (w.fail_next > 0) {
        w.fail_next--;
        if (is_stop) {
            /* Whatever the retries: a failed stop frame is sent again, before anything else,
             * until it has had its J288_ESTOP_ATTEMPTS. */
            w.stop_port_errors++;
            w.estop_expected = w.series_attempts < J288_ESTOP_ATTEMPTS;
        }
        return J288_ERR_PORT;
    }
    w.tx_start = w.now;
    memcpy(w.last_tx, data, J288_CMD_LEN);
    w.have_tx = true;
    w.tx_pending = true;
    w.tx_done_event = UINT64_MAX;
    w.echo_done_event = UINT64_MAX;
    if (w.tx_inline) {
        w.tx_pending = false;
        w.tx_done_event = ++w.event_no;
        j288_bus_on_tx_done(&bus);
    }
    return 0;
}

static uint32_t port_now(void *ctx)
{
    FUZZ_CHECK(ctx == &w);
    return w.now;
}

static void port_arm(void *ctx, uint32_t t)
{
    FUZZ_CHECK(ctx == &w);
    w.timer_armed = true;
    w.timer_at = t;
}

static void on_done(void *user, const j288_txn_t *t);

/* bus.h: transactions == ok + failed + aborted + (1 if one is in flight or queued). The
 * submits accepted and not yet called back are w.fifo_n, minus the one being called back
 * (counted already) when checked from its callback. */
static void check_stats_add_up(unsigned calling_back)
{
    const j288_bus_stats_t *st = j288_bus_stats(&bus);
    unsigned pending = w.fifo_n - calling_back;
    FUZZ_CHECK(pending <= 1u);
    FUZZ_CHECK(st->transactions == st->ok + st->failed + st->aborted + pending);
}

static uint8_t frames[2][J288_CMD_LEN]; /* frames submitted ready-made (bytewise run) */

/* The scheduler's way in (sched.c): a frame encoded beforehand, taken under the bus's lock
 * when the bus accepts a transaction, sent from where it lies. */
static int submit_frame(j288_bus_t *b, const uint8_t *frame, uint8_t id, uint32_t now, void *user)
{
    int rc = J288_ERR_BUSY;
    j288_bus_lock(b);
    if (j288_bus_accepts(b)) {
        j288_bus_accept_frame(b, frame, id, now, on_done, user);
        rc = J288_OK;
    }
    j288_bus_unlock(b);
    return rc;
}

static void try_submit(uint8_t id, bool valid_fields)
{
    j288_cmd_raw_t c;
    int rc;
    memset(&c, 0, sizeof c);
    c.id = id;
    c.status = valid_fields ? 1u : 2u;
    c.watchdog = true;
    c.pos = 1234;
    c.kp = 10;
    /* Expected before the call: submit may transmit at once. */
    FUZZ_CHECK(w.fifo_n < 8u);
    w.fifo_id[w.fifo_n] = id;
    w.fifo_pre_estop[w.fifo_n] = false;
    w.fifo_n++;
    if (bytewise && valid_fields && (id <= 15u)) {
        /* The scheduler's way in, compared with j288_bus_submit() of the other run: a frame
         * encoded beforehand, sent from where it lies. Two buffers: the frame of the
         * transaction still under way (the bus's) is left alone when this one is refused. */
        uint8_t *f = (bus.tx_frame == frames[0]) ? frames[1] : frames[0];
        FUZZ_CHECK(j288_cmd_encode(&c, f, NULL) == J288_OK);
        rc = submit_frame(&bus, f, id, w.now, &w);
    } else {
        rc = j288_bus_submit(&bus, &c, w.now, on_done, &w);
    }
    FUZZ_CHECK(rc == J288_OK || rc == J288_ERR_BUSY || rc == J288_ERR_BAD_ID ||
               rc == J288_ERR_BAD_STATUS);
    if (id > 15u) {
        FUZZ_CHECK(rc == J288_ERR_BAD_ID || rc == J288_ERR_BUSY); /* never sent */
    }
    if (!valid_fields) {
        FUZZ_CHECK(rc != J288_OK);
    }
    if (rc == J288_OK) {
        w.accepted++;
    } else {
        w.fifo_n--; /* refused: nothing was sent for it (start_tx checks the id) */
    }
}

static bool is_bus_result(int r)
{
    return r == J288_OK || r == J288_ERR_TIMEOUT || r == J288_ERR_WRONG_ID || r == J288_ERR_CRC ||
           r == J288_ERR_TRUNCATED || r == J288_ERR_COLLISION || r == J288_ERR_LINE ||
           r == J288_ERR_PORT || r == J288_ERR_TX_TIMEOUT || r == J288_ERR_ABORTED ||
           r == J288_ERR_OFFLINE || r == J288_ERR_OVERFLOW;
}

static void log_done(const j288_txn_t *t)
{
    done_log_t *l;
    if (record->nlog >= MAX_LOG) {
        return;
    }
    l = &record->log[record->nlog++];
    memset(l, 0, sizeof *l);
    l->id = t->id;
    l->attempts = t->attempts;
    l->result = t->result;
    memcpy(l->attempt_result, t->attempt_result, sizeof l->attempt_result);
    l->reply_pos = t->reply.pos;
    l->start_us = t->start_us;
    l->latency_us = t->latency_us;
}

static void on_done(void *user, const j288_txn_t *t)
{
    unsigned k;
    log_done(t);
    FUZZ_CHECK(user == &w);
    FUZZ_CHECK(w.fifo_n > 0u); /* exactly once per accepted submit */
    FUZZ_CHECK(t->id == w.fifo_id[0]);
    FUZZ_CHECK(is_bus_result(t->result));
    FUZZ_CHECK(t->attempts <= (unsigned)w.retries + 1u);
    check_stats_add_up(1u);
    if (w.fifo_pre_estop[0]) {
        FUZZ_CHECK(t->result == J288_ERR_ABORTED);
    }
    for (k = 0; k + 1u < t->attempts; k++) {
        FUZZ_CHECK(t->attempt_result[k] != J288_OK);
        FUZZ_CHECK(is_bus_result(t->attempt_result[k]));
    }
    for (k = 0; k < t->attempts; k++) {
        if (t->attempt_result[k] == J288_ERR_TIMEOUT || t->attempt_result[k] == J288_ERR_TX_TIMEOUT) {
            w.cb_timeouts++;
        } else if (t->attempt_result[k] == J288_ERR_COLLISION) {
            w.cb_collisions++;
        } else if (t->attempt_result[k] == J288_ERR_PORT) {
            w.cb_port_errors++;
        }
    }
    if (t->result == J288_OK) {
        FUZZ_CHECK(t->attempts >= 1u);
        FUZZ_CHECK(t->attempt_result[t->attempts - 1u] == J288_OK);
        if (t->id != J288_BROADCAST_ID) {
            int32_t s = t->reply.pos;
            FUZZ_CHECK(s >= 0 && s < w.serial_next);
            FUZZ_CHECK(w.serial_done_event[s] != 0u);          /* complete on the wire */
            FUZZ_CHECK(w.serial_id[s] == t->id);               /* for this servo */
            FUZZ_CHECK(t->reply.id == t->id);
            /* after our transmit ended (tx done, or with echo on, its whole echo heard) */
            FUZZ_CHECK(w.serial_done_event[s] > w.tx_done_event ||
                       (bus.cfg.echo && w.serial_done_event[s] > w.echo_done_event));
            FUZZ_CHECK(!w.serial_credited[s]);                 /* to one transaction only */
            w.serial_credited[s] = true;
        }
        w.cb_ok++;
    } else if (t->result == J288_ERR_ABORTED) {
        w.cb_aborted++;
    }
    w.cb_attempts += t->attempts;
    w.callbacks++;
    memmove(&w.fifo_id[0], &w.fifo_id[1], w.fifo_n - 1u);
    memmove(&w.fifo_pre_estop[0], &w.fifo_pre_estop[1], (w.fifo_n - 1u) * sizeof(bool));
    w.fifo_n--;
    if (w.chain && w.chain_budget > 0u) {
        w.chain_budget--;
        try_submit((uint8_t)(w.chain_budget % 16u), true);
    }
}

static void check_after_poll(void)
{
    if (port.arm_timeout != NULL && !j288_bus_is_idle(&bus)) {
        FUZZ_CHECK(w.timer_armed);
        FUZZ_CHECK((int32_t)(w.timer_at - w.now) > 0); /* a wake-up still to come */
    }
}

static void do_poll(void)
{
    j288_bus_poll(&bus, w.now);
    check_after_poll();
}

static void advance_time(uint32_t dt)
{
    w.now += dt;
    if (port.arm_timeout != NULL && w.timer_armed && (int32_t)(w.now - w.timer_at) >= 0) {
        w.timer_armed = false;
        j288_bus_on_timer(&bus);
        if (bus.cfg.advance_in_isr) {
            check_after_poll();
        }
    }
}

static void deliver(const uint8_t *d, size_t n, uint8_t chunk)
{
    size_t off = 0;
    size_t step = bytewise ? 1u : ((chunk == 0u) ? n : chunk);
    if (bus.cfg.advance_in_isr && !j288_bus_is_idle(&bus) &&
        ((int32_t)(w.now - bus.timer_at) >= 0)) {
        w.overdue_delivery = true; /* see the comparison of the two runs, above */
    }
    while (off < n) {
        size_t k = (n - off < step) ? n - off : step;
        j288_bus_on_rx(&bus, &d[off], k);
        off += k;
    }
}

/* A valid reply frame from id, stamped with a fresh serial. */
static int make_reply(fuzz_in_t *in, uint8_t id, uint8_t out[J288_REPLY_LEN])
{
    j288_reply_raw_t r;
    int s = w.serial_next;
    if (s >= (int)MAX_SERIALS) {
        return -1;
    }
    memset(&r, 0, sizeof r);
    r.id = id;
    r.status = (uint8_t)(fuzz_u8(in) & 7u);
    r.watchdog_tripped = (fuzz_u8(in) & 1u) != 0u;
    r.pos = s;
    r.faults = fuzz_u32(in);
    if (j288_reply_encode(&r, out, NULL) != J288_OK) {
        return -1;
    }
    w.serial_next++;
    w.serial_id[s] = id;
    return s;
}

static uint8_t current_id(void)
{
    return (w.fifo_n > 0u) ? w.fifo_id[0] : 0u;
}

static void do_op(fuzz_in_t *in)
{
    uint8_t op = fuzz_u8(in);
    uint8_t f[J288_REPLY_LEN];
    int s;

    w.event_no++;
    switch (op & 15u) {
    case 0: advance_time(fuzz_u8(in)); break;
    case 1: advance_time(fuzz_u16(in)); break;
    case 2: do_poll(); break;
    case 3:
        if (w.tx_pending) {
            w.tx_pending = false;
            w.tx_done_event = w.event_no;
            j288_bus_on_tx_done(&bus);
        }
        break;
    case 4: /* the addressed servo answers */
    case 5: /* some servo answers */
        s = make_reply(in, ((op & 15u) == 4u) ? current_id() : (uint8_t)(fuzz_u8(in) % 15u), f);
        if (s >= 0) {
            uint8_t chunk = (uint8_t)(fuzz_u8(in) % 27u);
            if ((op & 0x10u) != 0u) {
                /* The whole frame in one on_rx call, as a DMA of exactly one reply hands it
                 * over (with advance_in_isr, the bus's fast path for an awaited reply). */
                w.serial_done_event[s] = w.event_no;
                deliver(f, sizeof f, 0u);
                break;
            }
            /* All but the last byte, then mark the frame complete, then its last byte (the
             * bus may take it from inside on_rx when it advances in the ISR). */
            deliver(f, sizeof f - 1u, chunk);
            w.serial_done_event[s] = w.event_no;
            deliver(&f[sizeof f - 1u], 1u, 0u);
        }
        break;
    case 6: /* a truncated reply */
        s = make_reply(in, current_id(), f);
        if (s >= 0) {
            deliver(f, 1u + fuzz_u8(in) % 25u, 0u);
            /* Later bytes may complete it by chance (e.g. a next frame's 0xFC equal to its
             * last CRC byte): then it is a genuine frame, put on the wire from now on. */
            w.serial_done_event[s] = w.event_no;
        }
        break;
    case 7: { /* a corrupted reply: the CRC no longer matches */
        uint8_t bit = fuzz_u8(in);
        s = make_reply(in, current_id(), f);
        if (s >= 0) {
            f[2u + (bit >> 3) % 24u] ^= (uint8_t)(1u << (bit & 7u));
            deliver(f, sizeof f, (uint8_t)(fuzz_u8(in) % 27u));
        }
        break;
    }
    case 8: { /* line noise */
        uint8_t noise[40];
        size_t n = fuzz_u8(in) % sizeof noise, i;
        for (i = 0; i < n; i++) {
            noise[i] = fuzz_u8(in);
        }
        deliver(noise, n, 0u);
        break;
    }
    case 9: j288_bus_on_rx_idle(&bus); break;
    case 10: j288_bus_on_error(&bus, fuzz_u8(in) & 0x1Fu); break; /* not GONE: see drain */
    case 11: {
        uint8_t b = fuzz_u8(in);
        try_submit((uint8_t)(b % 17u), (b & 0x80u) == 0u);
        break;
    }
    case 12: {
        unsigned k;
        /* Expected before the call: the stop may go out from inside estop(). */
        for (k = 0; k < w.fifo_n; k++) {
            w.fifo_pre_estop[k] = true;
        }
        w.estops++;
        /* A stop already on the wire absorbs the request (bus.c, by design), even if that
         * stop then fails: only then is no new stop frame due. */
        if ((bus.flags & J288_BUSF_ESTOP_ACTIVE) == 0u) {
            w.estop_expected = true;
        }
        FUZZ_CHECK(j288_bus_estop(&bus, w.now) == J288_OK);
        break;
    }
    case 13: j288_bus_on_timer(&bus); break; /* early or spurious: the bus checks the time */
    case 14: /* the echo of our last frame, possibly corrupted */
        if (w.have_tx) {
            uint8_t e[J288_CMD_LEN];
            uint8_t bit = fuzz_u8(in);
            memcpy(e, w.last_tx, sizeof e);
            if ((bit & 0x80u) != 0u) {
                e[(bit >> 2) % J288_CMD_LEN] ^= (uint8_t)(1u << (bit & 3u));
            }
            deliver(e, sizeof e, (uint8_t)(fuzz_u8(in) % 21u));
            if (memcmp(e, w.last_tx, sizeof e) == 0 && w.echo_done_event == UINT64_MAX) {
                w.echo_done_event = w.event_no; /* the first whole echo of this attempt */
                w.tx_pending = false; /* heard whole: the transmit is over (done not sent) */
            }
        }
        break;
    default: w.fail_next = 1; break;
    }
    if (bus.cfg.advance_in_isr && (op & 15u) != 0u && (op & 15u) != 1u) {
        check_after_poll();
    }
}

static void run(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static outcome_t chunked, bytes;
    if (size < 3u) {
        return 0;
    }
    bytewise = false;
    memset(&chunked, 0, sizeof chunked);
    record = &chunked;
    run(data, size);
    bytewise = true;
    memset(&bytes, 0, sizeof bytes);
    record = &bytes;
    run(data, size);
    if (chunked.incomparable) {
        return 0;
    }
    FUZZ_CHECK(chunked.nlog == bytes.nlog);
    FUZZ_CHECK(memcmp(chunked.log, bytes.log, chunked.nlog * sizeof chunked.log[0]) == 0);
    FUZZ_CHECK(memcmp(&chunked.bus, &bytes.bus, sizeof chunked.bus) == 0);
    FUZZ_CHECK(memcmp(&chunked.parser, &bytes.parser, sizeof chunked.parser) == 0);
    return 0;
}

/* One run of the input with every invariant checked; its outcome goes to *record. */
static void run(const uint8_t *data, size_t size)
{
    static const uint32_t bauds[4] = {0u, 115200u, 1000000u, 9600u};
    j288_bus_config_t cfg;
    fuzz_in_t in;
    uint8_t c0, c1, c2;
    unsigned ops = 0, k;
    const j288_bus_stats_t *st;
    bool drain_tx;

    memset(&w, 0, sizeof w);
    c0 = data[0];
    c1 = data[1];
    c2 = data[2];
    in.p = &data[3];
    in.n = size - 3u;

    port = (j288_port_t){
        .start_tx = port_start_tx,
        .now_us = port_now,
        .arm_timeout = ((c0 & 0x20u) != 0u) ? port_arm : NULL,
    };
    memset(&cfg, 0, sizeof cfg);
    cfg.echo = (c0 & 1u) != 0u;
    cfg.advance_in_isr = (c0 & 2u) != 0u;
    w.tx_inline = (c0 & 4u) != 0u;
    cfg.retries = (uint8_t)((c0 >> 3) & 3u);
    w.retries = cfg.retries;
    w.chain = (c0 & 0x40u) != 0u;
    w.chain_budget = 50u;
    drain_tx = (c0 & 0x80u) != 0u;
    cfg.turnaround_us = 10u * (c1 & 15u);
    cfg.margin_us = 10u * (c1 >> 4);
    cfg.baud = bauds[c2 & 3u];
    cfg.guard_us = c2 >> 2;
    w.now = 0xFFFFF000u; /* wraps during the run */
    FUZZ_CHECK(j288_bus_init(&bus, &port, &w, &cfg) == J288_OK);
    FUZZ_CHECK(j288_bus_is_idle(&bus));
    w.serial_next = 0;

    while (in.n > 0u && ops < MAX_OPS) {
        do_op(&in);
        check_stats_add_up(0u);
        ops++;
    }

    /* Drain: no more bytes; time alone (and, if chosen, the transmit completions) must bring
     * the bus back to idle with every transaction called back. */
    w.chain = false;
    for (k = 0; k < 64u && (!j288_bus_is_idle(&bus) || w.fifo_n > 0u || w.estop_expected); k++) {
        if (drain_tx && w.tx_pending) {
            w.tx_pending = false;
            w.tx_done_event = ++w.event_no;
            j288_bus_on_tx_done(&bus);
        }
        advance_time(j288_bus_reply_budget_us(&bus) + bus.cfg.guard_us + 1u);
        do_poll();
    }
    FUZZ_CHECK(j288_bus_is_idle(&bus));
    FUZZ_CHECK(w.fifo_n == 0u);
    FUZZ_CHECK(!w.estop_expected); /* a requested stop was put on the wire */

    st = j288_bus_stats(&bus);
    FUZZ_CHECK(st->transactions == w.accepted);
    FUZZ_CHECK(st->transactions == w.callbacks + w.fifo_n);
    /* Stop frames count in estops only: ok is exactly the callbacks' successes. */
    FUZZ_CHECK(st->ok == w.cb_ok);
    FUZZ_CHECK(st->aborted == w.cb_aborted);
    FUZZ_CHECK(st->failed == w.callbacks - w.cb_ok - w.cb_aborted);
    check_stats_add_up(0u);
    FUZZ_CHECK(st->estops <= w.estops);
    /* Every frame handed to start_tx is an attempt of a called-back transaction or a stop
     * frame; the stops' own failures are the only attempt results without a callback. */
    FUZZ_CHECK(st->attempts == w.cb_attempts + w.stop_frames);
    FUZZ_CHECK(st->port_errors == w.cb_port_errors + w.stop_port_errors);
    FUZZ_CHECK(st->timeouts >= w.cb_timeouts && st->collisions >= w.cb_collisions);
    FUZZ_CHECK((st->timeouts - w.cb_timeouts) + (st->collisions - w.cb_collisions) +
                   w.stop_port_errors <= w.stop_frames);
    if (w.estops == 0u) {
        FUZZ_CHECK(w.stop_frames == 0u && st->estops == 0u);
    }
    /* A stop gets out within J288_ESTOP_ATTEMPTS transmits or is given up after exactly that
     * many (the fuzzer never reports J288_LINE_GONE, which would end it sooner). */
    FUZZ_CHECK(st->estop_failures <= st->estops);
    FUZZ_CHECK(w.stop_frames <= st->estops * J288_ESTOP_ATTEMPTS);
    FUZZ_CHECK(w.stop_frames >= st->estops + st->estop_failures * (J288_ESTOP_ATTEMPTS - 1u));
    record->bus = *st;
    record->parser = *j288_bus_parser_stats(&bus);
    record->incomparable = cfg.advance_in_isr && ((w.estops != 0u) || w.overdue_delivery);
}
