/* Incremental frame parser; see j288/parser.h for the contract. */
#include "j288/parser.h"

#include <string.h>

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
    p->head0 = (kind == J288_PARSE_REPLY) ? J288_REPLY_HEAD0 : J288_CMD_HEAD0;
    p->frame_len = (uint8_t)((kind == J288_PARSE_REPLY) ? J288_REPLY_LEN : J288_CMD_LEN);
    return J288_OK;
}

static bool frame_crc_ok(const j288_parser_t *p)
{
    uint32_t want = (p->kind == J288_PARSE_REPLY) ? j288_reply_crc_expected(p->buf, p->crc)
                                                  : j288_cmd_crc_expected(p->buf, p->crc);
    return want == j288_frame_crc_field(p->buf, p->frame_len);
}

/* After a bad frame: keep from the next position that could still start a frame. A head
 * byte at the very end counts, since its second byte is not known yet. */
static void resync(j288_parser_t *p)
{
    uint8_t i;
    for (i = 1u; i < p->len; i++) {
        if ((p->buf[i] == p->head0) &&
            (((i + 1u) == p->len) || (p->buf[i + 1u] == J288_REPLY_HEAD1))) {
            break;
        }
    }
    p->stats.dropped_bytes += i;
    p->len = (uint8_t)(p->len - i);
    (void)memmove(p->buf, &p->buf[i], p->len);
}

/* One byte in; true when a good frame completes. Both heads end in 0xEE. */
static bool take_byte(j288_parser_t *p, uint8_t b)
{
    if (p->len == 0u) {
        if (b == p->head0) {
            p->buf[0] = b;
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
    p->buf[p->len] = b;
    p->len++;
    if (p->len < p->frame_len) {
        return false;
    }
    if (frame_crc_ok(p)) {
        p->stats.frames++;
        p->len = 0u;
        return true;
    }
    p->stats.crc_errors++;
    resync(p);
    return false;
}

int j288_parser_feed(j288_parser_t *p, const uint8_t *data, size_t len, size_t *consumed)
{
    size_t i;
    if (consumed != NULL) {
        *consumed = 0u;
    }
    if ((p == NULL) || (consumed == NULL) || ((data == NULL) && (len != 0u))) {
        return J288_ERR_NULL;
    }
    for (i = 0u; i < len; i++) {
        if (take_byte(p, data[i])) {
            *consumed = i + 1u;
            return J288_PARSE_FRAME;
        }
    }
    *consumed = len;
    return J288_PARSE_NONE;
}

const uint8_t *j288_parser_frame(const j288_parser_t *p)
{
    /* A completed frame stays in buf: len went back to 0 but the bytes are untouched until
     * the next byte arrives. */
    return p->buf;
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
        p->len = 0u;
    }
}
