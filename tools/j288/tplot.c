/* A live plot in braille characters; see tplot.h. */
#include "tplot.h"

#include <math.h>
#include <string.h>

void cli_tplot_init(cli_tplot_t *p, unsigned nseries, unsigned per_column)
{
    memset(p, 0, sizeof *p);
    p->nseries = nseries < 1u ? 1u : (nseries > CLI_TPLOT_MAX_SERIES ? CLI_TPLOT_MAX_SERIES : nseries);
    p->per_column = per_column < 1u ? 1u : per_column;
}

static void widen(cli_tplot_span_t *s, double v)
{
    if (!s->have) {
        s->lo = v;
        s->hi = v;
        s->have = true;
        return;
    }
    if (v < s->lo)
        s->lo = v;
    if (v > s->hi)
        s->hi = v;
}

void cli_tplot_add(cli_tplot_t *p, const double *values)
{
    unsigned s;
    for (s = 0; s < p->nseries; s++)
        if (isfinite(values[s]))
            widen(&p->open[s], values[s]);
    p->samples++;
    if (++p->in_column < p->per_column)
        return;
    memcpy(p->col[p->next], p->open, sizeof p->open);
    memset(p->open, 0, sizeof p->open);
    p->in_column = 0;
    p->next = (p->next + 1u) % CLI_TPLOT_MAX_COLS;
    if (p->ncols < CLI_TPLOT_MAX_COLS)
        p->ncols++;
}

/* The k-th newest closed column (k = 0: the newest). */
static const cli_tplot_span_t *column(const cli_tplot_t *p, unsigned k)
{
    return p->col[(p->next + CLI_TPLOT_MAX_COLS - 1u - k) % CLI_TPLOT_MAX_COLS];
}

/* The dot row of y, 0 at the top, clamped to the canvas. */
static int dot_row(const cli_tplot_canvas_t *c, double y)
{
    int last = (int)(c->rows * 4u) - 1;
    double r = floor((c->top - y) / (c->top - c->bottom) * (double)last + 0.5);
    if (r < 0.0)
        return 0;
    return r > (double)last ? last : (int)r;
}

/* Braille dot bits, Unicode's order: column 0 rows 0-2 are bits 0-2, column 1 rows 0-2 bits
 * 3-5, row 3 is bit 6 (column 0) and bit 7 (column 1). */
static uint8_t dot_bit(unsigned x, unsigned y)
{
    static const uint8_t bits[4][2] = {{0x01, 0x08}, {0x02, 0x10}, {0x04, 0x20}, {0x40, 0x80}};
    return bits[y][x];
}

static void light(cli_tplot_canvas_t *c, unsigned x, int from, int to, unsigned series)
{
    int y;
    for (y = from; y <= to; y++) {
        unsigned row = (unsigned)y / 4u, cell = x / 2u;
        c->dots[row][cell] = (uint8_t)(c->dots[row][cell] | dot_bit(x % 2u, (unsigned)y % 4u));
        c->who[row][cell] = (uint16_t)(c->who[row][cell] | (1u << series));
    }
}

/* The y range of the drawn series over the shown columns; false when there is no value. */
static bool y_range(const cli_tplot_t *p, uint32_t mask, unsigned shown, double *lo, double *hi)
{
    bool any = false;
    unsigned k, s;
    for (k = 0; k < shown; k++) {
        const cli_tplot_span_t *col = column(p, k);
        for (s = 0; s < p->nseries; s++) {
            if ((mask & (1ul << s)) == 0u || !col[s].have)
                continue;
            if (!any || col[s].lo < *lo)
                *lo = col[s].lo;
            if (!any || col[s].hi > *hi)
                *hi = col[s].hi;
            any = true;
        }
    }
    return any;
}

