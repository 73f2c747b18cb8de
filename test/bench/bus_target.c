/*
 * Engine cost on Cortex-M and RISC-V: instructions per transaction through the library, side
 * by side with a hand-written floor doing the same work, counted under QEMU -icount shift=0
 * (one instruction per ns) by reading SysTick (or minstret) around ITERATIONS transactions
 * (test/target/icount.h). The ticks-to-instructions factor is measured in the same run on a
 * loop of known length.
 *
 * Library rows: the codec alone (encode, parse, unpack: what any engine pays), the same with
 * a CRC unit behind a port's crc32 op, the bus in poll mode (submit, tx done, 26 bytes, idle,
 * poll, guard), and continuous scheduler sweeps over 15 servos with the bus advanced in the
 * event calls (tx done, 26 bytes, idle, timer), the way an MCU runs at the wire's limit, with
 * the slots' commands unchanged and with a new command for each transaction (printed first:
 * the like-for-like row, the floor encoding and checking every frame too). The
 * library's CRC is the compile-time default backend of this image (J288_CONFIG_CRC_BACKEND).
 *
 * Floor rows: the same work written by hand for this one job, with every shortcut a
 * firmware could take and the library cannot (see "floor" below). Built and run by
 * `make bench-bus-target`; docs/performance.md explains the figures.
 */
#include "j288/j288.h"

#include <stdio.h>
#include <string.h>

#include "../target/icount.h"
#include "crc_unit_model.h"
#include "../support/worked_cmd.h"

#ifndef ITERATIONS
#define ITERATIONS 300u
#endif
/* Rows to run (bits: 1 floors, 2 codec, 4 codec with the CRC unit, 8 poll, 16 sweeps, 32 joint,
 * 64 sweeps with a new command each transaction, 128 codec with the parser's unpack): a profile of one row under QEMU builds the
 * image with -DBUS_TARGET_ROWS=<bits>. */
#ifndef BUS_TARGET_ROWS
#define BUS_TARGET_ROWS 0xFFu
#endif
#define RUN_ROW(bit, call) (((BUS_TARGET_ROWS) & (bit)) != 0u ? (call) : 0u)
#define CAL_LOOPS  100000u
#define HW_BACKEND (J288_CONFIG_CRC_BACKEND == J288_CRC_BACKEND_HW)

static uint32_t clock_us;
static uint8_t last_id;
static uint32_t done_count;
static uint32_t done_expected;
static j288_bus_t bus;
static j288_sched_t sch;
static uint8_t replies[J288_MAX_SERVOS][J288_REPLY_LEN];

static uint32_t per_txn(uint32_t ticks, uint32_t ipt_milli)
{
    return (uint32_t)(((uint64_t)ticks * ipt_milli / 1000u + ITERATIONS / 2u) / ITERATIONS);
}

/* ---- a port that does nothing */

static int op_start_tx(void *ctx, const uint8_t *data, size_t len)
{
    (void)ctx;
    (void)len;
    last_id = (uint8_t)(data[2] & 0x0Fu);
    return 0;
}
static uint32_t op_now_us(void *ctx)
{
    (void)ctx;
    return clock_us;
}
static void op_arm_timeout(void *ctx, uint32_t t)
{
    (void)ctx;
    (void)t;
}
static void op_nothing(void *ctx)
{
    (void)ctx;
}

static const j288_port_t port = {
    .start_tx = op_start_tx,
    .now_us = op_now_us,
    .arm_timeout = op_arm_timeout,
    .lock = op_nothing,
    .unlock = op_nothing,
};

static void on_done(void *user, const j288_txn_t *txn)
{
    (void)user;
    if (txn->result == J288_OK) {
        done_count++;
    }
}

/* ---- the CRC unit (crc_unit_model.h) */

bench_crc_unit_t bench_unit;
uint32_t bench_unit_answer[2];
uint32_t bench_unit_next;

