/*
 * Fuzz target: the incremental frame parser, fed the same byte stream in arbitrary chunks.
 *
 * Input: byte 0 = flags (bit 0: parse commands instead of replies; bits 1-2: CRC engine:
 * default, table, nibble or bitwise through a j288_crc_t), byte 1 = number of chunk-size
 * bytes (0-15) that follow; each chunk byte gives a size (bits 0-5), a NULL data pointer for
 * an empty chunk (bit 6) and a flush (line idle) after the chunk (bit 7); the chunk sizes are
 * used cyclically. The rest is the stream.
 *
 * Invariants, checked against a plain sliding-window reference written from the spec (at
 * each position: a head followed by a full frame whose CRC is right is a frame, skip it;
 * otherwise move one byte on; an idle flush starts afresh):
 * - every frame handed out has the right head and a valid CRC (independent CRC), decodes,
 *   and is exactly the reference's next frame: chunking never changes what is accepted;
 * - feed never consumes more than it was given, and consumes the frame's last byte exactly;
 * - the statistics add up: garbage + dropped + 26 * frames + pending = bytes fed; CRC
 *   errors and truncations match the reference;
 * - the same stream fed one byte per call (so that the parser never sees a whole frame in one
 *   piece and only its byte state machine runs), flushed at the same places, gives the same
 *   frames at the same positions and exactly the same statistics: the whole-frame fast path
 *   and the byte path agree.
 */
#include "fuzz_common.h"

#include "j288/frame.h"
#include "j288/parser.h"

#include <string.h>

#define MAX_FRAMES 4096u
#define MAX_FLUSHES 8192u

typedef struct {
    size_t flen;
    uint8_t head0;
    size_t frame_pos[MAX_FRAMES]; /* where the reference finds frames */
    size_t nframes;
    uint32_t crc_errors;
    uint32_t truncated;
} ref_t;

/* Two unpacked replies agree field by field (padding aside). */
static inline int fuzz_reply_equal(const j288_reply_raw_t *a, const j288_reply_raw_t *b)
{
    return (a->id == b->id) && (a->status == b->status) &&
           (a->watchdog_tripped == b->watchdog_tripped) && (a->case_temp_c == b->case_temp_c) &&
           (a->winding_temp_c == b->winding_temp_c) && (a->voltage_raw == b->voltage_raw) &&
           (a->torque == b->torque) && (a->speed == b->speed) && (a->pos == b->pos) &&
           (a->faults == b->faults) && (a->out_pos == b->out_pos) &&
           (a->warnings == b->warnings) && (a->reserved == b->reserved);
}

static int ref_frame_ok(const ref_t *r, const uint8_t *f)
{
    return (r->flen == J288_REPLY_LEN) ? fuzz_reply_valid(f) : fuzz_cmd_valid(f);
}

/* The reference over one segment [s, e) between idle flushes; returns bytes left pending. */
static size_t ref_segment(ref_t *r, const uint8_t *st, size_t s, size_t e)
{
    size_t p = s;
    while (p < e) {
        int head = (st[p] == r->head0) && ((p + 1u == e) || (st[p + 1u] == 0xEEu));
        if (p + r->flen > e) {
            if (head) {
                return e - p;
            }
            p++;
            continue;
        }
        if (head && ref_frame_ok(r, &st[p])) {
            if (r->nframes < MAX_FRAMES) {
                r->frame_pos[r->nframes] = p;
            }
            r->nframes++;
            p += r->flen;
        } else {
            if (head) {
                r->crc_errors++;
            }
            p++;
        }
    }
    return 0u;
}

static uint32_t crc_fn_table(void *ctx, const uint8_t *d, size_t n)
{
    (void)ctx;
    return j288_crc32_update_table(J288_CRC32_INIT, d, n);
}
static uint32_t crc_fn_nibble(void *ctx, const uint8_t *d, size_t n)
{
    (void)ctx;
    return j288_crc32_update_nibble(J288_CRC32_INIT, d, n);
}
static uint32_t crc_fn_bitwise(void *ctx, const uint8_t *d, size_t n)
{
    (void)ctx;
    return j288_crc32_update_bitwise(J288_CRC32_INIT, d, n);
}

