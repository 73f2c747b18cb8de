/* Unit tests of the live plot (tools/j288/tplot.c): known series against braille worked out
 * by hand from Unicode's braille block (U+2800 + dot bits: dots 1-3 of the left column are
 * bits 0-2, of the right column bits 3-5, the bottom row bits 6 and 7) and tplot.h's rules
 * (dot row = round((top - y) / (top - bottom) * (4 * rows - 1)); a column joined to the
 * previous one; the newest column at the right edge). */
#include "unity.h"

#include <math.h>
#include <string.h>

#include "tplot.h"

static cli_tplot_t plot;
static cli_tplot_canvas_t canvas;

void setUp(void) {}

void tearDown(void) {}

/* One sample of series 0 (and 1, when two are given: NAN for none). */
static void add1(double a) { double v[CLI_TPLOT_MAX_SERIES] = {a}; cli_tplot_add(&plot, v); }
static void add2(double a, double b)
{
    double v[CLI_TPLOT_MAX_SERIES] = {a, b};
    cli_tplot_add(&plot, v);
}

static const char *line(unsigned row, const char *const *colors)
{
    static char buf[4096];
    (void)cli_tplot_line(&canvas, row, colors, buf, sizeof buf);
    return buf;
}

/* 0 then 1: the left dot column at the bottom (dot 7, 0x40), the right one at the top and
 * joined down to the row above the previous dot (dots 4, 5, 6: 0x38): U+2878. */
static void test_two_samples_make_one_joined_cell(void)
{
    cli_tplot_init(&plot, 1, 1);
    add1(0.0);
    add1(1.0);
    cli_tplot_render(&plot, 1u, 1, 1, 0.0, &canvas);
    TEST_ASSERT_FALSE(canvas.empty);
    TEST_ASSERT_EQUAL_DOUBLE(0.0, canvas.bottom);
    TEST_ASSERT_EQUAL_DOUBLE(1.0, canvas.top);
    TEST_ASSERT_EQUAL_HEX8(0x78, canvas.dots[0][0]);
    TEST_ASSERT_EQUAL_STRING("\xE2\xA1\xB8", line(0, NULL)); /* U+2878 */
}

/* Three samples in one column: lowest 0, highest 2, the whole right dot column (0xB8), at the
 * right edge; the left dot column had no data. */
static void test_a_column_keeps_its_samples_range(void)
{
    cli_tplot_init(&plot, 1, 3);
    add1(0.0);
    add1(2.0);
    add1(1.0);
    cli_tplot_render(&plot, 1u, 1, 1, 0.0, &canvas);
    TEST_ASSERT_EQUAL_UINT32(3, plot.samples);
    TEST_ASSERT_EQUAL_HEX8(0xB8, canvas.dots[0][0]);
    TEST_ASSERT_EQUAL_STRING("\xE2\xA2\xB8", line(0, NULL)); /* U+28B8 */
}

/* A column not yet complete is not drawn. */
static void test_the_open_column_is_not_drawn(void)
{
    cli_tplot_init(&plot, 1, 2);
    add1(5.0);
    cli_tplot_render(&plot, 1u, 2, 1, 0.0, &canvas);
    TEST_ASSERT_TRUE(canvas.empty);
    TEST_ASSERT_EQUAL_STRING("  ", line(0, NULL));
}

/* A flat 5 with a span of 2: y from 4 to 6, 5 at dot row round(1.5) = 2, the right column:
 * dot 6 (0x20). */
static void test_min_span_widens_about_the_middle(void)
{
    cli_tplot_init(&plot, 1, 1);
    add1(5.0);
    cli_tplot_render(&plot, 1u, 1, 1, 2.0, &canvas);
    TEST_ASSERT_EQUAL_DOUBLE(4.0, canvas.bottom);
    TEST_ASSERT_EQUAL_DOUBLE(6.0, canvas.top);
    TEST_ASSERT_EQUAL_STRING("\xE2\xA0\xA0", line(0, NULL)); /* U+2820 */
}

/* NaN and infinities are no value: nothing drawn, a blank row. */
static void test_missing_values_draw_nothing(void)
{
    cli_tplot_init(&plot, 1, 1);
    add1(NAN);
    add1(INFINITY);
    cli_tplot_render(&plot, 1u, 3, 2, 0.0, &canvas);
    TEST_ASSERT_TRUE(canvas.empty);
    TEST_ASSERT_EQUAL_STRING("   ", line(0, NULL));
    TEST_ASSERT_EQUAL_STRING("   ", line(1, NULL));
}

/* A gap in a series breaks its line: the column after it is not joined to the one before. */
static void test_a_gap_breaks_the_line(void)
{
    cli_tplot_init(&plot, 1, 1);
    add1(0.0);
    add1(NAN);
    add1(1.0);
    add1(1.0);
    cli_tplot_render(&plot, 1u, 2, 1, 0.0, &canvas);
    /* dot columns: 0 at the bottom (0x40), none, top (0x01), top (0x08) */
    TEST_ASSERT_EQUAL_HEX8(0x40, canvas.dots[0][0]);
    TEST_ASSERT_EQUAL_HEX8(0x09, canvas.dots[0][1]);
}

