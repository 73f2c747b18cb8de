/* Incremental parser: streams of golden frames cut every way, with garbage, truncation,
 * corruption and false heads; exact statistics. */
#include "unity.h"

#include "codec_support.h"
#include "j288/parser.h"

#include <string.h>

#define GOLDEN_WANT_COMMANDS
#define GOLDEN_WANT_REPLIES
#include "golden_vectors.h"

void setUp(void) {}
void tearDown(void) {}

/* Small enough for a 16 KiB-RAM Cortex-M0 (the tests also run on targets): long streams are
 * fed in batches of BATCH frames through the same parser. */
#define MAX_FRAMES 64u
#define BATCH      50u
#define STREAM_CAP 2600u

static uint8_t stream[STREAM_CAP];
static uint8_t got[MAX_FRAMES][J288_REPLY_LEN];

typedef struct {
    unsigned calls;
} crc_counter_t;

static uint32_t counting_crc(void *ctx, const uint8_t *d, size_t n)
{
    ((crc_counter_t *)ctx)->calls++;
    return j288_crc32_update_bitwise(J288_CRC32_INIT, d, n);
}

/* Feed len bytes in chunks of the given size (0: sizes from the PRNG, 1..40); copy each
 * frame out. Returns the number of frames. */
static size_t feed_chunks(j288_parser_t *p, const uint8_t *data, size_t len, size_t chunk,
                          codec_rng_t *rng)
{
    size_t off = 0, frames = 0;
    while (off < len) {
        size_t n = chunk != 0u ? chunk : 1u + codec_rng_below(rng, 40u);
        size_t done = 0;
        if (n > len - off) {
            n = len - off;
        }
        while (done < n) {
            size_t consumed = 12345u;
            int rc = j288_parser_feed(p, data + off + done, n - done, &consumed);
            TEST_ASSERT_TRUE(consumed <= n - done);
            if (rc == J288_PARSE_FRAME) {
                TEST_ASSERT_TRUE(consumed >= 1u);
                TEST_ASSERT_TRUE(frames < MAX_FRAMES);
                memcpy(got[frames], j288_parser_frame(p), p->frame_len);
                frames++;
            } else {
                TEST_ASSERT_EQUAL_INT(J288_PARSE_NONE, rc);
                TEST_ASSERT_EQUAL_UINT(n - done, consumed);
            }
            done += consumed;
        }
        off += n;
    }
    return frames;
}

/* Every byte fed is accounted for exactly once. */
static void assert_accounting(const j288_parser_t *p, size_t fed)
{
    const j288_parser_stats_t *s = &p->stats;
    TEST_ASSERT_EQUAL_UINT((unsigned)fed,
                           (unsigned)(s->garbage_bytes + s->dropped_bytes +
                                      s->frames * p->frame_len + j288_parser_pending(p)));
}

static void assert_stats(const j288_parser_t *p, uint32_t frames, uint32_t garbage,
                         uint32_t crc_errors, uint32_t truncated, uint32_t dropped)
{
    TEST_ASSERT_EQUAL_UINT32_MESSAGE(frames, p->stats.frames, "frames");
    TEST_ASSERT_EQUAL_UINT32_MESSAGE(garbage, p->stats.garbage_bytes, "garbage_bytes");
    TEST_ASSERT_EQUAL_UINT32_MESSAGE(crc_errors, p->stats.crc_errors, "crc_errors");
    TEST_ASSERT_EQUAL_UINT32_MESSAGE(truncated, p->stats.truncated, "truncated");
    TEST_ASSERT_EQUAL_UINT32_MESSAGE(dropped, p->stats.dropped_bytes, "dropped_bytes");
    TEST_ASSERT_EQUAL_PTR(&p->stats, j288_parser_stats(p)); /* the accessor the tools use */
}

