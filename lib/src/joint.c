/* The joint frame in SI units: the float facade over the joint core (jointq.c). It converts
 * at its edge and runs the core; the contract is in j288/joint.h, the model in j288/jointq.h
 * and docs/joint.md. The calibration fit is in joint_cal.c. */
#include "j288/joint.h"

#if J288_CONFIG_SI

#include <string.h>

#include "hints.h"
#include "jointq_priv.h"

#define HALF ((j288_real_t)0.5)
#define ZERO ((j288_real_t)0)
#define Q24_SCALE ((j288_real_t)16777216.0)
#define Q16_SCALE ((j288_real_t)65536.0)
#define Q24_STEP ((j288_real_t)(1.0 / 16777216.0))
#define Q16_STEP ((j288_real_t)(1.0 / 65536.0))
#define TWO_POW_32 ((j288_real_t)4294967296.0)
#define TWO_POW_M32 ((j288_real_t)(1.0 / 4294967296.0))
#define TWO_POW_63 ((j288_real_t)9223372036854775808.0)
#define Q24_SATURATED 0x7FFFFFFFFFFFFFFFu /* 2^63 - 1: beyond every range */

/* ---- the edge: reals to the core's integers and back, without an int64 <-> real conversion
 * (a soft-float helper on a single-precision FPU). Halves away from zero throughout. */

/* |x|: a single instruction on an FPU where the compiler has it built in (the conditional
 * form must keep -0's sign, so it is not one). */
#if defined(__GNUC__) && J288_CONFIG_SI_FLOAT
#define ABS_REAL(x) __builtin_fabsf(x)
#elif defined(__GNUC__)
#define ABS_REAL(x) __builtin_fabs(x)
#else
#define ABS_REAL(x) (((x) < ZERO) ? -(x) : (x))
#endif

/* 2v, |2v| < TWICE_EDGE: the truncation t of |2v| (exact: 2 floor|v| + 1 when |v|'s fraction
 * is a half or more) gives |v| rounded, halves up, as (t + 1) / 2; then v's sign. */
#define TWICE_EDGE ((j288_real_t)2147483646.0) /* float rounds it to 2^31: still within */
#define Q24_TWICE ((j288_real_t)33554432.0)    /* 2^25 */
#define Q16_TWICE ((j288_real_t)131072.0)      /* 2^17 */

static int32_t round_twice(j288_real_t v2, j288_real_t a2)
{
    int32_t m = (int32_t)(((uint32_t)a2 + 1u) >> 1);
    return (v2 < ZERO) ? -m : m;
}


/* x from 16384 - 2^-16 on saturated at int32's ends (beyond every range); NaN: 0 and *ok
 * false. */
static j288_q16_t q16_slow(j288_real_t x, bool *ok)
{
    if (x != x) {
        *ok = false;
        return 0;
    }
    return (x < ZERO) ? INT32_MIN : INT32_MAX;
}

/* a >= 2^31 (not NaN), below 2^63, rounded: the high word and the rest, each exact. */
static uint64_t round_big(j288_real_t a)
{
    uint32_t hi = (uint32_t)(a * TWO_POW_M32);
    j288_real_t rest = a - ((j288_real_t)hi * TWO_POW_32); /* in [0, 2^32): exact */
    uint32_t lo = (uint32_t)rest;
    uint64_t q = ((uint64_t)hi << 32) + (uint64_t)lo;
    if ((rest - (j288_real_t)lo) >= HALF) {
        q++;
    }
    return q;
}

/* x * 2^24 rounded, saturated at int64's ends: beyond 64 rad; NaN: 0 and *ok false. */
static j288_q24_t q24_slow(j288_real_t x, bool *ok)
{
    j288_real_t a = ((x < ZERO) ? -x : x) * Q24_SCALE;
    uint64_t m;
    if (x != x) {
        *ok = false;
        return 0;
    }
    m = (a >= TWO_POW_63) ? Q24_SATURATED : round_big(a);
    return (x < ZERO) ? -(j288_q24_t)m : (j288_q24_t)m; /* (-(2^63 - 1) at the low end) */
}

