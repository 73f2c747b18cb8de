/*
 * tplot.h - a live plot in a text terminal, for `j288 jog` and `j288 top --plot`: series of
 * samples drawn with Unicode braille characters (U+2800-U+28FF, 2 x 4 dots a character cell),
 * so that it shows in any UTF-8 terminal, over SSH too, with no graphics. Portable C99: no
 * allocation, no I/O, no OS (the caller prints the lines), so it is tested by its output.
 *
 * Feeding: cli_tplot_add() takes one sample of every series at once (NaN: no value for that
 * series). Every per_column samples close a column, which keeps each series' lowest and
 * highest value over them: a motion faster than a column shows as a filled band, never
 * aliased away. The latest CLI_TPLOT_MAX_COLS columns are kept.
 *
 * Drawing (cli_tplot_render()): the latest 2 * width columns, the newest at the right edge, in
 * rows character rows (4 * rows dot rows). The y range is the lowest and highest value of the
 * drawn series over those columns, widened about its middle to at least min_span. A value y
 * is dot row round((top - y) / (top - bottom) * (4 * rows - 1)) counted from the top. Each
 * column of a series lights the dots from its highest value's row to its lowest's, extended
 * to touch the previous column's dots, so that a trace is one connected line. Each cell
 * remembers which series lit it, for colours (cli_tplot_line()).
 */
#ifndef J288_CLI_TPLOT_H
#define J288_CLI_TPLOT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define CLI_TPLOT_MAX_SERIES 12u
#define CLI_TPLOT_MAX_COLS 512u /* dot columns kept: 256 character cells */
#define CLI_TPLOT_MAX_ROWS 48u  /* character rows drawn */
#define CLI_TPLOT_MAX_WIDTH (CLI_TPLOT_MAX_COLS / 2u)

typedef struct {
    double lo, hi; /* over the column's samples */
    bool have;    /* any sample had a value */
} cli_tplot_span_t;

typedef struct {
    unsigned nseries;
    unsigned per_column;
    unsigned in_column;  /* samples in the open column */
    unsigned ncols;      /* closed columns kept */
    unsigned next;       /* ring slot the next closed column goes to */
    uint32_t samples;    /* samples added in all */
    cli_tplot_span_t open[CLI_TPLOT_MAX_SERIES];
    cli_tplot_span_t col[CLI_TPLOT_MAX_COLS][CLI_TPLOT_MAX_SERIES];
} cli_tplot_t;

/* A drawn plot: per cell its braille dots (bit per dot, Unicode's order) and the series that
 * lit it (bit per series). */
typedef struct {
    unsigned width, rows;
    double bottom, top; /* the y range drawn */
    bool empty;         /* no value to draw: every cell blank, bottom = top = 0 */
    uint8_t dots[CLI_TPLOT_MAX_ROWS][CLI_TPLOT_MAX_WIDTH];
    uint16_t who[CLI_TPLOT_MAX_ROWS][CLI_TPLOT_MAX_WIDTH];
} cli_tplot_canvas_t;

/* nseries (1..CLI_TPLOT_MAX_SERIES) series, per_column (>= 1) samples a column: clamped into
 * those ranges. Forgets everything before. */
void cli_tplot_init(cli_tplot_t *p, unsigned nseries, unsigned per_column);

/* One sample of every series: values[0 .. nseries-1]; a NaN or infinite value is no value. */
void cli_tplot_add(cli_tplot_t *p, const double *values);

/* Draw the series whose bits are set in mask into c, width (1..CLI_TPLOT_MAX_WIDTH) cells by
 * rows (1..CLI_TPLOT_MAX_ROWS), both clamped into those ranges; min_span >= 0. */
void cli_tplot_render(const cli_tplot_t *p, uint32_t mask, unsigned width, unsigned rows,
                      double min_span, cli_tplot_canvas_t *c);

/* Row row of c as UTF-8 text into out (cap bytes, always NUL-terminated; a cell takes 3 bytes,
 * or 1 for a blank, plus colour codes): a blank cell is a space. With colors (an array of
 * CLI_TPLOT_MAX_SERIES ANSI SGR parameters such as "32", or NULL), a cell lit by one series
 * only takes its colour ("\033[32m" ... "\033[0m"). Returns the length written. */
size_t cli_tplot_line(const cli_tplot_canvas_t *c, unsigned row, const char *const *colors,
                      char *out, size_t cap);

#endif /* J288_CLI_TPLOT_H */
