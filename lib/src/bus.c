/* The half-duplex bus engine; see j288/bus.h for the contract and the state diagram. */
#include "j288/bus.h"

#include <string.h>

#include "bus_priv.h"
#include "frame_priv.h"
#include "parser_priv.h"

#define RING_MASK  (J288_CONFIG_RX_RING_SIZE - 1u)
#define MAX_CFG_US 60000000u /* longest turnaround, margin or guard: 1 minute */
#define MAX_STEPS  16u /* transitions per advance call; more is a bug, not a hang (no event
                          sequence takes more than a few: a re-send always waits a guard) */

/* Failure ranking at the deadline: the most specific observation names the result. A whole
 * frame that failed its CRC says more than a partial one given up at the deadline. */
static unsigned fail_rank(int err)
{
    switch (err) {
    case J288_ERR_WRONG_ID:
        return 4u;
    case J288_ERR_LINE:
        return 3u;
    case J288_ERR_CRC:
        return 2u;
    case J288_ERR_TRUNCATED:
        return 1u;
    default:
        return 0u;
    }
}

/* Wrap-safe "now is at or after t", for intervals below 2^31 us. */
static bool time_reached(uint32_t now, uint32_t t)
{
    return (uint32_t)(now - t) < 0x80000000u;
}

/* TX, ECHO or WAIT_REPLY: an attempt is on the wire (the states are numbered in that order). */
static bool is_active(uint8_t state)
{
    return (state >= (uint8_t)J288_BUS_TX) && (state <= (uint8_t)J288_BUS_WAIT_REPLY);
}

/* The flags (J288_BUSF_*, bus_priv.h): one byte, so that "anything pending?" is one test. */
static bool has_flag(const j288_bus_t *bus, uint8_t f)
{
    return (bus->flags & f) != 0u;
}

static void set_flag(j288_bus_t *bus, uint8_t f)
{
    bus->flags = (uint8_t)(bus->flags | f);
}

static void clear_flags(j288_bus_t *bus, uint8_t f)
{
    bus->flags = (uint8_t)(bus->flags & (uint8_t)~f);
}

static void arm_at(j288_bus_t *bus, uint32_t t)
{
    bus->timer_at = t;
    if (bus->port->arm_timeout != NULL) {
        bus->port->arm_timeout(bus->port_ctx, t);
    }
}

static void note_fail(j288_bus_t *bus, int err)
{
    if (fail_rank(err) > fail_rank(bus->attempt_fail)) {
        bus->attempt_fail = err;
    }
}

/* n / d and n % d for n below 2^24, by shift and subtract. */
static uint32_t div_small(uint32_t n, uint32_t d, uint32_t *rem)
{
    uint32_t q = 0u;
    uint32_t r = 0u;
    int bit;
    for (bit = 23; bit >= 0; bit--) {
        r = (r << 1) | ((n >> (unsigned)bit) & 1u); /* r < 2^24: no overflow */
        q <<= 1;
        if (r >= d) {
            r -= d;
            q |= 1u;
        }
    }
    *rem = r;
    return q;
}

/* r + add modulo d for r, add < d (any d): returns 1 when it wrapped past d. */
static uint32_t add_mod(uint32_t *r, uint32_t add, uint32_t d)
{
    uint32_t room = d - *r;
    if (add >= room) {
        *r = add - room;
        return 1u;
    }
    *r += add;
    return 0u;
}

/* ceil(nbytes * 10^7 / baud) modulo 2^32, 10^7 being 10 bits per byte in microseconds, with
 * neither a division instruction nor libgcc's 64-bit division (~750 bytes on a Cortex-M): the
 * product is built one bit of nbytes at a time as q * baud + r, r < baud. Init-time only. */
uint32_t j288_wire_time_us(uint32_t baud, uint32_t nbytes)
{
    const uint32_t b = (baud == 0u) ? J288_DEFAULT_BAUD : baud;
    uint32_t unit_r;
    const uint32_t unit_q = div_small(10000000u, b, &unit_r); /* 10^7 = unit_q * b + unit_r */
    uint32_t q = 0u;
    uint32_t r = 0u;
    int bit;
    for (bit = 31; bit >= 0; bit--) {
        q = (q << 1) + add_mod(&r, r, b);
        if (((nbytes >> (unsigned)bit) & 1u) != 0u) {
            q += unit_q + add_mod(&r, unit_r, b);
        }
    }
    return q + ((r != 0u) ? 1u : 0u);
}

uint32_t j288_bus_reply_budget_us(const j288_bus_t *bus)
{
    return (bus == NULL) ? 0u : bus->reply_budget_us;
}

const j288_bus_config_t *j288_bus_config(const j288_bus_t *bus)
{
    return (bus == NULL) ? NULL : &bus->cfg;
}

