# Shared helpers for the CLI end-to-end tests (sourced, not run). Each test script counts
# its checks and ends with a Unity-style summary line ("N Tests N Failures 0 Ignored" then
# OK or FAIL), exiting non-zero when anything failed.
# shellcheck shell=bash

BIN=${BIN:-build/bin}
BUILD=${BUILD:-build}
J288=${J288:-$BIN/j288}
E2E_TESTS=0
E2E_FAILURES=0
E2E_TMP=$(mktemp -d "${TMPDIR:-/tmp}/j288-e2e.XXXXXX")
# The port's notices (a pseudo-terminal refuses low-latency mode) would be a stderr line in
# every check; the checks of the notices themselves unset it.
export J288_QUIET=1

# For an EXIT trap; a no-op in a subshell (bash runs the trap in a subshell killed by a signal).
e2e_cleanup_tmp() { [ "$BASHPID" = "$$" ] && rm -rf "$E2E_TMP"; return 0; }

E2E_NAME=$(basename "$0" .sh)
e2e_pass() { E2E_TESTS=$((E2E_TESTS + 1)); echo "$E2E_NAME:$1:PASS"; }
e2e_fail() { # name reason
    E2E_TESTS=$((E2E_TESTS + 1)); E2E_FAILURES=$((E2E_FAILURES + 1))
    echo "$E2E_NAME:$1:FAIL: $2"
}

# e2e_scaled N: N times TEST_TIME_SCALE (a whole number, default 1; README "Running the tests"),
# for every time bound and poll count, so that a slow machine or valgrind raises them all.
TEST_TIME_SCALE=${TEST_TIME_SCALE:-1}
e2e_scaled() { echo $(($1 * TEST_TIME_SCALE)); }
# Seconds of host silence that must trip a servo's 1 s watchdog: 3, so that a simulator
# starved across the trip time (it excuses its whole stall, not knowing when within it the
# next command came; stalls of up to 1.6 s were seen beside stress-ng) still sees more than 1 s.
E2E_TRIP_SILENCE=3

# "${WITHOUT_RT_RIGHTS[@]}" CMD...: CMD without the rights to real time: RLIMIT_RTPRIO and
# RLIMIT_MEMLOCK at 0 and, for root, CAP_SYS_NICE and CAP_IPC_LOCK taken away (it stays root,
# so that it opens the simulator's pseudo-terminal): SCHED_FIFO and mlockall get EPERM. Each
# program execs the next: CMD keeps the pid a background start gives ($!).
WITHOUT_RT_RIGHTS=(prlimit --rtprio=0:0 --memlock=0:0)
[ "$(id -u)" = 0 ] &&
    WITHOUT_RT_RIGHTS+=(setpriv --bounding-set=-sys_nice,-ipc_lock --inh-caps=-sys_nice,-ipc_lock)

# logged FILE NEEDLE [FROM_LINE [SECONDS]]: wait (bounded: SECONDS, default 20, scaled) until a
# line of a simulator's log FILE after line FROM_LINE (default 0) contains NEEDLE; true as soon
# as one does. A program that has exited (or sent a broadcast, which has no reply) left its
# last frames in the pseudo-terminal: the simulator reads and logs them when it next runs,
# which on a loaded machine is later. Every check of a simulator's log for a frame the program
# sent waits here, never greps at once.
logged() {
    local i
    for i in $(seq 1 "$(e2e_scaled $((${4:-20} * 20)))"); do
        tail -n +"$((${3:-0} + 1))" "$1" 2>/dev/null | grep -q -- "$2" && return 0
        sleep 0.05
    done
    return 1
}

# Run a command with a time bound (E2E_CMD_TIMEOUT seconds, default 20, scaled), capturing
# stdout, stderr and status into E2E_OUT, E2E_ERR, E2E_RC.
e2e_run() {
    timeout -k 2 "$(e2e_scaled "${E2E_CMD_TIMEOUT:-20}")" "$@" >"$E2E_TMP/out" 2>"$E2E_TMP/err"
    E2E_RC=$?
    E2E_OUT=$(cat "$E2E_TMP/out")
    E2E_ERR=$(cat "$E2E_TMP/err")
}

# expect_ok NAME EXPECTED_STDOUT CMD...: exit 0, stdout exactly EXPECTED, stderr empty.
expect_ok() {
    local name=$1 want=$2; shift 2
    e2e_run "$@"
    if [ "$E2E_RC" -ne 0 ]; then
        e2e_fail "$name" "exit $E2E_RC (stderr: $E2E_ERR)"
    elif [ "$E2E_OUT" != "$want" ]; then
        e2e_fail "$name" "stdout '$E2E_OUT', want '$want'"
    elif [ -n "$E2E_ERR" ]; then
        e2e_fail "$name" "unexpected stderr '$E2E_ERR'"
    else
        e2e_pass "$name"
    fi
}

# expect_bad NAME WANT_RC PATTERN CMD...: exits WANT_RC ("nonzero" for any non-zero), prints
# nothing on stdout and exactly one line on stderr matching the extended regex PATTERN.
expect_bad() {
    local name=$1 want_rc=$2 pattern=$3; shift 3
    e2e_run "$@"
    local lines
    lines=$(printf '%s' "$E2E_ERR" | grep -c '')
    if [ "$E2E_RC" -eq 0 ]; then
        e2e_fail "$name" "exit 0, want failure"
    elif [ "$want_rc" != nonzero ] && [ "$E2E_RC" -ne "$want_rc" ]; then
        e2e_fail "$name" "exit $E2E_RC, want $want_rc (stderr: $E2E_ERR)"
    elif [ -n "$E2E_OUT" ]; then
        e2e_fail "$name" "stdout not empty: '$E2E_OUT'"
    elif [ "$lines" -ne 1 ]; then
        e2e_fail "$name" "want exactly one stderr line, got $lines: '$E2E_ERR'"
    elif ! printf '%s' "$E2E_ERR" | grep -Eq -- "$pattern"; then
        e2e_fail "$name" "stderr '$E2E_ERR' does not match /$pattern/"
    else
        e2e_pass "$name"
    fi
}

# expect_true NAME CMD...: the command (a shell check) succeeds.
expect_true() {
    local name=$1; shift
    if "$@" >"$E2E_TMP/chk" 2>&1; then
        e2e_pass "$name"
    else
        e2e_fail "$name" "$(head -c 600 "$E2E_TMP/chk")"
    fi
}

# e2e_check NAME CMD...: one check, passing when CMD (a test function; its output goes
# through, to say why it failed) succeeds.
e2e_check() {
    local name=$1; shift
    if "$@"; then e2e_pass "$name"; else e2e_fail "$name" "$1 failed"; fi
}

e2e_summary() {
    echo
    echo "-----------------------"
    echo "$E2E_TESTS Tests $E2E_FAILURES Failures 0 Ignored"
    if [ "$E2E_FAILURES" -eq 0 ]; then echo OK; else echo FAIL; fi
    [ "$E2E_FAILURES" -eq 0 ]
}

# e2e_need_python: the JSON and golden-vector checks use python3. Without it: outside CI the
# whole script is skipped with a one-line notice (what to install), with CI=true it fails.
e2e_need_python() {
    bash scripts/need.sh python3 python3 && return 0
    [ $? -eq 1 ] && { echo "0 Tests 0 Failures 1 Ignored"; exit 0; }
    exit 1
}
