/*
 * The joint: one suite, run twice (parameterised, as littlefs runs its suites across
 * geometries): against the joint core (j288/jointq.h, Q24/Q16 integers) and through the float
 * facade (j288/joint.h: j288_real_t is double, or float in the Cortex-M4F build). The suite
 * speaks SI in double; the adapter below hands each API the same quantities (the core gets
 * the integers of the values the facade's real type holds). The servo is a physical model
 * written here, independently of the library: r = N theta + c, the rotor position
 * p = r - 2 pi k with k fixed at power-up so that p starts in [0, 2 pi), reported in 32768
 * LSB per turn (rounded), OutPos = floor((theta mod 2 pi) * 8192 / 2 pi). Many random phases,
 * start poses, power-up poses, zeros, directions and ranges.
 * Then the tests of one side: the core's conversions against the golden vectors of the
 * independent generator (tools/vectors), its integer edges; the facade's edge (NaN,
 * infinities, rounding), its results against the core's bit for bit, and the phase fit.
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

#define PI 3.14159265358979323846
#define NR (5767.0 / 20.0)
#define TAU (2.0 * PI)
#define ROTOR_LSB (TAU / 32768.0)       /* rotor rad per position LSB */
#define COUNT (TAU / 8192.0)            /* output rad per OutPos count */
#define ROTOR_RES (0.5 * ROTOR_LSB / NR) /* output rad: half a rotor LSB */
#define Q24 16777216.0
#define Q16 65536.0
#define FAULT12 J288_FAULT_OUTPUT_ENCODER
#define EVB(k) J288_JOINT_EV_BIT(J288_JOINT_EV_##k)

/* The core's own rounding (a few Q24 steps) and, through a float facade, float's: EPS on
 * angles of a few rad, REL relative to larger ones. */
#if J288_CONFIG_SI && J288_CONFIG_SI_FLOAT
#define EPS 6e-6
#define REL 1.2e-7
#else
#define EPS (4.0 / Q24)
#define REL 0.0
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

/* The reply's rotor position: the servo's int32 counter, modulo 2^32. */
static int32_t model_pos(const model_t *m)
{
    double p = (NR * m->theta + m->c - TAU * m->k) / ROTOR_LSB;
    double w = fmod(nearbyint(p), 4294967296.0);
    w += (w < -2147483648.0) ? 4294967296.0 : ((w >= 2147483648.0) ? -4294967296.0 : 0.0);
    return (int32_t)w;
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

static void print_value(const char *what, double x, const char *unit)
{
    long long n = llround(fabs(x) * 1000.0);
    UnityPrint("  ");
    UnityPrint(what);
    UnityPrint(x < 0.0 ? ": -" : ": ");
    UnityPrintNumber((UNITY_INT)(n / 1000));
    UnityPrint(".");
    UnityPrintNumber((UNITY_INT)(n % 1000 / 100));
    UnityPrintNumber((UNITY_INT)(n % 100 / 10));
    UnityPrintNumber((UNITY_INT)(n % 10));
    UnityPrint(unit);
    UNITY_PRINT_EOL();
}

/* ---- the adapter: one joint (and one binding) through the API under test */

typedef enum { API_CORE, API_FACADE } api_t;
static api_t api = API_CORE;

typedef struct {
    uint8_t id;
    int8_t direction;
    bool clamp, has_phase, continuous;
    uint8_t init_samples;
    double zero, pos_min, pos_max, max_speed, max_torque, kp, kd, phase, track_tol, cal_tol;
} jcfg_t;

typedef struct {
    bool known, calibrated, cal_mismatch, encoder_fault, beyond_limit;
    double pos, speed, torque, encoder, residual, cal_residual;
} jstate_t;

typedef struct {
    double pos, speed, torque, kp, kd;
} jtarget_t;

static j288_jointq_t qj, qother;
#if J288_CONFIG_SI
static j288_joint_t fj, fother;
#endif

/* x as the facade's real type holds it. */
static double as_real(double x)
{
#if J288_CONFIG_SI
    return (double)(j288_real_t)x;
#else
    return x;
#endif
}

static j288_q24_t q24(double x)
{
    return (j288_q24_t)llround(as_real(x) * Q24);
}

static j288_q16_t q16(double x)
{
    return (j288_q16_t)llround(as_real(x) * Q16);
}

static double rad(j288_q24_t q)
{
    return (double)q / Q24;
}

static double si16(j288_q16_t q)
{
    return (double)q / Q16;
}

static jcfg_t cfg_for(uint8_t id)
{
    jcfg_t c;
    memset(&c, 0, sizeof c);
    c.id = id;
    return c;
}

static j288_jointq_config_t qcfg_of(const jcfg_t *c)
{
    j288_jointq_config_t q;
    memset(&q, 0, sizeof q);
    q.id = c->id;
    q.direction = c->direction;
    q.clamp = c->clamp;
    q.has_phase = c->has_phase;
    q.continuous = c->continuous;
    q.init_samples = c->init_samples;
    q.zero = q24(c->zero);
    q.pos_min = q24(c->pos_min);
    q.pos_max = q24(c->pos_max);
    q.max_speed = q16(c->max_speed);
    q.max_torque = q16(c->max_torque);
    q.kp = q16(c->kp);
    q.kd = q16(c->kd);
    q.phase = q24(c->phase);
    q.track_tol = q24(c->track_tol);
    q.cal_tol = q24(c->cal_tol);
    return q;
}

#if J288_CONFIG_SI
static j288_joint_config_t fcfg_of(const jcfg_t *c)
{
    j288_joint_config_t f;
    memset(&f, 0, sizeof f);
    f.id = c->id;
    f.direction = c->direction;
    f.clamp = c->clamp;
    f.has_phase = c->has_phase;
    f.continuous = c->continuous;
    f.init_samples = c->init_samples;
    f.zero = (j288_real_t)c->zero;
    f.pos_min = (j288_real_t)c->pos_min;
    f.pos_max = (j288_real_t)c->pos_max;
    f.max_speed = (j288_real_t)c->max_speed;
    f.max_torque = (j288_real_t)c->max_torque;
    f.kp = (j288_real_t)c->kp;
    f.kd = (j288_real_t)c->kd;
    f.phase = (j288_real_t)c->phase;
    f.track_tol = (j288_real_t)c->track_tol;
    f.cal_tol = (j288_real_t)c->cal_tol;
    return f;
}

static j288_joint_target_t ftarget_of(const jtarget_t *t)
{
    j288_joint_target_t f;
    f.pos = (j288_real_t)t->pos;
    f.speed = (j288_real_t)t->speed;
    f.torque = (j288_real_t)t->torque;
    f.kp = (j288_real_t)t->kp;
    f.kd = (j288_real_t)t->kd;
    return f;
}
#endif

static j288_jointq_target_t qtarget_of(const jtarget_t *t)
{
    j288_jointq_target_t q;
    q.pos = q24(t->pos);
    q.speed = q16(t->speed);
    q.torque = q16(t->torque);
    q.kp = q16(t->kp);
    q.kd = q16(t->kd);
    return q;
}

static int j_init_one(const jcfg_t *c, bool other)
{
#if J288_CONFIG_SI
    if (api == API_FACADE) {
        j288_joint_config_t f = fcfg_of(c);
        return j288_joint_init(other ? &fother : &fj, &f);
    }
#endif
    {
        j288_jointq_config_t q = qcfg_of(c);
        return j288_jointq_init(other ? &qother : &qj, &q);
    }
}

static int j_init(const jcfg_t *c)
{
    return j_init_one(c, false);
}

/* The joint core under test (the facade's own, through its accessor). */
static j288_jointq_t *j_core(void)
{
#if J288_CONFIG_SI
    if (api == API_FACADE) {
        TEST_ASSERT_EQUAL_PTR(&fj.core, j288_joint_core(&fj));
        return &fj.core;
    }
#endif
    return &qj;
}

static void j_reset(void)
{
#if J288_CONFIG_SI
    if (api == API_FACADE) {
        j288_joint_reset(&fj);
        return;
    }
#endif
    j288_jointq_reset(&qj);
}

static int j_take(const j288_reply_raw_t *r, unsigned *ev)
{
#if J288_CONFIG_SI
    if (api == API_FACADE) {
        return j288_joint_take_reply(&fj, r, ev);
    }
#endif
    return j288_jointq_take_reply(&qj, r, ev);
}

static jstate_t j_state(void)
{
    jstate_t s;
#if J288_CONFIG_SI
    if (api == API_FACADE) {
        const j288_joint_state_t *f = j288_joint_state(&fj);
        s.known = f->known;
        s.calibrated = f->calibrated;
        s.cal_mismatch = f->cal_mismatch;
        s.encoder_fault = f->encoder_fault;
        s.beyond_limit = f->beyond_limit;
        s.pos = (double)f->pos;
        s.speed = (double)f->speed;
        s.torque = (double)f->torque;
        s.encoder = (double)f->encoder;
        s.residual = (double)f->residual;
        s.cal_residual = (double)f->cal_residual;
        return s;
    }
#endif
    {
        const j288_jointq_state_t *q = j288_jointq_state(&qj);
        s.known = q->known;
        s.calibrated = q->calibrated;
        s.cal_mismatch = q->cal_mismatch;
        s.encoder_fault = q->encoder_fault;
        s.beyond_limit = q->beyond_limit;
        s.pos = rad(q->pos);
        s.speed = si16(q->speed);
        s.torque = si16(q->torque);
        s.encoder = rad(q->encoder);
        s.residual = rad(q->residual);
        s.cal_residual = rad(q->cal_residual);
    }
    return s;
}

/* The configuration in use (the accessor), in SI. */
static jcfg_t j_config(void)
{
    jcfg_t c;
    memset(&c, 0, sizeof c);
#if J288_CONFIG_SI
    if (api == API_FACADE) {
        const j288_joint_config_t *f = j288_joint_config(&fj);
        c.id = f->id;
        c.direction = f->direction;
        c.clamp = f->clamp;
        c.continuous = f->continuous;
        c.init_samples = f->init_samples;
        c.pos_min = (double)f->pos_min;
        c.pos_max = (double)f->pos_max;
        c.track_tol = (double)f->track_tol;
        c.cal_tol = (double)f->cal_tol;
        c.kp = (double)f->kp;
        return c;
    }
#endif
    {
        const j288_jointq_config_t *q = j288_jointq_config(&qj);
        c.id = q->id;
        c.direction = q->direction;
        c.clamp = q->clamp;
        c.continuous = q->continuous;
        c.init_samples = q->init_samples;
        c.pos_min = rad(q->pos_min);
        c.pos_max = rad(q->pos_max);
        c.track_tol = rad(q->track_tol);
        c.cal_tol = rad(q->cal_tol);
        c.kp = si16(q->kp);
    }
    return c;
}

static jtarget_t j_target_init(void)
{
    jtarget_t t;
#if J288_CONFIG_SI
    if (api == API_FACADE) {
        j288_joint_target_t f;
        j288_joint_target_init(&fj, &f);
        t.pos = (double)f.pos;
        t.speed = (double)f.speed;
        t.torque = (double)f.torque;
        t.kp = (double)f.kp;
        t.kd = (double)f.kd;
        return t;
    }
#endif
    {
        j288_jointq_target_t q;
        j288_jointq_target_init(&qj, &q);
        t.pos = rad(q.pos);
        t.speed = si16(q.speed);
        t.torque = si16(q.torque);
        t.kp = si16(q.kp);
        t.kd = si16(q.kd);
    }
    return t;
}

static int j_command(const jtarget_t *t, j288_cmd_raw_t *cmd, unsigned *clamped)
{
#if J288_CONFIG_SI
    if (api == API_FACADE) {
        j288_joint_target_t f = ftarget_of(t);
        return j288_joint_command(&fj, &f, cmd, clamped);
    }
#endif
    {
        j288_jointq_target_t q = qtarget_of(t);
        return j288_jointq_command(&qj, &q, cmd, clamped);
    }
}

static int j_zero_here(double *zero)
{
    int err;
#if J288_CONFIG_SI
    if (api == API_FACADE) {
        j288_real_t z = (j288_real_t)*zero;
        err = j288_joint_zero_here(&fj, &z);
        *zero = (double)z;
        return err;
    }
#endif
    {
        j288_q24_t z = q24(*zero);
        err = j288_jointq_zero_here(&qj, &z);
        *zero = rad(z);
    }
    return err;
}

static int j_lock_command(j288_cmd_raw_t *cmd)
{
#if J288_CONFIG_SI
    if (api == API_FACADE) {
        return j288_joint_lock_command(&fj, cmd);
    }
#endif
    return j288_jointq_lock_command(&qj, cmd);
}

/* ---- joint helpers */

static unsigned feed(const model_t *m)
{
    j288_reply_raw_t r = reply_of(m, j_core()->cfg.id);
    unsigned ev = 0xFFFFu;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_take(&r, &ev));
    return ev;
}

static unsigned feed_faulty(const model_t *m, uint16_t out_pos)
{
    j288_reply_raw_t r = reply_of(m, j_core()->cfg.id);
    unsigned ev = 0u;
    r.faults = FAULT12 | J288_FAULT_CASE_TEMP;
    r.out_pos = out_pos;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_take(&r, &ev));
    return ev;
}

/* Feed replies until the angle is known (at most 3 * init_samples); the events, ORed. */
static unsigned start_joint(const model_t *m)
{
    unsigned all = 0u;
    int i;
    for (i = 0; (i < 3 * (int)j_core()->cfg.init_samples) && !j_state().known; i++) {
        all |= feed(m);
    }
    return all;
}

static double q_of(const jcfg_t *c, const model_t *m)
{
    double dir = (c->direction < 0) ? -1.0 : 1.0;
    return dir * (m->theta - as_real(c->zero));
}

static double q_err(const jcfg_t *c, const model_t *m)
{
    return fabs(j_state().pos - q_of(c, m));
}

/* A random joint and servo: a range of width up to 6 rad anywhere within +-3 rad, zero
 * within +-8 rad, either direction, a random phase, powered up at a random pose of the
 * range, then moved to another. */
static void random_setup(jcfg_t *c, model_t *m, bool calibrated)
{
    double width = urand(0.3, 6.0), centre = urand(-3.0, 3.0);
    double dir;
    *c = cfg_for(3u);
    c->direction = (rnd() & 1u) ? (int8_t)1 : (int8_t)-1;
    dir = (double)c->direction;
    c->zero = urand(-8.0, 8.0);
    c->pos_min = centre - 0.5 * width;
    c->pos_max = centre + 0.5 * width;
    memset(m, 0, sizeof *m);
    m->side = 1.0;
    m->c = urand(-PI, PI);
    m->theta = as_real(c->zero) + dir * urand(c->pos_min, c->pos_max);
    power_up(m);
    m->theta = as_real(c->zero) + dir * urand(c->pos_min, c->pos_max);
    c->has_phase = calibrated;
    c->phase = m->c;
}

static void known_joint(const jcfg_t *c, model_t *m)
{
    *m = servo_at(0.2, -0.9);
    TEST_ASSERT_EQUAL_INT(J288_OK, j_init(c));
    (void)start_joint(m);
    TEST_ASSERT_TRUE(j_state().known);
}

