/*
 * The fixed-point joint layer (j288/jointq.h): its conversions against the golden vectors
 * of the independent generator (tools/vectors/gen_vectors.py, exact arithmetic from the
 * spec), its joints against the servo model of test_joint.c (written again here: r = N theta
 * + c, p restarting in [0, 2 pi) at power-up, rotor rounded to its LSB, OutPos floored), and
 * side by side with the floating-point layer on the same replies and targets: the same
 * events, flags and errors on every step, states and commands within the bounds below.
 * The test itself uses double (the library under test does not).
 */
#include "unity.h"

#include "fake_port.h"
#include "j288/j288.h"
#include "j288/jointq.h"

#include <math.h>
#include <string.h>

#define GOLDEN_WANT_FIXED
#include "golden_vectors.h"

void setUp(void) {}
void tearDown(void) {}

#define NR (5767.0 / 20.0)
#define TAU (2.0 * 3.14159265358979323846)
#define ROTOR_LSB (TAU / 32768.0)
#define COUNT (TAU / 8192.0)
#define Q24 16777216.0
#define Q16 65536.0
#define EVB(k) J288_JOINT_EV_BIT(J288_JOINT_EV_##k)
/* The fixed state's angle against the model: the start's half count (uncalibrated) or half
 * a rotor LSB (calibrated), plus the fixed path's own rounding: 16 Q24 steps (1 urad). */
#define FIXED_RES (16.0 / Q24)
#define UNCAL_TOL (0.5 * COUNT + ROTOR_LSB / NR + FIXED_RES)
#define CAL_TOL (ROTOR_LSB / NR + FIXED_RES)

/* ---- the model (as test_joint.c) */

typedef struct {
    double theta; /* output angle, continuous */
    double c;     /* rotor phase */
    double k;     /* turns lost at power-up */
} model_t;

static void power_up(model_t *m)
{
    m->k = floor((NR * m->theta + m->c) / TAU);
}

static int32_t model_pos(const model_t *m)
{
    return (int32_t)llround((NR * m->theta + m->c - TAU * m->k) / ROTOR_LSB);
}

static uint16_t model_count(const model_t *m)
{
    double t = fmod(m->theta, TAU);
    if (t < 0.0) {
        t += TAU;
    }
    return (uint16_t)((unsigned)floor(t / COUNT) & 8191u);
}

static model_t servo_at(double theta, double c)
{
    model_t m;
    m.theta = theta;
    m.c = c;
    power_up(&m);
    return m;
}

static j288_reply_raw_t reply_of(const model_t *m, uint8_t id)
{
    j288_reply_raw_t r;
    memset(&r, 0, sizeof r);
    r.id = id;
    r.status = J288_MODE_FOC;
    r.pos = model_pos(m);
    r.out_pos = model_count(m);
    return r;
}

static uint32_t rng_state = 0x2468ACE1u;

static uint32_t rnd(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 17;
    rng_state ^= rng_state << 5;
    return rng_state;
}

static double urand(double lo, double hi)
{
    return lo + (hi - lo) * ((double)rnd() / 4294967296.0);
}

static int32_t q24(double x)
{
    return (int32_t)llround(x * Q24);
}

static int32_t q16(double x)
{
    return (int32_t)llround(x * Q16);
}

static double rad(int32_t q)
{
    return (double)q / Q24;
}

static void print_value(const char *what, double x, const char *unit)
{
    long long n = llround(x * 1000.0);
    UnityPrint("  ");
    UnityPrint(what);
    UnityPrint(": ");
    UnityPrintNumber((UNITY_INT)(n / 1000));
    UnityPrint(".");
    UnityPrintNumber((UNITY_INT)(n % 1000 / 100));
    UnityPrintNumber((UNITY_INT)(n % 100 / 10));
    UnityPrintNumber((UNITY_INT)(n % 10));
    UnityPrint(unit);
    UNITY_PRINT_EOL();
}

static j288_jointq_t jq;

static j288_jointq_config_t cfg_for(uint8_t id)
{
    j288_jointq_config_t c;
    memset(&c, 0, sizeof c);
    c.id = id;
    return c;
}

static unsigned feed(j288_jointq_t *j, const model_t *m)
{
    j288_reply_raw_t r = reply_of(m, j->cfg.id);
    unsigned ev = 0xFFFFu;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_take_reply(j, &r, &ev));
    return ev;
}

static unsigned start_joint(j288_jointq_t *j, const model_t *m)
{
    unsigned all = 0u;
    int i;
    for (i = 0; (i < 3 * (int)j->cfg.init_samples) && !j288_jointq_state(j)->known; i++) {
        all |= feed(j, m);
    }
    return all;
}

static double q_of(const j288_jointq_config_t *c, const model_t *m)
{
    return (double)c->direction * (m->theta - rad(c->zero));
}

/* ---- constants and conversions */

static void test_constants(void)
{
    TEST_ASSERT_EQUAL_INT32(q24(TAU / 2.0), J288_JOINTQ_PI);
    TEST_ASSERT_EQUAL_INT32(q24(TAU), J288_JOINTQ_TWO_PI);
    TEST_ASSERT_EQUAL_INT32(64 * 16777216, J288_JOINTQ_MAX_ANGLE);
    TEST_ASSERT_EQUAL_INT32(q24(0.010), J288_JOINTQ_DEFAULT_TRACK_TOL);
    TEST_ASSERT_EQUAL_INT32(q24(1.0), J288_JOINTQ_DEFAULT_CAL_TOL);
    TEST_ASSERT_EQUAL_INT32(q24(0.001), J288_JOINTQ_LIMIT_HYST);
    TEST_ASSERT_EQUAL_INT32(q24(-1.5), J288_Q24(-1.5));
    TEST_ASSERT_EQUAL_INT32(q16(20.25), J288_Q16(20.25));
}

