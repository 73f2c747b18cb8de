#!/usr/bin/env bash
# usage: VALGRIND="valgrind ..." BUILD=... BIN=... scripts/test-valgrind.sh "BINARIES" "SCRIPTS"
# `make test-valgrind`: the test binaries under $VALGRIND, then the test scripts with j288 and
# j288-sim run under memcheck through test/e2e/valgrind-wrap.sh (symlinks in
# $BUILD/valgrind-e2e/bin; reports in $BUILD/valgrind-e2e/logs: any line but valgrind's notice
# about the tty ioctls it does not know, TIOCEXCL/TIOCNXCL, fails the run, the simulator's
# reports included). The golden-vector checks there take every 20th vector and joint_seed one
# seed of its three (all of them run in `make test`; under memcheck each seed repeats the same
# code paths for some 60 s).
set -uo pipefail
export TEST_TIME_SCALE=${TEST_TIME_SCALE:-4} # memcheck runs the programs some 10-50 times slower
binaries=$1 scripts=$2
TEST_WRAPPER=$VALGRIND bash scripts/run-tests.sh $binaries
rc=$?
rm -rf "$BUILD/valgrind-e2e" && mkdir -p "$BUILD/valgrind-e2e/bin" "$BUILD/valgrind-e2e/logs" || exit 1
dir=$(cd "$BUILD/valgrind-e2e" && pwd)
for p in j288 j288-sim; do ln -s "$PWD/test/e2e/valgrind-wrap.sh" "$dir/bin/$p"; done
echo "test-valgrind: the scripts with j288 and j288-sim under memcheck"
J288=$dir/bin/j288 J288_SIM=$dir/bin/j288-sim J288_VALGRIND=$(command -v valgrind) \
J288_VALGRIND_BIN=$(cd "$BIN" && pwd) J288_VALGRIND_LOGS=$dir/logs J288_E2E_VECTOR_STRIDE=20 \
J288_JOINT_SEEDS=${J288_JOINT_SEEDS:-11} \
    bash scripts/run-tests.sh $scripts || rc=1
bad=$(grep -lEv 'unhandled ioctl 0x|could cause spurious value errors|README_MISSING_SYSCALL_OR_IOCTL' \
      "$dir"/logs/* 2>/dev/null | sort)
if [ -n "$bad" ]; then
    head -n 40 $bad
    echo "test-valgrind: memcheck errors in: $bad"
    rc=1
fi
echo "test-valgrind: $(ls "$dir/logs" | wc -l) program runs checked by memcheck in the scripts"
exit $rc
