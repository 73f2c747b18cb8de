/* Incremental frame parser; see j288/parser.h for the contract. */
#include "j288/parser.h"

#include <string.h>

#include "frame_priv.h"
#include "parser_priv.h"

/* The frame held: from the second byte of the word-aligned store (parser.h). */
static uint8_t *buf(j288_parser_t *p)
{
    return &p->held.bytes[2];
}

#if J288_STORE32_AS_WORD
/* Word i of the store (the frame's bytes 4i-2 .. 4i+1): one aligned store, little-endian as
 * the core (J288_STORE32_AS_WORD holds only on little-endian cores). */
static void hold_word(j288_parser_t *p, size_t i, uint32_t v)
{
    p->held.words[i] = v;
}
#endif

int j288_parser_init(j288_parser_t *p, j288_parse_kind_t kind, const j288_crc_t *crc)
{
    if (p == NULL) {
        return J288_ERR_NULL;
    }
    if ((kind != J288_PARSE_REPLY) && (kind != J288_PARSE_COMMAND)) {
        return J288_ERR_BAD_ARG;
    }
    (void)memset(p, 0, sizeof *p);
    p->kind = kind;
    p->crc = crc;
    if (kind == J288_PARSE_REPLY) {
        p->head0 = J288_REPLY_HEAD0;
        p->frame_len = (uint8_t)J288_REPLY_LEN;
    } else {
        p->head0 = J288_CMD_HEAD0;
        p->frame_len = (uint8_t)J288_CMD_LEN;
    }
    return J288_OK;
}

/* The CRC of a whole frame at f against its field, the frame's last four bytes; one
 * straight-line check per kind (constant offsets and word counts). */
J288_NOINLINE static bool frame_crc_ok(const j288_parser_t *p, const uint8_t *f)
{
    if (p->kind == J288_PARSE_REPLY) {
        return j288_reply_crc_ok(p->crc, f);
    }
    return j288_cmd_crc_ok(p->crc, f);
}

/* The head's two bytes as one little-endian halfword. */
static uint16_t head16(const j288_parser_t *p)
{
    return (uint16_t)(p->head0 | ((unsigned)J288_REPLY_HEAD1 << 8));
}

/* After a bad frame: keep from the next position that could still start a frame. A head
 * byte at the very end counts, since its second byte is not known yet. */
static void resync(j288_parser_t *p)
{
    uint8_t i;
    for (i = 1u; i < p->len; i++) {
        if ((buf(p)[i] == p->head0) &&
            (((i + 1u) == p->len) || (buf(p)[i + 1u] == J288_REPLY_HEAD1))) {
            break;
        }
    }
    p->stats.dropped_bytes += i;
    p->len = (uint8_t)(p->len - i);
    (void)memmove(buf(p), &buf(p)[i], p->len);
}

/* A whole frame held in buf failed its CRC: count it and resynchronise inside it. */
static void drop_frame(j288_parser_t *p)
{
    p->stats.crc_errors++;
    resync(p);
}

/* The byte path has collected a whole frame in buf: count it, or drop it and resync. Out of
 * line, so that the byte path's per-byte work stays short. */
J288_NOINLINE static bool collected(j288_parser_t *p)
{
    if (frame_crc_ok(p, buf(p))) {
        p->stats.frames++;
        p->len = 0u;
        return true;
    }
    drop_frame(p);
    return false;
}

/* One byte in; true when a good frame completes. Both heads end in 0xEE. */
static bool take_byte(j288_parser_t *p, uint8_t b)
{
    if (p->len == 0u) {
        if (b == p->head0) {
            buf(p)[0] = b;
            p->len = 1u;
        } else {
            p->stats.garbage_bytes++;
        }
        return false;
    }
    if ((p->len == 1u) && (b != J288_REPLY_HEAD1)) {
        /* Not a head after all: the first byte was garbage; this one may start a head. */
        p->stats.garbage_bytes++;
        if (b != p->head0) {
            p->stats.garbage_bytes++;
            p->len = 0u;
        }
        return false;
    }
    buf(p)[p->len] = b;
    p->len++;
    return (p->len == p->frame_len) && collected(p);
}

/* While hunting, a head with a whole frame behind it in the caller's data: checked where it
 * lies. True when good (counted); a bad one is copied into buf and dropped exactly as the byte
 * path drops it once collected. */
/* A whole frame at f failed its CRC: into buf, dropped as the byte path drops it. */
static void drop_whole(j288_parser_t *p, const uint8_t *f)
{
    (void)memcpy(buf(p), f, p->frame_len);
    p->len = p->frame_len;
    drop_frame(p);
}

static bool take_whole(j288_parser_t *p, const uint8_t *f)
{
    if (frame_crc_ok(p, f)) {
        p->stats.frames++;
        return true;
    }
    drop_whole(p, f);
    return false;
}