static void test_golden_commands(void)
{
    unsigned i;
    for (i = 0u; i < GOLDEN_FIXED_CMD_COUNT; i++) {
        const golden_fixed_cmd_t *g = &golden_fixed_cmds[i];
        j288_cmd_q_t q;
        j288_cmd_raw_t raw, before;
        unsigned mask = 99u;
        memset(&q, 0, sizeof q);
        q.id = 5u;
        q.status = J288_MODE_FOC;
        q.watchdog = true;
        q.tau = g->q[0];
        q.speed = g->q[1];
        q.pos = g->q[2];
        q.kp = g->q[3];
        q.kd = g->q[4];
        memset(&raw, 0xA5, sizeof raw);
        before = raw;
        TEST_ASSERT_EQUAL_INT_MESSAGE(g->expect, j288_cmd_from_q(&q, &raw), g->name);
        if (g->expect == J288_OK) {
            TEST_ASSERT_EQUAL_INT16_MESSAGE(g->raw[0], raw.tau, g->name);
            TEST_ASSERT_EQUAL_INT16_MESSAGE(g->raw[1], raw.speed, g->name);
            TEST_ASSERT_EQUAL_INT32_MESSAGE(g->raw[2], raw.pos, g->name);
            TEST_ASSERT_EQUAL_INT16_MESSAGE(g->raw[3], raw.kp, g->name);
            TEST_ASSERT_EQUAL_INT16_MESSAGE(g->raw[4], raw.kd, g->name);
            TEST_ASSERT_EQUAL_UINT8(5u, raw.id);
            TEST_ASSERT_EQUAL_UINT8(J288_MODE_FOC, raw.status);
            TEST_ASSERT_TRUE(raw.watchdog);
        } else {
            TEST_ASSERT_EQUAL_MEMORY_MESSAGE(&before, &raw, sizeof raw, g->name);
        }
        TEST_ASSERT_EQUAL_INT_MESSAGE(J288_OK, j288_cmd_from_q_clamped(&q, &raw, &mask), g->name);
        TEST_ASSERT_EQUAL_UINT_MESSAGE(g->clamp_mask, mask, g->name);
        TEST_ASSERT_EQUAL_INT16_MESSAGE(g->craw[0], raw.tau, g->name);
        TEST_ASSERT_EQUAL_INT16_MESSAGE(g->craw[1], raw.speed, g->name);
        TEST_ASSERT_EQUAL_INT32_MESSAGE(g->craw[2], raw.pos, g->name);
        TEST_ASSERT_EQUAL_INT16_MESSAGE(g->craw[3], raw.kp, g->name);
        TEST_ASSERT_EQUAL_INT16_MESSAGE(g->craw[4], raw.kd, g->name);
    }
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_cmd_from_q(NULL, &(j288_cmd_raw_t){0}));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_cmd_from_q_clamped(&(j288_cmd_q_t){0}, NULL, NULL));
}

/* Speed and the encoder angle within one step of the exact value (the documented bound),
 * torque exact. */
static void test_golden_replies(void)
{
    unsigned i;
    int32_t raw;
    for (i = 0u; i < GOLDEN_FIXED_REPLY_COUNT; i++) {
        const golden_fixed_reply_t *g = &golden_fixed_replies[i];
        TEST_ASSERT_INT32_WITHIN(1, g->speed, j288_speed_to_q(g->speed_raw));
        TEST_ASSERT_EQUAL_INT32(g->torque, j288_torque_to_q(g->torque_raw));
        TEST_ASSERT_INT32_WITHIN(1, g->encoder, j288_out_pos_to_q(g->out_pos));
    }
    /* Every input, against double: the same bounds. */
    for (raw = INT16_MIN; raw <= INT16_MAX; raw++) {
        double sp = (double)raw * Q16 * TAU / 2.56 / NR;
        double tq = (double)raw * Q16 * NR / 256000.0;
        TEST_ASSERT_TRUE(fabs((double)j288_speed_to_q((int16_t)raw) - sp) <= 1.0);
        TEST_ASSERT_TRUE(fabs((double)j288_torque_to_q((int16_t)raw) - tq) <= 0.5 + 1e-6);
    }
    for (raw = 0; raw < 8192; raw++) {
        double e = ((double)raw + 0.5) * COUNT * Q24;
        TEST_ASSERT_TRUE(fabs((double)j288_out_pos_to_q((uint16_t)raw) - e) <= 1.0);
    }
    /* OutPos is taken modulo 8192. */
    TEST_ASSERT_EQUAL_INT32(j288_out_pos_to_q(5u), j288_out_pos_to_q(8192u + 5u));
}

/* ---- configuration and errors */

static void test_config_checks(void)
{
    j288_jointq_config_t c = cfg_for(3u);
    j288_jointq_t before;

    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_init(&jq, &c));
    TEST_ASSERT_EQUAL_INT8(1, jq.cfg.direction);
    TEST_ASSERT_EQUAL_INT32(-J288_JOINTQ_PI, jq.cfg.pos_min);
    TEST_ASSERT_EQUAL_INT32(J288_JOINTQ_PI, jq.cfg.pos_max);
    TEST_ASSERT_EQUAL_INT32(J288_JOINTQ_DEFAULT_TRACK_TOL, jq.cfg.track_tol);
    TEST_ASSERT_EQUAL_UINT8(8u, jq.cfg.init_samples);
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_init(NULL, &c));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_init(&jq, NULL));
    before = jq;
#define BAD(field, value, err)                                                                 \
    do {                                                                                       \
        c = cfg_for(3u);                                                                       \
        c.field = value;                                                                       \
        TEST_ASSERT_EQUAL_INT(err, j288_jointq_init(&jq, &c));                                 \
        TEST_ASSERT_EQUAL_MEMORY(&before, &jq, sizeof jq);                                     \
    } while (0)
    BAD(id, 15u, J288_ERR_BAD_ID);
    BAD(direction, 2, J288_ERR_BAD_CONFIG);
    BAD(zero, J288_JOINTQ_MAX_ANGLE + 1, J288_ERR_BAD_CONFIG);
    BAD(pos_max, -1, J288_ERR_BAD_CONFIG); /* pos_min 0 >= pos_max */
    BAD(pos_min, -J288_JOINTQ_MAX_ANGLE - 1, J288_ERR_BAD_CONFIG);
    BAD(pos_max, J288_JOINTQ_MAX_ANGLE + 1, J288_ERR_BAD_CONFIG);
    BAD(max_speed, -1, J288_ERR_BAD_CONFIG);
    BAD(max_torque, -1, J288_ERR_BAD_CONFIG);
    BAD(kp, -1, J288_ERR_BAD_CONFIG);
    BAD(kd, INT32_MIN, J288_ERR_BAD_CONFIG);
    BAD(phase, J288_JOINTQ_TWO_PI + 1, J288_ERR_BAD_CONFIG);
    BAD(track_tol, J288_JOINTQ_PI + 1, J288_ERR_BAD_CONFIG);
    BAD(track_tol, -1, J288_ERR_BAD_CONFIG);
    BAD(cal_tol, -1, J288_ERR_BAD_CONFIG);
