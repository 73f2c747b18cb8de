#!/usr/bin/env python3
"""Check a live plot on a captured screen against the data the program logged.

usage: plot_check.py SCREEN CSV COLS

SCREEN is `tmux capture-pane -p` of `j288 jog --csv CSV` in a terminal COLS cells wide, showing
the angle-and-target view; CSV is jog's log, one row per sample since the plot began. The
plot is drawn again here from the CSV by the rules tools/j288/tplot.h states (written anew
from them, not from tplot.c): every P samples make a column holding each series' lowest and
highest value; the newest 2 * W columns are drawn, the newest at the right edge; y spans the
lowest and highest drawn value, widened about its middle to at least 0.01 rad; value y is dot
row round((top - y) / (top - bottom) * (4 * rows - 1)); a column lights the dots from its
highest to its lowest value's row, extended to touch the previous column's dots. Braille
cells are U+2800 plus one bit per dot (Unicode's order). Exit 0 when every cell and both
y labels agree; else 1, printing the first difference.
"""
import csv
import math
import re
import sys

MAX_COLS = 512          # columns the plot keeps (tplot.h: CLI_TPLOT_MAX_COLS)
MIN_SPAN = 0.01         # jog's span for angles, rad
BITS = [[0x01, 0x08], [0x02, 0x10], [0x04, 0x20], [0x40, 0x80]]  # [dot row][dot column]


def parse_screen(text):
    """(samples, samples a column, [(y label, cells)] per plot row) from the screen."""
    lines = text.split("\n")
    title = re.compile(r"^plot: angle \(green\) and target \(yellow\), rad of \S+ +(\d+) samples, (\d+) a column")
    for i, line in enumerate(lines):
        head = title.search(line)
        if head:
            break
    else:
        raise SystemExit("no angle plot on the screen")
    rows = []
    for line in lines[i + 1:]:
        m = re.match(r"^(.{9}) \|(.*)$", line)
        if not m:
            break
        rows.append((m.group(1).strip(), m.group(2)))
    return int(head.group(1)), int(head.group(2)), rows


def columns(csv_path, samples, per_column):
    with open(csv_path, newline="") as f:
        rows = list(csv.reader(f))[1:]
    if len(rows) < samples:
        raise SystemExit(f"the CSV has {len(rows)} rows, the screen {samples} samples")
    cols = []
    for c in range(samples // per_column):
        spans = []
        for series in (0, 1):
            vals = []
            for r in rows[c * per_column:(c + 1) * per_column]:
                if series == 0 and r[2] == "1":
                    vals.append(float(r[3]))
                if series == 1 and r[11] != "":
                    vals.append(float(r[11]))
            spans.append((min(vals), max(vals)) if vals else None)
        cols.append(spans)
    return cols[-MAX_COLS:]


def render(cols, width, nrows):
    shown = cols[-2 * width:]
    vals = [v for col in shown for s in col if s is not None for v in s]
    if not vals:
        return None
    lo, hi = min(vals), max(vals)
    if hi - lo < MIN_SPAN:
        mid = lo + (hi - lo) / 2.0
        lo, hi = mid - MIN_SPAN / 2.0, mid + MIN_SPAN / 2.0
    last = 4 * nrows - 1

    def row(y):
        r = math.floor((hi - y) / (hi - lo) * last + 0.5)
        return min(max(r, 0), last)

    dots = [[0] * width for _ in range(nrows)]
    for series in (0, 1):
        prev = None
        for k, col in enumerate(shown):
            x = 2 * width - len(shown) + k
            span = col[series]
            if span is None:
                prev = None
                continue
            top, bot = row(span[1]), row(span[0])
            t, b = top, bot
            if prev is not None and prev[1] < top - 1:
                t = prev[1] + 1
            if prev is not None and prev[0] > bot + 1:
                b = prev[0] - 1
            for y in range(t, b + 1):
                dots[y // 4][x // 2] |= BITS[y % 4][x % 2]
            prev = (top, bot)
    grid = ["".join(chr(0x2800 + d) if d else " " for d in line) for line in dots]
    return lo, hi, grid


def main():
    screen, csv_path, cols = sys.argv[1], sys.argv[2], int(sys.argv[3])
    with open(screen, encoding="utf-8") as f:
        samples, per_column, rows = parse_screen(f.read())
    width = cols - 11
    want = render(columns(csv_path, samples, per_column), width, len(rows))
    if want is None:
        raise SystemExit("nothing to plot in the CSV")
    lo, hi, grid = want
    if rows[0][0] != f"{hi:9.4f}".strip() or rows[-1][0] != f"{lo:9.4f}".strip():
        print(f"y labels {rows[0][0]} .. {rows[-1][0]}, want {hi:.4f} .. {lo:.4f}")
        return 1
    for r, (got, exp) in enumerate(zip((g for _, g in rows), grid)):
        if got.ljust(width) != exp:
            print(f"row {r} of {len(rows)} ({samples} samples, {per_column} a column):")
            print(f"  got  |{got.ljust(width)}|")
            print(f"  want |{exp}|")
            return 1
    print(f"plot agrees: {len(rows)} rows, {samples} samples")
    return 0


if __name__ == "__main__":
    sys.exit(main())