/* The port's crc32 op as a port for this unit writes it: reset, one write per word. */
static uint32_t unit_crc32(void *ctx, const uint8_t *data, size_t nwords)
{
    bench_crc_unit_t *u = (bench_crc_unit_t *)ctx;
    size_t i;
    u->CR = 1u;
    for (i = 0u; i < nwords; i++) {
        u->DR = j288_get_u32le(&data[4u * i]);
    }
    return bench_unit_result();
}

#if (J288_CONFIG_CRC_BACKEND == J288_CRC_BACKEND_HW) && !defined(J288_USER_CONFIG)
/* The same unit as the library's compile-time CRC backend (J288_CRC_BACKEND_HW), a function
 * the library calls, no port op in between (with J288_USER_CONFIG, hw_inline/: the same
 * function static inline). Only the codec and poll rows ask it in the order the two-entry
 * model answers (a command, then a reply). */
uint32_t bench_crc_unit(const uint8_t *data, size_t nwords);
uint32_t bench_crc_unit(const uint8_t *data, size_t nwords)
{
    return bench_crc_unit_inline(data, nwords);
}
#endif

/* The frames the rows use are made with the table backend, whatever this image's default. */
static uint32_t soft_crc(void *ctx, const uint8_t *data, size_t nwords)
{
    (void)ctx;
    return j288_crc32_update_table(J288_CRC32_INIT, data, nwords);
}
static const j288_crc_t soft_engine = {soft_crc, NULL};

/* ---- the floor: the same work written by hand for this job only. It knows the frames'
 * layout at compile time, keeps a reply where the DMA put it (2 bytes past a word boundary,
 * so the 20 CRC'd bytes and the CRC field load as aligned words), reads and writes whole words
 * (little-endian target), checks the head as one halfword and the CRC over words with
 * slicing-by-4 tables (built in RAM at start-up), validates the command's fields, unpacks
 * every reply field, and as an engine keeps just a state, a deadline and a guard: no ring,
 * no resync, no retries, no statistics beyond the slot's. */

static uint32_t s4[4][256];

/* The floor's entry points stay functions, as the library's are (called from another
 * translation unit, or as interrupt handlers): nothing is hoisted out of the loops. */
#define FLOOR_ENTRY static __attribute__((noinline))

static void floor_tables(void)
{
    unsigned i, k;
    for (i = 0u; i < 256u; i++) {
        uint32_t c = (uint32_t)i << 24;
        for (k = 0u; k < 8u; k++) {
            c = ((c & 0x80000000u) != 0u) ? ((c << 1) ^ J288_CRC32_POLY) : (c << 1);
        }
        s4[0][i] = c;
    }
    for (k = 1u; k < 4u; k++) {
        for (i = 0u; i < 256u; i++) {
            uint32_t p = s4[k - 1u][i];
            s4[k][i] = (p << 8) ^ s4[0][p >> 24];
        }
    }
}

/* One word into the CRC; the tables come in as four base pointers so that each lookup is a
 * single indexed load. */
#define FLOOR_TABLES                                                                           \
    const uint32_t *t0 = s4[0], *t1 = s4[1], *t2 = s4[2], *t3 = s4[3]
#define FLOOR_CRC_WORD(c, w)                                                                   \
    do {                                                                                       \
        uint32_t v_ = (c) ^ (w);                                                               \
        (c) = t3[v_ >> 24] ^ t2[(v_ >> 16) & 0xFFu] ^ t1[(v_ >> 8) & 0xFFu] ^ t0[v_ & 0xFFu]; \
    } while (0)

/* Replies as the floor receives them: word 0's upper half is the head, words 1-5 the CRC'd
 * bytes, word 6 the CRC. */
static uint32_t floor_replies[J288_MAX_SERVOS][7];