#undef BAD
    c = cfg_for(3u);
    c.pos_min = -J288_JOINTQ_MAX_ANGLE;
    c.pos_max = J288_JOINTQ_MAX_ANGLE;
    c.zero = -J288_JOINTQ_MAX_ANGLE;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_init(&jq, &c));
    TEST_ASSERT_EQUAL_INT32(0, jq.centre);
}

static void test_errors_and_unknown(void)
{
    j288_jointq_config_t c = cfg_for(3u);
    j288_jointq_target_t t;
    j288_cmd_raw_t cmd, before;
    j288_reply_raw_t r;
    j288_q24_t z = 7;
    unsigned ev = 0u;
    model_t m = servo_at(1.0, 0.3);

    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_init(&jq, &c));
    memset(&t, 0, sizeof t);
    memset(&cmd, 0x5A, sizeof cmd);
    before = cmd;
    TEST_ASSERT_EQUAL_INT(J288_ERR_ANGLE_UNKNOWN, j288_jointq_command(&jq, &t, &cmd, NULL));
    TEST_ASSERT_EQUAL_MEMORY(&before, &cmd, sizeof cmd);
    TEST_ASSERT_EQUAL_INT(J288_ERR_ANGLE_UNKNOWN, j288_jointq_zero_here(&jq, &z));
    TEST_ASSERT_EQUAL_INT32(7, z);
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_command(NULL, &t, &cmd, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_command(&jq, NULL, &cmd, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_command(&jq, &t, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_zero_here(NULL, &z));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_zero_here(&jq, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_lock_command(NULL, &cmd));
    TEST_ASSERT_NULL(j288_jointq_state(NULL));
    j288_jointq_reset(NULL);
    j288_jointq_target_init(NULL, &t);
    r = reply_of(&m, 4u);
    TEST_ASSERT_EQUAL_INT(J288_ERR_WRONG_ID, j288_jointq_take_reply(&jq, &r, &ev));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_take_reply(&jq, NULL, &ev));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_take_reply(NULL, &r, &ev));
    TEST_ASSERT_FALSE(jq.seen);
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_UNKNOWN), feed(&jq, &m));
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_KNOWN), start_joint(&jq, &m));
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, 1.0, rad(j288_jointq_state(&jq)->pos));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_zero_here(&jq, &z));
    TEST_ASSERT_EQUAL_INT32(j288_jointq_state(&jq)->pos, z);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_lock_command(&jq, &cmd));
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_LOCK, cmd.status);
    TEST_ASSERT_EQUAL_UINT8(3u, cmd.id);
    TEST_ASSERT_TRUE(cmd.watchdog);
    TEST_ASSERT_EQUAL_INT32(0, cmd.pos);
    j288_jointq_reset(&jq);
    TEST_ASSERT_FALSE(j288_jointq_state(&jq)->known);
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_UNKNOWN), feed(&jq, &m));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_lock_command(&jq, NULL));
    /* The hold-here target of an unknown joint is 0, with the default gains. */
    c.kp = q16(7.0);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_init(&jq, &c));
    j288_jointq_target_init(&jq, NULL);
    t.pos = 99;
    j288_jointq_target_init(&jq, &t);
    TEST_ASSERT_EQUAL_INT32(0, t.pos);
    TEST_ASSERT_EQUAL_INT32(q16(7.0), t.kp);
    /* A reversed joint's zero here is its zero minus the angle; beyond +-128 rad: an error. */
    c.direction = -1;
    c.zero = q24(2.0);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_init(&jq, &c));
    (void)start_joint(&jq, &m);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_zero_here(&jq, &z));
    TEST_ASSERT_EQUAL_INT32(c.zero - j288_jointq_state(&jq)->pos, z);
    c.direction = 1;
    c.zero = J288_JOINTQ_MAX_ANGLE;
    c.pos_min = q24(-64.0);
    c.pos_max = q24(64.0);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_init(&jq, &c));
    (void)start_joint(&jq, &m);
    r = reply_of(&m, 3u);
    r.faults = J288_FAULT_OUTPUT_ENCODER;
    r.pos = (int32_t)((uint32_t)r.pos + 2000000000u); /* saturates at +120 rad */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_take_reply(&jq, &r, &ev));
    z = 7;
    TEST_ASSERT_EQUAL_INT(J288_ERR_RANGE, j288_jointq_zero_here(&jq, &z));
    TEST_ASSERT_EQUAL_INT32(7, z);
}

/* ---- against the model */

static void random_setup(j288_jointq_config_t *c, model_t *m, bool calibrated)
{
    double width = urand(0.3, 6.0), centre = urand(-3.0, 3.0);
    double dir;
    *c = cfg_for(3u);
    c->direction = (rnd() & 1u) ? (int8_t)1 : (int8_t)-1;
    dir = (double)c->direction;
    c->zero = q24(urand(-8.0, 8.0));
    c->pos_min = q24(centre - 0.5 * width);
    c->pos_max = q24(centre + 0.5 * width);
    m->c = urand(-TAU / 2.0, TAU / 2.0);
    m->theta = rad(c->zero) + dir * urand(rad(c->pos_min), rad(c->pos_max));
    power_up(m);
    m->theta = rad(c->zero) + dir * urand(rad(c->pos_min), rad(c->pos_max));
    c->has_phase = calibrated;
    c->phase = q24(m->c);
}

static void random_runs(bool calibrated, double tol, const char *label)
{
    j288_jointq_config_t c;
    model_t m;
    double worst = 0.0;
    int trial;

    for (trial = 0; trial < 400; trial++) {
        double e;
        random_setup(&c, &m, calibrated);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_init(&jq, &c));
        TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_UNKNOWN) | EVB(ANGLE_KNOWN), start_joint(&jq, &m));
        TEST_ASSERT_EQUAL(calibrated, j288_jointq_state(&jq)->calibrated);
        e = fabs(rad(j288_jointq_state(&jq)->pos) - q_of(&c, &m));
        worst = (e > worst) ? e : worst;
        TEST_ASSERT_DOUBLE_WITHIN(tol, q_of(&c, &m), rad(j288_jointq_state(&jq)->pos));
        /* moved within the range: followed to the same bound, no event */
        m.theta = rad(c.zero) + (double)c.direction * urand(rad(c.pos_min), rad(c.pos_max));
        TEST_ASSERT_EQUAL_HEX(0u, feed(&jq, &m));
        TEST_ASSERT_DOUBLE_WITHIN(tol, q_of(&c, &m), rad(j288_jointq_state(&jq)->pos));
    }
    print_value(label, worst * 1e6, " urad");
}

