#!/usr/bin/env bash
# Run test binaries and test scripts given as arguments; each is bounded in time. Unity
# binaries report "N Tests N Failures N Ignored"; scripts report by exit status (and may print
# their own Unity-style summary). Ends with one line "N passed, N failed".
set -u
per_test_timeout=${TEST_TIMEOUT:-300}
passed=0 failed=0 failed_names=()
for t in "$@"; do
    name=${t#./}
    log=$(mktemp)
    if [[ "$t" == *.sh ]]; then
        timeout -k 5 "$per_test_timeout" bash "$t" >"$log" 2>&1
    else
        timeout -k 5 "$per_test_timeout" ${TEST_WRAPPER:-} "$t" >"$log" 2>&1
    fi
    rc=$?
    summary=$(grep -E '^[0-9]+ Tests [0-9]+ Failures [0-9]+ Ignored' "$log" | tail -n1)
    if [ $rc -eq 0 ]; then
        passed=$((passed + 1))
        echo "PASS  $name  ${summary}"
    else
        failed=$((failed + 1))
        failed_names+=("$name")
        echo "FAIL  $name  (exit $rc) ${summary}"
        grep -E ':FAIL|FAIL:|Error|error|Assert' "$log" | head -n 30 | sed 's/^/      /'
        [ $rc -eq 124 ] && echo "      timed out after ${per_test_timeout}s"
        tail -n 15 "$log" | sed 's/^/    | /'
    fi
    rm -f "$log"
done
echo
[ $failed -gt 0 ] && echo "failed: ${failed_names[*]}"
echo "$passed passed, $failed failed"
[ $failed -eq 0 ]
