/*
 * The joint layer against a physical model of the servo written here, independently of the
 * library: r = N * theta + c, the rotor position p = r - 2 pi k with k fixed at power-up so
 * that p starts in [0, 2 pi), the rotor reported in 32768 LSB per turn (rounded), OutPos =
 * floor((theta mod 2 pi) * 8192 / 2 pi). Many random phases, start poses, power-up poses,
 * zeros, directions and ranges; runs with j288_real_t = double, and float
 * (J288_CONFIG_SI_FLOAT=1, the Cortex-M4F target build), with tolerances to match.
 */
#include "unity.h"

#include "fake_port.h"
#include "j288/j288.h"
#include "j288/joint.h"

#include <math.h>
#include <string.h>

void setUp(void) {}
void tearDown(void) {}

#define NR J288_GEAR_RATIO
#define TAU (2.0 * J288_PI)
#define ROTOR_LSB (TAU / 32768.0)      /* rotor rad per position LSB */
#define COUNT (TAU / 8192.0)           /* output rad per OutPos count */
#define ROTOR_RES (0.5 * ROTOR_LSB / NR) /* output rad: half a rotor LSB */
#define FAULT12 J288_FAULT_OUTPUT_ENCODER
#define EVB(k) J288_JOINT_EV_BIT(J288_JOINT_EV_##k)

/* Arithmetic slack of the library's reals on angles of a few rad. */
#if J288_CONFIG_SI_FLOAT
#define EPS 6e-6
#else
#define EPS 1e-9
#endif
#define UNCAL_TOL (0.5 * COUNT + 2.0 * ROTOR_RES + EPS) /* half a count: the centre's error */
#define CAL_TOL (2.0 * ROTOR_RES + EPS)                 /* the rotor's resolution */

/* ---- the model */

typedef struct {
    double theta;    /* output angle, continuous, in the joint's turn labelling */
    double c;        /* rotor phase for that labelling */
    double k;        /* turns lost at power-up */
    double backlash; /* rad of output: the encoder's flange lags the gear by half of it */
    double side;     /* +1 / -1: the side of the backlash (the last motion's direction) */
    double theta_pu; /* where it was powered up */
} model_t;

static void power_up(model_t *m)
{
    m->theta_pu = m->theta;
    m->k = floor((NR * m->theta + m->c) / TAU); /* p restarts in [0, 2 pi) */
}

static int32_t model_pos(const model_t *m)
{
    double p = NR * m->theta + m->c - TAU * m->k;
    return (int32_t)llround(p / ROTOR_LSB);
}

static uint16_t model_count(const model_t *m)
{
    double t = fmod(m->theta + m->side * m->backlash * 0.5, TAU);
    if (t < 0.0) {
        t += TAU;
    }
    return (uint16_t)((unsigned)floor(t / COUNT) & 8191u);
}

static void move_to(model_t *m, double theta)
{
    if (theta != m->theta) {
        m->side = (theta > m->theta) ? -1.0 : 1.0;
    }
    m->theta = theta;
}

/* A servo at output angle theta with phase c, just powered up there. */
static model_t servo_at(double theta, double c)
{
    model_t m;
    memset(&m, 0, sizeof m);
    m.side = 1.0;
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
    r.voltage_raw = 48u;
    r.pos = model_pos(m);
    r.out_pos = model_count(m);
    return r;
}

#ifndef TEST_JOINT_SEED
#define TEST_JOINT_SEED 0x12345678u /* another (-DTEST_JOINT_SEED=...) must pass too */
#endif
static uint32_t rng_state = TEST_JOINT_SEED;

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

static double wrap(double x)
{
    return x - TAU * floor(x / TAU + 0.5);
}

static void print_urad(const char *what, double rad)
{
    long long nrad = llround(rad * 1e9);
    UnityPrint("  ");
    UnityPrint(what);
    UnityPrint(": ");
    UnityPrintNumber((UNITY_INT)(nrad / 1000));
    UnityPrint(".");
    UnityPrintNumber((UNITY_INT)(nrad % 1000 / 100));
    UnityPrintNumber((UNITY_INT)(nrad % 100 / 10));
    UnityPrintNumber((UNITY_INT)(nrad % 10));
    UnityPrint(" urad");
    UNITY_PRINT_EOL();
}

/* ---- joint helpers */

static j288_joint_t joint;

static j288_joint_config_t cfg_for(uint8_t id)
{
    j288_joint_config_t c;
    memset(&c, 0, sizeof c);
    c.id = id;
    return c;
}

static unsigned feed(j288_joint_t *j, const model_t *m)
{
    j288_reply_raw_t r = reply_of(m, j->cfg.id);
    unsigned ev = 0xFFFFu;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_take_reply(j, &r, &ev));
    return ev;
}

static unsigned feed_faulty(j288_joint_t *j, const model_t *m, uint16_t out_pos)
{
    j288_reply_raw_t r = reply_of(m, j->cfg.id);
    unsigned ev = 0u;
    r.faults = FAULT12 | J288_FAULT_CASE_TEMP;
    r.out_pos = out_pos;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_take_reply(j, &r, &ev));
    return ev;
}

/* Feed replies until the angle is known (at most 3 * init_samples); the events, ORed. */
static unsigned start_joint(j288_joint_t *j, const model_t *m)
{
    unsigned all = 0u;
    int i;
    for (i = 0; (i < 3 * (int)j->cfg.init_samples) && !j288_joint_state(j)->known; i++) {
        all |= feed(j, m);
    }
    return all;
}

static double q_of(const j288_joint_config_t *c, const model_t *m)
{
    double dir = (c->direction < 0) ? -1.0 : 1.0;
    return dir * (m->theta - (double)c->zero);
}

static double q_err(const j288_joint_t *j, const model_t *m)
{
    return fabs((double)j288_joint_state(j)->pos - q_of(&j->cfg, m));
}

/* A random joint and servo: a range of width up to 6 rad anywhere within +-3 rad, zero
 * within +-8 rad, either direction, a random phase, powered up at a random pose of the
 * range, then moved to another. */
static void random_setup(j288_joint_config_t *c, model_t *m, bool calibrated)
{
    double width = urand(0.3, 6.0), centre = urand(-3.0, 3.0);
    double dir;
    *c = cfg_for(3u);
    c->direction = (rnd() & 1u) ? (int8_t)1 : (int8_t)-1;
    dir = (double)c->direction;
    c->zero = (j288_real_t)urand(-8.0, 8.0);
    c->pos_min = (j288_real_t)(centre - 0.5 * width);
    c->pos_max = (j288_real_t)(centre + 0.5 * width);
    memset(m, 0, sizeof *m);
    m->side = 1.0;
    m->c = urand(-J288_PI, J288_PI);
    m->theta = (double)c->zero + dir * urand((double)c->pos_min, (double)c->pos_max);
    power_up(m);
    m->theta = (double)c->zero + dir * urand((double)c->pos_min, (double)c->pos_max);
    c->has_phase = calibrated;
    c->phase = (j288_real_t)m->c;
}

/* Field by field: struct copies leave padding undefined, so whole objects are not compared
 * bytewise (the state is never assigned as a whole: its bytes are). */
static void assert_same_joint(const j288_joint_t *a, const j288_joint_t *b)
{
    const j288_joint_config_t *x = &a->cfg, *y = &b->cfg;
    TEST_ASSERT_TRUE((x->id == y->id) && (x->direction == y->direction) &&
                     (x->clamp == y->clamp) && (x->has_phase == y->has_phase) &&
                     (x->init_samples == y->init_samples));
    TEST_ASSERT_TRUE((x->zero == y->zero) && (x->pos_min == y->pos_min) &&
                     (x->pos_max == y->pos_max) && (x->max_speed == y->max_speed) &&
                     (x->max_torque == y->max_torque) && (x->kp == y->kp) && (x->kd == y->kd) &&
                     (x->phase == y->phase) && (x->track_tol == y->track_tol) &&
                     (x->cal_tol == y->cal_tol));
    TEST_ASSERT_TRUE((a->dir == b->dir) && (a->centre == b->centre) && (a->k_q == b->k_q) &&
                     (a->k_speed == b->k_speed) && (a->k_torque == b->k_torque));
    TEST_ASSERT_TRUE((a->ref_pos == b->ref_pos) && (a->ref_q == b->ref_q) &&
                     (a->init_pos == b->init_pos) && (a->init_e0 == b->init_e0) &&
                     (a->init_sum == b->init_sum) && (a->init_n == b->init_n) &&
                     (a->seen == b->seen));
    TEST_ASSERT_EQUAL_MEMORY(&a->st, &b->st, sizeof a->st);
}

/* ---- configuration */