static void test_uncalibrated_random(void)
{
    random_runs(false, UNCAL_TOL, "uncalibrated start, worst error");
}

static void test_calibrated_random(void)
{
    random_runs(true, CAL_TOL, "calibrated start, worst error");
}

static void test_range_across_the_wrap_and_turns(void)
{
    j288_jointq_config_t c = cfg_for(2u);
    model_t m;

    c.pos_min = q24(5.8);
    c.pos_max = q24(6.8);
    m = servo_at(6.6, 1.1);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_init(&jq, &c));
    (void)start_joint(&jq, &m);
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, 6.6, rad(j288_jointq_state(&jq)->pos));
    TEST_ASSERT_FALSE(j288_jointq_state(&jq)->beyond_limit);
    /* A joint outside its range gets the label nearest to it and a limit event. */
    c.pos_min = q24(-1.0);
    c.pos_max = q24(1.0);
    m = servo_at(1.5, 0.2);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_init(&jq, &c));
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_UNKNOWN) | EVB(ANGLE_KNOWN) | EVB(LIMIT_REACHED),
                          start_joint(&jq, &m));
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, 1.5, rad(j288_jointq_state(&jq)->pos));
    m.theta = 0.9995;
    TEST_ASSERT_EQUAL_HEX(0u, feed(&jq, &m)); /* inside, but not by the hysteresis */
    m.theta = 0.95;
    TEST_ASSERT_EQUAL_HEX(EVB(LIMIT_LEFT), feed(&jq, &m));
    /* Far travel with the encoder out (fault bit 12): the rotor alone moves the angle, which
     * saturates at +-J288_JOINTQ_MAX_POS instead of overflowing. */
    {
        j288_reply_raw_t r = reply_of(&m, 2u);
        unsigned ev = 0u;
        r.faults = J288_FAULT_OUTPUT_ENCODER;
        r.pos = (int32_t)((uint32_t)r.pos + 2000000000u); /* +2e9 LSB: 1330 rad */
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_take_reply(&jq, &r, &ev));
        TEST_ASSERT_EQUAL_HEX(EVB(ENCODER_FAULT) | EVB(LIMIT_REACHED), ev);
        TEST_ASSERT_EQUAL_INT32(J288_JOINTQ_MAX_POS, j288_jointq_state(&jq)->pos);
        TEST_ASSERT_TRUE(j288_jointq_state(&jq)->beyond_limit);
        r.pos = (int32_t)((uint32_t)r.pos - 4000000000u); /* -2e9 LSB from the start */
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_take_reply(&jq, &r, &ev));
        TEST_ASSERT_EQUAL_INT32(-J288_JOINTQ_MAX_POS, j288_jointq_state(&jq)->pos);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_zero_here(&jq, &(j288_q24_t){0}));
    }
}

static void test_power_cycle_and_encoder_fault(void)
{
    j288_jointq_config_t c = cfg_for(1u);
    j288_reply_raw_t r;
    unsigned ev = 0u;
    model_t m = servo_at(0.4, -1.3);

    c.init_samples = 2u;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_init(&jq, &c));
    (void)start_joint(&jq, &m);
    m.k += 3.0; /* power-cycled 3 rotor turns elsewhere: 65 mrad of output */
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_LOST), feed(&jq, &m));
    TEST_ASSERT_FALSE(j288_jointq_state(&jq)->known);
    TEST_ASSERT_DOUBLE_WITHIN(0.001, -3.0 * TAU / NR, rad(j288_jointq_state(&jq)->residual));
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_KNOWN), start_joint(&jq, &m));
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, 0.4, rad(j288_jointq_state(&jq)->pos));
    /* Fault bit 12: the encoder is not used; the rotor is followed. */
    r = reply_of(&m, 1u);
    r.faults = J288_FAULT_OUTPUT_ENCODER;
    r.out_pos = 4000u;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_take_reply(&jq, &r, &ev));
    TEST_ASSERT_EQUAL_HEX(EVB(ENCODER_FAULT), ev);
    TEST_ASSERT_TRUE(j288_jointq_state(&jq)->known);
    TEST_ASSERT_EQUAL_INT32(0, j288_jointq_state(&jq)->residual);
    TEST_ASSERT_EQUAL_HEX(EVB(ENCODER_OK), feed(&jq, &m));
    /* A wrong phase: a calibrated start refuses, reports once, and commands say why. */
    c.has_phase = true;
    c.phase = q24(m.c + 2.0);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_init(&jq, &c));
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_UNKNOWN) | EVB(CAL_MISMATCH), start_joint(&jq, &m));
    TEST_ASSERT_TRUE(j288_jointq_state(&jq)->cal_mismatch);
    TEST_ASSERT_DOUBLE_WITHIN(0.2, 2.0, rad(j288_jointq_state(&jq)->cal_residual));
    TEST_ASSERT_EQUAL_HEX(0u, feed(&jq, &m) | feed(&jq, &m));
    {
        j288_jointq_target_t t;
        j288_cmd_raw_t cmd;
        memset(&t, 0, sizeof t);
        TEST_ASSERT_EQUAL_INT(J288_ERR_CAL_MISMATCH, j288_jointq_command(&jq, &t, &cmd, NULL));
    }
}

/* The turn choice at exactly a half turn from the range's middle (a wrap's boundary), far
 * zeros with a calibrated start (theta beyond +-20 pi, reduced by 40 pi), and a start that
 * sees a huge rotor jump between samples or an encoder fault. */
