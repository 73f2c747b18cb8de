/*
 * internal.h - what the library's modules share and a user never sees: the default CRC
 * backend as a direct call, the command checks and the lock command (one copy for the
 * encoder, the bus and the scheduler), the bus's thread-side lock, and the parser's scan that
 * leaves a frame where it lies. Not installed; nothing here is API.
 */
#ifndef J288_INTERNAL_H
#define J288_INTERNAL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "j288/bus.h"
#include "j288/config.h"
#include "j288/crc32.h"
#include "j288/frame.h"
#include "j288/parser.h"

/* Keeps a rarely taken path out of its caller, so that the common path stays short (no
 * register spills for the slow path's state). Only a hint. */
#if defined(__GNUC__)
#define J288_NOINLINE __attribute__((noinline))
#else
#define J288_NOINLINE
#endif

/* A small function on a hot path that has more than one caller: inlined in each (the
 * compiler would otherwise keep one out-of-line copy and a call). Only a hint, and only when
 * optimising: at -O0 (make coverage, debugging) forced inlining speeds nothing and would
 * multiply the branches that coverage counts, each inlined copy of a test on a constant
 * argument counting as a branch taken one way. */
#if defined(__GNUC__) && defined(__OPTIMIZE__)
#define J288_INLINE_HOT inline __attribute__((always_inline))
#else
#define J288_INLINE_HOT inline
#endif

/* ---- bytes */

/* Store v little-endian at p, any alignment. Where the core stores unaligned words and is
 * little-endian, this is a 4-byte memcpy, which the compiler turns into one store; elsewhere
 * byte by byte (the compiler's store merging does not see through the frame's words). */
#if defined(__BYTE_ORDER__) && defined(__ORDER_LITTLE_ENDIAN__) &&                            \
    (__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__) &&                                             \
    (defined(__ARM_FEATURE_UNALIGNED) || defined(__x86_64__) || defined(__i386__) ||           \
     defined(__aarch64__))
#define J288_STORE32_AS_WORD 1
#else
#define J288_STORE32_AS_WORD 0
#endif

static inline void j288_store_le32(uint8_t *p, uint32_t v)
{
#if J288_STORE32_AS_WORD
    /* cppcheck-suppress misra-c2012-21.15 ; the bytes of a word into a byte buffer, see above */
    (void)memcpy(p, &v, sizeof v);
#else
    j288_put_u32le(p, v);
#endif
}

/* The same for a load: one word load there, inlined even at -Os (where gcc calls the
 * header's j288_get_u32le() out of line once it has several callers). */
static J288_INLINE_HOT uint32_t j288_load_le32(const uint8_t *p)
{
#if J288_STORE32_AS_WORD
    uint32_t v;
    /* cppcheck-suppress misra-c2012-21.15 ; the bytes of a word from a byte buffer, see above */
    (void)memcpy(&v, p, sizeof v);
    return v;
#else
    return j288_get_u32le(p);
#endif
}

#if defined(__BYTE_ORDER__) && defined(__ORDER_LITTLE_ENDIAN__) &&                            \
    (__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__)
#define J288_LITTLE_ENDIAN 1
#else
#define J288_LITTLE_ENDIAN 0
#endif

/* Copy a whole frame (J288_CMD_LEN or J288_REPLY_LEN bytes, n a constant at every call).
 * Where the core loads unaligned words, memcpy, which the compiler turns into a few word
 * moves; elsewhere (Cortex-M0, RV32) memcpy is a library call that copies a byte at a time in
 * a loop (about 6 instructions a byte), so the bytes are moved in straight-line code here, two
 * instructions a byte, and no word is read from a pointer of unknown alignment. */
static inline void j288_copy4(uint8_t *dst, const uint8_t *src)
{
    dst[0] = src[0];
    dst[1] = src[1];
    dst[2] = src[2];
    dst[3] = src[3];
}

static J288_INLINE_HOT void j288_copy_frame(uint8_t *dst, const uint8_t *src, size_t n)
{
#if J288_STORE32_AS_WORD
    (void)memcpy(dst, src, n);
#else
    /* 20 = 5 * 4 and 26 = 6 * 4 + 2 */
    j288_copy4(&dst[0], &src[0]);
    j288_copy4(&dst[4], &src[4]);
    j288_copy4(&dst[8], &src[8]);
    j288_copy4(&dst[12], &src[12]);
    j288_copy4(&dst[16], &src[16]);
    if (n == J288_REPLY_LEN) {
        j288_copy4(&dst[20], &src[20]);
        dst[24] = src[24];
        dst[25] = src[25];
    }
#endif
}

