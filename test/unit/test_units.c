/* SI units: golden conversions, round trips, the gear-ratio rules, every rejection and the
 * saturating variant. Meaningful on double builds (exact) and on float builds
 * (J288_CONFIG_SI_FLOAT=1, e.g. Cortex-M4F), where tolerances follow single precision. */
#include "unity.h"

#include "codec_support.h"
#include "j288/units.h"

#include <math.h>
#include <string.h>

void setUp(void) {}
void tearDown(void) {}

#if J288_CONFIG_SI

#define GOLDEN_WANT_SI
#define GOLDEN_WANT_SI_COMMANDS
#define GOLDEN_WANT_COMMANDS
#include "golden_vectors.h"

#if J288_CONFIG_SI_FLOAT
#define IS_FLOAT 1
#define REL_TOL  1e-6 /* a few float roundings */
#else
#define IS_FLOAT 0
#define REL_TOL  1e-12
#endif

#define N_GEAR ((double)J288_GEAR_RATIO)
static const j288_side_t sides[2] = {J288_SIDE_ROTOR, J288_SIDE_OUTPUT};
static const j288_side_t bad_side = (j288_side_t)2;

/* LSB per unit, computed here from the definitions (in double, whatever the build). */
static double lsb(int q, j288_side_t side)
{
    static const double rotor[5] = {256000.0, 2.56 / (2.0 * 3.14159265358979323846),
                                    32768.0 / (2.0 * 3.14159265358979323846), 1280000.0,
                                    128000000.0};
    double k = rotor[q];
    if (side == J288_SIDE_OUTPUT) {
        if (q == GOLDEN_Q_SPEED || q == GOLDEN_Q_POS) {
            k *= N_GEAR;
        } else if (q == GOLDEN_Q_TORQUE) {
            k /= N_GEAR;
        } else {
            k /= N_GEAR * N_GEAR;
        }
    }
    return k;
}

/* One quantity through the single-value API; raw is 32-bit for all of them. */
static int to_raw(int q, j288_real_t v, j288_side_t side, int32_t *raw)
{
    int16_t r16;
    int rc;
    if (q == GOLDEN_Q_POS) {
        return j288_pos_to_raw(v, side, raw);
    }
    r16 = (int16_t)*raw;
    switch (q) {
    case GOLDEN_Q_TORQUE:
        rc = j288_torque_to_raw(v, side, &r16);
        break;
    case GOLDEN_Q_SPEED:
        rc = j288_speed_to_raw(v, side, &r16);
        break;
    case GOLDEN_Q_KP:
        rc = j288_kp_to_raw(v, side, &r16);
        break;
    default:
        rc = j288_kd_to_raw(v, side, &r16);
        break;
    }
    *raw = r16;
    return rc;
}

static double from_raw(int q, int32_t raw, j288_side_t side)
{
    switch (q) {
    case GOLDEN_Q_TORQUE:
        return (double)j288_torque_from_raw(raw, side);
    case GOLDEN_Q_SPEED:
        return (double)j288_speed_from_raw(raw, side);
    case GOLDEN_Q_POS:
        return (double)j288_pos_from_raw(raw, side);
    case GOLDEN_Q_KP:
        return (double)j288_kp_from_raw(raw, side);
    case GOLDEN_Q_KD:
        return (double)j288_kd_from_raw(raw, side);
    case GOLDEN_Q_OUT_POS:
        return (double)j288_out_pos_to_rad((uint16_t)raw);
    default: {
        j288_reply_raw_t r;
        j288_reply_si_t s;
        memset(&r, 0, sizeof r);
        r.voltage_raw = (uint8_t)raw;
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_reply_to_si(&r, side, &s));
        return (double)s.voltage_v;
    }
    }
}

static int32_t cmd_field(const j288_cmd_raw_t *c, int q)
{
    switch (q) {
    case GOLDEN_Q_TORQUE:
        return c->tau;
    case GOLDEN_Q_SPEED:
        return c->speed;
    case GOLDEN_Q_POS:
        return c->pos;
    case GOLDEN_Q_KP:
        return c->kp;
    default:
        return c->kd;
    }
}

static void set_si_field(j288_cmd_si_t *s, int q, j288_real_t v)
{
    switch (q) {
    case GOLDEN_Q_TORQUE:
        s->tau = v;
        break;
    case GOLDEN_Q_SPEED:
        s->speed = v;
        break;
    case GOLDEN_Q_POS:
        s->pos = v;
        break;
    case GOLDEN_Q_KP:
        s->kp = v;
        break;
    default:
        s->kd = v;
        break;
    }
}

static int range_err(int q)
{
    static const int e[5] = {J288_ERR_RANGE_TAU, J288_ERR_RANGE_SPEED, J288_ERR_RANGE_POS,
                             J288_ERR_RANGE_KP, J288_ERR_RANGE_KD};
    return e[q];
}

