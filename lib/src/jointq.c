/* The joint core: the one joint state machine, in integers. The contract is in j288/jointq.h,
 * the model in docs/joint.md; j288/joint.h's float API is a facade over it (joint.c). */
#include "j288/jointq.h"

#include <string.h>

#include "frame_priv.h"
#include "jointq_priv.h"

/* ---- constants. Each is the exact value rounded to an integer (pi taken to 60 digits, the
 * gear ratio N = 5767 / 20 exactly); test_joint pins them through the generator's golden
 * vectors and every reply field's input against double. */
#define PI_Q J288_JOINTQ_PI          /* pi * 2^24 */
#define TWO_PI_Q J288_JOINTQ_TWO_PI  /* 2 pi * 2^24, odd */
#define POS_FAR 0x4000000000000000   /* 2^62: a continuous joint's targets are bounded to it */
#define HALF_TURN_Q 52707178         /* (TWO_PI_Q - 1) / 2: the wrap's bound, below pi */
#define FORTY_PI_Q 2108287141        /* 40 pi * 2^24: N * 40 pi is 5767 turns of the rotor */
#define FORTY_PI_FRAC 1424062817u    /* its fraction, * 2^32 */
#define TWENTY_PI_Q 1054143570       /* FORTY_PI_Q / 2 */
#define GEAR_NUM 5767u
#define GEAR_DEN 20u
#define GEAR_INT 288u                /* N = 288 + 7 / 20 */
#define GEAR_REST 7u
#define HALF_26 0x2000000u           /* 2^25: rounds a value in 2^-26 units */
#define INV_TWO_PI_26 41721u         /* 2^42 / TWO_PI_Q rounded down: turns from |x| >> 16 */
#define ROTOR_LSB_MASK 0x7FFFu       /* position LSB within one rotor turn */
#define COUNT_MASK (J288_OUT_POS_COUNTS - 1u)
/* Rotor LSB in 20 output turns (5767 rotor turns): the output angle's period in LSB. The
 * anchor moves by it when the rotor is half of it away (10 output turns). */
#define LSB_PER_40PI 188973056u
#define ANCHOR_REACH 94486528        /* LSB_PER_40PI / 2 */
/* Q24 output rad per rotor LSB: 2^24 * 2 pi / 32768 / N, as K / 2^28. */
#define Q24_PER_LSB_K 2994813293u
#define Q24_PER_LSB_S 28u
/* Q24 rotor rad per rotor LSB (2 pi 2^24 / 32768 = 3216.99...) as integer + 16-bit fraction. */
#define ROTOR_Q24_INT 3216u
#define ROTOR_Q24_FRAC16 64938u
/* Q24 output rad per half OutPos count (pi 2^24 / 8192 = 6433.98...), + 17-bit fraction. */
#define HALF_COUNT_INT 6433u
#define HALF_COUNT_FRAC17 128681u
/* Q16 output rad/s per rotor speed LSB (2^16 2 pi / 2.56 / N = 557.83...), + 16-bit fraction. */
#define SPEED_Q16_INT 557u
#define SPEED_Q16_FRAC16 54227u
/* Q16 output N*m per rotor torque LSB: 2^16 N / 256000 = 46136 / 625 = 73.8176 exactly. */
#define TORQUE_Q16_INT 73u
#define TORQUE_Q16_FRAC16 53582u
#define TORQUE_Q16_NUM 46136u
#define TORQUE_Q16_DEN 625u
/* The limit law's damping at most: the wire's kd range at the output is 21.28 N*m*s/rad. */
#define LIMIT_KD_MAX (21 * 65536)
#define Q24_SPAN 0x100000000LL       /* 2^32: a position target's reach from the anchor */

/* ---- small integer arithmetic */

/* u modulo 2^32 as an int32, without an implementation-defined conversion. */
static int32_t jq_as_i32(uint32_t u)
{
    uint32_t below;
    if (u <= (uint32_t)INT32_MAX) {
        return (int32_t)u;
    }
    below = u - 0x80000000u; /* u - 2^32 = below - 2^31, without overflow */
    return (int32_t)below - INT32_MAX - 1;
}

/* |x|, INT32_MIN included. */
static uint32_t jq_mag32(int32_t x)
{
    return (x < 0) ? (0u - (uint32_t)x) : (uint32_t)x;
}

/* |x|, INT64_MIN included. */
static uint64_t jq_mag64(int64_t x)
{
    return (x < 0) ? ((uint64_t)0 - (uint64_t)x) : (uint64_t)x;
}

/* -m or m (m <= 2^31, and < 2^31 when not negated). */
static int32_t jq_signed_of(bool neg, uint32_t m)
{
    return neg ? jq_as_i32(0u - m) : (int32_t)m;
}

/* x saturated to +-(2^31 - 1). */
static int32_t jq_sat32(int64_t x)
{
    if (x > (int64_t)INT32_MAX) {
        return INT32_MAX;
    }
    return (x < -(int64_t)INT32_MAX) ? -INT32_MAX : (int32_t)x;
}

/* a * b, 64 bits. Cortex-M0/M0+/M23 have no 32x32->64 multiply: there, four 16-bit products
 * inline cost a third of the C library's 64x64 call (__aeabi_lmul) per use. */
#if defined(__ARM_ARCH_6M__) || defined(__ARM_ARCH_8M_BASE__)
static J288_INLINE_HOT uint64_t jq_mul64(uint32_t a, uint32_t b)
{
    uint32_t al = a & 0xFFFFu;
    uint32_t ah = a >> 16;
    uint32_t bl = b & 0xFFFFu;
    uint32_t bh = b >> 16;
    uint32_t ll = al * bl;
    uint32_t mid = (al * bh) + (ll >> 16);      /* < 2^32: (2^16 - 1)^2 + 2^16 */
    uint32_t mid2 = (ah * bl) + (mid & 0xFFFFu); /* the same */
    uint32_t hi = (ah * bh) + (mid >> 16) + (mid2 >> 16);
    uint32_t lo = (mid2 << 16) | (ll & 0xFFFFu);
    return ((uint64_t)hi << 32) | (uint64_t)lo;
}
#else
static J288_INLINE_HOT uint64_t jq_mul64(uint32_t a, uint32_t b)
{
    return (uint64_t)a * b;
}
#endif