static int check_config(const j288_bus_config_t *c)
{
    if (c->retries > J288_CONFIG_MAX_RETRIES) {
        return J288_ERR_BAD_CONFIG;
    }
    if ((c->baud != 0u) && (c->baud < 9600u)) {
        return J288_ERR_BAD_CONFIG;
    }
    if ((c->turnaround_us > MAX_CFG_US) || (c->margin_us > MAX_CFG_US) ||
        (c->guard_us > MAX_CFG_US)) {
        return J288_ERR_BAD_CONFIG;
    }
    return J288_OK;
}

static void apply_defaults(j288_bus_config_t *c)
{
    if (c->baud == 0u) {
        c->baud = J288_DEFAULT_BAUD;
    }
    if (c->turnaround_us == 0u) {
        c->turnaround_us = J288_DEFAULT_TURNAROUND_US;
    }
    if (c->margin_us == 0u) {
        c->margin_us = J288_DEFAULT_MARGIN_US;
    }
    if (c->guard_us == 0u) {
        c->guard_us = J288_DEFAULT_GUARD_US;
    }
}

int (j288_bus_init)(j288_bus_t *bus, const j288_port_t *port, void *port_ctx,
                    const j288_bus_config_t *cfg)
{
    j288_bus_config_t c;
    int err;

    if ((bus == NULL) || (port == NULL)) {
        return J288_ERR_NULL;
    }
    if ((port->start_tx == NULL) || (port->now_us == NULL) ||
        ((port->lock == NULL) != (port->unlock == NULL))) {
        return J288_ERR_PORT_OPS;
    }
    if (cfg != NULL) {
        c = *cfg;
    } else {
        (void)memset(&c, 0, sizeof c);
    }
    err = check_config(&c);
    if (err != J288_OK) {
        return err;
    }
    apply_defaults(&c);

    (void)memset(bus, 0, sizeof *bus);
    bus->port = port;
    bus->port_ctx = port_ctx;
    bus->crc.fn = port->crc32;
    bus->crc.ctx = port_ctx;
    bus->cfg = c;
    bus->reply_budget_us =
        j288_wire_time_us(c.baud, J288_CMD_LEN + J288_REPLY_LEN) + c.turnaround_us + c.margin_us;
    bus->state = (uint8_t)J288_BUS_IDLE;
    bus->attempt_fail = J288_OK;
    return j288_parser_init(&bus->parser, J288_PARSE_REPLY, &bus->crc);
}

/* ---- receive ring: on_rx is the only producer, the advancing context the only consumer */

J288_NOINLINE static void ring_put(j288_bus_t *bus, const uint8_t *data, size_t len)
{
    uint32_t head = bus->ring_head;
    uint32_t room = J288_CONFIG_RX_RING_SIZE - (uint32_t)(head - bus->ring_tail);
    size_t n = (len < room) ? len : room;
    uint32_t masked = head & RING_MASK;
    size_t off = masked;
    size_t first = J288_CONFIG_RX_RING_SIZE - off; /* bytes before the end of the array */

    if (n <= first) {
        (void)memcpy(&bus->ring[off], data, n);
    } else {
        (void)memcpy(&bus->ring[off], data, first);
        (void)memcpy(bus->ring, &data[first], n - first);
    }
    if (n < len) {
        bus->stats.rx_overflows += (uint32_t)(len - n);
    }
    bus->ring_head = head + (uint32_t)n; /* publish after the bytes are in place */
    bus->ev_any++;
}

/* ---- attempts and completion */

static void enter_guard(j288_bus_t *bus, uint32_t end)
{
    bus->state = (uint8_t)J288_BUS_GUARD;
    bus->guard_end = end;
    arm_at(bus, end);
    if (has_flag(bus, J288_BUSF_ESTOP_PENDING)) {
        bus->again = true; /* the stop goes out at once, not after the guard */
    }
}

/* The end of the guard after a failure: one reply budget after the later of now and the
 * deadline of the transaction's last attempt, so that a late reply to an attempt that ended
 * early (collision, port or line error) dies out before anything else is sent. A transaction
 * that never had an attempt (a queued submit aborted) counts from now. */
static uint32_t guard_after_failure(const j288_bus_t *bus, uint32_t now)
{
    uint32_t from = now;
    if ((bus->txn[bus->cur].attempts != 0u) && !time_reached(now, bus->deadline)) {
        from = bus->deadline;
    }
    return from + bus->reply_budget_us;
}

