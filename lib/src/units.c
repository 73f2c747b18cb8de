/* SI <-> raw conversions; see j288/units.h for the contract. */
#include "j288/units.h"

#if J288_CONFIG_SI

#include <stdint.h>
#include <string.h>

#include "hints.h"

#define N_RATIO ((j288_real_t)J288_GEAR_RATIO)

typedef enum { Q_TORQUE, Q_SPEED, Q_POS, Q_KP, Q_KD } quantity_t;

/* LSB per SI unit on the requested side (J288_SIDE_ROTOR or J288_SIDE_OUTPUT, checked by
 * every caller). Rotor angle = N * output angle, rotor torque = output torque / N, rotor
 * gains = output gains / N^2. A table of constants: converting a whole command looks each
 * factor up instead of computing it (a division each on the output side). */
static j288_real_t lsb_per_unit(quantity_t q, j288_side_t side)
{
    static const j288_real_t k[2][5] = {
        {(j288_real_t)J288_SCALE_TORQUE, (j288_real_t)J288_SCALE_SPEED,
         (j288_real_t)J288_SCALE_POS, (j288_real_t)J288_SCALE_KP, (j288_real_t)J288_SCALE_KD},
        {(j288_real_t)J288_SCALE_TORQUE / N_RATIO, (j288_real_t)J288_SCALE_SPEED * N_RATIO,
         (j288_real_t)J288_SCALE_POS * N_RATIO, (j288_real_t)J288_SCALE_KP / (N_RATIO * N_RATIO),
         (j288_real_t)J288_SCALE_KD / (N_RATIO * N_RATIO)}};
    return k[(side == J288_SIDE_OUTPUT) ? 1 : 0][q];
}

static bool side_ok(j288_side_t side)
{
    return (side == J288_SIDE_ROTOR) || (side == J288_SIDE_OUTPUT);
}

/*
 * Round a magnitude a >= 0 half away from zero into *mag, without libm: the fraction
 * a - trunc(a) is exact. Only 32-bit conversions are used, which FPUs do in hardware (a 64-bit
 * one would pull in library code on a Cortex-M4F). false: the result exceeds 2^31, outside
 * every field. The caller keeps a below 2^31 + 2, where a - 2^31 is exact.
 */
static bool round_magnitude(j288_real_t a, uint32_t *mag)
{
    const j288_real_t two31 = (j288_real_t)2147483648.0;
    uint32_t t;
    if (a >= two31) {
        if ((a - two31) < (j288_real_t)0.5) {
            *mag = 0x80000000u;
            return true;
        }
        return false;
    }
    t = (uint32_t)a;
    if ((a - (j288_real_t)t) >= (j288_real_t)0.5) {
        t++;
    }
    *mag = t;
    return true;
}

/* Below this magnitude v +- 1/2 is exact in float (and in double), so that truncating it
 * rounds v half away from zero: one conversion. Every 16-bit field's window lies below it. */
#define ROUND_FAST_LIMIT ((j288_real_t)8388608.0) /* 2^23 */

/* v rounded half away from zero into [lo, hi], |v| < ROUND_FAST_LIMIT. */
static J288_INLINE_HOT bool round_fast(j288_real_t v, int32_t lo, int32_t hi, int32_t *out)
{
    j288_real_t h = (v < (j288_real_t)0) ? (v - (j288_real_t)0.5) : (v + (j288_real_t)0.5);
    int32_t r = (int32_t)h;
    if ((r < lo) || (r > hi)) {
        return false;
    }
    *out = r;
    return true;
}

/* The same for the 32-bit field beyond ROUND_FAST_LIMIT (v within [INT32_MIN - 1,
 * INT32_MAX + 1]), by magnitude. */