/* Golden replies [first, first + n) back to back into dst; returns the length. */
static size_t some_replies(uint8_t *dst, size_t first, size_t n)
{
    size_t i;
    TEST_ASSERT_TRUE(n * J288_REPLY_LEN <= STREAM_CAP);
    for (i = 0; i < n; i++) {
        memcpy(dst + i * J288_REPLY_LEN, golden_replies[first + i].frame, J288_REPLY_LEN);
    }
    return n * J288_REPLY_LEN;
}

static size_t batch_size(size_t first, size_t total)
{
    return (total - first < BATCH) ? total - first : BATCH;
}

static const uint8_t *reply_named(const char *name)
{
    size_t i;
    for (i = 0; i < GOLDEN_REPLY_COUNT; i++) {
        if (strcmp(golden_replies[i].name, name) == 0) {
            return golden_replies[i].frame;
        }
    }
    TEST_FAIL_MESSAGE(name);
    return NULL;
}

/* A reply without 0xFC anywhere after its head (so no false head inside). */
static const uint8_t *plain_reply(void)
{
    return reply_named("spec_reply_id3");
}

static void test_api_errors(void)
{
    j288_parser_t p;
    size_t consumed = 99u;
    uint8_t b = 0;
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_parser_init(NULL, J288_PARSE_REPLY, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_ARG, j288_parser_init(&p, (j288_parse_kind_t)2, NULL));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_parser_init(&p, J288_PARSE_REPLY, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_parser_feed(NULL, &b, 1u, &consumed));
    TEST_ASSERT_EQUAL_UINT(0u, consumed);
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_parser_feed(&p, &b, 1u, NULL));
    consumed = 99u;
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_parser_feed(&p, NULL, 1u, &consumed));
    TEST_ASSERT_EQUAL_UINT(0u, consumed);
    TEST_ASSERT_EQUAL_INT(J288_PARSE_NONE, j288_parser_feed(&p, NULL, 0u, &consumed));
    TEST_ASSERT_EQUAL_UINT(0u, consumed);
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_parser_flush(NULL));
    j288_parser_reset(NULL); /* harmless */
    assert_stats(&p, 0, 0, 0, 0, 0);
}

/* All golden replies back to back, fed in chunks of many sizes and single bytes. */
static void test_back_to_back_any_chunking(void)
{
    static const size_t chunks[] = {1, 2, 3, 5, 7, 13, 25, 26, 27, 51, 52, 64, 1000, 0};
    size_t c, i;
    codec_rng_t rng;
    codec_rng_seed(&rng, 7u);
    for (c = 0; c < sizeof chunks / sizeof chunks[0]; c++) {
        j288_parser_t p;
        size_t first;
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_parser_init(&p, J288_PARSE_REPLY, NULL));
        for (first = 0; first < GOLDEN_REPLY_COUNT; first += BATCH) {
            size_t n = batch_size(first, GOLDEN_REPLY_COUNT);
            size_t len = some_replies(stream, first, n);
            TEST_ASSERT_EQUAL_UINT(n, feed_chunks(&p, stream, len, chunks[c], &rng));
            for (i = 0; i < n; i++) {
                TEST_ASSERT_EQUAL_HEX8_ARRAY_MESSAGE(golden_replies[first + i].frame, got[i],
                                                     J288_REPLY_LEN,
                                                     golden_replies[first + i].name);
            }
        }
        assert_stats(&p, GOLDEN_REPLY_COUNT, 0, 0, 0, 0);
        TEST_ASSERT_EQUAL_UINT(0u, j288_parser_pending(&p));
    }
    /* a whole batch in one call: one frame per call, consumed says where to go on */
    {
        j288_parser_t p;
        size_t off = 0, k = 0, consumed;
        size_t len = some_replies(stream, 0, BATCH);
        j288_parser_init(&p, J288_PARSE_REPLY, NULL);
        while (j288_parser_feed(&p, stream + off, len - off, &consumed) == J288_PARSE_FRAME) {
            TEST_ASSERT_EQUAL_UINT(J288_REPLY_LEN, consumed);
            TEST_ASSERT_EQUAL_HEX8_ARRAY(golden_replies[k].frame, j288_parser_frame(&p), 26u);
            off += consumed;
            k++;
        }
        TEST_ASSERT_EQUAL_UINT(BATCH, k);
        TEST_ASSERT_EQUAL_UINT(len, off);
        TEST_ASSERT_EQUAL_UINT(0u, consumed);
    }
}

