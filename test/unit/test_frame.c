/* Frame codec against the golden vectors, every rejection, every mode byte; names. */
#include "unity.h"

#include "codec_support.h"
#include "j288/error.h"
#include "j288/frame.h"

#include <string.h>

#define GOLDEN_WANT_COMMANDS
#define GOLDEN_WANT_REPLIES
#define GOLDEN_WANT_NAMES
#include "golden_vectors.h"

void setUp(void) {}
void tearDown(void) {}

static uint32_t table_engine(void *ctx, const uint8_t *d, size_t n)
{
    (void)ctx;
    return j288_crc32_update_table(J288_CRC32_INIT, d, n);
}
static uint32_t slice4_engine(void *ctx, const uint8_t *d, size_t n)
{
    (void)ctx;
    return j288_crc32_update_slice4(J288_CRC32_INIT, d, n);
}
static uint32_t nibble_engine(void *ctx, const uint8_t *d, size_t n)
{
    (void)ctx;
    return j288_crc32_update_nibble(J288_CRC32_INIT, d, n);
}
static uint32_t bitwise_engine(void *ctx, const uint8_t *d, size_t n)
{
    (void)ctx;
    return j288_crc32_update_bitwise(J288_CRC32_INIT, d, n);
}
static const j288_crc_t eng_table = {table_engine, NULL};
static const j288_crc_t eng_slice4 = {slice4_engine, NULL};
static const j288_crc_t eng_nibble = {nibble_engine, NULL};
static const j288_crc_t eng_bitwise = {bitwise_engine, NULL};
static const j288_crc_t *const engines[] = {NULL, &eng_table, &eng_slice4, &eng_nibble,
                                            &eng_bitwise};
#define N_ENGINES (sizeof engines / sizeof engines[0])

static j288_cmd_raw_t golden_cmd_fields(const golden_cmd_t *g)
{
    j288_cmd_raw_t c;
    memset(&c, 0, sizeof c);
    c.id = g->id;
    c.status = g->status;
    c.watchdog = g->watchdog != 0u;
    c.tau = g->tau;
    c.speed = g->speed;
    c.pos = g->pos;
    c.kp = g->kp;
    c.kd = g->kd;
    c.reserved = g->reserved;
    return c;
}

static j288_reply_raw_t golden_reply_fields(const golden_reply_t *g)
{
    j288_reply_raw_t r;
    memset(&r, 0, sizeof r);
    r.id = g->id;
    r.status = g->status;
    r.watchdog_tripped = g->watchdog != 0u;
    r.case_temp_c = g->case_temp;
    r.winding_temp_c = g->winding_temp;
    r.voltage_raw = g->voltage_raw;
    r.torque = g->torque;
    r.speed = g->speed;
    r.pos = g->pos;
    r.faults = g->faults;
    r.out_pos = g->out_pos;
    r.warnings = g->warnings;
    r.reserved = g->reserved;
    return r;
}

static void assert_cmd_equal(const j288_cmd_raw_t *want, const j288_cmd_raw_t *got,
                             const char *name)
{
    TEST_ASSERT_EQUAL_UINT8_MESSAGE(want->id, got->id, name);
    TEST_ASSERT_EQUAL_UINT8_MESSAGE(want->status, got->status, name);
    TEST_ASSERT_EQUAL_MESSAGE(want->watchdog, got->watchdog, name);
    TEST_ASSERT_EQUAL_INT16_MESSAGE(want->tau, got->tau, name);
    TEST_ASSERT_EQUAL_INT16_MESSAGE(want->speed, got->speed, name);
    TEST_ASSERT_EQUAL_INT32_MESSAGE(want->pos, got->pos, name);
    TEST_ASSERT_EQUAL_INT16_MESSAGE(want->kp, got->kp, name);
    TEST_ASSERT_EQUAL_INT16_MESSAGE(want->kd, got->kd, name);
    TEST_ASSERT_EQUAL_UINT8_MESSAGE(want->reserved, got->reserved, name);
}