static void finish(j288_bus_t *bus, int result, uint32_t now)
{
    j288_txn_t *t = &bus->txn[bus->cur];
    j288_bus_done_fn done = bus->done;
    void *user = bus->done_user;
    uint8_t flags = bus->flags;
    bool was_estop = (flags & J288_BUSF_ESTOP_ACTIVE) != 0u;

    if (!was_estop && ((flags & J288_BUSF_ESTOP_PENDING) != 0u)) {
        result = J288_ERR_ABORTED;
    }
    if (was_estop && (result != J288_OK)) {
        bus->stats.estop_failures++;
        /* a request merged into it: a stop of its own */
        flags = (uint8_t)(flags & (uint8_t)~J288_BUSF_ESTOP_PENDING);
        if ((flags & J288_BUSF_ESTOP_REARM) != 0u) {
            flags |= J288_BUSF_ESTOP_PENDING;
        }
    }
    bus->flags = (uint8_t)(flags & (uint8_t)~(J288_BUSF_QUEUED | J288_BUSF_RETRY |
                                              J288_BUSF_ESTOP_ACTIVE | J288_BUSF_ESTOP_REARM));
    t->result = result;
    if (t->attempts != 0u) {
        t->latency_us = (uint32_t)(now - t->start_us);
    } else {
        t->start_us = 0u; /* never sent */
        t->latency_us = 0u;
    }
    if ((result != J288_OK) || (t->id == J288_BROADCAST_ID)) {
        (void)memset(&t->reply, 0, sizeof t->reply); /* no reply was taken */
    }
    if (!was_estop) { /* the stop is counted in estops only: it is not a user transaction */
        if (result == J288_OK) {
            bus->stats.ok++;
        } else if (result == J288_ERR_ABORTED) {
            bus->stats.aborted++;
        } else {
            bus->stats.failed++;
        }
    }
    bus->done = NULL;
    enter_guard(bus, (result == J288_OK) ? (now + bus->cfg.guard_us)
                                         : guard_after_failure(bus, now));
    if (!was_estop && (done != NULL)) {
        done(user, t);
    }
}

static void count_result(j288_bus_t *bus, int result)
{
    switch (result) {
    case J288_ERR_TIMEOUT:
    case J288_ERR_TX_TIMEOUT:
        bus->stats.timeouts++;
        break;
    case J288_ERR_COLLISION:
        bus->stats.collisions++;
        break;
    default:
        break;
    }
}

/* Success and a vanished line end any transaction. A stop frame is sent again whatever
 * config.retries says (the lock must reach the servos), up to J288_ESTOP_ATTEMPTS; a user
 * transaction retries unless a stop waits. */
static bool attempt_is_final(const j288_bus_t *bus, int result, uint8_t attempts)
{
    if ((result == J288_OK) || (result == J288_ERR_OFFLINE)) {
        return true;
    }
    if (has_flag(bus, J288_BUSF_ESTOP_ACTIVE)) {
        return attempts >= J288_ESTOP_ATTEMPTS;
    }
    return has_flag(bus, J288_BUSF_ESTOP_PENDING) || (attempts > bus->cfg.retries);
}

/* An attempt ended: keep its reason, then retry after a guard or finish. */
static void end_attempt(j288_bus_t *bus, int result, uint32_t now)
{
    j288_txn_t *t = &bus->txn[bus->cur];
    bool final = attempt_is_final(bus, result, t->attempts);

    t->attempt_result[t->attempts - 1u] = result; /* only attempts end: attempts >= 1 */
    count_result(bus, result);
    if (final) {
        finish(bus, result, now);
        return;
    }
    set_flag(bus, J288_BUSF_RETRY);
    enter_guard(bus, guard_after_failure(bus, now));
}

/* An attempt ended with its reply taken: end_attempt(J288_OK) and finish() as they go when
 * no stop is pending or active (the common case, straight through): the transaction is done,
 * the guard begins, the callback runs. Nothing is queued or waiting to retry while an attempt
 * is on the wire, and its attempt_result[] entry is J288_OK since begin_txn(). */
static J288_INLINE_HOT void end_with_reply(j288_bus_t *bus, uint32_t now)
{
    j288_txn_t *t = &bus->txn[bus->cur];
    j288_bus_done_fn done = bus->done;

    if (bus->flags != 0u) {
        end_attempt(bus, J288_OK, now);
        return;
    }
    t->result = J288_OK;
    t->latency_us = (uint32_t)(now - t->start_us);
    bus->stats.ok++;
    bus->done = NULL;
    bus->state = (uint8_t)J288_BUS_GUARD;
    bus->guard_end = now + bus->cfg.guard_us;
    arm_at(bus, bus->guard_end);
    if (done != NULL) {
        done(bus->done_user, t);
    }
}