static void assert_close(double want, double got, double abs_tol, const char *msg)
{
    double tol = fabs(want) * REL_TOL + abs_tol;
    if (!(fabs(want - got) <= tol)) {
        char text[160];
        snprintf(text, sizeof text, "%s: want %.17g got %.17g", msg, want, got);
        TEST_FAIL_MESSAGE(text);
    }
}

/* Golden SI -> raw, through the single-value API and through j288_cmd_from_si(). */
static void test_golden_to_raw(void)
{
    size_t i, checked_exact = 0;
    for (i = 0; i < GOLDEN_SI_COUNT; i++) {
        const golden_si_t *g = &golden_si[i];
        j288_side_t side = sides[g->side];
        j288_real_t v = (j288_real_t)g->si;
        int32_t raw = 0x5A5A;
        int rc = to_raw(g->quantity, v, side, &raw);
        j288_cmd_si_t s;
        j288_cmd_raw_t c;
        int rc2;
        memset(&s, 0, sizeof s);
        set_si_field(&s, g->quantity, v);
        codec_canary_fill(&c, sizeof c);
        rc2 = j288_cmd_from_si(&s, side, &c);
        if (!IS_FLOAT || g->float_exact) {
            checked_exact++;
            TEST_ASSERT_EQUAL_INT_MESSAGE(g->expect, rc, g->name);
            TEST_ASSERT_EQUAL_INT_MESSAGE(g->expect, rc2, g->name);
            if (g->expect == J288_OK) {
                TEST_ASSERT_EQUAL_INT32_MESSAGE(g->raw, raw, g->name);
                TEST_ASSERT_EQUAL_INT32_MESSAGE(g->raw, cmd_field(&c, g->quantity), g->name);
            } else {
                TEST_ASSERT_EQUAL_INT32_MESSAGE(0x5A5A, raw, g->name); /* untouched */
                TEST_ASSERT_TRUE_MESSAGE(codec_canary_intact(&c, sizeof c), g->name);
            }
        } else if (rc == J288_OK && g->expect == J288_OK) {
            /* float, too close to a rounding edge for exactness: within float precision */
            double tol = 1.0 + fabs((double)g->raw) * 1e-6;
            TEST_ASSERT_TRUE_MESSAGE(fabs((double)raw - (double)g->raw) <= tol, g->name);
        } else {
            /* float, at a range edge: either answer, but never another error */
            TEST_ASSERT_TRUE_MESSAGE(rc == J288_OK || rc == range_err(g->quantity), g->name);
        }
    }
    /* most vectors are checked exactly, even in float (about 3 in 4) */
    TEST_ASSERT_TRUE(checked_exact * 3u >= GOLDEN_SI_COUNT * 2u);
}

static void test_golden_from_raw(void)
{
    size_t i;
    for (i = 0; i < GOLDEN_FROM_RAW_COUNT; i++) {
        const golden_from_raw_t *g = &golden_from_raw[i];
        double got = from_raw(g->quantity, g->raw, sides[g->side]);
        assert_close(g->si, got, 0.0, "from_raw");
    }
}

/* Whole SI commands: plain (encode_si) and saturating (from_si_clamped + encode). */
static void test_golden_si_commands(void)
{
    size_t i;
    for (i = 0; i < GOLDEN_SI_CMD_COUNT; i++) {
        const golden_si_cmd_t *g = &golden_si_cmds[i];
        j288_cmd_si_t s;
        j288_cmd_raw_t c;
        uint8_t out[J288_CMD_LEN];
        unsigned mask = 0xFFu;
        int rc;
        memset(&s, 0, sizeof s);
        s.id = g->id;
        s.status = g->status;
        s.watchdog = g->watchdog != 0u;
        s.tau = (j288_real_t)g->tau;
        s.speed = (j288_real_t)g->speed;
        s.pos = (j288_real_t)g->pos;
        s.kp = (j288_real_t)g->kp;
        s.kd = (j288_real_t)g->kd;
        codec_canary_fill(out, sizeof out);
        rc = j288_cmd_encode_si(&s, sides[g->side], out, NULL);
        TEST_ASSERT_EQUAL_INT_MESSAGE(g->expect, rc, g->name);
        if (rc == J288_OK) {
            if (!IS_FLOAT) {
                TEST_ASSERT_EQUAL_HEX8_ARRAY_MESSAGE(g->frame, out, J288_CMD_LEN, g->name);
            }
        } else {
            TEST_ASSERT_TRUE_MESSAGE(codec_canary_intact(out, sizeof out), g->name);
        }
        codec_canary_fill(&c, sizeof c);
        rc = j288_cmd_from_si_clamped(&s, sides[g->side], &c, &mask);
        if (rc == J288_OK) {
            rc = j288_cmd_encode(&c, out, NULL);
        } else {
            TEST_ASSERT_TRUE_MESSAGE(codec_canary_intact(&c, sizeof c), g->name);
            TEST_ASSERT_EQUAL_UINT_MESSAGE(0xFFu, mask, g->name); /* untouched on error */
        }
        TEST_ASSERT_EQUAL_INT_MESSAGE(g->clamp_expect, rc, g->name);
        if (g->clamp_expect == J288_OK) {
            TEST_ASSERT_EQUAL_UINT_MESSAGE(g->clamp_mask, mask, g->name);
            if (!IS_FLOAT) {
                TEST_ASSERT_EQUAL_HEX8_ARRAY_MESSAGE(g->clamp_frame, out, J288_CMD_LEN, g->name);
            }
        }
    }
}

