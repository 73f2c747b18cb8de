#!/usr/bin/env bash
# usage: [BUILD=build] [DURATION=5] [ROUNDS=3] [COUNT=300] [CALLGRIND=1] [STATE_ONLY=1]
#        [BASE_DDS=OTHER/j288-dds] scripts/bench-dds.sh         (make bench-dds)
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
# - the state rate: rt/joint_states samples a subscriber gets per second from the bridge at
#   --rate 500, idle, beside `stress-ng --cpu 2`, and while a peer floods rt/joint_command with
#   1.6 MB samples (100,000 names) at 50 a second; each as a ratio to idle. With BASE_DDS (an
#   older build's j288-dds, e.g. 2af1ea0's) the same for it, the two bridges taking turns in
#   every round. STATE_ONLY=1: that part alone. With CALLGRIND=1 also what one 1.6 MB sample
#   costs each bridge in instructions (valgrind --tool=callgrind, every thread).
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
e2e_scaled() { echo "$1"; } # (test/e2e/lib_e2e.sh's, unscaled: lib_sim.sh's waits use it)
. test/e2e/lib_sim.sh
PEER=$BUILD/test/dds_peer
DDS=$BIN/j288-dds
trap 'sim_cleanup TERM' EXIT
SHIM=$BUILD/bench/write_stamp.so
for f in "$BIN/j288" "$DDS" "$PEER" "$SIM" "$SHIM"; do
    [ -x "$f" ] || [ -f "$f" ] || { echo "bench-dds: $f missing (make dds all, then make bench-dds)" >&2; exit 1; }
done

start_sims 4 --exit-after 1800 --log "$tmp/log.{k}"
robot_config 4 "$tmp/robot.yaml" 5000 20 1

# state_rate BRIDGE idle|load|flood: joint_states samples per second a subscriber got in
# DURATION s from BRIDGE at --rate 500, idle, beside stress-ng --cpu 2, or under a flood
state_rate() {
    local b l="" n
    "$1" --config "$tmp/robot.yaml" --domain "$DDS_DOMAIN" --rate 500 2>"$tmp/sr.err" &
    b=$!
    for _ in $(seq 1 30); do "$PEER" states --timeout 1 >"$tmp/first" 2>/dev/null && ! grep -q nan "$tmp/first" && break; done
    case $2 in
        load) stress-ng --cpu 2 --timeout $((DURATION + 3)) >/dev/null 2>&1 & l=$! ;;
        flood) "$PEER" flood --hz 50 --for $((DURATION + 3)) >"$tmp/flood" 2>/dev/null & l=$!
               for _ in $(seq 1 200); do grep -qs '^writer ' "$tmp/flood" && break; sleep 0.05; done ;;
    esac
    sleep 1
    n=$("$PEER" listen --for "$DURATION" | sed -n 's/^samples //p')
    [ "$2" = flood ] && wait "$l" && sed -n 's/^sent \([0-9]*\) in \([0-9.]*\) s$/\1 \2/p' "$tmp/flood" >>"$tmp/sent"
    [ -n "$l" ] && { kill "$l" 2>/dev/null; wait "$l" 2>/dev/null; }
    kill -INT $b; wait $b || true
    # and the bridge's CPU time (all its threads, Cyclone's receive thread too) per cycle, over
    # its whole run, from its summary line: what the condition cost it, less swayed by other load
    awk -v n="${n:-0}" -v d="$DURATION" 'BEGIN { printf "%.1f ", n / d }'
    sed -n 's/^j288-dds: \([0-9]*\) cycles .*, cpu \([0-9.]*\) s$/\1 \2/p' "$tmp/sr.err" |
        awk '{ printf "%.0f", ($1 > 0 ? 1e6 * $2 / $1 : 0) }'
}
if [ "${STATE_ONLY:-0}" = 1 ] || [ -n "${BASE_DDS:-}" ]; then
    : >"$tmp/state"; : >"$tmp/sent"
    load_before=$(cut -d' ' -f1-3 /proc/loadavg)
    bridges=("$DDS")
    [ -n "${BASE_DDS:-}" ] && bridges=("$BASE_DDS" "$DDS")
    for r in $(seq 1 "$ROUNDS"); do
        for kind in idle load flood; do
            for k in "${!bridges[@]}"; do
                echo "$k $kind $(state_rate "${bridges[$k]}" $kind)" >>"$tmp/state"
            done
        done
    done
    echo "j288-dds state rate at --rate 500: joint_states samples/s a subscriber got, ${DURATION} s each,"
    echo "medians of $ROUNDS rounds (range); 4 buses x 3 servos on j288-sim, $(nproc) cores, load average before: $load_before, after: $(cut -d' ' -f1-3 /proc/loadavg)"
    python3 - "$tmp/state" "${BASE_DDS:-}" "$DDS" <<'PY'
import sys, statistics as st
rows, cpu = {}, {}
for l in open(sys.argv[1]):
    k, kind, rate, c = (l.split() + ['0'])[:4]
    rows.setdefault((int(k), kind), []).append(float(rate))
    cpu.setdefault((int(k), kind), []).append(float(c))