/* floor(a * b / 2^32). */
static J288_INLINE_HOT uint32_t jq_mulhi(uint32_t a, uint32_t b)
{
    return (uint32_t)(jq_mul64(a, b) >> 32);
}

/* k * x for a gain k >= 0 and a signed x (|x| < 2^31), 64 bits. */
static int64_t jq_gain_times(int32_t k, int32_t x)
{
    int64_t p = (int64_t)jq_mul64((uint32_t)k, jq_mag32(x));
    return (x < 0) ? -p : p;
}

/* round(m * (ki + kf / 2^b)), halves up, to within 1/2 + m / 2^(b+1): 32-bit multiplies
 * only (m * kf + 2^(b-1) < 2^32 for every caller). */
static uint32_t jq_mul_frac(uint32_t m, uint32_t ki, uint32_t kf, unsigned b)
{
    return (m * ki) + (((m * kf) + ((uint32_t)1 << (b - 1u))) >> b);
}

/* r, within 1 of round(m * num / den), corrected to it exactly (halves up): r is right when
 * -den <= 2 m num - 2 r den < den. That difference lies within +-3 den < 2^31, so it is
 * computed modulo 2^32 with 32-bit multiplies. */
static uint32_t jq_ratio_fix(uint32_t r, uint32_t m, uint32_t num, uint32_t den)
{
    int32_t t = jq_as_i32((2u * m * num) - (2u * r * den));
    if (t < -(int32_t)den) {
        return r - 1u;
    }
    if (t >= (int32_t)den) {
        return r + 1u;
    }
    return r;
}

/* The wrap: x - 2 pi n for the integer n that leaves it within [-HALF_TURN_Q, HALF_TURN_Q],
 * the Q24 angles within [-pi, pi] (TWO_PI_Q is odd: no tie). |x| < 2^31 - 2^26 (123 rad).
 * The turn estimate from |x| >> 16 and a reciprocal rounded down never exceeds the exact
 * turns and is within 0.001 turn of them: r is at least -HALF_TURN_Q, and one step down
 * corrects it. */
static int32_t jq_wrap_pi(int32_t x)
{
    uint32_t m = jq_mag32(x);
    uint32_t n = (((m >> 16) * INV_TWO_PI_26) + HALF_26) >> 26;
    uint32_t turns = n * (uint32_t)TWO_PI_Q; /* <= m + pi: an int32 */
    int32_t r = (int32_t)m - (int32_t)turns;
    if (r > HALF_TURN_Q) {
        r -= TWO_PI_Q;
    }
    return (x < 0) ? -r : r;
}

/* The same for |x| < 2^40 (starts and anchors only), in 64 bits without a division (which
 * would link a kilobyte of the C library's 64-bit division on Cortex-M0); the estimate is
 * within 0.05 turn below the exact one. */
static int32_t jq_wrap_pi64(int64_t x)
{
    uint64_t m = jq_mag64(x);
    uint32_t n = (uint32_t)((jq_mul64((uint32_t)(m >> 16), INV_TWO_PI_26) + HALF_26) >> 26);
    int64_t r = (int64_t)m - (int64_t)jq_mul64(n, (uint32_t)TWO_PI_Q);
    if (r > HALF_TURN_Q) {
        r -= TWO_PI_Q;
    }
    return (x < 0) ? -(int32_t)r : (int32_t)r;
}

/* round(s / n), halves away from zero, for a mean known to lie within +-2^31 (|s| < 2^40,
 * 0 < n < 256): by 20-bit halves with 32-bit divisions. */
static int32_t jq_mean_of(int64_t s, uint32_t n)
{
    uint32_t half = n / 2u;
    uint64_t m = jq_mag64(s) + (uint64_t)half;
    uint32_t hi = (uint32_t)(m >> 20);
    uint32_t q_hi = hi / n;
    uint32_t q_lo = (((hi % n) << 20) | ((uint32_t)m & 0xFFFFFu)) / n;
    return jq_signed_of(s < 0, (q_hi << 20) + q_lo);
}

int32_t j288_jointq_lsb_diff(int32_t a, int32_t b)
{
    return jq_as_i32((uint32_t)a - (uint32_t)b);
}


/* |d| rotor LSB as output Q24, rounded (to within 0.5 + |d| / 2^29 steps). */
static uint64_t jq_rotor_to_q24(uint32_t m)
{
    return (jq_mul64(m, Q24_PER_LSB_K) + ((uint64_t)1 << (Q24_PER_LSB_S - 1u))) >> Q24_PER_LSB_S;
}

/* The rotor position within its turn, [0, 2 pi) rotor rad. */
static int32_t jq_rotor_frac(int32_t pos)
{
    uint32_t lsb = (uint32_t)pos & ROTOR_LSB_MASK;
    return (int32_t)jq_mul_frac(lsb, ROTOR_Q24_INT, ROTOR_Q24_FRAC16, 16u);
}

/* The output motion of d rotor LSB modulo 40 pi (20 output turns, which 5767 rotor turns
 * make exactly), within +-20 pi: the start compares angles modulo 2 pi only. */
static int32_t jq_motion_mod(int32_t d)
{
    uint32_t m = jq_mag32(d) % LSB_PER_40PI;
    bool neg = d < 0;
    if (m > (LSB_PER_40PI / 2u)) {
        m = LSB_PER_40PI - m;
        neg = !neg;
    }
    return jq_signed_of(neg, (uint32_t)jq_rotor_to_q24(m));
}

/* t 20-output-turn steps, 40 pi t, in Q24 (|t| < 2^31: within 1 step of the exact value). */
static j288_q24_t jq_forty_pi_times(int32_t t)
{
    uint32_t m = jq_mag32(t);
    uint64_t q = jq_mul64(m, (uint32_t)FORTY_PI_Q) +
                 ((jq_mul64(m, FORTY_PI_FRAC) + 0x80000000u) >> 32);
    return (t < 0) ? -(j288_q24_t)q : (j288_q24_t)q;
}

/* ---- conversions, output side */

j288_q24_t j288_out_pos_to_q(uint16_t out_pos)
{
    uint32_t half_counts = (2u * ((uint32_t)out_pos & COUNT_MASK)) + 1u; /* the centre */
    return (j288_q24_t)jq_mul_frac(half_counts, HALF_COUNT_INT, HALF_COUNT_FRAC17, 17u);
}

