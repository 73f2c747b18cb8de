#!/usr/bin/env bash
# usage: scripts/fuzz.sh NAME SECONDS DIR
# `make fuzz`: run DIR/fuzz_NAME for SECONDS over the committed seeds (test/fuzz/corpus/NAME)
# plus its own working corpus DIR/work/NAME (new inputs go there: the committed corpus stays
# small). A crash or a broken invariant fails, with the input saved under DIR/artifacts/.
set -uo pipefail
name=$1 seconds=$2 dir=$3
mkdir -p "$dir/work/$name" "$dir/artifacts"
echo "fuzz: $name for $seconds s"
"$dir/fuzz_$name" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
    -dict=test/fuzz/j288.dict -print_final_stats=1 -artifact_prefix="$dir/artifacts/$name-" \
    "$dir/work/$name" "test/fuzz/corpus/$name" >"$dir/$name.log" 2>&1
rc=$?
grep -E '^stat::number_of_executed_units|^#[0-9]+.*DONE' "$dir/$name.log" | tail -n 2
if [ $rc -ne 0 ]; then
    tail -n 40 "$dir/$name.log"
    echo "fuzz: $name FAILED"
    exit 1
fi