/* The whole joint's bytes, for "untouched" (initialised with memset, so padding is zero). */
static void snapshot(uint8_t *buf, size_t cap)
{
#if J288_CONFIG_SI
    if (api == API_FACADE) {
        TEST_ASSERT_TRUE(sizeof fj <= cap);
        memcpy(buf, &fj, sizeof fj);
        return;
    }
#endif
    TEST_ASSERT_TRUE(sizeof qj <= cap);
    memcpy(buf, &qj, sizeof qj);
}

static uint8_t before_buf[1024], after_buf[1024];

/* ---- configuration */

static void test_config_checks(void)
{
    jcfg_t c = cfg_for(2u), got;
    int i;

    TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
    got = j_config();
    TEST_ASSERT_EQUAL_INT8(1, got.direction);
    TEST_ASSERT_EQUAL_UINT8(J288_JOINT_DEFAULT_INIT_SAMPLES, got.init_samples);
    TEST_ASSERT_DOUBLE_WITHIN(0.6 / Q24 + EPS, -PI, got.pos_min); /* +-pi: J288_JOINTQ_PI */
    TEST_ASSERT_DOUBLE_WITHIN(0.6 / Q24 + EPS, PI, got.pos_max);
    TEST_ASSERT_DOUBLE_WITHIN(EPS, 0.010, got.track_tol);
    TEST_ASSERT_DOUBLE_WITHIN(EPS, 1.0, got.cal_tol);
    TEST_ASSERT_FALSE(j_state().known);
    snapshot(before_buf, sizeof before_buf);
    for (i = 0; i < 24; i++) {
        int want = J288_ERR_BAD_CONFIG;
        c = cfg_for(2u);
        switch (i) {
        case 0: c.id = 15u; want = J288_ERR_BAD_ID; break;
        case 1: c.direction = 2; break;
        case 2: c.direction = -2; break;
        case 3: c.zero = 65.0; break;
        case 4: c.zero = -65.0; break;
        case 5: c.pos_min = -65.0; c.pos_max = 1; break;
        case 6: c.pos_min = 1; c.pos_max = 65.0; break;
        case 7: c.pos_min = 0.5; c.pos_max = 0.5; break;
        case 8: c.pos_min = 0.5; c.pos_max = 0.4; break;
        case 9: c.max_speed = -1; break;
        case 10: c.max_torque = -1; break;
        case 11: c.kp = -1; break;
        case 12: c.kd = -1; break;
        case 13: c.phase = 7.0; break;
        case 14: c.phase = -7.0; break;
        case 15: c.track_tol = -1; break;
        case 16: c.track_tol = 3.2; break;
        case 17: c.cal_tol = -1; break;
        case 18: c.cal_tol = 3.2; break;
        case 19: c.continuous = true; c.pos_max = 1.0; break; /* no limits on a wheel */
        case 20: c.continuous = true; c.pos_min = -1.0; break;
        case 21: c.zero = 64.00001; break; /* (a float's step at 64 is 7.6 urad) */
        case 22: c.track_tol = PI + 2.0 / Q24; break;
        default: c.pos_max = -0.5; break; /* pos_min 0 > pos_max */
        }
        TEST_ASSERT_EQUAL_INT_MESSAGE(want, j_init(&c), "case");
        snapshot(after_buf, sizeof after_buf);
        TEST_ASSERT_EQUAL_MEMORY(before_buf, after_buf, sizeof before_buf); /* untouched */
    }
    /* Edges that are fine. */
    c = cfg_for(14u);
    c.direction = -1;
    c.zero = 64.0;
    c.pos_min = -64.0;
    c.pos_max = 64.0;
    c.phase = 2.0 * PI - 2.0 * EPS; /* (a float's 2 pi and pi are above them) */
    c.track_tol = PI - EPS;
    c.cal_tol = PI - EPS;
    c.init_samples = 255u;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
    TEST_ASSERT_EQUAL_INT8(-1, j_config().direction);
    c.pos_min = 0;
    c.pos_max = 0.001; /* pos_min 0 alone is not the default */
    TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
    TEST_ASSERT_EQUAL_DOUBLE(0.0, j_config().pos_min);
    c = cfg_for(1u);
    c.continuous = true;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
    TEST_ASSERT_TRUE(j_config().continuous);
    TEST_ASSERT_EQUAL_DOUBLE(0.0, j_config().pos_max); /* no limits, not [-pi, pi] */
}

/* ---- the start */

static void test_default_is_the_encoder_angle_wrapped(void)
{
    jcfg_t c = cfg_for(1u);
    model_t m;
    int trial;
    double worst = 0.0;

    for (trial = 0; trial < 300; trial++) {
        double want;
        unsigned ev;
        double c0 = urand(-PI, PI); /* drawn first, as before */
        m = servo_at(urand(-20.0, 20.0), c0);
        m.theta += urand(-3.0, 3.0);
        TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
        ev = start_joint(&m);
        TEST_ASSERT_TRUE(j_state().known);
        TEST_ASSERT_FALSE(j_state().calibrated);
        TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_UNKNOWN) | EVB(ANGLE_KNOWN), ev);
        want = wrap(m.theta); /* [-pi, pi) */
        TEST_ASSERT_TRUE(j_state().pos >= -PI);
        TEST_ASSERT_TRUE(j_state().pos < PI);
        TEST_ASSERT_FALSE(j_state().beyond_limit);
        if (fabs(want) < PI - COUNT) { /* away from the wrap itself */
            double e = fabs(j_state().pos - want);
            TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, want, j_state().pos);
            worst = (e > worst) ? e : worst;
        }
    }
    print_value("uncalibrated start, default configuration, worst of 300", worst * 1e6, " urad");
}

static void test_start_events_and_refusals(void)
{
    jcfg_t c = cfg_for(5u);
    jtarget_t t;
    j288_cmd_raw_t cmd, before;
    model_t m;
    double z = 7.0;
    int i;

    m = servo_at(1.0, 0.3);
    c.init_samples = 4u;
    c.kp = 7.0;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
    memset(&before, 0x5A, sizeof before);
    cmd = before;
    t = j_target_init();
    TEST_ASSERT_EQUAL_DOUBLE(0.0, t.pos); /* unknown: 0, with the default gains */
    TEST_ASSERT_DOUBLE_WITHIN(EPS, 7.0, t.kp);
    TEST_ASSERT_EQUAL_INT(J288_ERR_ANGLE_UNKNOWN, j_command(&t, &cmd, NULL));
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_UNKNOWN), feed(&m));
    for (i = 0; i < 2; i++) {
        TEST_ASSERT_EQUAL_HEX(0u, feed(&m));
        TEST_ASSERT_FALSE(j_state().known);
        TEST_ASSERT_EQUAL_INT(J288_ERR_ANGLE_UNKNOWN, j_command(&t, &cmd, NULL));
        TEST_ASSERT_EQUAL_INT(J288_ERR_ANGLE_UNKNOWN, j_zero_here(&z));
        TEST_ASSERT_EQUAL_DOUBLE(7.0, z);
    }
    TEST_ASSERT_EQUAL_MEMORY(&before, &cmd, sizeof cmd);
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_KNOWN), feed(&m));
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, 1.0, j_state().pos);
    TEST_ASSERT_EQUAL_HEX(0u, feed(&m));
    /* A reset forgets: not yet known again, reported again. */
    j_reset();
    TEST_ASSERT_FALSE(j_state().known);
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_UNKNOWN), feed(&m));
    /* One sample is enough when configured so: both events in one reply. */
    c.init_samples = 1u;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_UNKNOWN) | EVB(ANGLE_KNOWN), feed(&m));
    /* The lock command. */
    TEST_ASSERT_EQUAL_INT(J288_OK, j_lock_command(&cmd));
    TEST_ASSERT_EQUAL_UINT8(5u, cmd.id);
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_LOCK, cmd.status);
    TEST_ASSERT_TRUE(cmd.watchdog);
    TEST_ASSERT_EQUAL_INT32(0, cmd.pos);
    TEST_ASSERT_EQUAL_INT16(0, cmd.kp);
}

static void test_take_reply_errors(void)
{
    jcfg_t c = cfg_for(5u);
    j288_reply_raw_t r;
    model_t m;
    unsigned ev = 77u;

    memset(&m, 0, sizeof m);
    r = reply_of(&m, 6u);
    TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
    snapshot(before_buf, sizeof before_buf);
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j_take(NULL, &ev));
    TEST_ASSERT_EQUAL_INT(J288_ERR_WRONG_ID, j_take(&r, &ev));
    snapshot(after_buf, sizeof after_buf);
    TEST_ASSERT_EQUAL_MEMORY(before_buf, after_buf, sizeof before_buf);
    TEST_ASSERT_EQUAL_UINT(77u, ev);
    r.id = 5u;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_take(&r, NULL)); /* events NULL */
    TEST_ASSERT_EQUAL_INT(J288_OK, j_take(&r, &ev));
    TEST_ASSERT_EQUAL_UINT(0u, ev);
}

/* Uncalibrated and calibrated starts over random joints, then motion over the range. */
static void random_runs(bool calibrated, double tol, const char *label)
{
    jcfg_t c;
    model_t m;
    int trial, step;
    double worst = 0.0;

    for (trial = 0; trial < 400; trial++) {
        double dir;
        random_setup(&c, &m, calibrated);
        dir = (double)c.direction;
        TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
        TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_UNKNOWN) | EVB(ANGLE_KNOWN), start_joint(&m));
        TEST_ASSERT_EQUAL(calibrated, j_state().calibrated);
        TEST_ASSERT_DOUBLE_WITHIN(tol, q_of(&c, &m), j_state().pos);
        worst = (q_err(&c, &m) > worst) ? q_err(&c, &m) : worst;
        /* A walk over the range, in steps up to 0.1 rad, either way. */
        for (step = 0; step < 40; step++) {
            double q = q_of(&c, &m) + urand(-0.1, 0.1);
            if ((q < c.pos_min) || (q > c.pos_max)) {
                q = urand(c.pos_min, c.pos_max);
            }
            move_to(&m, as_real(c.zero) + dir * q);
            TEST_ASSERT_EQUAL_HEX(0u, feed(&m));
            TEST_ASSERT_DOUBLE_WITHIN(tol, q, j_state().pos);
            TEST_ASSERT_DOUBLE_WITHIN(COUNT, 0.0, j_state().residual);
        }
    }
    print_value(label, worst * 1e6, " urad");
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
    jcfg_t c = cfg_for(7u);
    j288_reply_raw_t r;
    model_t m;
    int d;

    m = servo_at(0.25, 0.0);
    for (d = -1; d <= 1; d += 2) {
        c.direction = (int8_t)d;
        c.zero = 0.75;
        TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
        (void)start_joint(&m);
        TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, d * (0.25 - 0.75), j_state().pos);
        r = reply_of(&m, 7u);
        r.speed = -1234;
        r.torque = 4321;
        TEST_ASSERT_EQUAL_INT(J288_OK, j_take(&r, NULL));
        /* within one Q16 step of the exact value; torque exactly rounded */
        TEST_ASSERT_DOUBLE_WITHIN(1.0 / Q16 + EPS, d * -1234.0 * TAU / 2.56 / NR, j_state().speed);
        TEST_ASSERT_DOUBLE_WITHIN(0.5 / Q16 + EPS, d * 4321.0 * NR / 256000.0, j_state().torque);
        TEST_ASSERT_DOUBLE_WITHIN(1.0 / Q24 + EPS, (model_count(&m) + 0.5) * COUNT,
                                  j_state().encoder);
        /* Moving the output up moves the joint by direction. */
        move_to(&m, 0.35);
        (void)feed(&m);
        TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, d * (0.35 - 0.75), j_state().pos);
        move_to(&m, 0.25);
    }
}

/* A start with the joint moving, and one where a sample disagrees: the start restarts. */
static void test_start_while_moving_and_outlier(void)
{
    jcfg_t c = cfg_for(2u);
    j288_reply_raw_t r;
    model_t m;
    int i;

    m = servo_at(2.0, -2.0);
    TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
    for (i = 0; i < 8; i++) {
        (void)feed(&m);
        move_to(&m, m.theta + 0.013); /* 17 counts a reply */
    }
    TEST_ASSERT_TRUE(j_state().known);
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, m.theta - 0.013, j_state().pos);

    /* Sample 4 of 8 reads 30 counts off: the collection restarts from it, then again from
     * the next good one, so 8 good samples follow. */
    TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
    for (i = 0; i < 3; i++) {
        (void)feed(&m);
    }
    r = reply_of(&m, 2u);
    r.out_pos = (uint16_t)(r.out_pos + 30u);
    TEST_ASSERT_EQUAL_INT(J288_OK, j_take(&r, NULL));
    for (i = 0; i < 7; i++) {
        TEST_ASSERT_EQUAL_HEX(0u, feed(&m));
    }
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_KNOWN), feed(&m));
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, m.theta, j_state().pos);

    /* 150 million LSB between two samples (26 output rad modulo 20 turns): the second
     * disagrees and the collection starts again from it. */
    m = servo_at(0.3, 0.7);
    c.init_samples = 2u;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
    r = reply_of(&m, 2u);
    TEST_ASSERT_EQUAL_INT(J288_OK, j_take(&r, NULL));
    r.pos = (int32_t)((uint32_t)r.pos + 150000000u);
    TEST_ASSERT_EQUAL_INT(J288_OK, j_take(&r, NULL));
    TEST_ASSERT_FALSE(j_state().known);
    TEST_ASSERT_EQUAL_INT(J288_OK, j_take(&r, NULL));
    TEST_ASSERT_TRUE(j_state().known);
}

/* Averaging at the start pays when the joint moves: each sample's quantization differs. */
static void test_start_average_while_moving(void)
{
    jcfg_t c = cfg_for(2u);
    model_t m;
    int trial, i;
    double worst = 0.0;

    c.init_samples = 64u;
    for (trial = 0; trial < 50; trial++) {
        double step = COUNT * urand(0.3, 0.7);
        double c0 = urand(-PI, PI);
        m = servo_at(urand(-3.0, 2.5), c0);
        TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
        for (i = 0; i < 64; i++) {
            (void)feed(&m);
            move_to(&m, m.theta + step);
        }
        TEST_ASSERT_TRUE(j_state().known);
        m.theta -= step;
        worst = (q_err(&c, &m) > worst) ? q_err(&c, &m) : worst;
    }
    TEST_ASSERT_TRUE(worst < 0.15 * COUNT); /* under a third of the half count at rest */
    print_value("uncalibrated start over 64 replies while moving, worst of 50", worst * 1e6,
                " urad");
}

/* The start angle is chosen within pi of the range's middle: inside the range when the joint
 * is, else at the nearest end, with a limit event. */