static void test_commands_back_to_back(void)
{
    j288_parser_t p, rp;
    size_t i, first, fed = 0;
    codec_rng_t rng;
    codec_rng_seed(&rng, 11u);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_parser_init(&p, J288_PARSE_COMMAND, NULL));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_parser_init(&rp, J288_PARSE_REPLY, NULL));
    for (first = 0; first < GOLDEN_CMD_COUNT; first += BATCH) {
        size_t n = batch_size(first, GOLDEN_CMD_COUNT), len = 0;
        for (i = 0; i < n; i++) {
            memcpy(stream + len, golden_cmds[first + i].frame, J288_CMD_LEN);
            len += J288_CMD_LEN;
        }
        TEST_ASSERT_EQUAL_UINT(n, feed_chunks(&p, stream, len, 0u, &rng));
        for (i = 0; i < n; i++) {
            TEST_ASSERT_EQUAL_HEX8_ARRAY_MESSAGE(golden_cmds[first + i].frame, got[i], J288_CMD_LEN,
                                                 golden_cmds[first + i].name);
        }
        /* a reply parser finds no reply in a command stream */
        TEST_ASSERT_EQUAL_UINT(0u, feed_chunks(&rp, stream, len, 64u, &rng));
        fed += len;
    }
    assert_stats(&p, GOLDEN_CMD_COUNT, 0, 0, 0, 0);
    assert_accounting(&rp, fed);
}

/* One frame split in two at every offset. */
static void test_split_at_every_offset(void)
{
    const uint8_t *f = plain_reply();
    size_t cut;
    for (cut = 0; cut <= J288_REPLY_LEN; cut++) {
        j288_parser_t p;
        size_t consumed;
        j288_parser_init(&p, J288_PARSE_REPLY, NULL);
        TEST_ASSERT_EQUAL_INT(cut == J288_REPLY_LEN ? J288_PARSE_FRAME : J288_PARSE_NONE,
                              j288_parser_feed(&p, f, cut, &consumed));
        TEST_ASSERT_EQUAL_UINT(cut, consumed);
        if (cut < J288_REPLY_LEN) {
            TEST_ASSERT_EQUAL_UINT(cut, j288_parser_pending(&p));
            TEST_ASSERT_EQUAL_INT(J288_PARSE_FRAME,
                                  j288_parser_feed(&p, f + cut, J288_REPLY_LEN - cut, &consumed));
            TEST_ASSERT_EQUAL_UINT(J288_REPLY_LEN - cut, consumed);
        }
        TEST_ASSERT_EQUAL_HEX8_ARRAY(f, j288_parser_frame(&p), J288_REPLY_LEN);
        assert_stats(&p, 1, 0, 0, 0, 0);
    }
}

/* Garbage (no 0xFC in it) before, between and after frames: counted byte for byte. */
static void test_garbage_before_and_between(void)
{
    j288_parser_t p;
    codec_rng_t rng;
    size_t len = 0, i, n, garbage = 0;
    codec_rng_seed(&rng, 99u);
    for (i = 0; i < 40u; i++) {
        size_t g = codec_rng_below(&rng, 30u), k;
        TEST_ASSERT_TRUE(len + g + J288_REPLY_LEN + 9u <= STREAM_CAP);
        for (k = 0; k < g; k++) {
            uint8_t b = (uint8_t)codec_rng_u32(&rng);
            stream[len++] = (b == 0xFCu) ? 0xEEu : b;
        }
        garbage += g;
        memcpy(stream + len, golden_replies[i].frame, J288_REPLY_LEN);
        len += J288_REPLY_LEN;
    }
    memset(stream + len, 0x55, 9u);
    len += 9u;
    garbage += 9u;
    j288_parser_init(&p, J288_PARSE_REPLY, NULL);
    n = feed_chunks(&p, stream, len, 0u, &rng);
    TEST_ASSERT_EQUAL_UINT(40u, n);
    for (i = 0; i < n; i++) {
        TEST_ASSERT_EQUAL_HEX8_ARRAY(golden_replies[i].frame, got[i], J288_REPLY_LEN);
    }
    assert_stats(&p, 40u, (uint32_t)garbage, 0, 0, 0);
    assert_accounting(&p, len);
}