names = [a for a in sys.argv[2:] if a]
print('%-40s %18s %18s %18s %14s %14s' % ('bridge', 'idle', 'beside stress-ng', 'under a flood', 'stress / idle', 'flood / idle'))
for k, name in enumerate(names):
    med = {kind: st.median(rows[(k, kind)]) for kind in ('idle', 'load', 'flood')}
    cell = lambda kind: '%.0f (%.0f-%.0f)' % (med[kind], min(rows[(k, kind)]), max(rows[(k, kind)]))
    print('%-40s %18s %18s %18s %13.0f%% %13.0f%%' % (name[-40:], cell('idle'), cell('load'), cell('flood'),
          100 * med['load'] / med['idle'], 100 * med['flood'] / med['idle']))
print('the bridge\'s CPU time per cycle over its run (us, all its threads), medians:')
for k, name in enumerate(names):
    print('%-40s %18.0f %18.0f %18.0f' % (name[-40:], *(st.median(cpu[(k, kind)]) for kind in ('idle', 'load', 'flood'))))
PY
    awk '{ n += $1; t += $2 } END { if (t > 0) printf "the flooding peer wrote %.0f samples/s (%d in %.0f s)\n", n / t, n, t }' "$tmp/sent"
    if [ "${CALLGRIND:-0}" = 1 ]; then
        # what one 1.6 MB sample costs each bridge, in instructions (callgrind, every thread):
        # a run with 20 of them and one without, the per-cycle work of the quiet run taken off
        echo "instructions a 1.6 MB command sample costs the bridge (callgrind, all threads):"
        for k in "${!bridges[@]}"; do
            for kind in quiet flood; do
                valgrind --tool=callgrind --callgrind-out-file="$tmp/cg.$k.$kind" "${bridges[$k]}" \
                    --config "$tmp/robot.yaml" --domain "$DDS_DOMAIN" --rate 100 2>"$tmp/cg.err" &
                vp=$!
                for _ in $(seq 1 60); do "$PEER" states --timeout 1 >"$tmp/first" 2>/dev/null && ! grep -q nan "$tmp/first" && break; done
                if [ $kind = flood ]; then "$PEER" flood --count 20 --hz 10 >/dev/null 2>&1; else sleep 4; fi
                sleep 2
                "$PEER" diag --timeout 30 >"$tmp/cg.diag" 2>/dev/null
                kill -INT $vp; wait $vp || true
                echo "$k $kind $(sed -n 's/^j288-dds: \([0-9]*\) cycles .*/\1/p' "$tmp/cg.err") \
                    $(callgrind_annotate "$tmp/cg.$k.$kind" 2>/dev/null | awk '/PROGRAM TOTALS/ { gsub(",", "", $1); print $1; exit }') \
                    $(awk -F= '/^j288-dds: bridge\|messages=/ { m = $2 } /^j288-dds: bridge\|dropped_by_dds=/ { d = $2 } END { print m + d }' "$tmp/cg.diag")"
            done
        done >"$tmp/cg.rows"
        python3 - "$tmp/cg.rows" "${BASE_DDS:-}" "$DDS" <<'PY'
import sys
rows = {}
for l in open(sys.argv[1]):
    k, kind, cycles, total, samples = l.split()
    rows[(int(k), kind)] = (int(cycles), int(total), int(samples))
for k, name in enumerate(a for a in sys.argv[2:] if a):
    qc, qt, _ = rows[(k, 'quiet')]
    fc, ft, n = rows[(k, 'flood')]
    per = (ft - fc * qt / qc) / n if n else float('nan')
    print('%-40s %12.0f per sample (%d samples reached it; %.0f per cycle otherwise)' % (name[-40:], per, n, qt / qc))
PY
    fi
    [ "${STATE_ONLY:-0}" = 1 ] && exit 0
fi

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
python3 - "$tmp/sent" "$tmp/stamps" "$tmp/log.0" <<'PY'
import sys
sent = [(int(t), float(p)) for _, t, p in (l.split() for l in open(sys.argv[1]) if l.startswith('sent '))]
frames = [(int(t), h) for t, _, h in (l.split() for l in open(sys.argv[2]))]
# the simulator of bus leg0 decodes every frame it got: hex -> (id, status, pos)
dec = {}
for l in open(sys.argv[3]):
    f = l.split()
    if len(f) >= 8 and f[2] == 'id=1' and f[3] == 'status=1':
        dec[f[1]] = int(f[7].split('=')[1])
raws = sorted(set(dec.values()))
if len(raws) != 2:
    sys.exit('bench-dds: expected two target positions on the wire, saw %d' % len(raws))
raw_of = {0.30: raws[0], 0.35: raws[1]}   # direction 1: the larger angle, the larger count
lat, j = [], 0
for t, p in sent:
    while j < len(frames) and frames[j][0] < t:
        j += 1
    k = j
    while k < len(frames) and dec.get(frames[k][1]) != raw_of[round(p, 2)]:
        k += 1
    if k < len(frames):
        lat.append((frames[k][0] - t) / 1000.0)
lat.sort()
q = lambda f: lat[min(len(lat) - 1, int(f * len(lat)))]
print('command to wire at --rate 1000 (%d of %d commands): p50 %.0f us, p99 %.0f us, max %.0f us'
      % (len(lat), len(sent), q(0.5), q(0.99), lat[-1]))
PY
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