static void assert_reply_equal(const j288_reply_raw_t *want, const j288_reply_raw_t *got,
                               const char *name)
{
    TEST_ASSERT_EQUAL_UINT8_MESSAGE(want->id, got->id, name);
    TEST_ASSERT_EQUAL_UINT8_MESSAGE(want->status, got->status, name);
    TEST_ASSERT_EQUAL_MESSAGE(want->watchdog_tripped, got->watchdog_tripped, name);
    TEST_ASSERT_EQUAL_INT8_MESSAGE(want->case_temp_c, got->case_temp_c, name);
    TEST_ASSERT_EQUAL_UINT8_MESSAGE(want->winding_temp_c, got->winding_temp_c, name);
    TEST_ASSERT_EQUAL_UINT8_MESSAGE(want->voltage_raw, got->voltage_raw, name);
    TEST_ASSERT_EQUAL_INT16_MESSAGE(want->torque, got->torque, name);
    TEST_ASSERT_EQUAL_INT16_MESSAGE(want->speed, got->speed, name);
    TEST_ASSERT_EQUAL_INT32_MESSAGE(want->pos, got->pos, name);
    TEST_ASSERT_EQUAL_HEX32_MESSAGE(want->faults, got->faults, name);
    TEST_ASSERT_EQUAL_UINT16_MESSAGE(want->out_pos, got->out_pos, name);
    TEST_ASSERT_EQUAL_UINT8_MESSAGE(want->warnings, got->warnings, name);
    TEST_ASSERT_EQUAL_UINT16_MESSAGE(want->reserved, got->reserved, name);
}

static void test_golden_counts(void)
{
    TEST_ASSERT_TRUE(GOLDEN_CMD_COUNT >= 300u);
    TEST_ASSERT_TRUE(GOLDEN_REPLY_COUNT >= 300u);
}

/* The protocol description's worked frames, also present in the vectors by name. */
static void test_worked_frames(void)
{
    static const char *const cmd_hex[2] = {
        "fe ee 80 00 00 00 00 00 00 00 00 00 00 00 00 00 1d 99 fb 6e",
        "fe ee 93 00 00 00 00 00 5f 14 00 00 00 05 00 32 a6 4b 30 3f"};
    static const char *const reply_hex =
        "fc ee 13 24 29 30 00 05 d7 ff 5f 14 00 00 00 00 00 00 e8 03 00 00 49 c2 3b ee";
    uint8_t want[26], out[26];
    j288_cmd_raw_t c;
    j288_reply_raw_t r;
    memset(&c, 0, sizeof c);
    c.watchdog = true;
    TEST_ASSERT_EQUAL_INT(20, codec_hex_decode(cmd_hex[0], want, sizeof want));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_cmd_encode(&c, out, NULL));
    TEST_ASSERT_EQUAL_HEX8_ARRAY(want, out, 20u);
    c.id = 3;
    c.status = J288_MODE_FOC;
    c.pos = 5215;
    c.kp = 1280;
    c.kd = 12800;
    TEST_ASSERT_EQUAL_INT(20, codec_hex_decode(cmd_hex[1], want, sizeof want));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_cmd_encode(&c, out, NULL));
    TEST_ASSERT_EQUAL_HEX8_ARRAY(want, out, 20u);
    TEST_ASSERT_EQUAL_INT(26, codec_hex_decode(reply_hex, want, sizeof want));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_reply_decode(want, &r, NULL));
    TEST_ASSERT_EQUAL_UINT8(3, r.id);
    TEST_ASSERT_EQUAL_UINT8(1, r.status);
    TEST_ASSERT_FALSE(r.watchdog_tripped);
    TEST_ASSERT_EQUAL_INT8(36, r.case_temp_c);
    TEST_ASSERT_EQUAL_UINT8(41, r.winding_temp_c);
    TEST_ASSERT_EQUAL_UINT8(48, r.voltage_raw);
    TEST_ASSERT_EQUAL_INT16(1280, r.torque);
    TEST_ASSERT_EQUAL_INT16(-41, r.speed);
    TEST_ASSERT_EQUAL_INT32(5215, r.pos);
    TEST_ASSERT_EQUAL_HEX32(0, r.faults);
    TEST_ASSERT_EQUAL_UINT16(1000, r.out_pos);
    TEST_ASSERT_EQUAL_STRING("spec_lock_id0", golden_cmds[0].name);
    TEST_ASSERT_EQUAL_HEX8_ARRAY(out, golden_cmds[1].frame, 20u);
    TEST_ASSERT_EQUAL_HEX8_ARRAY(want, golden_replies[0].frame, 26u);
}