/* ---- CRC */

#if J288_CONFIG_CRC_BACKEND == J288_CRC_BACKEND_HW
extern uint32_t J288_CONFIG_CRC_HW_FUNCTION(const uint8_t *data, size_t nwords);
#endif

/* The compile-time default backend over nwords words, from J288_CRC32_INIT. */
static inline uint32_t j288_crc_default(const uint8_t *data, size_t nwords)
{
#if J288_CONFIG_CRC_BACKEND == J288_CRC_BACKEND_TABLE
    return j288_crc32_update_table(J288_CRC32_INIT, data, nwords);
#elif J288_CONFIG_CRC_BACKEND == J288_CRC_BACKEND_SLICE4
    return j288_crc32_update_slice4(J288_CRC32_INIT, data, nwords);
#elif J288_CONFIG_CRC_BACKEND == J288_CRC_BACKEND_NIBBLE
    return j288_crc32_update_nibble(J288_CRC32_INIT, data, nwords);
#elif J288_CONFIG_CRC_BACKEND == J288_CRC_BACKEND_BITWISE
    return j288_crc32_update_bitwise(J288_CRC32_INIT, data, nwords);
#else
    return J288_CONFIG_CRC_HW_FUNCTION(data, nwords);
#endif
}

/* The tables (crc32.c): T0[i] = i * x^32 mod P, Tk[i] = i * x^(32 + 8k) mod P. */
extern const uint32_t j288_crc_table256[256];
extern const uint32_t j288_crc_slice1[256];
extern const uint32_t j288_crc_slice2[256];
extern const uint32_t j288_crc_slice3[256];

/* One little-endian word into the register, MSB first: XOR it in, then shift the 32 bits out,
 * a byte at a time through T0, or all four bytes at once through T3..T0 (slicing by 4). */
static inline uint32_t j288_crc_table_w(uint32_t crc, uint32_t word)
{
    uint32_t c = crc ^ word;
    c = (c << 8) ^ j288_crc_table256[c >> 24];
    c = (c << 8) ^ j288_crc_table256[c >> 24];
    c = (c << 8) ^ j288_crc_table256[c >> 24];
    return (c << 8) ^ j288_crc_table256[c >> 24];
}

static inline uint32_t j288_crc_slice4_w(uint32_t crc, uint32_t word)
{
    uint32_t c = crc ^ word;
    return j288_crc_slice3[c >> 24] ^ j288_crc_slice2[(c >> 16) & 0xFFu] ^
           j288_crc_slice1[(c >> 8) & 0xFFu] ^ j288_crc_table256[c & 0xFFu];
}

/* The same, the word read from bytes (p: any alignment). */
static inline uint32_t j288_crc_table_word(uint32_t crc, const uint8_t *p)
{
    return j288_crc_table_w(crc, j288_get_u32le(p));
}

static inline uint32_t j288_crc_slice4_word(uint32_t crc, const uint8_t *p)
{
    return j288_crc_slice4_w(crc, j288_get_u32le(p));
}

/* One word of the default table backend. */
#if J288_CONFIG_CRC_BACKEND == J288_CRC_BACKEND_TABLE
static inline uint32_t j288_crc_frame_word(uint32_t crc, const uint8_t *p)
{
    return j288_crc_table_word(crc, p);
}
#elif J288_CONFIG_CRC_BACKEND == J288_CRC_BACKEND_SLICE4
static inline uint32_t j288_crc_frame_word(uint32_t crc, const uint8_t *p)
{
    return j288_crc_slice4_word(crc, p);
}
#endif

/* One word as a value into the default table backend. */
#if J288_CONFIG_CRC_BACKEND == J288_CRC_BACKEND_TABLE
static inline uint32_t j288_crc_frame_w(uint32_t crc, uint32_t word)
{
    return j288_crc_table_w(crc, word);
}
#elif J288_CONFIG_CRC_BACKEND == J288_CRC_BACKEND_SLICE4
static inline uint32_t j288_crc_frame_w(uint32_t crc, uint32_t word)
{
    return j288_crc_slice4_w(crc, word);
}
#endif

