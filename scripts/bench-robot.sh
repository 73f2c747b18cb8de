#!/usr/bin/env bash
# usage: [BUILD=build] [DURATION=3] [PYTHON=python3] scripts/bench-robot.sh
# Robot-scale throughput against j288-sim: cycles per second of the multi-bus runner, back to
# back (`j288 --config F log --rate 0`), for 4 buses x 3 servos (four simulators on four
# pseudo-terminals, one loop) against 1 bus x 3 servos, and the wire limit of a 3-servo bus;
# then the Python package's cost per cycle against the C loop (test/bench/robot_python.py).
# Wall-clock figures on a pseudo-terminal: they depend on the machine and its load (the
# simulators share its cores); run after `make all python`.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build}
BIN=$BUILD/bin
DURATION=${DURATION:-3}
PYTHON=${PYTHON:-python3}
# lib_sim.sh's waits use lib_e2e.sh's e2e_scaled (its scratch folder is ours, removed at exit)
. test/e2e/lib_e2e.sh
tmp=$E2E_TMP
SIM_DIR=$tmp
. test/e2e/lib_sim.sh
trap 'sim_cleanup TERM' EXIT
for f in "$BIN/j288" "$SIM"; do
    [ -x "$f" ] || { echo "bench-robot: $f missing (make first)" >&2; exit 1; }
done

rate() { # config file -> cycles/s (JSON field)
    # (exit 1 when a bus stopped answering meanwhile, which a loaded machine's starved
    # simulator can make: the rate is still the run's, and the tool has said so on stderr)
    { "$BIN/j288" --config "$1" log --rate 0 --duration "$DURATION" --json || true; } |
        sed -n 's/.*"cycles_per_s": *\([0-9.]*\).*/\1/p'
}

start_sims 4 --exit-after 300
robot_config 1 "$tmp/one.yaml" 5000 5 0.1
robot_config 4 "$tmp/four.yaml" 5000 5 0.1
one=$(rate "$tmp/one.yaml")
four=$(rate "$tmp/four.yaml")
# The wire: a 20-byte command and a 26-byte reply at 6 Mbit/s, 10 bits a byte (76.7 us), and
# the 2 us guard, per servo; buses run in parallel, so the robot's limit is one bus's.
wire=$(awk 'BEGIN { printf "%.0f", 1e6 / (3 * (46 * 10 / 6.0 + 2)) }')
echo "j288 --config F log --rate 0, ${DURATION} s each, $(nproc) cores"
printf '%-28s %10s\n' "setup" "cycles/s"
printf '%-28s %10.0f\n' "1 bus x 3 servos" "$one"
printf '%-28s %10.0f\n' "4 buses x 3 servos (robot)" "$four"
printf '%-28s %10s\n' "wire limit, 3 servos a bus" "$wire"

if "$PYTHON" -c 'import ctypes' 2>/dev/null && [ -f python/j288/libj288.so ]; then
    PYTHONPATH=python "$PYTHON" test/bench/robot_python.py "$tmp/four.yaml" "$DURATION"
else
    echo "bench-robot: python/j288/libj288.so missing (make python): no Python figures" >&2
fi