static void test_golden_commands_decode(void)
{
    size_t i, e;
    for (i = 0; i < GOLDEN_CMD_COUNT; i++) {
        const golden_cmd_t *g = &golden_cmds[i];
        j288_cmd_raw_t want = golden_cmd_fields(g), got;
        for (e = 0; e < N_ENGINES; e++) {
            memset(&got, 0xA5, sizeof got);
            TEST_ASSERT_EQUAL_INT_MESSAGE(J288_OK, j288_cmd_decode(g->frame, &got, engines[e]),
                                          g->name);
            assert_cmd_equal(&want, &got, g->name);
        }
        memset(&got, 0xA5, sizeof got);
        j288_cmd_unpack(g->frame, &got);
        assert_cmd_equal(&want, &got, g->name);
        TEST_ASSERT_EQUAL_HEX32_MESSAGE(j288_frame_crc_field(g->frame, J288_CMD_LEN),
                                        j288_cmd_crc_expected(g->frame, NULL), g->name);
    }
}

static void test_golden_commands_encode(void)
{
    size_t i, e;
    for (i = 0; i < GOLDEN_CMD_COUNT; i++) {
        const golden_cmd_t *g = &golden_cmds[i];
        j288_cmd_raw_t c = golden_cmd_fields(g);
        for (e = 0; e < N_ENGINES; e++) {
            uint8_t out[J288_CMD_LEN];
            int rc;
            codec_canary_fill(out, sizeof out);
            rc = j288_cmd_encode(&c, out, engines[e]);
            if (g->expect == J288_OK) {
                TEST_ASSERT_EQUAL_INT_MESSAGE(J288_OK, rc, g->name);
                TEST_ASSERT_EQUAL_HEX8_ARRAY_MESSAGE(g->frame, out, J288_CMD_LEN, g->name);
            } else if (g->expect == GOLDEN_DECODE_ONLY) {
                /* reserved is never sent: the frame equals the golden one with byte 3 = 0 */
                uint8_t want[J288_CMD_LEN];
                memcpy(want, g->frame, sizeof want);
                want[3] = 0;
                codec_fix_cmd_crc(want);
                TEST_ASSERT_EQUAL_INT_MESSAGE(J288_OK, rc, g->name);
                TEST_ASSERT_EQUAL_HEX8_ARRAY_MESSAGE(want, out, J288_CMD_LEN, g->name);
            } else {
                TEST_ASSERT_EQUAL_INT_MESSAGE(g->expect, rc, g->name);
                TEST_ASSERT_TRUE_MESSAGE(codec_canary_intact(out, sizeof out), g->name);
            }
        }
    }
}

static void test_golden_replies_decode(void)
{
    size_t i, e;
    for (i = 0; i < GOLDEN_REPLY_COUNT; i++) {
        const golden_reply_t *g = &golden_replies[i];
        j288_reply_raw_t want = golden_reply_fields(g), got;
        for (e = 0; e < N_ENGINES; e++) {
            memset(&got, 0xA5, sizeof got);
            TEST_ASSERT_EQUAL_INT_MESSAGE(J288_OK, j288_reply_decode(g->frame, &got, engines[e]),
                                          g->name);
            assert_reply_equal(&want, &got, g->name);
        }
        memset(&got, 0xA5, sizeof got);
        j288_reply_unpack(g->frame, &got);
        assert_reply_equal(&want, &got, g->name);
        TEST_ASSERT_EQUAL_HEX32_MESSAGE(j288_frame_crc_field(g->frame, J288_REPLY_LEN),
                                        j288_reply_crc_expected(g->frame, NULL), g->name);
    }
}

