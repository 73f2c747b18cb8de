/* The joint layer: absolute joint angles, soft limits, the binding to a scheduler and the
 * phase fit. The contract is in j288/joint.h, the model in docs/joint.md. */
#include "j288/joint.h"

#if J288_CONFIG_SI

#include <string.h>

#define N_RATIO ((j288_real_t)J288_GEAR_RATIO)
#define TWO_PI ((j288_real_t)(2.0 * J288_PI))
#define INV_TWO_PI ((j288_real_t)(1.0 / (2.0 * J288_PI)))
#define HALF ((j288_real_t)0.5)
#define ZERO ((j288_real_t)0)
/* Output rad per OutPos count; rotor rad per position LSB; output rad per position LSB. */
#define OUT_RAD_PER_COUNT ((j288_real_t)(2.0 * J288_PI / (double)J288_OUT_POS_COUNTS))
#define ROTOR_RAD_PER_LSB ((j288_real_t)(2.0 * J288_PI / 32768.0))
#define OUT_RAD_PER_LSB ((j288_real_t)(2.0 * J288_PI / 32768.0 / J288_GEAR_RATIO))
#define ROTOR_LSB_MASK 0x7FFFu /* position LSB within one rotor turn */
#define COUNT_MASK (J288_OUT_POS_COUNTS - 1u)
#define HALF_TURN_COUNTS 4096
#define TURN_COUNTS 8192
/* The fit's continued count stays within this (65536 output turns), far from int32's end. */
#define CONT_LIMIT 0x20000000
/* Finite bound for speed, torque and gain limits (a float holds it). */
#define BIG ((j288_real_t)1e30)

/* ---- small maths, without libm */

/* x - 2 pi n for the nearest integer n: [-pi, pi]. Every caller's |x| is far below 2^31 turns
 * (configuration angles are bounded, rotor differences are int32). */
static j288_real_t wrap_pi(j288_real_t x)
{
    j288_real_t t = x * INV_TWO_PI;
    int32_t n = (int32_t)((t >= ZERO) ? (t + HALF) : (t - HALF));
    return x - ((j288_real_t)n * TWO_PI);
}

static j288_real_t abs_real(j288_real_t x)
{
    return (x < ZERO) ? -x : x;
}

static bool in_range(j288_real_t x, j288_real_t lo, j288_real_t hi)
{
    return (x >= lo) && (x <= hi); /* false for NaN */
}

/* a - b in rotor LSB, modulo 2^32 (the wire's int32 may wrap), as an int32. */
static int32_t lsb_diff(int32_t a, int32_t b)
{
    uint32_t u = (uint32_t)a - (uint32_t)b;
    uint32_t below;
    if (u <= (uint32_t)INT32_MAX) {
        return (int32_t)u;
    }
    below = u - 0x80000000u; /* u - 2^32 = below - 2^31, computed without overflow */
    return (int32_t)below - INT32_MAX - 1;
}

/* The rotor position within its turn, [0, 2 pi): exact from the integer. */
static j288_real_t rotor_frac(int32_t pos)
{
    uint32_t lsb = (uint32_t)pos & ROTOR_LSB_MASK;
    return (j288_real_t)lsb * ROTOR_RAD_PER_LSB;
}

/* OutPos as an output angle: the centre of its count, (0, 2 pi). */
static j288_real_t encoder_angle(uint16_t out_pos)
{
    unsigned count = (unsigned)out_pos & COUNT_MASK;
    return ((j288_real_t)count + HALF) * OUT_RAD_PER_COUNT;
}

/* The turn choice: the joint angle of output angle theta (any turn) within pi of centre. */
static j288_real_t label_q(j288_real_t dir, j288_real_t zero, j288_real_t centre,
                           j288_real_t theta)
{
    j288_real_t q = dir * (theta - zero);
    return centre + wrap_pi(q - centre);
}

/* ---- configuration */