static bool round_into32(j288_real_t v, int32_t lo, int32_t hi, int32_t *out)
{
    bool neg = v < (j288_real_t)0;
    /* largest magnitude allowed on this side; -(lo + 1) + 1 avoids negating INT32_MIN */
    uint32_t limit = neg ? ((uint32_t)(-(lo + 1)) + 1u) : (uint32_t)hi;
    uint32_t mag = 0u;

    if (!round_magnitude(neg ? -v : v, &mag) || (mag > limit)) {
        return false;
    }
    if (!neg) {
        *out = (int32_t)mag;
    } else if (mag == 0x80000000u) {
        *out = INT32_MIN;
    } else {
        *out = -(int32_t)mag;
    }
    return true;
}

/* v rounded half away from zero, when the result lies in [lo, hi] (lo < 0 < hi). */
static J288_INLINE_HOT bool round_into(j288_real_t v, int32_t lo, int32_t hi, int32_t *out)
{
    /* A coarse window first: catches NaN and infinities and keeps the conversions defined.
     * Exactly half past a limit rounds away from zero, out of range, and is caught by the
     * integer test; comparing v against lo - 0.5 would be wrong in float, where that is not
     * representable for int32. A 16-bit field's window is symmetric, |v| <= 32769: one test
     * of the magnitude. */
    if (hi <= INT16_MAX) {
        j288_real_t a = (v < (j288_real_t)0) ? -v : v;
        if (!(a <= (j288_real_t)32769)) {
            return false;
        }
        return round_fast(v, lo, hi, out);
    }
    if (!((v >= ((j288_real_t)lo - (j288_real_t)1)) && (v <= ((j288_real_t)hi + (j288_real_t)1)))) {
        return false;
    }
    if ((v > -ROUND_FAST_LIMIT) && (v < ROUND_FAST_LIMIT)) {
        return round_fast(v, lo, hi, out);
    }
    return round_into32(v, lo, hi, out);
}

/* round_into() for a gain, v >= 0 (or NaN): the window and the rounding need no sign. */
static J288_INLINE_HOT bool round_gain(j288_real_t v, int32_t hi, int32_t *out)
{
    int32_t r;
    if (!(v <= ((j288_real_t)hi + (j288_real_t)1))) {
        return false;
    }
    r = (int32_t)(v + (j288_real_t)0.5);
    if (r > hi) {
        return false;
    }
    *out = r;
    return true;
}

/*
 * Scale and round one quantity into [lo, hi]. Returns J288_OK, J288_ERR_NOT_FINITE, or
 * range_err; with clamp set, out-of-range values saturate and *was_clamped is set instead.
 * Inlined where a whole command is converted: the quantity, the limits and the error are
 * constants there.
 */
static J288_INLINE_HOT int convert(j288_real_t si, quantity_t q, j288_side_t side, int32_t lo,
                                   int32_t hi, int range_err, bool clamp, bool *was_clamped,
                                   int32_t *out)
{
    j288_real_t v;
    int32_t r = 0;
    bool is_gain = (q == Q_KP) || (q == Q_KD);

    if (is_gain && (si < (j288_real_t)0)) { /* (false for NaN) */
        if (!clamp) {
            return J288_ERR_NEG_GAIN;
        }
        *was_clamped = true;
        *out = 0;
        return J288_OK;
    }
    v = si * lsb_per_unit(q, side);
    /* NaN fails every window: it is told apart only here */
    if (!(is_gain ? round_gain(v, hi, &r) : round_into(v, lo, hi, &r))) {
        if (si != si) {
            return J288_ERR_NOT_FINITE;
        }
        if (!clamp) {
            return range_err;
        }
        *was_clamped = true;
        *out = (v < (j288_real_t)0) ? lo : hi;
        return J288_OK;
    }
    *out = r;
    return J288_OK;
}

static J288_INLINE_HOT int convert16(j288_real_t si, quantity_t q, j288_side_t side,
                                     int range_err, bool clamp, bool *was_clamped,
                                     int16_t *out)
{
    int32_t v = 0;
    int err = convert(si, q, side, INT16_MIN, INT16_MAX, range_err, clamp, was_clamped, &v);
    if (err == J288_OK) {
        *out = (int16_t)v;
    }
    return err;
}

