#!/usr/bin/env bash
# usage: scripts/test-loop.sh [RUNS [LOAD]]   (make test-loop N=10 LOAD=2)
# `make test` RUNS times in a row (default 10), with `stress-ng --cpu LOAD` beside it when LOAD
# is above 0 (Debian's stress-ng): the suite's claim that it passes on a busy machine, checked.
# Prints each run's verdict and wall time, then the runs passed, the wall times (min, median,
# max) and the slowest tests (their longest time over the runs). Logs: $BUILD/test-loop/.
set -u
runs=${1:-10} load=${2:-0} dir=${BUILD:-build}/test-loop
mkdir -p "$dir"
rm -f "$dir"/run-*.log
if [ "$load" -gt 0 ]; then
    command -v stress-ng >/dev/null || { echo "test-loop: LOAD needs stress-ng (apt-get install stress-ng)"; exit 2; }
    stress-ng --cpu "$load" --quiet &
    stress=$!
    trap 'kill "$stress" 2>/dev/null; wait "$stress" 2>/dev/null' EXIT
fi
passed=0 walls=()
for i in $(seq 1 "$runs"); do
    t0=$(date +%s)
    make --no-print-directory test >"$dir/run-$i.log" 2>&1 && ok=PASS || ok=FAIL
    walls+=($(($(date +%s) - t0)))
    [ "$ok" = PASS ] && passed=$((passed + 1))
    echo "run $i: $ok  ${walls[-1]} s  $(grep -h '^failed: ' "$dir/run-$i.log")"
done
sorted=($(printf '%s\n' "${walls[@]}" | sort -n))
echo "$passed of $runs runs passed (stress-ng --cpu $load); wall s: min ${sorted[0]}," \
    "median ${sorted[$((runs / 2))]}, max ${sorted[-1]}"
echo "slowest tests (longest run, s):"
sed -nE 's/^(PASS|FAIL)  (\S+)  \((exit [0-9]+, )?([0-9]+) s\).*/\4 \2/p' "$dir"/run-*.log |
    sort -k2,2 -k1,1nr | sort -u -k2,2 | sort -nr | head -n 8 | sed 's/^/  /'
[ "$passed" -eq "$runs" ]