j288_q16_t j288_speed_to_q(int16_t raw)
{
    uint32_t m = jq_mag32(raw);
    return jq_signed_of(raw < 0, jq_mul_frac(m, SPEED_Q16_INT, SPEED_Q16_FRAC16, 16u));
}

j288_q16_t j288_torque_to_q(int16_t raw)
{
    uint32_t m = jq_mag32(raw);
    uint32_t r = jq_mul_frac(m, TORQUE_Q16_INT, TORQUE_Q16_FRAC16, 16u);
    return jq_signed_of(raw < 0, jq_ratio_fix(r, m, TORQUE_Q16_NUM, TORQUE_Q16_DEN));
}

/* A command field from Q16, output side: round(m * f) for the factor f (torque 256000 / N,
 * speed 2.56 N / (2 pi), kp 1280000 / N^2, kd 128000000 / N^2, each per 2^16). F = f 2^(k+16)
 * and m < 2^k: jq_mulhi(m << (32 - k), F) is m f in Q16, within 2^-15 LSB of it. Every m >= 2^k
 * is out of the field's range. The rational factors (all but speed's) are then made exact
 * by jq_ratio_fix() with num / den = f. */
#define TAU_F 3723744838u
#define TAU_K 22u
#define TAU_NUM 625u
#define TAU_DEN 46136u
#define SPEED_F 3942120944u
#define SPEED_K 25u
#define KP_F 4132472163u
#define KP_K 28u
#define KP_NUM 15625u
#define KP_DEN 66516578u
#define KD_F 3228493877u
#define KD_K 21u
#define KD_NUM 781250u
#define KD_DEN 33258289u
/* Position, from Q24: 32768 N / (2 pi) / 2^24 = K / 2^51, K = POS_K_HI 2^16 + POS_K_LO. */
#define POS_K_HI 3079781987u
#define POS_K_LO 2983919616u /* 45531 * 2^16: the low 16 bits of K, as a 32-bit fraction */
#define OUT_OF_RANGE 0xFFFFFFFFu

/* round(m f), halves up; OUT_OF_RANGE for m >= 2^k. Inlined: the constants fold. A zero
 * field (a target's speed or torque, often) costs a test only. */
static J288_INLINE_HOT uint32_t jq_scale_field(uint32_t m, uint32_t f, unsigned k, uint32_t num,
                                               uint32_t den)
{
    uint32_t r;
    if (m == 0u) {
        return 0u;
    }
    if (m >= ((uint32_t)1 << k)) {
        return OUT_OF_RANGE;
    }
    r = (jq_mulhi(m << (32u - k), f) + 0x8000u) >> 16;
    return (num != 0u) ? jq_ratio_fix(r, m, num, den) : r;
}

/* The rounded magnitude r with its sign into *out when it fits int16; else saturated in
 * clamp mode (bit into *mask), or err. */
static J288_INLINE_HOT int jq_put16(uint32_t r, bool neg, bool clamp, unsigned bit, int err,
                                    unsigned *mask, int16_t *out)
{
    if (r > (neg ? 32768u : 32767u)) {
        if (!clamp) {
            return err;
        }
        *mask |= bit;
        *out = neg ? INT16_MIN : INT16_MAX;
        return J288_OK;
    }
    *out = (int16_t)jq_signed_of(neg, r);
    return J288_OK;
}

/* A gain: negative is J288_ERR_NEG_GAIN, or 0 with its bit in clamp mode. */
static J288_INLINE_HOT int jq_put_gain(int32_t v, uint32_t r, bool clamp, unsigned bit, int err,
                                       unsigned *mask, int16_t *out)
{
    if (v < 0) {
        if (!clamp) {
            return J288_ERR_NEG_GAIN;
        }
        *mask |= bit;
        *out = 0;
        return J288_OK;
    }
    return jq_put16(r, false, clamp, bit, err, mask, out);
}

/* |dq| Q24 output rad (< 2^32) as rotor LSB, rounded: within 2^-16 LSB of exact. */
static J288_INLINE_HOT int32_t jq_pos_to_raw(uint32_t m, bool neg)
{
    uint64_t p = jq_mul64(m, POS_K_HI) + (uint64_t)jq_mulhi(m, POS_K_LO);
    return jq_signed_of(neg, (uint32_t)((p + ((uint64_t)1 << 34)) >> 35));
}

/* The fields in frame order but the position, the first failure's error: tau and speed with
 * their signs (the direction applied by the caller). */
static J288_INLINE_HOT int jq_fields_to_raw(int32_t tau, bool tau_neg, int32_t speed,
                                            bool speed_neg, int32_t kp, int32_t kd, bool clamp,
                                            j288_cmd_raw_t *r, unsigned *mask)
{
    uint32_t m = jq_mag32(tau);
    int err = jq_put16(jq_scale_field(m, TAU_F, TAU_K, TAU_NUM, TAU_DEN), tau_neg, clamp,
                       J288_FIELD_TAU, J288_ERR_RANGE_TAU, mask, &r->tau);
    if (err == J288_OK) {
        m = jq_mag32(speed);
        err = jq_put16(jq_scale_field(m, SPEED_F, SPEED_K, 0u, 1u), speed_neg, clamp,
                       J288_FIELD_SPEED, J288_ERR_RANGE_SPEED, mask, &r->speed);
    }
    if (err == J288_OK) {
        m = jq_mag32(kp);
        err = jq_put_gain(kp, jq_scale_field(m, KP_F, KP_K, KP_NUM, KP_DEN), clamp,
                          J288_FIELD_KP, J288_ERR_RANGE_KP, mask, &r->kp);
    }
    if (err == J288_OK) {
        m = jq_mag32(kd);
        err = jq_put_gain(kd, jq_scale_field(m, KD_F, KD_K, KD_NUM, KD_DEN), clamp,
                          J288_FIELD_KD, J288_ERR_RANGE_KD, mask, &r->kd);
    }
    return err;
}

/* A position error of the frame order: RANGE_POS comes after tau's and speed's errors, before
 * the gains'. */
