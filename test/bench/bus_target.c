/*
 * Engine cost on Cortex-M: instructions per transaction through the bus engine (and the
 * scheduler), with port operations that do nothing, counted under QEMU -icount shift=0 (one
 * instruction per ns) by reading SysTick around ITERATIONS transactions. The ticks-to-
 * instructions factor is measured in the same run on a loop of known length.
 *
 * Rows: the codec alone (encode + parse + unpack: the floor any engine pays), the bus in poll
 * mode (submit, tx done, 26 bytes, idle, poll, guard), and continuous scheduler sweeps over
 * 15 servos with the bus advanced in the event calls (tx done, 26 bytes, idle, timer), the
 * way an MCU runs at the wire's limit. Built and run by `make bench-bus-target`.
 */
#include "j288/j288.h"

#include <stdio.h>
#include <string.h>

#define SYST_CSR (*(volatile uint32_t *)0xE000E010u)
#define SYST_RVR (*(volatile uint32_t *)0xE000E014u)
#define SYST_CVR (*(volatile uint32_t *)0xE000E018u)

#define ITERATIONS 300u
#define CAL_LOOPS  100000u

static uint32_t clock_us;
static uint8_t last_id;
static uint32_t done_count;
static j288_bus_t bus;
static j288_sched_t sch;
static uint8_t replies[J288_MAX_SERVOS][J288_REPLY_LEN];

static void systick_start(void)
{
    SYST_CSR = 0u;
    SYST_RVR = 0x00FFFFFFu;
    SYST_CVR = 0u;
    SYST_CSR = 5u; /* enable, processor clock, no interrupt */
}

static uint32_t systick_now(void)
{
    return SYST_CVR;
}
static uint32_t ticks_between(uint32_t a, uint32_t b)
{
    return (a - b) & 0x00FFFFFFu;
}

/* Instructions per SysTick tick, x1000, from a two-instruction loop. */
static uint32_t calibrate(void)
{
    uint32_t n = CAL_LOOPS;
    uint32_t t0, t1;
    t0 = systick_now();
    __asm volatile(".syntax unified\n1: subs %0, %0, #1\n\tbne 1b" : "+l"(n) : : "cc");
    t1 = systick_now();
    return (uint32_t)((2ull * CAL_LOOPS * 1000u) / ticks_between(t0, t1));
}

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

static const j288_port_t port = {op_start_tx, op_now_us, NULL,       NULL,      op_arm_timeout,
                                 NULL,        NULL,      op_nothing, op_nothing};

static void on_done(void *user, const j288_txn_t *txn)
{
    (void)user;
    if (txn->result == J288_OK) {
        done_count++;
    }
}

/* ---- rows */

static uint32_t run_codec(void)
{
    j288_parser_t parser;
    j288_cmd_raw_t cmd;
    j288_reply_raw_t r;
    uint8_t frame[J288_CMD_LEN];
    uint32_t i, t0, t1;
    memset(&cmd, 0, sizeof cmd);
    cmd.id = 3u;
    (void)j288_parser_init(&parser, J288_PARSE_REPLY, NULL);
    t0 = systick_now();
    for (i = 0u; i < ITERATIONS; i++) {
        size_t used;
        (void)j288_cmd_encode(&cmd, frame, NULL);
        if (j288_parser_feed(&parser, replies[3], J288_REPLY_LEN, &used) == J288_PARSE_FRAME) {
            j288_reply_unpack(j288_parser_frame(&parser), &r);
            done_count++;
        }
    }
    t1 = systick_now();
    return ticks_between(t0, t1);
}

static uint32_t run_bus_poll(void)
{
    j288_cmd_raw_t cmd;
    uint32_t i, t0, t1;
    memset(&cmd, 0, sizeof cmd);
    cmd.id = 3u;
    (void)j288_bus_init(&bus, &port, NULL, NULL);
    t0 = systick_now();
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
    t1 = systick_now();
    return ticks_between(t0, t1);
}

