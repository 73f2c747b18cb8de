#!/usr/bin/env bash
# usage: [BUILD=build] [DURATION=5] [ROUNDS=3] [COUNT=300] [CALLGRIND=1] scripts/bench-dds.sh
#        (make bench-dds)
# j288-dds's cost, in a private network namespace (test/dds/lib_dds.sh), against four j288-sim
# buses of three servos (pseudo-terminals), everything back to back:
# - cycles/s and CPU per cycle of the runner alone (`j288 --config F log --rate 0`), of the
#   bridge publishing with nobody listening, and of the bridge publishing to a subscriber
#   (test/dds/dds_peer listen); the difference in CPU per cycle is what DDS costs;
# - command-to-wire latency at --rate 1000: the peer's dds_write of a joint_command (its
#   CLOCK_MONOTONIC) to the write() of the first frame carrying that target (stamped by
#   test/bench/write_stamp.so preloaded into the bridge), p50 / p99 / max over COUNT commands;
# - with CALLGRIND=1, instructions per cycle (valgrind --tool=callgrind, every thread): the
#   runner alone, and the bridge publishing to a subscriber, split into its parts.
# Wall-clock figures on a shared machine: compare the rows of one run. Needs make dds, j288.
set -euo pipefail
cd "$(dirname "$0")/.."
. test/dds/lib_dds.sh
dds_netns "$0" "$@"
BUILD=${BUILD:-build}
BIN=$BUILD/bin
DURATION=${DURATION:-5}
COUNT=${COUNT:-300}
ROUNDS=${ROUNDS:-3}
tmp=$(mktemp -d)
SIM_DIR=$tmp
. test/e2e/lib_sim.sh
PEER=$BUILD/test/dds_peer
DDS=$BIN/j288-dds
trap 'sim_cleanup TERM' EXIT
SHIM=$BUILD/bench/write_stamp.so
for f in "$BIN/j288" "$DDS" "$PEER" "$SIM" "$SHIM"; do
    [ -x "$f" ] || [ -f "$f" ] || { echo "bench-dds: $f missing (make dds all, then make bench-dds)" >&2; exit 1; }
done

start_sims 4 --exit-after 600 --log "$tmp/log.{k}"
robot_config 4 "$tmp/robot.yaml" 5000 20 1

# runner_run: "cycles rate cpu" of the runner alone (its JSON; CPU from time(1))
runner_run() {
    /usr/bin/time -f 'cpu %U %S' -o "$tmp/time" "$BIN/j288" --config "$tmp/robot.yaml" log \
        --rate 0 --duration "$DURATION" --json >"$tmp/log.json"
    echo "$(sed -n 's/.*"cycles": *\([0-9]*\).*/\1/p' "$tmp/log.json" | head -n1)" \
         "$(sed -n 's/.*"cycles_per_s": *\([0-9.]*\).*/\1/p' "$tmp/log.json")" \
         "$(awk '{ print $2 + $3 }' "$tmp/time")"
}
# bridge_run OPTIONS: the same of the bridge for DURATION s (its summary line at exit)
bridge_run() {
    "$DDS" --config "$tmp/robot.yaml" --domain "$DDS_DOMAIN" "$@" 2>"$tmp/bridge.err" &
    local p=$!
    sleep "$DURATION"
    kill -INT $p; wait $p || true
    sed -n 's/^j288-dds: \([0-9]*\) cycles .* s, \([0-9]*\) cycles\/s, cpu \([0-9.]*\) s$/\1 \2 \3/p' "$tmp/bridge.err"
}
# ROUNDS rounds of the three setups in turn (the machine's load drifts: medians of rounds)
: >"$tmp/rows"
for r in $(seq 1 "$ROUNDS"); do
    echo "runner $(runner_run)" >>"$tmp/rows"
    echo "quiet $(bridge_run --rate 0)" >>"$tmp/rows"
    "$PEER" listen --for $((DURATION + 3)) >"$tmp/listen" &
    lp=$!
    sleep 1
    echo "subscribed $(bridge_run --rate 0)" >>"$tmp/rows"
    wait $lp
done

# latency at 1 kHz
: >"$tmp/log.0"
J288_WRITE_STAMP=$tmp/stamps LD_PRELOAD=$PWD/$SHIM "$DDS" --config "$tmp/robot.yaml" \
    --domain "$DDS_DOMAIN" --rate 1000 --timeout 1000 2>"$tmp/bridge.err" &