static bool jq_before_pos(int err)
{
    return (err == J288_ERR_RANGE_TAU) || (err == J288_ERR_RANGE_SPEED);
}

/* dq (Q24, output side) as rotor LSB added to base, within int32: false when it is not. */
static bool jq_rotor_target(int64_t dq, bool neg, int32_t base, int32_t *pos)
{
    int64_t s;
    if (jq_mag64(dq) >= (uint64_t)Q24_SPAN) {
        return false;
    }
    s = (int64_t)base + (int64_t)jq_pos_to_raw((uint32_t)jq_mag64(dq), (dq < 0) != neg);
    if ((s > (int64_t)INT32_MAX) || (s < (int64_t)INT32_MIN)) {
        return false;
    }
    *pos = (int32_t)s;
    return true;
}

static int jq_cmd_from_q(const j288_cmd_q_t *q, j288_cmd_raw_t *raw, bool clamp, unsigned *clamped)
{
    j288_cmd_raw_t r;
    unsigned mask = 0u;
    int err;

    if ((q == NULL) || (raw == NULL)) {
        return J288_ERR_NULL;
    }
    (void)memset(&r, 0, sizeof r);
    err = jq_fields_to_raw(q->tau, q->tau < 0, q->speed, q->speed < 0, q->kp, q->kd, clamp, &r,
                           &mask);
    if (!jq_before_pos(err) && !jq_rotor_target(q->pos, false, 0, &r.pos)) {
        if (!clamp) {
            return J288_ERR_RANGE_POS;
        }
        mask |= J288_FIELD_POS;
        r.pos = (q->pos < 0) ? INT32_MIN : INT32_MAX;
    }
    if (err != J288_OK) {
        return err;
    }
    r.id = q->id;
    r.status = q->status;
    r.watchdog = q->watchdog;
    *raw = r;
    if (clamped != NULL) {
        *clamped = mask;
    }
    return J288_OK;
}

int j288_cmd_from_q(const j288_cmd_q_t *q, j288_cmd_raw_t *raw)
{
    return jq_cmd_from_q(q, raw, false, NULL);
}

int j288_cmd_from_q_clamped(const j288_cmd_q_t *q, j288_cmd_raw_t *raw, unsigned *clamped)
{
    return jq_cmd_from_q(q, raw, true, clamped);
}

/* ---- configuration */

static bool jq_within(int64_t x, int64_t lo, int64_t hi)
{
    return (x >= lo) && (x <= hi);
}

static void jq_fill_defaults(j288_jointq_config_t *c)
{
    if (c->direction == 0) {
        c->direction = 1;
    }
    if (c->init_samples == 0u) {
        c->init_samples = (uint8_t)J288_JOINT_DEFAULT_INIT_SAMPLES;
    }
    if ((c->pos_min == 0) && (c->pos_max == 0) && !c->continuous) {
        c->pos_min = -PI_Q;
        c->pos_max = PI_Q;
    }
    if (c->track_tol == 0) {
        c->track_tol = J288_JOINTQ_DEFAULT_TRACK_TOL;
    }
    if (c->cal_tol == 0) {
        c->cal_tol = J288_JOINTQ_DEFAULT_CAL_TOL;
    }
}

/* A range, or none for a continuous joint. */
static bool jq_range_ok(const j288_jointq_config_t *c)
{
    if (c->continuous) {
        return (c->pos_min == 0) && (c->pos_max == 0);
    }
    return c->pos_min < c->pos_max;
}

static bool jq_config_ok(const j288_jointq_config_t *c)
{
    const int64_t a = J288_JOINTQ_MAX_ANGLE;
    bool ok = (c->direction == 1) || (c->direction == -1);
    ok = ok && jq_within(c->zero, -a, a) && jq_within(c->pos_min, -a, a);
    ok = ok && jq_within(c->pos_max, -a, a) && jq_range_ok(c);
    ok = ok && (c->max_speed >= 0) && (c->max_torque >= 0) && (c->kp >= 0) && (c->kd >= 0);
    ok = ok && jq_within(c->phase, -TWO_PI_Q, TWO_PI_Q);
    return ok && jq_within(c->track_tol, 0, PI_Q) && jq_within(c->cal_tol, 0, PI_Q);
}

int j288_jointq_check_config(const j288_jointq_config_t *cfg, j288_jointq_config_t *out,
                             j288_q24_t *centre)
{
    j288_jointq_config_t c = *cfg;
    if (c.id > J288_MAX_ID) {
        return J288_ERR_BAD_ID;
    }
    jq_fill_defaults(&c);
    if (!jq_config_ok(&c)) {
        return J288_ERR_BAD_CONFIG;
    }
    *out = c;
    *centre = (c.pos_min + c.pos_max) / 2; /* both within 2^30; 0 for a continuous joint */
    return J288_OK;
}

int j288_jointq_init(j288_jointq_t *j, const j288_jointq_config_t *cfg)
{
    j288_jointq_config_t c;
    j288_q24_t centre;
    int err;

    if ((j == NULL) || (cfg == NULL)) {
        return J288_ERR_NULL;
    }
    /* (padding bytes too: a joint's bytes depend on its configuration alone) */
    (void)memset(&c, 0, sizeof c);
    err = j288_jointq_check_config(cfg, &c, &centre);
    if (err != J288_OK) {
        return err;
    }
    (void)memset(j, 0, sizeof *j);
    j->cfg = c;
    j->centre = centre;
    return J288_OK;
}

void j288_jointq_reset(j288_jointq_t *j)
{
    if (j != NULL) {
        j->seen = false;
        j->live = false;
        j->init_n = 0u;
        (void)memset(&j->st, 0, sizeof j->st);
    }
}

const j288_jointq_config_t *j288_jointq_config(const j288_jointq_t *j)
{
    return (j == NULL) ? NULL : &j->cfg;
}

const j288_jointq_state_t *j288_jointq_state(const j288_jointq_t *j)
{
    return (j == NULL) ? NULL : &j->st;
}

/* ---- replies */

static bool jq_reversed(const j288_jointq_t *j)
{
    return j->cfg.direction < 0;
}

/* x in the joint's direction: x, or -x for a reversed joint. */
static j288_q24_t jq_directed(const j288_jointq_config_t *c, j288_q24_t x)
{
    return (c->direction < 0) ? -x : x;
}