/* raw -> SI -> raw is exact for every int16 value, both sides (float builds too). */
static void test_round_trip_int16_exhaustive(void)
{
    static const int qs[4] = {GOLDEN_Q_TORQUE, GOLDEN_Q_SPEED, GOLDEN_Q_KP, GOLDEN_Q_KD};
    size_t qi, si;
    int32_t raw;
    for (qi = 0; qi < 4u; qi++) {
        int q = qs[qi];
        for (si = 0; si < 2u; si++) {
            int32_t lo = (q == GOLDEN_Q_KP || q == GOLDEN_Q_KD) ? 0 : INT16_MIN;
            for (raw = lo; raw <= INT16_MAX; raw++) {
                int32_t back = 0;
                j288_real_t v = (j288_real_t)from_raw(q, raw, sides[si]);
                TEST_ASSERT_EQUAL_INT(J288_OK, to_raw(q, v, sides[si], &back));
                if (back != raw) {
                    TEST_ASSERT_EQUAL_INT32(raw, back);
                }
            }
        }
    }
}

/* Positions over the int32 range: exact with double; float within its precision. */
static void test_round_trip_pos(void)
{
    codec_rng_t rng;
    size_t si;
    unsigned i;
    codec_rng_seed(&rng, 0x9051u);
    for (si = 0; si < 2u; si++) {
        for (i = 0; i < 20000u; i++) {
            int32_t raw, back = 0;
            int rc;
            uint32_t u = codec_rng_u32(&rng);
            if (i < 8u) {
                static const int32_t edges[8] = {INT32_MIN, INT32_MIN + 1, -1,        0,
                                                 1,         INT32_MAX - 1, INT32_MAX, 16777217};
                raw = edges[i];
            } else {
                raw = (int32_t)(u >> (u & 31u)) * ((u & 32u) ? -1 : 1); /* all magnitudes */
            }
            rc = j288_pos_to_raw(j288_pos_from_raw(raw, sides[si]), sides[si], &back);
            if (!IS_FLOAT) {
                TEST_ASSERT_EQUAL_INT(J288_OK, rc);
                TEST_ASSERT_EQUAL_INT32(raw, back);
            } else {
                double tol = 1.0 + fabs((double)raw) * 5e-7;
                if (rc == J288_OK) {
                    TEST_ASSERT_TRUE(fabs((double)back - (double)raw) <= tol);
                } else {
                    /* only just inside the int32 limits may a float round trip overflow */
                    TEST_ASSERT_EQUAL_INT(J288_ERR_RANGE_POS, rc);
                    TEST_ASSERT_TRUE(fabs((double)raw) >= 2147483648.0 - tol);
                }
            }
        }
    }
}

/* SI -> raw -> SI lands within half an LSB (plus float precision on float builds). */
static void test_round_trip_si_half_lsb(void)
{
    codec_rng_t rng;
    int q;
    size_t si;
    unsigned i;
    codec_rng_seed(&rng, 0x4A1Fu);
    for (q = GOLDEN_Q_TORQUE; q <= GOLDEN_Q_KD; q++) {
        for (si = 0; si < 2u; si++) {
            double k = lsb(q, sides[si]);
            double max_raw = (q == GOLDEN_Q_POS) ? 2147483000.0 : 32767.0;
            double min_raw = (q == GOLDEN_Q_KP || q == GOLDEN_Q_KD) ? 0.0 : -max_raw;
            for (i = 0; i < 5000u; i++) {
                double frac = (double)codec_rng_u32(&rng) / 4294967295.0;
                double want = (min_raw + frac * (max_raw - min_raw)) / k;
                j288_real_t v = (j288_real_t)want;
                int32_t raw = 0;
                double back, err;
                TEST_ASSERT_EQUAL_INT(J288_OK, to_raw(q, v, sides[si], &raw));
                back = from_raw(q, raw, sides[si]);
                err = fabs(back - (double)v) * k; /* in LSB */
                TEST_ASSERT_TRUE(err <= 0.5 + 1e-9 + (IS_FLOAT ? fabs((double)raw) * 5e-7 : 0.0));
            }
        }
    }
}