static void test_golden_replies_encode(void)
{
    size_t i, e;
    for (i = 0; i < GOLDEN_REPLY_COUNT; i++) {
        const golden_reply_t *g = &golden_replies[i];
        j288_reply_raw_t r = golden_reply_fields(g);
        for (e = 0; e < N_ENGINES; e++) {
            uint8_t out[J288_REPLY_LEN];
            int rc;
            codec_canary_fill(out, sizeof out);
            rc = j288_reply_encode(&r, out, engines[e]);
            TEST_ASSERT_EQUAL_INT_MESSAGE(g->expect, rc, g->name);
            if (g->expect == J288_OK) {
                TEST_ASSERT_EQUAL_HEX8_ARRAY_MESSAGE(g->frame, out, J288_REPLY_LEN, g->name);
            } else {
                TEST_ASSERT_TRUE_MESSAGE(codec_canary_intact(out, sizeof out), g->name);
            }
        }
    }
}

/* Every encoder rejection, each with the output buffer untouched. */
static void expect_cmd_reject(const j288_cmd_raw_t *c, int want)
{
    uint8_t out[J288_CMD_LEN];
    codec_canary_fill(out, sizeof out);
    TEST_ASSERT_EQUAL_INT(want, j288_cmd_encode(c, out, NULL));
    TEST_ASSERT_TRUE(codec_canary_intact(out, sizeof out));
}

static void test_cmd_encode_rejections(void)
{
    j288_cmd_raw_t base, c;
    unsigned v;
    uint8_t out[J288_CMD_LEN];
    memset(&base, 0, sizeof base);
    base.status = J288_MODE_FOC;
    codec_canary_fill(out, sizeof out);
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_cmd_encode(NULL, out, NULL));
    TEST_ASSERT_TRUE(codec_canary_intact(out, sizeof out));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_cmd_encode(&base, NULL, NULL));
    for (v = 16u; v <= 255u; v++) {
        c = base;
        c.id = (uint8_t)v;
        expect_cmd_reject(&c, J288_ERR_BAD_ID);
    }
    for (v = 2u; v <= 255u; v++) {
        c = base;
        c.status = (uint8_t)v;
        expect_cmd_reject(&c, J288_ERR_BAD_STATUS);
    }
    c = base;
    c.kp = -1;
    expect_cmd_reject(&c, J288_ERR_NEG_GAIN);
    c.kp = INT16_MIN;
    expect_cmd_reject(&c, J288_ERR_NEG_GAIN);
    c = base;
    c.kd = -1;
    expect_cmd_reject(&c, J288_ERR_NEG_GAIN);
    c.kd = INT16_MIN;
    expect_cmd_reject(&c, J288_ERR_NEG_GAIN);
    /* valid edges are accepted: id 15 broadcast, status 0 and 1, gains 0 */
    for (v = 0u; v <= 15u; v++) {
        c = base;
        c.id = (uint8_t)v;
        c.status = (uint8_t)(v & 1u);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_cmd_encode(&c, out, NULL));
        TEST_ASSERT_EQUAL_HEX8((uint8_t)(v | ((v & 1u) << 4)), out[2]);
    }
}

static void expect_reply_reject(const j288_reply_raw_t *r, int want)
{
    uint8_t out[J288_REPLY_LEN];
    codec_canary_fill(out, sizeof out);
    TEST_ASSERT_EQUAL_INT(want, j288_reply_encode(r, out, NULL));
    TEST_ASSERT_TRUE(codec_canary_intact(out, sizeof out));
}