static void test_config_checks(void)
{
    j288_joint_config_t c = cfg_for(2u);
    const j288_real_t nan = (j288_real_t)NAN;
    j288_joint_t before;
    int i;

    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_init(NULL, &c));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_init(&joint, NULL));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
    TEST_ASSERT_EQUAL_INT8(1, joint.cfg.direction);
    TEST_ASSERT_EQUAL_UINT8(J288_JOINT_DEFAULT_INIT_SAMPLES, joint.cfg.init_samples);
    TEST_ASSERT_EQUAL_DOUBLE((j288_real_t)-J288_PI, joint.cfg.pos_min);
    TEST_ASSERT_EQUAL_DOUBLE((j288_real_t)J288_PI, joint.cfg.pos_max);
    TEST_ASSERT_EQUAL_DOUBLE((j288_real_t)J288_JOINT_DEFAULT_TRACK_TOL, joint.cfg.track_tol);
    TEST_ASSERT_EQUAL_DOUBLE((j288_real_t)J288_JOINT_DEFAULT_CAL_TOL, joint.cfg.cal_tol);
    TEST_ASSERT_FALSE(j288_joint_state(&joint)->known);
    TEST_ASSERT_NULL(j288_joint_state(NULL));
    before = joint;
    for (i = 0; i < 26; i++) {
        int want = J288_ERR_BAD_CONFIG;
        c = cfg_for(2u);
        switch (i) {
        case 0: c.id = 15u; want = J288_ERR_BAD_ID; break;
        case 1: c.direction = 2; break;
        case 2: c.direction = -2; break;
        case 3: c.zero = (j288_real_t)65.0; break;
        case 4: c.zero = (j288_real_t)-65.0; break;
        case 5: c.zero = nan; break;
        case 6: c.pos_min = (j288_real_t)-65.0; c.pos_max = 1; break;
        case 7: c.pos_min = 1; c.pos_max = (j288_real_t)65.0; break;
        case 8: c.pos_min = (j288_real_t)0.5; c.pos_max = (j288_real_t)0.5; break;
        case 9: c.pos_min = (j288_real_t)0.5; c.pos_max = (j288_real_t)0.4; break;
        case 10: c.pos_min = nan; c.pos_max = 1; break;
        case 11: c.max_speed = -1; break;
        case 12: c.max_speed = (j288_real_t)INFINITY; break;
        case 13: c.max_torque = -1; break;
        case 14: c.max_torque = nan; break;
        case 15: c.kp = -1; break;
        case 16: c.kd = -1; break;
        case 17: c.kd = nan; break;
        case 18: c.phase = (j288_real_t)7.0; break;
        case 19: c.phase = (j288_real_t)-7.0; break;
        case 20: c.track_tol = -1; break;
        case 21: c.track_tol = (j288_real_t)3.2; break;
        case 22: c.cal_tol = -1; break;
        case 23: c.cal_tol = (j288_real_t)3.2; break;
        case 24: c.kp = nan; break;
        default: c.pos_max = (j288_real_t)-0.5; break; /* pos_min 0 > pos_max */
        }
        TEST_ASSERT_EQUAL_INT_MESSAGE(want, j288_joint_init(&joint, &c), "case");
        assert_same_joint(&before, &joint); /* untouched */
    }
    /* Edges that are fine. */
    c = cfg_for(14u);
    c.direction = -1;
    c.zero = (j288_real_t)64.0;
    c.pos_min = (j288_real_t)-64.0;
    c.pos_max = (j288_real_t)64.0;
    c.phase = (j288_real_t)(2.0 * J288_PI);
    c.track_tol = (j288_real_t)J288_PI;
    c.cal_tol = (j288_real_t)J288_PI;
    c.init_samples = 255u;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
    TEST_ASSERT_EQUAL_DOUBLE(-1.0, joint.dir);
    c.pos_min = 0;
    c.pos_max = (j288_real_t)0.001; /* pos_min 0 alone is not the default */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
    TEST_ASSERT_EQUAL_DOUBLE(0.0, joint.cfg.pos_min);
}

/* ---- the start */

static void test_default_is_the_encoder_angle_wrapped(void)
{
    j288_joint_config_t c = cfg_for(1u);
    model_t m;
    int trial;
    double worst = 0.0;

    for (trial = 0; trial < 300; trial++) {
        double want;
        unsigned ev;
        double c0 = urand(-J288_PI, J288_PI); /* drawn first, as before */
        m = servo_at(urand(-20.0, 20.0), c0);
        m.theta += urand(-3.0, 3.0);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
        ev = start_joint(&joint, &m);
        TEST_ASSERT_TRUE(j288_joint_state(&joint)->known);
        TEST_ASSERT_FALSE(j288_joint_state(&joint)->calibrated);
        TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_UNKNOWN) | EVB(ANGLE_KNOWN), ev);
        want = wrap(m.theta); /* [-pi, pi) */
        TEST_ASSERT_TRUE(j288_joint_state(&joint)->pos >= (j288_real_t)-J288_PI);
        TEST_ASSERT_TRUE(j288_joint_state(&joint)->pos < (j288_real_t)J288_PI);
        if (fabs(want) < J288_PI - COUNT) { /* away from the wrap itself */
            double e = fabs((double)j288_joint_state(&joint)->pos - want);
            TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, want, j288_joint_state(&joint)->pos);
            worst = (e > worst) ? e : worst;
        }
    }
    print_urad("uncalibrated start, default configuration, worst of 300", worst);
}

static void test_start_events_and_refusals(void)
{
    j288_joint_config_t c = cfg_for(5u);
    j288_joint_target_t t;
    j288_cmd_raw_t cmd, before;
    model_t m;
    int i;

    m = servo_at(1.0, 0.3);
    c.init_samples = 4u;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
    memset(&before, 0x5A, sizeof before);
    cmd = before;
    j288_joint_target_init(&joint, &t);
    TEST_ASSERT_EQUAL_DOUBLE(0.0, t.pos);
    TEST_ASSERT_EQUAL_INT(J288_ERR_ANGLE_UNKNOWN, j288_joint_command(&joint, &t, &cmd, NULL));
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_UNKNOWN), feed(&joint, &m));
    for (i = 0; i < 2; i++) {
        TEST_ASSERT_EQUAL_HEX(0u, feed(&joint, &m));
        TEST_ASSERT_FALSE(j288_joint_state(&joint)->known);
        TEST_ASSERT_EQUAL_INT(J288_ERR_ANGLE_UNKNOWN, j288_joint_command(&joint, &t, &cmd, NULL));
        TEST_ASSERT_EQUAL_INT(J288_ERR_ANGLE_UNKNOWN, j288_joint_zero_here(&joint, &t.pos));
    }
    TEST_ASSERT_EQUAL_MEMORY(&before, &cmd, sizeof cmd);
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_KNOWN), feed(&joint, &m));
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, 1.0, j288_joint_state(&joint)->pos);
    TEST_ASSERT_EQUAL_HEX(0u, feed(&joint, &m));
    /* A reset forgets: not yet known again, reported again. */
    j288_joint_reset(&joint);
    j288_joint_reset(NULL);
    TEST_ASSERT_FALSE(j288_joint_state(&joint)->known);
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_UNKNOWN), feed(&joint, &m));
    /* One sample is enough when configured so: both events in one reply. */
    c.init_samples = 1u;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_UNKNOWN) | EVB(ANGLE_KNOWN), feed(&joint, &m));
}

static void test_take_reply_errors(void)
{
    j288_joint_config_t c = cfg_for(5u);
    j288_reply_raw_t r;
    j288_joint_t before;
    model_t m;
    unsigned ev = 77u;

    memset(&m, 0, sizeof m);
    r = reply_of(&m, 6u);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
    before = joint;
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_take_reply(NULL, &r, &ev));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_take_reply(&joint, NULL, &ev));
    TEST_ASSERT_EQUAL_INT(J288_ERR_WRONG_ID, j288_joint_take_reply(&joint, &r, &ev));
    assert_same_joint(&before, &joint);
    TEST_ASSERT_EQUAL_UINT(77u, ev);
    r.id = 5u;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_take_reply(&joint, &r, NULL)); /* events NULL */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_take_reply(&joint, &r, &ev));
    TEST_ASSERT_EQUAL_UINT(0u, ev);
}

/* Uncalibrated and calibrated starts over random joints, then motion over the range. */
static void random_runs(bool calibrated, double tol, const char *label)
{
    j288_joint_config_t c;
    model_t m;
    int trial, step;
    double worst = 0.0;

    for (trial = 0; trial < 400; trial++) {
        double dir;
        random_setup(&c, &m, calibrated);
        dir = (double)c.direction;
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
        TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_UNKNOWN) | EVB(ANGLE_KNOWN), start_joint(&joint, &m));
        TEST_ASSERT_EQUAL(calibrated, j288_joint_state(&joint)->calibrated);
        TEST_ASSERT_DOUBLE_WITHIN(tol, q_of(&c, &m), j288_joint_state(&joint)->pos);
        worst = (q_err(&joint, &m) > worst) ? q_err(&joint, &m) : worst;
        /* A walk over the range, in steps up to 0.1 rad, either way. */
        for (step = 0; step < 40; step++) {
            double q = q_of(&c, &m) + urand(-0.1, 0.1);
            if ((q < (double)c.pos_min) || (q > (double)c.pos_max)) {
                q = urand((double)c.pos_min, (double)c.pos_max);
            }
            move_to(&m, (double)c.zero + dir * q);
            TEST_ASSERT_EQUAL_HEX(0u, feed(&joint, &m));
            TEST_ASSERT_DOUBLE_WITHIN(tol, q, j288_joint_state(&joint)->pos);
            TEST_ASSERT_DOUBLE_WITHIN(COUNT, 0.0, j288_joint_state(&joint)->residual);
        }
    }
    print_urad(label, worst);
}

static void test_uncalibrated_random(void)
{
    random_runs(false, UNCAL_TOL, "uncalibrated start, random joints, worst of 400");
}

static void test_calibrated_random(void)
{
    random_runs(true, CAL_TOL, "calibrated start, random joints, worst of 400");
}