static J288_INLINE_HOT void start_attempt(j288_bus_t *bus, uint32_t now)
{
    j288_txn_t *t = &bus->txn[bus->cur];
    uint32_t any = bus->ev_any; /* read first: what is recorded after it counts as new */
    int rc;

    /* Whatever arrived before this transmit belongs to nobody. */
    bus->stats.stale_bytes += (uint32_t)(bus->ring_head - bus->ring_tail);
    bus->ring_tail = bus->ring_head;
    j288_parser_drop(&bus->parser);
    bus->seen_tx_done = bus->ev_tx_done;
    bus->seen_line = bus->ev_line;
    bus->seen_gone = bus->ev_gone;
    bus->seen_any = any;
    bus->echo_pos = 0u;
    bus->tx_complete = false;
    bus->collided = false;
    bus->attempt_fail = J288_OK;

    t->attempts++;
    t->start_us = now;
    bus->stats.attempts++;
    bus->deadline = now + bus->reply_budget_us;
    /* State first: the port may report tx done from inside start_tx. */
    bus->state = (uint8_t)J288_BUS_TX;
    arm_at(bus, bus->deadline);
    if (bus->port->set_dir != NULL) {
        bus->port->set_dir(bus->port_ctx, J288_DIR_TX);
    }
    if (bus->cfg.echo && (bus->port->start_rx != NULL)) {
        bus->port->start_rx(bus->port_ctx); /* the echo must be heard */
    }
    rc = bus->port->start_tx(bus->port_ctx, bus->tx_frame, J288_CMD_LEN);
    if (rc < 0) {
        bus->stats.port_errors++;
        end_attempt(bus, J288_ERR_PORT, now);
    } else {
        /* Events reported from inside start_tx are taken in this same advance. */
        bus->again = bus->again || (bus->ev_any != any);
    }
}

/* The same out of line, for the paths that are not hot (a retry, the stop frame, a submit to
 * an idle bus); the guard's end in the event calls has it inlined. */
static void start_attempt_called(j288_bus_t *bus, uint32_t now)
{
    start_attempt(bus, now);
}

J288_NOINLINE static void send_estop(j288_bus_t *bus, uint32_t now)
{
    j288_cmd_raw_t stop;

    /* Watchdog bit 0: a locked servo needs no watchdog, and the bit 0 clears a trip, so a
     * stopped bus takes the next session's commands (the manual: a trip is cleared only by a
     * command with the bit 0). */
    j288_cmd_lock(&stop, J288_BROADCAST_ID, false);
    (void)j288_cmd_encode(&stop, bus->tx_buf, &bus->crc); /* constant, valid fields */
    bus->tx_frame = bus->tx_buf;
    bus->flags = (uint8_t)((bus->flags & (uint8_t)~J288_BUSF_ESTOP_PENDING) |
                           J288_BUSF_ESTOP_ACTIVE);
    j288_bus_begin_txn(bus, J288_BROADCAST_ID, NULL, NULL);
    bus->stats.estops++; /* not in transactions: the stop is not a user transaction */
    start_attempt_called(bus, now);
}

/* ---- byte consumption */

static void take_frame(j288_bus_t *bus, const uint8_t *frame, uint32_t now)
{
    uint8_t id = (uint8_t)(frame[2] & 0x0Fu);

    if (id != bus->tx_id) {
        bus->stats.wrong_id++;
        note_fail(bus, J288_ERR_WRONG_ID);
        return;
    }
    j288_reply_unpack(frame, &bus->txn[bus->cur].reply);
    end_with_reply(bus, now);
}

/* Reply window: through the parser, which checks a whole frame where it lies. Returns bytes
 * consumed (stops after a frame). */
static uint32_t take_reply_bytes(j288_bus_t *bus, const uint8_t *p, uint32_t n, uint32_t now)
{
    uint32_t crc_before = j288_parser_stats(&bus->parser)->crc_errors;
    const uint8_t *frame = NULL;
    size_t used = 0u;
    int rc = j288_parser_scan(&bus->parser, p, n, &used, &frame);
    uint32_t crc_new = j288_parser_stats(&bus->parser)->crc_errors - crc_before;

    if (crc_new != 0u) {
        bus->stats.crc_errors += crc_new;
        note_fail(bus, J288_ERR_CRC);
    }
    if (rc == J288_PARSE_FRAME) {
        take_frame(bus, frame, now);
    }
    return (uint32_t)used;
}

/* Echo window: compare with what we sent, up to the first byte that differs (what follows
 * it is stale, however the bytes were chunked). */
static uint32_t take_echo_bytes(j288_bus_t *bus, const uint8_t *p, uint32_t n)
{
    uint32_t want = J288_CMD_LEN - (uint32_t)bus->echo_pos;
    uint32_t k = (n < want) ? n : want;
    uint32_t i = 0u;

    while (i < k) {
        i++;
        if (p[i - 1u] != bus->tx_frame[bus->echo_pos + i - 1u]) {
            bus->collided = true;
            break;
        }
    }
    bus->echo_pos = (uint8_t)(bus->echo_pos + i);
    return i;
}

/* Bytes at ring index pos: stale, echo or reply, by state. Returns bytes consumed. */
static uint32_t take_bytes(j288_bus_t *bus, uint32_t pos, const uint8_t *p, uint32_t n,
                           uint32_t now)
{
    if (!is_active(bus->state) || bus->collided) {
        bus->stats.stale_bytes += n;
        return n;
    }
    if (bus->cfg.echo) {
        if (bus->echo_pos < J288_CMD_LEN) {
            return take_echo_bytes(bus, p, n);
        }
    } else if (!bus->tx_complete) {
        bus->stats.stale_bytes += n; /* heard before our transmit ended: not a reply */
        return n;
    } else {
        uint32_t before = bus->txdone_mark - pos; /* bytes received before tx done */
        if ((before != 0u) && (before <= J288_CONFIG_RX_RING_SIZE)) {
            uint32_t k = (n < before) ? n : before;
            bus->stats.stale_bytes += k;
            return k;
        }
    }
    if (bus->tx_id == J288_BROADCAST_ID) {
        bus->stats.stale_bytes += n; /* nobody answers a broadcast */
        return n;
    }
    return take_reply_bytes(bus, p, n, now);
}

