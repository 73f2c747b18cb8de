/* Unit tests of the simulator's servo and bus model (tools/j288-sim/servo_model.c), no I/O. */
#include "unity.h"

#include <math.h>
#include <string.h>

#include "j288/j288.h"
#include "servo_model.h"

#define MAX_SENT 64u

typedef struct {
    uint64_t at_us;
    size_t len;
    uint8_t data[32];
} sent_t;

static sent_t g_sent[MAX_SENT];
static size_t g_nsent;
static size_t g_nlog, g_nlog_bad;
static j288_sim_bus_t g_bus;

static void capture(void *user, uint64_t at_us, const uint8_t *data, size_t len)
{
    (void)user;
    TEST_ASSERT_TRUE(len <= sizeof g_sent[0].data);
    if (g_nsent == MAX_SENT) { /* keep the latest: drop the oldest */
        memmove(&g_sent[0], &g_sent[1], (MAX_SENT - 1u) * sizeof g_sent[0]);
        g_nsent--;
    }
    g_sent[g_nsent].at_us = at_us;
    g_sent[g_nsent].len = len;
    memcpy(g_sent[g_nsent].data, data, len);
    g_nsent++;
}

static void count_log(void *user, uint64_t now_us, const uint8_t frame[J288_CMD_LEN],
                      const j288_cmd_raw_t *cmd)
{
    (void)user;
    (void)now_us;
    (void)frame;
    g_nlog++;
    if (cmd == NULL)
        g_nlog_bad++;
}

void setUp(void)
{
    g_nsent = 0;
    g_nlog = 0;
    g_nlog_bad = 0;
}

void tearDown(void) {}

static void bus_up(uint16_t ids, const j288_sim_bus_config_t *cfg, const j288_sim_params_t *prm)
{
    TEST_ASSERT_EQUAL_INT(0, j288_sim_bus_init(&g_bus, ids, cfg, prm, capture, count_log, NULL));
}

static void send_cmd(const j288_cmd_raw_t *cmd, uint64_t now_us)
{
    uint8_t frame[J288_CMD_LEN];
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_cmd_encode(cmd, frame, NULL));
    j288_sim_bus_feed(&g_bus, frame, sizeof frame, now_us);
}

static j288_cmd_raw_t foc_cmd(uint8_t id, int32_t pos, int16_t kp, int16_t kd, bool wd)
{
    j288_cmd_raw_t c;
    memset(&c, 0, sizeof c);
    c.id = id;
    c.status = J288_MODE_FOC;
    c.watchdog = wd;
    c.pos = pos;
    c.kp = kp;
    c.kd = kd;
    return c;
}

static j288_cmd_raw_t lock_cmd(uint8_t id, bool wd)
{
    j288_cmd_raw_t c;
    memset(&c, 0, sizeof c);
    c.id = id;
    c.status = J288_MODE_LOCK;
    c.watchdog = wd;
    return c;
}

/* The last reply sent, decoded (fails the test if it is not a good reply). */
static j288_reply_raw_t last_reply(void)
{
    j288_reply_raw_t r;
    TEST_ASSERT_TRUE(g_nsent > 0u);
    TEST_ASSERT_EQUAL_UINT(J288_REPLY_LEN, g_sent[g_nsent - 1u].len);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_reply_decode(g_sent[g_nsent - 1u].data, &r, NULL));
    return r;
}

static void test_reply_to_addressed_servo_only(void)
{
    j288_cmd_raw_t c = lock_cmd(2, false);
    j288_reply_raw_t r;
    bus_up((1u << 1) | (1u << 2), NULL, NULL);
    send_cmd(&c, 1000);
    TEST_ASSERT_EQUAL_UINT(1, g_nsent);
    r = last_reply();
    TEST_ASSERT_EQUAL_UINT(2, r.id);
    TEST_ASSERT_EQUAL_UINT(J288_MODE_LOCK, r.status);
    TEST_ASSERT_EQUAL_UINT(48, r.voltage_raw); /* 24 V */
    TEST_ASSERT_EQUAL_INT(25, r.case_temp_c);
    TEST_ASSERT_EQUAL_UINT(0, r.faults);
    c.id = 7; /* not on this bus */
    send_cmd(&c, 2000);
    TEST_ASSERT_EQUAL_UINT(1, g_nsent);
    TEST_ASSERT_EQUAL_UINT64(1, g_bus.stats.for_others);
    TEST_ASSERT_EQUAL_UINT(2, g_nlog);
}

static void test_power_up_angle_single_turn(void)
{
    uint8_t id;
    bus_up(0x7FFFu, NULL, NULL);
    for (id = 0; id <= J288_MAX_ID; id++) {
        j288_sim_servo_t *s = j288_sim_bus_servo(&g_bus, id);
        TEST_ASSERT_NOT_NULL(s);
        TEST_ASSERT_TRUE(s->p >= 0.0 && s->p < 2.0 * J288_PI);
    }
    TEST_ASSERT_NULL(j288_sim_bus_servo(&g_bus, 15));
}

