#!/usr/bin/env bash
# usage: [BUILD=build] scripts/lint.sh [--update]
# `make lint`: static analysis of lib/.
#  1. cppcheck --std=c99 with the MISRA C:2012 addon (+ warning/style/performance/portability).
#     Rules the library deliberately departs from everywhere are suppressed here with the
#     reason in docs/misra.md. Every other finding is counted per (file, check id), with no
#     line numbers so that edits elsewhere do not disturb it, and compared with the committed
#     baseline scripts/lint/cppcheck-baseline.txt: a count above its baseline (or a new key)
#     fails. Counts below it print a reminder to ratchet the baseline down (--update).
#  2. clang-tidy with the repository's .clang-tidy; any warning fails.
# --update rewrites the baseline from the current tree.
set -uo pipefail
cd "$(dirname "$0")/.."
build=${BUILD:-build}
baseline=scripts/lint/cppcheck-baseline.txt
update=${1:-}
out=$build/lint
mkdir -p "$out/cppcheck-cache"

for tool in cppcheck clang-tidy; do
    bash scripts/need.sh $tool $tool || exit $(($? == 1 ? 0 : 1))
done

# Deviations kept library-wide (docs/misra.md says why): advisory rules only.
deviations=(misra-c2012-2.4 misra-c2012-2.5 misra-c2012-8.7 misra-c2012-15.5)
supp=()
for d in "${deviations[@]}"; do supp+=("--suppress=$d"); done

status=0
cppcheck --std=c99 --addon=misra --enable=warning,style,performance,portability \
    --inline-suppr --error-exitcode=0 -q -Ilib/include "${supp[@]}" \
    --cppcheck-build-dir="$out/cppcheck-cache" \
    --template='{file}:{line}:{id}:{severity}:{message}' lib/src 2>"$out/cppcheck.txt"
# Keys: "file id" with counts.
grep -E '^[^:]+:[0-9]+:' "$out/cppcheck.txt" | awk -F: '{print $1, $3}' | sort | uniq -c |
    awk '{print $2, $3, $1}' > "$out/cppcheck-counts.txt"

if [ "$update" = --update ]; then
    {
        echo "# cppcheck findings accepted in lib/ (file, check id, count); see docs/misra.md."
        echo "# Regenerate only for a reviewed reason: scripts/lint.sh --update"
        cat "$out/cppcheck-counts.txt"
    } > "$baseline"
    echo "lint: baseline rewritten ($(grep -vc '^#' "$baseline") keys)"
fi

new=0
while read -r file id count; do
    allowed=$(awk -v f="$file" -v i="$id" '$1 == f && $2 == i {print $3}' "$baseline" 2>/dev/null)
    allowed=${allowed:-0}
    if [ "$count" -gt "$allowed" ]; then
        echo "lint: NEW cppcheck finding(s): $file $id ($count, baseline $allowed):"
        grep -F "$file:" "$out/cppcheck.txt" | grep -F ":$id:" | sed 's/^/    /'
        new=1
    elif [ "$count" -lt "$allowed" ]; then
        echo "lint: note: $file $id down to $count from $allowed: ratchet with scripts/lint.sh --update"
    fi
done < "$out/cppcheck-counts.txt"
# Keys in the baseline that vanished entirely are also worth a ratchet.
grep -v '^#' "$baseline" 2>/dev/null | while read -r file id count; do
    grep -q "^$file $id " "$out/cppcheck-counts.txt" ||
        echo "lint: note: $file $id gone (baseline $count): ratchet with scripts/lint.sh --update"
done
total=$(awk '{s += $3} END {print s + 0}' "$out/cppcheck-counts.txt")
if [ $new -ne 0 ]; then
    status=1
    echo "lint: cppcheck FAILED: fix the new findings, or deviate with a reason in docs/misra.md"
else
    echo "lint: cppcheck ok ($total baselined findings, deviations: ${deviations[*]})"
fi

if clang-tidy -quiet lib/src/*.c -- -std=c99 -Ilib/include >"$out/clang-tidy.txt" 2>&1 &&
    ! grep -qE '(warning|error):' "$out/clang-tidy.txt"; then
    echo "lint: clang-tidy ok"
else
    grep -E '(warning|error):' -A3 "$out/clang-tidy.txt" | head -n 60
    echo "lint: clang-tidy FAILED"
    status=1
fi
exit $status
