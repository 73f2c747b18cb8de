/*
 * j288/crc32.h - the frame CRC: the manual's crc32_core.
 *
 * Polynomial 0x04C11DB7, initial value 0xFFFFFFFF, no reflection, no final XOR, fed 32-bit
 * words most significant bit first: the STM32 CRC unit in its reset configuration. Each word
 * is assembled from four bytes little-endian (byte 0 is the least significant), so the same
 * bytes give the same CRC on any host; byte buffers need no alignment. The same CRC seen as a
 * byte-stream CRC is CRC-32/MPEG-2 over each 4-byte group reversed (check value for
 * "123456789": 0x0376E6E7, available here as j288_crc32_mpeg2_bytes()).
 *
 * Backends (bit-identical): 256-entry table, slicing by 4 (four 256-entry tables), 16-entry
 * nibble table, bitwise reference, and a hardware hook. Each software backend is a streaming update: start from J288_CRC32_INIT and
 * feed words in as many calls as you like. All functions are pure: ISR-safe and reentrant.
 */
#ifndef J288_CRC32_H
#define J288_CRC32_H

#include <stddef.h>
#include <stdint.h>

#include "j288/config.h"

#ifdef __cplusplus
extern "C" {
#endif

#define J288_CRC32_INIT 0xFFFFFFFFu
#define J288_CRC32_POLY 0x04C11DB7u

/* Streaming software backends: fold nwords words (4 * nwords bytes from data, little-endian
 * words) into crc and return the new value. data may be NULL only when nwords is 0. */
uint32_t j288_crc32_update_table(uint32_t crc, const uint8_t *data, size_t nwords);
uint32_t j288_crc32_update_slice4(uint32_t crc, const uint8_t *data, size_t nwords);
uint32_t j288_crc32_update_nibble(uint32_t crc, const uint8_t *data, size_t nwords);
uint32_t j288_crc32_update_bitwise(uint32_t crc, const uint8_t *data, size_t nwords);

/* The compile-time default backend (J288_CONFIG_CRC_BACKEND) over a whole buffer,
 * starting from J288_CRC32_INIT. */
uint32_t j288_crc32(const uint8_t *data, size_t nwords);

/* CRC-32/MPEG-2 over a plain byte stream (no word grouping), for the check value and for
 * tools; not used on the wire. */
uint32_t j288_crc32_mpeg2_bytes(const uint8_t *data, size_t len);

/*
 * A CRC engine chosen at run time, e.g. a hardware CRC unit. fn computes the complete CRC
 * (from J288_CRC32_INIT) over nwords little-endian words at data, which is NOT necessarily
 * 4-byte aligned: an implementation feeding a peripheral assembles words from bytes or copies
 * into an aligned scratch buffer. It is called from wherever the frame is checked (poll, or
 * the ISR when the bus advances there), so it must be safe in that context; a CRC unit shared
 * with other code needs the port's lock. Everything that takes a `const j288_crc_t *` accepts
 * NULL for the compile-time default backend.
 */
typedef struct {
    uint32_t (*fn)(void *ctx, const uint8_t *data, size_t nwords);
    void *ctx;
} j288_crc_t;

/* Run an engine (NULL, or an engine with a NULL fn: the default backend). */
uint32_t j288_crc32_run(const j288_crc_t *crc, const uint8_t *data, size_t nwords);

#ifdef __cplusplus
}
#endif

#endif /* J288_CRC32_H */