/* Everything received so far, in order: bytes handed to on_rx for consumption in place (they
 * come first: the ring was empty then, and later bytes go to the ring behind them), then the
 * ring from the tail to the head. */
J288_NOINLINE static void consume_pending(j288_bus_t *bus, uint32_t now)
{
    uint32_t tail;

    while (bus->direct_len != 0u) {
        uint32_t used = take_bytes(bus, bus->direct_pos, bus->direct, bus->direct_len, now);
        bus->direct = &bus->direct[used];
        bus->direct_pos += used;
        bus->direct_len -= used;
    }
    tail = bus->ring_tail;
    while (tail != bus->ring_head) {
        uint32_t off = tail & RING_MASK;
        uint32_t n = bus->ring_head - tail;
        if (n > J288_CONFIG_RX_RING_SIZE - off) {
            n = J288_CONFIG_RX_RING_SIZE - off;
        }
        tail += take_bytes(bus, tail, &bus->ring[off], n, now);
        bus->ring_tail = tail;
    }
}

static void consume_all(j288_bus_t *bus, uint32_t now)
{
    if ((bus->direct_len != 0u) || (bus->ring_tail != bus->ring_head)) {
        consume_pending(bus, now);
    }
}

static void flush_partial(j288_bus_t *bus)
{
    if (j288_parser_flush(&bus->parser) == J288_ERR_TRUNCATED) {
        bus->stats.crc_errors++;
        note_fail(bus, J288_ERR_TRUNCATED);
    }
}

/* Take what the event calls recorded, in the order it happened. Called in an active state
 * only (events recorded while quiet are dropped by the next start_attempt). */
static void take_events(j288_bus_t *bus, uint32_t now)
{
    uint32_t n;

    if (bus->ev_tx_done != bus->seen_tx_done) {
        bus->seen_tx_done = bus->ev_tx_done;
        bus->tx_complete = true;
    }
    n = bus->ev_line;
    if (n != bus->seen_line) {
        bus->seen_line = n;
        note_fail(bus, J288_ERR_LINE);
    }
    consume_all(bus, now);
}

/* After the transmit (and its echo): collision, broadcast done, or wait for the reply. */
static void after_transmit(j288_bus_t *bus, uint32_t now)
{
    if (bus->collided) {
        end_attempt(bus, J288_ERR_COLLISION, now);
    } else if (bus->cfg.echo && (bus->echo_pos < J288_CMD_LEN)) {
        bus->state = (uint8_t)J288_BUS_ECHO;
    } else if (bus->tx_id == J288_BROADCAST_ID) {
        end_attempt(bus, (bus->attempt_fail == J288_ERR_LINE) ? J288_ERR_LINE : J288_OK, now);
    } else {
        bus->state = (uint8_t)J288_BUS_WAIT_REPLY; /* bytes so far were taken already */
    }
}

J288_NOINLINE static void on_deadline(j288_bus_t *bus, uint32_t now)
{
    if (!bus->tx_complete) {
        end_attempt(bus, J288_ERR_TX_TIMEOUT, now);
    } else if (bus->state == J288_BUS_ECHO) {
        end_attempt(bus, J288_ERR_COLLISION, now); /* our own frame never came back whole */
    } else {
        flush_partial(bus); /* a frame still incomplete at the deadline: TRUNCATED */
        end_attempt(bus, (bus->attempt_fail != J288_OK) ? bus->attempt_fail : J288_ERR_TIMEOUT,
                    now);
    }
}

static void step_active(j288_bus_t *bus, uint32_t now)
{
    uint32_t any = bus->ev_any; /* read first: this step takes every event recorded so far */

    if (bus->ev_gone != bus->seen_gone) {
        bus->seen_gone = bus->ev_gone;
        end_attempt(bus, J288_ERR_OFFLINE, now);
        consume_all(bus, now); /* stale now */
        return;
    }
    take_events(bus, now);
    bus->seen_any = any;
    if (!is_active(bus->state)) {
        return; /* a reply ended the attempt */
    }
    if (bus->tx_complete && (bus->state != J288_BUS_WAIT_REPLY)) {
        after_transmit(bus, now);
        if (!is_active(bus->state)) {
            return;
        }
    }
    if (time_reached(now, bus->deadline)) {
        on_deadline(bus, now);
    }
}