/* The general case: a byte that does not start a head while hunting is garbage, a head with a
 * whole frame behind it goes to take_whole(), everything else through take_byte(), which
 * also resynchronises inside a dropped frame. Returns the bytes consumed; *frame is set when
 * a good frame completed (and left alone otherwise). */
J288_NOINLINE static size_t scan_bytes(j288_parser_t *p, const uint8_t *data, size_t len,
                                       const uint8_t **frame)
{
    size_t i = 0u;

    while (i < len) {
        const uint8_t *f = &data[i];
        size_t left = len - i;
        if ((p->len == 0u) && (left >= 2u)) {
            if (j288_get_u16le(f) != head16(p)) {
                p->stats.garbage_bytes++;
                i++;
                continue;
            }
            if (left >= p->frame_len) {
                i += p->frame_len;
                if (take_whole(p, f)) {
                    *frame = f;
                    return i;
                }
                continue;
            }
        }
        i++;
        if (take_byte(p, *f)) {
            *frame = buf(p);
            return i;
        }
    }
    return len;
}

/* The common case: nothing held and data starting with a whole frame, as a frame received in
 * one piece arrives. Returns the bytes taken (the frame, good or dropped; *good tells), or 0
 * when data does not start that way. */
static J288_INLINE_HOT size_t take_first(j288_parser_t *p, const uint8_t *data, size_t len,
                                         bool *good)
{
    *good = false;
    /* (A frame is at least a command long: data holds two bytes to read.) */
    if ((p->len != 0u) || (len < J288_CMD_LEN) || (len < p->frame_len) ||
        (j288_get_u16le(data) != head16(p))) {
        return 0u;
    }
    *good = take_whole(p, data);
    return p->frame_len;
}

static J288_INLINE_HOT int scan(j288_parser_t *p, const uint8_t *data, size_t len,
                                size_t *consumed, const uint8_t **frame)
{
    const uint8_t *f = NULL;
    bool good;
    size_t from = take_first(p, data, len, &good);
    if (good) {
        *consumed = from;
        *frame = data;
        return J288_PARSE_FRAME;
    }
    /* A frame in progress takes the bytes that follow one by one, here (the common case when a
     * port hands over a byte at a time); the hunt for heads goes on in scan_bytes(). */
    while ((p->len != 0u) && (from < len)) {
        from++;
        if (take_byte(p, data[from - 1u])) {
            *consumed = from;
            *frame = buf(p);
            return J288_PARSE_FRAME;
        }
    }
    if (from == len) {
        *consumed = len;
        return J288_PARSE_NONE;
    }
    *consumed = from + scan_bytes(p, &data[from], len - from, &f);
    *frame = f;
    return (f != NULL) ? J288_PARSE_FRAME : J288_PARSE_NONE;
}

int j288_parser_scan(j288_parser_t *p, const uint8_t *data, size_t len, size_t *consumed,
                     const uint8_t **frame)
{
    return scan(p, data, len, consumed, frame);
}

/* A reply parser hunting, and data starting with a reply's head and as many bytes: the case of
 * take_first() that a host sees for nearly every reply, handled in j288_parser_feed() with
 * the CRC inline. */
static bool reply_at_start(const j288_parser_t *p, const uint8_t *data, size_t len)
{
    return (p->len == 0u) && (p->kind == J288_PARSE_REPLY) && (len >= J288_REPLY_LEN) &&
           (j288_get_u16le(data) == J288_REPLY_HEAD16);
}

/* A whole reply at the start of data (reply_at_start()), into buf, and its CRC checked
 * against its field there. Returns whether it is good; buf holds the reply either way (a bad
 * one is dropped from there). Each word of the reply is read from data once: where the core
 * loads unaligned words, as a word that is folded into the CRC and stored in buf (aligned);
 * elsewhere (Cortex-M0, RV32) the bytes are moved into buf, where the words are then loaded
 * aligned (fewer values live at once than assembling each word from four bytes). */
