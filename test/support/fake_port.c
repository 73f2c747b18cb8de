/* Scripted fake port with a virtual clock; see fake_port.h. */
#include "fake_port.h"

#include <string.h>

#include "j288/sched.h"

enum { EV_RX = 1, EV_IDLE, EV_ERR, EV_TXDONE, EV_HEAR };

#define NS_PER_US 1000u

/* ---- time */

uint32_t fake_port_now_us(const fake_port_t *fp)
{
    return fp->origin_us + (uint32_t)(fp->now_ns / NS_PER_US);
}

uint64_t fake_port_byte_ns(const fake_port_t *fp)
{
    return 10000000000ull / fp->baud;
}

/* End of byte i (0-based) of a stream that starts at t0, without accumulated rounding. */
static uint64_t byte_end_ns(const fake_port_t *fp, uint64_t t0, size_t i)
{
    return t0 + ((uint64_t)(i + 1u) * 10000000000ull) / fp->baud;
}

/* A 32-bit microsecond deadline as an absolute ns time (past deadlines: now). */
static uint64_t deadline_ns(const fake_port_t *fp, uint32_t deadline_us)
{
    uint32_t d = deadline_us - fake_port_now_us(fp);
    if (d >= 0x80000000u) {
        return fp->now_ns;
    }
    return (fp->now_ns / NS_PER_US + d) * NS_PER_US;
}

/* ---- event queue */

static struct fake_event *ev_new(fake_port_t *fp, uint64_t t_ns, uint8_t kind)
{
    struct fake_event *e;
    if (fp->nev >= FAKE_PORT_MAX_EVENTS) {
        fp->overflow_errors++;
        return NULL;
    }
    e = &fp->ev[fp->nev++];
    memset(e, 0, sizeof *e);
    e->t_ns = t_ns;
    e->seq = fp->seq++;
    e->kind = kind;
    return e;
}

void fake_port_rx_at(fake_port_t *fp, uint64_t t_ns, const uint8_t *data, size_t len)
{
    while (len > 0u) {
        size_t n = (len < FAKE_PORT_CHUNK_MAX) ? len : FAKE_PORT_CHUNK_MAX;
        struct fake_event *e = ev_new(fp, t_ns, EV_RX);
        if (e == NULL) {
            return;
        }
        memcpy(e->data, data, n);
        e->len = (uint8_t)n;
        data += n;
        len -= n;
    }
}

void fake_port_rx_paced(fake_port_t *fp, uint64_t t_ns, const uint8_t *data, size_t len)
{
    size_t i;
    for (i = 0u; i < len; i++) {
        fake_port_rx_at(fp, byte_end_ns(fp, t_ns, i), &data[i], 1u);
    }
}

void fake_port_idle_at(fake_port_t *fp, uint64_t t_ns)
{
    (void)ev_new(fp, t_ns, EV_IDLE);
}

void fake_port_error_at(fake_port_t *fp, uint64_t t_ns, uint32_t line_flags)
{
    struct fake_event *e = ev_new(fp, t_ns, EV_ERR);
    if (e != NULL) {
        e->flags = line_flags;
    }
}

void fake_port_tx_done_at(fake_port_t *fp, uint64_t t_ns)
{
    (void)ev_new(fp, t_ns, EV_TXDONE);
}

/* Earliest event index (ties: scheduling order), or -1. */
static int ev_earliest(const fake_port_t *fp)
{
    int best = -1;
    uint32_t i;
    for (i = 0u; i < fp->nev; i++) {
        const struct fake_event *e = &fp->ev[i];
        if ((best < 0) || (e->t_ns < fp->ev[best].t_ns) ||
            ((e->t_ns == fp->ev[best].t_ns) && (e->seq < fp->ev[best].seq))) {
            best = (int)i;
        }
    }
    return best;
}

uint64_t fake_port_next_event_ns(const fake_port_t *fp)
{
    int i = ev_earliest(fp);
    uint64_t t = (i >= 0) ? fp->ev[i].t_ns : UINT64_MAX;
    if (fp->timer_armed && (fp->timer_ns < t)) {
        t = fp->timer_ns;
    }
    return t;
}

static void servos_hear(fake_port_t *fp, const uint8_t *data, size_t len, uint64_t tx_end);

