#!/usr/bin/env bash
# j288-sim as a program: --help, argument errors, the pty path line, --link, --log, exit on
# SIGINT/SIGTERM and --exit-after with the statistics line, nothing left behind, and the
# fault switch (SIGUSR1 off, SIGUSR2 on) seen through the j288 tool's status command.
# Run from the repo root with BIN set (make test does); J288_SIM and J288 may name other
# binaries (make test-valgrind points them at test/e2e/valgrind-wrap.sh).
# No check depends on the machine's speed: waits poll for what they expect, bounded (10-30 s),
# and the status exchanges that must succeed use a 250 ms reply margin.
set -u
BIN=${BIN:-build/bin}
SIM=${J288_SIM:-$BIN/j288-sim}
J288=${J288:-$BIN/j288}
tmp=$(mktemp -d)
pids=()
cleanup() {
    for p in "${pids[@]}"; do kill -KILL "$p" 2>/dev/null; wait "$p" 2>/dev/null; done
    rm -rf "$tmp"
}
trap cleanup EXIT
tests=0 failures=0
check() { # name, then a command that must succeed
    local name=$1; shift
    tests=$((tests + 1))
    if "$@"; then echo "sim_cli.sh:$name:PASS"; else echo "sim_cli.sh:$name:FAIL"; failures=$((failures + 1)); fi
}

# Start the simulator in the background; sets SIM_PID, SIM_PTY (waits for the path line).
start_sim() {
    "$SIM" "$@" >"$tmp/out" 2>"$tmp/err" &
    SIM_PID=$!
    pids+=("$SIM_PID")
    SIM_PTY=
    for _ in $(seq 1 600); do # up to 30 s
        SIM_PTY=$(head -n1 "$tmp/out" 2>/dev/null)
        [ -n "$SIM_PTY" ] && break
        sleep 0.05
    done
}

# Wait up to 20 s for a pid to exit (it returns as soon as it does); returns its exit
# status, or 124 on time-out.
wait_exit() {
    for _ in $(seq 1 400); do
        if ! kill -0 "$1" 2>/dev/null; then wait "$1"; return $?; fi
        sleep 0.05
    done
    return 124
}