static void test_lock_holds_no_torque(void)
{
    j288_sim_params_t prm;
    j288_cmd_raw_t c = lock_cmd(1, false);
    j288_sim_servo_t *s;
    j288_reply_raw_t r;
    double p0;
    j288_sim_params_default(&prm);
    prm.load_torque = 5.0; /* output-side weight: a held servo would resist it */
    bus_up(1u << 1, NULL, &prm);
    s = j288_sim_bus_servo(&g_bus, 1);
    /* Gains and feed-forward in a lock command must be ignored. */
    c.kp = 1000;
    c.kd = 1000;
    c.tau = 20000;
    c.pos = 100000;
    p0 = s->p;
    send_cmd(&c, 0);
    send_cmd(&c, 200000);
    r = last_reply();
    TEST_ASSERT_EQUAL_UINT(J288_MODE_LOCK, r.status);
    TEST_ASSERT_EQUAL_INT(0, r.torque);
    TEST_ASSERT_EQUAL_DOUBLE(0.0, s->tau);
    /* With no motor torque the weight pulls the rotor backwards. */
    TEST_ASSERT_TRUE(s->p < p0 - 1.0);
}

static void test_foc_converges_to_target(void)
{
    j288_sim_servo_t *s;
    j288_reply_raw_t r;
    int32_t target;
    double err;
    uint64_t t;
    bus_up(1u << 1, NULL, NULL);
    s = j288_sim_bus_servo(&g_bus, 1);
    target = (int32_t)lround((s->p + 20.0) * J288_SCALE_POS); /* 20 rad rotor away */
    for (t = 0; t <= 3000000u; t += 1000u) {
        j288_cmd_raw_t c =
            foc_cmd(1, target, 1280 /* 0.001 N m/rad */, 12800 /* 0.0001 N m s/rad */, true);
        send_cmd(&c, t);
    }
    r = last_reply();
    TEST_ASSERT_EQUAL_UINT(J288_MODE_FOC, r.status);
    err = (double)target / J288_SCALE_POS - s->p;
    /* Coulomb friction (2e-4 N m) over kp (1e-3 N m/rad) leaves at most 0.2 rad. */
    TEST_ASSERT_DOUBLE_WITHIN(0.25, 0.0, err);
    TEST_ASSERT_INT32_WITHIN(2000, target, r.pos);
    TEST_ASSERT_INT_WITHIN(2, 0, r.speed);
    TEST_ASSERT_FALSE(r.watchdog_tripped);
    /* OutPos follows the output angle. */
    TEST_ASSERT_EQUAL_UINT(j288_sim_servo_out_pos(s), r.out_pos);
}

static void test_foc_law_torque_sign_and_saturation(void)
{
    j288_sim_servo_t *s;
    j288_reply_raw_t r;
    j288_cmd_raw_t c;
    bus_up(1u << 1, NULL, NULL);
    s = j288_sim_bus_servo(&g_bus, 1);
    /* Pure feed-forward: the reported torque is the commanded one. */
    c = foc_cmd(1, 0, 0, 0, false);
    c.tau = 1280;
    send_cmd(&c, 0);
    send_cmd(&c, 100);
    r = last_reply();
    TEST_ASSERT_EQUAL_INT(1280, r.torque);
    TEST_ASSERT_TRUE(s->w > 0.0);
    /* A far target with full stiffness saturates at the motor limit, pointing at it. */
    c = foc_cmd(1, (int32_t)lround((s->p - 1000.0) * J288_SCALE_POS), 32767, 0, false);
    send_cmd(&c, 200);
    send_cmd(&c, 300);
    r = last_reply();
    TEST_ASSERT_INT_WITHIN(2, -(int)lround(0.127 * J288_SCALE_TORQUE), r.torque);
}

static void test_watchdog_trips_and_clears(void)
{
    j288_reply_raw_t r;
    j288_cmd_raw_t foc;
    j288_sim_servo_t *s;
    bus_up(1u << 1, NULL, NULL);
    s = j288_sim_bus_servo(&g_bus, 1);
    foc = foc_cmd(1, (int32_t)lround(s->p * J288_SCALE_POS), 1280, 12800, true);
    send_cmd(&foc, 0);
    j288_sim_bus_advance(&g_bus, 999000);
    TEST_ASSERT_FALSE(s->wd_tripped);
    TEST_ASSERT_EQUAL_UINT(J288_MODE_FOC, s->mode);
    j288_sim_bus_advance(&g_bus, 1001000);
    TEST_ASSERT_TRUE(s->wd_tripped);
    TEST_ASSERT_EQUAL_UINT(J288_MODE_LOCK, s->mode);
    TEST_ASSERT_EQUAL_UINT64(1, g_bus.stats.watchdog_trips);
    /* A command with the watchdog bit set does not clear the trip: still locked. */
    send_cmd(&foc, 1100000);
    r = last_reply();
    TEST_ASSERT_TRUE(r.watchdog_tripped);
    TEST_ASSERT_EQUAL_UINT(J288_MODE_LOCK, r.status);
    TEST_ASSERT_EQUAL_INT(0, r.torque);
    /* Watchdog bit 0 clears it, and the command is obeyed. */
    foc.watchdog = false;
    send_cmd(&foc, 1200000);
    r = last_reply();
    TEST_ASSERT_FALSE(r.watchdog_tripped);
    TEST_ASSERT_EQUAL_UINT(J288_MODE_FOC, r.status);
    /* Disabled: no trip however long the silence. */
    j288_sim_bus_advance(&g_bus, 5000000);
    TEST_ASSERT_FALSE(s->wd_tripped);
}

/* A stretch the simulator did not run (starved) is not the host's silence; the silence
 * before and after it still counts. */
