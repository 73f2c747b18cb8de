#!/usr/bin/env bash
# usage: BIN=... BUILD=... test/bench/bus_bench.sh
# `make bench-bus`: the bus timing model, and instructions per transaction (callgrind).
set -euo pipefail
bin=${BIN:-build/bin}/bus_timing
turn=${ENGINE_BENCH_TURNAROUND:-0 10 20 50}
out=${BUILD:-build}/bench-bus
mkdir -p "$out"

echo "### Sweep time against wire time (virtual clock, 6 Mbps 8N1, guard 2 us)"
echo
"$bin" --turnaround "$turn"
echo
echo "### The same with the reply handed over one character time late (idle-line DMA)"
echo
"$bin" --turnaround "10" --rx-latency 1667

echo
bash scripts/need.sh valgrind valgrind || exit $(($? == 1 ? 0 : 1)) # the instruction counts
# Collected only inside the library's entry points (fake_port_deliver: the port's events;
# bench_poll/bench_start: the application's calls). Two run lengths, the difference divided by
# the difference in transactions, so set-up costs cancel.
count() { # count MODE N -> "transactions Ir_total Ir_in_fake_port"
    local f="$out/callgrind.$1.$2"
    valgrind --tool=callgrind --callgrind-out-file="$f" --toggle-collect=fake_port_deliver \
        --toggle-collect=bench_poll --toggle-collect=bench_start \
        "$bin" --count "$2" $([ "$1" = poll ] && echo --poll) >"$f.txt" 2>/dev/null
    local n ir fake
    n=$(awk '/transactions/ {print $1}' "$f.txt")
    ir=$(awk '/^summary:/ {print $2}' "$f")
    # self cost of the fake port's own functions (its ops, called from inside the library)
    fake=$(callgrind_annotate --threshold=100 "$f" 2>/dev/null |
        awk '/fake_port\.c:/ { gsub(",", "", $1); s += $1 } END { print s + 0 }')
    echo "$n $ir $fake"
}
echo "### Host instructions per transaction (x86-64, callgrind, 15 servos, continuous sweeps)"
echo
echo "| bus advanced | Ir per transaction, library | with the fake port's ops |"
echo "|---|---:|---:|"
# (The frame CRC is inlined where frames are built and checked: no separate CRC column.)
for mode in isr poll; do
    read -r n1 i1 f1 < <(count "$mode" 3000)
    read -r n2 i2 f2 < <(count "$mode" 6000)
    awk -v n1="$n1" -v i1="$i1" -v f1="$f1" -v n2="$n2" -v i2="$i2" -v f2="$f2" -v m="$mode" \
        'BEGIN { d = n2 - n1; printf "| %s | %.0f | %.0f |\n",
                 (m == "isr" ? "in the event calls (advance_in_isr)" : "by poll after each event"),
                 ((i2 - f2) - (i1 - f1)) / d, (i2 - i1) / d }'
done