static int floor_encode_words(const j288_cmd_raw_t *c, uint32_t w[4])
{
    if ((c->id > 15u) || (c->status > 1u) || (c->kp < 0) || (c->kd < 0)) {
        return -1;
    }
    w[0] = 0xEEFEu | ((uint32_t)c->id << 16) | ((uint32_t)c->status << 20) |
           (c->watchdog ? 0x800000u : 0u);
    w[1] = (uint16_t)c->tau | ((uint32_t)(uint16_t)c->speed << 16);
    w[2] = (uint32_t)c->pos;
    w[3] = (uint16_t)c->kp | ((uint32_t)(uint16_t)c->kd << 16);
    return 0;
}

FLOOR_ENTRY int floor_encode(const j288_cmd_raw_t *cmd, uint32_t out[5])
{
    FLOOR_TABLES;
    uint32_t w[4];
    uint32_t c = J288_CRC32_INIT;
    if (floor_encode_words(cmd, w) != 0) {
        return -1;
    }
    out[0] = w[0];
    out[1] = w[1];
    out[2] = w[2];
    out[3] = w[3];
    FLOOR_CRC_WORD(c, w[0]);
    FLOOR_CRC_WORD(c, w[1]);
    FLOOR_CRC_WORD(c, w[2]);
    FLOOR_CRC_WORD(c, w[3]);
    out[4] = c;
    return 0;
}

FLOOR_ENTRY int floor_encode_unit(const j288_cmd_raw_t *c, uint32_t out[5])
{
    uint32_t w[4];
    if (floor_encode_words(c, w) != 0) {
        return -1;
    }
    bench_unit.CR = 1u;
    bench_unit.DR = out[0] = w[0];
    bench_unit.DR = out[1] = w[1];
    bench_unit.DR = out[2] = w[2];
    bench_unit.DR = out[3] = w[3];
    out[4] = bench_unit_result();
    return 0;
}

static void floor_unpack(const uint32_t *f, j288_reply_raw_t *r)
{
    uint32_t w1 = f[1], w2 = f[2], w5 = f[5];
    r->id = (uint8_t)(w1 & 0x0Fu);
    r->status = (uint8_t)((w1 >> 4) & 7u);
    r->watchdog_tripped = (w1 & 0x80u) != 0u;
    r->case_temp_c = (int8_t)(w1 >> 8);
    r->winding_temp_c = (uint8_t)(w1 >> 16);
    r->voltage_raw = (uint8_t)(w1 >> 24);
    r->torque = (int16_t)w2;
    r->speed = (int16_t)(w2 >> 16);
    r->pos = (int32_t)f[3];
    r->faults = f[4];
    r->out_pos = (uint16_t)(w5 & 0x1FFFu);
    r->warnings = (uint8_t)((w5 >> 13) & 7u);
    r->reserved = (uint16_t)(w5 >> 16);
}

FLOOR_ENTRY int floor_decode(const uint32_t *f, j288_reply_raw_t *r)
{
    FLOOR_TABLES;
    uint32_t c = J288_CRC32_INIT;
    if ((f[0] >> 16) != 0xEEFCu) {
        return -1;
    }
    FLOOR_CRC_WORD(c, f[1]);
    FLOOR_CRC_WORD(c, f[2]);
    FLOOR_CRC_WORD(c, f[3]);
    FLOOR_CRC_WORD(c, f[4]);
    FLOOR_CRC_WORD(c, f[5]);
    if (c != f[6]) {
        return -1;
    }
    floor_unpack(f, r);
    return 0;
}

FLOOR_ENTRY int floor_decode_unit(const uint32_t *f, j288_reply_raw_t *r)
{
    if ((f[0] >> 16) != 0xEEFCu) {
        return -1;
    }
    bench_unit.CR = 1u;
    bench_unit.DR = f[1];
    bench_unit.DR = f[2];
    bench_unit.DR = f[3];
    bench_unit.DR = f[4];
    bench_unit.DR = f[5];
    if (bench_unit_result() != f[6]) {
        return -1;
    }
    floor_unpack(f, r);
    return 0;
}

/* The floor as an engine and scheduler: 15 slots swept back to back from the events, the
 * port's operations called as the library calls them. */