static J288_INLINE_HOT bool take_reply_words(j288_parser_t *p, const uint8_t *data)
{
#if J288_STORE32_AS_WORD
    uint32_t w[5];
    uint32_t field = j288_load_le32(&data[22]);
    w[0] = j288_load_le32(&data[2]);
    w[1] = j288_load_le32(&data[6]);
    w[2] = j288_load_le32(&data[10]);
    w[3] = j288_load_le32(&data[14]);
    w[4] = j288_load_le32(&data[18]);
    p->held.bytes[2] = J288_REPLY_HEAD0;
    p->held.bytes[3] = J288_REPLY_HEAD1;
    hold_word(p, 1u, w[0]);
    hold_word(p, 2u, w[1]);
    hold_word(p, 3u, w[2]);
    hold_word(p, 4u, w[3]);
    hold_word(p, 5u, w[4]);
    hold_word(p, 6u, field);
    return j288_crc_frame_words(p->crc, &buf(p)[2], w, 5u) == field;
#elif J288_LITTLE_ENDIAN
    /* The words are read where the CRC needs them (read before the test for a run-time
     * engine, they would stay live across its call). */
    j288_copy_frame(buf(p), data, J288_REPLY_LEN);
    return j288_crc_frame_words(p->crc, &buf(p)[2], &p->held.words[1], 5u) == p->held.words[6];
#else
    uint32_t w[5];
    j288_copy_frame(buf(p), data, J288_REPLY_LEN);
    w[0] = j288_get_u32le(&buf(p)[2]);
    w[1] = j288_get_u32le(&buf(p)[6]);
    w[2] = j288_get_u32le(&buf(p)[10]);
    w[3] = j288_get_u32le(&buf(p)[14]);
    w[4] = j288_get_u32le(&buf(p)[18]);
    return j288_crc_frame_words(p->crc, &buf(p)[2], w, 5u) == j288_get_u32le(&buf(p)[22]);
#endif
}

/* j288_parser_feed() when a reply at the start of data failed its CRC: what scan() does
 * there, with one CRC per frame as there: the frame is dropped as take_whole() drops it, and
 * the scan goes on behind it. (The good case is checked inline in j288_parser_feed(); this
 * rare one stays out of line.) */
J288_NOINLINE static int feed_after_bad_reply(j288_parser_t *p, const uint8_t *data, size_t len,
                                              size_t *consumed)
{
    const uint8_t *f = NULL;
    int rc;

    drop_whole(p, data);
    rc = scan(p, &data[J288_REPLY_LEN], len - J288_REPLY_LEN, consumed, &f);
    *consumed += J288_REPLY_LEN;
    if ((rc == J288_PARSE_FRAME) && (f != buf(p))) {
        j288_copy_frame(buf(p), f, J288_REPLY_LEN); /* a reply parser: checked where it lies */
    }
    return rc;
}

/* j288_parser_feed() for everything but a whole reply at the start of data, out of line so
 * that that common case saves and restores only the registers it needs. */
J288_NOINLINE static int feed_scan(j288_parser_t *p, const uint8_t *data, size_t len,
                                   size_t *consumed)
{
    const uint8_t *f = NULL;
    int rc = scan(p, data, len, consumed, &f);
    if ((rc == J288_PARSE_FRAME) && (f != buf(p))) {
        /* Checked in the caller's data: the parser keeps its own copy (constant lengths). */
        if (p->kind == J288_PARSE_REPLY) {
            j288_copy_frame(buf(p), f, J288_REPLY_LEN);
        } else {
            j288_copy_frame(buf(p), f, J288_CMD_LEN);
        }
    }
    return rc;
}

int j288_parser_feed(j288_parser_t *p, const uint8_t *data, size_t len, size_t *consumed)
{
    if (consumed != NULL) {
        *consumed = 0u;
    }
    if ((p == NULL) || (consumed == NULL) || ((data == NULL) && (len != 0u))) {
        return J288_ERR_NULL;
    }
    if (reply_at_start(p, data, len)) {
        if (take_reply_words(p, data)) {
            p->stats.frames++;
            *consumed = J288_REPLY_LEN;
            return J288_PARSE_FRAME;
        }
        return feed_after_bad_reply(p, data, len, consumed);
    }
    return feed_scan(p, data, len, consumed);
}

const uint8_t *j288_parser_frame(const j288_parser_t *p)
{
    /* A completed frame stays in buf: len went back to 0 but the bytes are untouched until
     * the next byte arrives. */
    return &p->held.bytes[2];
}

void j288_parser_reply(const j288_parser_t *p, j288_reply_raw_t *reply)
{
#if J288_LITTLE_ENDIAN
    j288_reply_unpack_words(&p->held.words[1], reply);
#else
    uint32_t w[5];
    w[0] = j288_get_u32le(&p->held.bytes[4]);
    w[1] = j288_get_u32le(&p->held.bytes[8]);
    w[2] = j288_get_u32le(&p->held.bytes[12]);
    w[3] = j288_get_u32le(&p->held.bytes[16]);
    w[4] = j288_get_u32le(&p->held.bytes[20]);
    j288_reply_unpack_words(w, reply);
#endif
}

int j288_parser_flush(j288_parser_t *p)
{
    if (p == NULL) {
        return J288_ERR_NULL;
    }
    if (p->len == 0u) {
        return J288_OK;
    }
    p->stats.truncated++;
    p->stats.dropped_bytes += p->len;
    p->len = 0u;
    return J288_ERR_TRUNCATED;
}

void j288_parser_reset(j288_parser_t *p)
{
    if (p != NULL) {
        j288_parser_drop(p);
    }
}