/* Lone head bytes and FC FC EE: the last FC before EE starts the frame. */
static void test_head_byte_sequences(void)
{
    static const uint8_t pre[][4] = {
        {0xFC, 0x00, 0xFC, 0x12}, /* FC not followed by EE, twice: 4 garbage */
        {0xFC, 0xFC, 0xFC, 0xFC}, /* then FC EE: 4 garbage (the frame's own FC follows) */
        {0xEE, 0xEE, 0xFE, 0xEE}, /* the other head, and EE alone: garbage for replies */
    };
    size_t k;
    for (k = 0; k < sizeof pre / sizeof pre[0]; k++) {
        j288_parser_t p;
        uint8_t buf[4 + J288_REPLY_LEN];
        size_t consumed;
        memcpy(buf, pre[k], 4u);
        memcpy(buf + 4, plain_reply(), J288_REPLY_LEN);
        j288_parser_init(&p, J288_PARSE_REPLY, NULL);
        TEST_ASSERT_EQUAL_INT(J288_PARSE_FRAME, j288_parser_feed(&p, buf, sizeof buf, &consumed));
        TEST_ASSERT_EQUAL_UINT(sizeof buf, consumed);
        TEST_ASSERT_EQUAL_HEX8_ARRAY(plain_reply(), j288_parser_frame(&p), J288_REPLY_LEN);
        assert_stats(&p, 1, 4, 0, 0, 0);
    }
    /* FC FC EE fed one byte at a time */
    {
        j288_parser_t p;
        static const uint8_t seq[3] = {0xFC, 0xFC, 0xEE};
        size_t consumed, i;
        j288_parser_init(&p, J288_PARSE_REPLY, NULL);
        for (i = 0; i < 3u; i++) {
            TEST_ASSERT_EQUAL_INT(J288_PARSE_NONE, j288_parser_feed(&p, &seq[i], 1u, &consumed));
        }
        TEST_ASSERT_EQUAL_UINT(2u, j288_parser_pending(&p));
        TEST_ASSERT_EQUAL_INT(J288_PARSE_FRAME,
                              j288_parser_feed(&p, plain_reply() + 2, 24u, &consumed));
        assert_stats(&p, 1, 1, 0, 0, 0);
    }
}

/* The line goes idle inside a frame: flush drops and counts it; the next frame is fine. */
static void test_truncated_then_flush(void)
{
    j288_parser_t p;
    size_t consumed, cut;
    for (cut = 1; cut < J288_REPLY_LEN; cut++) {
        j288_parser_init(&p, J288_PARSE_REPLY, NULL);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_parser_flush(&p)); /* nothing pending */
        j288_parser_feed(&p, plain_reply(), cut, &consumed);
        TEST_ASSERT_EQUAL_INT(J288_ERR_TRUNCATED, j288_parser_flush(&p));
        TEST_ASSERT_EQUAL_UINT(0u, j288_parser_pending(&p));
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_parser_flush(&p));
        TEST_ASSERT_EQUAL_INT(J288_PARSE_FRAME,
                              j288_parser_feed(&p, plain_reply(), J288_REPLY_LEN, &consumed));
        assert_stats(&p, 1, 0, 0, 1, (uint32_t)cut);
        assert_accounting(&p, cut + J288_REPLY_LEN);
    }
}