void cli_tplot_render(const cli_tplot_t *p, uint32_t mask, unsigned width, unsigned rows,
                      double min_span, cli_tplot_canvas_t *c)
{
    unsigned shown, k, s;
    double lo = 0.0, hi = 0.0;
    memset(c, 0, sizeof *c);
    c->width = width < 1u ? 1u : (width > CLI_TPLOT_MAX_WIDTH ? CLI_TPLOT_MAX_WIDTH : width);
    c->rows = rows < 1u ? 1u : (rows > CLI_TPLOT_MAX_ROWS ? CLI_TPLOT_MAX_ROWS : rows);
    shown = p->ncols < 2u * c->width ? p->ncols : 2u * c->width;
    c->empty = !y_range(p, mask, shown, &lo, &hi);
    if (c->empty)
        return;
    if (!(min_span >= 0.0))
        min_span = 0.0;
    if (hi - lo < min_span) {
        double mid = lo + (hi - lo) / 2.0;
        lo = mid - min_span / 2.0;
        hi = mid + min_span / 2.0;
    }
    if (!(hi > lo)) { /* one flat value and no span asked: a line through the middle */
        lo -= 0.5;
        hi += 0.5;
    }
    c->bottom = lo;
    c->top = hi;
    for (s = 0; s < p->nseries; s++) {
        int prev_top = -1, prev_bot = -1;
        if ((mask & (1ul << s)) == 0u)
            continue;
        /* oldest shown column first, at dot column 2 * width - shown */
        for (k = shown; k-- > 0u;) {
            const cli_tplot_span_t *v = &column(p, k)[s];
            unsigned x = 2u * c->width - 1u - k;
            int top, bot;
            if (!v->have) {
                prev_top = -1;
                continue;
            }
            top = dot_row(c, v->hi);
            bot = dot_row(c, v->lo);
            if (prev_top >= 0 && prev_bot < top - 1)
                top = prev_bot + 1;
            if (prev_top >= 0 && prev_top > bot + 1)
                bot = prev_top - 1;
            light(c, x, top, bot, s);
            prev_top = dot_row(c, v->hi);
            prev_bot = dot_row(c, v->lo);
        }
    }
}

/* The number of set bits of w: how many series lit a cell. */
static unsigned count_bits(uint32_t w)
{
    unsigned n = 0;
    for (; w != 0u; w &= w - 1u)
        n++;
    return n;
}

static unsigned lowest_bit(uint32_t w)
{
    unsigned i = 0;
    while ((w & 1u) == 0u && i < 31u) {
        w >>= 1;
        i++;
    }
    return i;
}

size_t cli_tplot_line(const cli_tplot_canvas_t *c, unsigned row, const char *const *colors,
                      char *out, size_t cap)
{
    size_t n = 0;
    unsigned x;
    if (cap == 0u)
        return 0;
    for (x = 0; row < c->rows && x < c->width; x++) {
        uint8_t d = c->dots[row][x];
        const char *color = NULL;
        char cell[32];
        size_t len;
        if (d == 0u) {
            cell[0] = ' ';
            len = 1;
        } else {
            /* U+2800 + d in UTF-8: 1110 0010, 10 1000 dd, 10 dddddd */
            unsigned cp = 0x2800u + d;
            char *q = cell;
            if (colors != NULL && count_bits(c->who[row][x]) == 1u)
                color = colors[lowest_bit(c->who[row][x])];
            if (color != NULL) {
                size_t cl = strlen(color);
                if (cl > 16u)
                    cl = 16u;
                memcpy(q, "\033[", 2);
                memcpy(q + 2, color, cl);
                q[2 + cl] = 'm';
                q += 3 + cl;
            }
            q[0] = (char)(0xE0u | (cp >> 12));
            q[1] = (char)(0x80u | ((cp >> 6) & 0x3Fu));
            q[2] = (char)(0x80u | (cp & 0x3Fu));
            q += 3;
            if (color != NULL) {
                memcpy(q, "\033[0m", 4);
                q += 4;
            }
            len = (size_t)(q - cell);
        }
        if (n + len >= cap)
            break;
        memcpy(out + n, cell, len);
        n += len;
    }
    out[n] = '\0';
    return n;
}