static void test_state_speed_torque_and_direction(void)
{
    j288_joint_config_t c = cfg_for(7u);
    j288_reply_raw_t r;
    model_t m;
    int d;

    m = servo_at(0.25, 0.0);
    for (d = -1; d <= 1; d += 2) {
        c.direction = (int8_t)d;
        c.zero = (j288_real_t)0.75;
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
        (void)start_joint(&joint, &m);
        TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, d * (0.25 - 0.75), j288_joint_state(&joint)->pos);
        r = reply_of(&m, 7u);
        r.speed = -1234;
        r.torque = 4321;
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_take_reply(&joint, &r, NULL));
        TEST_ASSERT_DOUBLE_WITHIN(1e-5 * 1234.0 / J288_SCALE_SPEED / NR,
                                  (double)d * (double)j288_speed_from_raw(-1234, J288_SIDE_OUTPUT),
                                  j288_joint_state(&joint)->speed);
        TEST_ASSERT_DOUBLE_WITHIN(1e-5 * 4321.0 * NR / J288_SCALE_TORQUE,
                                  (double)d * (double)j288_torque_from_raw(4321, J288_SIDE_OUTPUT),
                                  j288_joint_state(&joint)->torque);
        TEST_ASSERT_DOUBLE_WITHIN(1e-5, (model_count(&m) + 0.5) * COUNT,
                                  j288_joint_state(&joint)->encoder);
        /* Moving the output up moves the joint by direction. */
        move_to(&m, 0.35);
        (void)feed(&joint, &m);
        TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, d * (0.35 - 0.75), j288_joint_state(&joint)->pos);
        move_to(&m, 0.25);
    }
}

/* A reversed joint at rest reports speed and torque +0, not -0 (printed "-0" by tools). */
static void test_reversed_joint_at_rest_is_plus_zero(void)
{
    j288_joint_config_t c = cfg_for(7u);
    j288_reply_raw_t r;
    model_t m = servo_at(0.25, 0.0);

    c.direction = -1;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
    (void)start_joint(&joint, &m);
    r = reply_of(&m, 7u);
    r.speed = 0;
    r.torque = 0;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_take_reply(&joint, &r, NULL));
    /* copysign, not signbit: mingw-w64's signbit macro converts a double to float in its
     * float branch, which -Wconversion rejects. */
    TEST_ASSERT_TRUE(copysign(1.0, (double)j288_joint_state(&joint)->speed) > 0.0);
    TEST_ASSERT_TRUE(copysign(1.0, (double)j288_joint_state(&joint)->torque) > 0.0);
}

/* A start with the joint moving, and one where a sample disagrees: the start restarts. */
static void test_start_while_moving_and_outlier(void)
{
    j288_joint_config_t c = cfg_for(2u);
    j288_reply_raw_t r;
    model_t m;
    int i;

    m = servo_at(2.0, -2.0);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
    for (i = 0; i < 8; i++) {
        (void)feed(&joint, &m);
        move_to(&m, m.theta + 0.013); /* 17 counts a reply */
    }
    TEST_ASSERT_TRUE(j288_joint_state(&joint)->known);
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, m.theta - 0.013, j288_joint_state(&joint)->pos);

    /* Sample 4 of 8 reads 30 counts off: the collection restarts from it, then again from
     * the next good one, so 8 good samples follow. */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
    for (i = 0; i < 3; i++) {
        (void)feed(&joint, &m);
    }
    r = reply_of(&m, 2u);
    r.out_pos = (uint16_t)(r.out_pos + 30u);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_take_reply(&joint, &r, NULL));
    for (i = 0; i < 7; i++) {
        TEST_ASSERT_EQUAL_HEX(0u, feed(&joint, &m));
    }
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_KNOWN), feed(&joint, &m));
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, m.theta, j288_joint_state(&joint)->pos);
}

/* Averaging at the start pays when the joint moves: each sample's quantization differs. */
static void test_start_average_while_moving(void)
{
    j288_joint_config_t c = cfg_for(2u);
    model_t m;
    int trial, i;
    double worst = 0.0;

    c.init_samples = 64u;
    for (trial = 0; trial < 50; trial++) {
        double step = COUNT * urand(0.3, 0.7);
        double c0 = urand(-J288_PI, J288_PI);
        m = servo_at(urand(-3.0, 2.5), c0);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
        for (i = 0; i < 64; i++) {
            (void)feed(&joint, &m);
            move_to(&m, m.theta + step);
        }
        TEST_ASSERT_TRUE(j288_joint_state(&joint)->known);
        m.theta -= step;
        worst = (q_err(&joint, &m) > worst) ? q_err(&joint, &m) : worst;
    }
    TEST_ASSERT_TRUE(worst < 0.1 * COUNT); /* a fifth of the half count at rest */
    print_urad("uncalibrated start over 64 replies while moving, worst of 50", worst);
}

/* The start angle is chosen within pi of the range's middle: inside the range when the joint
 * is, else at the nearest end, with a limit event. */
static void test_turn_choice(void)
{
    j288_joint_config_t c = cfg_for(1u);
    model_t m;
    unsigned ev;

    c.pos_min = (j288_real_t)5.8; /* the encoder wraps inside: 2 pi = 6.283 */
    c.pos_max = (j288_real_t)6.8;
    m = servo_at(6.6, 0.0);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_UNKNOWN) | EVB(ANGLE_KNOWN), start_joint(&joint, &m));
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, 6.6, j288_joint_state(&joint)->pos); /* not 0.317 */

    /* Outside [0.5, 1.0]: 3.5 is 2.5 above the top end, or as 3.5 - 2 pi 3.28 below the
     * bottom end: labelled 3.5... */
    c.pos_min = (j288_real_t)0.5;
    c.pos_max = (j288_real_t)1.0;
    m.theta = 3.5;
    power_up(&m);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
    ev = start_joint(&joint, &m);
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_UNKNOWN) | EVB(ANGLE_KNOWN) | EVB(LIMIT_REACHED), ev);
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, 3.5, j288_joint_state(&joint)->pos);
    TEST_ASSERT_TRUE(j288_joint_state(&joint)->beyond_limit);
    /* ... and 4.1 is nearer the bottom end: labelled 4.1 - 2 pi = -2.18. */
    m.theta = 4.1;
    power_up(&m);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
    ev = start_joint(&joint, &m);
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_UNKNOWN) | EVB(ANGLE_KNOWN) | EVB(LIMIT_REACHED), ev);
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, 4.1 - TAU, j288_joint_state(&joint)->pos);

    /* Direction -1 and a zero: q = -(theta - zero) within pi of the middle. */
    c.direction = -1;
    c.zero = (j288_real_t)10.0;
    c.pos_min = (j288_real_t)-0.4;
    c.pos_max = (j288_real_t)0.4;
    m.theta = 10.0 - 0.3 - 2.0 * TAU; /* the same pose two turns away: the same reading */
    power_up(&m);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_UNKNOWN) | EVB(ANGLE_KNOWN), start_joint(&joint, &m));
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, 0.3, j288_joint_state(&joint)->pos);
}

/* Ranges across the encoder's wrap, crossed both ways, both directions, both modes. */
static void test_range_across_the_wrap(void)
{
    j288_joint_config_t c;
    model_t m;
    int mode, d, i;

    for (mode = 0; mode < 2; mode++) {
        for (d = -1; d <= 1; d += 2) {
            double tol = mode ? CAL_TOL : UNCAL_TOL;
            c = cfg_for(9u);
            c.direction = (int8_t)d;
            c.zero = (j288_real_t)(TAU * 3.0 + 0.2); /* theta = 6 pi + 0.2 is joint 0 */
            c.pos_min = (j288_real_t)-0.6;
            c.pos_max = (j288_real_t)0.6;
            m = servo_at((double)c.zero + d * 0.5, 1.7);
            c.has_phase = (mode == 1);
            c.phase = (j288_real_t)m.c;
            TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
            (void)start_joint(&joint, &m);
            TEST_ASSERT_DOUBLE_WITHIN(tol, 0.5, j288_joint_state(&joint)->pos);
            /* Down through theta = 6 pi (OutPos 0 -> 8191) to joint -0.55, and back. */
            for (i = 0; i <= 210; i++) {
                double q = (i <= 105) ? 0.5 - 0.01 * i : -0.55 + 0.01 * (i - 105);
                move_to(&m, (double)c.zero + d * q);
                TEST_ASSERT_EQUAL_HEX(0u, feed(&joint, &m));
                TEST_ASSERT_DOUBLE_WITHIN(tol, q, j288_joint_state(&joint)->pos);
            }
            /* A fresh start on the far side of the wrap labels the same way. */
            move_to(&m, (double)c.zero - 0.4 * d);
            j288_joint_reset(&joint);
            (void)start_joint(&joint, &m);
            TEST_ASSERT_DOUBLE_WITHIN(tol, -0.4, j288_joint_state(&joint)->pos);
        }
    }
}

/* ---- calibration at the start */

