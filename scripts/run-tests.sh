#!/usr/bin/env bash
# usage: [TEST_JOBS=N] [TEST_TIMEOUT=S] [TEST_TIME_SCALE=K] [TEST_WRAPPER=CMD] scripts/run-tests.sh TEST...
# Run test binaries and test scripts (*.sh), each bounded in time (TEST_TIMEOUT, 300 s, times
# TEST_TIME_SCALE, a whole number, default 1, which the scripts' own bounds scale with), up to
# TEST_JOBS at once (default: the number of processors), reporting in the order given with its time in seconds. Unity
# binaries report "N Tests N Failures N Ignored"; scripts report by exit status (and may print
# their own Unity-style summary). TEST_WRAPPER runs each binary (valgrind, qemu-user). Ends
# with one line "N passed, N failed".
set -u
export TEST_TIME_SCALE=${TEST_TIME_SCALE:-1}
per_test_timeout=$((${TEST_TIMEOUT:-300} * TEST_TIME_SCALE))
jobs=${TEST_JOBS:-$(nproc 2>/dev/null || echo 1)}
tests=("$@")
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

run_one() { # index test: the log in $out/i.log, its seconds in $out/i.s, the status in $out/i.rc
    local rc t0=$SECONDS
    if [[ "$2" == *.sh ]]; then
        timeout -k 5 "$per_test_timeout" bash "$2" >"$out/$1.log" 2>&1
    else
        timeout -k 5 "$per_test_timeout" ${TEST_WRAPPER:-} "$2" >"$out/$1.log" 2>&1
    fi
    rc=$?
    echo $((SECONDS - t0)) >"$out/$1.s"
    echo $rc >"$out/$1.rc.tmp" && mv "$out/$1.rc.tmp" "$out/$1.rc"
}

passed=0 failed=0 failed_names=() next=0 secs=
report_ready() { # every finished test from $next on, in order
    local name rc summary log
    while [ $next -lt ${#tests[@]} ] && [ -f "$out/$next.rc" ]; do
        name=${tests[$next]#./} rc=$(cat "$out/$next.rc") log=$out/$next.log
        secs="$(cat "$out/$next.s") s"
        summary=$(grep -E '^[0-9]+ Tests [0-9]+ Failures [0-9]+ Ignored' "$log" | tail -n1)
        if [ "$rc" -eq 0 ]; then
            passed=$((passed + 1))
            echo "PASS  $name  ($secs) ${summary}"
        else
            failed=$((failed + 1))
            failed_names+=("$name")
            echo "FAIL  $name  (exit $rc, $secs) ${summary}"
            grep -E -B4 ':FAIL|FAIL:|Error|error|Assert' "$log" | head -n 40 | sed 's/^/      /' # with the reason before
            [ "$rc" -eq 124 ] && echo "      timed out after ${per_test_timeout}s"
            tail -n 15 "$log" | sed 's/^/    | /'
        fi
        next=$((next + 1))
    done
}

for i in "${!tests[@]}"; do
    while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do
        wait -n
        report_ready
    done
    run_one "$i" "${tests[$i]}" &
done
wait
report_ready
echo
[ $failed -gt 0 ] && echo "failed: ${failed_names[*]}"
echo "$passed passed, $failed failed"
[ $failed -eq 0 ]