static void step_quiet(j288_bus_t *bus, uint32_t now)
{
    consume_all(bus, now); /* late replies and noise: stale */
    if (has_flag(bus, J288_BUSF_RETRY) && (bus->ev_gone != bus->seen_gone)) {
        bus->seen_gone = bus->ev_gone;
        finish(bus, J288_ERR_OFFLINE, now); /* the line went away between two attempts */
        return;
    }
    if (has_flag(bus, J288_BUSF_ESTOP_PENDING)) {
        if (has_flag(bus, J288_BUSF_QUEUED | J288_BUSF_RETRY)) {
            finish(bus, J288_ERR_ABORTED, now); /* calls back; the stop goes next time round */
            return;
        }
        send_estop(bus, now);
        return;
    }
    if ((bus->state == J288_BUS_IDLE) || time_reached(now, bus->guard_end)) {
        if (has_flag(bus, J288_BUSF_QUEUED | J288_BUSF_RETRY)) {
            clear_flags(bus, J288_BUSF_QUEUED | J288_BUSF_RETRY);
            start_attempt_called(bus, now);
        } else {
            bus->state = (uint8_t)J288_BUS_IDLE;
        }
    }
}

static void advance(j288_bus_t *bus, uint32_t now)
{
    unsigned steps = 0u;

    if (bus->in_advance) {
        return; /* an event reported from inside a port call: the outer loop takes it */
    }
    bus->in_advance = true;
    do {
        bus->again = false;
        if (is_active(bus->state)) {
            step_active(bus, now);
        } else {
            step_quiet(bus, now);
        }
        steps++;
    } while (bus->again && (steps < MAX_STEPS)); /* GCOVR_EXCL_BR_LINE: limit = bug backstop */
    bus->in_advance = false;
}

static void advance_from_event(j288_bus_t *bus)
{
    if (bus->cfg.advance_in_isr) {
        advance(bus, bus->port->now_us(bus->port_ctx));
    }
}

/* ---- the event calls' fast paths (advance_in_isr): the one transition a common event makes,
 * taken directly when nothing else is pending, so that the machine's general pass (every
 * event counter, the ring, the parser's hunt) is skipped. Each does exactly what advance()
 * would do for that event and falls back to it in every other case. */

/* Exactly n events were recorded since the machine last had taken every one (seen_any: a
 * transmit's start, a pass of step_active(), the tx-done fast path), so that with n = 1 in an
 * event call the event being handled is the only new one: no other event counter moved, no
 * byte was put in the ring. (Outside an advance no byte waits in place either.) */
static bool events_since_seen(const j288_bus_t *bus, uint32_t n)
{
    return (uint32_t)(bus->ev_any - bus->seen_any) == n;
}

/* Transmit complete, no echo expected, the deadline not passed: wait for the reply. */
static bool tx_done_fast(j288_bus_t *bus)
{
    uint32_t now;

    if ((bus->state != (uint8_t)J288_BUS_TX) || bus->cfg.echo ||
        (bus->tx_id == J288_BROADCAST_ID) || !events_since_seen(bus, 1u)) {
        return false;
    }
    now = bus->port->now_us(bus->port_ctx);
    if (time_reached(now, bus->deadline)) {
        advance(bus, now);
        return true;
    }
    bus->seen_tx_done = bus->ev_tx_done;
    bus->seen_any = bus->ev_any;
    bus->tx_complete = true;
    bus->state = (uint8_t)J288_BUS_WAIT_REPLY;
    return true;
}

/* Exactly one reply from the addressed servo, in one piece, while it is awaited: taken as
 * take_bytes() takes it (the parser's whole-frame case, then take_frame()), inside the
 * machine (in_advance: a submit from the completion only queues). Called from on_rx outside
 * an advance with the ring empty (so no bytes wait in place either). In WAIT_REPLY every byte
 * still in the ring's past came after the transmit (before it, the state was TX or ECHO), and
 * with nothing held by the parser the byte path would find this frame where it starts.
 * Nothing changes unless it is taken; then whatever the completion asked for (an estop)
 * follows in an advance, as advance() would take it. Returns whether it was taken. */
J288_NOINLINE static bool reply_fast(j288_bus_t *bus, const uint8_t *data, size_t len)
{
    uint32_t head = bus->ring_head;
    uint32_t now;

    if ((len != J288_REPLY_LEN) || (bus->state != (uint8_t)J288_BUS_WAIT_REPLY) ||
        !events_since_seen(bus, 0u) || (j288_parser_pending(&bus->parser) != 0u) ||
        (j288_get_u16le(data) != J288_REPLY_HEAD16) || ((data[2] & 0x0Fu) != bus->tx_id) ||
        !j288_reply_crc_ok(&bus->crc, data)) {
        return false;
    }
    now = bus->port->now_us(bus->port_ctx);
    bus->ring_head = head + J288_REPLY_LEN;
    bus->ring_tail = head + J288_REPLY_LEN;
    j288_parser_counters(&bus->parser)->frames++;
    bus->in_advance = true;
    bus->again = false;
    j288_reply_unpack(data, &bus->txn[bus->cur].reply);
    end_with_reply(bus, now);
    bus->in_advance = false;
    if (bus->again) {
        advance(bus, now); /* what the completion asked for (an estop), as advance() would */
    }
    return true;
}