/* The default backend over a frame's CRC'd words (nwords at least 4: a command's 4, a
 * reply's 5). Frames are checked at the wire's rate: the table backends are unrolled for
 * a frame's four or five words and inlined where a frame is built or checked in the hot path
 * (a loop and a call would cost a fifth of a word's work per word). */
static inline uint32_t j288_crc_frame_unrolled(const uint8_t *data, size_t nwords)
{
#if (J288_CONFIG_CRC_BACKEND == J288_CRC_BACKEND_TABLE) ||                                   \
    (J288_CONFIG_CRC_BACKEND == J288_CRC_BACKEND_SLICE4)
    uint32_t c = j288_crc_frame_word(J288_CRC32_INIT, data);
    size_t w;
    c = j288_crc_frame_word(c, &data[4]);
    c = j288_crc_frame_word(c, &data[8]);
    c = j288_crc_frame_word(c, &data[12]);
    for (w = 4u; w < nwords; w++) {
        c = j288_crc_frame_word(c, &data[4u * w]);
    }
    return c;
#else
    return j288_crc_default(data, nwords);
#endif
}

/* The same, called (for the paths that are not hot). */
uint32_t j288_crc_frame_default(const uint8_t *data, size_t nwords);

/* A frame's CRC in the hot path: the run-time engine crc if it has one, else the default
 * backend inlined. */
static inline uint32_t j288_crc_frame_hot(const j288_crc_t *crc, const uint8_t *data,
                                          size_t nwords)
{
    if ((crc != NULL) && (crc->fn != NULL)) {
        return crc->fn(crc->ctx, data, nwords);
    }
    return j288_crc_frame_unrolled(data, nwords);
}

/* Bytes the compiler knows to be word-aligned (the union's other member), filled a word at a
 * time with j288_le_word_set(): little-endian whatever the core. */
/* cppcheck-suppress misra-c2012-19.2 ; C99's only way to align a byte buffer (docs/misra.md) */
typedef union {
    uint32_t w[5];
    uint8_t b[20];
} j288_le_words_t; /* cppcheck-suppress misra-c2012-19.2 ; see above */

/* cppcheck-suppress misra-c2012-19.2 ; the union above */
static inline void j288_le_word_set(j288_le_words_t *u, size_t i, uint32_t v)
{
#if J288_LITTLE_ENDIAN
    u->w[i] = v;
#else
    j288_put_u32le(&u->b[4u * i], v);
#endif
}

/* A frame's CRC in the hot path from its CRC'd words (nwords 4 or 5, a constant at every
 * call) already read: w holds them as values (word i: bytes 4i..4i+3 little-endian), bytes
 * the same words as bytes (any alignment), for a run-time engine. The table backends fold
 * the values (no byte is read again). The CRC unit's function reads bytes: where the core
 * loads unaligned words, bytes as they are; elsewhere an aligned copy of the words, which an
 * inlined function loads as whole words (and where the compiler sees through the copy, it
 * writes the values as they are) instead of four byte loads a word. */
static J288_INLINE_HOT uint32_t j288_crc_frame_words(const j288_crc_t *crc, const uint8_t *bytes,
                                                     const uint32_t *w, size_t nwords)
{
    if ((crc != NULL) && (crc->fn != NULL)) {
        return crc->fn(crc->ctx, bytes, nwords);
    }
    {
        /* Straight-line code (gcc -O2 keeps a loop over w, and w on the stack). */
#if (J288_CONFIG_CRC_BACKEND == J288_CRC_BACKEND_TABLE) ||                                   \
    (J288_CONFIG_CRC_BACKEND == J288_CRC_BACKEND_SLICE4)
        uint32_t c = j288_crc_frame_w(J288_CRC32_INIT, w[0]);
        c = j288_crc_frame_w(c, w[1]);
        c = j288_crc_frame_w(c, w[2]);
        c = j288_crc_frame_w(c, w[3]);
        if (nwords > 4u) {
            c = j288_crc_frame_w(c, w[4]);
        }
        return c;
#elif (J288_CONFIG_CRC_BACKEND == J288_CRC_BACKEND_HW) && J288_STORE32_AS_WORD
        /* The core loads unaligned words: the bytes as they are (a copy would cost a function
         * that is called, not inlined, five stores). */
        (void)w;
        return J288_CONFIG_CRC_HW_FUNCTION(bytes, nwords);
#elif J288_CONFIG_CRC_BACKEND == J288_CRC_BACKEND_HW
        j288_le_words_t le;
        j288_le_word_set(&le, 0u, w[0]);
        j288_le_word_set(&le, 1u, w[1]);
        j288_le_word_set(&le, 2u, w[2]);
        j288_le_word_set(&le, 3u, w[3]);
        if (nwords > 4u) {
            j288_le_word_set(&le, 4u, w[4]);
        }
        return J288_CONFIG_CRC_HW_FUNCTION(le.b, nwords);
#else
        (void)w;
        return j288_crc_default(bytes, nwords);
#endif
    }
}