/* Truncated without an idle event: the next frame's head is found inside the dropped one. */
static void test_truncated_then_frame_without_flush(void)
{
    j288_parser_t p;
    uint8_t buf[2 * J288_REPLY_LEN];
    size_t cut;
    for (cut = 2; cut < J288_REPLY_LEN; cut++) {
        size_t n;
        codec_rng_t rng;
        codec_rng_seed(&rng, (uint32_t)cut);
        memcpy(buf, plain_reply(), cut);
        memcpy(buf + cut, golden_replies[5].frame, J288_REPLY_LEN);
        j288_parser_init(&p, J288_PARSE_REPLY, NULL);
        n = feed_chunks(&p, buf, cut + J288_REPLY_LEN, 0u, &rng);
        TEST_ASSERT_EQUAL_UINT(1u, n);
        TEST_ASSERT_EQUAL_HEX8_ARRAY(golden_replies[5].frame, got[0], J288_REPLY_LEN);
        assert_stats(&p, 1, 0, 1, 0, (uint32_t)cut);
    }
}

/* A corrupted frame (any single byte changed after the head) is dropped whole; the next
 * frame arrives. */
static void test_corrupted_frame(void)
{
    size_t pos;
    for (pos = 2; pos < J288_REPLY_LEN; pos++) {
        j288_parser_t p;
        uint8_t buf[2 * J288_REPLY_LEN];
        size_t n;
        codec_rng_t rng;
        codec_rng_seed(&rng, (uint32_t)pos);
        memcpy(buf, plain_reply(), J288_REPLY_LEN);
        buf[pos] = (uint8_t)(buf[pos] ^ 0x01u); /* never turns into 0xFC here */
        memcpy(buf + J288_REPLY_LEN, golden_replies[9].frame, J288_REPLY_LEN);
        j288_parser_init(&p, J288_PARSE_REPLY, NULL);
        n = feed_chunks(&p, buf, sizeof buf, 0u, &rng);
        TEST_ASSERT_EQUAL_UINT(1u, n);
        TEST_ASSERT_EQUAL_HEX8_ARRAY(golden_replies[9].frame, got[0], J288_REPLY_LEN);
        assert_stats(&p, 1, 0, 1, 0, J288_REPLY_LEN);
    }
}

/* A corrupted reply at the start of a feed and a good one behind it, in one call: the first is
 * dropped (one CRC error), the second comes out of the same call as the parser's own copy. */
static void test_corrupted_then_good_in_one_feed(void)
{
    j288_parser_t p;
    uint8_t buf[2 * J288_REPLY_LEN];
    size_t used = 0u;
    memcpy(buf, plain_reply(), J288_REPLY_LEN);
    buf[10] = (uint8_t)(buf[10] ^ 0x01u);
    memcpy(buf + J288_REPLY_LEN, golden_replies[9].frame, J288_REPLY_LEN);
    j288_parser_init(&p, J288_PARSE_REPLY, NULL);
    TEST_ASSERT_EQUAL_INT(J288_PARSE_FRAME, j288_parser_feed(&p, buf, sizeof buf, &used));
    TEST_ASSERT_EQUAL_UINT(sizeof buf, used);
    memset(buf, 0, sizeof buf); /* the frame must not point into the caller's data */
    TEST_ASSERT_EQUAL_HEX8_ARRAY(golden_replies[9].frame, j288_parser_frame(&p), J288_REPLY_LEN);
    assert_stats(&p, 1, 0, 1, 0, J288_REPLY_LEN);
}

/* A payload holding FC EE: intact it is one frame; with its real head lost, the parser locks
 * on the false head, fails the CRC, and still finds the next real frame. */