static void test_watchdog_excuses_the_simulators_stall(void)
{
    j288_cmd_raw_t c = lock_cmd(1, true);
    j288_sim_servo_t *s;
    bus_up(1u << 1, NULL, NULL);
    s = j288_sim_bus_servo(&g_bus, 1);
    send_cmd(&c, 0);
    j288_sim_bus_advance(&g_bus, 100000);
    j288_sim_bus_excuse_stall(&g_bus, 100000, 900000); /* 0.8 s asleep */
    j288_sim_bus_advance(&g_bus, 1700000);               /* 0.9 s of silence counted */
    TEST_ASSERT_FALSE(s->wd_tripped);
    j288_sim_bus_advance(&g_bus, 1801000); /* 1.001 s */
    TEST_ASSERT_TRUE(s->wd_tripped);
}

static void test_watchdog_fed_by_commands(void)
{
    j288_cmd_raw_t c = lock_cmd(1, true);
    uint64_t t;
    bus_up(1u << 1, NULL, NULL);
    for (t = 0; t <= 3000000u; t += 500000u)
        send_cmd(&c, t);
    TEST_ASSERT_FALSE(last_reply().watchdog_tripped);
    /* Broadcast feeds it too. */
    c.id = J288_BROADCAST_ID;
    send_cmd(&c, 3900000);
    j288_sim_bus_advance(&g_bus, 4500000);
    TEST_ASSERT_FALSE(j288_sim_bus_servo(&g_bus, 1)->wd_tripped);
}

static void test_bad_crc_no_reply_and_checksum_fault(void)
{
    j288_cmd_raw_t c = lock_cmd(1, false);
    uint8_t frame[J288_CMD_LEN];
    j288_reply_raw_t r;
    bus_up(1u << 1, NULL, NULL);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_cmd_encode(&c, frame, NULL));
    frame[10] ^= 0x40u;
    j288_sim_bus_feed(&g_bus, frame, sizeof frame, 1000);
    TEST_ASSERT_EQUAL_UINT(0, g_nsent);
    TEST_ASSERT_EQUAL_UINT64(1, g_bus.stats.bad_crc);
    TEST_ASSERT_EQUAL_UINT(1, g_nlog_bad);
    send_cmd(&c, 2000);
    r = last_reply();
    TEST_ASSERT_EQUAL_HEX32(J288_FAULT_COMM_CHECKSUM, r.faults);
    /* Reported once, then clear. */
    send_cmd(&c, 3000);
    r = last_reply();
    TEST_ASSERT_EQUAL_HEX32(0, r.faults);
}

static void test_broadcast_obeyed_silently(void)
{
    j288_cmd_raw_t c = foc_cmd(J288_BROADCAST_ID, 0, 0, 0, false);
    uint8_t id;
    bus_up((1u << 1) | (1u << 2) | (1u << 3), NULL, NULL);
    send_cmd(&c, 1000);
    TEST_ASSERT_EQUAL_UINT(0, g_nsent);
    TEST_ASSERT_EQUAL_UINT64(1, g_bus.stats.broadcasts);
    for (id = 1; id <= 3; id++)
        TEST_ASSERT_EQUAL_UINT(J288_MODE_FOC, j288_sim_bus_servo(&g_bus, id)->mode);
    c = lock_cmd(J288_BROADCAST_ID, true);
    send_cmd(&c, 2000);
    TEST_ASSERT_EQUAL_UINT(0, g_nsent);
    for (id = 1; id <= 3; id++)
        TEST_ASSERT_EQUAL_UINT(J288_MODE_LOCK, j288_sim_bus_servo(&g_bus, id)->mode);
}

static void test_split_and_noisy_input(void)
{
    j288_cmd_raw_t c = lock_cmd(1, false);
    uint8_t frame[J288_CMD_LEN];
    static const uint8_t junk[] = {0x00, 0xFE, 0x12, 0xEE, 0xFF};
    bus_up(1u << 1, NULL, NULL);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_cmd_encode(&c, frame, NULL));
    j288_sim_bus_feed(&g_bus, junk, sizeof junk, 100);
    j288_sim_bus_feed(&g_bus, frame, 7, 110);
    TEST_ASSERT_EQUAL_UINT(0, g_nsent);
    j288_sim_bus_feed(&g_bus, frame + 7, sizeof frame - 7u, 120);
    TEST_ASSERT_EQUAL_UINT(1, g_nsent);
    /* A half frame followed by a long silence is forgotten. */
    j288_sim_bus_feed(&g_bus, frame, 7, 1000);
    j288_sim_bus_feed(&g_bus, frame, sizeof frame, 100000);
    TEST_ASSERT_EQUAL_UINT(2, g_nsent);
}

static void test_turnaround_and_late(void)
{
    j288_sim_bus_config_t cfg;
    j288_cmd_raw_t c = lock_cmd(1, false);
    memset(&cfg, 0, sizeof cfg);
    cfg.turnaround_us = 30;
    cfg.late = 1.0;
    cfg.late_us = 7000;
    bus_up(1u << 1, &cfg, NULL);
    send_cmd(&c, 1000);
    TEST_ASSERT_EQUAL_UINT(1, g_nsent);
    TEST_ASSERT_EQUAL_UINT64(1000u + 30u + 7000u, g_sent[0].at_us);
    TEST_ASSERT_EQUAL_UINT64(1, g_bus.stats.late);
}

