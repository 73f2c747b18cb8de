/*
 * parser_priv.h - what parser.c gives the bus (not installed, not API): a parser the bus owns,
 * scanned without a copy.
 */
#ifndef J288_PARSER_PRIV_H
#define J288_PARSER_PRIV_H

#include <stddef.h>
#include <stdint.h>

#include "j288/parser.h"

/* j288_parser_reset() for the bus, which owns its parser: drop a partial frame. */
static inline void j288_parser_drop(j288_parser_t *p)
{
    p->len = 0u;
}

/* The parser's statistics, writable: the bus counts a reply it takes whole, without the
 * parser, as the parser would have (a frame). */
static inline j288_parser_stats_t *j288_parser_counters(j288_parser_t *p)
{
    return &p->stats;
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

#endif /* J288_PARSER_PRIV_H */