/* Inlined in both public callers, clamp a constant in each. */
static J288_INLINE_HOT int cmd_from_si(const j288_cmd_si_t *si, j288_side_t side,
                                       j288_cmd_raw_t *raw, bool clamp, unsigned *clamped)
{
    j288_cmd_raw_t r;
    bool c[5] = {false, false, false, false, false};
    int err;

    (void)memset(&r, 0, sizeof r); /* padding included: *raw gets a whole, defined record */

    if ((si == NULL) || (raw == NULL)) {
        return J288_ERR_NULL;
    }
    if (!side_ok(side)) {
        return J288_ERR_BAD_ARG;
    }
    err = convert16(si->tau, Q_TORQUE, side, J288_ERR_RANGE_TAU, clamp, &c[0], &r.tau);
    if (err == J288_OK) {
        err = convert16(si->speed, Q_SPEED, side, J288_ERR_RANGE_SPEED, clamp, &c[1], &r.speed);
    }
    if (err == J288_OK) {
        err = convert(si->pos, Q_POS, side, INT32_MIN, INT32_MAX, J288_ERR_RANGE_POS, clamp,
                      &c[2], &r.pos);
    }
    if (err == J288_OK) {
        err = convert16(si->kp, Q_KP, side, J288_ERR_RANGE_KP, clamp, &c[3], &r.kp);
    }
    if (err == J288_OK) {
        err = convert16(si->kd, Q_KD, side, J288_ERR_RANGE_KD, clamp, &c[4], &r.kd);
    }
    if (err != J288_OK) {
        return err;
    }
    if (clamped != NULL) {
        *clamped = (c[0] ? J288_FIELD_TAU : 0u) | (c[1] ? J288_FIELD_SPEED : 0u) |
                   (c[2] ? J288_FIELD_POS : 0u) | (c[3] ? J288_FIELD_KP : 0u) |
                   (c[4] ? J288_FIELD_KD : 0u);
    }
    r.id = si->id;
    r.status = si->status;
    r.watchdog = si->watchdog;
    *raw = r; /* only now: untouched on an error */
    return J288_OK;
}

int j288_cmd_from_si(const j288_cmd_si_t *si, j288_side_t side, j288_cmd_raw_t *raw)
{
    return cmd_from_si(si, side, raw, false, NULL);
}

int j288_cmd_from_si_clamped(const j288_cmd_si_t *si, j288_side_t side, j288_cmd_raw_t *raw,
                             unsigned *clamped)
{
    return cmd_from_si(si, side, raw, true, clamped);
}

int j288_cmd_encode_si(const j288_cmd_si_t *si, j288_side_t side, uint8_t out[J288_CMD_LEN],
                       const j288_crc_t *crc)
{
    j288_cmd_raw_t raw;
    int err = j288_cmd_from_si(si, side, &raw);
    if (err != J288_OK) {
        return err;
    }
    return j288_cmd_encode(&raw, out, crc);
}

static int one16(j288_real_t si, quantity_t q, j288_side_t side, int range_err, int16_t *raw)
{
    bool unused = false;
    if (raw == NULL) {
        return J288_ERR_NULL;
    }
    if (!side_ok(side)) {
        return J288_ERR_BAD_ARG;
    }
    return convert16(si, q, side, range_err, false, &unused, raw);
}

int j288_torque_to_raw(j288_real_t nm, j288_side_t side, int16_t *raw)
{
    return one16(nm, Q_TORQUE, side, J288_ERR_RANGE_TAU, raw);
}

int j288_speed_to_raw(j288_real_t rad_s, j288_side_t side, int16_t *raw)
{
    return one16(rad_s, Q_SPEED, side, J288_ERR_RANGE_SPEED, raw);
}

int j288_kp_to_raw(j288_real_t nm_per_rad, j288_side_t side, int16_t *raw)
{
    return one16(nm_per_rad, Q_KP, side, J288_ERR_RANGE_KP, raw);
}