static void test_turn_choice(void)
{
    jcfg_t c = cfg_for(1u);
    model_t m;
    unsigned ev;

    c.pos_min = 5.8; /* the encoder wraps inside: 2 pi = 6.283 */
    c.pos_max = 6.8;
    m = servo_at(6.6, 0.0);
    TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_UNKNOWN) | EVB(ANGLE_KNOWN), start_joint(&m));
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, 6.6, j_state().pos); /* not 0.317 */

    /* Outside [0.5, 1.0]: 3.5 is 2.5 above the top end, or as 3.5 - 2 pi 3.28 below the
     * bottom end: labelled 3.5... */
    c.pos_min = 0.5;
    c.pos_max = 1.0;
    m.theta = 3.5;
    power_up(&m);
    TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
    ev = start_joint(&m);
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_UNKNOWN) | EVB(ANGLE_KNOWN) | EVB(LIMIT_REACHED), ev);
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, 3.5, j_state().pos);
    TEST_ASSERT_TRUE(j_state().beyond_limit);
    /* ... and 4.1 is nearer the bottom end: labelled 4.1 - 2 pi = -2.18. */
    m.theta = 4.1;
    power_up(&m);
    TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
    ev = start_joint(&m);
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_UNKNOWN) | EVB(ANGLE_KNOWN) | EVB(LIMIT_REACHED), ev);
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, 4.1 - TAU, j_state().pos);

    /* Direction -1 and a zero: q = -(theta - zero) within pi of the middle. */
    c.direction = -1;
    c.zero = 10.0;
    c.pos_min = -0.4;
    c.pos_max = 0.4;
    m.theta = 10.0 - 0.3 - 2.0 * TAU; /* the same pose two turns away: the same reading */
    power_up(&m);
    TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_UNKNOWN) | EVB(ANGLE_KNOWN), start_joint(&m));
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, 0.3, j_state().pos);

    /* Far zeros with a calibrated start (theta beyond +-20 pi, reduced by 40 pi). */
    for (int sign = -1; sign <= 1; sign += 2) {
        m = servo_at(65.0 * sign, -0.4);
        c = cfg_for(1u);
        c.zero = 60.0 * sign;
        c.pos_min = (sign > 0) ? 3.0 : -7.0;
        c.pos_max = (sign > 0) ? 7.0 : -3.0;
        c.has_phase = true;
        c.phase = m.c;
        TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
        TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_UNKNOWN) | EVB(ANGLE_KNOWN), start_joint(&m));
        TEST_ASSERT_TRUE(j_state().calibrated);
        TEST_ASSERT_DOUBLE_WITHIN(CAL_TOL, 5.0 * sign, j_state().pos);
    }
}

/* Ranges across the encoder's wrap, crossed both ways, both directions, both modes. */
static void test_range_across_the_wrap(void)
{
    jcfg_t c;
    model_t m;
    int mode, d, i;

    for (mode = 0; mode < 2; mode++) {
        for (d = -1; d <= 1; d += 2) {
            double tol = mode ? CAL_TOL : UNCAL_TOL;
            c = cfg_for(9u);
            c.direction = (int8_t)d;
            c.zero = TAU * 3.0 + 0.2; /* theta = 6 pi + 0.2 is joint 0 */
            c.pos_min = -0.6;
            c.pos_max = 0.6;
            m = servo_at(as_real(c.zero) + d * 0.5, 1.7);
            c.has_phase = (mode == 1);
            c.phase = m.c;
            TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
            (void)start_joint(&m);
            TEST_ASSERT_DOUBLE_WITHIN(tol, 0.5, j_state().pos);
            /* Down through theta = 6 pi (OutPos 0 -> 8191) to joint -0.55, and back. */
            for (i = 0; i <= 210; i++) {
                double q = (i <= 105) ? 0.5 - 0.01 * i : -0.55 + 0.01 * (i - 105);
                move_to(&m, as_real(c.zero) + d * q);
                TEST_ASSERT_EQUAL_HEX(0u, feed(&m));
                TEST_ASSERT_DOUBLE_WITHIN(tol, q, j_state().pos);
            }
            /* A fresh start on the far side of the wrap labels the same way. */
            move_to(&m, as_real(c.zero) - 0.4 * d);
            j_reset();
            (void)start_joint(&m);
            TEST_ASSERT_DOUBLE_WITHIN(tol, -0.4, j_state().pos);
        }
    }
}

/* ---- calibration at the start */

static void test_wrong_calibration(void)
{
    jcfg_t c;
    jtarget_t t;
    j288_cmd_raw_t cmd;
    model_t m;
    int trial, i;

    for (trial = 0; trial < 200; trial++) {
        double delta = urand(-PI, PI);
        unsigned ev;
        random_setup(&c, &m, true);
        c.phase = wrap(m.c + delta);
        TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
        ev = start_joint(&m);
        if (fabs(delta) > j_config().cal_tol + 0.12) { /* beyond, with half a count of margin */
            TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_UNKNOWN) | EVB(CAL_MISMATCH), ev);
            TEST_ASSERT_FALSE(j_state().known);
            TEST_ASSERT_TRUE(j_state().cal_mismatch);
            TEST_ASSERT_DOUBLE_WITHIN(0.12, 0.0, wrap(j_state().cal_residual - delta));
            t = j_target_init();
            TEST_ASSERT_EQUAL_INT(J288_ERR_CAL_MISMATCH, j_command(&t, &cmd, NULL));
            /* It keeps trying, and says so once. */
            for (i = 0; i < 40; i++) {
                TEST_ASSERT_EQUAL_HEX(0u, feed(&m));
            }
            TEST_ASSERT_FALSE(j_state().known);
            /* The calibration is put right: the next start succeeds. */
            j_core()->cfg.phase = q24(m.c);
            ev = start_joint(&m);
            TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_KNOWN), ev);
            TEST_ASSERT_FALSE(j_state().cal_mismatch);
            TEST_ASSERT_DOUBLE_WITHIN(CAL_TOL, q_of(&c, &m), j_state().pos);
        } else if (fabs(delta) < j_config().cal_tol - 0.12) {
            /* Accepted: the angle is off by exactly delta / N (never more than cal_tol / N). */
            double want = q_of(&c, &m) - (double)c.direction * delta / NR;
            TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_UNKNOWN) | EVB(ANGLE_KNOWN), ev);
            TEST_ASSERT_DOUBLE_WITHIN(CAL_TOL, want, j_state().pos);
        }
    }
}

/* ---- tracking: power cycles, slipped gears, the output encoder's fault bit */

static void test_power_cycle(void)
{
    jcfg_t c;
    model_t m;
    int trial, lost = 0, harmless = 0;

    for (trial = 0; trial < 400; trial++) {
        bool calibrated = (trial & 1) != 0;
        double k_old, shift;
        unsigned ev;
        random_setup(&c, &m, calibrated);
        TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
        (void)start_joint(&m);
        /* Power off, move somewhere in the range, power on: p restarts, theta is kept. One
         * in eight goes back to where it was powered up before: the same turn count. */
        if (trial % 8 == 0) {
            move_to(&m, m.theta_pu);
        } else {
            move_to(&m, as_real(c.zero) + c.direction * urand(c.pos_min, c.pos_max));
        }
        k_old = m.k;
        power_up(&m);
        shift = TAU * (k_old - m.k) / NR; /* what the stale anchor would add */
        ev = feed(&m);
        if (fabs(wrap(shift)) > j_config().track_tol + COUNT) {
            TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_LOST), ev);
            TEST_ASSERT_FALSE(j_state().known);
            TEST_ASSERT_FALSE(j_state().calibrated);
            TEST_ASSERT_DOUBLE_WITHIN(COUNT, wrap(shift), j_state().residual);
            lost++;
            /* It starts again from the next replies, right. */
            TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_KNOWN), start_joint(&m));
            TEST_ASSERT_DOUBLE_WITHIN(calibrated ? CAL_TOL : UNCAL_TOL, q_of(&c, &m),
                                      j_state().pos);
        } else if (fabs(wrap(shift)) < j_config().track_tol - COUNT) {
            /* Undetectable, and then off by at most track_tol: the guarantee. */
            TEST_ASSERT_EQUAL_HEX(0u, ev & EVB(ANGLE_LOST));
            TEST_ASSERT_TRUE(q_err(&c, &m) <= j_config().track_tol + UNCAL_TOL);
            harmless++;
        }
    }
    TEST_ASSERT_TRUE(lost > 280);
    TEST_ASSERT_TRUE(harmless >= 50); /* the same turn count: nothing to see */
}

static void test_slipped_gear(void)
{
    jcfg_t c = cfg_for(4u);
    model_t m;
    int32_t p_before;

    m = servo_at(-1.0, 0.4);
    c.has_phase = true;
    c.phase = m.c;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
    (void)start_joint(&m);
    /* The rotor slips 5.5 turns against the output: 60 mrad of output. */
    p_before = model_pos(&m);
    m.c += 5.5 * TAU;
    TEST_ASSERT_TRUE(model_pos(&m) != p_before);
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_LOST), feed(&m));
    /* c is now off by half a turn: the calibrated start refuses, once. */
    TEST_ASSERT_EQUAL_HEX(EVB(CAL_MISMATCH), start_joint(&m));
    TEST_ASSERT_DOUBLE_WITHIN(0.12, PI, fabs(j_state().cal_residual));
    TEST_ASSERT_EQUAL_HEX(0u, start_joint(&m));
    /* Uncalibrated, the same slip is taken from the encoder. */
    c.has_phase = false;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
    (void)start_joint(&m);
    m.c += 3.0 * TAU; /* whole turns */
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_LOST), feed(&m));
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_KNOWN), start_joint(&m));
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, -1.0, j_state().pos);
}

static void test_encoder_fault(void)
{
    jcfg_t c = cfg_for(8u);
    model_t m;
    int i;

    m = servo_at(0.7, 2.5);
    c.init_samples = 3u;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
    /* Unknown and faulty: no start, whatever OutPos says. */
    TEST_ASSERT_EQUAL_HEX(EVB(ENCODER_FAULT) | EVB(ANGLE_UNKNOWN), feed_faulty(&m, 0u));
    TEST_ASSERT_TRUE(j_state().encoder_fault);
    for (i = 0; i < 10; i++) {
        TEST_ASSERT_EQUAL_HEX(0u, feed_faulty(&m, model_count(&m)));
        TEST_ASSERT_FALSE(j_state().known);
    }
    /* Two good replies, a faulty one (the start begins again), then three good ones. */
    TEST_ASSERT_EQUAL_HEX(EVB(ENCODER_OK), feed(&m));
    TEST_ASSERT_EQUAL_HEX(0u, feed(&m));
    TEST_ASSERT_EQUAL_HEX(EVB(ENCODER_FAULT), feed_faulty(&m, model_count(&m)));
    TEST_ASSERT_EQUAL_HEX(EVB(ENCODER_OK), feed(&m));
    TEST_ASSERT_EQUAL_HEX(0u, feed(&m));
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_KNOWN), feed(&m));
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, 0.7, j_state().pos);
    /* Known and faulty: no comparison (a wild OutPos is ignored), the rotor is followed. */
    move_to(&m, 0.9);
    TEST_ASSERT_EQUAL_HEX(EVB(ENCODER_FAULT), feed_faulty(&m, 4000u));
    TEST_ASSERT_TRUE(j_state().known);
    TEST_ASSERT_EQUAL_DOUBLE(0.0, j_state().residual);
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, 0.9, j_state().pos);
    /* Cleared: compared again, and a disagreement is a loss. */
    TEST_ASSERT_EQUAL_HEX(EVB(ENCODER_OK), feed(&m));
    TEST_ASSERT_TRUE(j_state().known);
    m.c += TAU * 2.0;
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_LOST), feed(&m));
}

/* Positions far from the power-up pose, and rotor counts that wrap at int32. */
static void test_large_rotor_positions(void)
{
    jcfg_t c = cfg_for(3u);
    j288_reply_raw_t r;
    jtarget_t t;
    j288_cmd_raw_t cmd;
    model_t m;
    const int32_t base = INT32_MAX - 1000;
    int32_t p0;
    int i;

    c.pos_min = 2.0;
    c.pos_max = 8.0;
    m = servo_at(-5.9, 0.1);
    move_to(&m, 5.9); /* 11.8 rad from power-up: 17.8 million LSB */
    TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
    (void)start_joint(&m);
    TEST_ASSERT_TRUE(model_pos(&m) > 17000000);
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, 5.9, j_state().pos);
    /* Counts near INT32_MAX that wrap to negative: followed modulo 2^32. */
    p0 = model_pos(&m);
    TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
    for (i = 0; i < 10; i++) {
        r = reply_of(&m, 3u);
        r.pos = base;
        TEST_ASSERT_EQUAL_INT(J288_OK, j_take(&r, NULL));
    }
    TEST_ASSERT_TRUE(j_state().known);
    move_to(&m, 5.95);
    r = reply_of(&m, 3u);
    r.pos = (int32_t)((uint32_t)base + (uint32_t)(model_pos(&m) - p0)); /* wraps */
    TEST_ASSERT_TRUE(r.pos < 0);
    TEST_ASSERT_EQUAL_INT(J288_OK, j_take(&r, NULL));
    TEST_ASSERT_TRUE(j_state().known);
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, 5.95, j_state().pos);
    /* A target beyond the wire's int32 from there: refused, never wrapped. */
    t = j_target_init();
    t.kp = 10.0;
    t.pos = 5.99;
    TEST_ASSERT_EQUAL_INT(J288_ERR_RANGE_POS, j_command(&t, &cmd, NULL));
    t.pos = 5.0; /* backwards is fine */
    TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&t, &cmd, NULL));
    TEST_ASSERT_TRUE(cmd.pos > 0);
    /* With kp = 0 the position has no effect: the rotor's latest goes out, never refused. */
    t.kp = 0.0;
    t.pos = 5.99;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&t, &cmd, NULL));
    TEST_ASSERT_EQUAL_INT32(r.pos, cmd.pos);
    /* The same at the other end of int32. */
    TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
    for (i = 0; i < 10; i++) {
        r = reply_of(&m, 3u);
        r.pos = INT32_MIN + 1000;
        TEST_ASSERT_EQUAL_INT(J288_OK, j_take(&r, NULL));
    }
    t.kp = 10.0;
    t.pos = 5.9;
    TEST_ASSERT_EQUAL_INT(J288_ERR_RANGE_POS, j_command(&t, &cmd, NULL));
    t.pos = 6.0;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&t, &cmd, NULL));
    TEST_ASSERT_TRUE(cmd.pos < 0);
}

/* ---- commands */

/* Where the model's rotor must go for joint angle q (same power-up), in LSB. */
static double rotor_lsb_for(const jcfg_t *c, const model_t *m, double q)
{
    double theta = as_real(c->zero) + (double)c->direction * q;
    return (NR * theta + m->c - TAU * m->k) / ROTOR_LSB;
}

