/* The cycle scheduler on the bus engine and the scripted fake port. */
#include "unity.h"

#include "fake_port.h"
#include "j288/j288.h"

#include <string.h>

void setUp(void) {}
void tearDown(void) {}

#define US     1000u
#define TXN_US 88u /* 33.3 tx + 10 turnaround + 43.3 reply, floored, + 2 guard */

static fake_port_t fp;
static j288_bus_t bus;
static j288_sched_t sch;

#define MAX_EV 64
static j288_event_t events[MAX_EV];
static int nev;
static uint32_t sweep_calls;
static uint32_t last_sweep_no;

static void on_event(void *user, const j288_event_t *ev)
{
    TEST_ASSERT_EQUAL_PTR(&sch, user);
    if (nev < MAX_EV) {
        events[nev] = *ev;
    }
    nev++;
}

static bool estop_on_sweep; /* on_sweep makes an emergency stop */

static void on_sweep(void *user, uint32_t sweep, uint32_t now_us)
{
    (void)user;
    sweep_calls++;
    last_sweep_no = sweep;
    if (estop_on_sweep) {
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_estop(&sch, now_us));
    }
}

static j288_reply_raw_t reply_for(uint8_t id)
{
    j288_reply_raw_t r;
    memset(&r, 0, sizeof r);
    r.id = id;
    r.status = 1u;
    r.voltage_raw = 48u;
    r.pos = 1000 * (int32_t)id;
    return r;
}

static void setup_all(bool isr, bool continuous, uint8_t offline_after)
{
    j288_bus_config_t bc;
    j288_sched_config_t sc;
    memset(&bc, 0, sizeof bc);
    memset(&sc, 0, sizeof sc);
    bc.advance_in_isr = isr;
    sc.continuous = continuous;
    sc.offline_after = offline_after;
    sc.on_event = on_event;
    sc.on_sweep = on_sweep;
    sc.user = &sch;
    nev = 0;
    sweep_calls = 0u;
    last_sweep_no = 0u;
    estop_on_sweep = false;
    fake_port_init(&fp);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_init(&bus, &fp.ops, &fp, &bc));
    fake_port_attach(&fp, &bus);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_init(&sch, &bus, &sc));
    if (!isr) {
        fp.poll_fn = fake_port_poll_sched;
        fp.poll_user = &sch;
    }
}

static void add_servos(const uint8_t *ids, size_t n)
{
    size_t i;
    for (i = 0u; i < n; i++) {
        j288_reply_raw_t r = reply_for(ids[i]);
        fake_port_add_servo(&fp, ids[i], &r);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_enable(&sch, ids[i], true));
    }
}

static j288_cmd_raw_t foc(uint8_t id, int32_t pos)
{
    j288_cmd_raw_t c;
    memset(&c, 0, sizeof c);
    c.id = id;
    c.status = J288_MODE_FOC;
    c.watchdog = true;
    c.pos = pos;
    c.kp = 100;
    c.kd = 10;
    return c;
}

static void assert_frame_cmd(uint32_t i, const j288_cmd_raw_t *cmd)
{
    uint8_t want[J288_CMD_LEN];
    const fake_frame_t *f = fake_port_frame(&fp, i);
    TEST_ASSERT_NOT_NULL(f);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_cmd_encode(cmd, want, NULL));
    TEST_ASSERT_EQUAL_HEX8_ARRAY(want, f->data, J288_CMD_LEN);
}

static uint8_t frame_id(uint32_t i)
{
    return (uint8_t)(fake_port_frame(&fp, i)->data[2] & 0x0Fu);
}
static bool frame_wd(uint32_t i)
{
    return (fake_port_frame(&fp, i)->data[2] & 0x80u) != 0u;
}

static int count_events(j288_event_kind_t kind, uint8_t id)
{
    int i, n = 0;
    for (i = 0; i < nev && i < MAX_EV; i++) {
        if ((events[i].kind == kind) && (events[i].id == id)) {
            n++;
        }
    }
    return n;
}

static void sweep_once(void)
{
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_start_sweep(&sch, fake_port_now_us(&fp)));
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, fp.now_ns + 20000u * US));
    TEST_ASSERT_FALSE(j288_sched_busy(&sch));
}

/* ---- setup and commands */