static void test_wrong_calibration(void)
{
    j288_joint_config_t c;
    j288_joint_target_t t;
    j288_cmd_raw_t cmd;
    model_t m;
    int trial, i;

    for (trial = 0; trial < 200; trial++) {
        double delta = urand(-J288_PI, J288_PI);
        unsigned ev;
        random_setup(&c, &m, true);
        c.phase = (j288_real_t)wrap(m.c + delta);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
        ev = start_joint(&joint, &m);
        if (fabs(delta) > (double)joint.cfg.cal_tol + 0.12) { /* beyond, with half a count of margin */
            TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_UNKNOWN) | EVB(CAL_MISMATCH), ev);
            TEST_ASSERT_FALSE(j288_joint_state(&joint)->known);
            TEST_ASSERT_TRUE(j288_joint_state(&joint)->cal_mismatch);
            TEST_ASSERT_DOUBLE_WITHIN(
                0.12, 0.0, wrap((double)j288_joint_state(&joint)->cal_residual - delta));
            j288_joint_target_init(&joint, &t);
            TEST_ASSERT_EQUAL_INT(J288_ERR_CAL_MISMATCH, j288_joint_command(&joint, &t, &cmd, NULL));
            /* It keeps trying, and says so once. */
            for (i = 0; i < 40; i++) {
                TEST_ASSERT_EQUAL_HEX(0u, feed(&joint, &m));
            }
            TEST_ASSERT_FALSE(j288_joint_state(&joint)->known);
            /* The calibration is put right: the next start succeeds. */
            joint.cfg.phase = (j288_real_t)m.c;
            ev = start_joint(&joint, &m);
            TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_KNOWN), ev);
            TEST_ASSERT_FALSE(j288_joint_state(&joint)->cal_mismatch);
            TEST_ASSERT_DOUBLE_WITHIN(CAL_TOL, q_of(&c, &m), j288_joint_state(&joint)->pos);
        } else if (fabs(delta) < (double)joint.cfg.cal_tol - 0.12) {
            /* Accepted: the angle is off by exactly delta / N (never more than cal_tol / N). */
            double want = q_of(&c, &m) - (double)c.direction * delta / NR;
            TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_UNKNOWN) | EVB(ANGLE_KNOWN), ev);
            TEST_ASSERT_DOUBLE_WITHIN(CAL_TOL, want, j288_joint_state(&joint)->pos);
        }
    }
}

/* ---- tracking: power cycles, slipped gears, the output encoder's fault bit */

static void test_power_cycle(void)
{
    j288_joint_config_t c;
    model_t m;
    int trial, lost = 0, harmless = 0;

    for (trial = 0; trial < 400; trial++) {
        bool calibrated = (trial & 1) != 0;
        double k_old, shift;
        unsigned ev;
        random_setup(&c, &m, calibrated);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
        (void)start_joint(&joint, &m);
        /* Power off, move somewhere in the range, power on: p restarts, theta is kept. One
         * in eight goes back to where it was powered up before: the same turn count. */
        if (trial % 8 == 0) {
            move_to(&m, m.theta_pu);
        } else {
            move_to(&m, (double)c.zero + c.direction * urand((double)c.pos_min, (double)c.pos_max));
        }
        k_old = m.k;
        power_up(&m);
        shift = TAU * (k_old - m.k) / NR; /* what the stale anchor would add */
        ev = feed(&joint, &m);
        if (fabs(wrap(shift)) > (double)joint.cfg.track_tol + COUNT) {
            TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_LOST), ev);
            TEST_ASSERT_FALSE(j288_joint_state(&joint)->known);
            TEST_ASSERT_FALSE(j288_joint_state(&joint)->calibrated);
            TEST_ASSERT_DOUBLE_WITHIN(COUNT, wrap(shift), j288_joint_state(&joint)->residual);
            lost++;
            /* It starts again from the next replies, right. */
            TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_KNOWN), start_joint(&joint, &m));
            TEST_ASSERT_DOUBLE_WITHIN(calibrated ? CAL_TOL : UNCAL_TOL, q_of(&c, &m),
                                      j288_joint_state(&joint)->pos);
        } else if (fabs(wrap(shift)) < (double)joint.cfg.track_tol - COUNT) {
            /* Undetectable, and then off by at most track_tol: the guarantee. */
            TEST_ASSERT_EQUAL_HEX(0u, ev & EVB(ANGLE_LOST));
            TEST_ASSERT_TRUE(q_err(&joint, &m) <= (double)joint.cfg.track_tol + UNCAL_TOL);
            harmless++;
        }
    }
    TEST_ASSERT_TRUE(lost > 280);
    TEST_ASSERT_TRUE(harmless >= 50); /* the same turn count: nothing to see */
}

static void test_slipped_gear(void)
{
    j288_joint_config_t c = cfg_for(4u);
    model_t m;
    int32_t p_before;

    m = servo_at(-1.0, 0.4);
    c.has_phase = true;
    c.phase = (j288_real_t)m.c;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
    (void)start_joint(&joint, &m);
    /* The rotor slips 5.5 turns against the output: 60 mrad of output. */
    p_before = model_pos(&m);
    m.c += 5.5 * TAU;
    TEST_ASSERT_TRUE(model_pos(&m) != p_before);
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_LOST), feed(&joint, &m));
    /* c is now off by half a turn: the calibrated start refuses, once. */
    TEST_ASSERT_EQUAL_HEX(EVB(CAL_MISMATCH), start_joint(&joint, &m));
    TEST_ASSERT_DOUBLE_WITHIN(0.12, J288_PI, fabs((double)j288_joint_state(&joint)->cal_residual));
    TEST_ASSERT_EQUAL_HEX(0u, start_joint(&joint, &m));
    /* Uncalibrated, the same slip is taken from the encoder. */
    c.has_phase = false;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
    (void)start_joint(&joint, &m);
    m.c += 3.0 * TAU; /* whole turns */
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_LOST), feed(&joint, &m));
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_KNOWN), start_joint(&joint, &m));
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, -1.0, j288_joint_state(&joint)->pos);
}

static void test_encoder_fault(void)
{
    j288_joint_config_t c = cfg_for(8u);
    model_t m;
    int i;

    m = servo_at(0.7, 2.5);
    c.init_samples = 3u;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
    /* Unknown and faulty: no start, whatever OutPos says. */
    TEST_ASSERT_EQUAL_HEX(EVB(ENCODER_FAULT) | EVB(ANGLE_UNKNOWN), feed_faulty(&joint, &m, 0u));
    TEST_ASSERT_TRUE(j288_joint_state(&joint)->encoder_fault);
    for (i = 0; i < 10; i++) {
        TEST_ASSERT_EQUAL_HEX(0u, feed_faulty(&joint, &m, model_count(&m)));
        TEST_ASSERT_FALSE(j288_joint_state(&joint)->known);
    }
    /* Two good replies, a faulty one (the start begins again), then three good ones. */
    TEST_ASSERT_EQUAL_HEX(EVB(ENCODER_OK), feed(&joint, &m));
    TEST_ASSERT_EQUAL_HEX(0u, feed(&joint, &m));
    TEST_ASSERT_EQUAL_HEX(EVB(ENCODER_FAULT), feed_faulty(&joint, &m, model_count(&m)));
    TEST_ASSERT_EQUAL_HEX(EVB(ENCODER_OK), feed(&joint, &m));
    TEST_ASSERT_EQUAL_HEX(0u, feed(&joint, &m));
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_KNOWN), feed(&joint, &m));
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, 0.7, j288_joint_state(&joint)->pos);
    /* Known and faulty: no comparison (a wild OutPos is ignored), the rotor is followed. */
    move_to(&m, 0.9);
    TEST_ASSERT_EQUAL_HEX(EVB(ENCODER_FAULT), feed_faulty(&joint, &m, 4000u));
    TEST_ASSERT_TRUE(j288_joint_state(&joint)->known);
    TEST_ASSERT_EQUAL_DOUBLE(0.0, j288_joint_state(&joint)->residual);
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, 0.9, j288_joint_state(&joint)->pos);
    /* Cleared: compared again, and a disagreement is a loss. */
    TEST_ASSERT_EQUAL_HEX(EVB(ENCODER_OK), feed(&joint, &m));
    TEST_ASSERT_TRUE(j288_joint_state(&joint)->known);
    m.c += TAU * 2.0;
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_LOST), feed(&joint, &m));
}

/* Positions far from the power-up pose, and rotor counts that wrap at int32. */
static void test_large_rotor_positions(void)
{
    j288_joint_config_t c = cfg_for(3u);
    j288_reply_raw_t r;
    j288_joint_target_t t;
    j288_cmd_raw_t cmd;
    model_t m;
    const int32_t base = INT32_MAX - 1000;
    int32_t p0;
    int i;

    c.pos_min = (j288_real_t)2.0;
    c.pos_max = (j288_real_t)8.0;
    m = servo_at(-5.9, 0.1);
    move_to(&m, 5.9); /* 11.8 rad from power-up: 17.8 million LSB */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
    (void)start_joint(&joint, &m);
    TEST_ASSERT_TRUE(model_pos(&m) > 17000000);
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, 5.9, j288_joint_state(&joint)->pos);
    /* Counts near INT32_MAX that wrap to negative: followed modulo 2^32. */
    p0 = model_pos(&m);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
    for (i = 0; i < 10; i++) {
        r = reply_of(&m, 3u);
        r.pos = base;
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_take_reply(&joint, &r, NULL));
    }
    TEST_ASSERT_TRUE(j288_joint_state(&joint)->known);
    move_to(&m, 5.95);
    r = reply_of(&m, 3u);
    r.pos = (int32_t)((uint32_t)base + (uint32_t)(model_pos(&m) - p0)); /* wraps */
    TEST_ASSERT_TRUE(r.pos < 0);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_take_reply(&joint, &r, NULL));
    TEST_ASSERT_TRUE(j288_joint_state(&joint)->known);
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, 5.95, j288_joint_state(&joint)->pos);
    /* A target beyond the wire's int32 from there: refused, never wrapped. */
    j288_joint_target_init(&joint, &t);
    t.pos = (j288_real_t)5.99;
    TEST_ASSERT_EQUAL_INT(J288_ERR_RANGE_POS, j288_joint_command(&joint, &t, &cmd, NULL));
    t.pos = (j288_real_t)5.0; /* backwards is fine */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_command(&joint, &t, &cmd, NULL));
    TEST_ASSERT_TRUE(cmd.pos > 0);
    /* The same at the other end of int32. */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
    for (i = 0; i < 10; i++) {
        r = reply_of(&m, 3u);
        r.pos = INT32_MIN + 1000;
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_take_reply(&joint, &r, NULL));
    }
    t.pos = (j288_real_t)5.9;
    TEST_ASSERT_EQUAL_INT(J288_ERR_RANGE_POS, j288_joint_command(&joint, &t, &cmd, NULL));
    t.pos = (j288_real_t)6.0;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_command(&joint, &t, &cmd, NULL));
    TEST_ASSERT_TRUE(cmd.pos < 0);
}