static void test_drop_corrupt_noise_dup(void)
{
    j288_sim_bus_config_t cfg;
    j288_cmd_raw_t c = lock_cmd(1, false);
    j288_reply_raw_t r;
    memset(&cfg, 0, sizeof cfg);
    cfg.drop = 1.0;
    bus_up(1u << 1, &cfg, NULL);
    send_cmd(&c, 1000);
    TEST_ASSERT_EQUAL_UINT(0, g_nsent);
    TEST_ASSERT_EQUAL_UINT64(1, g_bus.stats.dropped);

    memset(&cfg, 0, sizeof cfg);
    cfg.corrupt = 1.0;
    bus_up(1u << 1, &cfg, NULL);
    send_cmd(&c, 1000);
    TEST_ASSERT_EQUAL_UINT(1, g_nsent);
    TEST_ASSERT_NOT_EQUAL(J288_OK, j288_reply_decode(g_sent[0].data, &r, NULL));

    setUp();
    memset(&cfg, 0, sizeof cfg);
    cfg.noise = 1.0;
    bus_up(1u << 1, &cfg, NULL);
    send_cmd(&c, 1000);
    TEST_ASSERT_EQUAL_UINT(2, g_nsent);
    TEST_ASSERT_TRUE(g_sent[0].len >= 1u && g_sent[0].len <= 8u);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_reply_decode(g_sent[1].data, &r, NULL));

    setUp();
    memset(&cfg, 0, sizeof cfg);
    cfg.dup_ids = 1u << 1;
    bus_up(1u << 1, &cfg, NULL);
    send_cmd(&c, 1000);
    TEST_ASSERT_EQUAL_UINT(2, g_nsent);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_reply_decode(g_sent[0].data, &r, NULL));
    TEST_ASSERT_EQUAL_UINT(1, r.id);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_reply_decode(g_sent[1].data, &r, NULL));
    TEST_ASSERT_EQUAL_UINT(1, r.id);
    TEST_ASSERT_EQUAL_UINT64(1, g_bus.stats.duplicates);
}

static void run_faulty(uint64_t seed, sent_t *out, size_t *n)
{
    j288_sim_bus_config_t cfg;
    j288_cmd_raw_t c = lock_cmd(1, false);
    uint64_t t;
    memset(&cfg, 0, sizeof cfg);
    cfg.seed = seed;
    cfg.drop = 0.2;
    cfg.corrupt = 0.2;
    cfg.noise = 0.2;
    setUp();
    bus_up(1u << 1, &cfg, NULL);
    for (t = 0; t < 30u; t++)
        send_cmd(&c, t * 1000u);
    *n = g_nsent;
    memcpy(out, g_sent, g_nsent * sizeof g_sent[0]);
}

static void test_faults_are_deterministic_per_seed(void)
{
    static sent_t a[MAX_SENT], b[MAX_SENT], d[MAX_SENT];
    size_t na, nb, nd;
    run_faulty(42, a, &na);
    run_faulty(42, b, &nb);
    run_faulty(43, d, &nd);
    TEST_ASSERT_EQUAL_UINT(na, nb);
    TEST_ASSERT_EQUAL_MEMORY(a, b, na * sizeof a[0]);
    TEST_ASSERT_TRUE(na != nd || memcmp(a, d, na * sizeof a[0]) != 0);
}

static void test_injected_fault_and_voltage(void)
{
    j288_sim_params_t prm;
    j288_cmd_raw_t c = lock_cmd(4, false);
    j288_reply_raw_t r;
    j288_sim_params_default(&prm);
    prm.voltage = 10.5;
    bus_up(1u << 4, NULL, &prm);
    TEST_ASSERT_EQUAL_INT(0, j288_sim_bus_inject_faults(&g_bus, 4, J288_FAULT_OVER_CURRENT));
    TEST_ASSERT_EQUAL_INT(-1, j288_sim_bus_inject_faults(&g_bus, 5, 1));
    send_cmd(&c, 1000);
    r = last_reply();
    TEST_ASSERT_EQUAL_HEX32(J288_FAULT_OVER_CURRENT, r.faults);
    TEST_ASSERT_EQUAL_UINT(21, r.voltage_raw);
    TEST_ASSERT_EQUAL_UINT(J288_WARN_LOW_SUPPLY, r.warnings);
}

static void test_heating_under_torque(void)
{
    j288_sim_params_t prm;
    j288_cmd_raw_t c = foc_cmd(1, 0, 0, 0, false);
    j288_reply_raw_t r;
    j288_sim_params_default(&prm);
    prm.load_torque = -36.0; /* holds the rotor against the feed-forward */
    bus_up(1u << 1, NULL, &prm);
    c.tau = 32000; /* 0.125 N m */
    send_cmd(&c, 0);
    send_cmd(&c, 60000000u); /* one minute */
    r = last_reply();
    TEST_ASSERT_TRUE(r.winding_temp_c > r.case_temp_c);
    TEST_ASSERT_TRUE(r.case_temp_c > 30);
}

/* ---- the joint: r = N * theta_gear + c, p = r - 2 pi k, OutPos, backlash, power cycles ---- */

#define TWO_PI (2.0 * J288_PI)