static void test_reply_encode_rejections(void)
{
    j288_reply_raw_t base, r;
    unsigned v;
    uint8_t out[J288_REPLY_LEN];
    memset(&base, 0, sizeof base);
    codec_canary_fill(out, sizeof out);
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_reply_encode(NULL, out, NULL));
    TEST_ASSERT_TRUE(codec_canary_intact(out, sizeof out));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_reply_encode(&base, NULL, NULL));
    for (v = 15u; v <= 255u; v++) {
        r = base;
        r.id = (uint8_t)v;
        expect_reply_reject(&r, J288_ERR_BAD_ID);
    }
    for (v = 8u; v <= 255u; v++) {
        r = base;
        r.status = (uint8_t)v;
        expect_reply_reject(&r, J288_ERR_BAD_STATUS);
    }
    for (v = 8u; v <= 255u; v++) {
        r = base;
        r.warnings = (uint8_t)v;
        expect_reply_reject(&r, J288_ERR_RANGE);
    }
    for (v = 8192u; v <= 65535u; v += 97u) {
        r = base;
        r.out_pos = (uint16_t)v;
        expect_reply_reject(&r, J288_ERR_RANGE);
    }
    r = base;
    r.out_pos = 8192u;
    expect_reply_reject(&r, J288_ERR_RANGE);
    r.out_pos = 65535u;
    expect_reply_reject(&r, J288_ERR_RANGE);
}

/* Decoders: NULL, wrong heads (every other value of either byte), results untouched. */
static void test_decode_bad_header(void)
{
    uint8_t f[J288_REPLY_LEN];
    j288_cmd_raw_t c;
    j288_reply_raw_t r;
    unsigned pos, v;
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_cmd_decode(NULL, &c, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_cmd_decode(golden_cmds[0].frame, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_reply_decode(NULL, &r, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_reply_decode(golden_replies[0].frame, NULL, NULL));
    for (pos = 0; pos < 2u; pos++) {
        for (v = 0; v <= 255u; v++) {
            memcpy(f, golden_cmds[1].frame, J288_CMD_LEN);
            if (v == f[pos]) {
                continue;
            }
            f[pos] = (uint8_t)v;
            codec_fix_cmd_crc(f); /* the head is under the command CRC: keep the CRC right */
            codec_canary_fill(&c, sizeof c);
            TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_HEADER, j288_cmd_decode(f, &c, NULL));
            TEST_ASSERT_TRUE(codec_canary_intact(&c, sizeof c));

            memcpy(f, golden_replies[0].frame, J288_REPLY_LEN);
            if (v == f[pos]) {
                continue;
            }
            f[pos] = (uint8_t)v;
            codec_canary_fill(&r, sizeof r);
            TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_HEADER, j288_reply_decode(f, &r, NULL));
            TEST_ASSERT_TRUE(codec_canary_intact(&r, sizeof r));
        }
    }
    /* a command is not a reply and vice versa */
    memset(f, 0, sizeof f);
    memcpy(f, golden_cmds[0].frame, J288_CMD_LEN);
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_HEADER, j288_reply_decode(f, &r, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_HEADER, j288_cmd_decode(golden_replies[0].frame, &c, NULL));
}

/* Every single-bit error after the head is a CRC error, with the result untouched. */
static void test_decode_bad_crc(void)
{
    uint8_t f[J288_REPLY_LEN];
    j288_cmd_raw_t c;
    j288_reply_raw_t r;
    unsigned bit;
    size_t g;
    for (g = 0; g < 8u; g++) {
        for (bit = 16u; bit < 8u * J288_CMD_LEN; bit++) {
            memcpy(f, golden_cmds[g * 37u].frame, J288_CMD_LEN);
            f[bit / 8u] ^= (uint8_t)(1u << (bit % 8u));
            codec_canary_fill(&c, sizeof c);
            TEST_ASSERT_EQUAL_INT(J288_ERR_CRC, j288_cmd_decode(f, &c, NULL));
            TEST_ASSERT_TRUE(codec_canary_intact(&c, sizeof c));
        }
        for (bit = 16u; bit < 8u * J288_REPLY_LEN; bit++) {
            memcpy(f, golden_replies[g * 37u].frame, J288_REPLY_LEN);
            f[bit / 8u] ^= (uint8_t)(1u << (bit % 8u));
            codec_canary_fill(&r, sizeof r);
            TEST_ASSERT_EQUAL_INT(J288_ERR_CRC, j288_reply_decode(f, &r, NULL));
            TEST_ASSERT_TRUE(codec_canary_intact(&r, sizeof r));
        }
    }
}