static void test_edges_of_the_start(void)
{
    j288_jointq_config_t c = cfg_for(5u);
    j288_reply_raw_t r;
    unsigned ev = 0u;
    model_t m = servo_at(0.3, 0.7);
    int32_t enc = j288_out_pos_to_q(model_count(&m));
    int sign;

    for (sign = -1; sign <= 1; sign += 2) {
        /* zero a hair more than pi from the encoder angle: q = -+(pi + 100 steps) labels as
         * +-(pi - 100 steps) within the default range's middle */
        c = cfg_for(5u);
        c.zero = enc - sign * (J288_JOINTQ_PI + 100);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_init(&jq, &c));
        (void)start_joint(&jq, &m);
        TEST_ASSERT_INT32_WITHIN(1, -sign * (J288_JOINTQ_TWO_PI - J288_JOINTQ_PI - 100),
                                 j288_jointq_state(&jq)->pos);
    }
    for (sign = -1; sign <= 1; sign += 2) {
        double theta = 65.0 * (double)sign;
        m = servo_at(theta, -0.4);
        c = cfg_for(5u);
        c.zero = q24(60.0 * (double)sign);
        c.pos_min = q24(sign > 0 ? 3.0 : -7.0);
        c.pos_max = q24(sign > 0 ? 7.0 : -3.0);
        c.has_phase = true;
        c.phase = q24(m.c);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_init(&jq, &c));
        TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_UNKNOWN) | EVB(ANGLE_KNOWN), start_joint(&jq, &m));
        TEST_ASSERT_TRUE(j288_jointq_state(&jq)->calibrated);
        TEST_ASSERT_DOUBLE_WITHIN(CAL_TOL, 5.0 * (double)sign, rad(j288_jointq_state(&jq)->pos));
    }
    /* 150 million LSB between two samples (26 output rad modulo 20 turns): the second
     * disagrees and the collection starts again from it. */
    m = servo_at(0.3, 0.7);
    c = cfg_for(5u);
    c.init_samples = 2u;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_init(&jq, &c));
    r = reply_of(&m, 5u);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_take_reply(&jq, &r, &ev));
    r.pos = (int32_t)((uint32_t)r.pos + 150000000u);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_take_reply(&jq, &r, &ev));
    TEST_ASSERT_FALSE(j288_jointq_state(&jq)->known);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_take_reply(&jq, &r, &ev));
    TEST_ASSERT_TRUE(j288_jointq_state(&jq)->known);
    /* Fault bit 12 before the start: no start from the encoder, however many replies. */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_init(&jq, &c));
    r = reply_of(&m, 5u);
    r.faults = J288_FAULT_OUTPUT_ENCODER;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_take_reply(&jq, &r, &ev));
    TEST_ASSERT_EQUAL_HEX(EVB(ENCODER_FAULT) | EVB(ANGLE_UNKNOWN), ev);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_take_reply(&jq, &r, &ev));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_take_reply(&jq, &r, &ev));
    TEST_ASSERT_FALSE(j288_jointq_state(&jq)->known);
    TEST_ASSERT_EQUAL_HEX(EVB(ENCODER_OK), feed(&jq, &m));
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_KNOWN), feed(&jq, &m));
}

/* ---- targets */

static void known_joint(const j288_jointq_config_t *c, model_t *m)
{
    *m = servo_at(0.2, -0.9);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_init(&jq, c));
    (void)start_joint(&jq, m);
    TEST_ASSERT_TRUE(j288_jointq_state(&jq)->known);
}

static j288_jointq_config_t limited_cfg(bool clamp)
{
    j288_jointq_config_t c = cfg_for(6u);
    c.pos_min = q24(-0.5);
    c.pos_max = q24(1.25);
    c.max_speed = q16(3.0);
    c.max_torque = q16(10.0);
    c.clamp = clamp;
    return c;
}

static void test_limits_refused_and_clamped(void)
{
    j288_jointq_config_t c = limited_cfg(false);
    j288_jointq_target_t t, ok;
    j288_cmd_raw_t cmd, before, at_limit;
    unsigned mask = 99u;
    model_t m;

    known_joint(&c, &m);
    j288_jointq_target_init(&jq, &ok);
    TEST_ASSERT_EQUAL_INT32(j288_jointq_state(&jq)->pos, ok.pos);
    memset(&cmd, 0x33, sizeof cmd);
    before = cmd;
    /* Refused, in this order: position, speed, torque; then the wire's ranges. */
    t = ok;
    t.pos = q24(1.26);
    t.speed = q16(4.0);
    TEST_ASSERT_EQUAL_INT(J288_ERR_LIMIT_POS, j288_jointq_command(&jq, &t, &cmd, &mask));
    t.pos = ok.pos;
    TEST_ASSERT_EQUAL_INT(J288_ERR_LIMIT_SPEED, j288_jointq_command(&jq, &t, &cmd, &mask));
    t.speed = q16(-3.0);
    t.torque = q16(-10.5);
    TEST_ASSERT_EQUAL_INT(J288_ERR_LIMIT_TORQUE, j288_jointq_command(&jq, &t, &cmd, &mask));
    t.torque = 0;
    t.kp = -1;
    TEST_ASSERT_EQUAL_INT(J288_ERR_NEG_GAIN, j288_jointq_command(&jq, &t, &cmd, &mask));
    t.kp = q16(3000.0);
    TEST_ASSERT_EQUAL_INT(J288_ERR_RANGE_KP, j288_jointq_command(&jq, &t, &cmd, &mask));
    t.kp = 0;
    t.kd = q16(30.0);
    TEST_ASSERT_EQUAL_INT(J288_ERR_RANGE_KD, j288_jointq_command(&jq, &t, &cmd, &mask));
    TEST_ASSERT_EQUAL_MEMORY(&before, &cmd, sizeof cmd);
    TEST_ASSERT_EQUAL_UINT(99u, mask);
    /* At the limits exactly: accepted. */
    t = ok;
    t.pos = c.pos_max;
    t.speed = -c.max_speed;
    t.torque = c.max_torque;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_command(&jq, &t, &at_limit, &mask));
    TEST_ASSERT_EQUAL_UINT(0u, mask);
    /* Without limits the wire's range: torque 36.9 N*m, speed 279 rad/s at the output. */
    c = cfg_for(6u);
    known_joint(&c, &m);
    t = ok;
    t.torque = q16(37.0);
    TEST_ASSERT_EQUAL_INT(J288_ERR_RANGE_TAU, j288_jointq_command(&jq, &t, &cmd, NULL));
    t.torque = 0;
    t.speed = q16(-280.0);
    TEST_ASSERT_EQUAL_INT(J288_ERR_RANGE_SPEED, j288_jointq_command(&jq, &t, &cmd, NULL));
    /* Clamp mode: saturated at the same limits, the fields reported. */
    c = limited_cfg(true);
    known_joint(&c, &m);
    t = ok;
    t.pos = q24(9.0);
    t.speed = q16(-40.0);
    t.torque = q16(11.0);
    t.kp = -5;
    t.kd = q16(30.0);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_command(&jq, &t, &cmd, &mask));
    TEST_ASSERT_EQUAL_HEX(J288_FIELD_POS | J288_FIELD_SPEED | J288_FIELD_TAU | J288_FIELD_KP |
                              J288_FIELD_KD,
                          mask);
    TEST_ASSERT_EQUAL_INT32(at_limit.pos, cmd.pos);
    TEST_ASSERT_EQUAL_INT16(at_limit.speed, cmd.speed);
    TEST_ASSERT_EQUAL_INT16(at_limit.tau, cmd.tau);
    TEST_ASSERT_EQUAL_INT16(0, cmd.kp);
    TEST_ASSERT_EQUAL_INT16(INT16_MAX, cmd.kd);
}