static void test_init_and_set_cmd_checks(void)
{
    j288_cmd_raw_t c = foc(3u, 5);
    j288_cmd_raw_t lock;
    uint8_t i;
    setup_all(false, false, 0u);
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_sched_init(NULL, &bus, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_sched_init(&sch, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_init(&sch, &bus, NULL));
    for (i = 0u; i < J288_MAX_SERVOS; i++) {
        const j288_slot_t *sl = j288_sched_slot(&sch, i);
        memset(&lock, 0, sizeof lock);
        lock.id = i;
        lock.watchdog = true;
        TEST_ASSERT_NOT_NULL(sl);
        TEST_ASSERT_FALSE(sl->enabled);
        TEST_ASSERT_FALSE(sl->online);
        TEST_ASSERT_EQUAL_MEMORY(&lock, &sl->cmd, sizeof lock);
    }
    TEST_ASSERT_NULL(j288_sched_slot(&sch, 15u));
    TEST_ASSERT_NULL(j288_sched_slot(NULL, 1u));
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_ID, j288_sched_enable(&sch, 15u, true));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_sched_enable(NULL, 1u, true));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_sched_set_cmd(&sch, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_sched_set_cmd(NULL, &c));
    c.id = 15u;
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_ID, j288_sched_set_cmd(&sch, &c));
    c = foc(3u, 5);
    c.status = 2u;
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_STATUS, j288_sched_set_cmd(&sch, &c));
    c = foc(3u, 5);
    c.kp = -1;
    TEST_ASSERT_EQUAL_INT(J288_ERR_NEG_GAIN, j288_sched_set_cmd(&sch, &c));
    c = foc(3u, 5);
    c.kd = -1;
    TEST_ASSERT_EQUAL_INT(J288_ERR_NEG_GAIN, j288_sched_set_cmd(&sch, &c));
    TEST_ASSERT_EQUAL_INT32(0, j288_sched_slot(&sch, 3u)->cmd.pos); /* unchanged */
    c = foc(3u, 5);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_set_cmd(&sch, &c));
    TEST_ASSERT_EQUAL_INT32(5, j288_sched_slot(&sch, 3u)->cmd.pos);
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_ID, j288_sched_clear_watchdog(&sch, 15u));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_sched_clear_watchdog(NULL, 1u));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_sched_start_sweep(NULL, 0u));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_sched_estop(NULL, 0u));
    j288_sched_poll(NULL, 0u);
    TEST_ASSERT_FALSE(j288_sched_busy(NULL));
    TEST_ASSERT_EQUAL_UINT32(0u, j288_sched_sweeps(NULL));
    TEST_ASSERT_EQUAL_UINT32(0u, fp.nframes);
}

static void test_set_cmd_si(void)
{
    j288_cmd_si_t si;
    j288_cmd_raw_t raw;
    setup_all(false, false, 0u);
    memset(&si, 0, sizeof si);
    si.id = 2u;
    si.status = J288_MODE_FOC;
    si.watchdog = true;
    si.pos = 1.5;
    si.kp = (j288_real_t)0.01;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_set_cmd_si(&sch, &si, J288_SIDE_ROTOR));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_cmd_from_si(&si, J288_SIDE_ROTOR, &raw));
    TEST_ASSERT_EQUAL_MEMORY(&raw, &j288_sched_slot(&sch, 2u)->cmd, sizeof raw);
    si.kp = -1.0;
    TEST_ASSERT_EQUAL_INT(J288_ERR_NEG_GAIN, j288_sched_set_cmd_si(&sch, &si, J288_SIDE_ROTOR));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_enable(&sch, 2u, true));
    sweep_once();
    assert_frame_cmd(0u, &raw);
}

/* ---- sweeps */