static void test_false_head_inside_payload(void)
{
    const uint8_t *fh = reply_named("false_head_fc_ee_in_pos"); /* FC EE at bytes 11-12 */
    const uint8_t *next = plain_reply();
    uint8_t buf[3 * J288_REPLY_LEN];
    j288_parser_t p;
    size_t n, start;
    codec_rng_t rng;
    codec_rng_seed(&rng, 5u);
    TEST_ASSERT_EQUAL_HEX8(0xFC, fh[11]);
    TEST_ASSERT_EQUAL_HEX8(0xEE, fh[12]);

    memcpy(buf, fh, J288_REPLY_LEN);
    memcpy(buf + J288_REPLY_LEN, next, J288_REPLY_LEN);
    j288_parser_init(&p, J288_PARSE_REPLY, NULL);
    n = feed_chunks(&p, buf, 2u * J288_REPLY_LEN, 1u, &rng);
    TEST_ASSERT_EQUAL_UINT(2u, n);
    TEST_ASSERT_EQUAL_HEX8_ARRAY(fh, got[0], J288_REPLY_LEN);
    assert_stats(&p, 2, 0, 0, 0, 0);

    /* head lost (first byte, or both head bytes): bytes before the false head are garbage,
     * the bytes from it up to the next real head are dropped with one CRC error */
    for (start = 1; start <= 2u; start++) {
        size_t len = J288_REPLY_LEN - start + J288_REPLY_LEN;
        memcpy(buf, fh + start, J288_REPLY_LEN - start);
        memcpy(buf + J288_REPLY_LEN - start, next, J288_REPLY_LEN);
        j288_parser_init(&p, J288_PARSE_REPLY, NULL);
        n = feed_chunks(&p, buf, len, 0u, &rng);
        TEST_ASSERT_EQUAL_UINT(1u, n);
        TEST_ASSERT_EQUAL_HEX8_ARRAY(next, got[0], J288_REPLY_LEN);
        assert_stats(&p, 1, (uint32_t)(11u - start), 1, 0, J288_REPLY_LEN - 11u);
        assert_accounting(&p, len);
    }
}

/* The same for commands: FE EE inside a command's payload. */
static void test_false_head_inside_command(void)
{
    const golden_cmd_t *g = NULL;
    uint8_t buf[2 * J288_CMD_LEN];
    j288_parser_t p;
    size_t i, n, k = 0;
    codec_rng_t rng;
    codec_rng_seed(&rng, 6u);
    for (i = 0; i < GOLDEN_CMD_COUNT; i++) {
        if (strcmp(golden_cmds[i].name, "false_head_fe_ee_in_tau") == 0) {
            g = &golden_cmds[i];
        }
    }
    TEST_ASSERT_NOT_NULL(g);
    TEST_ASSERT_EQUAL_HEX8(0xFE, g->frame[4]);
    TEST_ASSERT_EQUAL_HEX8(0xEE, g->frame[5]);
    memcpy(buf, g->frame + 1, J288_CMD_LEN - 1u);
    memcpy(buf + J288_CMD_LEN - 1u, golden_cmds[0].frame, J288_CMD_LEN);
    j288_parser_init(&p, J288_PARSE_COMMAND, NULL);
    n = feed_chunks(&p, buf, 2u * J288_CMD_LEN - 1u, 1u, &rng);
    TEST_ASSERT_EQUAL_UINT(1u, n);
    TEST_ASSERT_EQUAL_HEX8_ARRAY(golden_cmds[0].frame, got[k], J288_CMD_LEN);
    assert_stats(&p, 1, 3, 1, 0, J288_CMD_LEN - 4u);
}

/* reset drops a partial frame without counting it. */
static void test_reset(void)
{
    j288_parser_t p;
    size_t consumed;
    j288_parser_init(&p, J288_PARSE_REPLY, NULL);
    j288_parser_feed(&p, plain_reply(), 10u, &consumed);
    TEST_ASSERT_EQUAL_UINT(10u, j288_parser_pending(&p));
    j288_parser_reset(&p);
    TEST_ASSERT_EQUAL_UINT(0u, j288_parser_pending(&p));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_parser_flush(&p));
    TEST_ASSERT_EQUAL_INT(J288_PARSE_FRAME,
                          j288_parser_feed(&p, plain_reply(), J288_REPLY_LEN, &consumed));
    assert_stats(&p, 1, 0, 0, 0, 0);
}