static j288_sim_truth_t truth_of(uint8_t id)
{
    j288_sim_truth_t t;
    j288_sim_servo_t *s = j288_sim_bus_servo(&g_bus, id);
    TEST_ASSERT_NOT_NULL(s);
    j288_sim_servo_truth(s, &t);
    return t;
}

/* r - N * theta_gear = c and r = p + 2 pi k, to rounding (r is at most a few thousand rad). */
static void assert_joint_relations(const j288_sim_truth_t *t)
{
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, t->c, t->r - J288_GEAR_RATIO * t->theta_gear);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, t->r, t->p + TWO_PI * (double)t->k);
}

/* The count an ideal 13-bit encoder gives for theta, worked out here independently. */
static uint16_t expected_out_pos(double theta)
{
    double turns = theta / TWO_PI;
    double frac = turns - floor(turns);
    return (uint16_t)((unsigned)floor(frac * 8192.0) % 8192u);
}

/* Drive servo id's rotor to p_target (rad, since power-up) over duration_us from t0_us with
 * an overdamped FOC loop (kp 0.005 N m/rad, kd 0.00025 N m s/rad on a 2e-6 kg m^2 rotor: no
 * overshoot, so the backlash tests see the gear move one way); returns the time reached. */
static uint64_t drive_to(uint8_t id, double p_target, uint64_t t0_us, uint64_t duration_us)
{
    uint64_t t;
    for (t = t0_us; t <= t0_us + duration_us; t += 1000u) {
        j288_cmd_raw_t c =
            foc_cmd(id, (int32_t)lround(p_target * J288_SCALE_POS), 6400, 32000, false);
        send_cmd(&c, t);
    }
    return t;
}

static void test_joint_power_up_relations(void)
{
    static const double cs[] = {0.0, 1.0, 3.14, 6.2, -2.5, 40.0};
    static const double thetas[] = {0.0, 0.5, -0.5, 3.1, -3.1, 6.0, -12.345, 100.0, -700.0};
    size_t i, j;
    bus_up(1u << 1, NULL, NULL);
    for (i = 0; i < sizeof cs / sizeof cs[0]; i++) {
        for (j = 0; j < sizeof thetas / sizeof thetas[0]; j++) {
            j288_sim_truth_t t;
            TEST_ASSERT_EQUAL_INT(0, j288_sim_bus_set_joint(&g_bus, 1, cs[i], thetas[j]));
            t = truth_of(1);
            TEST_ASSERT_TRUE(t.p >= 0.0 && t.p < TWO_PI);
            TEST_ASSERT_EQUAL_DOUBLE(cs[i], t.c);
            TEST_ASSERT_EQUAL_DOUBLE(thetas[j], t.theta);
            TEST_ASSERT_EQUAL_DOUBLE(thetas[j], t.theta_gear);
            assert_joint_relations(&t);
            TEST_ASSERT_EQUAL_UINT16(expected_out_pos(thetas[j]), t.out_pos);
            TEST_ASSERT_TRUE(t.powered);
        }
    }
    TEST_ASSERT_EQUAL_INT(-1, j288_sim_bus_set_joint(&g_bus, 2, 0.0, 0.0));
}

static void test_joint_drawn_from_seed(void)
{
    j288_sim_bus_config_t cfg;
    j288_sim_truth_t a[J288_MAX_SERVOS], b;
    uint8_t id;
    bool differs = false;
    memset(&cfg, 0, sizeof cfg);
    cfg.seed = 77;
    bus_up(0x7FFFu, &cfg, NULL);
    for (id = 0; id <= J288_MAX_ID; id++) {
        a[id] = truth_of(id);
        TEST_ASSERT_TRUE(a[id].c >= 0.0 && a[id].c < TWO_PI);
        TEST_ASSERT_TRUE(a[id].theta >= -J288_PI && a[id].theta < J288_PI);
        TEST_ASSERT_TRUE(a[id].p >= 0.0 && a[id].p < TWO_PI);
        assert_joint_relations(&a[id]);
    }
    /* Same seed, same draw (and a servo's draw does not depend on the others present). */
    bus_up(1u << 5, &cfg, NULL);
    b = truth_of(5);
    TEST_ASSERT_EQUAL_DOUBLE(a[5].c, b.c);
    TEST_ASSERT_EQUAL_DOUBLE(a[5].theta, b.theta);
    TEST_ASSERT_EQUAL_DOUBLE(a[5].p, b.p);
    TEST_ASSERT_EQUAL_INT32(a[5].k, b.k);
    cfg.seed = 78;
    bus_up(1u << 5, &cfg, NULL);
    b = truth_of(5);
    differs = b.c != a[5].c && b.theta != a[5].theta;
    TEST_ASSERT_TRUE(differs);
}

