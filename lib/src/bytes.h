/*
 * bytes.h - words to and from byte buffers, for the modules that build and check frames
 * (lib/src only, not installed). Byte buffers are never cast to a wider type: a word is
 * stored or loaded through memcpy where the core takes unaligned words, byte by byte
 * elsewhere.
 */
#ifndef J288_BYTES_H
#define J288_BYTES_H

#include <stddef.h>
#include <stdint.h>
#include <string.h>

#include "hints.h"
#include "j288/frame.h"

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

#endif /* J288_BYTES_H */