/* ---- public entry points */

/* The transaction of frame (to id) begins (the lock held where it is needed). */
static J288_INLINE_HOT void accept(j288_bus_t *bus, const uint8_t *frame, uint8_t id,
                                   uint32_t now_us, j288_bus_done_fn done, void *user)
{
    j288_bus_queue_frame(bus, frame, id, done, user);
    /* From a completion callback (inside an advance) the bus is in the guard that finish()
     * has just begun: the guard's timer, or the next poll, starts the transmit. */
    if (!bus->in_advance) {
        advance(bus, now_us);
    }
}

void j288_bus_accept_frame(j288_bus_t *bus, const uint8_t *frame, uint8_t id, uint32_t now_us,
                           j288_bus_done_fn done, void *user)
{
    accept(bus, frame, id, now_us, done, user);
}

int j288_bus_submit(j288_bus_t *bus, const j288_cmd_raw_t *cmd, uint32_t now_us,
                    j288_bus_done_fn done, void *user)
{
    int err;

    if ((bus == NULL) || (cmd == NULL)) {
        return J288_ERR_NULL;
    }
    j288_bus_lock(bus);
    if (!j288_bus_accepts(bus)) {
        j288_bus_unlock(bus);
        return J288_ERR_BUSY;
    }
    /* The transmit buffer is free: the previous transmit has completed. */
    err = j288_cmd_encode(cmd, bus->tx_buf, &bus->crc);
    if (err == J288_OK) {
        accept(bus, bus->tx_buf, cmd->id, now_us, done, user);
    }
    j288_bus_unlock(bus);
    return err;
}

void j288_bus_poll(j288_bus_t *bus, uint32_t now_us)
{
    if (bus == NULL) {
        return;
    }
    j288_bus_lock(bus);
    advance(bus, now_us);
    j288_bus_unlock(bus);
}

void j288_bus_on_tx_done(j288_bus_t *bus)
{
    if (bus == NULL) {
        return;
    }
    bus->txdone_mark = bus->ring_head;
    bus->ev_tx_done++;
    bus->ev_any++;
    /* Listen at once: the servo answers within microseconds. */
    if (bus->port->set_dir != NULL) {
        bus->port->set_dir(bus->port_ctx, J288_DIR_RX);
    }
    if (!bus->cfg.echo && (bus->port->start_rx != NULL)) {
        bus->port->start_rx(bus->port_ctx);
    }
    if (bus->cfg.advance_in_isr && !bus->in_advance && tx_done_fast(bus)) {
        return;
    }
    advance_from_event(bus);
}

/* With advance_in_isr, bytes arriving while nothing waits in the ring are taken where they
 * are, during this call, instead of being copied into the ring first: they are given the ring
 * positions they would have had (the ring stays empty, later bytes queue behind them), and
 * what the ring could not have held is lost the same way (rx_overflows). Out of line, so that
 * the ring path of on_rx stays short; a whole awaited reply goes to reply_fast() first. */
J288_NOINLINE static void take_in_place(j288_bus_t *bus, const uint8_t *data, size_t len)
{
    uint32_t head = bus->ring_head;
    size_t n = len;

    if (n > J288_CONFIG_RX_RING_SIZE) {
        bus->stats.rx_overflows += (uint32_t)(n - J288_CONFIG_RX_RING_SIZE);
        n = J288_CONFIG_RX_RING_SIZE;
    }
    bus->direct = data;
    bus->direct_pos = head;
    bus->direct_len = (uint32_t)n;
    bus->ring_head = head + (uint32_t)n;
    bus->ring_tail = head + (uint32_t)n;
    advance(bus, bus->port->now_us(bus->port_ctx));
    bus->direct = NULL; /* consumed by the advance's first step */
}

void j288_bus_on_rx(j288_bus_t *bus, const uint8_t *data, size_t len)
{
    if ((bus == NULL) || (data == NULL) || (len == 0u)) {
        return;
    }
    if (!bus->cfg.advance_in_isr || bus->in_advance || (bus->ring_head != bus->ring_tail)) {
        ring_put(bus, data, len);
        advance_from_event(bus);
        return;
    }
    if (!reply_fast(bus, data, len)) {
        take_in_place(bus, data, len);
    }
}

/* Nothing to do: a reply with a pause inside it is heard whole until the deadline, and a
 * partial frame is only given up there. Kept so that ports which report idle lines compile
 * and run unchanged. */
void j288_bus_on_rx_idle(j288_bus_t *bus)
{
    (void)bus;
}