static void test_one_sweep_in_order(void)
{
    static const uint8_t ids[4] = {9u, 1u, 5u, 2u};
    j288_cmd_raw_t c5 = foc(5u, -1234);
    j288_cmd_raw_t c1 = foc(1u, 0);
    j288_cmd_raw_t l2, l9;
    memset(&l2, 0, sizeof l2);
    l2.id = 2u;
    l2.watchdog = true;
    l9 = l2;
    l9.id = 9u;
    setup_all(false, false, 0u);
    add_servos(ids, 4u);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_set_cmd(&sch, &c5));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_set_cmd(&sch, &c1));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_start_sweep(&sch, 0u));
    TEST_ASSERT_TRUE(j288_sched_busy(&sch));
    TEST_ASSERT_EQUAL_INT(J288_ERR_BUSY, j288_sched_start_sweep(&sch, 0u));
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 20000u * US));
    TEST_ASSERT_EQUAL_UINT32(4u, fp.nframes);
    assert_frame_cmd(0u, &c1);
    assert_frame_cmd(1u, &l2);
    assert_frame_cmd(2u, &c5);
    assert_frame_cmd(3u, &l9);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_sched_sweeps(&sch));
    TEST_ASSERT_EQUAL_UINT32(1u, sweep_calls);
    TEST_ASSERT_EQUAL_UINT32(1u, last_sweep_no);
    TEST_ASSERT_EQUAL_INT32(5000, j288_sched_slot(&sch, 5u)->reply.pos);
    TEST_ASSERT_TRUE(j288_sched_slot(&sch, 5u)->has_reply);
    TEST_ASSERT_TRUE(j288_sched_slot(&sch, 5u)->online);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_sched_slot(&sch, 5u)->stats.transactions);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_sched_slot(&sch, 5u)->stats.successes);
    TEST_ASSERT_EQUAL_UINT32(86u, j288_sched_slot(&sch, 5u)->stats.last_latency_us);
    TEST_ASSERT_EQUAL_UINT32(2u * TXN_US + 86u, j288_sched_slot(&sch, 5u)->reply_us);
    TEST_ASSERT_FALSE(j288_sched_slot(&sch, 3u)->has_reply);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_sched_slot(&sch, 3u)->stats.transactions);
    TEST_ASSERT_EQUAL_INT(4, nev);
    TEST_ASSERT_EQUAL_INT(1, count_events(J288_EV_ONLINE, 9u));
    TEST_ASSERT_EQUAL_INT(J288_EV_ONLINE, events[0].kind);
    TEST_ASSERT_EQUAL_UINT8(1u, events[0].id);
    /* back to back inside the sweep: 88 us per servo */
    TEST_ASSERT_EQUAL_UINT32(3u * TXN_US, fake_port_frame(&fp, 3u)->start_us);
}

static void test_empty_sweep_ends_at_once(void)
{
    setup_all(false, true, 0u);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_start_sweep(&sch, 0u));
    TEST_ASSERT_FALSE(j288_sched_busy(&sch));
    TEST_ASSERT_EQUAL_UINT32(1u, j288_sched_sweeps(&sch));
    TEST_ASSERT_EQUAL_UINT32(0u, fp.nframes);
}

static void test_start_sweep_refused_while_bus_busy(void)
{
    static const uint8_t ids[1] = {1u};
    j288_cmd_raw_t c = foc(7u, 0);
    setup_all(false, false, 0u);
    add_servos(ids, 1u);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_submit(&bus, &c, 0u, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_BUSY, j288_sched_start_sweep(&sch, 0u));
    TEST_ASSERT_FALSE(j288_sched_busy(&sch));
    TEST_ASSERT_EQUAL_UINT32(0u, j288_sched_sweeps(&sch));
    TEST_ASSERT_EQUAL_UINT32(1u, fp.nframes);
}

static void test_back_to_back_sweeps_15_servos_from_interrupts(void)
{
    uint8_t ids[15];
    uint8_t i;
    uint32_t f;
    for (i = 0u; i < 15u; i++) {
        ids[i] = i;
    }
    setup_all(true, true, 0u);
    add_servos(ids, 15u);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_start_sweep(&sch, 0u));
    fake_port_run_until(&fp, 10000u * US); /* nobody polls */
    /* 15 x 88 us = 1320 us per sweep: 7 complete in 10 ms */
    TEST_ASSERT_EQUAL_UINT32(7u, j288_sched_sweeps(&sch));
    TEST_ASSERT_EQUAL_UINT32(7u, sweep_calls);
    TEST_ASSERT_TRUE(j288_sched_busy(&sch));
    for (f = 0u; f < 105u; f++) {
        TEST_ASSERT_EQUAL_UINT8(f % 15u, frame_id(f));
        TEST_ASSERT_EQUAL_UINT32(f * TXN_US, fake_port_frame(&fp, f)->start_us);
    }
    for (i = 0u; i < 15u; i++) {
        const j288_slot_t *sl = j288_sched_slot(&sch, i);
        TEST_ASSERT_TRUE(sl->stats.successes >= 7u);
        TEST_ASSERT_EQUAL_UINT32(sl->stats.transactions, sl->stats.successes);
        TEST_ASSERT_EQUAL_UINT32(86u, sl->stats.worst_latency_us);
    }
    TEST_ASSERT_EQUAL_INT(15, nev); /* 15 ONLINE, nothing else */
    TEST_ASSERT_EQUAL_INT(0, fp.tx_overlap_errors);
    TEST_ASSERT_EQUAL_INT(0, fp.lock_errors);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_stats(&bus)->stale_bytes);
}