/* Every mode byte decodes to id = bits 0-3, status = bits 4-6, flag = bit 7. */
static void test_decode_every_mode_byte(void)
{
    unsigned m;
    for (m = 0; m <= 255u; m++) {
        uint8_t f[J288_REPLY_LEN];
        j288_cmd_raw_t c;
        j288_reply_raw_t r;
        memcpy(f, golden_cmds[0].frame, J288_CMD_LEN);
        f[2] = (uint8_t)m;
        codec_fix_cmd_crc(f);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_cmd_decode(f, &c, NULL));
        TEST_ASSERT_EQUAL_UINT8(m & 15u, c.id);
        TEST_ASSERT_EQUAL_UINT8((m >> 4) & 7u, c.status);
        TEST_ASSERT_EQUAL(m >= 128u, c.watchdog);

        memcpy(f, golden_replies[0].frame, J288_REPLY_LEN);
        f[2] = (uint8_t)m;
        codec_fix_reply_crc(f);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_reply_decode(f, &r, NULL));
        TEST_ASSERT_EQUAL_UINT8(m & 15u, r.id);
        TEST_ASSERT_EQUAL_UINT8((m >> 4) & 7u, r.status);
        TEST_ASSERT_EQUAL(m >= 128u, r.watchdog_tripped);
        /* and the device-side encoder writes it back identically where it may */
        if ((m & 15u) <= 14u) {
            uint8_t out[J288_REPLY_LEN];
            TEST_ASSERT_EQUAL_INT(J288_OK, j288_reply_encode(&r, out, NULL));
            TEST_ASSERT_EQUAL_HEX8_ARRAY(f, out, J288_REPLY_LEN);
        }
    }
}

/* The out word: OutPos bits 0-12, ExFlag bits 13-15, for every warning and edge position. */
static void test_decode_out_word(void)
{
    static const uint16_t words[] = {0x0000u, 0x1FFFu, 0x2000u, 0xE000u, 0xFFFFu, 0x3FFFu, 0x8001u};
    size_t i;
    for (i = 0; i < sizeof words / sizeof words[0]; i++) {
        uint8_t f[J288_REPLY_LEN];
        j288_reply_raw_t r;
        memcpy(f, golden_replies[0].frame, J288_REPLY_LEN);
        f[18] = (uint8_t)words[i];
        f[19] = (uint8_t)(words[i] >> 8);
        codec_fix_reply_crc(f);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_reply_decode(f, &r, NULL));
        TEST_ASSERT_EQUAL_UINT16(words[i] & 0x1FFFu, r.out_pos);
        TEST_ASSERT_EQUAL_UINT8(words[i] >> 13, r.warnings);
    }
}

/* The CRC field accessor is public: a wrong length must read nothing (found in review: len 2
 * read before the buffer). */
static void test_crc_field_rejects_bad_lengths(void)
{
    uint8_t two[2] = {0xAAu, 0xBBu};
    uint8_t frame[J288_REPLY_LEN];
    size_t i;
    for (i = 0; i < sizeof frame; i++) {
        frame[i] = (uint8_t)(0x11u * (i + 1u));
    }
    TEST_ASSERT_EQUAL_HEX32(0u, j288_frame_crc_field(two, sizeof two));
    TEST_ASSERT_EQUAL_HEX32(0u, j288_frame_crc_field(NULL, J288_CMD_LEN));
    TEST_ASSERT_EQUAL_HEX32(0u, j288_frame_crc_field(frame, 0u));
    TEST_ASSERT_EQUAL_HEX32(0u, j288_frame_crc_field(frame, J288_REPLY_LEN - 1u));
    TEST_ASSERT_EQUAL_HEX32(0u, j288_frame_crc_field(frame, J288_REPLY_LEN + 1u));
    TEST_ASSERT_EQUAL_HEX32(j288_get_u32le(&frame[16]), j288_frame_crc_field(frame, J288_CMD_LEN));
    TEST_ASSERT_EQUAL_HEX32(j288_get_u32le(&frame[22]),
                            j288_frame_crc_field(frame, J288_REPLY_LEN));
}

