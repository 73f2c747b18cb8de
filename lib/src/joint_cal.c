/* The phase fit (j288_cal_*): the rotor phase c of a joint from (OutPos, rotor position)
 * pairs, in j288_real_t (it runs on a host); the contract is in j288/joint.h. The first pair
 * is labelled by the joint core's own turn choice, so that c belongs to the labelling the
 * core's calibrated start uses. */
#include "j288/joint.h"

#if J288_CONFIG_SI

#include <string.h>

#include "jointq_priv.h"

#define N_RATIO ((j288_real_t)J288_GEAR_RATIO)
#define TWO_PI ((j288_real_t)(2.0 * J288_PI))
#define INV_TWO_PI ((j288_real_t)(1.0 / (2.0 * J288_PI)))
#define HALF ((j288_real_t)0.5)
#define ZERO ((j288_real_t)0)
/* Output rad per OutPos count; rotor rad per position LSB. */
#define OUT_RAD_PER_COUNT ((j288_real_t)(2.0 * J288_PI / (double)J288_OUT_POS_COUNTS))
#define ROTOR_RAD_PER_LSB ((j288_real_t)(2.0 * J288_PI / 32768.0))
#define ROTOR_LSB_MASK 0x7FFFu /* position LSB within one rotor turn */
#define COUNT_MASK (J288_OUT_POS_COUNTS - 1u)
#define HALF_TURN_COUNTS 4096
#define TURN_COUNTS 8192
/* The continued count stays within this (65536 output turns), far from int32's end. */
#define CONT_LIMIT 0x20000000

/* x - 2 pi n for the nearest integer n: [-pi, pi]. |x| is far below 2^31 turns here. */
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

/* The rotor position within its turn, [0, 2 pi): exact from the integer. */
static j288_real_t rotor_frac(int32_t pos)
{
    uint32_t lsb = (uint32_t)pos & ROTOR_LSB_MASK;
    return (j288_real_t)lsb * ROTOR_RAD_PER_LSB;
}

int j288_cal_init(j288_cal_t *cal, const j288_joint_config_t *cfg)
{
    static const j288_joint_config_t defaults = {0};
    j288_joint_t j;
    int err;

    if (cal == NULL) {
        return J288_ERR_NULL;
    }
    err = j288_joint_init(&j, (cfg != NULL) ? cfg : &defaults);
    if (err != J288_OK) {
        return err;
    }
    (void)memset(cal, 0, sizeof *cal);
    cal->label = *j288_jointq_config_of(&j.core);
    cal->centre = j288_jointq_centre(&j.core);
    cal->cal_tol = j.cfg.cal_tol;
    return J288_OK;
}

/* The first pair: its labelled output angle fixes the turns of all later ones. */
static void cal_first(j288_cal_t *cal, uint16_t count, int32_t pos)
{
    j288_q24_t theta = j288_jointq_label_theta(&cal->label, cal->centre, j288_out_pos_to_q(count));

    cal->first_pos = pos;
    cal->first_v = wrap_pi(rotor_frac(pos) - (N_RATIO * j288_joint_real_of_q24(theta)));
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
    y = (j288_real_t)j288_jointq_lsb_diff(rotor_pos, cal->first_pos) * ROTOR_RAD_PER_LSB;
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
typedef int j288_joint_cal_disabled_t;
#endif /* J288_CONFIG_SI */