/* ---- commands */

/* Where the model's rotor must go for joint angle q (same power-up), in LSB. */
static double rotor_lsb_for(const j288_joint_config_t *c, const model_t *m, double q)
{
    double theta = (double)c->zero + (double)c->direction * q;
    return (NR * theta + m->c - TAU * m->k) / ROTOR_LSB;
}

static void test_command_frames(void)
{
    j288_joint_config_t c;
    j288_joint_target_t t;
    j288_cmd_raw_t cmd;
    model_t m;
    int trial;

    for (trial = 0; trial < 300; trial++) {
        double d, pos_tol;
        bool calibrated = (trial & 1) != 0;
        unsigned clamped = 99u;
        random_setup(&c, &m, calibrated);
        d = (double)c.direction;
        c.kp = (j288_real_t)urand(0.0, 100.0);
        c.kd = (j288_real_t)urand(0.0, 5.0);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
        (void)start_joint(&joint, &m);
        j288_joint_target_init(&joint, &t);
        TEST_ASSERT_EQUAL_DOUBLE(j288_joint_state(&joint)->pos, t.pos);
        TEST_ASSERT_EQUAL_DOUBLE(c.kp, t.kp);
        TEST_ASSERT_EQUAL_DOUBLE(c.kd, t.kd);
        t.pos = (j288_real_t)urand((double)c.pos_min, (double)c.pos_max);
        t.speed = (j288_real_t)urand(-20.0, 20.0);
        t.torque = (j288_real_t)urand(-30.0, 30.0);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_command(&joint, &t, &cmd, &clamped));
        TEST_ASSERT_EQUAL_UINT(0u, clamped);
        TEST_ASSERT_EQUAL_UINT8(3u, cmd.id);
        TEST_ASSERT_EQUAL_UINT8(J288_MODE_FOC, cmd.status);
        TEST_ASSERT_TRUE(cmd.watchdog);
        /* The position: the start's error (uncalibrated) plus rounding, in rotor LSB. */
        pos_tol = (calibrated ? 1.0 : 0.5 * COUNT * NR / ROTOR_LSB + 1.0) +
                  EPS * NR / ROTOR_LSB * 4.0;
        TEST_ASSERT_DOUBLE_WITHIN(pos_tol, rotor_lsb_for(&c, &m, (double)t.pos), (double)cmd.pos);
        TEST_ASSERT_INT_WITHIN(1, (int)lround(d * (double)t.speed * NR * J288_SCALE_SPEED),
                               cmd.speed);
        TEST_ASSERT_INT_WITHIN(1, (int)lround(d * (double)t.torque / NR * J288_SCALE_TORQUE),
                               cmd.tau);
        TEST_ASSERT_INT_WITHIN(1, (int)lround((double)t.kp / (NR * NR) * J288_SCALE_KP), cmd.kp);
        TEST_ASSERT_INT_WITHIN(1, (int)lround((double)t.kd / (NR * NR) * J288_SCALE_KD), cmd.kd);
    }
    /* The lock command. */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_lock_command(&joint, &cmd));
    TEST_ASSERT_EQUAL_UINT8(3u, cmd.id);
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_LOCK, cmd.status);
    TEST_ASSERT_TRUE(cmd.watchdog);
    TEST_ASSERT_EQUAL_INT32(0, cmd.pos);
    TEST_ASSERT_EQUAL_INT16(0, cmd.kp);
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_lock_command(NULL, &cmd));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_lock_command(&joint, NULL));
}

/* Commands bring the model's joint where the targets say: after a move, q reads the target. */
static void test_command_round_trip(void)
{
    j288_joint_config_t c;
    j288_joint_target_t t;
    j288_cmd_raw_t cmd;
    model_t m;
    int trial;

    for (trial = 0; trial < 200; trial++) {
        double theta_cmd;
        random_setup(&c, &m, (trial & 1) != 0);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
        (void)start_joint(&joint, &m);
        j288_joint_target_init(&joint, &t);
        t.pos = (j288_real_t)urand((double)c.pos_min, (double)c.pos_max);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_command(&joint, &t, &cmd, NULL));
        /* The servo holds its rotor at cmd.pos: the output is where the rotor says. */
        theta_cmd = ((double)cmd.pos * ROTOR_LSB - m.c + TAU * m.k) / NR;
        move_to(&m, theta_cmd);
        TEST_ASSERT_EQUAL_HEX(0u, feed(&joint, &m) & ~(EVB(LIMIT_LEFT)));
        TEST_ASSERT_DOUBLE_WITHIN(2.0 * ROTOR_RES + EPS, t.pos, j288_joint_state(&joint)->pos);
    }
}

static void known_joint(j288_joint_config_t *c, model_t *m)
{
    *m = servo_at(0.2, -0.9);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, c));
    (void)start_joint(&joint, m);
    TEST_ASSERT_TRUE(j288_joint_state(&joint)->known);
}

/* Joint 6 with limits [-0.5, 1.25] rad, 3 rad/s, 10 N*m, refusing or clamping. */
static j288_joint_config_t limited_cfg(bool clamp)
{
    j288_joint_config_t c = cfg_for(6u);
    c.pos_min = (j288_real_t)-0.5;
    c.pos_max = (j288_real_t)1.25;
    c.max_speed = (j288_real_t)3.0;
    c.max_torque = (j288_real_t)10.0;
    c.clamp = clamp;
    return c;
}

static void test_limits_refused(void)
{
    j288_joint_config_t c = limited_cfg(false);
    j288_joint_target_t t, good;
    j288_cmd_raw_t cmd, before;
    model_t m;
    unsigned clamped = 55u;
    int i;

    c.kp = (j288_real_t)20.0;
    c.kd = (j288_real_t)0.5;
    known_joint(&c, &m);
    j288_joint_target_init(&joint, &good);
    good.speed = (j288_real_t)3.0; /* the limits themselves are fine */
    good.torque = (j288_real_t)-10.0;
    good.pos = (j288_real_t)1.25;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_command(&joint, &good, &cmd, &clamped));
    TEST_ASSERT_EQUAL_UINT(0u, clamped);
    good.pos = (j288_real_t)-0.5;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_command(&joint, &good, &cmd, NULL));
    memset(&before, 0x3C, sizeof before);
    for (i = 0; i < 14; i++) {
        int want;
        t = good;
        switch (i) {
        case 0: t.pos = (j288_real_t)1.2501; want = J288_ERR_LIMIT_POS; break;
        case 1: t.pos = (j288_real_t)-0.5001; want = J288_ERR_LIMIT_POS; break;
        case 2: t.pos = (j288_real_t)INFINITY; want = J288_ERR_LIMIT_POS; break;
        case 3: t.speed = (j288_real_t)3.01; want = J288_ERR_LIMIT_SPEED; break;
        case 4: t.speed = (j288_real_t)-3.01; want = J288_ERR_LIMIT_SPEED; break;
        case 5: t.torque = (j288_real_t)10.01; want = J288_ERR_LIMIT_TORQUE; break;
        case 6: t.torque = (j288_real_t)-INFINITY; want = J288_ERR_LIMIT_TORQUE; break;
        case 7: t.pos = (j288_real_t)NAN; want = J288_ERR_NOT_FINITE; break;
        case 8: t.speed = (j288_real_t)NAN; want = J288_ERR_NOT_FINITE; break;
        case 9: t.torque = (j288_real_t)NAN; want = J288_ERR_NOT_FINITE; break;
        case 10: t.kp = (j288_real_t)NAN; want = J288_ERR_NOT_FINITE; break;
        case 11: t.kd = (j288_real_t)NAN; want = J288_ERR_NOT_FINITE; break;
        case 12: t.kp = (j288_real_t)-1.0; want = J288_ERR_NEG_GAIN; break;
        default: t.kp = (j288_real_t)3000.0; want = J288_ERR_RANGE_KP; break; /* > wire */
        }
        cmd = before;
        clamped = 55u;
        TEST_ASSERT_EQUAL_INT_MESSAGE(want, j288_joint_command(&joint, &t, &cmd, &clamped), "case");
        TEST_ASSERT_EQUAL_MEMORY(&before, &cmd, sizeof cmd);
        TEST_ASSERT_EQUAL_UINT(55u, clamped);
    }
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_command(NULL, &good, &cmd, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_command(&joint, NULL, &cmd, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_command(&joint, &good, NULL, NULL));
    /* No speed or torque limit configured: only the wire's range. */
    c.max_speed = 0;
    c.max_torque = 0;
    known_joint(&c, &m);
    t = good;
    t.speed = (j288_real_t)250.0;
    t.torque = (j288_real_t)36.0;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_command(&joint, &t, &cmd, NULL));
    t.torque = (j288_real_t)40.0; /* 0.1387 N*m of rotor > 0.128 on the wire */
    TEST_ASSERT_EQUAL_INT(J288_ERR_RANGE_TAU, j288_joint_command(&joint, &t, &cmd, NULL));
}