static void test_joint_relation_holds_while_moving(void)
{
    j288_sim_truth_t t0, t;
    uint64_t now;
    bus_up(1u << 1, NULL, NULL);
    TEST_ASSERT_EQUAL_INT(0, j288_sim_bus_set_joint(&g_bus, 1, 2.0, -3.0));
    t0 = truth_of(1);
    /* 25 rad of rotor forward (four turns), then 40 back. */
    now = drive_to(1, t0.p + 25.0, 0, 2000000u);
    t = truth_of(1);
    TEST_ASSERT_DOUBLE_WITHIN(0.1, t0.p + 25.0, t.p);
    TEST_ASSERT_EQUAL_INT32(t0.k, t.k); /* the turn count is kept while powered */
    assert_joint_relations(&t);
    TEST_ASSERT_EQUAL_DOUBLE(t.theta_gear, t.theta);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, -3.0 + (t.p - t0.p) / J288_GEAR_RATIO, t.theta);
    TEST_ASSERT_EQUAL_UINT16(expected_out_pos(t.theta), t.out_pos);
    TEST_ASSERT_EQUAL_UINT16(t.out_pos, last_reply().out_pos);
    (void)drive_to(1, t0.p - 15.0, now, 2000000u);
    t = truth_of(1);
    TEST_ASSERT_TRUE(t.p < 0.0); /* multi-turn since power-up, below its start */
    assert_joint_relations(&t);
    TEST_ASSERT_EQUAL_UINT16(expected_out_pos(t.theta), last_reply().out_pos);
}

static void test_out_pos_quantisation(void)
{
    const double step = TWO_PI / 8192.0;
    static const struct {
        double theta;
        uint16_t count;
    } cases[] = {
        {0.0, 0u},
        {1e-12, 0u},
        {-1e-12, 8191u},
        {100.5 * (2.0 * J288_PI / 8192.0), 100u},
        {100.999 * (2.0 * J288_PI / 8192.0), 100u},
        {101.001 * (2.0 * J288_PI / 8192.0), 101u},
        {8191.5 * (2.0 * J288_PI / 8192.0), 8191u},
        {2.0 * J288_PI + 0.5 * (2.0 * J288_PI / 8192.0), 0u},
        {-0.5 * (2.0 * J288_PI / 8192.0), 8191u},
        {-1.5 * (2.0 * J288_PI / 8192.0), 8190u},
        {-2.0 * J288_PI + 3.5 * (2.0 * J288_PI / 8192.0), 3u},
    };
    size_t i;
    bus_up(1u << 1, NULL, NULL);
    for (i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        j288_sim_servo_t *s;
        (void)j288_sim_bus_set_joint(&g_bus, 1, 1.0, cases[i].theta);
        s = j288_sim_bus_servo(&g_bus, 1);
        TEST_ASSERT_EQUAL_UINT16(cases[i].count, j288_sim_servo_out_pos(s));
    }
    /* One count is 2 pi / 8192 of output: 0.77 mrad. */
    TEST_ASSERT_DOUBLE_WITHIN(1e-6, 0.000767, step);
}

/* With play b and no load, the shaft stays put until the gear side reaches an edge of the
 * play, then is pushed along half the play behind it; reversing, the gear crosses the whole
 * play before the shaft moves again. */
static void test_backlash_dead_band_both_directions(void)
{
    const double b = 0.02; /* output rad */
    const double n = J288_GEAR_RATIO;
    j288_sim_params_t prm;
    j288_sim_truth_t t0, t;
    uint64_t now;
    j288_sim_params_default(&prm);
    prm.backlash = b;
    bus_up(1u << 1, NULL, &prm);
    TEST_ASSERT_EQUAL_INT(0, j288_sim_bus_set_joint(&g_bus, 1, 0.5, 1.0));
    t0 = truth_of(1);
    TEST_ASSERT_EQUAL_DOUBLE(1.0, t0.theta);
    TEST_ASSERT_EQUAL_DOUBLE(1.0, t0.theta_gear); /* starts centred */
    /* Forward by 0.3 b of gear: inside the play, the shaft does not move. */
    now = drive_to(1, t0.p + 0.3 * b * n, 0, 1000000u);
    t = truth_of(1);
    TEST_ASSERT_TRUE(t.theta_gear > 1.0 + 0.2 * b);
    TEST_ASSERT_EQUAL_DOUBLE(1.0, t.theta);
    TEST_ASSERT_EQUAL_UINT16(t0.out_pos, last_reply().out_pos);
    assert_joint_relations(&t);
    /* Forward by 3 b in all: the shaft is pushed, half the play behind the gear. */
    now = drive_to(1, t0.p + 3.0 * b * n, now, 1000000u);
    t = truth_of(1);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, t.theta_gear - 0.5 * b, t.theta);
    TEST_ASSERT_TRUE(t.theta > 1.0 + 2.0 * b);
    assert_joint_relations(&t);
    t0 = t;
    /* Back by 0.8 b: the gear crosses the play, the shaft stays. */
    now = drive_to(1, t0.p - 0.8 * b * n, now, 1000000u);
    t = truth_of(1);
    TEST_ASSERT_TRUE(t.theta_gear < t0.theta_gear - 0.7 * b);
    TEST_ASSERT_EQUAL_DOUBLE(t0.theta, t.theta);
    /* Back by 3 b: pushed the other way, half the play ahead of the gear. */
    (void)drive_to(1, t0.p - 3.0 * b * n, now, 1000000u);
    t = truth_of(1);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, t.theta_gear + 0.5 * b, t.theta);
    TEST_ASSERT_TRUE(t.theta < t0.theta - 1.5 * b);
    TEST_ASSERT_EQUAL_UINT16(expected_out_pos(t.theta), last_reply().out_pos);
    assert_joint_relations(&t);
}

/* A load keeps the shaft against one side of the play (a positive load torque pulls the
 * output backwards), from power-up on and while the gear moves either way. */
