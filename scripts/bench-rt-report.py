#!/usr/bin/env python3
"""The tables of scripts/bench-rt.sh (make bench-rt) from its run directory.

usage: bench-rt-report.py DIR PERIOD_US

Percentiles are nearest-rank: cyclictest's from its per-microsecond histogram, the loop's as
j288 reports them (its histogram's bucket tops, at most 3.2 % high above 64 us). A ratio is
the loop's percentile over cyclictest's at the same moment: 1.0 is the machine's floor.
"""

import json
import os
import sys

import wire_latency  # (beside this file)

D = sys.argv[1]
PERIOD = int(sys.argv[2])
QS = (0.5, 0.99, 0.999, 1.0)
LABEL = {"idle": "idle", "stress": "stress-ng --cpu 2"}


def nearest_rank(sorted_counts, n, q):
    """sorted_counts: [(value, count)] ascending; the smallest value with >= q*n at or below."""
    need = max(1, -(-int(q * n * 1000000) // 1000000))
    seen = 0
    for v, c in sorted_counts:
        seen += c
        if seen >= need:
            return v
    return sorted_counts[-1][0]


def cyclictest(path):
    t = json.load(open(path))["thread"]["0"]
    h = sorted((int(k), v) for k, v in t["histogram"].items())
    over = t["cycles"] - sum(c for _, c in h)
    if over > 0:  # beyond the histogram's bound: counted at the maximum
        h.append((t["max"], over))
    n = sum(c for _, c in h)
    return [nearest_rank(h, n, q) for q in QS[:-1]] + [t["max"]]


def values(samples):
    s = sorted(samples)
    h = [(v, 1) for v in s]
    return [nearest_rank(h, len(s), q) for q in QS[:-1]] + [s[-1]]


def ratio(a, b):
    return "%5.1f" % (a / b) if b else "    -"


def rows(name):
    p = os.path.join(D, name)
    return [l.split() for l in open(p)] if os.path.exists(p) and os.path.getsize(p) else []


def loop_tables():
    r = rows("loop.rows")
    if not r:
        return
    print("\nthe loop: j288 --config F log --rate %d (4 buses x 3 servos), wake-up lateness (us) "
          "against cyclictest's at the same moment" % (1000000 // PERIOD))
    print("%-30s %27s | %27s | %23s" % ("run", "loop p50 p99 p99.9 max",
                                       "cyclictest p50 p99 p99.9 max", "ratio p50 p99 p99.9 max"))
    for name, load, mode, down, _ in r:
        j = json.load(open(os.path.join(D, name + ".json")))
        t = j["timing"]["lateness_us"]
        lp = [t["p50"], t["p99"], t["p99_9"], t["max"]]
        cp = cyclictest(os.path.join(D, name + ".ct"))
        print("%-30s %6d %6d %6d %7d | %6d %6d %6d %7d | %5s %5s %5s %5s"
              % ("%s, %s" % (LABEL[load], "--realtime" if mode == "realtime" else "normal"),
                 *lp, *cp, *(ratio(a, b) for a, b in zip(lp, cp))))
    print("%-30s %9s %9s %8s %8s %5s %10s %11s %10s %9s" % (
        "", "cycles/s", "wake-ups", "missed", "skipped", "cut", "cycle p50", "cycle p99.9",
        "cycle max", "bus down"))
    for name, load, mode, down, _ in r:
        j = json.load(open(os.path.join(D, name + ".json")))
        t = j["timing"]
        print("%-30s %9.1f %9d %8d %8d %5d %7d us %8d us %7d us %9s"
              % ("%s, %s" % (LABEL[load], "--realtime" if mode == "realtime" else "normal"),
                 j["cycles_per_s"], t["lateness_us"]["count"], t["missed_deadlines"],
                 t["skipped_periods"], t["cut_cycles"], t["duration_us"]["p50"],
                 t["duration_us"]["p99_9"], t["duration_us"]["max"], down))


def csv_starts(path):
    starts, last = [], None
    for line in open(path):
        if line.startswith("time_s"):
            continue
        f = line.rstrip("\n").split(",")
        if f[-1] != last:
            starts.append(round(float(f[0]) * 1e6))
            last = f[-1]
    return starts


def summary_line(path):
    for line in open(path):
        if line.startswith("robot: "):  # robot: N cycles in T s: R cycles/s, C complete, worst cycle W us
            w = line.split()
            return float(w[6]), int(w[-2])
    return 0.0, 0


def old_new_table():
    r = rows("csv.rows")
    if not r:
        return
    print("\nold against new (both with --csv; old: 2af1ea0-era runner, chrt -f %s and taskset "
          "for --realtime): jitter of cycle starts |interval - period|, us" % "PRIO")
    print("%-36s %9s %10s %10s %10s %12s %10s" % ("run", "cycles/s", "late", "worst cyc",
                                                   "jitter p99", "jitter p99.9", "bus down"))
    for name, load, mode, down in r:
        s = csv_starts(os.path.join(D, name + ".csv"))
        rate, worst = summary_line(os.path.join(D, name + ".out"))
        jit = values([abs(b - a - PERIOD) for a, b in zip(s, s[1:])]) if len(s) > 2 else [0] * 4
        # late: cycles that started a period or more after the one before's due time
        late = sum(1 for a, b in zip(s, s[1:]) if b - a >= 2 * PERIOD)
        print("%-36s %9.1f %10d %8d us %7d us %9d us %10s"
              % ("%s %s, %s" % (name.split("-")[0], LABEL[load], mode), rate, late, worst,
                 jit[1], jit[2], down))
    print("(late: cycle starts two periods or more apart, a whole period lost)")


def trace_table():
    r = rows("trace.rows")
    if not r:
        return
    print("\nthe kernel worker's share (--realtime beside stress-ng): delay of each tty flush, "
          "queued by the writer -> run by a kworker (flush_to_ldisc), us")
    print("%-44s %7s %7s %7s %7s %9s | %10s %9s %10s %9s" % (
        "run", "p50", "p99", "p99.9", "max", "flushes", "cycle p99", "wake-ups", "cycles/s",
        "bus down"))
    for name, down in r:
        queued, delays = {}, []
        for line in open(os.path.join(D, name + ".trace")):
            f = line.split()
            ts = next(x for x in f if x.endswith(":") and x[:-1].replace(".", "").isdigit())
            t = float(ts[:-1])
            if "workqueue_queue_work:" in line:
                queued[line.split("work struct=")[1].split()[0]] = t
            elif "workqueue_execute_start:" in line:
                w = line.split("work struct ")[1].split(":")[0]
                if w in queued:
                    delays.append(round((t - queued.pop(w)) * 1e6))
        j = json.load(open(os.path.join(D, name + ".json")))
        p = values(delays) if delays else [0] * 4
        label = {"trace-default": "kworkers as the kernel makes them (SCHED_OTHER)",
                 "trace-nice": "stress-ng at nice 19 (the rest at low weight)",
                 "trace-raised": "unbound kworkers under SCHED_FIFO PRIO-1"}.get(name, name)
        print("%-44s %7d %7d %7d %7d %9d | %7d us %9d %10.1f %9s"
              % (label, *p, len(delays), j["timing"]["duration_us"]["p99"],
                 j["timing"]["lateness_us"]["count"], j["cycles_per_s"], down))


def dds_table():
    r = rows("dds.rows")
    if not r:
        return
    print("\nthe bridge: j288-dds --rate %d, command to wire (us) against cyclictest's lateness "
          "at the same moment" % (1000000 // PERIOD))
    print("%-30s %31s | %27s | %23s" % ("run", "wire p50 p99 p99.9 max (n)",
                                       "cyclictest p50 p99 p99.9 max", "ratio p50 p99 p99.9 max"))
    for name, load, mode in r:
        lat = [round(v) for v in wire_latency.latencies(
            os.path.join(D, name + ".sent"), os.path.join(D, name + ".stamps"),
            os.path.join(D, name + ".log0"))[0]]
        wp = values(lat)
        cp = cyclictest(os.path.join(D, name + ".ct"))
        print("%-30s %6d %6d %6d %7d (%d) | %6d %6d %6d %7d | %5s %5s %5s %5s"
              % ("%s, %s" % (LABEL[load], "--realtime" if mode == "realtime" else "normal"),
                 *wp, len(lat), *cp, *(ratio(a, b) for a, b in zip(wp, cp))))


loop_tables()
old_new_table()
trace_table()
dds_table()