static void test_servo_drops_out_and_comes_back(void)
{
    static const uint8_t ids[3] = {1u, 2u, 3u};
    int k;
    setup_all(false, false, 3u);
    add_servos(ids, 3u);
    sweep_once();
    TEST_ASSERT_TRUE(j288_sched_slot(&sch, 2u)->online);
    fp.servo[2].present = false;
    for (k = 0; k < 2; k++) {
        sweep_once();
    }
    TEST_ASSERT_TRUE(j288_sched_slot(&sch, 2u)->online); /* 2 failures: not yet */
    TEST_ASSERT_EQUAL_INT(0, count_events(J288_EV_OFFLINE, 2u));
    sweep_once();
    TEST_ASSERT_FALSE(j288_sched_slot(&sch, 2u)->online);
    TEST_ASSERT_EQUAL_INT(1, count_events(J288_EV_OFFLINE, 2u));
    sweep_once();
    TEST_ASSERT_EQUAL_INT(1, count_events(J288_EV_OFFLINE, 2u)); /* once */
    TEST_ASSERT_EQUAL_UINT32(4u, j288_sched_slot(&sch, 2u)->stats.timeouts);
    TEST_ASSERT_EQUAL_UINT32(4u, j288_sched_slot(&sch, 2u)->stats.consecutive_failures);
    TEST_ASSERT_EQUAL_INT(J288_ERR_TIMEOUT, j288_sched_slot(&sch, 2u)->last_result);
    /* latencies are of good replies only */
    TEST_ASSERT_EQUAL_UINT32(86u, j288_sched_slot(&sch, 2u)->stats.worst_latency_us);
    TEST_ASSERT_TRUE(j288_sched_slot(&sch, 3u)->online); /* the others are unaffected */
    TEST_ASSERT_EQUAL_UINT32(5u, j288_sched_slot(&sch, 3u)->stats.successes);
    fp.servo[2].present = true;
    sweep_once();
    TEST_ASSERT_TRUE(j288_sched_slot(&sch, 2u)->online);
    TEST_ASSERT_EQUAL_INT(2, count_events(J288_EV_ONLINE, 2u));
    TEST_ASSERT_EQUAL_UINT32(0u, j288_sched_slot(&sch, 2u)->stats.consecutive_failures);
    TEST_ASSERT_EQUAL_UINT32(2u, j288_sched_slot(&sch, 2u)->stats.successes);
    TEST_ASSERT_EQUAL_UINT32(6u, j288_sched_sweeps(&sch));
}

static void test_fault_and_warning_events(void)
{
    static const uint8_t ids[1] = {4u};
    setup_all(false, false, 0u);
    add_servos(ids, 1u);
    fp.servo[4].reply.faults = J288_FAULT_UNDER_VOLTAGE;
    sweep_once();
    TEST_ASSERT_EQUAL_INT(1, count_events(J288_EV_FAULTS_CHANGED, 4u));
    TEST_ASSERT_EQUAL_UINT32(0u, events[1].old_bits);
    TEST_ASSERT_EQUAL_UINT32(J288_FAULT_UNDER_VOLTAGE, events[1].new_bits);
    sweep_once(); /* unchanged: no event */
    TEST_ASSERT_EQUAL_INT(2, nev);
    fp.servo[4].reply.faults = J288_FAULT_UNDER_VOLTAGE | J288_FAULT_CASE_TEMP;
    fp.servo[4].reply.warnings = J288_WARN_LOW_SUPPLY;
    sweep_once();
    TEST_ASSERT_EQUAL_INT(4, nev);
    TEST_ASSERT_EQUAL_INT(J288_EV_FAULTS_CHANGED, events[2].kind);
    TEST_ASSERT_EQUAL_UINT32(J288_FAULT_UNDER_VOLTAGE, events[2].old_bits);
    TEST_ASSERT_EQUAL_UINT32(J288_FAULT_UNDER_VOLTAGE | J288_FAULT_CASE_TEMP, events[2].new_bits);
    TEST_ASSERT_EQUAL_INT(J288_EV_WARNINGS_CHANGED, events[3].kind);
    TEST_ASSERT_EQUAL_UINT32(0u, events[3].old_bits);
    TEST_ASSERT_EQUAL_UINT32(J288_WARN_LOW_SUPPLY, events[3].new_bits);
}