/* The turn choice: the joint angle of output angle theta (any turn, within a few turns of
 * 0) within pi of centre. */
static j288_q24_t jq_label_q(const j288_jointq_config_t *c, j288_q24_t centre, j288_q24_t theta)
{
    return centre + jq_wrap_pi64(jq_directed(c, theta - c->zero) - centre);
}

j288_q24_t j288_jointq_label_theta(const j288_jointq_config_t *c, j288_q24_t centre,
                                   j288_q24_t theta)
{
    return c->zero + jq_directed(c, jq_label_q(c, centre, theta));
}

static void jq_first_sample(j288_jointq_t *j, int32_t pos)
{
    j->init_pos = pos;
    j->init_e0 = (int32_t)j->st.encoder;
    j->init_sum = 0;
    j->init_n = 1u;
}

/* The anchor moved by whole 20-output-turn steps until the rotor's d LSB from it are within
 * ANCHOR_REACH; the d left. Its angle moves by exactly 40 pi a step, so the tracking's base
 * (ref_theta) stays. A saturated step count stops the anchor (at 2.7e11 rad). */
static int32_t jq_move_anchor(j288_jointq_t *j, int32_t d_in)
{
    int32_t d = d_in;
    while ((d > ANCHOR_REACH) && (j->turns < INT32_MAX)) {
        d -= (int32_t)LSB_PER_40PI;
        j->ref_pos = jq_as_i32((uint32_t)j->ref_pos + LSB_PER_40PI);
        j->turns++;
    }
    while ((d < -ANCHOR_REACH) && (j->turns > -INT32_MAX)) {
        d += (int32_t)LSB_PER_40PI;
        j->ref_pos = jq_as_i32((uint32_t)j->ref_pos - LSB_PER_40PI);
        j->turns--;
    }
    j->ref_q = j->start_q + jq_directed(&j->cfg, jq_forty_pi_times(j->turns));
    return d;
}

/* The joint angle of the current reply, and its residual against the encoder. */
static void jq_follow(j288_jointq_t *j, int32_t pos)
{
    int32_t d = j288_jointq_lsb_diff(pos, j->ref_pos);
    int32_t m;

    if ((d > ANCHOR_REACH) || (d < -ANCHOR_REACH)) {
        d = jq_move_anchor(j, d); /* within: |d| <= ANCHOR_REACH */
    }
    m = (int32_t)jq_rotor_to_q24(jq_mag32(d)); /* <= 20 pi */
    m = (d < 0) ? -m : m;                        /* the output's motion since the anchor */
    j->st.pos = j->ref_q + jq_directed(&j->cfg, m);
    j->st.residual =
        j->st.encoder_fault ? 0 : jq_wrap_pi((j->ref_theta - (int32_t)j->st.encoder) + m);
}

/* N |theta| rounded, exactly: 288 theta + 7 theta / 20 (|theta| < 2^31). */
static uint64_t jq_gear_up(uint32_t m)
{
    uint32_t q = m / GEAR_DEN;
    uint32_t r = m % GEAR_DEN;
    uint32_t rest = (GEAR_REST * q) + (((GEAR_REST * r) + (GEAR_DEN / 2u)) / GEAR_DEN);
    return jq_mul64(m, GEAR_INT) + (uint64_t)rest;
}

/* Calibrated start: correct the anchor angle q by eps = N theta + c - p (mod 2 pi). */
static bool jq_apply_phase(j288_jointq_t *j, j288_q24_t *q, unsigned *ev)
{
    j288_q24_t theta = j->cfg.zero + jq_directed(&j->cfg, *q);
    uint64_t rotor;
    int32_t eps;
    int32_t corr;

    /* N theta modulo 2 pi depends on theta modulo 40 pi only; |theta| < 1.1 * 40 pi. */
    if (theta > TWENTY_PI_Q) {
        theta -= FORTY_PI_Q;
    } else if (theta < -(j288_q24_t)TWENTY_PI_Q) {
        theta += FORTY_PI_Q;
    } else {
        /* within */
    }
    rotor = jq_gear_up((uint32_t)jq_mag64(theta)); /* |theta| <= 20 pi: |N theta| < 2^39 */
    eps = jq_wrap_pi64(((theta < 0) ? -(int64_t)rotor : (int64_t)rotor) + j->cfg.phase -
                       jq_rotor_frac(j->init_pos));
    j->st.cal_residual = eps;
    if (jq_mag32(eps) > (uint32_t)j->cfg.cal_tol) {
        if (!j->st.cal_mismatch) {
            *ev |= J288_JOINT_EV_BIT(J288_JOINT_EV_CAL_MISMATCH);
        }
        j->st.cal_mismatch = true;
        return false;
    }
    /* eps / N in output rad: |eps| <= pi, so 20 |eps| < 2^31 */
    corr = jq_signed_of(eps < 0, ((jq_mag32(eps) * GEAR_DEN) + (GEAR_NUM / 2u)) / GEAR_NUM);
    *q -= jq_directed(&j->cfg, corr);
    j->st.calibrated = true;
    return true;
}

static void jq_finish_start(j288_jointq_t *j, int32_t pos, unsigned *ev)
{
    j288_q24_t theta = (j288_q24_t)j->init_e0 + jq_mean_of(j->init_sum, j->init_n);
    j288_q24_t q = jq_label_q(&j->cfg, j->centre, theta);

    j->init_n = 0u;
    if (j->cfg.has_phase && !jq_apply_phase(j, &q, ev)) {
        return;
    }
    j->st.cal_mismatch = false;
    j->ref_pos = j->init_pos;
    j->start_q = q;
    j->ref_q = q;
    j->turns = 0;
    j->ref_theta = jq_wrap_pi64(j->cfg.zero + jq_directed(&j->cfg, q));
    j->st.known = true;
    *ev |= J288_JOINT_EV_BIT(J288_JOINT_EV_ANGLE_KNOWN);
    jq_follow(j, pos);
}