typedef struct {
    j288_cmd_raw_t cmd;
    j288_reply_raw_t reply;
    uint32_t successes;
    uint32_t latency_us;
} floor_slot_t;

static struct {
    uint8_t state; /* 0 guard, 1 transmitting, 2 waiting for the reply */
    uint8_t id;
    uint32_t start_us, deadline_us, guard_end_us;
    uint32_t tx[5];
    floor_slot_t slot[J288_MAX_SERVOS];
} fl;

static void floor_next(uint32_t now)
{
    fl.id = (uint8_t)((fl.id == J288_MAX_ID) ? 0u : fl.id + 1u);
    (void)floor_encode(&fl.slot[fl.id].cmd, fl.tx);
    fl.state = 0u;
    fl.guard_end_us = now + J288_DEFAULT_GUARD_US;
    port.arm_timeout(NULL, fl.guard_end_us);
}

FLOOR_ENTRY void floor_on_tx_done(void)
{
    fl.state = 2u;
}

FLOOR_ENTRY void floor_on_rx(const uint32_t *f, size_t len)
{
    uint32_t now = port.now_us(NULL);
    floor_slot_t *s = &fl.slot[fl.id];
    j288_reply_raw_t r;
    if ((fl.state != 2u) || (len != J288_REPLY_LEN) || (floor_decode(f, &r) != 0) ||
        (r.id != fl.id)) {
        return;
    }
    s->reply = r;
    s->successes++;
    s->latency_us = now - fl.start_us;
    done_count++;
    floor_next(now);
}

FLOOR_ENTRY void floor_on_timer(void)
{
    uint32_t now = port.now_us(NULL);
    if ((fl.state == 0u) && ((uint32_t)(now - fl.guard_end_us) < 0x80000000u)) {
        fl.state = 1u;
        fl.start_us = now;
        fl.deadline_us = now + 147u;
        port.arm_timeout(NULL, fl.deadline_us);
        (void)port.start_tx(NULL, (const uint8_t *)fl.tx, J288_CMD_LEN);
    }
}

/* ---- rows */

static uint32_t run_floor_codec(bool with_unit)
{
    j288_cmd_raw_t cmd = worked_cmd();
    j288_reply_raw_t r;
    uint32_t frame[5];
    uint32_t i, t0, t1;
    bench_unit_next = 0u;
    t0 = icount_now();
    for (i = 0u; i < ITERATIONS; i++) {
        if (with_unit) {
            (void)floor_encode_unit(&cmd, frame);
            if (floor_decode_unit(floor_replies[3], &r) == 0) {
                done_count++;
            }
        } else {
            (void)floor_encode(&cmd, frame);
            if (floor_decode(floor_replies[3], &r) == 0) {
                done_count++;
            }
        }
    }
    t1 = icount_now();
    done_expected += ITERATIONS;
    return icount_between(t0, t1);
}

static uint32_t run_floor_engine(void)
{
    uint32_t i, t0, t1;
    uint8_t id;
    memset(&fl, 0, sizeof fl);
    for (id = 0u; id < J288_MAX_SERVOS; id++) {
        fl.slot[id].cmd = worked_cmd();
        fl.slot[id].cmd.id = id;
    }
    fl.id = J288_MAX_ID;
    floor_next(clock_us);
    clock_us += 2u;
    floor_on_timer();
    t0 = icount_now();
    for (i = 0u; i < ITERATIONS; i++) {
        floor_on_tx_done();
        floor_on_rx(floor_replies[last_id], J288_REPLY_LEN);
        clock_us += 90u;
        floor_on_timer(); /* the guard ends: the next command starts */
    }
    t1 = icount_now();
    done_expected += ITERATIONS;
    return icount_between(t0, t1);
}

/* The codec rows' loop; with parser_unpacks, the reply is unpacked by j288_parser_reply()
 * from the parser's aligned buffer instead of j288_reply_unpack(j288_parser_frame()), which
 * reads bytes of unknown alignment. Always inlined, so that each row's loop is compiled for
 * its own unpack (a test in the loop would count in both rows). */
