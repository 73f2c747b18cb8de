/*
 * Fuzz target: SI <-> raw conversions (units.h), with arbitrary doubles (NaN, infinities,
 * subnormals, huge values) and arbitrary raw integers.
 *
 * Input: byte 0 = flags (bit 0: output side; bit 1: raw -> SI -> raw case), then five 8-byte
 * values (doubles, or raw fields).
 *
 * Invariants:
 * - j288_cmd_from_si: NaN gives J288_ERR_NOT_FINITE, a negative gain J288_ERR_NEG_GAIN, a value
 *   that does not round into its field J288_ERR_RANGE_<field> (checked against scale factors
 *   written here from the spec, with a tiny tolerance at the rounding edges); on success
 *   every field is within half an LSB of value * scale. Errors leave the output untouched.
 * - the clamped variant never fails on a finite value; it sets a field's bit exactly when the
 *   strict conversion fails for that field, gives the strict result for the others and the
 *   field's limit (0 for a negative gain) for the clamped ones.
 * - raw -> SI -> raw is exact for every command with non-negative gains, on either side.
 */
#include "fuzz_common.h"

#include "j288/units.h"

#include <math.h>
#include <string.h>

#if J288_CONFIG_SI && !J288_CONFIG_SI_FLOAT

#define TWO_PI (2.0 * 3.14159265358979323846)
#define RATIO 288.35

/* LSB per SI unit, written from the spec's table. */
static double scale(int field, int output)
{
    static const double rotor[5] = {256000.0, 2.56 / TWO_PI, 32768.0 / TWO_PI, 1280000.0,
                                    128000000.0};
    double k = rotor[field];
    if (output) {
        if (field == 1 || field == 2) {
            k *= RATIO;
        } else if (field == 0) {
            k /= RATIO;
        } else {
            k /= RATIO * RATIO;
        }
    }
    return k;
}

static const int range_err[5] = {J288_ERR_RANGE_TAU, J288_ERR_RANGE_SPEED, J288_ERR_RANGE_POS,
                                 J288_ERR_RANGE_KP, J288_ERR_RANGE_KD};

/* 1: fits for sure, 0: out for sure, -1: too close to the edge to judge. */
static int fits(double v, double lo, double hi)
{
    double tol;
    if (isinf(v)) {
        return 0;
    }
    tol = 1e-9 * (fabs(v) + 1.0);
    if (v >= lo - 0.5 + tol && v < hi + 0.5 - tol) {
        return 1;
    }
    if (v < lo - 0.5 - tol || v >= hi + 0.5 + tol) {
        return 0;
    }
    return -1;
}

static double get_double(fuzz_in_t *in)
{
    uint8_t b[8];
    double d;
    size_t i;
    for (i = 0; i < 8u; i++) {
        b[i] = fuzz_u8(in);
    }
    memcpy(&d, b, sizeof d);
    return d;
}

static int32_t raw_field(const j288_cmd_raw_t *r, int field)
{
    switch (field) {
    case 0: return r->tau;
    case 1: return r->speed;
    case 2: return r->pos;
    case 3: return r->kp;
    default: return r->kd;
    }
}

