/*
 * Helpers shared by the codec unit tests (CRC, frames, parser, units). Linked into every host
 * unit test; no main, no setUp/tearDown, names prefixed codec_.
 */
#ifndef J288_TEST_CODEC_SUPPORT_H
#define J288_TEST_CODEC_SUPPORT_H

#include <stddef.h>
#include <stdint.h>

/* Deterministic PRNG (xorshift32): the same sequence on every host and target. */
typedef struct {
    uint32_t s;
} codec_rng_t;

void codec_rng_seed(codec_rng_t *r, uint32_t seed);
uint32_t codec_rng_u32(codec_rng_t *r);
uint32_t codec_rng_below(codec_rng_t *r, uint32_t n); /* 0 .. n-1, n > 0 */
void codec_rng_fill(codec_rng_t *r, uint8_t *buf, size_t len);

/* The test's own CRC reference, written independently of lib/: bitwise CRC-32/MPEG-2 over
 * the byte stream with every 4-byte group reversed (== the manual's word-wise crc32_core).
 * Starts from crc (0xFFFFFFFF for a fresh CRC); len must be a multiple of 4. */
uint32_t codec_ref_crc(uint32_t crc, const uint8_t *data, size_t len);

/* Plain CRC-32/MPEG-2 over bytes, bitwise (for the check value). */
uint32_t codec_ref_mpeg2(const uint8_t *data, size_t len);

/* Rewrite the CRC field of a command (20 bytes) or reply (26 bytes) after editing it. */
void codec_fix_cmd_crc(uint8_t frame[20]);
void codec_fix_reply_crc(uint8_t frame[26]);

/* Hex text (spaces allowed) to bytes. Returns the byte count, or -1 on a bad digit, an odd
 * count or more than cap bytes. */
int codec_hex_decode(const char *hex, uint8_t *out, size_t cap);

/* A stand-in for a hardware CRC unit with the signature J288_CONFIG_CRC_HW_FUNCTION needs,
 * computed by codec_ref_crc(); it counts its calls in *codec_hw_crc_calls_ptr() so a test can
 * tell it was used. Builds with -DJ288_CONFIG_CRC_BACKEND=J288_CRC_BACKEND_HW
 * -DJ288_CONFIG_CRC_HW_FUNCTION=codec_hw_crc_stub use it (make test: crc-hw variant). */
uint32_t codec_hw_crc_stub(const uint8_t *data, size_t nwords);
unsigned long *codec_hw_crc_calls_ptr(void);

/* Fill with a canary pattern / check it is still there (1) or not (0). */
void codec_canary_fill(void *buf, size_t len);
int codec_canary_intact(const void *buf, size_t len);

#endif /* J288_TEST_CODEC_SUPPORT_H */