/* Everything that enters the bus from the fake goes through here (benchmarks count it). */
void fake_port_deliver(fake_port_t *fp, int kind, const uint8_t *data, size_t len, uint32_t flags)
{
    switch (kind) {
    case EV_RX:
        j288_bus_on_rx(fp->bus, data, len);
        break;
    case EV_IDLE:
        j288_bus_on_rx_idle(fp->bus);
        break;
    case EV_ERR:
        j288_bus_on_error(fp->bus, flags);
        break;
    case EV_TXDONE:
        j288_bus_on_tx_done(fp->bus);
        break;
    default:
        j288_bus_on_timer(fp->bus);
        break;
    }
}

static void deliver(fake_port_t *fp, const struct fake_event *e)
{
    if (e->kind == EV_HEAR) {
        servos_hear(fp, e->data, e->len, e->t_ns);
        return;
    }
    if (e->kind == EV_TXDONE) {
        fp->tx_busy = false;
    }
    fake_port_deliver(fp, e->kind, e->data, e->len, e->flags);
}

/* Deliver the earliest event (events before the timer at equal times). Returns false when
 * nothing is due by t_ns. */
static bool deliver_next(fake_port_t *fp, uint64_t t_ns)
{
    int i = ev_earliest(fp);
    bool timer_first = fp->timer_armed && ((i < 0) || (fp->timer_ns < fp->ev[i].t_ns));

    if (timer_first) {
        if (fp->timer_ns > t_ns) {
            return false;
        }
        if (fp->timer_ns > fp->now_ns) {
            fp->now_ns = fp->timer_ns;
        }
        fp->timer_armed = false;
        fp->timer_fires++;
        fake_port_deliver(fp, 0, NULL, 0u, 0u);
        return true;
    }
    if ((i < 0) || (fp->ev[i].t_ns > t_ns)) {
        return false;
    }
    {
        struct fake_event e = fp->ev[i];
        fp->ev[i] = fp->ev[--fp->nev]; /* remove first: deliver may schedule more */
        if (e.t_ns > fp->now_ns) {
            fp->now_ns = e.t_ns;
        }
        deliver(fp, &e);
    }
    return true;
}

static void poll_hook(fake_port_t *fp)
{
    if (fp->poll_fn != NULL) {
        fp->poll_fn(fp->poll_user, fake_port_now_us(fp));
    }
}

void fake_port_run_until(fake_port_t *fp, uint64_t t_ns)
{
    while (deliver_next(fp, t_ns)) {
        poll_hook(fp);
    }
    if (t_ns > fp->now_ns) {
        fp->now_ns = t_ns;
    }
    poll_hook(fp);
}

void fake_port_run_for(fake_port_t *fp, uint64_t dt_ns)
{
    fake_port_run_until(fp, fp->now_ns + dt_ns);
}

bool fake_port_run_until_idle(fake_port_t *fp, uint64_t limit_ns)
{
    for (;;) {
        uint64_t next = fake_port_next_event_ns(fp);
        if (j288_bus_is_idle(fp->bus) && (fp->nev == 0u)) {
            return true;
        }
        if (fp->now_ns >= limit_ns) {
            return false;
        }
        if ((next == UINT64_MAX) || (next <= fp->now_ns)) {
            next = fp->now_ns + NS_PER_US; /* a poll-only bus needs time to pass */
        }
        fake_port_run_until(fp, (next < limit_ns) ? next : limit_ns);
    }
}

/* ---- the servo model */

void fake_port_encode_reply(const j288_reply_raw_t *reply, uint8_t out[J288_REPLY_LEN])
{
    if (j288_reply_encode(reply, out, NULL) != J288_OK) {
        memset(out, 0, J288_REPLY_LEN);
    }
}

static void garbage_bytes(uint8_t *out, size_t n)
{
    size_t i;
    for (i = 0u; i < n; i++) {
        out[i] = ((i % 3u) == 1u) ? J288_REPLY_HEAD0 : (uint8_t)(0x5Au + i); /* false heads */
    }
}