static inline __attribute__((always_inline)) uint32_t codec_loop(const j288_crc_t *crc,
                                                                 bool parser_unpacks)
{
    j288_parser_t parser;
    j288_cmd_raw_t cmd = worked_cmd();
    j288_reply_raw_t r;
    uint8_t frame[J288_CMD_LEN];
    uint32_t i, t0, t1;
    (void)j288_parser_init(&parser, J288_PARSE_REPLY, crc);
    bench_unit_next = 0u;
    t0 = icount_now();
    for (i = 0u; i < ITERATIONS; i++) {
        size_t used;
        (void)j288_cmd_encode(&cmd, frame, crc);
        if (j288_parser_feed(&parser, replies[3], J288_REPLY_LEN, &used) == J288_PARSE_FRAME) {
            if (parser_unpacks) {
                j288_parser_reply(&parser, &r);
            } else {
                j288_reply_unpack(j288_parser_frame(&parser), &r);
            }
            done_count++;
        }
    }
    t1 = icount_now();
    done_expected += ITERATIONS;
    return icount_between(t0, t1);
}

static uint32_t run_codec(const j288_crc_t *crc)
{
    return codec_loop(crc, false);
}

static uint32_t run_codec_parser_unpacks(void)
{
    return codec_loop(NULL, true);
}

static uint32_t run_bus_poll(void)
{
    j288_cmd_raw_t cmd = worked_cmd();
    uint32_t i, t0, t1;
    (void)j288_bus_init(&bus, &port, NULL, NULL);
    t0 = icount_now();
    for (i = 0u; i < ITERATIONS; i++) {
        (void)j288_bus_submit(&bus, &cmd, clock_us, on_done, NULL);
        j288_bus_on_tx_done(&bus);
        j288_bus_on_rx(&bus, replies[3], J288_REPLY_LEN);
        j288_bus_on_rx_idle(&bus);
        clock_us += 90u;
        j288_bus_poll(&bus, clock_us); /* the reply is taken */
        clock_us += 10u;
        j288_bus_poll(&bus, clock_us); /* the guard ends */
    }
    t1 = icount_now();
    done_expected += ITERATIONS;
    return icount_between(t0, t1);
}

/* Continuous sweeps; with new_cmds, the control loop's case: every transaction's slot gets a
 * new command (j288_sched_set_cmd, a position that changes) before it is sent, so that each
 * command is encoded afresh, as the floor encodes every one. */
static uint32_t run_sched_isr(bool new_cmds)
{
    j288_bus_config_t bc;
    j288_sched_config_t sc;
    uint32_t i, t0, t1, before;
    uint8_t id;
    memset(&bc, 0, sizeof bc);
    memset(&sc, 0, sizeof sc);
    bc.advance_in_isr = true;
    sc.continuous = true;
    (void)j288_bus_init(&bus, &port, NULL, &bc);
    (void)j288_sched_init(&sch, &bus, &sc);
    for (id = 0u; id < J288_MAX_SERVOS; id++) {
        j288_cmd_raw_t cmd = worked_cmd();
        cmd.id = id;
        (void)j288_sched_enable(&sch, id, true);
        (void)j288_sched_set_cmd(&sch, &cmd);
    }
    (void)j288_sched_start_sweep(&sch, clock_us);
    before = sch.slot[14].stats.successes;
    t0 = icount_now();
    for (i = 0u; i < ITERATIONS; i++) {
        if (new_cmds) {
            j288_cmd_raw_t cmd = worked_cmd();
            cmd.id = (uint8_t)((last_id == J288_MAX_ID) ? 0u : last_id + 1u);
            cmd.pos = (int32_t)(i & 7u);
            (void)j288_sched_set_cmd(&sch, &cmd);
        }
        j288_bus_on_tx_done(&bus);
        j288_bus_on_rx(&bus, replies[last_id], J288_REPLY_LEN);
        clock_us += 88u;
        j288_bus_on_rx_idle(&bus);
        clock_us += 2u;
        j288_bus_on_timer(&bus); /* the guard ends: the next command starts */
    }
    t1 = icount_now();
    if (sch.slot[14].stats.successes - before != ITERATIONS / J288_MAX_SERVOS) {
        done_count = 0u; /* not every transaction succeeded */
    }
    return icount_between(t0, t1);
}