static void test_watchdog_trip_and_clear(void)
{
    static const uint8_t ids[2] = {6u, 7u};
    setup_all(false, false, 0u);
    add_servos(ids, 2u);
    fp.servo[6].reply.watchdog_tripped = true;
    sweep_once();
    TEST_ASSERT_EQUAL_INT(1, count_events(J288_EV_WATCHDOG_TRIPPED, 6u));
    TEST_ASSERT_TRUE(j288_sched_slot(&sch, 6u)->reply.watchdog_tripped);
    TEST_ASSERT_TRUE(frame_wd(0u));
    sweep_once(); /* still tripped: reported once */
    TEST_ASSERT_EQUAL_INT(1, count_events(J288_EV_WATCHDOG_TRIPPED, 6u));

    /* Clearing sends the watchdog bit 0 once; a failed attempt keeps the request. */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_clear_watchdog(&sch, 6u));
    fp.servo[6].present = false;
    sweep_once();
    TEST_ASSERT_FALSE(frame_wd(4u));
    TEST_ASSERT_TRUE(frame_wd(5u)); /* servo 7 untouched */
    TEST_ASSERT_TRUE(j288_sched_slot(&sch, 6u)->clear_watchdog);
    fp.servo[6].present = true;
    fp.servo[6].reply.watchdog_tripped = true;
    sweep_once();
    TEST_ASSERT_FALSE(frame_wd(6u));
    TEST_ASSERT_FALSE(fp.servo[6].last_cmd.watchdog);
    TEST_ASSERT_FALSE(j288_sched_slot(&sch, 6u)->clear_watchdog);
    TEST_ASSERT_EQUAL_INT(1, count_events(J288_EV_WATCHDOG_CLEARED, 6u));
    TEST_ASSERT_FALSE(j288_sched_slot(&sch, 6u)->reply.watchdog_tripped);
    sweep_once();
    TEST_ASSERT_TRUE(frame_wd(8u)); /* the slot's own setting again */
    TEST_ASSERT_EQUAL_INT(1, count_events(J288_EV_WATCHDOG_CLEARED, 6u));
    TEST_ASSERT_EQUAL_UINT32(10u, fp.nframes);
}

static void test_wrong_id_and_crc_in_slot_stats(void)
{
    static const uint8_t ids[2] = {1u, 2u};
    setup_all(false, false, 0u);
    add_servos(ids, 2u);
    fp.servo[1].reply_id = 11;
    fp.servo[2].corrupt = true;
    sweep_once();
    TEST_ASSERT_EQUAL_UINT32(1u, j288_sched_slot(&sch, 1u)->stats.wrong_id);
    TEST_ASSERT_EQUAL_INT(J288_ERR_WRONG_ID, j288_sched_slot(&sch, 1u)->last_result);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_sched_slot(&sch, 2u)->stats.crc_errors);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_sched_slot(&sch, 2u)->stats.consecutive_failures);
    TEST_ASSERT_FALSE(j288_sched_slot(&sch, 2u)->online);
    TEST_ASSERT_EQUAL_INT(0, nev);
}

static void test_collision_in_slot_stats(void)
{
    static const uint8_t ids[1] = {1u};
    j288_bus_config_t bc;
    j288_sched_config_t sc;
    memset(&bc, 0, sizeof bc);
    memset(&sc, 0, sizeof sc);
    bc.echo = true;
    fake_port_init(&fp);
    fp.echo = true;
    fp.echo_flip_at = 3;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_init(&bus, &fp.ops, &fp, &bc));
    fake_port_attach(&fp, &bus);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_init(&sch, &bus, &sc));
    fp.poll_fn = fake_port_poll_sched;
    fp.poll_user = &sch;
    add_servos(ids, 1u);
    sweep_once();
    TEST_ASSERT_EQUAL_UINT32(1u, j288_sched_slot(&sch, 1u)->stats.collisions);
}

static void test_estop_while_sweeping(void)
{
    static const uint8_t ids[4] = {0u, 1u, 2u, 3u};
    j288_cmd_raw_t stop, lock;
    uint8_t i;
    memset(&stop, 0, sizeof stop);
    stop.id = 15u;
    stop.watchdog = false; /* the stop clears a trip: watchdog bit 0 */
    setup_all(true, true, 0u);
    add_servos(ids, 4u);
    for (i = 0u; i < 4u; i++) {
        j288_cmd_raw_t c = foc(i, 100 * (int32_t)i);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_set_cmd(&sch, &c));
    }
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_start_sweep(&sch, 0u));
    fake_port_run_until(&fp, (TXN_US + 20u) * US); /* servo 1's command on the wire */
    TEST_ASSERT_EQUAL_UINT32(2u, fp.nframes);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_estop(&sch, fake_port_now_us(&fp)));
    TEST_ASSERT_FALSE(j288_sched_busy(&sch));
    TEST_ASSERT_EQUAL_INT(0, fp.lock_depth);
    fake_port_run_until(&fp, 2000u * US);
    TEST_ASSERT_EQUAL_UINT32(3u, fp.nframes); /* the stop, and nothing after it */
    assert_frame_cmd(2u, &stop);
    TEST_ASSERT_EQUAL_UINT32(TXN_US + 86u, fake_port_frame(&fp, 2u)->start_us);
    TEST_ASSERT_EQUAL_INT(J288_ERR_ABORTED, j288_sched_slot(&sch, 1u)->last_result);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_sched_slot(&sch, 1u)->stats.other_errors);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_sched_slot(&sch, 1u)->stats.consecutive_failures);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_sched_slot(&sch, 2u)->stats.transactions);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_sched_sweeps(&sch));
    /* on the bus: servo 0 ok, servo 1 aborted, the stop in estops only */
    TEST_ASSERT_EQUAL_UINT32(2u, j288_bus_stats(&bus)->transactions);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->ok);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_stats(&bus)->failed);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->aborted);
    for (i = 0u; i < 4u; i++) {
        TEST_ASSERT_EQUAL_UINT8(J288_MODE_LOCK, fp.servo[i].last_cmd.status);
        TEST_ASSERT_EQUAL_UINT8(15u, fp.servo[i].last_cmd.id);
    }
    /* Commands became lock: a later sweep does not resume motion. */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_start_sweep(&sch, fake_port_now_us(&fp)));
    fake_port_run_until(&fp, 2200u * US);
    memset(&lock, 0, sizeof lock);
    lock.id = 0u;
    lock.watchdog = true;
    assert_frame_cmd(3u, &lock);
    TEST_ASSERT_EQUAL_INT(0, fp.lock_errors);
}