static void test_command_frames(void)
{
    jcfg_t c;
    jtarget_t t;
    j288_cmd_raw_t cmd;
    model_t m;
    int trial;

    for (trial = 0; trial < 300; trial++) {
        double d, pos_tol;
        bool calibrated = (trial & 1) != 0;
        unsigned clamped = 99u;
        random_setup(&c, &m, calibrated);
        d = (double)c.direction;
        c.kp = urand(1.0, 100.0);
        c.kd = urand(0.0, 5.0);
        TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
        (void)start_joint(&m);
        t = j_target_init();
        TEST_ASSERT_DOUBLE_WITHIN(1.0 / Q24, j_state().pos, t.pos);
        TEST_ASSERT_DOUBLE_WITHIN(1.0 / Q16, c.kp, t.kp);
        TEST_ASSERT_DOUBLE_WITHIN(1.0 / Q16, c.kd, t.kd);
        t.pos = urand(c.pos_min, c.pos_max);
        t.speed = urand(-20.0, 20.0);
        t.torque = urand(-30.0, 30.0);
        t.kd = 0.0; /* no damping: the limit law never wins over this target at rest */
        TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&t, &cmd, &clamped));
        if ((clamped & J288_JOINT_LIMITED) != 0u) {
            continue; /* a target toward a limit it is about to reach: test_limit_law */
        }
        TEST_ASSERT_EQUAL_UINT(0u, clamped);
        TEST_ASSERT_EQUAL_UINT8(3u, cmd.id);
        TEST_ASSERT_EQUAL_UINT8(J288_MODE_FOC, cmd.status);
        TEST_ASSERT_TRUE(cmd.watchdog);
        /* The position: the start's error (uncalibrated) plus rounding, in rotor LSB. */
        pos_tol =
            (calibrated ? 1.0 : 0.5 * COUNT * NR / ROTOR_LSB + 1.0) + EPS * NR / ROTOR_LSB * 4.0;
        TEST_ASSERT_DOUBLE_WITHIN(pos_tol, rotor_lsb_for(&c, &m, as_real(t.pos)), (double)cmd.pos);
        TEST_ASSERT_INT_WITHIN(1, (int)lround(d * as_real(t.speed) * NR * 2.56 / TAU), cmd.speed);
        TEST_ASSERT_INT_WITHIN(1, (int)lround(d * as_real(t.torque) / NR * 256000.0), cmd.tau);
        TEST_ASSERT_INT_WITHIN(1, (int)lround(as_real(t.kp) / (NR * NR) * 1280000.0), cmd.kp);
        TEST_ASSERT_EQUAL_INT16(0, cmd.kd);
    }
}

/* Commands bring the model's joint where the targets say: after a move, q reads the target. */
static void test_command_round_trip(void)
{
    jcfg_t c;
    jtarget_t t;
    j288_cmd_raw_t cmd;
    model_t m;
    int trial;

    for (trial = 0; trial < 200; trial++) {
        double theta_cmd;
        random_setup(&c, &m, (trial & 1) != 0);
        c.kp = 10.0;
        TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
        (void)start_joint(&m);
        t = j_target_init();
        t.pos = urand(c.pos_min, c.pos_max);
        TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&t, &cmd, NULL));
        /* The servo holds its rotor at cmd.pos: the output is where the rotor says. */
        theta_cmd = ((double)cmd.pos * ROTOR_LSB - m.c + TAU * m.k) / NR;
        move_to(&m, theta_cmd);
        TEST_ASSERT_EQUAL_HEX(0u, feed(&m) & ~(EVB(LIMIT_LEFT)));
        TEST_ASSERT_DOUBLE_WITHIN(2.0 * ROTOR_RES + EPS, as_real(t.pos), j_state().pos);
    }
}

/* Field by field: a command's padding is not part of it. */
static void assert_same_cmd(const j288_cmd_raw_t *a, const j288_cmd_raw_t *b)
{
    TEST_ASSERT_EQUAL_UINT8(a->id, b->id);
    TEST_ASSERT_EQUAL_UINT8(a->status, b->status);
    TEST_ASSERT_EQUAL(a->watchdog, b->watchdog);
    TEST_ASSERT_EQUAL_INT16(a->tau, b->tau);
    TEST_ASSERT_EQUAL_INT16(a->speed, b->speed);
    TEST_ASSERT_EQUAL_INT32(a->pos, b->pos);
    TEST_ASSERT_EQUAL_INT16(a->kp, b->kp);
    TEST_ASSERT_EQUAL_INT16(a->kd, b->kd);
}

/* Joint 6 with limits [-0.5, 1.25] rad, 3 rad/s, 10 N*m, refusing or clamping. */
static jcfg_t limited_cfg(bool clamp)
{
    jcfg_t c = cfg_for(6u);
    c.pos_min = -0.5;
    c.pos_max = 1.25;
    c.max_speed = 3.0;
    c.max_torque = 10.0;
    c.clamp = clamp;
    return c;
}

static void test_limits_refused(void)
{
    jcfg_t c = limited_cfg(false);
    jtarget_t t, good;
    j288_cmd_raw_t cmd, before;
    model_t m;
    unsigned clamped = 55u;
    int i;

    c.kp = 20.0;
    c.kd = 0.5;
    known_joint(&c, &m);
    good = j_target_init();
    good.speed = 3.0; /* the limits themselves are fine */
    good.torque = -10.0;
    good.pos = 1.25;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&good, &cmd, &clamped));
    TEST_ASSERT_EQUAL_UINT(0u, clamped);
    good.pos = -0.5;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&good, &cmd, NULL));
    memset(&before, 0x3C, sizeof before);
    for (i = 0; i < 10; i++) {
        int want;
        t = good;
        switch (i) {
        case 0: t.pos = 1.2501; want = J288_ERR_LIMIT_POS; break;
        case 1: t.pos = -0.5001; want = J288_ERR_LIMIT_POS; break;
        case 2: t.speed = 3.01; want = J288_ERR_LIMIT_SPEED; break;
        case 3: t.speed = -3.01; want = J288_ERR_LIMIT_SPEED; break;
        case 4: t.torque = 10.01; want = J288_ERR_LIMIT_TORQUE; break;
        case 5: t.torque = -20000.0; want = J288_ERR_LIMIT_TORQUE; break;
        case 6: t.kp = -1.0; want = J288_ERR_NEG_GAIN; break;
        case 7: t.kd = 30.0; want = J288_ERR_RANGE_KD; break;
        case 8: t.pos = 1.2501; t.speed = 4.0; want = J288_ERR_LIMIT_POS; break; /* the order */
        default: t.kp = 3000.0; want = J288_ERR_RANGE_KP; break; /* > wire */
        }
        cmd = before;
        clamped = 55u;
        TEST_ASSERT_EQUAL_INT_MESSAGE(want, j_command(&t, &cmd, &clamped), "case");
        TEST_ASSERT_EQUAL_MEMORY(&before, &cmd, sizeof cmd);
        TEST_ASSERT_EQUAL_UINT(55u, clamped);
    }
    /* A position beyond the limits is not checked when kp is 0: it has no effect. */
    t = good;
    t.kp = 0.0;
    t.pos = 7.0;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&t, &cmd, NULL));
    /* No speed or torque limit configured: only the wire's range. */
    c.max_speed = 0;
    c.max_torque = 0;
    known_joint(&c, &m);
    t = good;
    t.speed = 250.0;
    t.torque = 36.0;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&t, &cmd, NULL));
    t.torque = 40.0; /* 0.1387 N*m of rotor > 0.128 on the wire */
    TEST_ASSERT_EQUAL_INT(J288_ERR_RANGE_TAU, j_command(&t, &cmd, NULL));
    t.torque = 0;
    t.speed = -280.0;
    TEST_ASSERT_EQUAL_INT(J288_ERR_RANGE_SPEED, j_command(&t, &cmd, NULL));
}

static void test_limits_clamped(void)
{
    jcfg_t c = limited_cfg(true);
    jtarget_t t, want;
    j288_cmd_raw_t cmd, ref;
    model_t m;
    unsigned clamped = 0u;

    known_joint(&c, &m);
    t = j_target_init();
    t.kp = 20.0;
    t.pos = 2.0;
    t.speed = -3.0;
    t.torque = -10.0; /* away from the top: not shaped by the limit law */
    TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&t, &cmd, &clamped));
    TEST_ASSERT_EQUAL_UINT(J288_FIELD_POS, clamped);
    t.speed = -7.0;
    t.torque = -11.0;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&t, &cmd, &clamped));
    TEST_ASSERT_EQUAL_UINT(J288_FIELD_POS | J288_FIELD_SPEED | J288_FIELD_TAU, clamped);
    want = t;
    want.pos = 1.25;
    want.speed = -3.0;
    want.torque = -10.0;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&want, &ref, &clamped));
    TEST_ASSERT_EQUAL_UINT(0u, clamped);
    assert_same_cmd(&ref, &cmd);
    want.torque = 0.0; /* (-10 N*m at the bottom would drive through it) */
    t = want;
    t.pos = -100.0;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&t, &cmd, &clamped));
    TEST_ASSERT_EQUAL_UINT(J288_FIELD_POS, clamped);
    want.pos = -0.5;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&want, &ref, NULL));
    TEST_ASSERT_EQUAL_INT32(ref.pos, cmd.pos);
    /* Gains beyond the wire saturate as j288_cmd_from_q_clamped() does. */
    t = want;
    t.speed = 0.0;
    t.kp = 3000.0;
    t.kd = -1.0;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&t, &cmd, &clamped));
    TEST_ASSERT_EQUAL_UINT(J288_FIELD_KP | J288_FIELD_KD, clamped);
    TEST_ASSERT_EQUAL_INT16(INT16_MAX, cmd.kp);
    TEST_ASSERT_EQUAL_INT16(0, cmd.kd);
    t.kd = 30.0;
    t.kp = -5.0;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&t, &cmd, &clamped));
    TEST_ASSERT_EQUAL_UINT(J288_FIELD_KP | J288_FIELD_KD, clamped);
    TEST_ASSERT_EQUAL_INT16(0, cmd.kp);
    TEST_ASSERT_EQUAL_INT16(INT16_MAX, cmd.kd);
}

static void test_limit_events(void)
{
    jcfg_t c = cfg_for(6u);
    model_t m;

    c.pos_min = -0.5;
    c.pos_max = 1.0;
    known_joint(&c, &m);
    TEST_ASSERT_FALSE(j_state().beyond_limit);
    move_to(&m, 0.999);
    TEST_ASSERT_EQUAL_HEX(0u, feed(&m));
    move_to(&m, 1.0004);
    TEST_ASSERT_EQUAL_HEX(EVB(LIMIT_REACHED), feed(&m));
    TEST_ASSERT_TRUE(j_state().beyond_limit);
    move_to(&m, 1.2);
    TEST_ASSERT_EQUAL_HEX(0u, feed(&m));
    move_to(&m, 0.9995); /* inside, but within the hysteresis */
    TEST_ASSERT_EQUAL_HEX(0u, feed(&m));
    move_to(&m, 0.998);
    TEST_ASSERT_EQUAL_HEX(EVB(LIMIT_LEFT), feed(&m));
    TEST_ASSERT_FALSE(j_state().beyond_limit);
    move_to(&m, -0.6);
    TEST_ASSERT_EQUAL_HEX(EVB(LIMIT_REACHED), feed(&m));
    move_to(&m, -0.4995);
    TEST_ASSERT_EQUAL_HEX(0u, feed(&m));
    move_to(&m, -0.49);
    TEST_ASSERT_EQUAL_HEX(EVB(LIMIT_LEFT), feed(&m));
    /* Beyond the limit, then lost: the next start reports the limit again. */
    move_to(&m, 1.1);
    TEST_ASSERT_EQUAL_HEX(EVB(LIMIT_REACHED), feed(&m));
    m.c += 2.0 * TAU;
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_LOST), feed(&m));
    TEST_ASSERT_FALSE(j_state().beyond_limit);
    TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_KNOWN) | EVB(LIMIT_REACHED), start_joint(&m));
}

/* Holding near a limit: within J288_JOINTQ_HOLD_BEYOND beyond, at the limit; farther, where it
 * is (refused). */
static void test_hold_near_a_limit(void)
{
    jcfg_t c = cfg_for(6u);
    j288_cmd_raw_t cmd;
    jtarget_t t;
    model_t m;

    c.pos_min = -0.5;
    c.pos_max = 1.0;
    c.kp = 30.0;
    c.kd = 1.0;
    known_joint(&c, &m);
    move_to(&m, 1.04);
    (void)feed(&m);
    t = j_target_init();
    TEST_ASSERT_DOUBLE_WITHIN(1.0 / Q24, 1.0, t.pos);
    TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&t, &cmd, NULL));
    move_to(&m, -0.54);
    (void)feed(&m);
    TEST_ASSERT_DOUBLE_WITHIN(1.0 / Q24, -0.5, j_target_init().pos);
    move_to(&m, 1.06);
    (void)feed(&m);
    t = j_target_init();
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, 1.06, t.pos);
    TEST_ASSERT_EQUAL_INT(J288_ERR_LIMIT_POS, j_command(&t, &cmd, NULL));
    /* A continuous joint has no limit: held where it is. */
    c = cfg_for(6u);
    c.continuous = true;
    known_joint(&c, &m);
    move_to(&m, 3.3);
    (void)feed(&m);
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, 3.3, j_target_init().pos);
}

static void test_zero_here(void)
{
    jcfg_t c = cfg_for(2u);
    double zero = 0;
    j288_reply_raw_t r;
    model_t m;
    int d;

    for (d = -1; d <= 1; d += 2) {
        c.direction = (int8_t)d;
        c.zero = 1.0;
        c.has_phase = true;
        c.phase = -0.9; /* known_joint()'s servo */
        known_joint(&c, &m);
        move_to(&m, 0.45);
        (void)feed(&m);
        TEST_ASSERT_EQUAL_INT(J288_OK, j_zero_here(&zero));
        TEST_ASSERT_DOUBLE_WITHIN(CAL_TOL, 0.45, zero);
        c.zero = zero;
        TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
        (void)start_joint(&m);
        TEST_ASSERT_DOUBLE_WITHIN(CAL_TOL, 0.0, j_state().pos);
    }
    /* The zero it gives is always one the configuration takes: within +-64 rad, 64 included;
     * beyond, J288_ERR_RANGE (the encoder out, the rotor followed that far). */
    for (d = -1; d <= 1; d += 2) {
        c = cfg_for(2u);
        c.zero = 60.0 * d;
        c.pos_min = -64.0;
        c.pos_max = 64.0;
        m = servo_at(62.0 * d, 0.3);
        TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
        (void)start_joint(&m);
        r = reply_of(&m, 2u);
        r.faults = FAULT12;
        r.pos =
            (int32_t)((uint32_t)r.pos + (uint32_t)(d * (int32_t)llround(1.999 * NR / ROTOR_LSB)));
        TEST_ASSERT_EQUAL_INT(J288_OK, j_take(&r, NULL)); /* 63.999 rad from zero 0 */
        zero = 99.0;
        TEST_ASSERT_EQUAL_INT(J288_OK, j_zero_here(&zero));
        TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, 63.999 * d, zero);
        r.pos =
            (int32_t)((uint32_t)r.pos + (uint32_t)(d * (int32_t)llround(0.01 * NR / ROTOR_LSB)));
        TEST_ASSERT_EQUAL_INT(J288_OK, j_take(&r, NULL));
        zero = 99.0;
        TEST_ASSERT_EQUAL_INT(J288_ERR_RANGE, j_zero_here(&zero));
        TEST_ASSERT_EQUAL_DOUBLE(99.0, zero);
    }
}