int j288_kd_to_raw(j288_real_t nms_per_rad, j288_side_t side, int16_t *raw)
{
    return one16(nms_per_rad, Q_KD, side, J288_ERR_RANGE_KD, raw);
}

int j288_pos_to_raw(j288_real_t rad, j288_side_t side, int32_t *raw)
{
    bool unused = false;
    if (raw == NULL) {
        return J288_ERR_NULL;
    }
    if (!side_ok(side)) {
        return J288_ERR_BAD_ARG;
    }
    return convert(rad, Q_POS, side, INT32_MIN, INT32_MAX, J288_ERR_RANGE_POS, false, &unused,
                   raw);
}

static j288_real_t from_raw(int32_t raw, quantity_t q, j288_side_t side)
{
    return (j288_real_t)raw / lsb_per_unit(q, side_ok(side) ? side : J288_SIDE_ROTOR);
}

j288_real_t j288_torque_from_raw(int32_t raw, j288_side_t side)
{
    return from_raw(raw, Q_TORQUE, side);
}

j288_real_t j288_speed_from_raw(int32_t raw, j288_side_t side)
{
    return from_raw(raw, Q_SPEED, side);
}

j288_real_t j288_pos_from_raw(int32_t raw, j288_side_t side) { return from_raw(raw, Q_POS, side); }

j288_real_t j288_kp_from_raw(int32_t raw, j288_side_t side) { return from_raw(raw, Q_KP, side); }

j288_real_t j288_kd_from_raw(int32_t raw, j288_side_t side) { return from_raw(raw, Q_KD, side); }

j288_real_t j288_out_pos_to_rad(uint16_t out_pos)
{
    unsigned counts = (unsigned)out_pos & (J288_OUT_POS_COUNTS - 1u);
    return (j288_real_t)counts *
           (j288_real_t)(2.0 * J288_PI / (double)J288_OUT_POS_COUNTS);
}

int j288_reply_to_si(const j288_reply_raw_t *raw, j288_side_t side, j288_reply_si_t *si)
{
    if ((raw == NULL) || (si == NULL)) {
        return J288_ERR_NULL;
    }
    if (!side_ok(side)) {
        return J288_ERR_BAD_ARG;
    }
    si->id = raw->id;
    si->status = raw->status;
    si->watchdog_tripped = raw->watchdog_tripped;
    si->case_temp_c = (j288_real_t)raw->case_temp_c;
    si->winding_temp_c = (j288_real_t)raw->winding_temp_c;
    si->voltage_v = (j288_real_t)raw->voltage_raw * (j288_real_t)J288_SCALE_VOLTAGE;
    si->torque = j288_torque_from_raw(raw->torque, side);
    si->speed = j288_speed_from_raw(raw->speed, side);
    si->pos = j288_pos_from_raw(raw->pos, side);
    si->out_pos = j288_out_pos_to_rad(raw->out_pos);
    si->faults = raw->faults;
    si->warnings = raw->warnings;
    return J288_OK;
}

int j288_cmd_to_si(const j288_cmd_raw_t *raw, j288_side_t side, j288_cmd_si_t *si)
{
    if ((raw == NULL) || (si == NULL)) {
        return J288_ERR_NULL;
    }
    if (!side_ok(side)) {
        return J288_ERR_BAD_ARG;
    }
    si->id = raw->id;
    si->status = raw->status;
    si->watchdog = raw->watchdog;
    si->tau = j288_torque_from_raw(raw->tau, side);
    si->speed = j288_speed_from_raw(raw->speed, side);
    si->pos = j288_pos_from_raw(raw->pos, side);
    si->kp = j288_kp_from_raw(raw->kp, side);
    si->kd = j288_kd_from_raw(raw->kd, side);
    return J288_OK;
}

#else
/* ISO C forbids an empty translation unit. */
typedef int j288_units_disabled_t;
#endif /* J288_CONFIG_SI */
