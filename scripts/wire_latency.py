#!/usr/bin/env python3
"""Command to wire, for the benchmarks (scripts/bench-dds.sh, scripts/bench-rt.sh).

usage: wire_latency.py SENT STAMPS LOG

SENT: dds_peer latency's 'sent T_NS POS' lines (a joint's target alternating between 0.30 and
0.35 rad); STAMPS: test/bench/write_stamp.so's 'T_NS FD HEX' line for every command frame the
bridge wrote; LOG: the simulator's --log of that bus, which decodes each frame (hex -> id,
status, pos). For each command: from its dds_write() to the write() of the first frame that
carries its target. Prints 'command to wire at --rate 1000 (N of M commands): p50 .., p99 ..,
max ..' (the summary bench-dds.sh shows), or with --values one latency (us) a line.
"""

import sys


def latencies(sent_path, stamps_path, log_path):
    """The latencies in microseconds, in the order sent; (list, commands sent)."""
    sent = [(int(t), float(p)) for _, t, p in
            (l.split() for l in open(sent_path) if l.startswith("sent "))]
    frames = [(int(t), h) for t, _, h in (l.split() for l in open(stamps_path))]
    dec = {}
    for l in open(log_path):
        f = l.split()
        if len(f) >= 8 and f[2] == "id=1" and f[3] == "status=1":
            dec[f[1]] = int(f[7].split("=")[1])
    raws = sorted(set(dec.values()))
    if len(raws) != 2:
        sys.exit("wire_latency: expected two target positions on the wire, saw %d" % len(raws))
    raw_of = {0.30: raws[0], 0.35: raws[1]}  # direction 1: the larger angle, the larger count
    lat, j = [], 0
    for t, p in sent:
        while j < len(frames) and frames[j][0] < t:
            j += 1
        k = j
        while k < len(frames) and dec.get(frames[k][1]) != raw_of[round(p, 2)]:
            k += 1
        if k < len(frames):
            lat.append((frames[k][0] - t) / 1000.0)
    return lat, len(sent)


if __name__ == "__main__":
    values = sys.argv[1] == "--values"
    lat, n = latencies(*sys.argv[2:5] if values else sys.argv[1:4])
    if values:
        print("\n".join("%.0f" % v for v in lat))
    else:
        lat.sort()
        q = lambda f: lat[min(len(lat) - 1, int(f * len(lat)))]
        print("command to wire at --rate 1000 (%d of %d commands): p50 %.0f us, p99 %.0f us, "
              "max %.0f us" % (len(lat), n, q(0.5), q(0.99), lat[-1]))