/* Output side = rotor through N: angles and speeds / N, torque * N, gains * N^2. */
static void test_gear_ratio_rules(void)
{
    static const int32_t raws[] = {1, 7, 1000, 12345, 32767};
    size_t i;
    for (i = 0; i < sizeof raws / sizeof raws[0]; i++) {
        int32_t r = raws[i];
        assert_close(j288_pos_from_raw(r, J288_SIDE_ROTOR) / N_GEAR,
                     j288_pos_from_raw(r, J288_SIDE_OUTPUT), 0.0, "pos / N");
        assert_close(j288_speed_from_raw(r, J288_SIDE_ROTOR) / N_GEAR,
                     j288_speed_from_raw(r, J288_SIDE_OUTPUT), 0.0, "speed / N");
        assert_close(j288_torque_from_raw(r, J288_SIDE_ROTOR) * N_GEAR,
                     j288_torque_from_raw(r, J288_SIDE_OUTPUT), 0.0, "torque * N");
        assert_close(j288_kp_from_raw(r, J288_SIDE_ROTOR) * N_GEAR * N_GEAR,
                     j288_kp_from_raw(r, J288_SIDE_OUTPUT), 0.0, "kp * N^2");
        assert_close(j288_kd_from_raw(r, J288_SIDE_ROTOR) * N_GEAR * N_GEAR,
                     j288_kd_from_raw(r, J288_SIDE_OUTPUT), 0.0, "kd * N^2");
    }
    /* the same rules SI -> raw: an output-side value and its rotor equivalent agree */
    for (i = 0; i < sizeof raws / sizeof raws[0]; i++) {
        int q;
        for (q = GOLDEN_Q_TORQUE; q <= GOLDEN_Q_KD; q++) {
            double rotor = ((double)raws[i] + 0.25) / lsb(q, J288_SIDE_ROTOR);
            double output = (q == GOLDEN_Q_SPEED || q == GOLDEN_Q_POS) ? rotor / N_GEAR
                            : (q == GOLDEN_Q_TORQUE)                   ? rotor * N_GEAR
                                                                       : rotor * N_GEAR * N_GEAR;
            int32_t a = -1, b = -2;
            TEST_ASSERT_EQUAL_INT(J288_OK, to_raw(q, (j288_real_t)rotor, J288_SIDE_ROTOR, &a));
            TEST_ASSERT_EQUAL_INT(J288_OK, to_raw(q, (j288_real_t)output, J288_SIDE_OUTPUT, &b));
            TEST_ASSERT_EQUAL_INT32(raws[i], a);
            TEST_ASSERT_EQUAL_INT32(raws[i], b);
        }
    }
    /* one output turn is N rotor turns: 288.35 * 32768 LSB */
    {
        int32_t raw = 0;
        TEST_ASSERT_EQUAL_INT(
            J288_OK, j288_pos_to_raw((j288_real_t)(2.0 * J288_PI), J288_SIDE_OUTPUT, &raw));
        TEST_ASSERT_INT32_WITHIN(IS_FLOAT ? 8 : 0, 9448653, raw); /* 288.35*32768 = 9448652.8 */
    }
}

/* Every rejection of the single-value API, with the output untouched. */
static void test_single_value_rejections(void)
{
    int q;
    size_t si;
    for (q = GOLDEN_Q_TORQUE; q <= GOLDEN_Q_KD; q++) {
        for (si = 0; si < 2u; si++) {
            j288_side_t side = sides[si];
            double k = lsb(q, side);
            double hi = (q == GOLDEN_Q_POS) ? 2147483647.0 : 32767.0;
            int32_t raw = 0x5A5A;
            TEST_ASSERT_EQUAL_INT(J288_ERR_NOT_FINITE, to_raw(q, (j288_real_t)NAN, side, &raw));
            TEST_ASSERT_EQUAL_INT(range_err(q), to_raw(q, (j288_real_t)INFINITY, side, &raw));
            TEST_ASSERT_EQUAL_INT(range_err(q),
                                  to_raw(q, (j288_real_t)((hi + 2000.0) / k), side, &raw));
            if (q == GOLDEN_Q_KP || q == GOLDEN_Q_KD) {
                TEST_ASSERT_EQUAL_INT(J288_ERR_NEG_GAIN, to_raw(q, (j288_real_t)-1.0, side, &raw));
                TEST_ASSERT_EQUAL_INT(J288_ERR_NEG_GAIN,
                                      to_raw(q, (j288_real_t)-1e-30, side, &raw));
                TEST_ASSERT_EQUAL_INT(J288_ERR_NEG_GAIN,
                                      to_raw(q, (j288_real_t)-INFINITY, side, &raw));
            } else {
                TEST_ASSERT_EQUAL_INT(range_err(q),
                                      to_raw(q, (j288_real_t)(-(hi + 2000.0) / k), side, &raw));
                TEST_ASSERT_EQUAL_INT(range_err(q), to_raw(q, (j288_real_t)-INFINITY, side, &raw));
            }
            TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_ARG, to_raw(q, (j288_real_t)0, bad_side, &raw));
            TEST_ASSERT_EQUAL_INT32(0x5A5A, raw);
        }
    }
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_torque_to_raw(0, J288_SIDE_ROTOR, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_speed_to_raw(0, J288_SIDE_ROTOR, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_pos_to_raw(0, J288_SIDE_ROTOR, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_kp_to_raw(0, J288_SIDE_ROTOR, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_kd_to_raw(0, J288_SIDE_ROTOR, NULL));
    /* -0.0 is not negative */
    {
        int16_t r = 5;
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_kp_to_raw((j288_real_t)-0.0, J288_SIDE_OUTPUT, &r));
        TEST_ASSERT_EQUAL_INT16(0, r);
    }
    /* from_raw has no error path: an invalid side reads as the rotor side */
    TEST_ASSERT_TRUE(j288_pos_from_raw(1000, (j288_side_t)7) ==
                     j288_pos_from_raw(1000, J288_SIDE_ROTOR));
}

/* Exactly half an LSB past either end rounds away from zero, out of range (double builds:
 * the value is found by stepping to a double whose product is exactly the half). */
#if !J288_CONFIG_SI_FLOAT
static double find_exact_product(double target, double k)
{
    double x = target / k;
    int i;
    for (i = 0; i < 4000; i++) {
        if (x * k == target) {
            return x;
        }
        x = (x * k < target) ? nextafter(x, INFINITY) : nextafter(x, -INFINITY);
    }
    return NAN;
}
#endif

/* "Any negative gain is refused, however small": a mutant that only refused gains below
 * -1e-300 survived review. Use the smallest negative value the real type holds. */
static void test_smallest_negative_gain_refused(void)
{
    j288_real_t tiny = (j288_real_t)1;
    j288_real_t half = tiny / (j288_real_t)2;
    int16_t raw = 0x5A5A;
    while (half > (j288_real_t)0) {
        tiny = half;
        half = tiny / (j288_real_t)2;
    }
    TEST_ASSERT_EQUAL_INT(J288_ERR_NEG_GAIN, j288_kp_to_raw(-tiny, J288_SIDE_ROTOR, &raw));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NEG_GAIN, j288_kd_to_raw(-tiny, J288_SIDE_OUTPUT, &raw));
    TEST_ASSERT_EQUAL_INT(0x5A5A, raw);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_kp_to_raw(-(j288_real_t)0, J288_SIDE_ROTOR, &raw));
    TEST_ASSERT_EQUAL_INT(0, raw);
}