/* The stream again, one byte per feed, with the flushes at the recorded stream positions (in
 * order, before the byte at that position); frames, statistics and pending bytes must equal
 * those of the chunked run. */
static void check_bytewise(const j288_parser_t *chunked, j288_parse_kind_t kind,
                           const j288_crc_t *crc, const uint8_t *st, size_t n,
                           const size_t *flush_pos, size_t nflush, const size_t *got_pos,
                           size_t got)
{
    static size_t pos2[MAX_FRAMES];
    j288_parser_t p;
    size_t i, f = 0u, got2 = 0u;
    size_t flen = (kind == J288_PARSE_REPLY) ? J288_REPLY_LEN : J288_CMD_LEN;
    FUZZ_CHECK(j288_parser_init(&p, kind, crc) == J288_OK);
    for (i = 0u; i <= n; i++) {
        size_t used = 0u;
        while ((f < nflush) && (flush_pos[f] == i)) {
            (void)j288_parser_flush(&p);
            f++;
        }
        if (i == n) {
            break;
        }
        if (j288_parser_feed(&p, &st[i], 1u, &used) == J288_PARSE_FRAME) {
            FUZZ_CHECK(i + 1u >= flen);
            if (got2 < MAX_FRAMES) {
                pos2[got2] = i + 1u - flen;
            }
            got2++;
        }
        FUZZ_CHECK(used == 1u);
    }
    FUZZ_CHECK(got2 == got);
    for (i = 0u; (i < got) && (i < MAX_FRAMES); i++) {
        FUZZ_CHECK(pos2[i] == got_pos[i]);
    }
    FUZZ_CHECK(p.stats.frames == chunked->stats.frames);
    FUZZ_CHECK(p.stats.garbage_bytes == chunked->stats.garbage_bytes);
    FUZZ_CHECK(p.stats.crc_errors == chunked->stats.crc_errors);
    FUZZ_CHECK(p.stats.truncated == chunked->stats.truncated);
    FUZZ_CHECK(p.stats.dropped_bytes == chunked->stats.dropped_bytes);
    FUZZ_CHECK(j288_parser_pending(&p) == j288_parser_pending(chunked));
}