static void test_limits_clamped(void)
{
    j288_joint_config_t c = limited_cfg(true);
    j288_joint_target_t t, want;
    j288_cmd_raw_t cmd, ref;
    model_t m;
    unsigned clamped = 0u;

    known_joint(&c, &m);
    j288_joint_target_init(&joint, &t);
    t.pos = (j288_real_t)2.0;
    t.speed = (j288_real_t)-7.0;
    t.torque = (j288_real_t)11.0;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_command(&joint, &t, &cmd, &clamped));
    TEST_ASSERT_EQUAL_UINT(J288_FIELD_POS | J288_FIELD_SPEED | J288_FIELD_TAU, clamped);
    want = t;
    want.pos = (j288_real_t)1.25;
    want.speed = (j288_real_t)-3.0;
    want.torque = (j288_real_t)10.0;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_command(&joint, &want, &ref, &clamped));
    TEST_ASSERT_EQUAL_UINT(0u, clamped);
    TEST_ASSERT_EQUAL_MEMORY(&ref, &cmd, sizeof cmd);
    t = want;
    t.pos = (j288_real_t)-INFINITY;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_command(&joint, &t, &cmd, &clamped));
    TEST_ASSERT_EQUAL_UINT(J288_FIELD_POS, clamped);
    want.pos = (j288_real_t)-0.5;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_command(&joint, &want, &ref, NULL));
    TEST_ASSERT_EQUAL_INT32(ref.pos, cmd.pos);
    /* Gains beyond the wire saturate as j288_cmd_from_si_clamped() does; NaN is refused. */
    t = want;
    t.kp = (j288_real_t)3000.0;
    t.kd = (j288_real_t)-1.0;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_command(&joint, &t, &cmd, &clamped));
    TEST_ASSERT_EQUAL_UINT(J288_FIELD_KP | J288_FIELD_KD, clamped);
    TEST_ASSERT_EQUAL_INT16(INT16_MAX, cmd.kp);
    TEST_ASSERT_EQUAL_INT16(0, cmd.kd);
    t.pos = (j288_real_t)NAN;
    TEST_ASSERT_EQUAL_INT(J288_ERR_NOT_FINITE, j288_joint_command(&joint, &t, &cmd, &clamped));
}

static void test_limit_events(void)
{
    j288_joint_config_t c = cfg_for(6u);
    model_t m;

    c.pos_min = (j288_real_t)-0.5;
    c.pos_max = (j288_real_t)1.0;
    known_joint(&c, &m);
    TEST_ASSERT_FALSE(j288_joint_state(&joint)->beyond_limit);
    move_to(&m, 0.999);
    TEST_ASSERT_EQUAL_HEX(0u, feed(&joint, &m));
    move_to(&m, 1.0004);
    TEST_ASSERT_EQUAL_HEX(EVB(LIMIT_REACHED), feed(&joint, &m));
    TEST_ASSERT_TRUE(j288_joint_state(&joint)->beyond_limit);
    move_to(&m, 1.2);
    TEST_ASSERT_EQUAL_HEX(0u, feed(&joint, &m));
    move_to(&m, 0.9995); /* inside, but within the hysteresis */
    TEST_ASSERT_EQUAL_HEX(0u, feed(&joint, &m));
    move_to(&m, 0.998);
    TEST_ASSERT_EQUAL_HEX(EVB(LIMIT_LEFT), feed(&joint, &m));
    TEST_ASSERT_FALSE(j288_joint_state(&joint)->beyond_limit);
    move_to(&m, -0.6);
    TEST_ASSERT_EQUAL_HEX(EVB(LIMIT_REACHED), feed(&joint, &m));
    move_to(&m, -0.4995);
    TEST_ASSERT_EQUAL_HEX(0u, feed(&joint, &m));
    move_to(&m, -0.49);
    TEST_ASSERT_EQUAL_HEX(EVB(LIMIT_LEFT), feed(&joint, &m));
    /* Beyond the limit, then lost: the next start reports the limit again. */
    move_to(&m, 1.1);
    TEST_ASSERT_EQUAL_HEX(EVB(LIMIT_REACHED), feed(&joint, &m));
    m.c += 2.0 * TAU;
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_LOST), feed(&joint, &m));
    TEST_ASSERT_FALSE(j288_joint_state(&joint)->beyond_limit);
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_KNOWN) | EVB(LIMIT_REACHED), start_joint(&joint, &m));
}

static void test_zero_here(void)
{
    j288_joint_config_t c = cfg_for(2u);
    j288_real_t zero = 0;
    model_t m;
    int d;

    for (d = -1; d <= 1; d += 2) {
        c.direction = (int8_t)d;
        c.zero = (j288_real_t)1.0;
        c.has_phase = true;
        c.phase = (j288_real_t)-0.9; /* known_joint()'s servo */
        known_joint(&c, &m);
        move_to(&m, 0.45);
        (void)feed(&joint, &m);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_zero_here(&joint, &zero));
        TEST_ASSERT_DOUBLE_WITHIN(CAL_TOL, 0.45, zero);
        c.zero = zero;
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
        (void)start_joint(&joint, &m);
        TEST_ASSERT_DOUBLE_WITHIN(CAL_TOL, 0.0, j288_joint_state(&joint)->pos);
    }
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_zero_here(NULL, &zero));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_zero_here(&joint, NULL));
    j288_joint_target_init(NULL, NULL); /* ignored */
    j288_joint_target_init(&joint, NULL);
}

/* ---- calibration fit */

/* A slow back-and-forth motion of `span` rad around the labelled pose theta_mid, n replies,
 * into the fit. */
static void sweep_fit(j288_cal_t *cal, model_t *m, double theta_mid, double span, int n)
{
    int i;
    for (i = 0; i < n; i++) {
        double phase = fmod(4.0 * (double)i / (double)n, 2.0); /* two triangles */
        double tri = (phase < 1.0) ? phase : 2.0 - phase;     /* 0 -> 1 -> 0 */
        j288_reply_raw_t r;
        move_to(m, theta_mid + span * (tri - 0.5));
        r = reply_of(m, 1u);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_cal_add_reply(cal, &r));
    }
}

static void fit_random(double backlash, double c_tol, const char *label)
{
    j288_joint_config_t c;
    j288_cal_t cal;
    j288_cal_report_t rep;
    model_t m;
    int trial;
    double worst = 0.0, worst_rms = 0.0;

    for (trial = 0; trial < 100; trial++) {
        double mid, err;
        random_setup(&c, &m, false);
        c.has_phase = false;
        m.backlash = backlash;
        mid = (double)c.zero + (double)c.direction * 0.5 * (double)(c.pos_min + c.pos_max);
        move_to(&m, mid);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_cal_init(&cal, &c));
        sweep_fit(&cal, &m, mid, 0.05, 2000); /* 65 counts, 2.9 deg */
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_cal_result(&cal, &rep));
        TEST_ASSERT_EQUAL_UINT(0u, rep.problems);
        TEST_ASSERT_EQUAL_UINT32(2000u, rep.samples);
        /* 65 counts, and the backlash's shift at both ends */
        TEST_ASSERT_UINT32_WITHIN(1u, 65u + (uint32_t)lround(backlash / COUNT), rep.span_counts);
        TEST_ASSERT_DOUBLE_WITHIN(NR * 1e-3, NR, rep.ratio);
        err = fabs(wrap((double)rep.phase - m.c));
        TEST_ASSERT_TRUE(err < c_tol);
        worst = (err > worst) ? err : worst;
        worst_rms = ((double)rep.rms > worst_rms) ? (double)rep.rms : worst_rms;
        /* The fitted phase starts the joint, calibrated, on the truth. */
        c.has_phase = true;
        c.phase = rep.phase;
        m.backlash = 0.0;
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
        TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_UNKNOWN) | EVB(ANGLE_KNOWN), start_joint(&joint, &m));
        TEST_ASSERT_DOUBLE_WITHIN(c_tol / NR + CAL_TOL, q_of(&c, &m), j288_joint_state(&joint)->pos);
    }
    UnityPrint("  ");
    UnityPrint(label);
    UNITY_PRINT_EOL();
    print_urad("    worst phase error, rotor", worst);
    print_urad("    as output angle", worst / NR);
    print_urad("    worst residual rms, rotor", worst_rms);
}

static void test_fit_random(void)
{
    fit_random(0.0, 0.01, "phase fit, 100 random joints, 2000 pairs over 65 counts:");
}

static void test_fit_with_backlash(void)
{
    /* 2 mrad of backlash: each pair is off by N * 1 mrad = 0.29 rotor rad, one way or the
     * other; the motion loads both sides evenly, so the mean stays close. */
    fit_random(0.002, 0.02, "the same with 2 mrad of backlash:");
}