/* ---- the deviations the two layers had (issue 28), one rule each now */

/* Replies of a joint at rest on the boundary between OutPos 4095 and 4096: alternating counts,
 * averaging exactly pi. */
static void feed_at_pi(int n)
{
    model_t m = servo_at(PI, 0.0);
    int i;
    for (i = 0; i < n; i++) {
        j288_reply_raw_t r = reply_of(&m, j_core()->cfg.id);
        r.out_pos = (i & 1) ? 4096u : 4095u;
        TEST_ASSERT_EQUAL_INT(J288_OK, j_take(&r, NULL));
    }
}

static void test_one_rule_for_pi(void)
{
    jcfg_t c = cfg_for(1u);
    j288_cmd_raw_t cmd;
    jtarget_t t;

    /* The pi tie: an all-zero configuration averaging exactly pi is labelled -pi (the wrap is
     * to the Q24 angles within [-pi, pi]; pi rounds above it). */
    TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
    feed_at_pi(8);
    TEST_ASSERT_TRUE(j_state().known);
    TEST_ASSERT_DOUBLE_WITHIN(2.0 / Q24 + EPS, -PI, j_state().pos);
    TEST_ASSERT_TRUE(rad(j_core()->st.pos) > -PI);
    TEST_ASSERT_FALSE(j_state().beyond_limit);
    /* The same rule with zero 1 and range [-2, 0] (middle -1): the middle minus pi. */
    c.zero = 1.0;
    c.pos_min = -2.0;
    c.pos_max = 0.0;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
    feed_at_pi(8);
    TEST_ASSERT_DOUBLE_WITHIN(2.0 / Q24 + EPS, -1.0 - PI, j_state().pos);
    /* The default range is [-pi, pi] as a configured one (pi as the API's number holds it:
     * J288_JOINTQ_PI in the core and from a double; a float's pi is 0.6 Q24 step above):
     * pi itself is taken, a target 2 Q24 steps beyond it is refused. */
    c = cfg_for(1u);
    c.kp = 5.0;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
    TEST_ASSERT_EQUAL_INT64((api == API_CORE) ? J288_JOINTQ_PI : q24(PI), j_core()->cfg.pos_max);
    TEST_ASSERT_EQUAL_INT64((api == API_CORE) ? -J288_JOINTQ_PI : -q24(PI), j_core()->cfg.pos_min);
    c.pos_min = -PI;
    c.pos_max = PI;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
    TEST_ASSERT_EQUAL_INT64(q24(PI), j_core()->cfg.pos_max);
    TEST_ASSERT_EQUAL_INT64(-q24(PI), j_core()->cfg.pos_min);
    feed_at_pi(8);
    t = j_target_init();
    t.pos = PI;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&t, &cmd, NULL));
    t.pos = -PI;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&t, &cmd, NULL));
    t.pos = PI + 2.0 / Q24 + 2.0 * EPS;
    TEST_ASSERT_EQUAL_INT(J288_ERR_LIMIT_POS, j_command(&t, &cmd, NULL));
    t.pos = -PI - 2.0 / Q24 - 2.0 * EPS;
    TEST_ASSERT_EQUAL_INT(J288_ERR_LIMIT_POS, j_command(&t, &cmd, NULL));
    /* Tolerances of exactly pi are taken; above it (as Q24), refused: one bound. */
    c = cfg_for(1u);
    c.track_tol = PI - EPS; /* (a float's pi is above pi) */
    c.cal_tol = PI - EPS;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
    c.cal_tol = PI + 2.0 / Q24 + 2.0 * EPS;
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, j_init(&c));
}

/* Halves away from zero everywhere: kp at exact halves of a LSB (Q16 33258289 is 7812.5 LSB,
 * 99774867 is 23437.5), through either API. */
static void test_halves_away_from_zero(void)
{
    jcfg_t c = cfg_for(1u);
    j288_cmd_raw_t cmd;
    jtarget_t t;
    model_t m;

    known_joint(&c, &m);
    t = j_target_init();
    if (as_real(33258289.0 / Q16) == 33258289.0 / Q16) { /* not in float: 25 bits */
        t.kp = 33258289.0 / Q16;
        TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&t, &cmd, NULL));
        TEST_ASSERT_EQUAL_INT16(7813, cmd.kp);
        t.kp = 99774867.0 / Q16;
        TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&t, &cmd, NULL));
        TEST_ASSERT_EQUAL_INT16(23438, cmd.kp);
    }
    t.kp = 0.0;
    t.torque = -23068.0 / Q16; /* -312.5 LSB */
    TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&t, &cmd, NULL));
    TEST_ASSERT_EQUAL_INT16(-313, cmd.tau);
}

/* ---- continuous joints */

static void test_continuous_start_and_travel(void)
{
    jcfg_t c;
    j288_cmd_raw_t cmd;
    jtarget_t t;
    model_t m;
    unsigned ev;
    int d, i;

    for (d = -1; d <= 1; d += 2) {
        double q0 = 2.0 * TAU + 2.9; /* the model's angle: two turns plus 2.9 rad */
        c = cfg_for(3u);
        c.continuous = true;
        c.direction = (int8_t)d;
        c.zero = 0.5;
        c.kp = 20.0;
        c.kd = 1.0;
        /* Started anywhere, without a turn to choose: within pi of 0. */
        m = servo_at(0.5 + d * q0, 0.8);
        TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
        TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_UNKNOWN) | EVB(ANGLE_KNOWN), start_joint(&m));
        TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, 2.9, j_state().pos);
        /* 1560 rad one way in steps of 1.3 rad (the rotor's int32 count wraps on the way,
         * at 1428 rad), never a limit event, the angle never wrapped. */
        for (i = 1; i <= 1200; i++) {
            move_to(&m, 0.5 + d * (q0 + 1.3 * i));
            ev = feed(&m);
            TEST_ASSERT_EQUAL_HEX(0u, ev);
            TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, q_of(&c, &m) - 2.0 * TAU, j_state().pos);
        }
        TEST_ASSERT_FALSE(j_state().beyond_limit);
        /* Positions relative to it: a target 1 rad on, and one 300 rad off (beyond reach). */
        t = j_target_init();
        TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, 2.9 + 1560.0, t.pos);
        t.pos += 1.0;
        TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&t, &cmd, NULL));
        TEST_ASSERT_INT_WITHIN(3 + (int)(REL * 1600.0 * NR / ROTOR_LSB),
                               (int32_t)((uint32_t)model_pos(&m) +
                                         (uint32_t)(d * (int32_t)llround(NR / ROTOR_LSB))),
                               cmd.pos);
        t.pos += 299.0;
        TEST_ASSERT_EQUAL_INT(J288_ERR_RANGE_POS, j_command(&t, &cmd, NULL));
        t.kp = 0.0; /* a speed target: the position has no effect */
        t.speed = 10.0;
        TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&t, &cmd, NULL));
        TEST_ASSERT_EQUAL_INT32(model_pos(&m), cmd.pos);
        /* And back, the other way, past where it started. */
        for (i = 1199; i >= -400; i--) {
            move_to(&m, 0.5 + d * (q0 + 1.3 * i));
            TEST_ASSERT_EQUAL_HEX(0u, feed(&m));
        }
        TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, 2.9 - 520.0, j_state().pos);
        /* A jump of 1.5e9 LSB between two replies (the anchor moves 8 steps at once). */
        move_to(&m, m.theta - d * 1500000000.0 * ROTOR_LSB / NR);
        TEST_ASSERT_EQUAL_HEX(0u, feed(&m));
        TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, q_of(&c, &m) - 2.0 * TAU, j_state().pos);
    }
}

/* A wheel at 30 rad/s for a day (2.6e6 rad), a reply every 10 s (300 rad: 4.5e8 rotor LSB
 * between replies, the anchor moving 2 or 3 steps at each, the int32 count wrapping every
 * 48 s): the core's angle stays within the start's error of the truth on every reply, the
 * tracking check never trips. */
static void test_continuous_wheel_for_a_day(void)
{
    jcfg_t c = cfg_for(2u);
    model_t m = servo_at(1.0, -1.2);
    const double w = 30.0;
    double worst = 0.0, start_err;
    int s;

    c.continuous = true;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
    (void)start_joint(&m);
    start_err = rad(j_core()->st.pos) - q_of(&c, &m);
    TEST_ASSERT_TRUE(fabs(start_err) <= UNCAL_TOL);
    for (s = 10; s <= 86400; s += 10) {
        j288_reply_raw_t r;
        unsigned ev = 1u;
        double e;
        move_to(&m, 1.0 + w * s);
        r = reply_of(&m, 2u);
        r.speed = (int16_t)lround(w * NR * 2.56 / TAU);
        TEST_ASSERT_EQUAL_INT(J288_OK, j_take(&r, &ev));
        TEST_ASSERT_EQUAL_HEX(0u, ev);
        /* exact: the start's error, the rotor's LSB and 2 Q24 steps, however far */
        e = rad(j_core()->st.pos) - q_of(&c, &m) - start_err;
        worst = (fabs(e) > worst) ? fabs(e) : worst;
    }
    TEST_ASSERT_TRUE(j_state().known);
    TEST_ASSERT_TRUE(worst <= 2.0 * ROTOR_RES + 3.0 / Q24);
    TEST_ASSERT_EQUAL_DOUBLE(2592001.0, m.theta);
#if J288_CONFIG_SI
    if (api == API_FACADE) { /* the float type's own resolution: 2^-24 of the angle in float */
        TEST_ASSERT_DOUBLE_WITHIN(j_state().pos * (sizeof(j288_real_t) < 8 ? 1e-7 : 1e-15),
                                  rad(j_core()->st.pos), j_state().pos);
    }
#endif
    print_value("a wheel at 30 rad/s for a day, angle vs the truth beyond the start's", worst * 1e9,
                " nrad");
}

/* ---- soft limits in every mode: the limit law (docs/joint.md) */

/* The limit law's command for limit x, joint at rest anywhere: what jointq.h says it is. */
static void assert_limit_law(const j288_cmd_raw_t *cmd, double x, double kd_l, const model_t *m,
                             const jcfg_t *c)
{
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_FOC, cmd->status);
    TEST_ASSERT_EQUAL_INT16(0, cmd->tau);
    TEST_ASSERT_EQUAL_INT16(0, cmd->speed);
    TEST_ASSERT_INT_WITHIN(1, (int)lround(kd_l / (NR * NR) * 128000000.0), cmd->kd);
    TEST_ASSERT_INT_WITHIN(1, (int)lround(kd_l * J288_JOINTQ_LIMIT_RATE / (NR * NR) * 1280000.0),
                           cmd->kp);
    TEST_ASSERT_DOUBLE_WITHIN(0.5 * COUNT * NR / ROTOR_LSB + 2.0, rotor_lsb_for(c, m, x),
                              (double)cmd->pos);
}

static void set_speed(model_t *m, double w, const jcfg_t *c)
{
    j288_reply_raw_t r = reply_of(m, c->id);
    r.speed = (int16_t)lround((double)c->direction * w * NR * 2.56 / TAU);
    TEST_ASSERT_EQUAL_INT(J288_OK, j_take(&r, NULL));
}

static void test_limit_law(void)
{
    const double kd_floor = (double)J288_JOINTQ_LIMIT_KD / Q16;
    jcfg_t c;
    j288_cmd_raw_t cmd, plain;
    jtarget_t t;
    model_t m;
    unsigned mask;
    int d;

    for (d = -1; d <= 1; d += 2) {
        c = cfg_for(6u);
        c.direction = (int8_t)d;
        c.pos_min = -0.5;
        c.pos_max = 1.0;
        c.kp = 30.0;
        c.kd = 0.5;
        known_joint(&c, &m);
        /* A position target inside, feed-forward below its spring: never shaped. */
        t = j_target_init();
        t.pos = 0.99;
        t.torque = 0.2; /* 30 N*m/rad * 0.01 rad = 0.3 N*m at the limit */
        move_to(&m, as_real(c.zero) + d * 0.999);
        set_speed(&m, 2.0, &c);
        mask = 99u;
        TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&t, &cmd, &mask));
        TEST_ASSERT_EQUAL_UINT(0u, mask);
        /* A speed target toward the top (kp 0, kd 1, 1 rad/s): sent as it is far away... */
        t.kp = 0.0;
        t.kd = 1.0;
        t.speed = 1.0;
        t.torque = 0.0;
        move_to(&m, as_real(c.zero) + d * 0.0);
        set_speed(&m, 1.0, &c);
        TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&t, &plain, &mask));
        TEST_ASSERT_EQUAL_UINT(0u, mask);
        TEST_ASSERT_INT_WITHIN(1, (int)lround(d * NR * 2.56 / TAU), plain.speed);
        /* ... and the limit law near the limit, where its push toward it is the smaller:
         * kd_L = max(1, 0.5, floor). */
        move_to(&m, as_real(c.zero) + d * 0.99);
        set_speed(&m, 1.0, &c);
        TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&t, &cmd, &mask));
        TEST_ASSERT_EQUAL_UINT(J288_JOINT_LIMITED, mask);
        assert_limit_law(&cmd, 1.0, fmax(1.0, kd_floor), &m, &c);
        /* Beyond the top: a speed back toward the range is sent as it is; one further out,
         * or a torque out, gets the limit law; a torque back as it is. */
        move_to(&m, as_real(c.zero) + d * 1.3);
        set_speed(&m, 0.0, &c);
        t.speed = -0.2;
        TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&t, &cmd, &mask));
        TEST_ASSERT_EQUAL_UINT(0u, mask);
        t.speed = 0.2;
        TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&t, &cmd, &mask));
        TEST_ASSERT_EQUAL_UINT(J288_JOINT_LIMITED, mask);
        assert_limit_law(&cmd, 1.0, fmax(1.0, kd_floor), &m, &c);
        t.speed = 0.0;
        t.kd = 0.0;
        t.torque = 3.0;
        TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&t, &cmd, &mask));
        TEST_ASSERT_EQUAL_UINT(J288_JOINT_LIMITED, mask);
        assert_limit_law(&cmd, 1.0, fmax(0.5, kd_floor), &m, &c); /* the joint's kd 0.5 */
        t.torque = -3.0;
        TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&t, &cmd, &mask));
        TEST_ASSERT_EQUAL_UINT(0u, mask);
        /* The bottom likewise: a torque down near it, moving down fast. */
        move_to(&m, as_real(c.zero) + d * -0.45);
        set_speed(&m, -3.0, &c);
        t.torque = -1.0;
        TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&t, &cmd, &mask));
        TEST_ASSERT_EQUAL_UINT(J288_JOINT_LIMITED, mask);
        assert_limit_law(&cmd, -0.5, fmax(0.5, kd_floor), &m, &c);
        /* A position target with a big damping and a speed toward the bottom: kd_L is it. */
        t = j_target_init();
        t.pos = -0.4;
        t.kd = 4.0;
        t.speed = -2.0;
        TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&t, &cmd, &mask));
        TEST_ASSERT_EQUAL_UINT(J288_JOINT_LIMITED, mask);
        assert_limit_law(&cmd, -0.5, 4.0, &m, &c);
        /* Clamp mode reports both. */
        c.clamp = true;
        c.max_speed = 1.0;
        known_joint(&c, &m);
        move_to(&m, as_real(c.zero) + d * 0.99);
        set_speed(&m, 1.0, &c);
        t = j_target_init();
        t.kp = 0.0;
        t.kd = 1.0;
        t.speed = 2.0;
        TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&t, &cmd, &mask));
        TEST_ASSERT_EQUAL_UINT(J288_JOINT_LIMITED | J288_FIELD_SPEED, mask);
    }
    /* A continuous joint: no limit, nothing shaped. */
    c = cfg_for(6u);
    c.continuous = true;
    known_joint(&c, &m);
    move_to(&m, 1000.0);
    set_speed(&m, 20.0, &c);
    t = j_target_init();
    t.kd = 1.0;
    t.speed = 20.0;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&t, &cmd, &mask));
    TEST_ASSERT_EQUAL_UINT(0u, mask);
    /* The limit law's rotor target beyond the wire's int32: refused (J288_ERR_RANGE_POS). */
    c = cfg_for(6u);
    c.pos_min = -0.5;
    c.pos_max = 1.0;
    m = servo_at(0.95, 0.1);
    TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
    for (d = 0; d < 8; d++) {
        j288_reply_raw_t r = reply_of(&m, 6u);
        r.pos = INT32_MAX - 1000;
        r.speed = 300;
        TEST_ASSERT_EQUAL_INT(J288_OK, j_take(&r, NULL));
    }
    t = j_target_init();
    t.kp = 0.0;
    t.kd = 1.0;
    t.speed = 1.0;
    TEST_ASSERT_EQUAL_INT(J288_ERR_RANGE_POS, j_command(&t, &cmd, &mask));
}