static void test_backlash_load_drives_shaft(void)
{
    const double b = 0.01;
    j288_sim_params_t prm;
    j288_sim_truth_t t;
    uint64_t now;
    j288_sim_params_default(&prm);
    prm.backlash = b;
    prm.load_torque = 0.5;
    bus_up(1u << 1, NULL, &prm);
    TEST_ASSERT_EQUAL_INT(0, j288_sim_bus_set_joint(&g_bus, 1, 0.0, 2.0));
    t = truth_of(1);
    TEST_ASSERT_EQUAL_DOUBLE(2.0, t.theta); /* the start angle is the shaft's */
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 2.0 + 0.5 * b, t.theta_gear);
    assert_joint_relations(&t);
    now = drive_to(1, t.p + 2.0, 0, 500000u);
    t = truth_of(1);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, t.theta_gear - 0.5 * b, t.theta);
    (void)drive_to(1, t.p - 4.0, now, 500000u);
    t = truth_of(1);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, t.theta_gear - 0.5 * b, t.theta);

    prm.load_torque = -0.5;
    bus_up(1u << 1, NULL, &prm);
    TEST_ASSERT_EQUAL_INT(0, j288_sim_bus_set_joint(&g_bus, 1, 0.0, 2.0));
    t = truth_of(1);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, 2.0 - 0.5 * b, t.theta_gear);
    (void)drive_to(1, t.p - 2.0, 0, 500000u);
    t = truth_of(1);
    TEST_ASSERT_DOUBLE_WITHIN(1e-12, t.theta_gear + 0.5 * b, t.theta);
}

/* A power cycle keeps theta and c, loses the turn count (p back in [0, 2 pi)), is silent
 * and deaf for the off time, then comes back in lock with the watchdog off. */
static void test_power_cycle_keeps_theta_and_c_resets_k(void)
{
    j288_sim_bus_config_t cfg;
    j288_sim_truth_t t0, before, after;
    j288_cmd_raw_t lock = lock_cmd(1, false);
    j288_cmd_raw_t foc;
    j288_reply_raw_t r;
    uint64_t now;
    size_t nsent;
    memset(&cfg, 0, sizeof cfg);
    cfg.power_off_us = 100000u;
    bus_up(1u << 1, &cfg, NULL);
    TEST_ASSERT_EQUAL_INT(0, j288_sim_bus_set_joint(&g_bus, 1, 4.0, 0.7));
    t0 = truth_of(1);
    now = drive_to(1, t0.p + 30.0, 0, 2000000u); /* almost five turns */
    /* The same target with the watchdog armed: the power cycle must disarm it. */
    foc = foc_cmd(1, (int32_t)lround((t0.p + 30.0) * J288_SCALE_POS), 6400, 32000, true);
    send_cmd(&foc, now);
    before = truth_of(1);
    TEST_ASSERT_TRUE(before.p > TWO_PI);

    TEST_ASSERT_EQUAL_INT(1, j288_sim_bus_power_cycle(&g_bus, 1u << 1, now));
    TEST_ASSERT_EQUAL_UINT64(1, g_bus.stats.power_cycles);
    TEST_ASSERT_FALSE(truth_of(1).powered);
    /* Off: no reply, no torque, commands unheard. */
    nsent = g_nsent;
    send_cmd(&foc, now + 50000u);
    TEST_ASSERT_EQUAL_UINT(nsent, g_nsent);
    TEST_ASSERT_EQUAL_DOUBLE(0.0, j288_sim_bus_servo(&g_bus, 1)->tau);
    TEST_ASSERT_EQUAL_UINT(J288_MODE_LOCK, j288_sim_bus_servo(&g_bus, 1)->mode);
    /* Back after 100 ms, and nothing latched or pending from before. */
    j288_sim_bus_advance(&g_bus, now + 101000u);
    after = truth_of(1);
    TEST_ASSERT_TRUE(after.powered);
    TEST_ASSERT_EQUAL_UINT32(1, after.power_cycles);
    TEST_ASSERT_TRUE(after.p >= 0.0 && after.p < TWO_PI);
    TEST_ASSERT_EQUAL_DOUBLE(before.c, after.c);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, before.theta, after.theta);
    TEST_ASSERT_DOUBLE_WITHIN(1e-9, before.r, after.r);
    TEST_ASSERT_EQUAL_UINT16(before.out_pos, after.out_pos);
    TEST_ASSERT_TRUE(after.k > before.k); /* the turns since power-up moved into k */
    assert_joint_relations(&after);
    /* The watchdog the FOC command armed is gone: no trip however long the silence. */
    j288_sim_bus_advance(&g_bus, now + 5000000u);
    TEST_ASSERT_FALSE(j288_sim_bus_servo(&g_bus, 1)->wd_enabled);
    TEST_ASSERT_FALSE(j288_sim_bus_servo(&g_bus, 1)->wd_tripped);
    send_cmd(&lock, now + 5000000u);
    r = last_reply();
    TEST_ASSERT_EQUAL_UINT(J288_MODE_LOCK, r.status);
    TEST_ASSERT_FALSE(r.watchdog_tripped);
    TEST_ASSERT_EQUAL_INT32((int32_t)lround(after.p * J288_SCALE_POS), r.pos);
}

/* A power cycle forgets a latched checksum fault; while off a servo hears nothing: no
 * checksum fault latched, broadcasts not obeyed. */
