/* CRC32: every backend equals an independent bitwise reference; streaming; check values. */
#include "unity.h"

#include "codec_support.h"
#include "j288/crc32.h"
#include "j288/frame.h"

#include <string.h>

void setUp(void) {}
void tearDown(void) {}

typedef uint32_t (*update_fn)(uint32_t, const uint8_t *, size_t);

static uint32_t whole_table(const uint8_t *d, size_t n)
{
    return j288_crc32_update_table(J288_CRC32_INIT, d, n);
}
static uint32_t whole_slice4(const uint8_t *d, size_t n)
{
    return j288_crc32_update_slice4(J288_CRC32_INIT, d, n);
}
static uint32_t whole_nibble(const uint8_t *d, size_t n)
{
    return j288_crc32_update_nibble(J288_CRC32_INIT, d, n);
}
static uint32_t whole_bitwise(const uint8_t *d, size_t n)
{
    return j288_crc32_update_bitwise(J288_CRC32_INIT, d, n);
}
static uint32_t whole_default(const uint8_t *d, size_t n)
{
    return j288_crc32(d, n);
}
static uint32_t whole_run_null(const uint8_t *d, size_t n)
{
    return j288_crc32_run(NULL, d, n);
}
static uint32_t whole_run_nullfn(const uint8_t *d, size_t n)
{
    const j288_crc_t engine = {NULL, NULL};
    return j288_crc32_run(&engine, d, n);
}

typedef struct {
    const char *name;
    uint32_t (*whole)(const uint8_t *, size_t);
} backend_t;

static const backend_t backends[] = {
    {"table", whole_table},     {"slice4", whole_slice4},      {"nibble", whole_nibble},
    {"bitwise", whole_bitwise}, {"default", whole_default},    {"run(NULL)", whole_run_null},
    {"run(fn NULL)", whole_run_nullfn},
};
#define N_BACKENDS (sizeof backends / sizeof backends[0])

static const update_fn updates[] = {j288_crc32_update_table, j288_crc32_update_slice4,
                                    j288_crc32_update_nibble, j288_crc32_update_bitwise};

static void test_check_value_mpeg2(void)
{
    const uint8_t *s = (const uint8_t *)"123456789";
    TEST_ASSERT_EQUAL_HEX32(0x0376E6E7u, codec_ref_mpeg2(s, 9u)); /* the reference itself */
    TEST_ASSERT_EQUAL_HEX32(0x0376E6E7u, j288_crc32_mpeg2_bytes(s, 9u));
    TEST_ASSERT_EQUAL_HEX32(J288_CRC32_INIT, j288_crc32_mpeg2_bytes(NULL, 0u));
}

/* Word-wise over "4321" "8765" is the byte-stream CRC over "12345678": the word/byte subtlety. */
static void test_words_are_little_endian(void)
{
    static const uint8_t grouped[8] = {'4', '3', '2', '1', '8', '7', '6', '5'};
    uint32_t want = codec_ref_mpeg2((const uint8_t *)"12345678", 8u);
    size_t b;
    for (b = 0; b < N_BACKENDS; b++) {
        TEST_ASSERT_EQUAL_HEX32_MESSAGE(want, backends[b].whole(grouped, 2u), backends[b].name);
    }
}

/* The worked lock frame of the protocol description: CRC 0x6efb991d over bytes 0-15. */
static void test_worked_frame_crc(void)
{
    uint8_t f[16] = {0xfe, 0xee, 0x80};
    size_t b;
    for (b = 0; b < N_BACKENDS; b++) {
        TEST_ASSERT_EQUAL_HEX32_MESSAGE(0x6efb991du, backends[b].whole(f, 4u), backends[b].name);
    }
}

static void test_empty_is_init(void)
{
    size_t b;
    for (b = 0; b < N_BACKENDS; b++) {
        TEST_ASSERT_EQUAL_HEX32_MESSAGE(J288_CRC32_INIT, backends[b].whole(NULL, 0u),
                                        backends[b].name);
    }
}