static void test_half_lsb_past_the_ends(void)
{
#if !J288_CONFIG_SI_FLOAT
    double x;
    int16_t r16 = 7;
    int32_t r32 = 7;
    x = find_exact_product(-32768.5, J288_SCALE_TORQUE);
    TEST_ASSERT_DOUBLE_IS_NOT_NAN(x); /* not isnan(): mingw-w64's macro converts to float */
    TEST_ASSERT_EQUAL_INT(J288_ERR_RANGE_TAU, j288_torque_to_raw(x, J288_SIDE_ROTOR, &r16));
    x = find_exact_product(32767.5, J288_SCALE_TORQUE);
    TEST_ASSERT_DOUBLE_IS_NOT_NAN(x);
    TEST_ASSERT_EQUAL_INT(J288_ERR_RANGE_TAU, j288_torque_to_raw(x, J288_SIDE_ROTOR, &r16));
    x = find_exact_product(-32767.5, J288_SCALE_TORQUE);
    TEST_ASSERT_DOUBLE_IS_NOT_NAN(x);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_torque_to_raw(x, J288_SIDE_ROTOR, &r16));
    TEST_ASSERT_EQUAL_INT16(-32768, r16);
    x = find_exact_product(-2147483648.5, J288_SCALE_POS);
    TEST_ASSERT_DOUBLE_IS_NOT_NAN(x);
    TEST_ASSERT_EQUAL_INT(J288_ERR_RANGE_POS, j288_pos_to_raw(x, J288_SIDE_ROTOR, &r32));
    TEST_ASSERT_EQUAL_INT32(7, r32);
    x = -2147483648.2 / J288_SCALE_POS; /* rounds to the limit itself */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_pos_to_raw(x, J288_SIDE_ROTOR, &r32));
    TEST_ASSERT_EQUAL_INT32(INT32_MIN, r32);
#else
    /* float: the largest float below 2^31 is in range, 2^31 is not; -2^31 is */
    int32_t r32 = 7;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_pos_to_raw(2147483520.0f / (j288_real_t)J288_SCALE_POS,
                                                   J288_SIDE_ROTOR, &r32));
    TEST_ASSERT_INT32_WITHIN(1024, 2147483520, r32);
    TEST_ASSERT_EQUAL_INT(
        J288_ERR_RANGE_POS,
        j288_pos_to_raw(4294967296.0f / (j288_real_t)J288_SCALE_POS, J288_SIDE_ROTOR, &r32));
#endif
}