static uint32_t run_sched_isr(void)
{
    j288_bus_config_t bc;
    j288_sched_config_t sc;
    uint32_t i, t0, t1;
    uint8_t id;
    memset(&bc, 0, sizeof bc);
    memset(&sc, 0, sizeof sc);
    bc.advance_in_isr = true;
    sc.continuous = true;
    (void)j288_bus_init(&bus, &port, NULL, &bc);
    (void)j288_sched_init(&sch, &bus, &sc);
    for (id = 0u; id < J288_MAX_SERVOS; id++) {
        (void)j288_sched_enable(&sch, id, true);
    }
    (void)j288_sched_start_sweep(&sch, clock_us);
    t0 = systick_now();
    for (i = 0u; i < ITERATIONS; i++) {
        j288_bus_on_tx_done(&bus);
        j288_bus_on_rx(&bus, replies[last_id], J288_REPLY_LEN);
        clock_us += 88u;
        j288_bus_on_rx_idle(&bus);
        clock_us += 2u;
        j288_bus_on_timer(&bus); /* the guard ends: the next command starts */
    }
    t1 = systick_now();
    return ticks_between(t0, t1);
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
    (void)j288_joint_init(&joint, &jc);
    for (i = 0u; i < J288_JOINT_DEFAULT_INIT_SAMPLES; i++) {
        (void)j288_joint_take_reply(&joint, &r, NULL);
    }
    t0 = systick_now();
    for (i = 0u; i < ITERATIONS; i++) {
        unsigned ev;
        r.pos = 5000 + (int32_t)(i & 7u);
        joint_errors += (uint32_t)(j288_joint_take_reply(&joint, &r, &ev) != J288_OK);
    }
    t1 = systick_now();
    joint_errors += (uint32_t)!j288_joint_state(&joint)->known;
    return ticks_between(t0, t1);
}

static uint32_t run_joint_command(void)
{
    j288_joint_target_t t;
    j288_cmd_raw_t cmd;
    uint32_t i, t0, t1;
    j288_joint_target_init(&joint, &t);
    t.kp = (j288_real_t)20;
    t.kd = (j288_real_t)0.5;
    t0 = systick_now();
    for (i = 0u; i < ITERATIONS; i++) {
        t.pos = (j288_real_t)(i & 7u) * (j288_real_t)0.01;
        joint_errors += (uint32_t)(j288_joint_command(&joint, &t, &cmd, NULL) != J288_OK);
    }
    t1 = systick_now();
    return ticks_between(t0, t1);
}
#endif

int main(void)
{
    uint32_t ipt, codec, poll, isr;
    uint8_t id;

    for (id = 0u; id < J288_MAX_SERVOS; id++) {
        j288_reply_raw_t r;
        memset(&r, 0, sizeof r);
        r.id = id;
        r.status = 1u;
        r.pos = 1000 * (int32_t)id;
        (void)j288_reply_encode(&r, replies[id], NULL);
    }
    systick_start();
    ipt = calibrate();
    codec = per_txn(run_codec(), ipt);
    poll = per_txn(run_bus_poll(), ipt);
    isr = per_txn(run_sched_isr(), ipt);
    printf("| codec only (encode, parse, unpack) | %lu |\n", (unsigned long)codec);
    printf("| bus, poll mode | %lu |\n", (unsigned long)poll);
    printf("| scheduler sweeps, advance_in_isr | %lu |\n", (unsigned long)isr);
#if J288_CONFIG_SI
    printf("| joint: reply -> state | %lu |\n", (unsigned long)per_txn(run_joint_reply(), ipt));
    printf("| joint: target -> command | %lu |\n",
           (unsigned long)per_txn(run_joint_command(), ipt));
    if (joint_errors != 0u) {
        printf("bus_target: the joint layer failed (%lu)\n", (unsigned long)joint_errors);
        return 1;
    }
#endif
    if (done_count != 2u * ITERATIONS || sch.slot[14].stats.successes == 0u) {
        printf("bus_target: transactions did not complete (%lu)\n", (unsigned long)done_count);
        return 1;
    }
    return 0;
}