#if J288_CONFIG_SI
/* ---- the joint layer: a known joint taking replies (tracking, encoder check, limits) and
 * turning targets into commands; each loop adds a few instructions of its own. */
static j288_joint_t joint;
static uint32_t joint_errors;

static uint32_t run_joint_reply(void)
{
    j288_joint_config_t jc;
    j288_reply_raw_t r;
    uint32_t i, t0, t1;
    memset(&jc, 0, sizeof jc);
    memset(&r, 0, sizeof r);
    jc.id = 3u;
    r.id = 3u;
    r.pos = 5000;
    r.out_pos = 100u;
    r.speed = 100; /* a moving joint: speed and torque are scaled, not skipped as zero */
    r.torque = 10;
    (void)j288_joint_init(&joint, &jc);
    for (i = 0u; i < J288_JOINT_DEFAULT_INIT_SAMPLES; i++) {
        (void)j288_joint_take_reply(&joint, &r, NULL);
    }
    t0 = icount_now();
    for (i = 0u; i < ITERATIONS; i++) {
        unsigned ev;
        r.pos = 5000 + (int32_t)(i & 7u);
        joint_errors += (uint32_t)(j288_joint_take_reply(&joint, &r, &ev) != J288_OK);
    }
    t1 = icount_now();
    joint_errors += (uint32_t)!j288_joint_state(&joint)->known;
    return icount_between(t0, t1);
}

static uint32_t run_joint_command(void)
{
    j288_joint_target_t t;
    j288_cmd_raw_t cmd;
    uint32_t i, t0, t1;
    j288_joint_target_init(&joint, &t);
    t.kp = (j288_real_t)20;
    t.kd = (j288_real_t)0.5;
    t0 = icount_now();
    for (i = 0u; i < ITERATIONS; i++) {
        t.pos = (j288_real_t)(i & 7u) * (j288_real_t)0.01;
        joint_errors += (uint32_t)(j288_joint_command(&joint, &t, &cmd, NULL) != J288_OK);
    }
    t1 = icount_now();
    return icount_between(t0, t1);
}
#endif

/* ---- the joint core (j288/jointq.h), the same work as the rows above (which run it through
 * the float facade), and a speed target near a limit (the limit law's path). */
static j288_jointq_t jointq;
static uint32_t jointq_errors;

static uint32_t run_jointq_reply(void)
{
    j288_jointq_config_t jc;
    j288_reply_raw_t r;
    uint32_t i, t0, t1;
    memset(&jc, 0, sizeof jc);
    memset(&r, 0, sizeof r);
    jc.id = 3u;
    r.id = 3u;
    r.pos = 5000;
    r.out_pos = 100u;
    r.speed = 100;
    r.torque = 10;
    (void)j288_jointq_init(&jointq, &jc);
    for (i = 0u; i < J288_JOINT_DEFAULT_INIT_SAMPLES; i++) {
        (void)j288_jointq_take_reply(&jointq, &r, NULL);
    }
    t0 = icount_now();
    for (i = 0u; i < ITERATIONS; i++) {
        unsigned ev;
        r.pos = 5000 + (int32_t)(i & 7u);
        jointq_errors += (uint32_t)(j288_jointq_take_reply(&jointq, &r, &ev) != J288_OK);
    }
    t1 = icount_now();
    jointq_errors += (uint32_t)!j288_jointq_state(&jointq)->known;
    return icount_between(t0, t1);
}