static void test_fit_quality_checks(void)
{
    j288_cal_t cal;
    j288_cal_report_t rep;
    j288_joint_config_t c = cfg_for(1u);
    j288_reply_raw_t r;
    model_t m;
    int i;

    m = servo_at(0.3, 1.0);
    r = reply_of(&m, 1u);
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_cal_init(NULL, &c));
    c.direction = 3;
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, j288_cal_init(&cal, &c));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_cal_init(&cal, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_cal_add(NULL, 0u, 0));
    TEST_ASSERT_EQUAL_INT(J288_ERR_RANGE, j288_cal_add(&cal, 8192u, 0));
    /* The bounds that keep hostile input from overflowing: refused, nothing taken. */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_cal_add(&cal, 0u, 0));
    cal.cont = 0x20000001;
    TEST_ASSERT_EQUAL_INT(J288_ERR_RANGE, j288_cal_add(&cal, 4095u, 0));
    cal.cont = -0x20000001;
    TEST_ASSERT_EQUAL_INT(J288_ERR_RANGE, j288_cal_add(&cal, 4097u, 0));
    cal.cont = 0x20000000; /* the limit itself is fine */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_cal_add(&cal, 4095u, 0));
    cal.cont = 0;
    cal.n = UINT32_MAX;
    TEST_ASSERT_EQUAL_INT(J288_ERR_RANGE, j288_cal_add(&cal, 1u, 0));
    TEST_ASSERT_EQUAL_UINT32(UINT32_MAX, cal.n);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_cal_init(&cal, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_cal_add_reply(&cal, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_cal_add_reply(NULL, &r));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_cal_result(NULL, &rep));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_cal_result(&cal, NULL));
    /* Nothing yet. */
    TEST_ASSERT_EQUAL_INT(J288_ERR_CAL_DATA, j288_cal_result(&cal, &rep));
    TEST_ASSERT_EQUAL_UINT(J288_CAL_FEW_SAMPLES | J288_CAL_SMALL_SPAN | J288_CAL_RATIO,
                           rep.problems);
    TEST_ASSERT_EQUAL_UINT32(0u, rep.samples);
    TEST_ASSERT_EQUAL_DOUBLE(0.0, rep.rms);
    /* At rest: enough pairs, no span, no ratio; the phase is still near. */
    for (i = 0; i < 150; i++) {
        r = reply_of(&m, 1u);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_cal_add_reply(&cal, &r));
    }
    r.faults = FAULT12;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_cal_add_reply(&cal, &r));
    TEST_ASSERT_EQUAL_INT(J288_ERR_CAL_DATA, j288_cal_result(&cal, &rep));
    TEST_ASSERT_EQUAL_UINT(J288_CAL_SMALL_SPAN | J288_CAL_RATIO, rep.problems);
    TEST_ASSERT_EQUAL_UINT32(150u, rep.samples);
    TEST_ASSERT_EQUAL_UINT32(1u, rep.rejected);
    TEST_ASSERT_EQUAL_DOUBLE(0.0, rep.ratio);
    TEST_ASSERT_DOUBLE_WITHIN(0.12, m.c, rep.phase);
    /* A short good motion: enough span, too few pairs. */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_cal_init(&cal, NULL));
    sweep_fit(&cal, &m, 0.3, 0.05, 60);
    TEST_ASSERT_EQUAL_INT(J288_ERR_CAL_DATA, j288_cal_result(&cal, &rep));
    TEST_ASSERT_EQUAL_UINT(J288_CAL_FEW_SAMPLES, rep.problems);
    /* A noisy encoder: pairs 40 counts off now and then. */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_cal_init(&cal, NULL));
    for (i = 0; i < 400; i++) {
        move_to(&m, 0.3 + 0.0002 * i);
        r = reply_of(&m, 1u);
        if (i % 50 == 7) {
            r.out_pos = (uint16_t)((r.out_pos + 40u) & 8191u);
        }
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_cal_add_reply(&cal, &r));
    }
    TEST_ASSERT_EQUAL_INT(J288_ERR_CAL_DATA, j288_cal_result(&cal, &rep));
    TEST_ASSERT_TRUE((rep.problems & J288_CAL_NOISY) != 0u);
    TEST_ASSERT_TRUE((double)rep.max_abs > 2.0); /* 40 counts: 8.8 rotor rad, wrapped */
    TEST_ASSERT_TRUE((double)rep.max_abs <= J288_PI + 1e-6); /* residuals are phases */
    /* Another gear ratio (a model with N = 6.33): the ratio check. */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_cal_init(&cal, NULL));
    for (i = 0; i < 400; i++) {
        double theta = 0.3 + 0.0005 * i;
        m.theta = theta;
        r = reply_of(&m, 1u);
        r.pos = (int32_t)llround(6.33 * theta / ROTOR_LSB);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_cal_add_reply(&cal, &r));
    }
    TEST_ASSERT_EQUAL_INT(J288_ERR_CAL_DATA, j288_cal_result(&cal, &rep));
    TEST_ASSERT_TRUE((rep.problems & J288_CAL_RATIO) != 0u);
    TEST_ASSERT_DOUBLE_WITHIN(0.1, 6.33, rep.ratio);
}

/* A fit whose motion crosses the encoder's wrap, both ways, with direction -1. */
static void test_fit_across_the_wrap(void)
{
    j288_joint_config_t c = cfg_for(1u);
    j288_cal_t cal;
    j288_cal_report_t rep;
    model_t m;
    int d;

    for (d = -1; d <= 1; d += 2) {
        c.direction = (int8_t)d;
        c.zero = (j288_real_t)(-TAU); /* theta = -2 pi (OutPos 0) is joint 0 */
        m = servo_at(-TAU + 0.1, -2.9);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_cal_init(&cal, &c));
        sweep_fit(&cal, &m, -TAU, 0.04, 1000);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_cal_result(&cal, &rep));
        TEST_ASSERT_DOUBLE_WITHIN(0.01, 0.0, wrap((double)rep.phase - m.c));
        c.has_phase = true;
        c.phase = rep.phase;
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
        move_to(&m, -TAU - 0.01);
        (void)start_joint(&joint, &m);
        TEST_ASSERT_TRUE(j288_joint_state(&joint)->calibrated);
        TEST_ASSERT_DOUBLE_WITHIN(0.01 / NR + CAL_TOL, -0.01 * d, j288_joint_state(&joint)->pos);
        c.has_phase = false;
        c.phase = 0;
    }
}

/* ---- the binding, through a real scheduler on the fake port */

#define US 1000u
#define JID 4u

static fake_port_t fp;
static j288_bus_t bus;
static j288_sched_t sch;
static j288_joint_bus_t jb;
static j288_joint_event_t jev[32];
static int njev;

static void on_joint_event(void *user, const j288_joint_event_t *ev)
{
    TEST_ASSERT_EQUAL_PTR(&fp, user);
    if (njev < 32) {
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

static void bound_setup(j288_joint_config_t *c, model_t *m)
{
    j288_sched_config_t sc;
    j288_reply_raw_t r;

    *m = servo_at(-0.8, 0.6);
    *c = cfg_for(JID);
    c->init_samples = 3u;
    c->kp = (j288_real_t)10.0;
    memset(&sc, 0, sizeof sc);
    sc.on_reply = j288_joint_bus_on_reply;
    sc.user = &jb;
    njev = 0;
    fake_port_init(&fp);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_init(&bus, &fp.ops, &fp, NULL));
    fake_port_attach(&fp, &bus);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_init(&sch, &bus, &sc));
    fp.poll_fn = fake_port_poll_sched;
    fp.poll_user = &sch;
    r = reply_of(m, JID);
    fake_port_add_servo(&fp, JID, &r);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, c));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_bus_init(&jb, &sch, on_joint_event, &fp));
}