/* A sweep started while the stop waits for the transaction on the wire is refused, and the
 * frame on the wire stays as it was sent: with echo on, its echo still matches (no collision),
 * and the aborted transaction's frame is the command that was set. */
static void test_start_refused_under_estop_leaves_the_frame_on_the_wire(void)
{
    static const uint8_t ids[1] = {1u};
    j288_cmd_raw_t c = foc(1u, 4321);
    j288_bus_config_t bc;
    j288_sched_config_t sc;
    memset(&bc, 0, sizeof bc);
    memset(&sc, 0, sizeof sc);
    bc.echo = true;
    fake_port_init(&fp);
    fp.echo = true;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_init(&bus, &fp.ops, &fp, &bc));
    fake_port_attach(&fp, &bus);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_init(&sch, &bus, &sc));
    fp.poll_fn = fake_port_poll_sched;
    fp.poll_user = &sch;
    add_servos(ids, 1u);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_set_cmd(&sch, &c));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_start_sweep(&sch, 0u));
    fake_port_run_until(&fp, 10u * US); /* the command half sent, half its echo heard */
    TEST_ASSERT_EQUAL_INT(J288_BUS_TX, j288_bus_state(&bus));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_estop(&sch, fake_port_now_us(&fp)));
    TEST_ASSERT_EQUAL_INT(J288_ERR_BUSY, j288_sched_start_sweep(&sch, fake_port_now_us(&fp)));
    fake_port_run_until(&fp, 2000u * US);
    TEST_ASSERT_EQUAL_UINT32(2u, fp.nframes); /* the command, then the stop */
    assert_frame_cmd(0u, &c);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_stats(&bus)->collisions);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->aborted);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->estops);
    /* the next sweep sends the lock estop made */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_start_sweep(&sch, fake_port_now_us(&fp)));
    fake_port_run_until(&fp, 4000u * US);
    TEST_ASSERT_EQUAL_UINT32(3u, fp.nframes);
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_LOCK, fp.servo[1].last_cmd.status);
    TEST_ASSERT_EQUAL_UINT8(1u, fp.servo[1].last_cmd.id);
}

static void estop_on_fault(void *user, const j288_event_t *ev)
{
    on_event(user, ev);
    if (ev->kind == J288_EV_FAULTS_CHANGED) {
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_estop(&sch, 0u));
    }
}

static void test_estop_from_an_event_callback(void)
{
    static const uint8_t ids[3] = {0u, 1u, 2u};
    j288_cmd_raw_t stop;
    memset(&stop, 0, sizeof stop);
    stop.id = 15u;
    stop.watchdog = false;
    setup_all(true, true, 0u);
    sch.cfg.on_event = estop_on_fault;
    add_servos(ids, 3u);
    fp.servo[1].reply.faults = J288_FAULT_OVER_CURRENT;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_start_sweep(&sch, 0u));
    fake_port_run_until(&fp, 5000u * US);
    /* servo 0, servo 1 (fault: stop), then the stop frame right after servo 1's reply */
    TEST_ASSERT_EQUAL_UINT32(3u, fp.nframes);
    assert_frame_cmd(2u, &stop);
    TEST_ASSERT_EQUAL_UINT32(TXN_US + 86u, fake_port_frame(&fp, 2u)->start_us);
    TEST_ASSERT_FALSE(j288_sched_busy(&sch));
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->estops);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_stats(&bus)->aborted);
    TEST_ASSERT_EQUAL_INT(0, fp.lock_errors);
}

/* A continuous scheduler whose on_sweep makes an emergency stop does not start the next
 * sweep: the stop is the last frame. */
