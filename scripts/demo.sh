#!/usr/bin/env bash
# usage: [BUILD=build] [BIN=$BUILD/bin] scripts/demo.sh
# `make demo`: the j288 tool against the built-in servo simulator, no hardware needed.
# Starts j288-sim with servos 1, 2, 3 on a pseudo-terminal, scans the bus, reads servo 1's
# absolute joint angle (status --json: joint_pos), moves the three
# servos through a 2-second swing at 1 kHz while logging (achieved loop rate, tracking error
# and bus statistics are printed), writes the CSV (and a PNG when gnuplot is installed) under
# $BUILD/demo/, then stops the simulator. Every step is bounded in time; the simulator is
# stopped on any exit, so nothing is left running.
set -euo pipefail
BUILD=${BUILD:-build}
BIN=${BIN:-$BUILD/bin}
J288=$BIN/j288
SIM=$BIN/j288-sim
OUT=$BUILD/demo
DEV=$OUT/bus
SIM_PID=

stop_sim() {
    if [ -n "$SIM_PID" ]; then
        kill -TERM "$SIM_PID" 2>/dev/null || true
        wait "$SIM_PID" 2>/dev/null || true
        SIM_PID=
    fi
}
trap stop_sim EXIT
trap 'exit 130' INT TERM

for f in "$J288" "$SIM"; do
    [ -x "$f" ] || { echo "demo: $f is missing (run make first)" >&2; exit 1; }
done
mkdir -p "$OUT"
rm -f "$OUT/log.csv" "$OUT/log.png"

run() { # show the command as a user would type it (without the timeout), then run it
    local line="$*"
    echo
    echo "\$ ${line#timeout -k 2 * }"
    "$@"
}

echo "== starting the simulator: servos 1, 2, 3 on a pseudo-terminal"
# --exit-after is a backstop only: the trap stops it as soon as the demo ends.
# Start angles inside [-pi, pi - 0.5]: the swing below stays inside the joints' default range.
timeout -k 2 90 "$SIM" --ids 1,2,3 --start-angle 1:-0.8 --start-angle 2:0.3 --start-angle 3:1.9 \
    --link "$DEV" --exit-after 80 \
    >"$OUT/sim.out" 2>"$OUT/sim.err" &
SIM_PID=$!
for _ in $(seq 1 100); do
    [ -L "$DEV" ] && [ -s "$OUT/sim.out" ] && break
    sleep 0.05
done
[ -L "$DEV" ] || { echo "demo: the simulator did not start: $(cat "$OUT/sim.err")" >&2; exit 1; }
echo "simulator on $(head -n 1 "$OUT/sim.out"), linked as $DEV"

run timeout -k 2 20 "$J288" --port "$DEV" scan

# The absolute joint angle (the output encoder's, wrapped to [-pi, pi), without a config).
run timeout -k 2 20 "$J288" --port "$DEV" status --id 1 --json

# A 2-second swing of 0.5 rad (joint frame) and back, at 1 kHz over the three servos.
run timeout -k 2 30 "$J288" --port "$DEV" log --id 1,2,3 --rate 1000 --duration 2 \
    --swing 0.5 --kp 100 --kd 5.7 --csv "$OUT/log.csv"

set +e
run timeout -k 2 30 "$J288" plot "$OUT/log.csv" --png "$OUT/log.png"
rc=$?
set -e
# Exit 3: gnuplot is not installed; j288 has said so in one line, and the demo goes on.
if [ $rc -ne 0 ] && [ $rc -ne 3 ]; then
    exit $rc
fi

stop_sim
echo
echo "== simulator stopped: $(tail -n 1 "$OUT/sim.err")"
echo "== results in $OUT/: log.csv$( [ -s "$OUT/log.png" ] && echo ", log.png")"
echo "Next: point j288 at a real adapter, e.g. j288 --port /dev/ttyUSB0 scan (see README)."
