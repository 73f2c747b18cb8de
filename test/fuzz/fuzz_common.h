/*
 * Shared helpers for the fuzz targets in test/fuzz/.
 *
 * Every target is an LLVMFuzzerTestOneInput() that checks invariants with FUZZ_CHECK: a
 * broken invariant prints where and aborts, which libFuzzer records as a crash (and saves the
 * input), and which fails the corpus replay test (replay_main.c) that `make test` runs.
 *
 * The reference CRC and byte readers here are written from the protocol text, independently
 * of lib/, so that a target can tell a frame the library accepts is really valid.
 */
#ifndef J288_FUZZ_COMMON_H
#define J288_FUZZ_COMMON_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define FUZZ_CHECK(cond)                                                                       \
    do {                                                                                       \
        if (!(cond)) {                                                                         \
            fprintf(stderr, "%s:%d: invariant broken: %s\n", __FILE__, __LINE__, #cond);       \
            abort();                                                                           \
        }                                                                                      \
    } while (0)

/* The manual's crc32_core, bit by bit: poly 0x04C11DB7, init all ones, words taken
 * little-endian from the bytes and fed most significant bit first. */
static inline uint32_t fuzz_ref_crc(const uint8_t *d, size_t nwords)
{
    uint32_t c = 0xFFFFFFFFu;
    size_t w;
    for (w = 0; w < nwords; w++) {
        int k;
        for (k = 3; k >= 0; k--) {
            int bit;
            c ^= (uint32_t)d[4u * w + (size_t)k] << 24;
            for (bit = 0; bit < 8; bit++) {
                c = ((c & 0x80000000u) != 0u) ? ((c << 1) ^ 0x04C11DB7u) : (c << 1);
            }
        }
    }
    return c;
}

static inline uint32_t fuzz_le32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) |
           ((uint32_t)p[3] << 24);
}

static inline uint16_t fuzz_le16(const uint8_t *p)
{
    return (uint16_t)((unsigned)p[0] | ((unsigned)p[1] << 8));
}

static inline void fuzz_put_le32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)(v & 0xFFu);
    p[1] = (uint8_t)((v >> 8) & 0xFFu);
    p[2] = (uint8_t)((v >> 16) & 0xFFu);
    p[3] = (uint8_t)(v >> 24);
}

/* A 26-byte reply is valid: head FC EE, CRC over bytes 2-21 in bytes 22-25. */
static inline int fuzz_reply_valid(const uint8_t *f)
{
    return (f[0] == 0xFCu) && (f[1] == 0xEEu) && (fuzz_ref_crc(&f[2], 5u) == fuzz_le32(&f[22]));
}

/* A 20-byte command is valid: head FE EE, CRC over bytes 0-15 in bytes 16-19. */
static inline int fuzz_cmd_valid(const uint8_t *f)
{
    return (f[0] == 0xFEu) && (f[1] == 0xEEu) && (fuzz_ref_crc(f, 4u) == fuzz_le32(&f[16]));
}

/* Two's complement from a wire pattern, spelled out (no implementation-defined casts). */
static inline int32_t fuzz_s16(uint16_t u)
{
    return (u < 0x8000u) ? (int32_t)u : (int32_t)u - 65536;
}

static inline int64_t fuzz_s32(uint32_t u)
{
    return (u < 0x80000000u) ? (int64_t)u : (int64_t)u - 4294967296LL;
}

/* A little reader that hands out bytes from the fuzz input, zeros once it runs dry. */
typedef struct {
    const uint8_t *p;
    size_t n;
} fuzz_in_t;

static inline uint8_t fuzz_u8(fuzz_in_t *in)
{
    uint8_t b = 0u;
    if (in->n > 0u) {
        b = in->p[0];
        in->p++;
        in->n--;
    }
    return b;
}

static inline uint16_t fuzz_u16(fuzz_in_t *in)
{
    uint16_t lo = fuzz_u8(in);
    return (uint16_t)(lo | ((unsigned)fuzz_u8(in) << 8));
}

static inline uint32_t fuzz_u32(fuzz_in_t *in)
{
    uint32_t lo = fuzz_u16(in);
    return lo | ((uint32_t)fuzz_u16(in) << 16);
}

#endif /* J288_FUZZ_COMMON_H */