/* End of a segment: the parser's pending bytes and frames so far match the reference. */
static void check_segment(ref_t *ref, const j288_parser_t *parser, const uint8_t *st,
                          size_t seg_start, size_t seg_end, const size_t *got_pos, size_t got)
{
    size_t k;
    size_t pending = ref_segment(ref, st, seg_start, seg_end);
    FUZZ_CHECK(pending == j288_parser_pending(parser));
    FUZZ_CHECK(ref->nframes == got);
    for (k = 0u; k < got && k < MAX_FRAMES; k++) {
        FUZZ_CHECK(got_pos[k] == ref->frame_pos[k]);
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static ref_t ref;
    static size_t got_pos[MAX_FRAMES];
    static size_t flush_pos[MAX_FLUSHES];
    size_t nflush = 0u;
    j288_parser_t parser;
    j288_crc_t engine = {NULL, NULL};
    const j288_crc_t *crc = &engine;
    uint8_t flags, nchunks;
    const uint8_t *chunks, *st;
    size_t n, pos = 0u, seg_start = 0u, got = 0u, ci = 0u;
    j288_parse_kind_t kind;
    const j288_parser_stats_t *stv;

    if (size < 2u) {
        return 0;
    }
    flags = data[0];
    nchunks = (uint8_t)(data[1] & 15u);
    if (size < 2u + (size_t)nchunks) {
        return 0;
    }
    chunks = &data[2];
    st = &data[2u + nchunks];
    n = size - 2u - nchunks;

    kind = ((flags & 1u) != 0u) ? J288_PARSE_COMMAND : J288_PARSE_REPLY;
    switch ((flags >> 1) & 3u) {
    case 1u: engine.fn = crc_fn_table; break;
    case 2u: engine.fn = crc_fn_nibble; break;
    case 3u: engine.fn = crc_fn_bitwise; break;
    default: crc = NULL; break;
    }
    FUZZ_CHECK(j288_parser_init(&parser, kind, crc) == J288_OK);
    FUZZ_CHECK(j288_parser_pending(&parser) == 0u);

    memset(&ref, 0, sizeof ref);
    ref.flen = (kind == J288_PARSE_REPLY) ? J288_REPLY_LEN : J288_CMD_LEN;
    ref.head0 = (kind == J288_PARSE_REPLY) ? 0xFCu : 0xFEu;

    for (;;) {
        uint8_t c = (nchunks > 0u) ? chunks[ci % nchunks] : 0u;
        size_t want = (nchunks > 0u) ? (size_t)(c & 0x3Fu) : n;
        size_t take, off = 0u;
        const uint8_t *chunk;

        if ((pos >= n) && (ci >= nchunks)) {
            break; /* every byte fed and every chunk descriptor used once */
        }
        if (ci > 4u * n + 64u) {
            break; /* only empty chunks: stop */
        }
        ci++;
        take = (want < n - pos) ? want : n - pos;
        chunk = ((take == 0u) && ((c & 0x40u) != 0u)) ? NULL : &st[pos];
        do {
            size_t consumed = 12345u;
            int rc = j288_parser_feed(&parser, (chunk == NULL) ? NULL : &chunk[off], take - off,
                                      &consumed);
            FUZZ_CHECK((rc == J288_PARSE_NONE) || (rc == J288_PARSE_FRAME));
            FUZZ_CHECK(consumed <= take - off);
            if (rc == J288_PARSE_FRAME) {
                const uint8_t *f = j288_parser_frame(&parser);
                size_t end = pos + off + consumed; /* stream index just past the frame */
                FUZZ_CHECK(consumed >= 1u);
                FUZZ_CHECK(f != NULL);
                if (kind == J288_PARSE_REPLY) {
                    j288_reply_raw_t r, held;
                    FUZZ_CHECK(fuzz_reply_valid(f));
                    FUZZ_CHECK(j288_reply_decode(f, &r, NULL) == J288_OK);
                    /* The parser's word-wise unpack against the byte-wise one. */
                    memset(&held, 0, sizeof held);
                    j288_parser_reply(&parser, &held);
                    FUZZ_CHECK(fuzz_reply_equal(&r, &held));
                } else {
                    j288_cmd_raw_t cmd;
                    FUZZ_CHECK(fuzz_cmd_valid(f));
                    FUZZ_CHECK(j288_cmd_decode(f, &cmd, NULL) == J288_OK);
                }
                /* The frame is exactly the stream's bytes ending at the last consumed one. */
                FUZZ_CHECK(end >= ref.flen);
                FUZZ_CHECK(memcmp(f, &st[end - ref.flen], ref.flen) == 0);
                if (got < MAX_FRAMES) {
                    got_pos[got] = end - ref.flen;
                }
                got++;
            } else {
                FUZZ_CHECK(consumed == take - off);
            }
            off += consumed;
        } while (off < take);
        pos += take;
        if ((c & 0x80u) != 0u) {
            size_t pending = j288_parser_pending(&parser);
            if (nflush < MAX_FLUSHES) {
                flush_pos[nflush] = pos;
            }
            nflush++;
            check_segment(&ref, &parser, st, seg_start, pos, got_pos, got);
            FUZZ_CHECK(j288_parser_flush(&parser) ==
                       ((pending > 0u) ? J288_ERR_TRUNCATED : J288_OK));
            FUZZ_CHECK(j288_parser_pending(&parser) == 0u);
            if (pending > 0u) {
                ref.truncated++;
            }
            seg_start = pos;
        }
    }
    check_segment(&ref, &parser, st, seg_start, pos, got_pos, got);
    stv = &parser.stats;
    FUZZ_CHECK(stv->frames == got);
    FUZZ_CHECK(stv->crc_errors == ref.crc_errors);
    FUZZ_CHECK(stv->truncated == ref.truncated);
    FUZZ_CHECK((size_t)stv->garbage_bytes + stv->dropped_bytes + ref.flen * (size_t)stv->frames +
                   j288_parser_pending(&parser) ==
               pos);
    if (nflush <= MAX_FLUSHES) {
        check_bytewise(&parser, kind, crc, st, pos, flush_pos, nflush, got_pos, got);
    }
    return 0;
}