/* Random noise with golden frames in between: every frame comes out, in order, and every
 * byte is accounted for. Noise may hold heads: they cost CRC errors, never a frame. */
static void test_noise_with_frames(void)
{
    codec_rng_t rng;
    unsigned round;
    codec_rng_seed(&rng, 0x5EEDu);
    for (round = 0; round < 40u; round++) {
        j288_parser_t p;
        crc_counter_t counter = {0u};
        const j288_crc_t engine = {counting_crc, &counter};
        size_t len = 0, i, n, nframes = 28u;
        for (i = 0; i < nframes; i++) {
            size_t g = codec_rng_below(&rng, 60u), k;
            TEST_ASSERT_TRUE(len + g + J288_REPLY_LEN <= STREAM_CAP);
            for (k = 0; k < g; k++) {
                /* heads are frequent on purpose */
                uint32_t r = codec_rng_below(&rng, 8u);
                stream[len++] = r == 0u ? 0xFCu : r == 1u ? 0xEEu : (uint8_t)codec_rng_u32(&rng);
            }
            memcpy(stream + len, golden_replies[(round * 61u + i) % GOLDEN_REPLY_COUNT].frame,
                   J288_REPLY_LEN);
            len += J288_REPLY_LEN;
        }
        j288_parser_init(&p, J288_PARSE_REPLY, &engine);
        n = feed_chunks(&p, stream, len, 0u, &rng);
        TEST_ASSERT_EQUAL_UINT(nframes, n);
        for (i = 0; i < n; i++) {
            TEST_ASSERT_EQUAL_HEX8_ARRAY(
                golden_replies[(round * 61u + i) % GOLDEN_REPLY_COUNT].frame, got[i], 26u);
        }
        TEST_ASSERT_EQUAL_UINT32(nframes, p.stats.frames);
        TEST_ASSERT_EQUAL_UINT32(0u, p.stats.truncated);
        assert_accounting(&p, len);
        /* bounded work: at most one CRC per byte fed */
        TEST_ASSERT_TRUE(counter.calls <= len);
        TEST_ASSERT_EQUAL_UINT(p.stats.frames + p.stats.crc_errors, counter.calls);
    }
}

/* Worst case: nothing but heads. No frame, at most one CRC per byte, all accounted for. */
static void test_only_heads(void)
{
    j288_parser_t p;
    crc_counter_t counter = {0u};
    const j288_crc_t engine = {counting_crc, &counter};
    size_t i, len = 2000u;
    codec_rng_t rng;
    codec_rng_seed(&rng, 3u);
    for (i = 0; i < len; i++) {
        stream[i] = (i % 2u == 0u) ? 0xFCu : 0xEEu;
    }
    j288_parser_init(&p, J288_PARSE_REPLY, &engine);
    TEST_ASSERT_EQUAL_UINT(0u, feed_chunks(&p, stream, len, 0u, &rng));
    assert_accounting(&p, len);
    TEST_ASSERT_TRUE(counter.calls > 0u);
    TEST_ASSERT_TRUE(counter.calls <= len);
    TEST_ASSERT_EQUAL_UINT32(0u, p.stats.garbage_bytes);
    TEST_ASSERT_TRUE(j288_parser_pending(&p) < J288_REPLY_LEN);
}

/* j288_parser_reply(): every golden reply's fields (the generator's, not the codec's), the
 * reply taken whole (checked where it lies, then moved into the parser) and a byte at a time
 * (collected in the parser), behind a garbage byte so that the caller's copy is unaligned. */