/* Rotor positions near the ends of int32: followed modulo 2^32; a target beyond the wire's
 * int32 from there is refused (J288_ERR_RANGE_POS), never wrapped. */
static void test_large_rotor_positions(void)
{
    j288_jointq_config_t c = cfg_for(3u);
    j288_jointq_target_t t;
    j288_cmd_raw_t cmd;
    j288_reply_raw_t r;
    model_t m = servo_at(5.9, 0.1);
    int i;

    c.pos_min = q24(2.0);
    c.pos_max = q24(8.0);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_init(&jq, &c));
    for (i = 0; i < 10; i++) {
        r = reply_of(&m, 3u);
        r.pos = INT32_MAX - 1000;
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_take_reply(&jq, &r, NULL));
    }
    TEST_ASSERT_TRUE(j288_jointq_state(&jq)->known);
    r.pos = INT32_MIN + 1000; /* 2001 LSB further on, wrapped */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_take_reply(&jq, &r, NULL));
    TEST_ASSERT_DOUBLE_WITHIN(1e-7, 2001.0 * ROTOR_LSB / NR,
                              rad(j288_jointq_state(&jq)->pos) - rad(jq.ref_q));
    j288_jointq_target_init(&jq, &t);
    t.pos = q24(5.99);
    TEST_ASSERT_EQUAL_INT(J288_ERR_RANGE_POS, j288_jointq_command(&jq, &t, &cmd, NULL));
    t.pos = q24(5.0);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_command(&jq, &t, &cmd, NULL));
    TEST_ASSERT_TRUE(cmd.pos > 0);
    /* The same at the other end of int32. */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_init(&jq, &c));
    for (i = 0; i < 10; i++) {
        r = reply_of(&m, 3u);
        r.pos = INT32_MIN + 1000;
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_take_reply(&jq, &r, NULL));
    }
    t.pos = q24(5.8);
    TEST_ASSERT_EQUAL_INT(J288_ERR_RANGE_POS, j288_jointq_command(&jq, &t, &cmd, NULL));
    t.pos = q24(6.0);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_command(&jq, &t, &cmd, NULL));
    TEST_ASSERT_TRUE(cmd.pos < 0);
}

#if J288_CONFIG_SI
/* ---- side by side with the floating-point layer */

#if J288_CONFIG_SI_FLOAT
#define TWIN_POS_TOL (3e-6)  /* rad: the float layer's own ~1 urad, and ours */
#define TWIN_Q16_TOL 3.0     /* Q16 steps: float's relative 6e-8 on up to 279 rad/s */
#define TWIN_HALF_MARGIN 0.01 /* LSB: float products this close to a half may go either way */
#define TWIN_CMD_POS_TOL 6     /* rotor LSB: 3 urad of output is 4.5 LSB */
#else
#define TWIN_POS_TOL (16.0 / Q24) /* 1 urad: the bound the header states, with margin */
#define TWIN_Q16_TOL 1.0
#define TWIN_HALF_MARGIN 1e-6
#define TWIN_CMD_POS_TOL 1 /* rotor LSB: the anchors differ by 0.1 LSB at most */
#endif

static j288_joint_t jf;

static j288_joint_config_t float_cfg(const j288_jointq_config_t *c)
{
    j288_joint_config_t f;
    memset(&f, 0, sizeof f);
    f.id = c->id;
    f.direction = c->direction;
    f.clamp = c->clamp;
    f.has_phase = c->has_phase;
    f.init_samples = c->init_samples;
    f.zero = (j288_real_t)rad(c->zero);
    f.pos_min = (j288_real_t)rad(c->pos_min);
    f.pos_max = (j288_real_t)rad(c->pos_max);
    f.max_speed = (j288_real_t)((double)c->max_speed / Q16);
    f.max_torque = (j288_real_t)((double)c->max_torque / Q16);
    f.kp = (j288_real_t)((double)c->kp / Q16);
    f.kd = (j288_real_t)((double)c->kd / Q16);
    f.phase = (j288_real_t)rad(c->phase);
    return f;
}

static double worst_pos, worst_q16;

static void twin_reply(const j288_reply_raw_t *r)
{
    const j288_jointq_state_t *a = j288_jointq_state(&jq);
    const j288_joint_state_t *b = j288_joint_state(&jf);
    unsigned ea = 0u, eb = 0u;
    double e;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_take_reply(&jq, r, &ea));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_take_reply(&jf, r, &eb));
    TEST_ASSERT_EQUAL_HEX(eb, ea);
    TEST_ASSERT_EQUAL(b->known, a->known);
    TEST_ASSERT_EQUAL(b->calibrated, a->calibrated);
    TEST_ASSERT_EQUAL(b->beyond_limit, a->beyond_limit);
    TEST_ASSERT_EQUAL(b->cal_mismatch, a->cal_mismatch);
    if (a->known) {
        e = fabs(rad(a->pos) - (double)b->pos);
        worst_pos = (e > worst_pos) ? e : worst_pos;
        TEST_ASSERT_TRUE(e <= TWIN_POS_TOL);
        TEST_ASSERT_TRUE(fabs(rad(a->residual) - (double)b->residual) <= TWIN_POS_TOL);
    }
    e = fabs((double)a->speed - (double)b->speed * Q16);
    e = fmax(e, fabs((double)a->torque - (double)b->torque * Q16));
    worst_q16 = (e > worst_q16) ? e : worst_q16;
    TEST_ASSERT_TRUE(e <= TWIN_Q16_TOL);
}

/* |v| is within the margin of a half: the two paths may round apart. */
static bool near_half(double v)
{
    double f = fabs(v) - floor(fabs(v));
    return fabs(f - 0.5) < TWIN_HALF_MARGIN;
}