static void test_binding_locks_until_known_and_after_a_loss(void)
{
    j288_joint_config_t c;
    j288_joint_target_t t;
    j288_cmd_raw_t foc, want;
    model_t m;
    int i;

    bound_setup(&c, &m);
    memset(&t, 0, sizeof t);
    /* The app had put a FOC command in the slot: adding the joint makes it lock. */
    memset(&foc, 0, sizeof foc);
    foc.id = JID;
    foc.status = J288_MODE_FOC;
    foc.pos = 12345;
    foc.kp = 100;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_set_cmd(&sch, &foc));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_bus_add(&jb, &joint));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_enable(&sch, JID, true));
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_LOCK, j288_sched_slot(&sch, JID)->cmd.status);
    sweep(&m);
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_LOCK, last_frame().status);
    TEST_ASSERT_EQUAL_INT(1, njev);
    TEST_ASSERT_EQUAL_INT(J288_JOINT_EV_ANGLE_UNKNOWN, jev[0].kind);
    TEST_ASSERT_EQUAL_UINT8(JID, jev[0].id);
    TEST_ASSERT_EQUAL_PTR(&joint, jev[0].joint);
    TEST_ASSERT_EQUAL_INT(J288_ERR_ANGLE_UNKNOWN, j288_joint_bus_set_target(&jb, &joint, &t, NULL));
    /* A FOC command slipped in directly while unknown goes out once, then lock again. */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_set_cmd(&sch, &foc));
    sweep(&m);
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_FOC, last_frame().status);
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_LOCK, j288_sched_slot(&sch, JID)->cmd.status);
    sweep(&m);
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_LOCK, last_frame().status);
    TEST_ASSERT_EQUAL_INT(2, njev);
    TEST_ASSERT_EQUAL_INT(J288_JOINT_EV_ANGLE_KNOWN, jev[1].kind);
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, -0.8, jev[1].value);
    /* Known: targets go out in the rotor frame. */
    j288_joint_target_init(&joint, &t);
    t.pos = (j288_real_t)-0.7;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_bus_set_target(&jb, &joint, &t, NULL));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_command(&joint, &t, &want, NULL));
    sweep(&m);
    TEST_ASSERT_EQUAL_MEMORY(&want, &j288_sched_slot(&sch, JID)->cmd, sizeof want);
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_FOC, last_frame().status);
    TEST_ASSERT_EQUAL_INT32(want.pos, last_frame().pos);
    TEST_ASSERT_EQUAL_INT16(want.kp, last_frame().kp);
    move_to(&m, -0.7);
    sweep(&m);
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_FOC, last_frame().status);
    TEST_ASSERT_EQUAL_INT(2, njev);
    /* The servo is power-cycled: the reply to the stale FOC command shows it, and the
     * slot's next command is lock, set inside the scheduler before anything else is sent. */
    m.k += 40.0; /* as if powered up 40 rotor turns higher: 0.87 rad of output */
    sweep(&m);
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_FOC, last_frame().status);
    TEST_ASSERT_EQUAL_INT(3, njev);
    TEST_ASSERT_EQUAL_INT(J288_JOINT_EV_ANGLE_LOST, jev[2].kind);
    TEST_ASSERT_DOUBLE_WITHIN(0.01, wrap(-TAU * 40.0 / NR), jev[2].value);
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_LOCK, j288_sched_slot(&sch, JID)->cmd.status);
    TEST_ASSERT_TRUE(j288_sched_slot(&sch, JID)->cmd.watchdog);
    TEST_ASSERT_EQUAL_INT(J288_ERR_ANGLE_UNKNOWN, j288_joint_bus_set_target(&jb, &joint, &t, NULL));
    for (i = 0; i < 3; i++) {
        sweep(&m);
        TEST_ASSERT_EQUAL_UINT8(J288_MODE_LOCK, last_frame().status);
    }
    TEST_ASSERT_EQUAL_INT(4, njev);
    TEST_ASSERT_EQUAL_INT(J288_JOINT_EV_ANGLE_KNOWN, jev[3].kind);
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, -0.7, j288_joint_state(&joint)->pos);
    /* In the new frame the same target is another rotor position. */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_bus_set_target(&jb, &joint, &t, NULL));
    sweep(&m);
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_FOC, last_frame().status);
    TEST_ASSERT_INT_WITHIN(2000, want.pos - 40 * 32768, last_frame().pos);
    /* Lock on request. */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_bus_lock(&jb, &joint));
    sweep(&m);
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_LOCK, last_frame().status);
    TEST_ASSERT_EQUAL_INT(4, njev);
}

static void test_binding_events_order_and_values(void)
{
    j288_joint_config_t c;
    model_t m;

    bound_setup(&c, &m);
    c.pos_min = (j288_real_t)0.0;
    c.pos_max = (j288_real_t)1.0;
    c.init_samples = 1u;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_bus_add(&jb, &joint));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_bus_add(&jb, &joint)); /* again: fine */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_enable(&sch, JID, true));
    fp.servo[JID].reply.faults = FAULT12;
    sweep(&m);
    TEST_ASSERT_EQUAL_INT(2, njev);
    TEST_ASSERT_EQUAL_INT(J288_JOINT_EV_ENCODER_FAULT, jev[0].kind);
    TEST_ASSERT_EQUAL_INT(J288_JOINT_EV_ANGLE_UNKNOWN, jev[1].kind);
    TEST_ASSERT_EQUAL_DOUBLE(0.0, jev[1].value);
    fp.servo[JID].reply.faults = 0u;
    sweep(&m); /* -0.8: outside [0, 1], nearest the bottom */
    TEST_ASSERT_EQUAL_INT(5, njev);
    TEST_ASSERT_EQUAL_INT(J288_JOINT_EV_ENCODER_OK, jev[2].kind);
    TEST_ASSERT_EQUAL_INT(J288_JOINT_EV_ANGLE_KNOWN, jev[3].kind);
    TEST_ASSERT_EQUAL_INT(J288_JOINT_EV_LIMIT_REACHED, jev[4].kind);
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, -0.8, jev[4].value);
    move_to(&m, 0.5);
    sweep(&m);
    TEST_ASSERT_EQUAL_INT(6, njev);
    TEST_ASSERT_EQUAL_INT(J288_JOINT_EV_LIMIT_LEFT, jev[5].kind);
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, 0.5, jev[5].value);
    /* A calibration mismatch, with its residual. */
    c.has_phase = true;
    c.phase = (j288_real_t)wrap(m.c + 2.0);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &c));
    sweep(&m);
    TEST_ASSERT_EQUAL_INT(8, njev);
    TEST_ASSERT_EQUAL_INT(J288_JOINT_EV_ANGLE_UNKNOWN, jev[6].kind);
    TEST_ASSERT_EQUAL_INT(J288_JOINT_EV_CAL_MISMATCH, jev[7].kind);
    TEST_ASSERT_DOUBLE_WITHIN(0.12, 2.0, jev[7].value);
    TEST_ASSERT_EQUAL_INT(J288_ERR_CAL_MISMATCH, j288_joint_bus_set_target(&jb, &joint,
                          &(j288_joint_target_t){0, 0, 0, 0, 0}, NULL));
    /* No event callback: nothing is reported, the lock is still kept. */
    jb.on_event = NULL;
    sweep(&m);
    TEST_ASSERT_EQUAL_INT(8, njev);
}

static void test_binding_argument_checks(void)
{
    j288_joint_config_t c;
    j288_joint_t other;
    j288_joint_target_t t;
    j288_slot_t slot;
    model_t m;
    j288_joint_t before;

    bound_setup(&c, &m);
    memset(&t, 0, sizeof t);
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_bus_init(NULL, &sch, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_bus_init(&jb, NULL, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_bus_add(NULL, &joint));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_bus_add(&jb, NULL));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_bus_add(&jb, &joint));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&other, &c));
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, j288_joint_bus_add(&jb, &other)); /* same id */
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_bus_set_target(NULL, &joint, &t, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_bus_set_target(&jb, NULL, &t, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_ARG, j288_joint_bus_set_target(&jb, &other, &t, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_bus_lock(NULL, &joint));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_bus_lock(&jb, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_ARG, j288_joint_bus_lock(&jb, &other));
    other.cfg.id = 15u; /* a joint that was never initialised properly */
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_ARG, j288_joint_bus_lock(&jb, &other));
    /* The hook ignores what is not for a bound joint, and replies from another id. */
    memset(&slot, 0, sizeof slot);
    slot.reply = reply_of(&m, JID);
    slot.cmd.status = J288_MODE_FOC;
    before = joint;
    j288_joint_bus_on_reply(NULL, JID, &slot);
    j288_joint_bus_on_reply(&jb, JID, NULL);
    j288_joint_bus_on_reply(&jb, 15u, &slot);
    j288_joint_bus_on_reply(&jb, 3u, &slot);
    slot.reply.id = 5u;
    j288_joint_bus_on_reply(&jb, JID, &slot);
    assert_same_joint(&before, &joint);
    TEST_ASSERT_EQUAL_INT(0, njev);
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_LOCK, j288_sched_slot(&sch, JID)->cmd.status);
}

static void test_error_strings(void)
{
    static const int codes[] = {J288_ERR_ANGLE_UNKNOWN, J288_ERR_CAL_MISMATCH,
                                J288_ERR_LIMIT_POS,     J288_ERR_LIMIT_SPEED,
                                J288_ERR_LIMIT_TORQUE,  J288_ERR_CAL_DATA};
    size_t i;
    int other;
    for (i = 0; i < sizeof codes / sizeof codes[0]; i++) {
        const char *s = j288_strerror(codes[i]);
        TEST_ASSERT_TRUE(strcmp(s, "unknown error") != 0);
        for (other = -1; other >= -60; other--) {
            if (other != codes[i]) {
                TEST_ASSERT_TRUE_MESSAGE(strcmp(s, j288_strerror(other)) != 0, s);
            }
        }
    }
    TEST_ASSERT_EQUAL_INT(-39, J288_ERR_OFFLINE); /* earlier codes keep their values */
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_config_checks);
    RUN_TEST(test_default_is_the_encoder_angle_wrapped);
    RUN_TEST(test_start_events_and_refusals);
    RUN_TEST(test_take_reply_errors);
    RUN_TEST(test_uncalibrated_random);
    RUN_TEST(test_calibrated_random);
    RUN_TEST(test_state_speed_torque_and_direction);
    RUN_TEST(test_reversed_joint_at_rest_is_plus_zero);
    RUN_TEST(test_start_while_moving_and_outlier);
    RUN_TEST(test_start_average_while_moving);
    RUN_TEST(test_turn_choice);
    RUN_TEST(test_range_across_the_wrap);
    RUN_TEST(test_wrong_calibration);
    RUN_TEST(test_power_cycle);
    RUN_TEST(test_slipped_gear);
    RUN_TEST(test_encoder_fault);
    RUN_TEST(test_large_rotor_positions);
    RUN_TEST(test_command_frames);
    RUN_TEST(test_command_round_trip);
    RUN_TEST(test_limits_refused);
    RUN_TEST(test_limits_clamped);
    RUN_TEST(test_limit_events);
    RUN_TEST(test_zero_here);
    RUN_TEST(test_fit_random);
    RUN_TEST(test_fit_with_backlash);
    RUN_TEST(test_fit_quality_checks);
    RUN_TEST(test_fit_across_the_wrap);
    RUN_TEST(test_binding_locks_until_known_and_after_a_loss);
    RUN_TEST(test_binding_events_order_and_values);
    RUN_TEST(test_binding_argument_checks);
    RUN_TEST(test_error_strings);
    return UNITY_END();
}