/* Halves round away from zero (dyadic inputs: exact in float and double). */
static void test_round_half_away(void)
{
    int16_t r = 0;
    TEST_ASSERT_EQUAL_INT(J288_OK,
                          j288_torque_to_raw((j288_real_t)(1.0 / 4096.0), J288_SIDE_ROTOR, &r));
    TEST_ASSERT_EQUAL_INT16(63, r); /* 62.5 */
    TEST_ASSERT_EQUAL_INT(J288_OK,
                          j288_torque_to_raw((j288_real_t)(-1.0 / 4096.0), J288_SIDE_ROTOR, &r));
    TEST_ASSERT_EQUAL_INT16(-63, r);
    TEST_ASSERT_EQUAL_INT(
        J288_OK, j288_torque_to_raw((j288_real_t)(0.99 / 256000.0 / 2.0), J288_SIDE_ROTOR, &r));
    TEST_ASSERT_EQUAL_INT16(0, r); /* 0.495 */
    TEST_ASSERT_EQUAL_INT(J288_OK,
                          j288_kd_to_raw((j288_real_t)(1.0 / 16384.0), J288_SIDE_ROTOR, &r));
    TEST_ASSERT_EQUAL_INT16(7813, r); /* 7812.5 */
#if !J288_CONFIG_SI_FLOAT
    /* the largest double below 0.5 scaled by 1 must not round up (naive floor(x + 0.5) does) */
    TEST_ASSERT_EQUAL_INT(
        J288_OK, j288_torque_to_raw(0.49999999999999994 / 256000.0 * 1.0, J288_SIDE_ROTOR, &r));
    TEST_ASSERT_EQUAL_INT16(0, r);
#endif
}

static j288_cmd_si_t si_zero(void)
{
    j288_cmd_si_t s;
    memset(&s, 0, sizeof s);
    s.id = 1;
    s.status = J288_MODE_FOC;
    s.watchdog = true;
    return s;
}

/* j288_cmd_from_si: the first bad field names the error; the output is untouched. */
static void test_cmd_from_si_rejections(void)
{
    j288_cmd_si_t s = si_zero();
    j288_cmd_raw_t c;
    uint8_t out[J288_CMD_LEN];
    int q;
    codec_canary_fill(&c, sizeof c);
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_cmd_from_si(NULL, J288_SIDE_ROTOR, &c));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_cmd_from_si(&s, J288_SIDE_ROTOR, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_ARG, j288_cmd_from_si(&s, bad_side, &c));
    TEST_ASSERT_TRUE(codec_canary_intact(&c, sizeof c));
    for (q = GOLDEN_Q_TORQUE; q <= GOLDEN_Q_KD; q++) {
        s = si_zero();
        set_si_field(&s, q, (j288_real_t)1e12);
        TEST_ASSERT_EQUAL_INT(range_err(q), j288_cmd_from_si(&s, J288_SIDE_OUTPUT, &c));
        set_si_field(&s, q, (j288_real_t)NAN);
        TEST_ASSERT_EQUAL_INT(J288_ERR_NOT_FINITE, j288_cmd_from_si(&s, J288_SIDE_OUTPUT, &c));
        set_si_field(&s, q, (j288_real_t)-1e12);
        TEST_ASSERT_EQUAL_INT((q == GOLDEN_Q_KP || q == GOLDEN_Q_KD) ? J288_ERR_NEG_GAIN
                                                                     : range_err(q),
                              j288_cmd_from_si(&s, J288_SIDE_OUTPUT, &c));
        TEST_ASSERT_TRUE(codec_canary_intact(&c, sizeof c));
        codec_canary_fill(out, sizeof out);
        TEST_ASSERT_NOT_EQUAL(J288_OK, j288_cmd_encode_si(&s, J288_SIDE_OUTPUT, out, NULL));
        TEST_ASSERT_TRUE(codec_canary_intact(out, sizeof out));
    }
    /* id and status pass through from_si unchecked; encode_si refuses them */
    s = si_zero();
    s.id = 16;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_cmd_from_si(&s, J288_SIDE_ROTOR, &c));
    TEST_ASSERT_EQUAL_UINT8(16, c.id);
    codec_canary_fill(out, sizeof out);
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_ID, j288_cmd_encode_si(&s, J288_SIDE_ROTOR, out, NULL));
    s = si_zero();
    s.status = 2;
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_STATUS, j288_cmd_encode_si(&s, J288_SIDE_ROTOR, out, NULL));
    TEST_ASSERT_TRUE(codec_canary_intact(out, sizeof out));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_cmd_encode_si(NULL, J288_SIDE_ROTOR, out, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_cmd_encode_si(&s, J288_SIDE_ROTOR, NULL, NULL));
}

