#!/usr/bin/env bash
# How close `j288 calibrate` and `j288 zero` get to the truth, measured on j288-sim: for each
# seed (the simulator draws the servo's phase c and start angle from it) and each backlash,
# zero uncalibrated, calibrate, zero calibrated, each compared with the simulator's --truth
# file. Prints one row per run and the worst case per backlash (docs/joint.md has a run).
# Usage: scripts/joint-accuracy.sh [--seeds N] [--backlash "RAD RAD ..."] [BIN]
#   defaults: 10 seeds (1..N), backlash "0 0.001 0.004" (output rad), BIN build/bin
set -euo pipefail
seeds=10
backlashes="0 0.001 0.004"
while [ $# -gt 0 ]; do
    case $1 in
    --seeds) seeds=$2; shift 2 ;;
    --backlash) backlashes=$2; shift 2 ;;
    -h | --help) sed -n '2,7p' "$0"; exit 0 ;;
    *) break ;;
    esac
done
bin=${1:-build/bin}
for f in "$bin/j288" "$bin/j288-sim"; do
    [ -x "$f" ] || { echo "$f not built (make cli sim)" >&2; exit 1; }
done
tmp=$(mktemp -d)
sim_pid=
trap '[ -n "$sim_pid" ] && kill "$sim_pid" 2>/dev/null; rm -rf "$tmp"' EXIT
M=(--margin-us 250000 --retries 1)

truth_seq() { sed -n '1s/^# j288-sim truth seq=\([0-9]*\) .*/\1/p' "$tmp/truth"; }
truth_now() { # ask for the truth and wait until it is written
    local seq i
    seq=$(truth_seq)
    kill -s WINCH "$sim_pid"
    for i in $(seq 1 400); do [ "$(truth_seq)" != "$seq" ] && return 0; sleep 0.05; done
    echo "no truth from the simulator" >&2; return 1
}
truth_val() { awk -v key="$1" '$1 == "id=1" { for (i = 2; i <= NF; i++) { n = index($i, "="); if (substr($i, 1, n - 1) == key) print substr($i, n + 1) } }' "$tmp/truth"; }
jval() { python3 -c 'import json, sys; print(json.loads(sys.argv[1])[sys.argv[2]])' "$1" "$2"; }

echo "seed backlash_rad c_err_rotor_mrad c_err_output_urad zero_uncal_err_mrad zero_cal_err_mrad zero_cal_vs_gear_mrad" >"$tmp/rows"
for b in $backlashes; do
    for s in $(seq 1 "$seeds"); do
        rm -f "$tmp/bus" "$tmp/truth"
        "$bin/j288-sim" --ids 1 --seed "$s" --backlash "$b" --link "$tmp/bus" --truth "$tmp/truth" \
            --quiet --exit-after 600 >/dev/null 2>&1 &
        sim_pid=$!
        for _ in $(seq 1 200); do [ -L "$tmp/bus" ] && break; sleep 0.05; done
        printf 'buses:\n  - name: sim\n    port: %s\njoints:\n  - name: j\n    id: 1\n    limits: [-3, 3]\n' "$tmp/bus" >"$tmp/robot.yaml"
        z_u=$(jval "$("$bin/j288" zero --joint j --config "$tmp/robot.yaml" --json "${M[@]}")" zero)
        truth_now; th_u=$(truth_val theta)
        cal=$("$bin/j288" calibrate --joint j --config "$tmp/robot.yaml" --json "${M[@]}")
        truth_now; c=$(truth_val c)
        z_c=$(jval "$("$bin/j288" zero --joint j --config "$tmp/robot.yaml" --json "${M[@]}")" zero)
        truth_now; th_c=$(truth_val theta); thg_c=$(truth_val theta_gear)
        python3 -c '
import math, sys
s, b, zu, thu, ph, c, zc, thc, thg = sys.argv[1:]
w = lambda d: math.remainder(d, 2 * math.pi)
dc = w(float(ph) - float(c))
print(s, b, "%.3f" % (dc * 1e3), "%.2f" % (dc / 288.35 * 1e6), "%.3f" % (w(float(zu) - float(thu)) * 1e3),
      "%.4f" % (w(float(zc) - float(thc)) * 1e3), "%.4f" % (w(float(zc) - float(thg)) * 1e3))' \
            "$s" "$b" "$z_u" "$th_u" "$(jval "$cal" phase)" "$c" "$z_c" "$th_c" "$thg_c" >>"$tmp/rows"
        kill "$sim_pid" 2>/dev/null; wait "$sim_pid" 2>/dev/null || true; sim_pid=
    done
done
column -t "$tmp/rows"
echo
python3 - "$tmp/rows" <<'PY'
import sys, collections
rows = [l.split() for l in open(sys.argv[1]).read().splitlines()[1:]]
by = collections.defaultdict(list)
for r in rows:
    by[r[1]].append([abs(float(x)) for x in r[2:]])
print("worst |error| per backlash over %d seeds:" % (len(rows) // max(1, len(by))))
print("backlash_rad c_rotor_mrad c_output_urad zero_uncal_mrad zero_cal_mrad zero_cal_vs_gear_mrad")
for b, v in by.items():
    print(b, *["%.4g" % max(col) for col in zip(*v)])
PY