/* Two series: where both light a cell it takes no colour; a single series' cells do. */
static void test_series_share_cells_and_colours(void)
{
    static const char *const colors[CLI_TPLOT_MAX_SERIES] = {"32", "33"};
    int i;
    cli_tplot_init(&plot, 2, 1);
    for (i = 0; i < 4; i++)
        add2(1.0, 0.0);
    /* both: 1 at the top row (0x01, 0x08), 0 at the bottom (0x40, 0x80): U+28C9 twice */
    cli_tplot_render(&plot, 3u, 2, 1, 0.0, &canvas);
    TEST_ASSERT_EQUAL_STRING("\xE2\xA3\x89\xE2\xA3\x89", line(0, colors));
    TEST_ASSERT_EQUAL_HEX16(3, canvas.who[0][1]);
    /* series 0 alone, flat: y 0.5 to 1.5, 1 at dot row 2 (0x04, 0x20): U+2824, green */
    cli_tplot_render(&plot, 1u, 2, 1, 0.0, &canvas);
    TEST_ASSERT_EQUAL_STRING("\033[32m\xE2\xA0\xA4\033[0m\033[32m\xE2\xA0\xA4\033[0m",
                             line(0, colors));
    /* series 1 alone, without colours */
    cli_tplot_render(&plot, 2u, 2, 1, 0.0, &canvas);
    TEST_ASSERT_EQUAL_STRING("\xE2\xA0\xA4\xE2\xA0\xA4", line(0, NULL));
}

/* Two character rows: 8 dot rows; 0 then 1 then 0.5: dot rows 7, 0 and round(3.5) = 4, the
 * second column joined down to row 6, the third joined up to row 1. */
static void test_rows_split_the_dots(void)
{
    cli_tplot_init(&plot, 1, 1);
    add1(0.0);
    add1(1.0);
    add1(0.5);
    cli_tplot_render(&plot, 1u, 2, 2, 0.0, &canvas);
    /* dot columns 1, 2, 3 (the newest three of four); cell 0 right column: rows 7 (0x80 in
     * the lower cell); cell 1 left column: rows 0-6; cell 1 right column: rows 1-4 */
    TEST_ASSERT_EQUAL_HEX8(0x00, canvas.dots[0][0]);
    TEST_ASSERT_EQUAL_HEX8(0x80, canvas.dots[1][0]);
    TEST_ASSERT_EQUAL_HEX8(0x01 | 0x02 | 0x04 | 0x40 | 0x10 | 0x20 | 0x80, canvas.dots[0][1]);
    TEST_ASSERT_EQUAL_HEX8(0x01 | 0x02 | 0x04 | 0x08, canvas.dots[1][1]);
}

/* More columns than the ring holds: the newest are kept and drawn at the right edge. */
static void test_the_ring_keeps_the_newest(void)
{
    int i;
    cli_tplot_init(&plot, 1, 1);
    for (i = 0; i < (int)CLI_TPLOT_MAX_COLS + 88; i++)
        add1((double)i);
    TEST_ASSERT_EQUAL_UINT(CLI_TPLOT_MAX_COLS, plot.ncols);
    cli_tplot_render(&plot, 1u, 1, 1, 0.0, &canvas);
    TEST_ASSERT_EQUAL_DOUBLE((double)CLI_TPLOT_MAX_COLS + 86.0, canvas.bottom);
    TEST_ASSERT_EQUAL_DOUBLE((double)CLI_TPLOT_MAX_COLS + 87.0, canvas.top);
    TEST_ASSERT_EQUAL_STRING("\xE2\xA1\xB8", line(0, NULL));
}

/* Sizes are clamped, lines fit their buffer, a row beyond the canvas is empty. */
static void test_sizes_and_buffers_are_bounded(void)
{
    char small[5];
    cli_tplot_init(&plot, 99, 0);
    TEST_ASSERT_EQUAL_UINT(CLI_TPLOT_MAX_SERIES, plot.nseries);
    TEST_ASSERT_EQUAL_UINT(1, plot.per_column);
    add1(0.0);
    add1(1.0);
    cli_tplot_render(&plot, 1u, 10000, 10000, 0.0, &canvas);
    TEST_ASSERT_EQUAL_UINT(CLI_TPLOT_MAX_WIDTH, canvas.width);
    TEST_ASSERT_EQUAL_UINT(CLI_TPLOT_MAX_ROWS, canvas.rows);
    cli_tplot_render(&plot, 1u, 2, 1, 0.0, &canvas);
    TEST_ASSERT_EQUAL_UINT(4, cli_tplot_line(&canvas, 0, NULL, small, sizeof small));
    TEST_ASSERT_EQUAL_STRING(" \xE2\xA1\xB8", small);
    TEST_ASSERT_EQUAL_UINT(1, cli_tplot_line(&canvas, 0, NULL, small, 3)); /* no room: 1 cell */
    TEST_ASSERT_EQUAL_STRING(" ", small);
    TEST_ASSERT_EQUAL_UINT(0, cli_tplot_line(&canvas, 5, NULL, small, sizeof small));
    TEST_ASSERT_EQUAL_STRING("", small);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_two_samples_make_one_joined_cell);
    RUN_TEST(test_a_column_keeps_its_samples_range);
    RUN_TEST(test_the_open_column_is_not_drawn);
    RUN_TEST(test_min_span_widens_about_the_middle);
    RUN_TEST(test_missing_values_draw_nothing);
    RUN_TEST(test_a_gap_breaks_the_line);
    RUN_TEST(test_series_share_cells_and_colours);
    RUN_TEST(test_rows_split_the_dots);
    RUN_TEST(test_the_ring_keeps_the_newest);
    RUN_TEST(test_sizes_and_buffers_are_bounded);
    return UNITY_END();
}
