#!/usr/bin/env bash
# usage: [BUILD=build] [PYTHON=python3] tools/vectors/check-drift.sh
# The committed golden vectors (test/vectors/) must equal what the generator produces now:
# regenerate into $BUILD/vectors-fresh and compare file by file. Run from the repository root.
set -euo pipefail
build=${BUILD:-build}
python=${PYTHON:-python3}
# python3 is not on every fresh machine: outside CI skip with a notice, in CI fail.
bash scripts/need.sh "$python" python3 || { [ $? -eq 1 ] && { echo "0 Tests 0 Failures 1 Ignored"; exit 0; }; exit 1; }
fresh="$build/vectors-fresh"
rm -rf "$fresh"
mkdir -p "$fresh"
"$python" tools/vectors/gen_vectors.py --out "$fresh"
status=0 n=0 bad=0
for f in "$fresh"/*; do
    n=$((n + 1))
    name=$(basename "$f")
    if ! cmp -s "$f" "test/vectors/$name"; then
        echo "FAIL: test/vectors/$name differs from a fresh regeneration (run: make vectors)"
        diff -u "test/vectors/$name" "$f" | head -n 20 || true
        status=1 bad=$((bad + 1))
    fi
done
for f in test/vectors/*; do
    case "$f" in *.md) continue ;; esac
    [ -e "$fresh/$(basename "$f")" ] || { echo "FAIL: $f is not produced by the generator"; status=1; }
done
[ $status -eq 0 ] && echo "vectors: committed files equal a fresh regeneration"
echo "$n Tests $bad Failures 0 Ignored"
exit $status