/* x * 2^24 rounded (NaN: *ok false). The fast path inline in every caller. */
static J288_INLINE_HOT j288_q24_t q24_of(j288_real_t x, bool *ok)
{
    j288_real_t v2 = x * Q24_TWICE;
    j288_real_t a2 = ABS_REAL(v2);
    return (a2 < TWICE_EDGE) ? round_twice(v2, a2) : q24_slow(x, ok); /* NaN: slow */
}

/* x * 2^16 rounded (NaN: *ok false). */
static J288_INLINE_HOT j288_q16_t q16_of(j288_real_t x, bool *ok)
{
    j288_real_t v2 = x * Q16_TWICE;
    j288_real_t a2 = ABS_REAL(v2);
    return (a2 < TWICE_EDGE) ? round_twice(v2, a2) : q16_slow(x, ok); /* NaN: slow */
}

static j288_real_t real_of_q16(j288_q16_t q)
{
    return (j288_real_t)q * Q16_STEP;
}

/* An angle the core keeps within +-2 pi (encoder, residuals). */
static j288_real_t real_of_small(j288_q24_t q)
{
    return (j288_real_t)(int32_t)q * Q24_STEP;
}

j288_real_t j288_joint_real_of_q24(j288_q24_t q)
{
    uint64_t m;
    j288_real_t r;
    if ((q > -(j288_q24_t)INT32_MAX) && (q < (j288_q24_t)INT32_MAX)) {
        return real_of_small(q); /* within 128 rad */
    }
    m = (q < 0) ? ((uint64_t)0 - (uint64_t)q) : (uint64_t)q;
    r = ((j288_real_t)(uint32_t)(m >> 32) * (TWO_POW_32 * Q24_STEP)) +
        ((j288_real_t)(uint32_t)m * Q24_STEP);
    return (q < 0) ? -r : r;
}

static bool finite_real(j288_real_t x)
{
    return (x - x) == ZERO; /* NaN and infinities are not */
}

/* ---- configuration */

static bool config_finite(const j288_joint_config_t *c)
{
    return finite_real(c->zero) && finite_real(c->pos_min) && finite_real(c->pos_max) &&
           finite_real(c->max_speed) && finite_real(c->max_torque) && finite_real(c->kp) &&
           finite_real(c->kd) && finite_real(c->phase) && finite_real(c->track_tol) &&
           finite_real(c->cal_tol);
}

/* c (finite: config_finite()) in the core's units. */
static void config_to_q(const j288_joint_config_t *c, j288_jointq_config_t *q)
{
    bool ok = true; /* (finite) */
    (void)memset(q, 0, sizeof *q);
    q->id = c->id;
    q->direction = c->direction;
    q->clamp = c->clamp;
    q->has_phase = c->has_phase;
    q->continuous = c->continuous;
    q->init_samples = c->init_samples;
    q->zero = q24_of(c->zero, &ok);
    q->pos_min = q24_of(c->pos_min, &ok);
    q->pos_max = q24_of(c->pos_max, &ok);
    if ((c->pos_min == ZERO) && (c->pos_max == ZERO) && !c->continuous) {
        /* the default range: [-pi, pi] with pi as j288_real_t holds it (a float's pi rounds
         * to J288_JOINTQ_PI + 1, a double's to J288_JOINTQ_PI: a target of pi is inside) */
        q->pos_min = q24_of((j288_real_t)-J288_PI, &ok);
        q->pos_max = q24_of((j288_real_t)J288_PI, &ok);
    }
    q->max_speed = q16_of(c->max_speed, &ok);
    q->max_torque = q16_of(c->max_torque, &ok);
    q->kp = q16_of(c->kp, &ok);
    q->kd = q16_of(c->kd, &ok);
    q->phase = q24_of(c->phase, &ok);
    q->track_tol = q24_of(c->track_tol, &ok);
    q->cal_tol = q24_of(c->cal_tol, &ok);
}