static void jq_start(j288_jointq_t *j, int32_t pos, unsigned *ev)
{
    j->st.residual = 0;
    if (j->st.encoder_fault) {
        j->init_n = 0u; /* the encoder is not trusted: no start from it */
        return;
    }
    if (j->init_n == 0u) {
        jq_first_sample(j, pos);
    } else {
        /* this sample's output angle, moved back by the rotor's motion, against the first */
        int32_t d = jq_wrap_pi(((int32_t)j->st.encoder - j->init_e0) -
                               jq_motion_mod(j288_jointq_lsb_diff(pos, j->init_pos)));
        if (jq_mag32(d) > (uint32_t)j->cfg.track_tol) {
            jq_first_sample(j, pos); /* the samples disagree: begin again from this one */
        } else {
            j->init_sum += d;
            j->init_n++;
        }
    }
    if (j->init_n >= j->cfg.init_samples) {
        jq_finish_start(j, pos, ev);
    }
}

static void jq_track(j288_jointq_t *j, int32_t pos, unsigned *ev)
{
    jq_follow(j, pos);
    if (jq_mag64(j->st.residual) > (uint64_t)j->cfg.track_tol) {
        j->st.known = false;
        j->st.calibrated = false;
        j->st.beyond_limit = false;
        j->init_n = 0u;
        j->live = false;
        *ev |= J288_JOINT_EV_BIT(J288_JOINT_EV_ANGLE_LOST);
    }
}

