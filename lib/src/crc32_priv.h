/*
 * crc32_priv.h - what crc32.c gives the other modules of lib/ (not installed, not API): the
 * compile-time default backend as a direct call, its tables, and a frame's CRC inlined where
 * frames are built or checked at the wire's rate.
 */
#ifndef J288_CRC32_PRIV_H
#define J288_CRC32_PRIV_H

#include <stddef.h>
#include <stdint.h>

#include "bytes.h"
#include "j288/config.h"
#include "j288/crc32.h"

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

#endif /* J288_CRC32_PRIV_H */