/* Random buffers of 0..64 words at every alignment: all backends equal the reference. */
static void test_backends_equal_reference_random(void)
{
    static uint8_t buf[4 * 64 + 3];
    codec_rng_t rng;
    unsigned iter;
    codec_rng_seed(&rng, 0xC0FFEEu);
    for (iter = 0; iter < 2000u; iter++) {
        size_t nwords = codec_rng_below(&rng, 65u);
        size_t offset = iter % 4u;
        uint32_t want;
        size_t b;
        codec_rng_fill(&rng, buf, sizeof buf);
        want = codec_ref_crc(0xFFFFFFFFu, buf + offset, 4u * nwords);
        for (b = 0; b < N_BACKENDS; b++) {
            TEST_ASSERT_EQUAL_HEX32_MESSAGE(want, backends[b].whole(buf + offset, nwords),
                                            backends[b].name);
        }
    }
}

/* Special patterns: all zero, all ones, single bits. */
static void test_backends_equal_reference_patterns(void)
{
    uint8_t buf[32];
    unsigned bit;
    size_t b;
    for (bit = 0; bit <= 8u * sizeof buf; bit++) {
        memset(buf, 0, sizeof buf);
        if (bit < 8u * sizeof buf) {
            buf[bit / 8u] = (uint8_t)(1u << (bit % 8u));
        }
        for (b = 0; b < N_BACKENDS; b++) {
            TEST_ASSERT_EQUAL_HEX32(codec_ref_crc(0xFFFFFFFFu, buf, sizeof buf),
                                    backends[b].whole(buf, sizeof buf / 4u));
        }
    }
    memset(buf, 0xFF, sizeof buf);
    for (b = 0; b < N_BACKENDS; b++) {
        TEST_ASSERT_EQUAL_HEX32(codec_ref_crc(0xFFFFFFFFu, buf, sizeof buf),
                                backends[b].whole(buf, sizeof buf / 4u));
    }
}

/* Streaming: any split into word-aligned pieces gives the one-shot value, for any start. */
static void test_streaming_in_pieces(void)
{
    uint8_t buf[4 * 24];
    codec_rng_t rng;
    size_t u, a, bsplit;
    codec_rng_seed(&rng, 288u);
    codec_rng_fill(&rng, buf, sizeof buf);
    for (u = 0; u < sizeof updates / sizeof updates[0]; u++) {
        uint32_t whole = updates[u](J288_CRC32_INIT, buf, 24u);
        TEST_ASSERT_EQUAL_HEX32(codec_ref_crc(0xFFFFFFFFu, buf, sizeof buf), whole);
        for (a = 0; a <= 24u; a++) {
            for (bsplit = a; bsplit <= 24u; bsplit++) {
                uint32_t c = updates[u](J288_CRC32_INIT, buf, a);
                c = updates[u](c, buf + 4u * a, bsplit - a);
                c = updates[u](c, buf + 4u * bsplit, 24u - bsplit);
                TEST_ASSERT_EQUAL_HEX32(whole, c);
            }
        }
        /* word by word, and from an arbitrary start value */
        {
            uint32_t c = 0x12345678u;
            size_t w;
            for (w = 0; w < 24u; w++) {
                c = updates[u](c, buf + 4u * w, 1u);
            }
            TEST_ASSERT_EQUAL_HEX32(codec_ref_crc(0x12345678u, buf, sizeof buf), c);
        }
    }
}

typedef struct {
    unsigned calls;
    const uint8_t *last_data;
    size_t last_nwords;
    uint8_t seen[20]; /* copy of up to 5 words passed in */
} fake_hw_t;

static uint32_t fake_hw_crc(void *ctx, const uint8_t *data, size_t nwords)
{
    fake_hw_t *hw = ctx;
    hw->calls++;
    hw->last_data = data;
    hw->last_nwords = nwords;
    memcpy(hw->seen, data, (nwords <= 5u ? nwords : 5u) * 4u);
    return 0xDEADBEEFu;
}

/* A run-time engine is called with its ctx and its answer is used as is. */
static void test_runtime_engine_is_used(void)
{
    fake_hw_t hw = {0u, NULL, 0u, {0}};
    const j288_crc_t engine = {fake_hw_crc, &hw};
    uint8_t buf[8] = {1, 2, 3, 4, 5, 6, 7, 8};
    TEST_ASSERT_EQUAL_HEX32(0xDEADBEEFu, j288_crc32_run(&engine, buf, 2u));
    TEST_ASSERT_EQUAL_UINT(1u, hw.calls);
    TEST_ASSERT_EQUAL_PTR(buf, hw.last_data);
    TEST_ASSERT_EQUAL_UINT(2u, hw.last_nwords);
}