/* One reply stream (garbage + frame) starting at t0; returns when its last byte ends. */
static uint64_t schedule_reply(fake_port_t *fp, const fake_servo_t *sv, const uint8_t *frame,
                               uint64_t t0)
{
    uint8_t stream[2u * FAKE_PORT_CHUNK_MAX + J288_REPLY_LEN];
    size_t g = (sv->garbage < 2u * FAKE_PORT_CHUNK_MAX) ? sv->garbage : 2u * FAKE_PORT_CHUNK_MAX;
    size_t n = g + (sv->truncate ? 15u : J288_REPLY_LEN);
    size_t pos = 0u;
    uint64_t end = byte_end_ns(fp, t0, n - 1u);

    garbage_bytes(stream, g);
    memcpy(&stream[g], frame, J288_REPLY_LEN);
    if (sv->chunk == 0u) {
        fake_port_rx_at(fp, end + fp->rx_latency_ns, stream, n);
    } else {
        while (pos < n) {
            size_t k = ((n - pos) < sv->chunk) ? (n - pos) : sv->chunk;
            fake_port_rx_at(fp, byte_end_ns(fp, t0, pos + k - 1u) + fp->rx_latency_ns, &stream[pos],
                            k);
            pos += k;
        }
    }
    if (fp->idle) {
        fake_port_idle_at(fp, end + fake_port_byte_ns(fp) + fp->rx_latency_ns);
    }
    return end;
}

static void servo_answer(fake_port_t *fp, uint8_t id, fake_servo_t *sv, uint64_t tx_end)
{
    j288_reply_raw_t r = sv->reply;
    uint8_t frame[J288_REPLY_LEN];
    uint64_t t0 = tx_end + (sv->turnaround_ns != 0u ? sv->turnaround_ns : fp->turnaround_ns) +
                  sv->extra_delay_ns;
    uint64_t end;

    r.id = (sv->reply_id >= 0) ? (uint8_t)sv->reply_id : id;
    fake_port_encode_reply(&r, frame);
    if (sv->corrupt) {
        frame[10] ^= 0x01u;
    }
    end = schedule_reply(fp, sv, frame, t0);
    if (sv->twin) {
        fake_servo_t twin = *sv;
        twin.garbage = 0u;
        twin.corrupt = false;
        twin.truncate = false;
        r.pos += 1000;
        fake_port_encode_reply(&r, frame);
        (void)schedule_reply(fp, &twin, frame, end + sv->twin_gap_ns);
    }
}

static void servo_take(fake_servo_t *sv, const j288_cmd_raw_t *cmd)
{
    sv->commands++;
    sv->last_cmd = *cmd;
    if (!cmd->watchdog) {
        sv->reply.watchdog_tripped = false; /* the manual: bit 0 clears the trip */
    }
}

static void servos_hear(fake_port_t *fp, const uint8_t *data, size_t len, uint64_t tx_end)
{
    j288_cmd_raw_t cmd;
    uint8_t i;

    if ((len != J288_CMD_LEN) || (j288_cmd_decode(data, &cmd, NULL) != J288_OK)) {
        return;
    }
    if (cmd.id == J288_BROADCAST_ID) {
        for (i = 0u; i < J288_MAX_SERVOS; i++) {
            if (fp->servo[i].present) {
                servo_take(&fp->servo[i], &cmd);
            }
        }
        return;
    }
    if (fp->servo[cmd.id].present) {
        servo_take(&fp->servo[cmd.id], &cmd);
        servo_answer(fp, cmd.id, &fp->servo[cmd.id], tx_end);
    }
}

/* ---- port ops */

static int op_start_tx(void *ctx, const uint8_t *data, size_t len)
{
    fake_port_t *fp = (fake_port_t *)ctx;
    fake_frame_t f;
    size_t i;

    if (fp->start_tx_fail > 0) {
        fp->start_tx_fail--;
        return J288_ERR_PORT;
    }
    if (fp->tx_busy) {
        fp->tx_overlap_errors++;
    }
    memset(&f, 0, sizeof f);
    f.len = (len < sizeof f.data) ? len : sizeof f.data;
    memcpy(f.data, data, f.len);
    f.start_ns = fp->now_ns;
    f.end_ns = byte_end_ns(fp, fp->now_ns, len - 1u);
    f.start_us = fake_port_now_us(fp);
    if (fp->nframes < FAKE_PORT_MAX_FRAMES) {
        fp->frame[fp->nframes] = f;
    }
    fp->nframes++;
    fp->last = f;

    if (fp->echo) {
        for (i = 0u; i < len; i++) {
            uint8_t b = data[i];
            if ((int)i == fp->echo_flip_at) {
                b ^= 0x10u;
            }
            fake_port_rx_at(fp, byte_end_ns(fp, fp->now_ns, i) + fp->echo_delay_ns, &b, 1u);
        }
    }
    {
        /* The servos act on the command once its last byte has arrived. */
        struct fake_event *e = ev_new(fp, f.end_ns, EV_HEAR);
        if (e != NULL) {
            e->len = (uint8_t)f.len;
            memcpy(e->data, f.data, f.len);
        }
    }
    if (fp->txdone == FAKE_TXDONE_TIMED) {
        fp->tx_busy = true;
        fake_port_tx_done_at(fp, f.end_ns);
    } else if (fp->txdone == FAKE_TXDONE_INLINE) {
        j288_bus_on_tx_done(fp->bus);
    } else {
        fp->tx_busy = true;
    }
    return 0;
}