static void test_fault_and_warning_names(void)
{
    unsigned bit;
    for (bit = 0; bit < GOLDEN_FAULT_NAME_COUNT; bit++) {
        TEST_ASSERT_EQUAL_STRING(golden_fault_names[bit], j288_fault_name(bit));
    }
    TEST_ASSERT_EQUAL_UINT(J288_FAULT_COUNT, GOLDEN_FAULT_NAME_COUNT);
    for (bit = J288_FAULT_COUNT; bit < 40u; bit++) {
        TEST_ASSERT_EQUAL_STRING("unknown fault", j288_fault_name(bit));
    }
    for (bit = 0; bit < 3u; bit++) {
        TEST_ASSERT_EQUAL_STRING(golden_warning_names[bit], j288_warning_name(bit));
    }
    TEST_ASSERT_EQUAL_STRING("unknown warning", j288_warning_name(100u));
    TEST_ASSERT_EQUAL_HEX32(0x3FFFFFu, J288_FAULT_KNOWN_MASK);
    TEST_ASSERT_EQUAL_HEX32(1ul << 21, J288_FAULT_ENCODER_ANGLE);
}

static void test_strerror_every_code(void)
{
    static const int codes[] = {J288_OK,
                                J288_ERR_NULL,
                                J288_ERR_BAD_ID,
                                J288_ERR_BAD_STATUS,
                                J288_ERR_NEG_GAIN,
                                J288_ERR_RANGE_TAU,
                                J288_ERR_RANGE_SPEED,
                                J288_ERR_RANGE_POS,
                                J288_ERR_RANGE_KP,
                                J288_ERR_RANGE_KD,
                                J288_ERR_NOT_FINITE,
                                J288_ERR_RANGE,
                                J288_ERR_BAD_ARG,
                                J288_ERR_BAD_CONFIG,
                                J288_ERR_PORT_OPS,
                                J288_ERR_BAD_HEADER,
                                J288_ERR_CRC,
                                J288_ERR_TRUNCATED,
                                J288_ERR_BUSY,
                                J288_ERR_TIMEOUT,
                                J288_ERR_WRONG_ID,
                                J288_ERR_COLLISION,
                                J288_ERR_LINE,
                                J288_ERR_PORT,
                                J288_ERR_TX_TIMEOUT,
                                J288_ERR_ABORTED,
                                J288_ERR_OVERFLOW,
                                J288_ERR_OFFLINE};
    const size_t n = sizeof codes / sizeof codes[0];
    size_t i, j;
    const char *unknown = j288_strerror(12345);
    TEST_ASSERT_NOT_NULL(unknown);
    TEST_ASSERT_EQUAL_STRING("unknown error", unknown);
    TEST_ASSERT_EQUAL_STRING("unknown error", j288_strerror(1));
    TEST_ASSERT_EQUAL_STRING("unknown error", j288_strerror(-19));
    for (i = 0; i < n; i++) {
        const char *s = j288_strerror(codes[i]);
        TEST_ASSERT_NOT_NULL(s);
        TEST_ASSERT_TRUE(s[0] != '\0');
        TEST_ASSERT_TRUE(strcmp(s, unknown) != 0);
        for (j = 0; j < i; j++) {
            TEST_ASSERT_TRUE(codes[i] != codes[j]);
            TEST_ASSERT_TRUE_MESSAGE(strcmp(s, j288_strerror(codes[j])) != 0, s);
        }
    }
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_golden_counts);
    RUN_TEST(test_worked_frames);
    RUN_TEST(test_golden_commands_decode);
    RUN_TEST(test_golden_commands_encode);
    RUN_TEST(test_golden_replies_decode);
    RUN_TEST(test_golden_replies_encode);
    RUN_TEST(test_cmd_encode_rejections);
    RUN_TEST(test_reply_encode_rejections);
    RUN_TEST(test_decode_bad_header);
    RUN_TEST(test_decode_bad_crc);
    RUN_TEST(test_decode_every_mode_byte);
    RUN_TEST(test_decode_out_word);
    RUN_TEST(test_crc_field_rejects_bad_lengths);
    RUN_TEST(test_fault_and_warning_names);
    RUN_TEST(test_strerror_every_code);
    return UNITY_END();
}
