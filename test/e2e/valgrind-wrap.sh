#!/bin/bash
# Runs a j288 program under valgrind memcheck, for `make test-valgrind`. That rule makes
# symlinks to this script named after the programs (j288, j288-sim) and points the e2e
# scripts at them (J288=..., J288_SIM=...); each call runs $J288_VALGRIND_BIN/<name> with the
# same arguments in the same process (exec: the PID, signals and exit status pass through).
# A memcheck error or a leak makes the exit status 97 and writes a report to
# $J288_VALGRIND_LOGS/<name>.<pid>.log (empty when clean); the rule fails on any non-empty
# report, which also covers programs whose exit status a test does not look at (the
# simulator). Needs no PATH (a test runs `env PATH=/nonexistent "$J288" ...`).
set -u
name=${0##*/}
: "${J288_VALGRIND_BIN:?set by make test-valgrind}" "${J288_VALGRIND_LOGS:?set by make test-valgrind}"
exec "${J288_VALGRIND:-/usr/bin/valgrind}" -q --error-exitcode=97 --leak-check=full \
    --show-leak-kinds=definite,indirect,possible --errors-for-leak-kinds=definite,indirect,possible \
    --log-file="$J288_VALGRIND_LOGS/$name.%p.log" "$J288_VALGRIND_BIN/$name" "$@"
