/*
 * j288/parser.h - incremental frame parser for bytes from the wire.
 *
 * Feed it chunks of any size: a DMA idle-line event, a read() result, one byte from an ISR.
 * It hunts for the head (0xFC 0xEE for replies, 0xFE 0xEE for commands on the device side),
 * collects the fixed frame length, checks the CRC, and stops after each good frame so that
 * the caller can take it. A frame with a bad CRC is dropped and the hunt restarts at the
 * next candidate head inside it, so a false head in a payload never hides a real frame.
 * Work per byte is bounded (at most one CRC and one 26-byte move per dropped frame, and a
 * frame is only dropped after at least one new byte). It never reads beyond len and never
 * writes outside the parser object.
 *
 * Thread/ISR: a parser is owned by one context at a time; no function here blocks or uses
 * globals, so an ISR may own it. The parser object is caller-allocated; it keeps no pointer
 * to the data fed in.
 */
#ifndef J288_PARSER_H
#define J288_PARSER_H

#include <stddef.h>
#include <stdint.h>

#include "j288/crc32.h"
#include "j288/frame.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    J288_PARSE_REPLY = 0,   /* host side: 26-byte replies, head 0xFC 0xEE */
    J288_PARSE_COMMAND = 1  /* device side: 20-byte commands, head 0xFE 0xEE */
} j288_parse_kind_t;

/* Why bytes were dropped; counters only grow (they wrap at 2^32). */
typedef struct {
    uint32_t frames;          /* good frames handed out */
    uint32_t garbage_bytes;   /* bytes skipped while hunting for a head */
    uint32_t crc_errors;      /* complete frames dropped for a CRC mismatch */
    uint32_t truncated;       /* partial frames dropped by j288_parser_flush() */
    uint32_t dropped_bytes;   /* bytes of frames dropped for CRC or truncation */
} j288_parser_stats_t;

typedef struct {
    /* Private: read through the functions below. */
    uint8_t len;       /* bytes of the frame collected */
    uint8_t frame_len;
    uint8_t head0;
    /* The frame, from bytes[2]: a reply's CRC'd words and its CRC field are words[1..6], so
     * that the library reads and writes them as aligned words (the union is what makes the
     * bytes word-aligned; bytes[0..1] are unused). */
    /* cppcheck-suppress misra-c2012-19.2 ; C99's only way to align a byte buffer (docs/misra.md) */
    union {
        uint32_t words[7];
        uint8_t bytes[J288_REPLY_LEN + 2u];
    } held; /* cppcheck-suppress misra-c2012-19.2 ; see above */
    j288_parse_kind_t kind;
    const j288_crc_t *crc;
    j288_parser_stats_t stats;
} j288_parser_t;

#define J288_PARSE_NONE 0   /* all bytes consumed, no complete frame yet */
#define J288_PARSE_FRAME 1  /* a good frame is ready: j288_parser_frame() */

/* Set up an empty parser. crc may be NULL (default backend); a non-NULL crc must outlive the
 * parser. Errors: J288_ERR_NULL, J288_ERR_BAD_ARG (kind). */
int j288_parser_init(j288_parser_t *p, j288_parse_kind_t kind, const j288_crc_t *crc);

/*
 * Consume bytes from data[0..len). Returns J288_PARSE_FRAME as soon as a good frame completes
 * (with *consumed < len possibly: call again with the rest), J288_PARSE_NONE when every byte
 * was consumed without completing one, or J288_ERR_NULL. *consumed is set in every case.
 * data may be NULL when len is 0.
 */
int j288_parser_feed(j288_parser_t *p, const uint8_t *data, size_t len, size_t *consumed);

/* The last good frame (frame_len bytes). Valid after J288_PARSE_FRAME until the next feed,
 * flush or reset. */
const uint8_t *j288_parser_frame(const j288_parser_t *p);

/* A reply parser's last good reply, unpacked: the same as j288_reply_unpack(
 * j288_parser_frame(p), reply), read from the parser's own buffer a whole word at a time
 * (where j288_reply_unpack() reads bytes, not knowing its buffer's alignment: four loads a
 * word on Cortex-M0 and RV32). Same validity as j288_parser_frame(); a command parser's frame
 * gives meaningless fields. ISR-safe like the rest of the parser. */
void j288_parser_reply(const j288_parser_t *p, j288_reply_raw_t *reply);

/* The line went idle (or the caller gives up on this frame): drop a partial frame, counting
 * it as truncated. Returns J288_ERR_TRUNCATED when something was dropped, else J288_OK. */
int j288_parser_flush(j288_parser_t *p);

/* Drop any partial frame without counting it (e.g. before a new transaction). Stats stay. */
void j288_parser_reset(j288_parser_t *p);

/* The parser's statistics (frames, CRC errors, ... since init), valid as long as the parser.
 * ISR-safe like the rest of the parser; never NULL for a non-NULL p. */
static inline const j288_parser_stats_t *j288_parser_stats(const j288_parser_t *p)
{
    return &p->stats;
}

/* Bytes currently held (0 = hunting). */
static inline size_t j288_parser_pending(const j288_parser_t *p) { return p->len; }

#ifdef __cplusplus
}
#endif

#endif /* J288_PARSER_H */
