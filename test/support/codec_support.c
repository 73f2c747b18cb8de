/* Helpers for the codec unit tests; see codec_support.h. */
#include "codec_support.h"

void codec_rng_seed(codec_rng_t *r, uint32_t seed)
{
    r->s = (seed != 0u) ? seed : 1u;
}

uint32_t codec_rng_u32(codec_rng_t *r)
{
    uint32_t s = r->s;
    s ^= s << 13;
    s ^= s >> 17;
    s ^= s << 5;
    r->s = s;
    return s;
}

uint32_t codec_rng_below(codec_rng_t *r, uint32_t n)
{
    return codec_rng_u32(r) % n;
}

void codec_rng_fill(codec_rng_t *r, uint8_t *buf, size_t len)
{
    size_t i;
    for (i = 0; i < len; i++) {
        buf[i] = (uint8_t)(codec_rng_u32(r) >> 24);
    }
}

static uint32_t mpeg2_byte(uint32_t crc, uint8_t b)
{
    int bit;
    crc ^= (uint32_t)b << 24;
    for (bit = 0; bit < 8; bit++) {
        crc = (crc & 0x80000000u) ? (crc << 1) ^ 0x04C11DB7u : crc << 1;
    }
    return crc;
}

uint32_t codec_ref_crc(uint32_t crc, const uint8_t *data, size_t len)
{
    size_t i;
    for (i = 0; i + 4u <= len; i += 4u) {
        crc = mpeg2_byte(crc, data[i + 3u]);
        crc = mpeg2_byte(crc, data[i + 2u]);
        crc = mpeg2_byte(crc, data[i + 1u]);
        crc = mpeg2_byte(crc, data[i]);
    }
    return crc;
}

uint32_t codec_ref_mpeg2(const uint8_t *data, size_t len)
{
    uint32_t crc = 0xFFFFFFFFu;
    size_t i;
    for (i = 0; i < len; i++) {
        crc = mpeg2_byte(crc, data[i]);
    }
    return crc;
}

static void put_le32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    p[2] = (uint8_t)(v >> 16);
    p[3] = (uint8_t)(v >> 24);
}

void codec_fix_cmd_crc(uint8_t frame[20])
{
    put_le32(&frame[16], codec_ref_crc(0xFFFFFFFFu, frame, 16u));
}

void codec_fix_reply_crc(uint8_t frame[26])
{
    put_le32(&frame[22], codec_ref_crc(0xFFFFFFFFu, &frame[2], 20u));
}

/* Test-only state: a call counter for the hardware-CRC stand-in (tests are single-threaded). */
static unsigned long hw_crc_calls;

unsigned long *codec_hw_crc_calls_ptr(void)
{
    return &hw_crc_calls;
}

uint32_t codec_hw_crc_stub(const uint8_t *data, size_t nwords)
{
    hw_crc_calls++;
    return codec_ref_crc(0xFFFFFFFFu, data, 4u * nwords);
}

static int hex_digit(char c)
{
    if (c >= '0' && c <= '9') {
        return c - '0';
    }
    if (c >= 'a' && c <= 'f') {
        return c - 'a' + 10;
    }
    if (c >= 'A' && c <= 'F') {
        return c - 'A' + 10;
    }
    return -1;
}

int codec_hex_decode(const char *hex, uint8_t *out, size_t cap)
{
    size_t n = 0;
    int hi = -1;
    for (; *hex != '\0'; hex++) {
        int d;
        if (*hex == ' ') {
            continue;
        }
        d = hex_digit(*hex);
        if (d < 0) {
            return -1;
        }
        if (hi < 0) {
            hi = d;
            continue;
        }
        if (n >= cap) {
            return -1;
        }
        out[n++] = (uint8_t)((hi << 4) | d);
        hi = -1;
    }
    return (hi < 0) ? (int)n : -1;
}

#define CODEC_CANARY(i) ((uint8_t)(0xA5u ^ (uint8_t)((i)*7u)))

void codec_canary_fill(void *buf, size_t len)
{
    uint8_t *p = buf;
    size_t i;
    for (i = 0; i < len; i++) {
        p[i] = CODEC_CANARY(i);
    }
}

int codec_canary_intact(const void *buf, size_t len)
{
    const uint8_t *p = buf;
    size_t i;
    for (i = 0; i < len; i++) {
        if (p[i] != CODEC_CANARY(i)) {
            return 0;
        }
    }
    return 1;
}