/* A frame's CRC (nwords at least 4): the run-time engine crc if it has one, else the default
 * backend. j288_crc32_run() for the frame paths. */
static inline uint32_t j288_crc_frame(const j288_crc_t *crc, const uint8_t *data, size_t nwords)
{
    if ((crc != NULL) && (crc->fn != NULL)) {
        return crc->fn(crc->ctx, data, nwords);
    }
    return j288_crc_frame_default(data, nwords);
}

/* ---- frames */

/* The head's two bytes as one little-endian halfword, for a single compare. */
#define J288_CMD_HEAD16 (J288_CMD_HEAD0 | ((uint32_t)J288_CMD_HEAD1 << 8u))
#define J288_REPLY_HEAD16 (J288_REPLY_HEAD0 | ((uint32_t)J288_REPLY_HEAD1 << 8u))

/* A whole reply's CRC (bytes 2-21) against its field (bytes 22-25), with constant offsets so
 * that the default table backends unroll to straight-line code. The head is not checked. */
static J288_INLINE_HOT bool j288_reply_crc_ok(const j288_crc_t *crc, const uint8_t *f)
{
    return j288_crc_frame_hot(crc, &f[2], 5u) == j288_get_u32le(&f[22]);
}

/* The same for a whole command (bytes 0-15, field 16-19). */
static J288_INLINE_HOT bool j288_cmd_crc_ok(const j288_crc_t *crc, const uint8_t *f)
{
    return j288_crc_frame_hot(crc, f, 4u) == j288_get_u32le(&f[16]);
}

/* j288_reply_unpack() from the reply's words 1-5 as values (word i: bytes 4i+2 .. 4i+5,
 * little-endian), e.g. read aligned from the parser's buffer. */
void j288_reply_unpack_words(const uint32_t w[5], j288_reply_raw_t *reply);

/* ---- commands */

/* The encoder's checks, in its order: J288_ERR_BAD_ID (id > 15), J288_ERR_BAD_STATUS,
 * J288_ERR_NEG_GAIN, else J288_OK. */
static inline int j288_cmd_check(const j288_cmd_raw_t *cmd)
{
    if (cmd->id > J288_BROADCAST_ID) {
        return J288_ERR_BAD_ID;
    }
    if (cmd->status > J288_MODE_FOC) {
        return J288_ERR_BAD_STATUS;
    }
    if ((cmd->kp < 0) || (cmd->kd < 0)) {
        return J288_ERR_NEG_GAIN;
    }
    return J288_OK;
}

/* j288_cmd_encode() without its checks, for a command that passed them (the scheduler's
 * slots: j288_sched_set_cmd() checks, init and estop make lock commands). */
void j288_cmd_pack(const j288_cmd_raw_t *cmd, uint8_t out[J288_CMD_LEN], const j288_crc_t *crc);

/* Lock (no torque), every other field 0: the scheduler's initial and post-estop command, and
 * with id 15 and the watchdog on, the emergency stop frame. */
static inline void j288_cmd_lock(j288_cmd_raw_t *c, uint8_t id, bool watchdog)
{
    (void)memset(c, 0, sizeof *c);
    c->id = id;
    c->status = J288_MODE_LOCK;
    c->watchdog = watchdog;
}

/* ---- the bus's thread-side lock (bus.h: with advance_in_isr, thread calls are wrapped in
 * the port's lock/unlock; from inside an advance the lock is already held or not needed). */

static inline bool j288_bus_needs_lock(const j288_bus_t *bus)
{
    return bus->cfg.advance_in_isr && !bus->in_advance && (bus->port->lock != NULL);
}

static inline void j288_bus_lock(const j288_bus_t *bus)
{
    if (j288_bus_needs_lock(bus)) {
        bus->port->lock(bus->port_ctx);
    }
}