static void case_from_si(fuzz_in_t *in, int output)
{
    j288_cmd_si_t si;
    j288_cmd_raw_t raw, clamped_raw, before;
    double val[5];
    int expect[5];
    int first_err = J288_OK, judged = 1;
    unsigned clamped = 0xFFFFu;
    int rc, f;
    j288_side_t side = output ? J288_SIDE_OUTPUT : J288_SIDE_ROTOR;

    memset(&si, 0, sizeof si);
    for (f = 0; f < 5; f++) {
        val[f] = get_double(in);
    }
    si.id = 3u;
    si.status = 1u;
    si.tau = val[0];
    si.speed = val[1];
    si.pos = val[2];
    si.kp = val[3];
    si.kd = val[4];
    for (f = 0; f < 5; f++) {
        double lo = (f == 2) ? -2147483648.0 : -32768.0;
        double hi = (f == 2) ? 2147483647.0 : 32767.0;
        if (isnan(val[f])) {
            expect[f] = J288_ERR_NOT_FINITE;
        } else if (f >= 3 && val[f] < 0.0) {
            expect[f] = J288_ERR_NEG_GAIN;
        } else {
            int k = fits(val[f] * scale(f, output), lo, hi);
            if (k < 0) {
                judged = 0;
            }
            expect[f] = (k == 0) ? range_err[f] : J288_OK;
        }
        if (first_err == J288_OK) {
            first_err = expect[f];
        }
    }
    memset(&raw, 0x3C, sizeof raw);
    memcpy(&before, &raw, sizeof raw);
    rc = j288_cmd_from_si(&si, side, &raw);
    if (judged) {
        FUZZ_CHECK(rc == first_err);
    }
    if (rc != J288_OK) {
        FUZZ_CHECK(memcmp(&raw, &before, sizeof raw) == 0);
    } else {
        FUZZ_CHECK(raw.id == 3u && raw.status == 1u);
        for (f = 0; f < 5; f++) {
            double want = val[f] * scale(f, output);
            FUZZ_CHECK(fabs((double)raw_field(&raw, f) - want) <= 0.5 + 1e-9 * (fabs(want) + 1.0));
        }
    }

    rc = j288_cmd_from_si_clamped(&si, side, &clamped_raw, &clamped);
    for (f = 0; f < 5; f++) {
        if (isnan(val[f])) {
            FUZZ_CHECK(rc == J288_ERR_NOT_FINITE);
            return;
        }
    }
    FUZZ_CHECK(rc == J288_OK);
    FUZZ_CHECK(clamped < 32u);
    for (f = 0; f < 5; f++) {
        int32_t v = raw_field(&clamped_raw, f);
        int32_t lo = (f == 2) ? INT32_MIN : INT16_MIN;
        int32_t hi = (f == 2) ? INT32_MAX : INT16_MAX;
        unsigned bit = 1u << f;
        if (!judged) {
            continue;
        }
        if (expect[f] == J288_OK) {
            double want = val[f] * scale(f, output);
            FUZZ_CHECK((clamped & bit) == 0u);
            FUZZ_CHECK(fabs((double)v - want) <= 0.5 + 1e-9 * (fabs(want) + 1.0));
        } else if (expect[f] == J288_ERR_NEG_GAIN) {
            FUZZ_CHECK((clamped & bit) != 0u && v == 0);
        } else {
            FUZZ_CHECK((clamped & bit) != 0u);
            FUZZ_CHECK(v == ((val[f] < 0.0) ? lo : hi));
        }
    }
    FUZZ_CHECK(j288_cmd_from_si_clamped(&si, side, &clamped_raw, NULL) == J288_OK);
}

static void case_round_trip(fuzz_in_t *in, int output)
{
    j288_cmd_raw_t raw, back;
    j288_cmd_si_t si;
    j288_reply_raw_t rr;
    j288_reply_si_t rsi;
    j288_side_t side = output ? J288_SIDE_OUTPUT : J288_SIDE_ROTOR;

    memset(&raw, 0, sizeof raw);
    raw.id = (uint8_t)(fuzz_u8(in) & 15u);
    raw.status = (uint8_t)(fuzz_u8(in) & 1u);
    raw.tau = (int16_t)fuzz_s16(fuzz_u16(in));
    raw.speed = (int16_t)fuzz_s16(fuzz_u16(in));
    raw.pos = (int32_t)fuzz_s32(fuzz_u32(in));
    raw.kp = (int16_t)(fuzz_u16(in) & 0x7FFFu);
    raw.kd = (int16_t)(fuzz_u16(in) & 0x7FFFu);
    FUZZ_CHECK(j288_cmd_to_si(&raw, side, &si) == J288_OK);
    FUZZ_CHECK(j288_cmd_from_si(&si, side, &back) == J288_OK);
    FUZZ_CHECK(back.id == raw.id && back.status == raw.status);
    FUZZ_CHECK(back.tau == raw.tau && back.speed == raw.speed && back.pos == raw.pos);
    FUZZ_CHECK(back.kp == raw.kp && back.kd == raw.kd);

    /* Any reply converts to finite values; the output encoder angle lies in [0, 2 pi). */
    memset(&rr, 0, sizeof rr);
    rr.torque = raw.tau;
    rr.speed = raw.speed;
    rr.pos = raw.pos;
    rr.out_pos = fuzz_u16(in); /* beyond 13 bits on purpose: the library masks */
    rr.voltage_raw = fuzz_u8(in);
    FUZZ_CHECK(j288_reply_to_si(&rr, side, &rsi) == J288_OK);
    FUZZ_CHECK(isfinite(rsi.torque) && isfinite(rsi.speed) && isfinite(rsi.pos));
    FUZZ_CHECK(rsi.out_pos >= 0.0 && rsi.out_pos < TWO_PI);
    FUZZ_CHECK(rsi.voltage_v >= 0.0 && rsi.voltage_v <= 127.5);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fuzz_in_t in;
    if (size < 1u) {
        return 0;
    }
    in.p = &data[1];
    in.n = size - 1u;
    if ((data[0] & 2u) != 0u) {
        case_round_trip(&in, data[0] & 1u);
    } else {
        case_from_si(&in, data[0] & 1u);
    }
    return 0;
}

#else
/* Built without the double SI API: nothing to fuzz. */
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    (void)data;
    (void)size;
    return 0;
}
#endif