/* ---- the binding, through a real scheduler on the fake port */

#define US 1000u
#define JID 4u

static fake_port_t fp;
static j288_bus_t bus;
static j288_sched_t sch;
static j288_jointq_bus_t qb;
#if J288_CONFIG_SI
static j288_joint_bus_t fb;
#endif

typedef struct {
    j288_joint_event_kind_t kind;
    uint8_t id;
    bool ours; /* the event's joint is the one under test */
    double value;
} jev_t;

static jev_t jev[32];
static int njev;

static void record(void *user, j288_joint_event_kind_t kind, uint8_t id, bool ours, double value)
{
    TEST_ASSERT_EQUAL_PTR(&fp, user);
    if (njev < 32) {
        jev[njev].kind = kind;
        jev[njev].id = id;
        jev[njev].ours = ours;
        jev[njev].value = value;
    }
    njev++;
}

static void on_qevent(void *user, const j288_jointq_event_t *ev)
{
    record(user, ev->kind, ev->id, ev->joint == &qj, rad(ev->value));
}

#if J288_CONFIG_SI
static void on_fevent(void *user, const j288_joint_event_t *ev)
{
    record(user, ev->kind, ev->id, ev->joint == &fj, (double)ev->value);
}
#endif

static int jb_init(bool with_events)
{
#if J288_CONFIG_SI
    if (api == API_FACADE) {
        return j288_joint_bus_init(&fb, &sch, with_events ? on_fevent : NULL, &fp);
    }
#endif
    return j288_jointq_bus_init(&qb, &sch, with_events ? on_qevent : NULL, &fp);
}

static int jb_add(bool other)
{
#if J288_CONFIG_SI
    if (api == API_FACADE) {
        return j288_joint_bus_add(&fb, other ? &fother : &fj);
    }
#endif
    return j288_jointq_bus_add(&qb, other ? &qother : &qj);
}

static int jb_set_target(const jtarget_t *t, bool other)
{
#if J288_CONFIG_SI
    if (api == API_FACADE) {
        j288_joint_target_t f = ftarget_of(t);
        return j288_joint_bus_set_target(&fb, other ? &fother : &fj, &f, NULL);
    }
#endif
    {
        j288_jointq_target_t q = qtarget_of(t);
        return j288_jointq_bus_set_target(&qb, other ? &qother : &qj, &q, NULL);
    }
}

static int jb_lock(bool other)
{
#if J288_CONFIG_SI
    if (api == API_FACADE) {
        return j288_joint_bus_lock(&fb, other ? &fother : &fj);
    }
#endif
    return j288_jointq_bus_lock(&qb, other ? &qother : &qj);
}

static void jb_hook(uint8_t id, const j288_slot_t *slot)
{
#if J288_CONFIG_SI
    if (api == API_FACADE) {
        j288_joint_bus_on_reply(&fb, id, slot);
        return;
    }
#endif
    j288_jointq_bus_on_reply(&qb, id, slot);
}

static void sweep_with(const j288_reply_raw_t *r)
{
    fp.servo[JID].reply.pos = r->pos;
    fp.servo[JID].reply.out_pos = r->out_pos;
    fp.servo[JID].reply.speed = r->speed;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_start_sweep(&sch, fake_port_now_us(&fp)));
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, fp.now_ns + 20000u * US));
}

static void sweep(const model_t *m)
{
    j288_reply_raw_t r = reply_of(m, JID);
    sweep_with(&r);
}

static j288_cmd_raw_t last_frame(void)
{
    j288_cmd_raw_t c;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_cmd_decode(fp.last.data, &c, NULL));
    return c;
}

static const j288_cmd_raw_t *slot_cmd(void)
{
    return &j288_sched_slot(&sch, JID)->cmd;
}

static void bound_setup(jcfg_t *c, model_t *m)
{
    j288_sched_config_t sc;
    j288_reply_raw_t r;

    *m = servo_at(-0.8, 0.6);
    *c = cfg_for(JID);
    c->init_samples = 3u;
    c->kp = 10.0;
    memset(&sc, 0, sizeof sc);
#if J288_CONFIG_SI
    sc.on_reply = (api == API_FACADE) ? j288_joint_bus_on_reply : j288_jointq_bus_on_reply;
    sc.user = (api == API_FACADE) ? (void *)&fb : (void *)&qb;
#else
    sc.on_reply = j288_jointq_bus_on_reply;
    sc.user = &qb;
#endif
    njev = 0;
    fake_port_init(&fp);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_init(&bus, &fp.ops, &fp, NULL));
    fake_port_attach(&fp, &bus);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_init(&sch, &bus, &sc));
    fp.poll_fn = fake_port_poll_sched;
    fp.poll_user = &sch;
    r = reply_of(m, JID);
    fake_port_add_servo(&fp, JID, &r);
    TEST_ASSERT_EQUAL_INT(J288_OK, j_init(c));
    TEST_ASSERT_EQUAL_INT(J288_OK, jb_init(true));
}

static void test_binding_locks_until_known_and_after_a_loss(void)
{
    jcfg_t c;
    jtarget_t t;
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
    TEST_ASSERT_EQUAL_INT(J288_OK, jb_add(false));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_enable(&sch, JID, true));
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_LOCK, slot_cmd()->status);
    sweep(&m);
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_LOCK, last_frame().status);
    TEST_ASSERT_EQUAL_INT(1, njev);
    TEST_ASSERT_EQUAL_INT(J288_JOINT_EV_ANGLE_UNKNOWN, jev[0].kind);
    TEST_ASSERT_EQUAL_UINT8(JID, jev[0].id);
    TEST_ASSERT_TRUE(jev[0].ours);
    TEST_ASSERT_EQUAL_INT(J288_ERR_ANGLE_UNKNOWN, jb_set_target(&t, false));
    /* A FOC command slipped in directly while unknown goes out once, then lock again. */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_set_cmd(&sch, &foc));
    sweep(&m);
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_FOC, last_frame().status);
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_LOCK, slot_cmd()->status);
    sweep(&m);
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_LOCK, last_frame().status);
    TEST_ASSERT_EQUAL_INT(2, njev);
    TEST_ASSERT_EQUAL_INT(J288_JOINT_EV_ANGLE_KNOWN, jev[1].kind);
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, -0.8, jev[1].value);
    /* Known: targets go out in the rotor frame. */
    t = j_target_init();
    t.pos = -0.7;
    TEST_ASSERT_EQUAL_INT(J288_OK, jb_set_target(&t, false));
    TEST_ASSERT_EQUAL_INT(J288_OK, j_command(&t, &want, NULL));
    sweep(&m);
    assert_same_cmd(&want, slot_cmd());
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
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_LOCK, slot_cmd()->status);
    TEST_ASSERT_TRUE(slot_cmd()->watchdog);
    TEST_ASSERT_EQUAL_INT(J288_ERR_ANGLE_UNKNOWN, jb_set_target(&t, false));
    for (i = 0; i < 3; i++) {
        sweep(&m);
        TEST_ASSERT_EQUAL_UINT8(J288_MODE_LOCK, last_frame().status);
    }
    TEST_ASSERT_EQUAL_INT(4, njev);
    TEST_ASSERT_EQUAL_INT(J288_JOINT_EV_ANGLE_KNOWN, jev[3].kind);
    TEST_ASSERT_DOUBLE_WITHIN(UNCAL_TOL, -0.7, j_state().pos);
    /* In the new frame the same target is another rotor position. */
    TEST_ASSERT_EQUAL_INT(J288_OK, jb_set_target(&t, false));
    sweep(&m);
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_FOC, last_frame().status);
    TEST_ASSERT_INT_WITHIN(2000, want.pos - 40 * 32768, last_frame().pos);
    /* Lock on request. */
    TEST_ASSERT_EQUAL_INT(J288_OK, jb_lock(false));
    sweep(&m);
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_LOCK, last_frame().status);
    TEST_ASSERT_EQUAL_INT(4, njev);
}

static void test_binding_events_order_and_values(void)
{
    jcfg_t c;
    jtarget_t t;
    model_t m;

    bound_setup(&c, &m);
    c.pos_min = 0.0;
    c.pos_max = 1.0;
    c.init_samples = 1u;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
    TEST_ASSERT_EQUAL_INT(J288_OK, jb_add(false));
    TEST_ASSERT_EQUAL_INT(J288_OK, jb_add(false)); /* again: fine */
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
    c.phase = wrap(m.c + 2.0);
    TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
    sweep(&m);
    TEST_ASSERT_EQUAL_INT(8, njev);
    TEST_ASSERT_EQUAL_INT(J288_JOINT_EV_ANGLE_UNKNOWN, jev[6].kind);
    TEST_ASSERT_EQUAL_INT(J288_JOINT_EV_CAL_MISMATCH, jev[7].kind);
    TEST_ASSERT_DOUBLE_WITHIN(0.12, 2.0, jev[7].value);
    memset(&t, 0, sizeof t);
    TEST_ASSERT_EQUAL_INT(J288_ERR_CAL_MISMATCH, jb_set_target(&t, false));
    /* No event callback: nothing is reported, the lock is still kept. */
    TEST_ASSERT_EQUAL_INT(J288_OK, jb_init(false));
    TEST_ASSERT_EQUAL_INT(J288_OK, jb_add(false));
    j_reset(); /* (an event to report) */
    sweep(&m);
    TEST_ASSERT_EQUAL_INT(8, njev);
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_LOCK, slot_cmd()->status);
}

static void test_binding_argument_checks(void)
{
    jcfg_t c;
    jtarget_t t;
    j288_slot_t slot;
    model_t m;

    bound_setup(&c, &m);
    memset(&t, 0, sizeof t);
    TEST_ASSERT_EQUAL_INT(J288_OK, jb_add(false));
    TEST_ASSERT_EQUAL_INT(J288_OK, j_init_one(&c, true));
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, jb_add(true)); /* same id */
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_ARG, jb_set_target(&t, true));
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_ARG, jb_lock(true));
    /* The hook ignores what is not for a bound joint, and replies from another id. */
    memset(&slot, 0, sizeof slot);
    slot.reply = reply_of(&m, JID);
    slot.cmd.status = J288_MODE_FOC;
    snapshot(before_buf, sizeof before_buf);
    jb_hook(JID, NULL);
    jb_hook(15u, &slot);
    jb_hook(3u, &slot);
    slot.reply.id = 5u;
    jb_hook(JID, &slot);
    snapshot(after_buf, sizeof after_buf);
    TEST_ASSERT_EQUAL_MEMORY(before_buf, after_buf, sizeof before_buf);
    TEST_ASSERT_EQUAL_INT(0, njev);
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_LOCK, slot_cmd()->status);
    slot.reply.id = JID;
    jb_hook(JID, &slot); /* now it is taken */
    TEST_ASSERT_EQUAL_INT(1, njev);
}

/* A speed target set once through the binding: its command is made again from the joint's
 * state on every reply, so it turns into the limit law as the joint nears the limit; a lock,
 * a command put in the slot otherwise, a loss or a failing remake end it. */
static void test_binding_remakes_targets_toward_a_limit(void)
{
    jcfg_t c;
    jtarget_t t;
    j288_cmd_raw_t foc;
    j288_reply_raw_t r;
    model_t m;
    int i;

    bound_setup(&c, &m);
    c.pos_min = -1.0;
    c.pos_max = 0.0;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
    TEST_ASSERT_EQUAL_INT(J288_OK, jb_add(false));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_enable(&sch, JID, true));
    for (i = 0; i < 3; i++) {
        sweep(&m);
    }
    TEST_ASSERT_TRUE(j_state().known);
    t = j_target_init();
    t.kp = 0.0;
    t.kd = 1.0;
    t.speed = 1.0;
    TEST_ASSERT_EQUAL_INT(J288_OK, jb_set_target(&t, false));
    sweep(&m);
    TEST_ASSERT_EQUAL_INT16(0, last_frame().kp); /* the speed target itself */
    TEST_ASSERT_TRUE(last_frame().speed > 0);
    for (i = 1; i <= 8; i++) {
        move_to(&m, -0.8 + 0.1 * i);
        r = reply_of(&m, JID);
        r.speed = (int16_t)lround(NR * 2.56 / TAU);
        sweep_with(&r);
    }
    TEST_ASSERT_TRUE(last_frame().kp > 0); /* the limit law, made from the replies */
    TEST_ASSERT_EQUAL_INT16(0, last_frame().speed);
    /* A lock ends it. */
    TEST_ASSERT_EQUAL_INT(J288_OK, jb_lock(false));
    sweep_with(&r);
    sweep_with(&r);
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_LOCK, last_frame().status);
    /* So does a command put in the slot by anyone else (an emergency stop's lock, ...). */
    TEST_ASSERT_EQUAL_INT(J288_OK, jb_set_target(&t, false));
    memset(&foc, 0, sizeof foc);
    foc.id = JID;
    foc.status = J288_MODE_FOC;
    foc.kd = 77;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_set_cmd(&sch, &foc));
    sweep_with(&r);
    sweep_with(&r);
    TEST_ASSERT_EQUAL_INT16(77, last_frame().kd);
    TEST_ASSERT_EQUAL_INT16(77, slot_cmd()->kd);
    /* And a loss (lock, then a fresh start); the target is not taken up again after it. */
    TEST_ASSERT_EQUAL_INT(J288_OK, jb_set_target(&t, false));
    m.k += 40.0;
    sweep(&m);
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_LOCK, slot_cmd()->status);
    for (i = 0; i < 4; i++) {
        sweep(&m);
    }
    TEST_ASSERT_TRUE(j_state().known);
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_LOCK, slot_cmd()->status);
    /* A remake that fails (the limit's rotor target beyond int32 from there): lock. */
    TEST_ASSERT_EQUAL_INT(J288_OK, jb_set_target(&t, false));
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_FOC, slot_cmd()->status);
    r = reply_of(&m, JID);
    r.faults = FAULT12; /* the encoder out: the rotor alone, which jumps near int32's end */
    r.pos = (int32_t)((uint32_t)r.pos + 2147000000u);
    fp.servo[JID].reply.faults = FAULT12;
    sweep_with(&r);
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_LOCK, slot_cmd()->status);
    /* A position target needs no remaking: kept as it is. */
    fp.servo[JID].reply.faults = 0u;
    j_reset();
    for (i = 0; i < 4; i++) {
        sweep(&m);
    }
    t = j_target_init();
    TEST_ASSERT_EQUAL_INT(J288_OK, jb_set_target(&t, false));
    foc = *slot_cmd();
    sweep(&m);
    assert_same_cmd(&foc, slot_cmd());
}