/* The saturating variant: each field's bit, its limit, and what it still refuses. */
static void test_clamped_variant(void)
{
    static const unsigned bits[5] = {J288_FIELD_TAU, J288_FIELD_SPEED, J288_FIELD_POS,
                                     J288_FIELD_KP, J288_FIELD_KD};
    static const int32_t his[5] = {INT16_MAX, INT16_MAX, INT32_MAX, INT16_MAX, INT16_MAX};
    static const int32_t los[5] = {INT16_MIN, INT16_MIN, INT32_MIN, 0, 0};
    j288_cmd_si_t s;
    j288_cmd_raw_t c;
    unsigned mask;
    int q;
    for (q = GOLDEN_Q_TORQUE; q <= GOLDEN_Q_KD; q++) {
        s = si_zero();
        set_si_field(&s, q, (j288_real_t)1e12);
        mask = 0;
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_cmd_from_si_clamped(&s, J288_SIDE_OUTPUT, &c, &mask));
        TEST_ASSERT_EQUAL_UINT(bits[q], mask);
        TEST_ASSERT_EQUAL_INT32(his[q], cmd_field(&c, q));
        set_si_field(&s, q, (j288_real_t)-INFINITY);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_cmd_from_si_clamped(&s, J288_SIDE_ROTOR, &c, &mask));
        TEST_ASSERT_EQUAL_UINT(bits[q], mask);
        TEST_ASSERT_EQUAL_INT32(los[q], cmd_field(&c, q)); /* gains: 0 */
        set_si_field(&s, q, (j288_real_t)NAN);
        codec_canary_fill(&c, sizeof c);
        mask = 77u;
        TEST_ASSERT_EQUAL_INT(J288_ERR_NOT_FINITE,
                              j288_cmd_from_si_clamped(&s, J288_SIDE_ROTOR, &c, &mask));
        TEST_ASSERT_EQUAL_UINT(77u, mask);
        TEST_ASSERT_TRUE(codec_canary_intact(&c, sizeof c));
    }
    /* nothing clamped: mask 0, same result as the plain conversion */
    {
        j288_cmd_raw_t plain;
        s = si_zero();
        s.tau = (j288_real_t)1.5;
        s.speed = (j288_real_t)-3.0;
        s.pos = (j288_real_t)0.7;
        s.kp = (j288_real_t)20.0;
        s.kd = (j288_real_t)0.3;
        mask = 99u;
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_cmd_from_si_clamped(&s, J288_SIDE_OUTPUT, &c, &mask));
        TEST_ASSERT_EQUAL_UINT(0u, mask);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_cmd_from_si(&s, J288_SIDE_OUTPUT, &plain));
        TEST_ASSERT_EQUAL_MEMORY(&plain, &c, sizeof c);
        /* all at once, and clamped may be NULL */
        s.tau = (j288_real_t)-1e9;
        s.speed = (j288_real_t)1e9;
        s.pos = (j288_real_t)-1e9;
        s.kp = (j288_real_t)-5.0;
        s.kd = (j288_real_t)1e9;
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_cmd_from_si_clamped(&s, J288_SIDE_OUTPUT, &c, &mask));
        TEST_ASSERT_EQUAL_UINT(0x1Fu, mask);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_cmd_from_si_clamped(&s, J288_SIDE_OUTPUT, &c, NULL));
        TEST_ASSERT_EQUAL_INT16(INT16_MIN, c.tau);
        TEST_ASSERT_EQUAL_INT16(INT16_MAX, c.speed);
        TEST_ASSERT_EQUAL_INT32(INT32_MIN, c.pos);
        TEST_ASSERT_EQUAL_INT16(0, c.kp);
        TEST_ASSERT_EQUAL_INT16(INT16_MAX, c.kd);
    }
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL,
                          j288_cmd_from_si_clamped(NULL, J288_SIDE_ROTOR, &c, &mask));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL,
                          j288_cmd_from_si_clamped(&s, J288_SIDE_ROTOR, NULL, &mask));
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_ARG, j288_cmd_from_si_clamped(&s, bad_side, &c, &mask));
}

