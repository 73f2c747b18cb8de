/*
 * live.h - what the j288 tool's live screens (`top`, `jog`) share: the terminal (keys without
 * Enter, arrow keys, its size), frames redrawn in place and cut to the terminal's width and
 * height (a narrow or short terminal never wraps or scrolls them), and the robot config of one
 * bus given by --port. POSIX (termios, poll, TIOCGWINSZ): the Windows build leaves these
 * screens out (tools/j288/windows/).
 *
 * Keys: the terminal goes raw (no echo, no line editing) only while cli_live_raw() is in force
 * and only when stdin is a terminal; ISIG stays on, so Ctrl-C is still SIGINT and the
 * command's signal handling (cli_bus.h) locks the servos. cli_live_restore() must follow on
 * every path (it is safe to call twice).
 */
#ifndef J288_CLI_LIVE_H
#define J288_CLI_LIVE_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "j288_robot_config.h"
#include "tplot.h"

/* cli_live_key()'s results besides a plain byte (0-255). */
#define CLI_KEY_NONE  (-1)
#define CLI_KEY_UP    0x101
#define CLI_KEY_DOWN  0x102
#define CLI_KEY_RIGHT 0x103
#define CLI_KEY_LEFT  0x104

/* Keys without Enter and without echo, when stdin is a terminal; returns whether it is. */
bool cli_live_raw(void);
void cli_live_restore(void);

/* The next key typed, or CLI_KEY_NONE when none is waiting; never blocks. Arrow keys (ESC [ A
 * and ESC O A forms) come as CLI_KEY_*; other escape sequences are dropped. */
int cli_live_key(void);

/* The size of stdout's terminal in character cells; 80 x 24 when it does not say. */
void cli_live_size(unsigned *cols, unsigned *rows);

/* A frame being drawn: lines written with fprintf(cli_live_frame_file(), ...) ending in '\n'. */
typedef struct {
    FILE *f;
    char *text;
    size_t len;
} cli_live_frame_t;

/* Start a frame; false when memory ran out (then draw nothing). */
bool cli_live_frame_begin(cli_live_frame_t *fr);

/* Draw the frame from the top left corner of the terminal (stdout): each line cut to cols
 * cells (UTF-8 characters are one cell each, escape sequences none) and cleared to its end, at
 * most rows - 1 lines, the rest of the screen cleared; then free the frame. */
void cli_live_frame_show(cli_live_frame_t *fr, unsigned cols, unsigned rows);

/* Cut one line (no '\n') to cols cells into out (cap bytes, NUL-terminated), keeping every
 * escape sequence (colours) and dropping the characters beyond; returns the length. */
size_t cli_live_cut(const char *line, size_t len, unsigned cols, char *out, size_t cap);

/* The plot p (tplot.h) of the series in mask as rows + 1 lines on f, cols cells wide: a
 * 10-cell y axis on the left (the top and bottom values, in unit), the braille plot, and a
 * time axis spanning span_s seconds up to "now". With color, series k takes the k-th of
 * green, yellow, cyan, magenta among those drawn. Nothing when cols < 20 or rows < 2. */
void cli_live_plot(FILE *f, const cli_tplot_t *p, uint32_t mask, unsigned cols, unsigned rows,
                   double min_span, double span_s, bool color);

/* A robot config of one bus named "bus" on port (its baud, margin and echo come with the
 * runner's options) and a joint "idN" for every id in ids (bit per id), at the library's
 * defaults: the joint angle is the output encoder's, wrapped. */
void cli_live_bus_config(const char *port, uint32_t ids, j288_robot_config_t *cfg);

#endif /* J288_CLI_LIVE_H */