static void test_estop_from_on_sweep_ends_continuous_sweeps(void)
{
    static const uint8_t ids[3] = {0u, 1u, 2u};
    j288_cmd_raw_t stop;
    memset(&stop, 0, sizeof stop);
    stop.id = 15u;
    stop.watchdog = false;
    setup_all(true, true, 0u);
    add_servos(ids, 3u);
    estop_on_sweep = true;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_start_sweep(&sch, 0u));
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 10000u * US));
    TEST_ASSERT_FALSE(j288_sched_busy(&sch));
    TEST_ASSERT_EQUAL_UINT32(1u, j288_sched_sweeps(&sch));
    TEST_ASSERT_EQUAL_UINT32(1u, sweep_calls);
    TEST_ASSERT_EQUAL_UINT32(4u, fp.nframes);
    assert_frame_cmd(3u, &stop);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->estops);
    TEST_ASSERT_EQUAL_UINT32(3u, j288_bus_stats(&bus)->ok);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_slot(&sch, 0u)->last_result); /* not retried */
}

/* Interrupt-driven sweeps on a port without lock/unlock ops: thread-side calls simply run. */
static void test_isr_sweeps_without_lock_ops(void)
{
    static const uint8_t ids[2] = {5u, 6u};
    j288_bus_config_t bc;
    j288_cmd_raw_t c = foc(5u, 55);
    memset(&bc, 0, sizeof bc);
    bc.advance_in_isr = true;
    nev = 0;
    fake_port_init(&fp);
    fp.ops.lock = NULL;
    fp.ops.unlock = NULL;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_init(&bus, &fp.ops, &fp, &bc));
    fake_port_attach(&fp, &bus);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_init(&sch, &bus, NULL));
    add_servos(ids, 2u);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_set_cmd(&sch, &c));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_clear_watchdog(&sch, 6u));
    sweep_once();
    TEST_ASSERT_EQUAL_UINT32(2u, fp.nframes);
    assert_frame_cmd(0u, &c);
    TEST_ASSERT_FALSE(frame_wd(1u));
    TEST_ASSERT_EQUAL_UINT32(1u, j288_sched_slot(&sch, 6u)->stats.successes);
    TEST_ASSERT_EQUAL_UINT32(0u, fp.lock_calls);
}

static void test_default_config_without_handlers(void)
{
    static const uint8_t ids[2] = {3u, 4u};
    j288_cmd_si_t si;
    setup_all(false, false, 0u);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_init(&sch, &bus, NULL)); /* no handlers */
    memset(&si, 0, sizeof si);
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_sched_set_cmd_si(NULL, &si, J288_SIDE_ROTOR));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_sched_set_cmd_si(&sch, NULL, J288_SIDE_ROTOR));
    add_servos(ids, 2u);
    fp.servo[4].present = false;
    sweep_once();
    sweep_once();
    sweep_once();
    TEST_ASSERT_EQUAL_INT(0, nev);
    TEST_ASSERT_TRUE(j288_sched_slot(&sch, 3u)->online);
    TEST_ASSERT_EQUAL_UINT32(3u, j288_sched_slot(&sch, 4u)->stats.consecutive_failures);
    TEST_ASSERT_EQUAL_UINT32(3u, j288_sched_sweeps(&sch));
    TEST_ASSERT_EQUAL_UINT32(0u, sweep_calls);
}

static void test_control_loop_ticks_in_poll_mode(void)
{
    static const uint8_t ids[3] = {0u, 1u, 2u};
    uint32_t tick;
    setup_all(false, false, 0u);
    add_servos(ids, 3u);
    for (tick = 0u; tick < 10u; tick++) {
        fake_port_run_until(&fp, (uint64_t)tick * 1000u * US);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_start_sweep(&sch, fake_port_now_us(&fp)));
    }
    fake_port_run_until(&fp, 10000u * US);
    TEST_ASSERT_EQUAL_UINT32(10u, j288_sched_sweeps(&sch));
    TEST_ASSERT_EQUAL_UINT32(30u, fp.nframes);
    TEST_ASSERT_EQUAL_UINT32(9000u + 2u * TXN_US, fake_port_frame(&fp, 29u)->start_us);
}

/* ---- the per-reply hook */

static uint32_t nreply_calls;
static int events_at_reply; /* nev when the hook ran */