/* The frame codec goes through the engine too (bytes 0-15 of a command, 2-21 of a reply). */
static void test_frame_codec_uses_engine(void)
{
    fake_hw_t hw = {0u, NULL, 0u, {0}};
    const j288_crc_t engine = {fake_hw_crc, &hw};
    j288_cmd_raw_t cmd = {0};
    j288_reply_raw_t rep = {0};
    uint8_t c[J288_CMD_LEN], r[J288_REPLY_LEN];
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_cmd_encode(&cmd, c, &engine));
    TEST_ASSERT_EQUAL_UINT(4u, hw.last_nwords);
    TEST_ASSERT_EQUAL_HEX8_ARRAY(c, hw.seen, 16u); /* bytes 0-15, head included */
    TEST_ASSERT_EQUAL_HEX32(0xDEADBEEFu, j288_get_u32le(&c[16]));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_reply_encode(&rep, r, &engine));
    TEST_ASSERT_EQUAL_UINT(5u, hw.last_nwords);
    TEST_ASSERT_EQUAL_HEX8_ARRAY(&r[2], hw.seen, 20u); /* bytes 2-21, head excluded */
    TEST_ASSERT_EQUAL_HEX32(0xDEADBEEFu, j288_get_u32le(&r[22]));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_reply_decode(r, &rep, &engine));
    TEST_ASSERT_EQUAL_INT(J288_ERR_CRC, j288_reply_decode(r, &rep, NULL));
}

/* The compile-time default backend is the configured one (make test builds the variants). */
static void test_compile_time_backend(void)
{
    uint8_t buf[8] = {1, 2, 3, 4, 5, 6, 7, 8};
    unsigned long before = *codec_hw_crc_calls_ptr();
    uint32_t want = codec_ref_crc(0xFFFFFFFFu, buf, sizeof buf);
    TEST_ASSERT_EQUAL_HEX32(want, j288_crc32(buf, 2u));
    TEST_ASSERT_EQUAL_HEX32(want, j288_crc32_run(NULL, buf, 2u));
#if J288_CONFIG_CRC_BACKEND == J288_CRC_BACKEND_HW
    TEST_ASSERT_EQUAL_UINT32(before + 2u, *codec_hw_crc_calls_ptr());
#else
    TEST_ASSERT_EQUAL_UINT32(before, *codec_hw_crc_calls_ptr());
    TEST_ASSERT_EQUAL_HEX32(want, codec_hw_crc_stub(buf, 2u)); /* the stand-in itself */
#endif
}

/* Little-endian helpers never depend on alignment or host order. */
static void test_le_helpers(void)
{
    uint8_t b[7] = {0};
    j288_put_u32le(&b[1], 0x11223344u);
    TEST_ASSERT_EQUAL_HEX8(0x44, b[1]);
    TEST_ASSERT_EQUAL_HEX8(0x11, b[4]);
    TEST_ASSERT_EQUAL_HEX32(0x11223344u, j288_get_u32le(&b[1]));
    j288_put_u16le(&b[5], 0xBEEFu);
    TEST_ASSERT_EQUAL_HEX8(0xEF, b[5]);
    TEST_ASSERT_EQUAL_HEX16(0xBEEFu, j288_get_u16le(&b[5]));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_check_value_mpeg2);
    RUN_TEST(test_words_are_little_endian);
    RUN_TEST(test_worked_frame_crc);
    RUN_TEST(test_empty_is_init);
    RUN_TEST(test_backends_equal_reference_random);
    RUN_TEST(test_backends_equal_reference_patterns);
    RUN_TEST(test_streaming_in_pieces);
    RUN_TEST(test_runtime_engine_is_used);
    RUN_TEST(test_frame_codec_uses_engine);
    RUN_TEST(test_compile_time_backend);
    RUN_TEST(test_le_helpers);
    return UNITY_END();
}