static inline void j288_bus_unlock(const j288_bus_t *bus)
{
    if (j288_bus_needs_lock(bus)) {
        bus->port->unlock(bus->port_ctx);
    }
}

/* j288_bus_t.flags: what waits for the machine, one bit each, written only by the context
 * that advances it (never by the event calls). */
#define J288_BUSF_QUEUED 0x01u        /* an accepted submit waits for the guard to end */
#define J288_BUSF_RETRY 0x02u         /* the failed attempt is re-sent when the guard ends */
#define J288_BUSF_ESTOP_PENDING 0x04u /* a stop was requested and is not on the wire yet */
#define J288_BUSF_ESTOP_ACTIVE 0x08u  /* the frame in flight (or to be re-sent) is the stop */
#define J288_BUSF_ESTOP_REARM 0x10u   /* an estop was requested while the stop was active */
/* Any of these refuses a submit. */
#define J288_BUSF_REFUSE                                                                       \
    (J288_BUSF_QUEUED | J288_BUSF_RETRY | J288_BUSF_ESTOP_PENDING | J288_BUSF_ESTOP_ACTIVE)

/* Whether the bus accepts a new transaction now (j288_bus_submit()'s J288_ERR_BUSY test:
 * idle or in the guard, nothing queued, no retry or estop pending). Call it, and
 * j288_bus_accept_frame() after it, under one j288_bus_lock(). */
static inline bool j288_bus_accepts(const j288_bus_t *bus)
{
    uint8_t st = bus->state;
    return ((bus->flags & J288_BUSF_REFUSE) == 0u) &&
           ((st == (uint8_t)J288_BUS_IDLE) || (st == (uint8_t)J288_BUS_GUARD));
}

/* A new transaction record, in the slot the previous callback is not looking at. Only what a
 * callback may read is set here (no clearing of the whole record), and only what the end of
 * the transaction does not set (result, start and latency: start_attempt() and finish()); the
 * reply is cleared by finish() when none is taken. */
static J288_INLINE_HOT void j288_bus_begin_txn(j288_bus_t *bus, uint8_t id,
                                               j288_bus_done_fn done, void *user)
{
    j288_txn_t *t;
    unsigned i;

    bus->cur ^= 1u;
    t = &bus->txn[bus->cur];
    t->id = id;
    t->attempts = 0u;
    /* Element by element: a few stores, where some targets' compilers (RV32) would call
     * memset for these 16 bytes. */
    for (i = 0u; i < (J288_CONFIG_MAX_RETRIES + 1u); i++) {
        t->attempt_result[i] = J288_OK;
    }
    bus->tx_id = id;
    bus->done = done;
    bus->done_user = user;
}

/* j288_bus_accept_frame() from inside an advance (a completion callback), where it only
 * queues: the guard's timer, or the next poll, starts the transmit. */
static J288_INLINE_HOT void j288_bus_queue_frame(j288_bus_t *bus, const uint8_t *frame,
                                                 uint8_t id, j288_bus_done_fn done, void *user)
{
    bus->tx_frame = frame;
    j288_bus_begin_txn(bus, id, done, user);
    bus->stats.transactions++;
    bus->flags = (uint8_t)(bus->flags | J288_BUSF_QUEUED);
}

/* The transaction of frame (J288_CMD_LEN bytes, addressed to id, CRC in place) begins, once
 * j288_bus_accepts() said yes under the same lock; the frame is sent from where it is, for
 * every attempt and the echo check, and must stay untouched until the completion call. */
void j288_bus_accept_frame(j288_bus_t *bus, const uint8_t *frame, uint8_t id, uint32_t now_us,
                           j288_bus_done_fn done, void *user);

/* ---- parser */

/* j288_parser_reset() for the bus, which owns its parser: drop a partial frame. */
static inline void j288_parser_drop(j288_parser_t *p)
{
    p->len = 0u;
}

/*
 * j288_parser_feed() without the copy: on J288_PARSE_FRAME, *frame points at the good frame,
 * which is inside data when it arrived whole while the parser was hunting (checked where it
 * lies), else p->buf. Valid as long as both data and the parser are untouched. Same
 * statistics, consumption and results as j288_parser_feed(), byte for byte; p, data (unless
 * len is 0), consumed and frame must not be NULL.
 */
int j288_parser_scan(j288_parser_t *p, const uint8_t *data, size_t len, size_t *consumed,
                     const uint8_t **frame);

#endif /* J288_INTERNAL_H */