/* Replaces servo 2's next command with a lock, as the joint layer does on a mismatch. */
static void on_reply_lock_two(void *user, uint8_t id, const j288_slot_t *slot)
{
    TEST_ASSERT_EQUAL_PTR(&sch, user);
    TEST_ASSERT_TRUE(slot->has_reply);
    TEST_ASSERT_EQUAL_UINT8(id, slot->reply.id);
    TEST_ASSERT_EQUAL_PTR(j288_sched_slot(&sch, id), slot);
    nreply_calls++;
    events_at_reply = nev;
    if (id == 2u) {
        j288_cmd_raw_t lock;
        memset(&lock, 0, sizeof lock);
        lock.id = 2u;
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_set_cmd(&sch, &lock));
    }
}

static void test_reply_hook_sees_every_good_reply_and_may_change_the_next_command(void)
{
    static const uint8_t ids[2] = {2u, 3u};
    j288_cmd_raw_t c2 = foc(2u, 777);
    j288_cmd_raw_t lock2;
    memset(&lock2, 0, sizeof lock2);
    lock2.id = 2u;
    setup_all(false, false, 0u);
    sch.cfg.on_reply = on_reply_lock_two;
    nreply_calls = 0u;
    add_servos(ids, 2u);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_set_cmd(&sch, &c2));
    sweep_once();
    TEST_ASSERT_EQUAL_UINT32(2u, nreply_calls);
    TEST_ASSERT_EQUAL_INT(2, events_at_reply); /* after servo 3's ONLINE event */
    assert_frame_cmd(0u, &c2);
    fp.servo[3].present = false; /* a failure is not a reply */
    sweep_once();
    TEST_ASSERT_EQUAL_UINT32(3u, nreply_calls);
    assert_frame_cmd(2u, &lock2); /* the hook's command went out next time */
}

/* A command set while the slot's transaction is under way changes the next transaction, not
 * the re-send of this one: the frame the bus sends (kept by the scheduler) is not rewritten by
 * j288_sched_set_cmd(), which may run while that frame is on the wire. */
static void test_set_cmd_during_a_retry_changes_the_next_sweep_only(void)
{
    static const uint8_t ids[1] = {4u};
    j288_cmd_raw_t first = foc(4u, 111);
    j288_cmd_raw_t second = foc(4u, -222);
    j288_bus_config_t bc;
    memset(&bc, 0, sizeof bc);
    bc.retries = 1u;
    setup_all(false, false, 0u);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_init(&bus, &fp.ops, &fp, &bc));
    fake_port_attach(&fp, &bus);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_init(&sch, &bus, &sch.cfg));
    add_servos(ids, 1u);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_set_cmd(&sch, &first));
    fp.servo[4].present = false; /* the first attempt goes unanswered */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_start_sweep(&sch, 0u));
    while ((j288_bus_stats(&bus)->timeouts == 0u) && (fp.now_ns < 5000u * US)) {
        fake_port_run_until(&fp, fp.now_ns + US); /* until the first attempt times out */
    }
    TEST_ASSERT_EQUAL_UINT32(1u, fp.nframes);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->timeouts);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_set_cmd(&sch, &second));
    fp.servo[4].present = true;
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 20000u * US));
    TEST_ASSERT_EQUAL_UINT32(2u, fp.nframes);
    assert_frame_cmd(0u, &first);
    assert_frame_cmd(1u, &first); /* the re-send */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_slot(&sch, 4u)->last_result);
    sweep_once();
    TEST_ASSERT_EQUAL_UINT32(3u, fp.nframes);
    assert_frame_cmd(2u, &second);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_init_and_set_cmd_checks);
    RUN_TEST(test_set_cmd_si);
    RUN_TEST(test_one_sweep_in_order);
    RUN_TEST(test_empty_sweep_ends_at_once);
    RUN_TEST(test_start_sweep_refused_while_bus_busy);
    RUN_TEST(test_back_to_back_sweeps_15_servos_from_interrupts);
    RUN_TEST(test_servo_drops_out_and_comes_back);
    RUN_TEST(test_fault_and_warning_events);
    RUN_TEST(test_watchdog_trip_and_clear);
    RUN_TEST(test_wrong_id_and_crc_in_slot_stats);
    RUN_TEST(test_collision_in_slot_stats);
    RUN_TEST(test_estop_while_sweeping);
    RUN_TEST(test_start_refused_under_estop_leaves_the_frame_on_the_wire);
    RUN_TEST(test_estop_from_an_event_callback);
    RUN_TEST(test_estop_from_on_sweep_ends_continuous_sweeps);
    RUN_TEST(test_isr_sweeps_without_lock_ops);
    RUN_TEST(test_default_config_without_handlers);
    RUN_TEST(test_control_loop_ticks_in_poll_mode);
    RUN_TEST(test_reply_hook_sees_every_good_reply_and_may_change_the_next_command);
    RUN_TEST(test_set_cmd_during_a_retry_changes_the_next_sweep_only);
    return UNITY_END();
}