/* ---- the core alone: constants, conversions, integer edges */

static void test_core_constants_and_macros(void)
{
    TEST_ASSERT_EQUAL_INT64(llround(PI * Q24), J288_JOINTQ_PI);
    TEST_ASSERT_EQUAL_INT64(llround(TAU * Q24), J288_JOINTQ_TWO_PI);
    TEST_ASSERT_EQUAL_INT64(1, J288_JOINTQ_TWO_PI % 2); /* odd: the wrap has no tie */
    TEST_ASSERT_EQUAL_INT64(64 * 16777216LL, J288_JOINTQ_MAX_ANGLE);
    TEST_ASSERT_EQUAL_INT64(llround(0.010 * Q24), J288_JOINTQ_DEFAULT_TRACK_TOL);
    TEST_ASSERT_EQUAL_INT64(llround(1.0 * Q24), J288_JOINTQ_DEFAULT_CAL_TOL);
    TEST_ASSERT_EQUAL_INT64(llround(0.001 * Q24), J288_JOINTQ_LIMIT_HYST);
    TEST_ASSERT_EQUAL_INT64(llround(0.05 * Q24), J288_JOINTQ_HOLD_BEYOND);
    TEST_ASSERT_EQUAL_INT64(llround(-1.5 * Q24), J288_Q24(-1.5));
    TEST_ASSERT_EQUAL_INT32(llround(20.25 * Q16), J288_Q16(20.25));
    /* The macros' range is checked: defined for every input, saturated beyond. */
    TEST_ASSERT_EQUAL_INT64(2147483648LL, J288_Q24(127.99999997019768)); /* int32 overflowed */
    TEST_ASSERT_EQUAL_INT64(llround(2.6e6 * Q24), J288_Q24(2.6e6));
    TEST_ASSERT_EQUAL_INT64(INT64_MAX, J288_Q24(549755813888.0));
    TEST_ASSERT_EQUAL_INT64(INT64_MIN, J288_Q24(-1e300));
    TEST_ASSERT_EQUAL_INT64(INT64_MAX, J288_Q24(NAN));
    TEST_ASSERT_EQUAL_INT32(INT32_MAX, J288_Q16(32768.0));
    TEST_ASSERT_EQUAL_INT32(INT32_MIN, J288_Q16(-40000.0));
    TEST_ASSERT_EQUAL_INT32(INT32_MAX, J288_Q16(NAN));
    TEST_ASSERT_EQUAL_INT32(llround(32767.99 * Q16), J288_Q16(32767.99));
    /* NULL everywhere. */
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_init(NULL, &(j288_jointq_config_t){0}));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_init(&qj, NULL));
    TEST_ASSERT_NULL(j288_jointq_state(NULL));
    TEST_ASSERT_NULL(j288_jointq_config(NULL));
    j288_jointq_reset(NULL);
    j288_jointq_target_init(NULL, NULL);
    j288_jointq_target_init(&qj, NULL);
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL,
                          j288_jointq_take_reply(NULL, &(j288_reply_raw_t){0}, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_command(NULL, &(j288_jointq_target_t){0},
                                                             &(j288_cmd_raw_t){0}, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL,
                          j288_jointq_command(&qj, NULL, &(j288_cmd_raw_t){0}, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL,
                          j288_jointq_command(&qj, &(j288_jointq_target_t){0}, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_lock_command(NULL, &(j288_cmd_raw_t){0}));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_lock_command(&qj, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_zero_here(NULL, &(j288_q24_t){0}));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_zero_here(&qj, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_bus_init(NULL, &sch, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_bus_init(&qb, NULL, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_bus_add(NULL, &qj));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_bus_add(&qb, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_bus_set_target(NULL, &qj, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_bus_set_target(&qb, NULL, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_bus_lock(NULL, &qj));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_jointq_bus_lock(&qb, NULL));
    j288_jointq_bus_on_reply(NULL, JID, NULL); /* ignored */
    qother.cfg.id = 15u; /* a joint never initialised right is not bound anywhere */
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_ARG, j288_jointq_bus_lock(&qb, &qother));
}

static void test_core_golden_commands(void)
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
        q.tau = (j288_q16_t)g->q[0];
        q.speed = (j288_q16_t)g->q[1];
        q.pos = g->q[2];
        q.kp = (j288_q16_t)g->q[3];
        q.kd = (j288_q16_t)g->q[4];
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
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_cmd_from_q_clamped(&(j288_cmd_q_t){0},
                                                           &(j288_cmd_raw_t){0}, NULL));
}

/* Speed and the encoder angle within one step of the exact value (the documented bound),
 * torque exact. */
static void test_core_golden_replies(void)
{
    unsigned i;
    int32_t raw;
    for (i = 0u; i < GOLDEN_FIXED_REPLY_COUNT; i++) {
        const golden_fixed_reply_t *g = &golden_fixed_replies[i];
        TEST_ASSERT_INT32_WITHIN(1, g->speed, j288_speed_to_q(g->speed_raw));
        TEST_ASSERT_EQUAL_INT32(g->torque, j288_torque_to_q(g->torque_raw));
        TEST_ASSERT_INT64_WITHIN(1, g->encoder, j288_out_pos_to_q(g->out_pos));
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
    TEST_ASSERT_EQUAL_INT64(j288_out_pos_to_q(5u), j288_out_pos_to_q(8192u + 5u));
}

/* The turn choice at a hair more than a half turn from the range's middle, both ways; the
 * anchor's step count at its end. */
static void test_core_integer_edges(void)
{
    j288_jointq_config_t c;
    model_t m = servo_at(0.3, 0.7);
    j288_q24_t enc = j288_out_pos_to_q(model_count(&m));
    j288_reply_raw_t r;
    int sign;

    for (sign = -1; sign <= 1; sign += 2) {
        /* zero a hair more than pi from the encoder angle: q = -+(pi + 100 steps) labels as
         * +-(pi - 100 steps) within the default range's middle */
        memset(&c, 0, sizeof c);
        c.id = 5u;
        c.zero = enc - sign * (J288_JOINTQ_PI + 100);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_init(&qj, &c));
        api = API_CORE;
        (void)start_joint(&m);
        TEST_ASSERT_INT64_WITHIN(1, -sign * (J288_JOINTQ_TWO_PI - J288_JOINTQ_PI - 100),
                                 j288_jointq_state(&qj)->pos);
    }
    /* zero_here's range: +-64 rad included (-128 rad was refused before), beyond refused. */
    for (sign = -1; sign <= 1; sign += 2) {
        j288_q24_t z = 0;
        qj.cfg.zero = 0;
        qj.cfg.direction = (int8_t)sign;
        qj.st.pos = sign * (j288_q24_t)J288_JOINTQ_MAX_ANGLE;
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_zero_here(&qj, &z));
        TEST_ASSERT_EQUAL_INT64(J288_JOINTQ_MAX_ANGLE, z);
        qj.cfg.zero = -2 * (j288_q24_t)J288_JOINTQ_MAX_ANGLE;
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_zero_here(&qj, &z));
        TEST_ASSERT_EQUAL_INT64(-J288_JOINTQ_MAX_ANGLE, z);
        qj.st.pos += sign;
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_zero_here(&qj, &z));
        qj.cfg.zero = 0;
        TEST_ASSERT_EQUAL_INT(J288_ERR_RANGE, j288_jointq_zero_here(&qj, &z));
    }
    /* A reply half a turn off the encoder: a residual at the wrap's edge, a loss. */
    for (sign = -1; sign <= 1; sign += 2) {
        memset(&c, 0, sizeof c);
        c.id = 5u;
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_init(&qj, &c));
        m = servo_at(0.3, 0.7);
        (void)start_joint(&m);
        r = reply_of(&m, 5u);
        r.out_pos = (uint16_t)((r.out_pos + (sign > 0 ? 4096u : 4097u)) & 8191u);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_take_reply(&qj, &r, NULL));
        TEST_ASSERT_FALSE(j288_jointq_state(&qj)->known);
        TEST_ASSERT_INT64_WITHIN(2 * 6434, J288_JOINTQ_PI,
                                 (j288_jointq_state(&qj)->residual < 0 ? -1 : 1) *
                                     j288_jointq_state(&qj)->residual);
    }
    /* The anchor's step count saturates (at 2.7e11 rad) rather than overflow. */
    memset(&c, 0, sizeof c);
    c.id = 5u;
    c.continuous = true;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_init(&qj, &c));
    (void)start_joint(&m);
    r = reply_of(&m, 5u);
    r.faults = FAULT12;
    qj.turns = INT32_MAX;
    r.pos = (int32_t)((uint32_t)qj.ref_pos + 200000000u);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_take_reply(&qj, &r, NULL));
    TEST_ASSERT_EQUAL_INT32(INT32_MAX, qj.turns);
    TEST_ASSERT_TRUE(j288_jointq_state(&qj)->pos > 0x7FFFFFFF00000000LL / 256);
    qj.turns = -INT32_MAX;
    r.pos = (int32_t)((uint32_t)qj.ref_pos - 200000000u);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_take_reply(&qj, &r, NULL));
    TEST_ASSERT_EQUAL_INT32(-INT32_MAX, qj.turns);
    TEST_ASSERT_TRUE(j288_jointq_state(&qj)->pos < -(0x7FFFFFFF00000000LL / 256));
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

#if J288_CONFIG_SI
/* ---- the facade alone: its edge, and its results against the core's */