static void test_power_cycle_deaf_while_off(void)
{
    j288_sim_bus_config_t cfg;
    j288_cmd_raw_t lock = lock_cmd(1, false);
    j288_cmd_raw_t bcast = foc_cmd(J288_BROADCAST_ID, 0, 0, 0, false);
    uint8_t frame[J288_CMD_LEN];
    size_t nsent;
    memset(&cfg, 0, sizeof cfg);
    cfg.power_off_us = 20000u;
    bus_up((1u << 1) | (1u << 2), &cfg, NULL);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_cmd_encode(&lock, frame, NULL));
    frame[10] ^= 0x01u;
    j288_sim_bus_feed(&g_bus, frame, sizeof frame, 500);
    TEST_ASSERT_EQUAL_HEX32(J288_FAULT_COMM_CHECKSUM,
                            j288_sim_bus_servo(&g_bus, 1)->faults_latched);
    TEST_ASSERT_EQUAL_INT(1, j288_sim_bus_power_cycle(&g_bus, 1u << 1, 1000));
    j288_sim_bus_feed(&g_bus, frame, sizeof frame, 12000);
    send_cmd(&bcast, 3000);
    TEST_ASSERT_EQUAL_UINT(J288_MODE_LOCK, j288_sim_bus_servo(&g_bus, 1)->mode);
    TEST_ASSERT_EQUAL_UINT(J288_MODE_FOC, j288_sim_bus_servo(&g_bus, 2)->mode);
    send_cmd(&lock, 30000);
    TEST_ASSERT_EQUAL_HEX32(0, last_reply().faults);
    /* Instant cycle (off time 0): heard at once. */
    cfg.power_off_us = 0u;
    bus_up(1u << 1, &cfg, NULL);
    TEST_ASSERT_EQUAL_INT(1, j288_sim_bus_power_cycle(&g_bus, 1u << 1, 1000));
    TEST_ASSERT_TRUE(truth_of(1).powered);
    nsent = g_nsent;
    send_cmd(&lock, 1000);
    TEST_ASSERT_EQUAL_UINT(nsent + 1u, g_nsent);
}

static void test_power_cycle_ids(void)
{
    j288_sim_bus_config_t cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.dup_ids = 1u << 2;
    cfg.power_off_us = 1000u;
    bus_up((1u << 1) | (1u << 2), &cfg, NULL);
    TEST_ASSERT_EQUAL_INT(-1, j288_sim_bus_power_cycle(&g_bus, (1u << 1) | (1u << 3), 0));
    TEST_ASSERT_EQUAL_UINT64(0, g_bus.stats.power_cycles);
    TEST_ASSERT_TRUE(truth_of(1).powered);
    /* Servo 2 and its duplicate. */
    TEST_ASSERT_EQUAL_INT(3, j288_sim_bus_power_cycle(&g_bus, (1u << 1) | (1u << 2), 0));
    TEST_ASSERT_EQUAL_UINT64(3, g_bus.stats.power_cycles);
    TEST_ASSERT_FALSE(g_bus.dup[2].powered);
    TEST_ASSERT_EQUAL_INT(0, j288_sim_bus_inject_faults(&g_bus, 1, J288_FAULT_OUTPUT_ENCODER));
    j288_sim_bus_advance(&g_bus, 2000);
    TEST_ASSERT_TRUE(g_bus.dup[2].powered);
    /* Injected faults survive a new joint placement (and power cycles). */
    TEST_ASSERT_EQUAL_INT(0, j288_sim_bus_set_joint(&g_bus, 1, 1.0, 1.0));
    TEST_ASSERT_EQUAL_INT(1, j288_sim_bus_power_cycle(&g_bus, 1u << 1, 3000));
    j288_sim_bus_advance(&g_bus, 5000);
    TEST_ASSERT_EQUAL_HEX32(J288_FAULT_OUTPUT_ENCODER,
                            j288_sim_bus_servo(&g_bus, 1)->faults_injected);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_reply_to_addressed_servo_only);
    RUN_TEST(test_power_up_angle_single_turn);
    RUN_TEST(test_lock_holds_no_torque);
    RUN_TEST(test_foc_converges_to_target);
    RUN_TEST(test_foc_law_torque_sign_and_saturation);
    RUN_TEST(test_watchdog_trips_and_clears);
    RUN_TEST(test_watchdog_fed_by_commands);
    RUN_TEST(test_watchdog_excuses_the_simulators_stall);
    RUN_TEST(test_bad_crc_no_reply_and_checksum_fault);
    RUN_TEST(test_broadcast_obeyed_silently);
    RUN_TEST(test_split_and_noisy_input);
    RUN_TEST(test_turnaround_and_late);
    RUN_TEST(test_drop_corrupt_noise_dup);
    RUN_TEST(test_faults_are_deterministic_per_seed);
    RUN_TEST(test_injected_fault_and_voltage);
    RUN_TEST(test_heating_under_torque);
    RUN_TEST(test_joint_power_up_relations);
    RUN_TEST(test_joint_drawn_from_seed);
    RUN_TEST(test_joint_relation_holds_while_moving);
    RUN_TEST(test_out_pos_quantisation);
    RUN_TEST(test_backlash_dead_band_both_directions);
    RUN_TEST(test_backlash_load_drives_shaft);
    RUN_TEST(test_power_cycle_keeps_theta_and_c_resets_k);
    RUN_TEST(test_power_cycle_deaf_while_off);
    RUN_TEST(test_power_cycle_ids);
    return UNITY_END();
}