/* The defaults the core filled in, in the given configuration's terms. */
static void fill_defaults(j288_joint_config_t *c, const j288_jointq_config_t *q)
{
    c->direction = q->direction;
    c->init_samples = q->init_samples;
    if ((c->pos_min == ZERO) && (c->pos_max == ZERO) && !c->continuous) {
        c->pos_min = (j288_real_t)-J288_PI;
        c->pos_max = (j288_real_t)J288_PI;
    }
    if (c->track_tol == ZERO) {
        c->track_tol = (j288_real_t)J288_JOINT_DEFAULT_TRACK_TOL;
    }
    if (c->cal_tol == ZERO) {
        c->cal_tol = (j288_real_t)J288_JOINT_DEFAULT_CAL_TOL;
    }
}

/* The state after the core's latest reply. */
static void state_from_core(j288_joint_t *j)
{
    const j288_jointq_state_t *s = j288_jointq_state_of(&j->core);
    j->st.known = s->known;
    j->st.calibrated = s->calibrated;
    j->st.cal_mismatch = s->cal_mismatch;
    j->st.encoder_fault = s->encoder_fault;
    j->st.beyond_limit = s->beyond_limit;
    j->st.pos = j288_joint_real_of_q24(s->pos);
    j->st.speed = real_of_q16(s->speed);
    j->st.torque = real_of_q16(s->torque);
    j->st.encoder = real_of_small(s->encoder);
    j->st.residual = real_of_small(s->residual);
    j->st.cal_residual = real_of_small(s->cal_residual);
}

int j288_joint_init(j288_joint_t *j, const j288_joint_config_t *cfg)
{
    j288_jointq_config_t q;
    j288_jointq_config_t filled;
    j288_q24_t centre;
    int err;

    if ((j == NULL) || (cfg == NULL)) {
        return J288_ERR_NULL;
    }
    if (cfg->id > J288_MAX_ID) {
        return J288_ERR_BAD_ID;
    }
    if (!config_finite(cfg)) {
        return J288_ERR_BAD_CONFIG;
    }
    config_to_q(cfg, &q);
    err = j288_jointq_check_config(&q, &filled, &centre);
    if (err != J288_OK) {
        return err;
    }
    (void)memset(j, 0, sizeof *j);
    (void)j288_jointq_init(&j->core, &q); /* checked above */
    j->cfg = *cfg;
    fill_defaults(&j->cfg, &filled);
    state_from_core(j);
    return J288_OK;
}

void j288_joint_reset(j288_joint_t *j)
{
    if (j != NULL) {
        j288_jointq_reset(&j->core);
        state_from_core(j);
    }
}

const j288_joint_config_t *j288_joint_config(const j288_joint_t *j)
{
    return (j == NULL) ? NULL : &j->cfg;
}

const j288_jointq_t *j288_joint_core(const j288_joint_t *j)
{
    return (j == NULL) ? NULL : &j->core;
}

const j288_joint_state_t *j288_joint_state(const j288_joint_t *j)
{
    return (j == NULL) ? NULL : &j->st;
}

int j288_joint_take_reply(j288_joint_t *j, const j288_reply_raw_t *reply, unsigned *events)
{
    int err;
    if (j == NULL) {
        return J288_ERR_NULL;
    }
    err = j288_jointq_take_reply(&j->core, reply, events);
    if (err == J288_OK) {
        state_from_core(j);
    }
    return err;
}

/* ---- targets and commands */

void j288_joint_target_init(const j288_joint_t *j, j288_joint_target_t *t)
{
    if ((j != NULL) && (t != NULL)) {
        j288_jointq_target_t q;
        j288_jointq_target_init(&j->core, &q);
        t->pos = j288_joint_real_of_q24(q.pos);
        t->speed = ZERO;
        t->torque = ZERO;
        t->kp = j->cfg.kp;
        t->kd = j->cfg.kd;
    }
}

/* The target in the core's units: false for a NaN in it (refused at the edge, before
 * anything else; a NaN takes the conversions' slow path, so a good target pays no test). */
static bool target_to_q(const j288_joint_target_t *t, j288_jointq_target_t *q)
{
    bool ok = true;
    q->pos = q24_of(t->pos, &ok);
    q->speed = q16_of(t->speed, &ok);
    q->torque = q16_of(t->torque, &ok);
    q->kp = q16_of(t->kp, &ok);
    q->kd = q16_of(t->kd, &ok);
    return ok;
}