t_help() { "$SIM" --help | grep -q -- '--ids' && "$SIM" --help | grep -q -- '--exit-after'; }
t_bad_option() {
    "$SIM" --bogus >/dev/null 2>"$tmp/e"; local rc=$?
    [ $rc -eq 2 ] && [ "$(wc -l <"$tmp/e")" -eq 1 ] && grep -q "unknown option '--bogus'" "$tmp/e"
}
t_bad_ids() {
    "$SIM" --ids 1,15 >/dev/null 2>"$tmp/e"; [ $? -eq 2 ] && grep -q -- '--ids' "$tmp/e" || return 1
    "$SIM" --ids 1 --dup 2 >/dev/null 2>"$tmp/e"; [ $? -eq 2 ] && grep -q -- '--dup' "$tmp/e" || return 1
    "$SIM" --drop 1.5 >/dev/null 2>"$tmp/e"; [ $? -eq 2 ] && grep -q -- '--drop' "$tmp/e"
}
t_path_link_exit_after() {
    # Long enough that the link is still there when looked at on a loaded machine.
    start_sim --ids 1,2,3 --link "$tmp/bus" --exit-after 3 || return 1
    [[ "$SIM_PTY" == /dev/pts/* ]] || return 1
    [ -c "$SIM_PTY" ] && [ -L "$tmp/bus" ] && [ "$(readlink "$tmp/bus")" = "$SIM_PTY" ] || return 1
    wait_exit "$SIM_PID" || return 1
    [ ! -e "$tmp/bus" ] && grep -q '^j288-sim: stats: ' "$tmp/err"
}
t_signals() {
    local sig
    for sig in TERM INT; do
        start_sim --exit-after 120 || return 1
        [ -n "$SIM_PTY" ] || return 1
        kill -s "$sig" "$SIM_PID"
        wait_exit "$SIM_PID" || return 1
        grep -q '^j288-sim: stats: ' "$tmp/err" || return 1
    done
}
# wait_file FILE PATTERN: up to 10 s for a line of FILE to match the extended regex.
wait_file() {
    for _ in $(seq 1 200); do
        grep -Eq "$2" "$1" 2>/dev/null && return 0
        sleep 0.05
    done
    return 1
}
t_log_frames() {
    start_sim --ids 0 --log "$tmp/log" --exit-after 60 || return 1
    stty -F "$SIM_PTY" raw -echo || return 1
    # The protocol's worked lock frame for servo 0, then the same with a broken CRC; each
    # written once the simulator has logged the one before (it may be slow to read).
    printf '\xfe\xee\x80\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x1d\x99\xfb\x6e' >"$SIM_PTY"
    wait_file "$tmp/log" 'feee80000000000000000000000000001d99fb6e id=0 status=0 wd=1 ' ||
        { echo "the lock frame was not logged"; return 1; }
    printf '\xfe\xee\x80\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x1d\x99\xfb\x6f' >"$SIM_PTY"
    wait_file "$tmp/log" ' bad-crc id=0$' || { echo "the bad frame was not logged"; return 1; }
    kill -s TERM "$SIM_PID"; wait_exit "$SIM_PID" || return 1
    [ "$(grep -c '' "$tmp/log")" -eq 2 ] &&
        grep -q 'commands 1 .*bad-crc 1 ' "$tmp/err" && grep -q ' replies 1 ' "$tmp/err"
}
# wait_err PATTERN: up to 20 s for a line of the simulator's stderr to match.
wait_err() {
    for _ in $(seq 1 400); do
        grep -Eq "$1" "$tmp/err" && return 0
        sleep 0.05
    done
    return 1
}
# status_ok / status_fails: one status exchange with servo 1, no retries (status_ok with a
# 250 ms margin: a slow machine must not make a good exchange fail).
status_ok() {
    timeout 30 "$J288" --port "$SIM_PTY" status --id 1 --retries 0 --margin-us 250000 >/dev/null 2>"$tmp/st"
}
status_fails() {
    timeout 30 "$J288" --port "$SIM_PTY" status --id 1 --retries 0 >/dev/null 2>"$tmp/st"
    [ $? -eq 1 ] && grep -q 'no reply from servo 1' "$tmp/st"
}
# Every reply dropped: status times out; after SIGUSR1 it succeeds (acknowledged with the
# statistics so far); after SIGUSR2 it times out again.
t_fault_switch() {
    [ -x "$J288" ] || { echo "$J288 not built"; return 1; }
    start_sim --ids 1 --drop 1 --exit-after 120 || return 1
    status_fails || { echo "status succeeded with --drop 1"; return 1; }
    kill -s USR1 "$SIM_PID"
    wait_err '^j288-sim: faults off: stats: .* replies 0 dropped 1 ' || { echo "no ack"; return 1; }
    status_ok || { echo "status failed after SIGUSR1: $(cat "$tmp/st")"; return 1; }
    status_ok || return 1
    kill -s USR2 "$SIM_PID"
    wait_err '^j288-sim: faults on: stats: .* replies 2 dropped 1 ' || return 1
    status_fails || { echo "status succeeded after SIGUSR2"; return 1; }
    kill -s TERM "$SIM_PID"; wait_exit "$SIM_PID" || return 1
    grep -q '^j288-sim: stats: .* commands 4 .* replies 2 dropped 2 ' "$tmp/err"
}
# A reply delayed before SIGUSR1 still goes out when due (counted as sent); it does not
# disturb the clean exchanges after the switch.
t_fault_switch_late_in_flight() {
    [ -x "$J288" ] || { echo "$J288 not built"; return 1; }
    start_sim --ids 1 --late 1 --late-us 400000 --exit-after 120 || return 1
    status_fails || { echo "status succeeded with the reply 400 ms late"; return 1; }
    kill -s USR1 "$SIM_PID"
    wait_err '^j288-sim: faults off: stats: .* late 1 ' || { echo "no ack"; return 1; }
    status_ok || { echo "status failed after SIGUSR1: $(cat "$tmp/st")"; return 1; }
    sleep 0.5 # the late reply is out now
    status_ok || { echo "status failed after the late reply: $(cat "$tmp/st")"; return 1; }
    kill -s TERM "$SIM_PID"; wait_exit "$SIM_PID" || return 1
    grep -q '^j288-sim: stats: .* commands 3 .* replies 3 dropped 0 corrupted 0 late 1 ' "$tmp/err"
}
t_link_refuses_file() {
    echo keep >"$tmp/file"
    "$SIM" --link "$tmp/file" --exit-after 1 >/dev/null 2>"$tmp/e"; local rc=$?
    [ $rc -eq 2 ] && [ "$(cat "$tmp/file")" = keep ]
}

check help t_help
check bad_option t_bad_option
check bad_values t_bad_ids
check path_link_exit_after t_path_link_exit_after
check signals t_signals
check log_frames t_log_frames
check link_refuses_file t_link_refuses_file
check fault_switch t_fault_switch
check fault_switch_late_in_flight t_fault_switch_late_in_flight

echo "$tests Tests $failures Failures 0 Ignored"
[ $failures -eq 0 ]