/* Raw -> SI for whole frames. */
static void test_reply_and_cmd_to_si(void)
{
    j288_reply_raw_t r;
    j288_reply_si_t s;
    j288_cmd_si_t cs;
    size_t i, si;
    memset(&r, 0, sizeof r);
    r.id = 3;
    r.status = 1;
    r.watchdog_tripped = true;
    r.case_temp_c = -40;
    r.winding_temp_c = 200;
    r.voltage_raw = 255;
    r.torque = 1280;
    r.speed = -41;
    r.pos = 5215;
    r.faults = 0x80000001u;
    r.out_pos = 2048;
    r.warnings = 5;
    for (si = 0; si < 2u; si++) {
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_reply_to_si(&r, sides[si], &s));
        TEST_ASSERT_EQUAL_UINT8(3, s.id);
        TEST_ASSERT_EQUAL_UINT8(1, s.status);
        TEST_ASSERT_TRUE(s.watchdog_tripped);
        assert_close(-40.0, (double)s.case_temp_c, 0.0, "case");
        assert_close(200.0, (double)s.winding_temp_c, 0.0, "winding");
        assert_close(127.5, (double)s.voltage_v, 0.0, "voltage");
        assert_close(1280.0 / lsb(GOLDEN_Q_TORQUE, sides[si]), (double)s.torque, 0.0, "torque");
        assert_close(-41.0 / lsb(GOLDEN_Q_SPEED, sides[si]), (double)s.speed, 0.0, "speed");
        assert_close(5215.0 / lsb(GOLDEN_Q_POS, sides[si]), (double)s.pos, 0.0, "pos");
        assert_close(J288_PI / 2.0, (double)s.out_pos, 0.0, "out_pos");
        TEST_ASSERT_EQUAL_HEX32(0x80000001u, s.faults);
        TEST_ASSERT_EQUAL_UINT8(5, s.warnings);
    }
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_reply_to_si(NULL, J288_SIDE_ROTOR, &s));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_reply_to_si(&r, J288_SIDE_ROTOR, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_ARG, j288_reply_to_si(&r, bad_side, &s));
    /* commands: raw -> SI -> raw is the identity for every encodable golden command */
    for (i = 0; i < GOLDEN_CMD_COUNT; i++) {
        const golden_cmd_t *g = &golden_cmds[i];
        j288_cmd_raw_t raw, back;
        if (g->expect != J288_OK) {
            continue;
        }
        memset(&raw, 0, sizeof raw);
        raw.id = g->id;
        raw.status = g->status;
        raw.watchdog = g->watchdog != 0u;
        raw.tau = g->tau;
        raw.speed = g->speed;
        raw.pos = g->pos;
        raw.kp = g->kp;
        raw.kd = g->kd;
        for (si = 0; si < 2u; si++) {
            int rc;
            TEST_ASSERT_EQUAL_INT(J288_OK, j288_cmd_to_si(&raw, sides[si], &cs));
            rc = j288_cmd_from_si(&cs, sides[si], &back);
            if (IS_FLOAT && (raw.pos > 2147480000 || raw.pos < -2147480000)) {
                continue; /* float may land just past the int32 limit; see test_round_trip_pos */
            }
            TEST_ASSERT_EQUAL_INT_MESSAGE(J288_OK, rc, g->name);
            TEST_ASSERT_EQUAL_UINT8(raw.id, back.id);
            TEST_ASSERT_EQUAL_UINT8(raw.status, back.status);
            TEST_ASSERT_EQUAL(raw.watchdog, back.watchdog);
            TEST_ASSERT_EQUAL_INT16_MESSAGE(raw.tau, back.tau, g->name);
            TEST_ASSERT_EQUAL_INT16_MESSAGE(raw.speed, back.speed, g->name);
            TEST_ASSERT_INT32_WITHIN_MESSAGE(
                IS_FLOAT ? (uint32_t)(1.0 + fabs((double)raw.pos) * 5e-7) : 0u, raw.pos, back.pos,
                g->name);
            TEST_ASSERT_EQUAL_INT16_MESSAGE(raw.kp, back.kp, g->name);
            TEST_ASSERT_EQUAL_INT16_MESSAGE(raw.kd, back.kd, g->name);
        }
    }
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_cmd_to_si(NULL, J288_SIDE_ROTOR, &cs));
    {
        j288_cmd_raw_t zero;
        memset(&zero, 0, sizeof zero);
        TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_cmd_to_si(&zero, J288_SIDE_ROTOR, NULL));
        TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_ARG, j288_cmd_to_si(&zero, bad_side, &cs));
    }
}

/* The scale constants are the documented ones (the speed factor follows the manual). */
static void test_scale_constants(void)
{
    assert_close(2.56 / (2.0 * 3.14159265358979323846), J288_SCALE_SPEED, 0.0, "speed scale");
    assert_close(32768.0 / (2.0 * 3.14159265358979323846), J288_SCALE_POS, 0.0, "pos scale");
    TEST_ASSERT_EQUAL_DOUBLE(256000.0, J288_SCALE_TORQUE);
    TEST_ASSERT_EQUAL_DOUBLE(1280000.0, J288_SCALE_KP);
    TEST_ASSERT_EQUAL_DOUBLE(128000000.0, J288_SCALE_KD);
    TEST_ASSERT_EQUAL_DOUBLE(288.35, J288_GEAR_RATIO);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_scale_constants);
    RUN_TEST(test_golden_to_raw);
    RUN_TEST(test_golden_from_raw);
    RUN_TEST(test_golden_si_commands);
    RUN_TEST(test_round_trip_int16_exhaustive);
    RUN_TEST(test_round_trip_pos);
    RUN_TEST(test_round_trip_si_half_lsb);
    RUN_TEST(test_gear_ratio_rules);
    RUN_TEST(test_single_value_rejections);
    RUN_TEST(test_smallest_negative_gain_refused);
    RUN_TEST(test_half_lsb_past_the_ends);
    RUN_TEST(test_round_half_away);
    RUN_TEST(test_cmd_from_si_rejections);
    RUN_TEST(test_clamped_variant);
    RUN_TEST(test_reply_and_cmd_to_si);
    return UNITY_END();
}

#else /* !J288_CONFIG_SI: nothing to test, the API is compiled out */

int main(void)
{
    UNITY_BEGIN();
    return UNITY_END();
}

#endif