static uint32_t run_jointq_command(void)
{
    j288_jointq_target_t t;
    j288_cmd_raw_t cmd;
    uint32_t i, t0, t1;
    j288_jointq_target_init(&jointq, &t);
    t.kp = J288_Q16(20.0);
    t.kd = J288_Q16(0.5);
    t0 = icount_now();
    for (i = 0u; i < ITERATIONS; i++) {
        t.pos = (j288_q24_t)(i & 7u) * J288_Q24(0.01);
        jointq_errors += (uint32_t)(j288_jointq_command(&jointq, &t, &cmd, NULL) != J288_OK);
    }
    t1 = icount_now();
    return icount_between(t0, t1);
}

/* kp 0, kd 1, 1 rad/s toward the top limit 0.1 rad away (the default range, the joint near
 * pi): the target's law and the limit law compared at every call, the limit law sent. */
static uint32_t run_jointq_limit(void)
{
    j288_jointq_config_t jc;
    j288_jointq_target_t t;
    j288_reply_raw_t r;
    j288_cmd_raw_t cmd;
    uint32_t i, t0, t1;
    unsigned mask = 0u;
    memset(&jc, 0, sizeof jc);
    memset(&r, 0, sizeof r);
    jc.id = 3u;
    r.id = 3u;
    r.pos = 5000;
    r.out_pos = 3950u; /* 3.03 rad */
    r.speed = 400;     /* 1 rad/s toward the top */
    (void)j288_jointq_init(&jointq, &jc);
    for (i = 0u; i < J288_JOINT_DEFAULT_INIT_SAMPLES; i++) {
        (void)j288_jointq_take_reply(&jointq, &r, NULL);
    }
    j288_jointq_target_init(&jointq, &t);
    t.kp = 0;
    t.kd = J288_Q16(1.0);
    t.speed = J288_Q16(1.0);
    t0 = icount_now();
    for (i = 0u; i < ITERATIONS; i++) {
        t.speed = J288_Q16(1.0) + (j288_q16_t)(i & 7u);
        jointq_errors += (uint32_t)(j288_jointq_command(&jointq, &t, &cmd, &mask) != J288_OK);
    }
    t1 = icount_now();
    jointq_errors += (uint32_t)((mask & J288_JOINT_LIMITED) == 0u);
    return icount_between(t0, t1);
}

static const char *backend_name(void)
{
#if J288_CONFIG_CRC_BACKEND == J288_CRC_BACKEND_SLICE4
    return "slicing-by-4";
#elif J288_CONFIG_CRC_BACKEND == J288_CRC_BACKEND_NIBBLE
    return "nibble";
#elif J288_CONFIG_CRC_BACKEND == J288_CRC_BACKEND_BITWISE
    return "bitwise";
#elif (J288_CONFIG_CRC_BACKEND == J288_CRC_BACKEND_HW) && defined(J288_USER_CONFIG)
    return "the CRC unit (J288_CRC_BACKEND_HW, its function static inline)";
#elif J288_CONFIG_CRC_BACKEND == J288_CRC_BACKEND_HW
    return "the CRC unit (J288_CRC_BACKEND_HW, its function called)";
#else
    return "table";
#endif
}

static void row(const char *name, uint32_t floor, uint32_t lib)
{
    if (floor == 0u) {
        printf("| %s | | %lu | |\n", name, (unsigned long)lib);
    } else {
        printf("| %s | %lu | %lu | %lu.%02lux |\n", name, (unsigned long)floor,
               (unsigned long)lib, (unsigned long)(lib / floor),
               (unsigned long)((lib % floor) * 100u / floor));
    }
}