static void twin_command(const j288_jointq_target_t *t)
{
    j288_joint_target_t tf;
    j288_cmd_raw_t a, b;
    unsigned ma = 0u, mb = 0u;
    int ea, eb;
    double d = (double)jq.cfg.direction;
    tf.pos = (j288_real_t)rad(t->pos);
    tf.speed = (j288_real_t)((double)t->speed / Q16);
    tf.torque = (j288_real_t)((double)t->torque / Q16);
    tf.kp = (j288_real_t)((double)t->kp / Q16);
    tf.kd = (j288_real_t)((double)t->kd / Q16);
    memset(&a, 0, sizeof a);
    memset(&b, 0, sizeof b);
    ea = j288_jointq_command(&jq, t, &a, &ma);
    eb = j288_joint_command(&jf, &tf, &b, &mb);
    TEST_ASSERT_EQUAL_INT(eb, ea);
    if (ea != J288_OK) {
        return;
    }
    TEST_ASSERT_EQUAL_HEX(mb, ma);
    /* Positions: the anchors differ by the bound above (1.5 rotor LSB per urad). */
    TEST_ASSERT_INT32_WITHIN(TWIN_CMD_POS_TOL, b.pos, a.pos);
    if (!near_half(d * (double)tf.torque / NR * 256000.0)) {
        TEST_ASSERT_EQUAL_INT16(b.tau, a.tau);
    }
    if (!near_half(d * (double)tf.speed * NR * 2.56 / TAU)) {
        TEST_ASSERT_EQUAL_INT16(b.speed, a.speed);
    }
    if (!near_half((double)tf.kp / (NR * NR) * 1280000.0)) {
        TEST_ASSERT_EQUAL_INT16(b.kp, a.kp);
    }
    if (!near_half((double)tf.kd / (NR * NR) * 128000000.0)) {
        TEST_ASSERT_EQUAL_INT16(b.kd, a.kd);
    }
    TEST_ASSERT_EQUAL_UINT8(b.id, a.id);
    TEST_ASSERT_EQUAL_UINT8(b.status, a.status);
    TEST_ASSERT_EQUAL(b.watchdog, a.watchdog);
}

static void test_side_by_side_with_float(void)
{
    j288_jointq_config_t c;
    j288_joint_config_t fc;
    model_t m;
    int trial, step;

    worst_pos = 0.0;
    worst_q16 = 0.0;
    for (trial = 0; trial < 300; trial++) {
        random_setup(&c, &m, (trial & 1) != 0);
        c.clamp = (trial & 2) != 0;
        c.max_speed = (trial & 4) ? q16(urand(0.5, 50.0)) : 0;
        c.max_torque = (trial & 8) ? q16(urand(0.5, 30.0)) : 0;
        c.init_samples = (uint8_t)(1u + rnd() % 12u);
        fc = float_cfg(&c);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_init(&jq, &c));
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&jf, &fc));
        for (step = 0; step < 40; step++) {
            j288_reply_raw_t r = reply_of(&m, 3u);
            j288_jointq_target_t t;
            r.speed = (int16_t)(int32_t)(rnd() % 65536u - 32768u);
            r.torque = (int16_t)(int32_t)(rnd() % 65536u - 32768u);
            twin_reply(&r);
            /* targets: mostly inside, some beyond each limit and the wire's ranges */
            t.pos = c.pos_min + (int32_t)(rnd() % (uint32_t)(c.pos_max - c.pos_min + 1));
            if (rnd() % 8u == 0u) {
                t.pos += q24(urand(-0.5, 0.5));
            }
            t.speed = q16(urand(-300.0, 300.0) * ((rnd() % 4u == 0u) ? 1.0 : 0.05));
            t.torque = q16(urand(-40.0, 40.0) * ((rnd() % 4u == 0u) ? 1.0 : 0.2));
            t.kp = q16(urand(-100.0, 2200.0) * ((rnd() % 4u == 0u) ? 1.0 : 0.05));
            t.kd = q16(urand(-1.0, 22.0) * ((rnd() % 4u == 0u) ? 1.0 : 0.1));
            twin_command(&t);
            /* the joint moves about its range, sometimes beyond it */
            m.theta += urand(-0.05, 0.05);
            if (rnd() % 64u == 0u) {
                m.k += 1.0; /* a power cycle: both lose the angle on the same reply */
            }
        }
    }
    print_value("fixed vs float joint angle, worst", worst_pos * 1e9, " nrad");
    print_value("fixed vs float speed / torque, worst", worst_q16, " Q16 steps");
}
#endif /* J288_CONFIG_SI */

/* ---- binding */

#define US 1000u
#define JID 4u

static fake_port_t fp;
static j288_bus_t bus;
static j288_sched_t sch;
static j288_jointq_bus_t jb;
static j288_jointq_event_t jev[16];
static int njev;

static void on_event(void *user, const j288_jointq_event_t *ev)
{
    TEST_ASSERT_EQUAL_PTR(&fp, user);
    if (njev < 16) {
        jev[njev] = *ev;
    }
    njev++;
}

static void sweep(const model_t *m)
{
    j288_reply_raw_t r = reply_of(m, JID);
    fp.servo[JID].reply.pos = r.pos;
    fp.servo[JID].reply.out_pos = r.out_pos;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_start_sweep(&sch, fake_port_now_us(&fp)));
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, fp.now_ns + 20000u * US));
}

static j288_cmd_raw_t last_frame(void)
{
    j288_cmd_raw_t c;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_cmd_decode(fp.last.data, &c, NULL));
    return c;
}