static void fill_defaults(j288_joint_config_t *c)
{
    if (c->direction == 0) {
        c->direction = 1;
    }
    if (c->init_samples == 0u) {
        c->init_samples = (uint8_t)J288_JOINT_DEFAULT_INIT_SAMPLES;
    }
    if ((c->pos_min == ZERO) && (c->pos_max == ZERO)) {
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

static bool config_ok(const j288_joint_config_t *c)
{
    const j288_real_t a = (j288_real_t)J288_JOINT_MAX_ANGLE;
    const j288_real_t pi = (j288_real_t)J288_PI;
    bool ok = (c->direction == 1) || (c->direction == -1);
    ok = ok && in_range(c->zero, -a, a) && in_range(c->pos_min, -a, a);
    ok = ok && in_range(c->pos_max, -a, a) && (c->pos_min < c->pos_max);
    ok = ok && in_range(c->max_speed, ZERO, BIG) && in_range(c->max_torque, ZERO, BIG);
    ok = ok && in_range(c->kp, ZERO, BIG) && in_range(c->kd, ZERO, BIG);
    ok = ok && in_range(c->phase, -TWO_PI, TWO_PI);
    return ok && in_range(c->track_tol, ZERO, pi) && in_range(c->cal_tol, ZERO, pi);
}

/* cfg checked, with its defaults, into *out. */
static int joint_check_config(const j288_joint_config_t *cfg, j288_joint_config_t *out)
{
    j288_joint_config_t c = *cfg;
    if (c.id > J288_MAX_ID) {
        return J288_ERR_BAD_ID;
    }
    fill_defaults(&c);
    if (!config_ok(&c)) {
        return J288_ERR_BAD_CONFIG;
    }
    *out = c;
    return J288_OK;
}

int j288_joint_init(j288_joint_t *j, const j288_joint_config_t *cfg)
{
    j288_joint_config_t c;
    int err;

    if ((j == NULL) || (cfg == NULL)) {
        return J288_ERR_NULL;
    }
    err = joint_check_config(cfg, &c);
    if (err != J288_OK) {
        return err;
    }
    (void)memset(j, 0, sizeof *j);
    j->cfg = c;
    j->dir = (c.direction < 0) ? (j288_real_t)-1 : (j288_real_t)1;
    j->centre = (c.pos_min + c.pos_max) * HALF;
    j->k_q = j->dir * OUT_RAD_PER_LSB;
    j->k_speed = j->dir * (j288_real_t)(1.0 / (J288_SCALE_SPEED * J288_GEAR_RATIO));
    j->k_torque = j->dir * (j288_real_t)(J288_GEAR_RATIO / J288_SCALE_TORQUE);
    return J288_OK;
}

void j288_joint_reset(j288_joint_t *j)
{
    if (j != NULL) {
        j->seen = false;
        j->init_n = 0u;
        (void)memset(&j->st, 0, sizeof j->st);
    }
}

const j288_joint_state_t *j288_joint_state(const j288_joint_t *j)
{
    return (j == NULL) ? NULL : &j->st;
}

/* ---- replies */

/* The output angle minus the rotor's motion since the start's first sample. */
static j288_real_t start_sample(const j288_joint_t *j, int32_t pos)
{
    return j->st.encoder - ((j288_real_t)lsb_diff(pos, j->init_pos) * OUT_RAD_PER_LSB);
}

static void first_sample(j288_joint_t *j, int32_t pos)
{
    j->init_pos = pos;
    j->init_e0 = j->st.encoder;
    j->init_sum = ZERO;
    j->init_n = 1u;
}

/* The joint angle of the current reply, and its residual against the encoder. */
static void follow(j288_joint_t *j, int32_t pos)
{
    j->st.pos = j->ref_q + (j->k_q * (j288_real_t)lsb_diff(pos, j->ref_pos));
    j->st.residual =
        j->st.encoder_fault ? ZERO : wrap_pi((j->cfg.zero + (j->dir * j->st.pos)) - j->st.encoder);
}

/* Calibrated start: correct the angle q at the anchor by the residual eps. false: eps beyond
 * cal_tol (a mismatch, reported once until a start succeeds). */
static bool apply_phase(j288_joint_t *j, j288_real_t *q, unsigned *ev)
{
    j288_real_t theta = j->cfg.zero + (j->dir * *q);
    j288_real_t eps = wrap_pi(((N_RATIO * theta) + j->cfg.phase) - rotor_frac(j->init_pos));

    j->st.cal_residual = eps;
    if (abs_real(eps) > j->cfg.cal_tol) {
        if (!j->st.cal_mismatch) {
            *ev |= J288_JOINT_EV_BIT(J288_JOINT_EV_CAL_MISMATCH);
        }
        j->st.cal_mismatch = true;
        return false;
    }
    *q -= (j->dir * eps) / N_RATIO;
    j->st.calibrated = true;
    return true;
}

/* Enough samples: label the turn, apply the phase, anchor. */
static void finish_start(j288_joint_t *j, int32_t pos, unsigned *ev)
{
    j288_real_t theta = j->init_e0 + (j->init_sum / (j288_real_t)j->init_n);
    j288_real_t q = label_q(j->dir, j->cfg.zero, j->centre, theta);

    j->init_n = 0u; /* a later start collects afresh */
    if (j->cfg.has_phase && !apply_phase(j, &q, ev)) {
        return;
    }
    j->st.cal_mismatch = false;
    j->ref_pos = j->init_pos;
    j->ref_q = q;
    j->st.known = true;
    *ev |= J288_JOINT_EV_BIT(J288_JOINT_EV_ANGLE_KNOWN);
    follow(j, pos);
}

static void start(j288_joint_t *j, int32_t pos, unsigned *ev)
{
    j->st.residual = ZERO;
    if (j->st.encoder_fault) {
        j->init_n = 0u; /* the encoder is not trusted: no start from it */
        return;
    }
    if (j->init_n == 0u) {
        first_sample(j, pos);
    } else {
        j288_real_t d = wrap_pi(start_sample(j, pos) - j->init_e0);
        if (abs_real(d) > j->cfg.track_tol) {
            first_sample(j, pos); /* the samples disagree: begin again from this one */
        } else {
            j->init_sum += d;
            j->init_n++;
        }
    }
    if (j->init_n >= j->cfg.init_samples) {
        finish_start(j, pos, ev);
    }
}

static void track(j288_joint_t *j, int32_t pos, unsigned *ev)
{
    follow(j, pos);
    if (abs_real(j->st.residual) > j->cfg.track_tol) {
        j->st.known = false;
        j->st.calibrated = false;
        j->st.beyond_limit = false;
        j->init_n = 0u;
        *ev |= J288_JOINT_EV_BIT(J288_JOINT_EV_ANGLE_LOST);
    }
}

static void check_limits(j288_joint_t *j, unsigned *ev)
{
    j288_real_t q = j->st.pos;
    j288_real_t h = (j288_real_t)J288_JOINT_LIMIT_HYST;

    if (!j->st.beyond_limit) {
        if ((q < j->cfg.pos_min) || (q > j->cfg.pos_max)) {
            j->st.beyond_limit = true;
            *ev |= J288_JOINT_EV_BIT(J288_JOINT_EV_LIMIT_REACHED);
        }
    } else if ((q >= (j->cfg.pos_min + h)) && (q <= (j->cfg.pos_max - h))) {
        j->st.beyond_limit = false;
        *ev |= J288_JOINT_EV_BIT(J288_JOINT_EV_LIMIT_LEFT);
    } else {
        /* still beyond */
    }
}

/* k * raw, and +0 for raw 0: a reversed joint at rest is not -0 (tools print "-0"). A test
 * is cheaper than adding 0 in soft float. */
static j288_real_t scale_raw(j288_real_t k, int16_t raw)
{
    return (raw == 0) ? ZERO : (k * (j288_real_t)raw);
}

int j288_joint_take_reply(j288_joint_t *j, const j288_reply_raw_t *reply, unsigned *events)
{
    unsigned ev = 0u;
    bool fault;

    if ((j == NULL) || (reply == NULL)) {
        return J288_ERR_NULL;
    }
    if (reply->id != j->cfg.id) {
        return J288_ERR_WRONG_ID;
    }
    fault = (reply->faults & J288_FAULT_OUTPUT_ENCODER) != 0u;
    if (fault != j->st.encoder_fault) {
        ev |= J288_JOINT_EV_BIT(fault ? J288_JOINT_EV_ENCODER_FAULT : J288_JOINT_EV_ENCODER_OK);
    }
    j->st.encoder_fault = fault;
    j->st.speed = scale_raw(j->k_speed, reply->speed);
    j->st.torque = scale_raw(j->k_torque, reply->torque);
    j->st.encoder = encoder_angle(reply->out_pos);
    if (!j->seen) {
        j->seen = true;
        ev |= J288_JOINT_EV_BIT(J288_JOINT_EV_ANGLE_UNKNOWN);
    }
    if (j->st.known) {
        track(j, reply->pos, &ev);
    } else {
        start(j, reply->pos, &ev);
    }
    if (j->st.known) {
        check_limits(j, &ev);
    }
    if (events != NULL) {
        *events = ev;
    }
    return J288_OK;
}

/* ---- targets and commands */

void j288_joint_target_init(const j288_joint_t *j, j288_joint_target_t *t)
{
    if ((j != NULL) && (t != NULL)) {
        t->pos = j->st.known ? j->st.pos : ZERO;
        t->speed = ZERO;
        t->torque = ZERO;
        t->kp = j->cfg.kp;
        t->kd = j->cfg.kd;
    }
}

static bool target_has_nan(const j288_joint_target_t *t)
{
    return (t->pos != t->pos) || (t->speed != t->speed) || (t->torque != t->torque) ||
           (t->kp != t->kp) || (t->kd != t->kd);
}

/* *x within [lo, hi], or saturated there (bit into *clamped) in clamp mode, or err. A NaN
 * anywhere in the target (t) fails first: NaN is never clamped, and its error comes before
 * any other. */
static int limit_one(const j288_joint_target_t *t, j288_real_t *x, j288_real_t lo,
                     j288_real_t hi, bool clamp, unsigned bit, int err, unsigned *clamped)
{
    if (in_range(*x, lo, hi)) { /* false for NaN */
        return J288_OK;
    }
    if (target_has_nan(t)) {
        return J288_ERR_NOT_FINITE;
    }
    if (!clamp) {
        return err;
    }
    *x = (*x < lo) ? lo : hi;
    *clamped |= bit;
    return J288_OK;
}

static int apply_limits(const j288_joint_config_t *c, j288_joint_target_t *t, unsigned *clamped)
{
    int err = limit_one(t, &t->pos, c->pos_min, c->pos_max, c->clamp, J288_FIELD_POS,
                        J288_ERR_LIMIT_POS, clamped);
    if ((err == J288_OK) && (c->max_speed > ZERO)) {
        err = limit_one(t, &t->speed, -c->max_speed, c->max_speed, c->clamp, J288_FIELD_SPEED,
                        J288_ERR_LIMIT_SPEED, clamped);
    }
    if ((err == J288_OK) && (c->max_torque > ZERO)) {
        err = limit_one(t, &t->torque, -c->max_torque, c->max_torque, c->clamp, J288_FIELD_TAU,
                        J288_ERR_LIMIT_TORQUE, clamped);
    }
    return err;
}

/* a + b when it fits int32 (false otherwise), wrap-free: in unsigned arithmetic, the sum
 * overflowed when both operands have the same sign and the sum has the other. */
static bool add_i32(int32_t a, int32_t b, int32_t *sum)
{
    uint32_t ua = (uint32_t)a;
    uint32_t ub = (uint32_t)b;
    uint32_t us = ua + ub;
    if ((((ua ^ us) & (ub ^ us)) & 0x80000000u) != 0u) {
        return false;
    }
    if (us <= (uint32_t)INT32_MAX) {
        *sum = (int32_t)us;
    } else {
        uint32_t below = us - 0x80000000u; /* us - 2^32 = below - 2^31, without overflow */
        *sum = (int32_t)below - INT32_MAX - 1;
    }
    return true;
}

/* The limited target in the rotor frame, its position relative to the anchor. */
static int target_to_raw(const j288_joint_t *j, const j288_joint_target_t *t,
                         j288_cmd_raw_t *raw, unsigned *clamped)
{
    j288_cmd_si_t si;
    unsigned wire = 0u;
    int err;

    si.id = j->cfg.id;
    si.status = J288_MODE_FOC;
    si.watchdog = true;
    si.tau = j->dir * t->torque;
    si.speed = j->dir * t->speed;
    si.pos = j->dir * (t->pos - j->ref_q);
    si.kp = t->kp;
    si.kd = t->kd;
    err = j->cfg.clamp ? j288_cmd_from_si_clamped(&si, J288_SIDE_OUTPUT, raw, &wire)
                       : j288_cmd_from_si(&si, J288_SIDE_OUTPUT, raw);
    if (err != J288_OK) {
        return err;
    }
    if (!add_i32(j->ref_pos, raw->pos, &raw->pos)) {
        return J288_ERR_RANGE_POS;
    }
    *clamped |= wire;
    return J288_OK;
}

int j288_joint_command(const j288_joint_t *j, const j288_joint_target_t *t, j288_cmd_raw_t *cmd,
                       unsigned *clamped)
{
    j288_joint_target_t v;
    j288_cmd_raw_t raw;
    unsigned mask = 0u;
    int err;

    if ((j == NULL) || (t == NULL) || (cmd == NULL)) {
        return J288_ERR_NULL;
    }
    if (!j->st.known) {
        return j->st.cal_mismatch ? J288_ERR_CAL_MISMATCH : J288_ERR_ANGLE_UNKNOWN;
    }
    /* NaN is refused before anything else, but tested only where a step fails (a NaN fails
     * every limit and every conversion): a good target pays no test of its own. */
    v = *t;
    err = apply_limits(&j->cfg, &v, &mask);
    if (err == J288_OK) {
        err = target_to_raw(j, &v, &raw, &mask);
    }
    if (err != J288_OK) {
        return target_has_nan(t) ? J288_ERR_NOT_FINITE : err;
    }
    *cmd = raw;
    if (clamped != NULL) {
        *clamped = mask;
    }
    return J288_OK;
}

static void joint_lock_cmd(uint8_t id, bool watchdog, j288_cmd_raw_t *cmd)
{
    (void)memset(cmd, 0, sizeof *cmd);
    cmd->id = id;
    cmd->status = J288_MODE_LOCK;
    cmd->watchdog = watchdog;
}

int j288_joint_lock_command(const j288_joint_t *j, j288_cmd_raw_t *cmd)
{
    if ((j == NULL) || (cmd == NULL)) {
        return J288_ERR_NULL;
    }
    joint_lock_cmd(j->cfg.id, true, cmd);
    return J288_OK;
}

int j288_joint_zero_here(const j288_joint_t *j, j288_real_t *zero)
{
    if ((j == NULL) || (zero == NULL)) {
        return J288_ERR_NULL;
    }
    if (!j->st.known) {
        return J288_ERR_ANGLE_UNKNOWN;
    }
    *zero = j->cfg.zero + (j->dir * j->st.pos);
    return J288_OK;
}

/* ---- binding */

int j288_joint_bus_init(j288_joint_bus_t *jb, j288_sched_t *sched, j288_joint_event_fn on_event,
                        void *user)
{
    if ((jb == NULL) || (sched == NULL)) {
        return J288_ERR_NULL;
    }
    (void)memset(jb, 0, sizeof *jb);
    jb->sched = sched;
    jb->on_event = on_event;
    jb->user = user;
    return J288_OK;
}

int j288_joint_bus_add(j288_joint_bus_t *jb, j288_joint_t *j)
{
    j288_cmd_raw_t lock;
    uint8_t id;

    if ((jb == NULL) || (j == NULL)) {
        return J288_ERR_NULL;
    }
    id = j->cfg.id; /* 0-14: j288_joint_init() checked it */
    if ((jb->joint[id] != NULL) && (jb->joint[id] != j)) {
        return J288_ERR_BAD_CONFIG;
    }
    jb->joint[id] = j;
    joint_lock_cmd(id, true, &lock);
    return j288_sched_set_cmd(jb->sched, &lock);
}

/* The joint bound under j's id is j itself. */
static bool bound_here(const j288_joint_bus_t *jb, const j288_joint_t *j)
{
    return (j->cfg.id <= J288_MAX_ID) && (jb->joint[j->cfg.id] == j);
}

int j288_joint_bus_set_target(j288_joint_bus_t *jb, const j288_joint_t *j,
                              const j288_joint_target_t *t, unsigned *clamped)
{
    j288_cmd_raw_t cmd;
    int err;

    if ((jb == NULL) || (j == NULL)) {
        return J288_ERR_NULL;
    }
    if (!bound_here(jb, j)) {
        return J288_ERR_BAD_ARG;
    }
    err = j288_joint_command(j, t, &cmd, clamped);
    if (err != J288_OK) {
        return err;
    }
    return j288_sched_set_cmd(jb->sched, &cmd);
}

int j288_joint_bus_lock(j288_joint_bus_t *jb, const j288_joint_t *j)
{
    j288_cmd_raw_t lock;

    if ((jb == NULL) || (j == NULL)) {
        return J288_ERR_NULL;
    }
    if (!bound_here(jb, j)) {
        return J288_ERR_BAD_ARG;
    }
    joint_lock_cmd(j->cfg.id, true, &lock);
    return j288_sched_set_cmd(jb->sched, &lock);
}

static j288_real_t event_value(const j288_joint_t *j, j288_joint_event_kind_t kind)
{
    switch (kind) {
    case J288_JOINT_EV_ANGLE_LOST:
        return j->st.residual;
    case J288_JOINT_EV_CAL_MISMATCH:
        return j->st.cal_residual;
    case J288_JOINT_EV_ANGLE_KNOWN:
    case J288_JOINT_EV_LIMIT_REACHED:
    case J288_JOINT_EV_LIMIT_LEFT:
        return j->st.pos;
    default:
        return ZERO;
    }
}

static void report(const j288_joint_bus_t *jb, const j288_joint_t *j, unsigned events)
{
    static const j288_joint_event_kind_t order[J288_JOINT_EV_COUNT] = {
        J288_JOINT_EV_ENCODER_FAULT, J288_JOINT_EV_ENCODER_OK,   J288_JOINT_EV_ANGLE_UNKNOWN,
        J288_JOINT_EV_ANGLE_LOST,    J288_JOINT_EV_CAL_MISMATCH, J288_JOINT_EV_ANGLE_KNOWN,
        J288_JOINT_EV_LIMIT_REACHED, J288_JOINT_EV_LIMIT_LEFT};
    j288_joint_event_t ev;
    unsigned i;

    if (jb->on_event == NULL) {
        return;
    }
    ev.id = j->cfg.id;
    ev.joint = j;
    for (i = 0u; i < J288_JOINT_EV_COUNT; i++) {
        if ((events & J288_JOINT_EV_BIT(order[i])) != 0u) {
            ev.kind = order[i];
            ev.value = event_value(j, order[i]);
            jb->on_event(jb->user, &ev);
        }
    }
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
    if (!j->st.known && (slot->cmd.status != J288_MODE_LOCK)) {
        j288_cmd_raw_t lock;
        joint_lock_cmd(id, slot->cmd.watchdog, &lock);
        (void)j288_sched_set_cmd(jb->sched, &lock); /* a valid lock is never refused */
    }
    report(jb, j, events);
}

/* ---- calibration */

int j288_cal_init(j288_cal_t *cal, const j288_joint_config_t *cfg)
{
    static const j288_joint_config_t defaults = {0};
    const j288_joint_config_t *given = (cfg != NULL) ? cfg : &defaults;
    j288_joint_config_t c;
    int err;

    if (cal == NULL) {
        return J288_ERR_NULL;
    }
    err = joint_check_config(given, &c);
    if (err != J288_OK) {
        return err;
    }
    (void)memset(cal, 0, sizeof *cal);
    cal->dir = (c.direction < 0) ? (j288_real_t)-1 : (j288_real_t)1;
    cal->zero = c.zero;
    cal->centre = (c.pos_min + c.pos_max) * HALF;
    cal->cal_tol = c.cal_tol;
    return J288_OK;
}

/* The first pair: its labelled output angle fixes the turns of all later ones. */
static void cal_first(j288_cal_t *cal, uint16_t count, int32_t pos)
{
    j288_real_t q = label_q(cal->dir, cal->zero, cal->centre, encoder_angle(count));
    j288_real_t theta = cal->zero + (cal->dir * q);

    cal->first_pos = pos;
    cal->first_v = wrap_pi(rotor_frac(pos) - (N_RATIO * theta));
    cal->prev_count = count;
}

/* Continue the OutPos count across the wrap (consecutive pairs within half a turn). */
static void cal_continue(j288_cal_t *cal, uint16_t count)
{
    int32_t step = (int32_t)count - (int32_t)cal->prev_count;
    if (step >= HALF_TURN_COUNTS) {
        step -= TURN_COUNTS;
    } else if (step < -HALF_TURN_COUNTS) {
        step += TURN_COUNTS;
    } else {
        /* no wrap */
    }
    cal->prev_count = count;
    cal->cont += step;
    if (cal->cont < cal->cont_min) {
        cal->cont_min = cal->cont;
    }
    if (cal->cont > cal->cont_max) {
        cal->cont_max = cal->cont;
    }
}

/* Welford updates: the residual v (unwrapped around the running mean) and the motion. */
static void cal_accumulate(j288_cal_t *cal, j288_real_t x, j288_real_t y)
{
    j288_real_t n = (j288_real_t)cal->n;
    j288_real_t v = cal->first_v + (y - (N_RATIO * x));
    j288_real_t dv;
    j288_real_t dx;
    j288_real_t dy;

    v = (cal->n == 1u) ? v : (cal->mean + wrap_pi(v - cal->mean));
    dv = v - cal->mean;
    cal->mean += dv / n;
    cal->m2 += dv * (v - cal->mean);
    if ((cal->n == 1u) || (v < cal->vmin)) {
        cal->vmin = v;
    }
    if ((cal->n == 1u) || (v > cal->vmax)) {
        cal->vmax = v;
    }
    dx = x - cal->mx;
    dy = y - cal->my;
    cal->mx += dx / n;
    cal->my += dy / n;
    cal->cxy += dx * (y - cal->my);
    cal->m2y += dy * (y - cal->my);
}

int j288_cal_add(j288_cal_t *cal, uint16_t out_pos, int32_t rotor_pos)
{
    j288_real_t x;
    j288_real_t y;

    if (cal == NULL) {
        return J288_ERR_NULL;
    }
    if ((out_pos > COUNT_MASK) || (cal->n == UINT32_MAX) || (cal->cont > CONT_LIMIT) ||
        (cal->cont < -CONT_LIMIT)) {
        return J288_ERR_RANGE;
    }
    if (cal->n == 0u) {
        cal_first(cal, out_pos, rotor_pos);
    } else {
        cal_continue(cal, out_pos);
    }
    cal->n++;
    x = (j288_real_t)cal->cont * OUT_RAD_PER_COUNT;
    y = (j288_real_t)lsb_diff(rotor_pos, cal->first_pos) * ROTOR_RAD_PER_LSB;
    cal_accumulate(cal, x, y);
    return J288_OK;
}

int j288_cal_add_reply(j288_cal_t *cal, const j288_reply_raw_t *reply)
{
    if ((cal == NULL) || (reply == NULL)) {
        return J288_ERR_NULL;
    }
    if ((reply->faults & J288_FAULT_OUTPUT_ENCODER) != 0u) {
        cal->rejected++;
        return J288_OK;
    }
    return j288_cal_add(cal, reply->out_pos, reply->pos);
}

/* Square root of x >= 0 by Newton's iteration from above (monotone, so it stops). */
static j288_real_t sqrt_nonneg(j288_real_t x)
{
    j288_real_t y = (x > (j288_real_t)1) ? x : (j288_real_t)1;
    if (x <= ZERO) {
        return ZERO;
    }
    for (;;) {
        j288_real_t next = HALF * (y + (x / y));
        if (!(next < y)) {
            return y;
        }
        y = next;
    }
}

int j288_cal_result(const j288_cal_t *cal, j288_cal_report_t *report)
{
    j288_cal_report_t r;

    if ((cal == NULL) || (report == NULL)) {
        return J288_ERR_NULL;
    }
    (void)memset(&r, 0, sizeof r);
    r.samples = cal->n;
    r.rejected = cal->rejected;
    r.span_counts = (uint32_t)cal->cont_max - (uint32_t)cal->cont_min; /* max >= 0 >= min */
    r.phase = wrap_pi(cal->mean);
    r.rms = (cal->n == 0u) ? ZERO : sqrt_nonneg(cal->m2 / (j288_real_t)cal->n);
    r.max_abs = ((cal->vmax - cal->mean) > (cal->mean - cal->vmin)) ? (cal->vmax - cal->mean)
                                                                    : (cal->mean - cal->vmin);
    r.ratio = (abs_real(cal->cxy) > ZERO) ? (cal->m2y / cal->cxy) : ZERO;
    if (r.samples < J288_CAL_MIN_SAMPLES) {
        r.problems |= J288_CAL_FEW_SAMPLES;
    }
    if (r.span_counts < J288_CAL_MIN_SPAN) {
        r.problems |= J288_CAL_SMALL_SPAN;
    }
    if (r.max_abs > cal->cal_tol) {
        r.problems |= J288_CAL_NOISY;
    }
    if (abs_real((r.ratio / N_RATIO) - (j288_real_t)1) >
        (j288_real_t)J288_CAL_MAX_RATIO_ERROR) {
        r.problems |= J288_CAL_RATIO;
    }
    *report = r;
    return (r.problems == 0u) ? J288_OK : J288_ERR_CAL_DATA;
}

#else
/* ISO C forbids an empty translation unit. */
typedef int j288_joint_disabled_t;
#endif /* J288_CONFIG_SI */