bp=$!
for _ in $(seq 1 30); do "$PEER" states --timeout 1 >"$tmp/first" 2>/dev/null && ! grep -q nan "$tmp/first" && break; done
"$PEER" latency --count "$COUNT" --hz 50 leg0_1 0.30 0.35 >"$tmp/sent"
sleep 0.5
kill -INT $bp; wait $bp || true

# instructions per cycle, counted by callgrind (repeatable, unlike the seconds above)
if [ "${CALLGRIND:-0}" = 1 ]; then
    valgrind --tool=callgrind --callgrind-out-file="$tmp/runner.cg" "$BIN/j288" \
        --config "$tmp/robot.yaml" log --rate 0 --duration 4 --json >"$tmp/log.json" 2>/dev/null
    cg_runner_cycles=$(sed -n 's/.*"cycles": *\([0-9]*\).*/\1/p' "$tmp/log.json" | head -n1)
    "$PEER" listen --for 12 >/dev/null &
    lp=$!
    valgrind --tool=callgrind --callgrind-out-file="$tmp/dds.cg" "$DDS" --config "$tmp/robot.yaml" \
        --domain "$DDS_DOMAIN" --rate 0 2>"$tmp/dds.err" &
    vp=$!
    sleep 8
    kill -INT $vp; wait $vp || true
    wait $lp
    cg_dds_cycles=$(sed -n 's/^j288-dds: \([0-9]*\) cycles .*/\1/p' "$tmp/dds.err")
fi

echo "j288-dds benchmark: 4 buses x 3 servos on j288-sim, ${DURATION} s each, $(nproc) cores"
python3 - "$tmp/rows" <<'PY'
import sys, statistics as st
rows = {}
for l in open(sys.argv[1]):
    name, cycles, rate, cpu = l.split()
    rows.setdefault(name, []).append((float(rate), float(cpu) * 1e6 / float(cycles)))
label = {'runner': 'runner alone (j288 log --rate 0)', 'quiet': 'j288-dds, nobody subscribed',
         'subscribed': 'j288-dds, publishing to a subscriber'}
base = st.median(r for r, _ in rows['runner'])
print('%-40s %16s %8s %14s' % ('setup (back to back), median of rounds', 'cycles/s', 'vs alone', 'CPU us/cycle'))
for k in ('runner', 'quiet', 'subscribed'):
    rate = st.median(r for r, _ in rows[k]); cpu = st.median(c for _, c in rows[k])
    spread = '%.0f-%.0f' % (min(r for r, _ in rows[k]), max(r for r, _ in rows[k]))
    print('%-40s %6.0f (%s) %7.0f%% %14.1f' % (label[k], rate, spread, 100 * rate / base, cpu))
PY
python3 scripts/wire_latency.py "$tmp/sent" "$tmp/stamps" "$tmp/log.0"
if [ "${CALLGRIND:-0}" = 1 ]; then
    echo "instructions per cycle (callgrind, all threads; start-up included in the totals):"
    # inclusive cost of a function: the first number on its line of callgrind_annotate
    incl() { callgrind_annotate --inclusive=yes "$1" 2>/dev/null | awk -v f="$2" '$0 ~ f { gsub(",", "", $1); print $1; exit }'; }
    total() { callgrind_annotate "$1" 2>/dev/null | awk '/PROGRAM TOTALS/ { gsub(",", "", $1); print $1; exit }'; }
    per() { awk -v a="${1:-0}" -v c="$2" 'BEGIN { printf "%8.0f", a / c }'; }
    printf '  runner alone: total %s, j288_robot_cycle %s  (%s cycles)\n' \
        "$(per "$(total "$tmp/runner.cg")" "$cg_runner_cycles")" \
        "$(per "$(incl "$tmp/runner.cg" ':j288_robot_cycle ')" "$cg_runner_cycles")" "$cg_runner_cycles"
    printf '  j288-dds:     total %s, j288_robot_cycle %s, dds_write %s, dds_take %s, fill %s, diagnostics %s  (%s cycles)\n' \
        "$(per "$(total "$tmp/dds.cg")" "$cg_dds_cycles")" \
        "$(per "$(incl "$tmp/dds.cg" ':j288_robot_cycle ')" "$cg_dds_cycles")" \
        "$(per "$(incl "$tmp/dds.cg" ':dds_write ')" "$cg_dds_cycles")" \
        "$(per "$(incl "$tmp/dds.cg" ':dds_take ')" "$cg_dds_cycles")" \
        "$(per "$(incl "$tmp/dds.cg" 'bridge_fill_joint_state ')" "$cg_dds_cycles")" \
        "$(per "$(incl "$tmp/dds.cg" 'publish_diagnostics')" "$cg_dds_cycles")" "$cg_dds_cycles"
fi