static void test_binding(void)
{
    j288_sched_config_t sc;
    j288_jointq_config_t c = cfg_for(JID);
    j288_jointq_t other;
    j288_jointq_target_t t;
    j288_cmd_raw_t want, foc;
    j288_reply_raw_t r;
    model_t m = servo_at(-0.8, 0.6);
    int i;

    c.init_samples = 3u;
    memset(&sc, 0, sizeof sc);
    sc.on_reply = j288_jointq_bus_on_reply;
    sc.user = &jb;
    njev = 0;
    fake_port_init(&fp);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_init(&bus, &fp.ops, &fp, NULL));
    fake_port_attach(&fp, &bus);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_init(&sch, &bus, &sc));
    fp.poll_fn = fake_port_poll_sched;
    fp.poll_user = &sch;
    r = reply_of(&m, JID);
    fake_port_add_servo(&fp, JID, &r);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_init(&jq, &c));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_bus_init(NULL, &sch, on_event, &fp));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_bus_init(&jb, NULL, on_event, &fp));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_bus_init(&jb, &sch, on_event, &fp));
    memset(&foc, 0, sizeof foc);
    foc.id = JID;
    foc.status = J288_MODE_FOC;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_set_cmd(&sch, &foc));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_bus_add(&jb, &jq));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_enable(&sch, JID, true));
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_LOCK, j288_sched_slot(&sch, JID)->cmd.status);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_init(&other, &c));
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, j288_jointq_bus_add(&jb, &other));
    memset(&t, 0, sizeof t);
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_ARG, j288_jointq_bus_set_target(&jb, &other, &t, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_ARG, j288_jointq_bus_lock(&jb, &other));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_bus_lock(NULL, &jq));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_bus_add(&jb, NULL));
    j288_jointq_bus_on_reply(NULL, JID, NULL); /* ignored */
    /* Unknown: lock, even after a FOC command slipped into the slot. */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_set_cmd(&sch, &foc));
    sweep(&m);
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_FOC, last_frame().status);
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_LOCK, j288_sched_slot(&sch, JID)->cmd.status);
    TEST_ASSERT_EQUAL_INT(J288_ERR_ANGLE_UNKNOWN, j288_jointq_bus_set_target(&jb, &jq, &t, NULL));
    sweep(&m);
    sweep(&m);
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_LOCK, last_frame().status);
    TEST_ASSERT_EQUAL_INT(2, njev);
    TEST_ASSERT_EQUAL_INT(J288_JOINT_EV_ANGLE_UNKNOWN, jev[0].kind);
    TEST_ASSERT_EQUAL_INT(J288_JOINT_EV_ANGLE_KNOWN, jev[1].kind);
    TEST_ASSERT_EQUAL_UINT8(JID, jev[1].id);
    TEST_ASSERT_EQUAL_PTR(&jq, jev[1].joint);
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, -0.8, rad(jev[1].value));
    /* Known: the target goes out as j288_jointq_command() makes it. */
    j288_jointq_target_init(&jq, &t);
    t.pos = q24(-0.7);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_bus_set_target(&jb, &jq, &t, NULL));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_command(&jq, &t, &want, NULL));
    sweep(&m);
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_FOC, last_frame().status);
    TEST_ASSERT_EQUAL_INT32(want.pos, last_frame().pos);
    /* A power cycle: lost, and the slot is lock before the next transaction. */
    m.k += 40.0;
    sweep(&m);
    TEST_ASSERT_EQUAL_INT(3, njev);
    TEST_ASSERT_EQUAL_INT(J288_JOINT_EV_ANGLE_LOST, jev[2].kind);
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_LOCK, j288_sched_slot(&sch, JID)->cmd.status);
    for (i = 0; i < 3; i++) {
        sweep(&m);
        TEST_ASSERT_EQUAL_UINT8(J288_MODE_LOCK, last_frame().status);
    }
    TEST_ASSERT_EQUAL_INT(4, njev);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_bus_set_target(&jb, &jq, &t, NULL));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_bus_lock(&jb, &jq));
    sweep(&m);
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_LOCK, last_frame().status);
    /* A wrong phase: the mismatch event carries eps. */
    c.has_phase = true;
    c.phase = q24(m.c + 2.0);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_init(&jq, &c));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_bus_add(&jb, &jq)); /* again: the same joint */
    njev = 0;
    for (i = 0; i < 3; i++) {
        sweep(&m);
    }
    TEST_ASSERT_EQUAL_INT(2, njev);
    TEST_ASSERT_EQUAL_INT(J288_JOINT_EV_CAL_MISMATCH, jev[1].kind);
    TEST_ASSERT_DOUBLE_WITHIN(0.2, 2.0, rad(jev[1].value));
    /* Argument checks, and a joint whose id was overwritten is not the bound one. */
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_bus_add(NULL, &jq));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_bus_set_target(NULL, &jq, &t, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_bus_set_target(&jb, NULL, &t, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_bus_lock(&jb, NULL));
    other.cfg.id = 15u;
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_ARG, j288_jointq_bus_set_target(&jb, &other, &t, NULL));
}

/* The hook called directly: no callback, bad ids, a slot of another servo, an unbound id. */
static void test_binding_hook_inputs(void)
{
    j288_jointq_bus_t b;
    j288_slot_t slot;
    j288_jointq_config_t c = cfg_for(2u);
    model_t m = servo_at(0.5, 0.1);

    fake_port_init(&fp);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_init(&bus, &fp.ops, &fp, NULL));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_init(&sch, &bus, NULL));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_bus_init(&b, &sch, NULL, NULL));
    c.init_samples = 1u;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_init(&jq, &c));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_bus_add(&b, &jq));
    memset(&slot, 0, sizeof slot);
    slot.reply = reply_of(&m, 2u);
    j288_jointq_bus_on_reply(&b, 15u, &slot);     /* no such id: nothing */
    j288_jointq_bus_on_reply(&b, 2u, NULL);       /* nothing */
    j288_jointq_bus_on_reply(NULL, 2u, &slot);    /* nothing */
    j288_jointq_bus_on_reply(&b, 3u, &slot);      /* no joint 3: nothing */
    TEST_ASSERT_FALSE(jq.seen);
    slot.reply.id = 7u;
    j288_jointq_bus_on_reply(&b, 2u, &slot);      /* another servo's reply: refused */
    TEST_ASSERT_FALSE(jq.seen);
    slot.reply.id = 2u;
    j288_jointq_bus_on_reply(&b, 2u, &slot);      /* no callback: the state still moves */
    TEST_ASSERT_TRUE(j288_jointq_state(&jq)->known);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_constants);
    RUN_TEST(test_golden_commands);
    RUN_TEST(test_golden_replies);
    RUN_TEST(test_config_checks);
    RUN_TEST(test_errors_and_unknown);
    RUN_TEST(test_uncalibrated_random);
    RUN_TEST(test_calibrated_random);
    RUN_TEST(test_range_across_the_wrap_and_turns);
    RUN_TEST(test_power_cycle_and_encoder_fault);
    RUN_TEST(test_edges_of_the_start);
    RUN_TEST(test_limits_refused_and_clamped);
    RUN_TEST(test_large_rotor_positions);
#if J288_CONFIG_SI
    RUN_TEST(test_side_by_side_with_float);
#endif
    RUN_TEST(test_binding);
    RUN_TEST(test_binding_hook_inputs);
    return UNITY_END();
}