static void jq_check_limits(j288_jointq_t *j, unsigned *ev)
{
    j288_q24_t q = j->st.pos;
    const j288_q24_t h = J288_JOINTQ_LIMIT_HYST;

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

int j288_jointq_take_reply(j288_jointq_t *j, const j288_reply_raw_t *reply, unsigned *events)
{
    unsigned ev = 0u;
    bool fault;
    j288_q16_t speed;
    j288_q16_t torque;

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
    speed = j288_speed_to_q(reply->speed);
    torque = j288_torque_to_q(reply->torque);
    j->st.speed = jq_reversed(j) ? -speed : speed; /* |.| < 2^25: no overflow */
    j->st.torque = jq_reversed(j) ? -torque : torque;
    j->st.encoder = j288_out_pos_to_q(reply->out_pos);
    j->last_pos = reply->pos;
    if (!j->seen) {
        j->seen = true;
        ev |= J288_JOINT_EV_BIT(J288_JOINT_EV_ANGLE_UNKNOWN);
    }
    if (j->st.known) {
        jq_track(j, reply->pos, &ev);
    } else {
        jq_start(j, reply->pos, &ev);
    }
    if (j->st.known && !j->cfg.continuous) {
        jq_check_limits(j, &ev);
    }
    if (events != NULL) {
        *events = ev;
    }
    return J288_OK;
}

/* ---- targets and commands */

void j288_jointq_target_init(const j288_jointq_t *j, j288_jointq_target_t *t)
{
    if ((j != NULL) && (t != NULL)) {
        j288_q24_t q = j->st.known ? j->st.pos : 0;
        if (!j->cfg.continuous) {
            if ((q > j->cfg.pos_max) && ((q - j->cfg.pos_max) <= J288_JOINTQ_HOLD_BEYOND)) {
                q = j->cfg.pos_max;
            } else if ((q < j->cfg.pos_min) && ((j->cfg.pos_min - q) <= J288_JOINTQ_HOLD_BEYOND)) {
                q = j->cfg.pos_min;
            } else {
                /* inside, or too far beyond to pull in */
            }
        }
        t->pos = q;
        t->speed = 0;
        t->torque = 0;
        t->kp = j->cfg.kp;
        t->kd = j->cfg.kd;
    }
}

/* *x within [lo, hi], or saturated there (bit into *mask) in clamp mode, or err. */
static int jq_limit_one(int32_t *x, int32_t lo, int32_t hi, bool clamp, unsigned bit, int err,
                        unsigned *mask)
{
    if ((*x >= lo) && (*x <= hi)) {
        return J288_OK;
    }
    if (!clamp) {
        return err;
    }
    *x = (*x < lo) ? lo : hi;
    *mask |= bit;
    return J288_OK;
}

/* The target's position within the limits (checked only when kp > 0: with kp = 0 it has no
 * effect, and is 0 from here on), then its speed and torque. A position may be any int64: a
 * continuous joint's is bounded to +-2^62 (far beyond the wire's reach), so that differences
 * to the anchor and the state never overflow. */
static int jq_apply_limits(const j288_jointq_config_t *c, j288_jointq_target_t *t, unsigned *mask)
{
    int err = J288_OK;
    if (t->kp <= 0) {
        t->pos = 0;
    } else if (c->continuous) {
        t->pos = (t->pos > POS_FAR) ? POS_FAR : ((t->pos < -POS_FAR) ? -POS_FAR : t->pos);
    } else if (!jq_within(t->pos, c->pos_min, c->pos_max)) {
        if (!c->clamp) {
            return J288_ERR_LIMIT_POS;
        }
        t->pos = (t->pos < c->pos_min) ? c->pos_min : c->pos_max;
        *mask |= J288_FIELD_POS;
    } else {
        /* within the limits: as given */
    }
    if (c->max_speed > 0) {
        err = jq_limit_one(&t->speed, -c->max_speed, c->max_speed, c->clamp, J288_FIELD_SPEED,
                           J288_ERR_LIMIT_SPEED, mask);
    }
    if ((err == J288_OK) && (c->max_torque > 0)) {
        err = jq_limit_one(&t->torque, -c->max_torque, c->max_torque, c->clamp, J288_FIELD_TAU,
                           J288_ERR_LIMIT_TORQUE, mask);
    }
    return err;
}

/* ---- the limit law (j288/jointq.h, "Soft limits"). Torques in N*m * 2^32 (Q32). */

/* A gain (Q16) times an angle difference (Q24, saturated at +-128 rad), in Q32. */
static int64_t jq_spring(int32_t k, j288_q24_t dx)
{
    int64_t p = jq_gain_times(k, jq_sat32(dx));
    uint64_t m = jq_mag64(p) >> 8;
    return (p < 0) ? -(int64_t)m : (int64_t)m;
}

/* The target's law's push toward hi (or lo) from rest there: T + kp (P - x) + kd V. */
static int64_t jq_push_at(const j288_jointq_target_t *t, int32_t kp, int32_t kd, j288_q24_t x)
{
    return ((int64_t)t->torque * 65536) + jq_spring(kp, t->pos - x) +
           jq_gain_times(kd, t->speed);
}

/* The limit law's damping: the target's, the joint's or the floor, within the wire's range. */
static int32_t jq_limit_kd(const j288_jointq_t *j, int32_t kd)
{
    int32_t k = (kd > j->cfg.kd) ? kd : j->cfg.kd;
    k = (k > J288_JOINTQ_LIMIT_KD) ? k : J288_JOINTQ_LIMIT_KD;
    return (k < LIMIT_KD_MAX) ? k : LIMIT_KD_MAX;
}

/* The limit of the range the target's law drives through and pushes toward harder than the
 * limit law, at the latest angle q and speed w; NULL when none. (At most one: the push at hi
 * is the push at lo minus kp (hi - lo).) */
static const j288_q24_t *jq_limit_hit(const j288_jointq_t *j, const j288_jointq_target_t *t,
                                      int32_t kd_l)
{
    const j288_jointq_state_t *s = &j->st;
    int32_t kp = (t->kp > 0) ? t->kp : 0;
    int32_t kd = (t->kd > 0) ? t->kd : 0;
    int32_t kp_l = kd_l * J288_JOINTQ_LIMIT_RATE;
    bool up = jq_push_at(t, kp, kd, j->cfg.pos_max) > 0;
    bool down = jq_push_at(t, kp, kd, j->cfg.pos_min) < 0;
    int64_t u; /* the target's law minus the limit law's damping term, at (q, w) */

    if (!up && !down) {
        return NULL;
    }
    u = ((int64_t)t->torque * 65536) + jq_spring(kp, t->pos - s->pos) +
        jq_gain_times(kd, jq_sat32((int64_t)t->speed - s->speed)) + jq_gain_times(kd_l, s->speed);
    if (up && (u > jq_spring(kp_l, j->cfg.pos_max - s->pos))) {
        return &j->cfg.pos_max;
    }
    if (down && (u < jq_spring(kp_l, j->cfg.pos_min - s->pos))) {
        return &j->cfg.pos_min;
    }
    return NULL;
}

/* The limit law of limit x: hold at x, speed 0, no feed-forward, kp_L = kd_L * rate (both
 * within the wire's gains: kd_l <= LIMIT_KD_MAX). */
static int jq_limit_command(const j288_jointq_t *j, j288_q24_t x, int32_t kd_l, j288_cmd_raw_t *raw)
{
    uint32_t kd = (uint32_t)kd_l;
    uint32_t kp = kd * (uint32_t)J288_JOINTQ_LIMIT_RATE;
    if (!jq_rotor_target(x - j->ref_q, jq_reversed(j), j->ref_pos, &raw->pos)) {
        return J288_ERR_RANGE_POS;
    }
    raw->tau = 0;
    raw->speed = 0;
    raw->kp = (int16_t)jq_scale_field(kp, KP_F, KP_K, KP_NUM, KP_DEN);
    raw->kd = (int16_t)jq_scale_field(kd, KD_F, KD_K, KD_NUM, KD_DEN);
    return J288_OK;
}

/* A target whose law can push the joint through a limit: its command depends on the state. */
static bool jq_drives_out(const j288_jointq_t *j, const j288_jointq_target_t *t)
{
    return !j->cfg.continuous && ((t->speed != 0) || (t->torque != 0));
}

/* j288_jointq_command(), and *keep: the command is to be made again on every reply. */
static int jq_make_command(const j288_jointq_t *j, const j288_jointq_target_t *t,
                           j288_cmd_raw_t *cmd, unsigned *clamped, bool *keep)
{
    j288_jointq_target_t v;
    j288_cmd_raw_t raw;
    unsigned mask = 0u;
    bool rev;
    int err;

    if ((j == NULL) || (t == NULL) || (cmd == NULL)) {
        return J288_ERR_NULL;
    }
    if (!j->st.known) {
        return j->st.cal_mismatch ? J288_ERR_CAL_MISMATCH : J288_ERR_ANGLE_UNKNOWN;
    }
    v.pos = t->pos; /* field by field: a struct copy is a byte loop on Cortex-M0 */
    v.speed = t->speed;
    v.torque = t->torque;
    v.kp = t->kp;
    v.kd = t->kd;
    raw.kd = 0; /* (set below on every path that uses it: quiets gcc) */
    err = jq_apply_limits(&j->cfg, &v, &mask);
    if (err != J288_OK) {
        return err;
    }
    /* The rotor frame: direction applied, position relative to the anchor. */
    rev = jq_reversed(j);
    err = jq_fields_to_raw(v.torque, (v.torque < 0) != rev, v.speed, (v.speed < 0) != rev, v.kp,
                           v.kd, j->cfg.clamp, &raw, &mask);
    raw.pos = j->last_pos; /* kp <= 0: the position has no effect */
    if (!jq_before_pos(err) && (v.kp > 0) &&
        !jq_rotor_target(v.pos - j->ref_q, rev, j->ref_pos, &raw.pos)) {
        err = J288_ERR_RANGE_POS;
    }
    *keep = (err == J288_OK) && jq_drives_out(j, &v);
    if (*keep) {
        int32_t kd_l = jq_limit_kd(j, v.kd);
        const j288_q24_t *x = jq_limit_hit(j, &v, kd_l);
        if (x != NULL) {
            err = jq_limit_command(j, *x, kd_l, &raw);
            mask |= J288_JOINT_LIMITED;
        }
    }
    if (err != J288_OK) {
        return err;
    }
    cmd->id = j->cfg.id;
    cmd->status = J288_MODE_FOC;
    cmd->watchdog = true;
    cmd->tau = raw.tau;
    cmd->speed = raw.speed;
    cmd->pos = raw.pos;
    cmd->kp = raw.kp;
    cmd->kd = raw.kd;
    if (clamped != NULL) {
        *clamped = mask;
    }
    return J288_OK;
}

int j288_jointq_command(const j288_jointq_t *j, const j288_jointq_target_t *t,
                        j288_cmd_raw_t *cmd, unsigned *clamped)
{
    bool keep;
    return jq_make_command(j, t, cmd, clamped, &keep);
}

int j288_jointq_lock_command(const j288_jointq_t *j, j288_cmd_raw_t *cmd)
{
    if ((j == NULL) || (cmd == NULL)) {
        return J288_ERR_NULL;
    }
    j288_cmd_lock(cmd, j->cfg.id, true);
    return J288_OK;
}

int j288_jointq_zero_here(const j288_jointq_t *j, j288_q24_t *zero)
{
    j288_q24_t z;

    if ((j == NULL) || (zero == NULL)) {
        return J288_ERR_NULL;
    }
    if (!j->st.known) {
        return J288_ERR_ANGLE_UNKNOWN;
    }
    z = j->cfg.zero + jq_directed(&j->cfg, j->st.pos);
    if (!jq_within(z, -(int64_t)J288_JOINTQ_MAX_ANGLE, J288_JOINTQ_MAX_ANGLE)) {
        return J288_ERR_RANGE;
    }
    *zero = z;
    return J288_OK;
}

/* ---- binding */

int j288_jointq_bus_init(j288_jointq_bus_t *jb, j288_sched_t *sched,
                         j288_jointq_event_fn on_event, void *user)
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

static int jq_set_lock(j288_sched_t *sched, uint8_t id, bool watchdog)
{
    j288_cmd_raw_t lock;
    j288_cmd_lock(&lock, id, watchdog);
    return j288_sched_set_cmd(sched, &lock);
}

int j288_jointq_bus_add(j288_jointq_bus_t *jb, j288_jointq_t *j)
{
    uint8_t id;

    if ((jb == NULL) || (j == NULL)) {
        return J288_ERR_NULL;
    }
    id = j->cfg.id; /* 0-14: j288_jointq_init() checked it */
    if ((jb->joint[id] != NULL) && (jb->joint[id] != j)) {
        return J288_ERR_BAD_CONFIG;
    }
    jb->joint[id] = j;
    j->live = false;
    return jq_set_lock(jb->sched, id, true);
}

/* The joint bound under j's id, when that is j itself; else NULL. */
static j288_jointq_t *jq_bound_here(const j288_jointq_bus_t *jb, const j288_jointq_t *j)
{
    if ((j->cfg.id > J288_MAX_ID) || (jb->joint[j->cfg.id] != j)) {
        return NULL;
    }
    return jb->joint[j->cfg.id];
}

int j288_jointq_bus_set_target(j288_jointq_bus_t *jb, const j288_jointq_t *j,
                               const j288_jointq_target_t *t, unsigned *clamped)
{
    j288_jointq_t *bound;
    j288_cmd_raw_t cmd;
    bool keep;
    int err;

    if ((jb == NULL) || (j == NULL)) {
        return J288_ERR_NULL;
    }
    bound = jq_bound_here(jb, j);
    if (bound == NULL) {
        return J288_ERR_BAD_ARG;
    }
    err = jq_make_command(bound, t, &cmd, clamped, &keep);
    if (err != J288_OK) {
        return err;
    }
    bound->live = keep;
    if (keep) {
        bound->live_target = *t;
        bound->live_cmd = cmd;
    }
    return j288_sched_set_cmd(jb->sched, &cmd);
}

int j288_jointq_bus_lock(j288_jointq_bus_t *jb, const j288_jointq_t *j)
{
    j288_jointq_t *bound;

    if ((jb == NULL) || (j == NULL)) {
        return J288_ERR_NULL;
    }
    bound = jq_bound_here(jb, j);
    if (bound == NULL) {
        return J288_ERR_BAD_ARG;
    }
    bound->live = false;
    return jq_set_lock(jb->sched, j->cfg.id, true);
}

static j288_q24_t jq_event_value(const j288_jointq_t *j, j288_joint_event_kind_t kind)
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
        return 0;
    }
}

