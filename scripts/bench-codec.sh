#!/usr/bin/env bash
# usage: scripts/bench-codec.sh BENCH N LABEL
# `make bench-codec`: host instructions per call of each codec hot path, counted by valgrind's
# callgrind over N calls of test/bench/codec_bench, less its empty run ("none").
set -euo pipefail
bench=$1 n=$2 label=$3
ir() { valgrind --tool=callgrind --callgrind-out-file=/dev/null "$bench" "$1" "$n" 2>&1 |
       sed -n 's/.*Collected : *//p'; }
base=$(ir none)
echo "instructions per call ($n calls each, $label):"
for m in crc-table crc-nibble crc-bitwise cmd-encode reply-decode parse-chunk parse-bytes cmd-from-si; do
    t=$(ir "$m")
    echo "  $m: $(( (t - base) / n ))"
done