static uint32_t op_now_us(void *ctx)
{
    return fake_port_now_us((const fake_port_t *)ctx);
}

static void op_start_rx(void *ctx)
{
    ((fake_port_t *)ctx)->start_rx_calls++;
}

static void op_set_dir(void *ctx, j288_dir_t dir)
{
    fake_port_t *fp = (fake_port_t *)ctx;
    fp->set_dir_calls++;
    fp->dir = dir;
}

static void op_arm_timeout(void *ctx, uint32_t deadline_us)
{
    fake_port_t *fp = (fake_port_t *)ctx;
    fp->timer_arms++;
    fp->timer_armed = true;
    fp->timer_ns = deadline_ns(fp, deadline_us);
}

static int op_wait(void *ctx, uint32_t until_us)
{
    fake_port_t *fp = (fake_port_t *)ctx;
    uint64_t until = deadline_ns(fp, until_us);
    fp->wait_calls++;
    if (fp->gone || ((fp->gone_after_ns != 0u) && (fp->now_ns >= fp->gone_after_ns))) {
        return J288_ERR_OFFLINE;
    }
    if (!deliver_next(fp, until) && (until > fp->now_ns)) {
        fp->now_ns = until;
    }
    return 0;
}

uint32_t fake_port_crc32(void *ctx, const uint8_t *data, size_t nwords)
{
    ((fake_port_t *)ctx)->crc_calls++;
    return j288_crc32_update_bitwise(J288_CRC32_INIT, data, nwords);
}

static void op_lock(void *ctx)
{
    fake_port_t *fp = (fake_port_t *)ctx;
    if (fp->lock_depth != 0) {
        fp->lock_errors++;
    }
    fp->lock_depth++;
    fp->lock_calls++;
}

static void op_unlock(void *ctx)
{
    fake_port_t *fp = (fake_port_t *)ctx;
    if (fp->lock_depth != 1) {
        fp->lock_errors++;
    }
    fp->lock_depth--;
}

/* ---- setup and observation */

/* Every operation but crc32 (a test sets ops.crc32 = fake_port_crc32 to count CRC calls). */
static const j288_port_t fake_ops = {
    .start_tx = op_start_tx,
    .now_us = op_now_us,
    .start_rx = op_start_rx,
    .set_dir = op_set_dir,
    .arm_timeout = op_arm_timeout,
    .wait = op_wait,
    .lock = op_lock,
    .unlock = op_unlock,
};

void fake_port_init(fake_port_t *fp)
{
    uint8_t i;
    memset(fp, 0, sizeof *fp);
    fp->ops = fake_ops;
    fp->baud = 6000000u;
    fp->txdone = FAKE_TXDONE_TIMED;
    fp->echo_flip_at = -1;
    fp->idle = true;
    fp->turnaround_ns = 10000u;
    fp->dir = J288_DIR_RX;
    for (i = 0u; i < J288_MAX_SERVOS; i++) {
        fp->servo[i].reply_id = -1;
    }
}

void fake_port_attach(fake_port_t *fp, j288_bus_t *bus)
{
    fp->bus = bus;
}

void fake_port_add_servo(fake_port_t *fp, uint8_t id, const j288_reply_raw_t *reply)
{
    fake_servo_t *sv;
    if (id >= J288_MAX_SERVOS) {
        return;
    }
    sv = &fp->servo[id];
    memset(sv, 0, sizeof *sv);
    sv->present = true;
    sv->reply_id = -1;
    if (reply != NULL) {
        sv->reply = *reply;
    }
    sv->reply.id = id;
}

const fake_frame_t *fake_port_frame(const fake_port_t *fp, uint32_t i)
{
    return (i < fp->nframes && i < FAKE_PORT_MAX_FRAMES) ? &fp->frame[i] : NULL;
}

void fake_port_poll_bus(void *bus, uint32_t now_us)
{
    j288_bus_poll((j288_bus_t *)bus, now_us);
}

void fake_port_poll_sched(void *sched, uint32_t now_us)
{
    j288_sched_poll((j288_sched_t *)sched, now_us);
}