static void test_facade_edge(void)
{
    static const double bad[] = {NAN, INFINITY, -INFINITY};
    j288_joint_config_t fc;
    j288_joint_target_t t, good;
    j288_cmd_raw_t cmd, ref;
    j288_jointq_target_t q;
    jcfg_t c = limited_cfg(false);
    model_t m;
    unsigned mask;
    size_t i;
    int f;

    api = API_FACADE;
    /* Not finite in the configuration: refused, whatever field. */
    for (f = 0; f < 10; f++) {
        for (i = 0; i < 3; i++) {
            j288_real_t *field[10];
            fc = fcfg_of(&c);
            field[0] = &fc.zero, field[1] = &fc.pos_min, field[2] = &fc.pos_max;
            field[3] = &fc.max_speed, field[4] = &fc.max_torque, field[5] = &fc.kp;
            field[6] = &fc.kd, field[7] = &fc.phase, field[8] = &fc.track_tol;
            field[9] = &fc.cal_tol;
            *field[f] = (j288_real_t)bad[i];
            TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, j288_joint_init(&fj, &fc));
        }
    }
    /* Finite but beyond the core's range: saturated (a limit beyond the wire's). */
    fc = fcfg_of(&c);
    fc.max_speed = (j288_real_t)1e30;
    fc.max_torque = (j288_real_t)-1e30;
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, j288_joint_init(&fj, &fc)); /* negative */
    fc.max_torque = (j288_real_t)1e30;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&fj, &fc));
    TEST_ASSERT_EQUAL_INT32(INT32_MAX, fj.core.cfg.max_speed);
    c.kp = 20.0;
    known_joint(&c, &m);
    j288_joint_target_init(&fj, &good);
    /* NaN first, before anything else but NULL (even an unknown angle). */
    for (f = 0; f < 5; f++) {
        j288_real_t *field[5];
        t = good;
        field[0] = &t.pos, field[1] = &t.speed, field[2] = &t.torque, field[3] = &t.kp;
        field[4] = &t.kd;
        *field[f] = (j288_real_t)NAN;
        TEST_ASSERT_EQUAL_INT(J288_ERR_NOT_FINITE, j288_joint_command(&fj, &t, &cmd, NULL));
        TEST_ASSERT_EQUAL_INT(J288_ERR_NOT_FINITE, j288_joint_bus_set_target(&fb, &fj, &t, NULL));
    }
    /* Infinities saturate: refused at the limits, or clamped there. */
    t = good;
    t.pos = (j288_real_t)INFINITY;
    TEST_ASSERT_EQUAL_INT(J288_ERR_LIMIT_POS, j288_joint_command(&fj, &t, &cmd, NULL));
    t = good;
    t.torque = (j288_real_t)-INFINITY;
    TEST_ASSERT_EQUAL_INT(J288_ERR_LIMIT_TORQUE, j288_joint_command(&fj, &t, &cmd, NULL));
    c.clamp = true;
    known_joint(&c, &m);
    t = good;
    t.pos = (j288_real_t)-INFINITY;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_command(&fj, &t, &cmd, &mask));
    TEST_ASSERT_EQUAL_UINT(J288_FIELD_POS, mask);
    t.pos = (j288_real_t)-0.5;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_command(&fj, &t, &ref, NULL));
    TEST_ASSERT_EQUAL_INT32(ref.pos, cmd.pos);
    /* Reals round half away from zero at the edge: 0.5 and 1.5 Q24 steps, both signs. */
    c = cfg_for(3u);
    c.continuous = true;
    known_joint(&c, &m);
    j288_joint_target_init(&fj, &t);
    t.kp = (j288_real_t)10.0;
    j288_jointq_target_init(&fj.core, &q);
    q.kp = J288_Q16(10.0);
    for (f = -3; f <= 3; f += 2) {
        double x = (double)f * 0.5 / Q24;
        t.pos = (j288_real_t)x;
        q.pos = (f < 0) ? -(j288_q24_t)((1 - f) / 2) : (j288_q24_t)((1 + f) / 2);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_command(&fj, &t, &cmd, NULL));
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_command(&fj.core, &q, &ref, NULL));
        TEST_ASSERT_EQUAL_INT32(ref.pos, cmd.pos);
    }
    /* Beyond 128 rad (a continuous joint's targets): the same rounding in two words; beyond
     * the core's range, saturated and out of reach. */
    t.pos = (j288_real_t)((2147483648.0 + 0.5) / Q24);
    q.pos = 2147483649LL;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_command(&fj, &t, &cmd, NULL));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_command(&fj.core, &q, &ref, NULL));
    assert_same_cmd(&ref, &cmd);
    t.pos = (j288_real_t)-300.0;
    TEST_ASSERT_EQUAL_INT(J288_ERR_RANGE_POS, j288_joint_command(&fj, &t, &cmd, NULL));
    t.pos = (j288_real_t)-1e30;
    TEST_ASSERT_EQUAL_INT(J288_ERR_RANGE_POS, j288_joint_command(&fj, &t, &cmd, NULL));
    t.pos = (j288_real_t)1e30;
    TEST_ASSERT_EQUAL_INT(J288_ERR_RANGE_POS, j288_joint_command(&fj, &t, &cmd, NULL));
    t.kp = (j288_real_t)1e10; /* a gain beyond Q16: saturated, then beyond the wire */
    t.pos = (j288_real_t)0.0;
    TEST_ASSERT_EQUAL_INT(J288_ERR_RANGE_KP, j288_joint_command(&fj, &t, &cmd, NULL));
    t.kp = (j288_real_t)-1e10;
    TEST_ASSERT_EQUAL_INT(J288_ERR_NEG_GAIN, j288_joint_command(&fj, &t, &cmd, NULL));
    /* NULL. */
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_init(NULL, &fc));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_init(&fj, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_take_reply(NULL, &(j288_reply_raw_t){0}, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_command(NULL, &t, &cmd, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_command(&fj, NULL, &cmd, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_command(&fj, &t, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_lock_command(NULL, &cmd));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_zero_here(NULL, &t.pos));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_zero_here(&fj, NULL));
    TEST_ASSERT_NULL(j288_joint_state(NULL));
    TEST_ASSERT_NULL(j288_joint_config(NULL));
    TEST_ASSERT_NULL(j288_joint_core(NULL));
    j288_joint_reset(NULL);
    j288_joint_target_init(NULL, &t);
    j288_joint_target_init(&fj, NULL);
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_bus_init(NULL, &sch, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_bus_init(&fb, NULL, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_bus_add(NULL, &fj));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_bus_add(&fb, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_bus_set_target(NULL, &fj, &t, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_bus_set_target(&fb, NULL, &t, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_bus_set_target(&fb, &fj, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_bus_lock(NULL, &fj));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_joint_bus_lock(&fb, NULL));
    j288_joint_bus_on_reply(NULL, JID, NULL); /* ignored */
}

/* A reversed joint at rest reports speed and torque +0, not -0 (printed "-0" by tools). */
static void test_facade_reversed_joint_at_rest_is_plus_zero(void)
{
    jcfg_t c = cfg_for(7u);
    j288_reply_raw_t r;
    model_t m = servo_at(0.25, 0.0);

    api = API_FACADE;
    c.direction = -1;
    TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
    (void)start_joint(&m);
    r = reply_of(&m, 7u);
    TEST_ASSERT_EQUAL_INT(J288_OK, j_take(&r, NULL));
    /* copysign, not signbit: mingw-w64's signbit macro converts a double to float in its
     * float branch, which -Wconversion rejects. */
    TEST_ASSERT_TRUE(copysign(1.0, (double)j288_joint_state(&fj)->speed) > 0.0);
    TEST_ASSERT_TRUE(copysign(1.0, (double)j288_joint_state(&fj)->torque) > 0.0);
}

static j288_real_t real_of(j288_q24_t q)
{
    return (j288_real_t)((double)q / Q24);
}

/* The facade's results are the core's, bit for bit: the same events, errors, clamp masks and
 * command frames, and its state the core's converted, over random joints, replies, targets. */
static void test_facade_matches_core(void)
{
    jcfg_t c;
    model_t m;
    int trial, step, commands = 0;

    api = API_FACADE;
    for (trial = 0; trial < 300; trial++) {
        j288_jointq_config_t qc;
        j288_joint_config_t fc;
        random_setup(&c, &m, (trial & 1) != 0);
        c.clamp = (trial & 2) != 0;
        c.continuous = (trial % 7) == 0;
        if (c.continuous) {
            c.pos_min = c.pos_max = 0.0;
        }
        c.max_speed = (trial & 4) ? urand(0.5, 50.0) : 0;
        c.max_torque = (trial & 8) ? urand(0.5, 30.0) : 0;
        c.kd = urand(0.0, 3.0);
        c.init_samples = (uint8_t)(1u + rnd() % 12u);
        qc = qcfg_of(&c);
        fc = fcfg_of(&c);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_init(&qj, &qc));
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&fj, &fc));
        for (step = 0; step < 40; step++) {
            j288_reply_raw_t r = reply_of(&m, 3u);
            const j288_jointq_state_t *a = j288_jointq_state(&qj);
            const j288_joint_state_t *b = j288_joint_state(&fj);
            j288_joint_target_t tf;
            j288_jointq_target_t tq;
            j288_cmd_raw_t ca, cb;
            unsigned ea = 0u, eb = 0u, ma = 0u, mb = 0u;
            int ra, rb;
            r.speed = (int16_t)(int32_t)(rnd() % 65536u - 32768u);
            r.torque = (int16_t)(int32_t)(rnd() % 65536u - 32768u);
            TEST_ASSERT_EQUAL_INT(J288_OK, j288_jointq_take_reply(&qj, &r, &ea));
            TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_take_reply(&fj, &r, &eb));
            TEST_ASSERT_EQUAL_HEX(ea, eb);
            TEST_ASSERT_EQUAL_MEMORY(a, &fj.core.st, sizeof *a); /* the same core state */
            TEST_ASSERT_TRUE((a->known == b->known) && (a->calibrated == b->calibrated) &&
                             (a->beyond_limit == b->beyond_limit) &&
                             (a->cal_mismatch == b->cal_mismatch) &&
                             (a->encoder_fault == b->encoder_fault));
            TEST_ASSERT_DOUBLE_WITHIN(REL * fabs((double)b->pos), (double)real_of(a->pos),
                                      (double)b->pos); /* float: within 1 ulp */
            TEST_ASSERT_TRUE(real_of(a->residual) == b->residual);
            TEST_ASSERT_TRUE(real_of(a->encoder) == b->encoder);
            TEST_ASSERT_TRUE(real_of(a->cal_residual) == b->cal_residual);
            TEST_ASSERT_TRUE((j288_real_t)((double)a->speed / Q16) == b->speed);
            TEST_ASSERT_TRUE((j288_real_t)((double)a->torque / Q16) == b->torque);
            /* targets: mostly inside, some beyond each limit and the wire's ranges */
            tf.pos = (j288_real_t)(urand(c.pos_min, c.pos_max) +
                                   ((rnd() % 8u == 0u) ? urand(-0.5, 0.5) : 0.0));
            tf.speed = (j288_real_t)(urand(-300.0, 300.0) * ((rnd() % 4u == 0u) ? 1.0 : 0.05));
            tf.torque = (j288_real_t)(urand(-40.0, 40.0) * ((rnd() % 4u == 0u) ? 1.0 : 0.2));
            tf.kp = (j288_real_t)(urand(-100.0, 2200.0) * ((rnd() % 4u == 0u) ? 1.0 : 0.05));
            tf.kd = (j288_real_t)(urand(-1.0, 22.0) * ((rnd() % 4u == 0u) ? 1.0 : 0.1));
            tq.pos = q24((double)tf.pos);
            tq.speed = q16((double)tf.speed);
            tq.torque = q16((double)tf.torque);
            tq.kp = q16((double)tf.kp);
            tq.kd = q16((double)tf.kd);
            memset(&ca, 0, sizeof ca);
            memset(&cb, 0, sizeof cb);
            ra = j288_jointq_command(&qj, &tq, &ca, &ma);
            rb = j288_joint_command(&fj, &tf, &cb, &mb);
            TEST_ASSERT_EQUAL_INT(ra, rb);
            TEST_ASSERT_EQUAL_HEX(ma, mb);
            assert_same_cmd(&ca, &cb);
            commands += (ra == J288_OK);
            /* the joint moves about its range, sometimes beyond it, sometimes far */
            m.theta += urand(-0.05, 0.05) + ((rnd() % 16u == 0u) ? urand(-200.0, 200.0) : 0.0);
            if (rnd() % 64u == 0u) {
                m.k += 1.0; /* a power cycle: both lose the angle on the same reply */
            }
        }
    }
    TEST_ASSERT_TRUE(commands > 3000);
    print_value("commands compared bit for bit", (double)commands, "");
}

/* ---- the phase fit (joint_cal.c, in j288_real_t) */

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
    jcfg_t c;
    j288_joint_config_t fc;
    j288_cal_t cal;
    j288_cal_report_t rep;
    model_t m;
    int trial;
    double worst = 0.0, worst_rms = 0.0;

    api = API_FACADE;
    for (trial = 0; trial < 100; trial++) {
        double mid, err;
        random_setup(&c, &m, false);
        c.has_phase = false;
        m.backlash = backlash;
        mid = as_real(c.zero) + (double)c.direction * 0.5 * (c.pos_min + c.pos_max);
        move_to(&m, mid);
        fc = fcfg_of(&c);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_cal_init(&cal, &fc));
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
        c.phase = (double)rep.phase;
        m.backlash = 0.0;
        TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
        TEST_ASSERT_EQUAL_HEX(EVB(ANGLE_UNKNOWN) | EVB(ANGLE_KNOWN), start_joint(&m));
        TEST_ASSERT_DOUBLE_WITHIN(c_tol / NR + CAL_TOL, q_of(&c, &m), j_state().pos);
    }
    UnityPrint("  ");
    UnityPrint(label);
    UNITY_PRINT_EOL();
    print_value("    worst phase error, rotor", worst * 1e6, " urad");
    print_value("    as output angle", worst / NR * 1e6, " urad");
    print_value("    worst residual rms, rotor", worst_rms * 1e6, " urad");
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
    j288_joint_config_t c;
    j288_reply_raw_t r;
    model_t m;
    int i;

    memset(&c, 0, sizeof c);
    c.id = 1u;
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
    TEST_ASSERT_TRUE((double)rep.max_abs <= PI + 1e-6); /* residuals are phases */
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

/* A fit whose motion crosses the encoder's wrap, both ways, with direction -1; and one of a
 * continuous joint (labelled within pi of 0). */
static void test_fit_across_the_wrap(void)
{
    jcfg_t c = cfg_for(1u);
    j288_joint_config_t fc;
    j288_cal_t cal;
    j288_cal_report_t rep;
    model_t m;
    int d;

    api = API_FACADE;
    for (d = -1; d <= 1; d += 2) {
        c.direction = (int8_t)d;
        c.zero = -TAU; /* theta = -2 pi (OutPos 0) is joint 0 */
        c.continuous = (d > 0);
        m = servo_at(-TAU + 0.1, -2.9);
        fc = fcfg_of(&c);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_cal_init(&cal, &fc));
        sweep_fit(&cal, &m, -TAU, 0.04, 1000);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_cal_result(&cal, &rep));
        TEST_ASSERT_DOUBLE_WITHIN(0.01, 0.0, wrap((double)rep.phase - m.c));
        c.has_phase = true;
        c.phase = (double)rep.phase;
        TEST_ASSERT_EQUAL_INT(J288_OK, j_init(&c));
        move_to(&m, -TAU - 0.01);
        (void)start_joint(&m);
        TEST_ASSERT_TRUE(j_state().calibrated);
        TEST_ASSERT_DOUBLE_WITHIN(0.01 / NR + CAL_TOL, -0.01 * d, j_state().pos);
        c.has_phase = false;
        c.phase = 0;
    }
}
#endif /* J288_CONFIG_SI */

/* Each test of the suite against the core, then through the facade. */
static void run_both(UnityTestFunction fn, const char *name, int line)
{
    static char label[2][96];
    (void)snprintf(label[0], sizeof label[0], "core: %s", name);
    api = API_CORE;
    rng_state = TEST_JOINT_SEED; /* both runs see the same joints, replies and targets */
    UnityDefaultTestRun(fn, label[0], line);
#if J288_CONFIG_SI
    (void)snprintf(label[1], sizeof label[1], "facade: %s", name);
    api = API_FACADE;
    rng_state = TEST_JOINT_SEED;
    UnityDefaultTestRun(fn, label[1], line);
#endif
}

#define RUN_BOTH(fn) run_both(fn, #fn, __LINE__)

int main(void)
{
    UNITY_BEGIN();
    RUN_BOTH(test_config_checks);
    RUN_BOTH(test_default_is_the_encoder_angle_wrapped);
    RUN_BOTH(test_start_events_and_refusals);
    RUN_BOTH(test_take_reply_errors);
    RUN_BOTH(test_uncalibrated_random);
    RUN_BOTH(test_calibrated_random);
    RUN_BOTH(test_state_speed_torque_and_direction);
    RUN_BOTH(test_start_while_moving_and_outlier);
    RUN_BOTH(test_start_average_while_moving);
    RUN_BOTH(test_turn_choice);
    RUN_BOTH(test_range_across_the_wrap);
    RUN_BOTH(test_wrong_calibration);
    RUN_BOTH(test_power_cycle);
    RUN_BOTH(test_slipped_gear);
    RUN_BOTH(test_encoder_fault);
    RUN_BOTH(test_large_rotor_positions);
    RUN_BOTH(test_command_frames);
    RUN_BOTH(test_command_round_trip);
    RUN_BOTH(test_limits_refused);
    RUN_BOTH(test_limits_clamped);
    RUN_BOTH(test_limit_events);
    RUN_BOTH(test_hold_near_a_limit);
    RUN_BOTH(test_zero_here);
    RUN_BOTH(test_one_rule_for_pi);
    RUN_BOTH(test_halves_away_from_zero);
    RUN_BOTH(test_continuous_start_and_travel);
    RUN_BOTH(test_continuous_wheel_for_a_day);
    RUN_BOTH(test_limit_law);
    RUN_BOTH(test_binding_locks_until_known_and_after_a_loss);
    RUN_BOTH(test_binding_events_order_and_values);
    RUN_BOTH(test_binding_argument_checks);
    RUN_BOTH(test_binding_remakes_targets_toward_a_limit);
    RUN_TEST(test_core_constants_and_macros);
    RUN_TEST(test_core_golden_commands);
    RUN_TEST(test_core_golden_replies);
    RUN_TEST(test_core_integer_edges);
#if J288_CONFIG_SI
    RUN_TEST(test_facade_edge);
    RUN_TEST(test_facade_reversed_joint_at_rest_is_plus_zero);
    RUN_TEST(test_facade_matches_core);
    RUN_TEST(test_fit_random);
    RUN_TEST(test_fit_with_backlash);
    RUN_TEST(test_fit_quality_checks);
    RUN_TEST(test_fit_across_the_wrap);
#endif
    RUN_TEST(test_error_strings);
    return UNITY_END();
}