int j288_joint_command(const j288_joint_t *j, const j288_joint_target_t *t, j288_cmd_raw_t *cmd,
                       unsigned *clamped)
{
    j288_jointq_target_t q;

    if ((j == NULL) || (t == NULL) || (cmd == NULL)) {
        return J288_ERR_NULL;
    }
    if (!target_to_q(t, &q)) {
        return J288_ERR_NOT_FINITE;
    }
    return j288_jointq_command(&j->core, &q, cmd, clamped);
}

int j288_joint_lock_command(const j288_joint_t *j, j288_cmd_raw_t *cmd)
{
    return j288_jointq_lock_command((j == NULL) ? NULL : &j->core, cmd);
}

int j288_joint_zero_here(const j288_joint_t *j, j288_real_t *zero)
{
    j288_q24_t z;
    int err;

    if ((j == NULL) || (zero == NULL)) {
        return J288_ERR_NULL;
    }
    err = j288_jointq_zero_here(&j->core, &z);
    if (err == J288_OK) {
        *zero = j288_joint_real_of_q24(z);
    }
    return err;
}

/* ---- binding: the core's, its events converted (the user's callback in the facade). */

static void event_to_real(void *user, const j288_jointq_event_t *ev)
{
    const j288_joint_bus_t *jb = (const j288_joint_bus_t *)user; /* ours, set at init */
    j288_joint_event_t e;

    if (jb->on_event == NULL) {
        return;
    }
    e.kind = ev->kind;
    e.id = ev->id; /* 0-14: a bound joint's */
    e.joint = jb->joint[ev->id];
    e.value = j288_joint_real_of_q24(ev->value);
    jb->on_event(jb->user, &e);
}

int j288_joint_bus_init(j288_joint_bus_t *jb, j288_sched_t *sched, j288_joint_event_fn on_event,
                        void *user)
{
    int err;
    if (jb == NULL) {
        return J288_ERR_NULL;
    }
    err = j288_jointq_bus_init(&jb->core, sched, event_to_real, jb);
    if (err == J288_OK) {
        (void)memset(jb->joint, 0, sizeof jb->joint);
        jb->on_event = on_event;
        jb->user = user;
    }
    return err;
}

int j288_joint_bus_add(j288_joint_bus_t *jb, j288_joint_t *j)
{
    int err;
    if ((jb == NULL) || (j == NULL)) {
        return J288_ERR_NULL;
    }
    err = j288_jointq_bus_add(&jb->core, &j->core);
    if (err == J288_OK) {
        jb->joint[j288_jointq_config_of(&j->core)->id] = j; /* 0-14: the core checked it */
    }
    return err;
}

void j288_joint_bus_on_reply(void *user, uint8_t id, const j288_slot_t *slot)
{
    j288_joint_bus_t *jb = (j288_joint_bus_t *)user; /* the scheduler hands back our own */
    j288_joint_t *j;
    unsigned events = 0u;

    if ((jb == NULL) || (slot == NULL) || (id > J288_MAX_ID)) {
        return;
    }
    j = jb->joint[id];
    if ((j == NULL) || (j288_joint_take_reply(j, &slot->reply, &events) != J288_OK)) {
        return;
    }
    j288_jointq_after_reply(&jb->core, &j->core, slot, events);
}

int j288_joint_bus_set_target(j288_joint_bus_t *jb, const j288_joint_t *j,
                              const j288_joint_target_t *t, unsigned *clamped)
{
    j288_jointq_target_t q;

    if ((jb == NULL) || (j == NULL) || (t == NULL)) {
        return J288_ERR_NULL;
    }
    if (!target_to_q(t, &q)) {
        return J288_ERR_NOT_FINITE;
    }
    return j288_jointq_bus_set_target(&jb->core, &j->core, &q, clamped);
}

int j288_joint_bus_lock(j288_joint_bus_t *jb, const j288_joint_t *j)
{
    return j288_jointq_bus_lock((jb == NULL) ? NULL : &jb->core, (j == NULL) ? NULL : &j->core);
}

#else
/* ISO C forbids an empty translation unit. */
typedef int j288_joint_disabled_t;
#endif /* J288_CONFIG_SI */