static void check_parser_reply(const j288_parser_t *p, const golden_reply_t *g)
{
    j288_reply_raw_t r;
    memset(&r, 0xA5, sizeof r);
    j288_parser_reply(p, &r);
    TEST_ASSERT_EQUAL_UINT8_MESSAGE(g->id, r.id, g->name);
    TEST_ASSERT_EQUAL_UINT8_MESSAGE(g->status, r.status, g->name);
    TEST_ASSERT_EQUAL_MESSAGE(g->watchdog != 0u, r.watchdog_tripped, g->name);
    TEST_ASSERT_EQUAL_INT8_MESSAGE(g->case_temp, r.case_temp_c, g->name);
    TEST_ASSERT_EQUAL_UINT8_MESSAGE(g->winding_temp, r.winding_temp_c, g->name);
    TEST_ASSERT_EQUAL_UINT8_MESSAGE(g->voltage_raw, r.voltage_raw, g->name);
    TEST_ASSERT_EQUAL_INT16_MESSAGE(g->torque, r.torque, g->name);
    TEST_ASSERT_EQUAL_INT16_MESSAGE(g->speed, r.speed, g->name);
    TEST_ASSERT_EQUAL_INT32_MESSAGE(g->pos, r.pos, g->name);
    TEST_ASSERT_EQUAL_HEX32_MESSAGE(g->faults, r.faults, g->name);
    TEST_ASSERT_EQUAL_UINT16_MESSAGE(g->out_pos, r.out_pos, g->name);
    TEST_ASSERT_EQUAL_UINT8_MESSAGE(g->warnings, r.warnings, g->name);
    TEST_ASSERT_EQUAL_UINT16_MESSAGE(g->reserved, r.reserved, g->name);
}

static void test_parser_reply_golden(void)
{
    size_t k, i, used;
    for (k = 0; k < GOLDEN_REPLY_COUNT; k++) {
        const golden_reply_t *g = &golden_replies[k];
        j288_parser_t p;
        if (g->expect != J288_OK) {
            continue;
        }
        stream[0] = 0x00u;
        memcpy(&stream[1], g->frame, J288_REPLY_LEN);
        j288_parser_init(&p, J288_PARSE_REPLY, NULL);
        TEST_ASSERT_EQUAL_INT(J288_PARSE_NONE, j288_parser_feed(&p, stream, 1u, &used));
        TEST_ASSERT_EQUAL_INT_MESSAGE(J288_PARSE_FRAME,
                                      j288_parser_feed(&p, &stream[1], J288_REPLY_LEN, &used),
                                      g->name);
        check_parser_reply(&p, g);
        j288_parser_init(&p, J288_PARSE_REPLY, NULL);
        for (i = 0; i + 1u < J288_REPLY_LEN; i++) {
            TEST_ASSERT_EQUAL_INT(J288_PARSE_NONE, j288_parser_feed(&p, &g->frame[i], 1u, &used));
        }
        TEST_ASSERT_EQUAL_INT(J288_PARSE_FRAME, j288_parser_feed(&p, &g->frame[i], 1u, &used));
        check_parser_reply(&p, g);
    }
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_api_errors);
    RUN_TEST(test_back_to_back_any_chunking);
    RUN_TEST(test_commands_back_to_back);
    RUN_TEST(test_split_at_every_offset);
    RUN_TEST(test_garbage_before_and_between);
    RUN_TEST(test_head_byte_sequences);
    RUN_TEST(test_truncated_then_flush);
    RUN_TEST(test_truncated_then_frame_without_flush);
    RUN_TEST(test_corrupted_frame);
    RUN_TEST(test_corrupted_then_good_in_one_feed);
    RUN_TEST(test_false_head_inside_payload);
    RUN_TEST(test_false_head_inside_command);
    RUN_TEST(test_reset);
    RUN_TEST(test_noise_with_frames);
    RUN_TEST(test_only_heads);
    RUN_TEST(test_parser_reply_golden);
    return UNITY_END();
}