void j288_bus_on_error(j288_bus_t *bus, uint32_t line_flags)
{
    if (bus == NULL) {
        return;
    }
    bus->line_flags |= line_flags;
    bus->stats.line_errors++;
    if ((line_flags & J288_LINE_GONE) != 0u) {
        bus->ev_gone++;
    } else {
        bus->ev_line++;
    }
    bus->ev_any++;
    advance_from_event(bus);
}

/* The guard's end with a submit queued and nothing else waiting (no retry, no stop: the
 * line's going away matters only to a retry): the next attempt starts, as step_quiet()
 * starts it. Bytes still in the ring are stale either way (start_attempt() counts them as
 * step_quiet()'s consume_all() would). Returns false, having done nothing, in any other case. */
static bool guard_end_fast(j288_bus_t *bus, uint32_t now)
{
    if ((bus->flags != J288_BUSF_QUEUED) || (bus->state != (uint8_t)J288_BUS_GUARD) ||
        !time_reached(now, bus->guard_end)) {
        return false;
    }
    bus->flags = 0u;
    bus->in_advance = true;
    bus->again = false;
    start_attempt(bus, now);
    bus->in_advance = false;
    if (bus->again) {
        advance(bus, now); /* events from inside start_tx, as advance() would take them */
    }
    return true;
}

void j288_bus_on_timer(j288_bus_t *bus)
{
    uint32_t now;

    if ((bus == NULL) || !bus->cfg.advance_in_isr) {
        return;
    }
    now = bus->port->now_us(bus->port_ctx);
    if (bus->in_advance || !guard_end_fast(bus, now)) {
        advance(bus, now);
    }
}

int j288_bus_estop(j288_bus_t *bus, uint32_t now_us)
{
    if (bus == NULL) {
        return J288_ERR_NULL;
    }
    j288_bus_lock(bus);
    if (has_flag(bus, J288_BUSF_ESTOP_ACTIVE)) {
        set_flag(bus, J288_BUSF_ESTOP_REARM); /* merged into the stop in progress, unless that
                                                 one fails */
    } else {
        set_flag(bus, J288_BUSF_ESTOP_PENDING);
    }
    if (bus->in_advance) {
        bus->again = true;
    } else {
        advance(bus, now_us);
    }
    j288_bus_unlock(bus);
    return J288_OK;
}

/* Force the pending transaction to end, e.g. the device went away: its attempt if one is on
 * the wire (the result is final), else the submit queued or waiting to retry. */
static void abort_txn(j288_bus_t *bus, int result, uint32_t now)
{
    if (is_active(bus->state)) {
        end_attempt(bus, result, now);
    } else {
        finish(bus, result, now);
    }
}

typedef struct {
    bool done;
    int result;
    j288_txn_t *out;
} blocking_t;

static void blocking_done(void *user, const j288_txn_t *txn)
{
    blocking_t *b = (blocking_t *)user;
    b->done = true;
    b->result = txn->result;
    if (b->out != NULL) {
        *b->out = *txn;
    }
}

int j288_bus_transfer_blocking(j288_bus_t *bus, const j288_cmd_raw_t *cmd, j288_txn_t *txn)
{
    blocking_t b;
    int rc;

    if ((bus == NULL) || (cmd == NULL)) {
        return J288_ERR_NULL;
    }
    if (bus->port->wait == NULL) {
        return J288_ERR_PORT_OPS;
    }
    if (bus->in_advance) {
        return J288_ERR_BUSY; /* not from a completion callback */
    }
    b.done = false;
    b.result = J288_ERR_BUSY;
    b.out = txn;
    rc = j288_bus_submit(bus, cmd, bus->port->now_us(bus->port_ctx), blocking_done, &b);
    if (rc != J288_OK) {
        return rc;
    }
    for (;;) {
        j288_bus_poll(bus, bus->port->now_us(bus->port_ctx));
        if (b.done) {
            break;
        }
        rc = bus->port->wait(bus->port_ctx, bus->timer_at);
        if (rc < 0) {
            /* Not done: ours is in flight, queued or waiting to retry; this ends it (with
             * J288_ERR_OFFLINE, or J288_ERR_ABORTED under a pending estop) and calls back. */
            j288_bus_lock(bus);
            abort_txn(bus, J288_ERR_OFFLINE, bus->port->now_us(bus->port_ctx));
            j288_bus_unlock(bus);
            break;
        }
    }
    return b.result;
}

j288_bus_state_t j288_bus_state(const j288_bus_t *bus)
{
    return (bus == NULL) ? J288_BUS_IDLE : (j288_bus_state_t)bus->state;
}

bool j288_bus_is_idle(const j288_bus_t *bus)
{
    return j288_bus_state(bus) == J288_BUS_IDLE;
}

const j288_bus_stats_t *j288_bus_stats(const j288_bus_t *bus)
{
    return (bus == NULL) ? NULL : &bus->stats;
}

const j288_parser_stats_t *j288_bus_parser_stats(const j288_bus_t *bus)
{
    return (bus == NULL) ? NULL : j288_parser_stats(&bus->parser);
}