int main(void)
{
    const j288_crc_t unit_engine = {unit_crc32, &bench_unit};
    uint32_t ipt, f_codec, f_unit, f_engine, codec, codec_held, codec_unit, poll, isr, isr_new;
    uint8_t id;

    for (id = 0u; id < J288_MAX_SERVOS; id++) {
        j288_reply_raw_t r;
        memset(&r, 0, sizeof r);
        r.id = id;
        r.status = 1u;
        r.pos = 1000 * (int32_t)id;
        (void)j288_reply_encode(&r, replies[id], &soft_engine);
        memcpy((uint8_t *)floor_replies[id] + 2, replies[id], J288_REPLY_LEN);
    }
    {
        j288_cmd_raw_t cmd = worked_cmd();
        uint8_t f[J288_CMD_LEN];
        (void)j288_cmd_encode(&cmd, f, &soft_engine);
        bench_unit_answer[0] = j288_frame_crc_field(f, J288_CMD_LEN);
        bench_unit_answer[1] = j288_frame_crc_field(replies[3], J288_REPLY_LEN);
    }
    floor_tables();
    icount_start();
    ipt = icount_calibrate(CAL_LOOPS);
    f_codec = per_txn(RUN_ROW(1u, run_floor_codec(false)), ipt);
    f_unit = per_txn(RUN_ROW(1u, run_floor_codec(true)), ipt);
    f_engine = per_txn(RUN_ROW(1u, run_floor_engine()), ipt);
    codec = per_txn(RUN_ROW(2u, run_codec(NULL)), ipt);
    codec_held = per_txn(RUN_ROW(128u, run_codec_parser_unpacks()), ipt);
    codec_unit = per_txn(RUN_ROW(4u, run_codec(&unit_engine)), ipt);
    poll = per_txn(RUN_ROW(8u, run_bus_poll()), ipt);
    /* (With the CRC unit as the backend, the model's two answers do not fit 15 servos.) */
    isr = HW_BACKEND ? 0u : per_txn(RUN_ROW(16u, run_sched_isr(false)), ipt);
    isr_new = HW_BACKEND ? 0u : per_txn(RUN_ROW(64u, run_sched_isr(true)), ipt);
    printf("library CRC: %s | floor | j288 | ratio |\n", backend_name());
    if (!HW_BACKEND) {
        /* The like-for-like row first: the floor encodes and checks every frame too. */
        row("sweeps, a new command each transaction", f_engine, isr_new);
    }
    if (HW_BACKEND) {
        row("codec, CRC unit (compile-time backend)", f_unit, codec);
    } else {
        row("codec only (encode, parse, unpack)", f_codec, codec);
    }
    if (HW_BACKEND) {
        row("codec, CRC unit (compile-time backend), reply unpacked by the parser", f_unit,
            codec_held);
    } else {
        row("codec, reply unpacked by the parser (j288_parser_reply)", f_codec, codec_held);
    }
    row("codec, CRC unit (port crc32 op)", f_unit, codec_unit);
    row("bus, poll mode", 0u, poll);
    if (!HW_BACKEND) {
        row("scheduler sweeps, advance_in_isr", f_engine, isr);
    }
#if J288_CONFIG_SI
    row("joint (float facade): reply -> state", 0u, per_txn(RUN_ROW(32u, run_joint_reply()), ipt));
    row("joint (float facade): target -> command", 0u, per_txn(RUN_ROW(32u, run_joint_command()), ipt));
    if (joint_errors != 0u) {
        printf("bus_target: the joint layer failed (%lu)\n", (unsigned long)joint_errors);
        return 1;
    }
#endif
    row("joint (core): reply -> state", 0u, per_txn(RUN_ROW(32u, run_jointq_reply()), ipt));
    row("joint (core): target -> command", 0u, per_txn(RUN_ROW(32u, run_jointq_command()), ipt));
    row("joint (core): speed target near a limit -> command", 0u,
        per_txn(RUN_ROW(32u, run_jointq_limit()), ipt));
    if (jointq_errors != 0u) {
        printf("bus_target: the joint core failed (%lu)\n", (unsigned long)jointq_errors);
        return 1;
    }
    if (done_count != done_expected) {
        printf("bus_target: transactions did not complete (%lu of %lu)\n",
               (unsigned long)done_count, (unsigned long)done_expected);
        return 1;
    }
    return 0;
}