/* The events in J288_JOINT_EV_* order: the kinds' values are that order. */
static void jq_report(const j288_jointq_bus_t *jb, const j288_jointq_t *j, unsigned events)
{
    j288_jointq_event_t ev;
    unsigned i;

    if (jb->on_event == NULL) {
        return;
    }
    ev.id = j->cfg.id;
    ev.joint = j;
    for (i = 0u; i < J288_JOINT_EV_COUNT; i++) {
        if ((events & (1u << i)) != 0u) {
            ev.kind = (j288_joint_event_kind_t)i;
            ev.value = jq_event_value(j, ev.kind);
            jb->on_event(jb->user, &ev);
        }
    }
}

/* The slot still holds the command the binding made (field by field: padding differs). */
static bool jq_same_cmd(const j288_cmd_raw_t *a, const j288_cmd_raw_t *b)
{
    return (a->status == b->status) && (a->pos == b->pos) && (a->tau == b->tau) &&
           (a->speed == b->speed) && (a->kp == b->kp) && (a->kd == b->kd) &&
           (a->watchdog == b->watchdog);
}

void j288_jointq_after_reply(j288_jointq_bus_t *jb, j288_jointq_t *j, const j288_slot_t *slot,
                             unsigned events)
{
    uint8_t id = j->cfg.id;
    if (!j->st.known) {
        j->live = false;
        if (slot->cmd.status != J288_MODE_LOCK) {
            (void)jq_set_lock(jb->sched, id, slot->cmd.watchdog); /* valid: never refused */
        }
    } else if (j->live && jq_same_cmd(&slot->cmd, &j->live_cmd)) {
        bool keep;
        if (jq_make_command(j, &j->live_target, &j->live_cmd, NULL, &keep) == J288_OK) {
            (void)j288_sched_set_cmd(jb->sched, &j->live_cmd); /* ours: never refused */
        } else {
            j->live = false;
            (void)jq_set_lock(jb->sched, id, true);
        }
    } else {
        j->live = false; /* no kept target, or another command took the slot */
    }
    jq_report(jb, j, events);
}

void j288_jointq_bus_on_reply(void *user, uint8_t id, const j288_slot_t *slot)
{
    j288_jointq_bus_t *jb = (j288_jointq_bus_t *)user; /* the scheduler hands back our own */
    j288_jointq_t *j;
    unsigned events = 0u;

    if ((jb == NULL) || (slot == NULL) || (id > J288_MAX_ID)) {
        return;
    }
    j = jb->joint[id];
    if ((j == NULL) || (j288_jointq_take_reply(j, &slot->reply, &events) != J288_OK)) {
        return;
    }
    j288_jointq_after_reply(jb, j, slot, events);
}
