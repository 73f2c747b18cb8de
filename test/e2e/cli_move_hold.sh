#!/usr/bin/env bash
# How move, hold and torque leave the servo (issue 29 item 4), against j288-sim's truth under a
# constant load (--load-torque 0.5 N*m on the output shaft): `move` ends holding at its target
# with the watchdog bit 0, so the joint is still there 2 s (simulator time) after the tool has
# exited; `--then lock` releases it (the load makes it fall); `hold --then hold` keeps holding
# likewise; a signal locks whatever --then says; torque refuses --then hold.
# Run from the repo root with BIN set (make test does); helpers in test/e2e/lib_joint.sh.
set -u
. "$(dirname "$0")/lib_joint.sh"

LOAD=(--load-torque 0.5)
# sim_time: the simulator's clock (s) in the truth file just written.
sim_time() { sed -n '1s/^# j288-sim truth seq=[0-9]* t=\([0-9.]*\) .*/\1/p' "$TRUTH"; }
# after_sim_seconds S: a fresh truth at least S s of simulator time after the current one
# (bounded by the polls; a condition on the simulator's clock, not a sleep).
after_sim_seconds() {
    local t0 i
    truth_now || return 1
    t0=$(sim_time)
    for i in $(seq 1 "$(e2e_scaled 200)"); do
        sleep 0.1
        truth_now || return 1
        awk -v a="$(sim_time)" -v b="$t0" -v s="$1" 'BEGIN { exit !(a - b >= s) }' && return 0
    done
    echo "the simulator's clock did not advance $1 s"; return 1
}
# last_frame_is ID PATTERN: the last command the simulator took for servo ID matches PATTERN.
last_frame_is() { grep "id=$1 " "$SLOG" | tail -n 1 | grep -Eq "$2" || { echo "last frame for $1: $(grep "id=$1 " "$SLOG" | tail -n 1)"; return 1; }; }
# falls_from ID POS: the joint leaves POS by more than 0.2 rad (the load pulls it), bounded.
falls_from() {
    local i
    for i in $(seq 1 "$(e2e_scaled 100)"); do
        truth_now || return 1
        near "$(truth_val "$1" theta)" "$2" 0.2 >/dev/null || return 0
        sleep 0.1
    done
    echo "servo $1 stayed at $2 (theta $(truth_val "$1" theta)): not released"; return 1
}

t_move_holds() {
    local held
    start_sim mh --ids 1 --start-angle 1:0 "${LOAD[@]}" --quiet || return 1
    # The issue's command (its 3 s scaled under memcheck): ramp, hold, exit; then 2 s with no host.
    e2e_run "$J288" --port "$DEV" move --id 1 --pos 0.5 --duration "$(e2e_scaled 3)" "${M[@]}"
    [ "$E2E_RC" -eq 0 ] || { echo "move: exit $E2E_RC: $E2E_ERR"; return 1; }
    after_sim_seconds 2 || return 1
    near "$(truth_val 1 theta)" 0.5 0.05 || { echo "2 s after move exited"; return 1; }
    last_frame_is 1 'status=1 wd=0 ' || return 1
    grep -q "holding at 0.5 rad with the watchdog off: the servo keeps holding after exit" <<<"$E2E_OUT" ||
        { echo "move said: $E2E_OUT"; return 1; }
    # hold --then hold: the same after a hold of the pose it is at (hold_pos: the angle it
    # found, which the load had already pulled some tau/kp = 25 mrad below 0.5).
    e2e_run "$J288" --port "$DEV" hold --id 1 --duration 0.5 --then hold --json "${M[@]}"
    [ "$E2E_RC" -eq 0 ] || { echo "hold --then hold: exit $E2E_RC: $E2E_ERR"; return 1; }
    echo "$E2E_OUT" >"$E2E_TMP/hold.json"
    [ "$(jget "$E2E_TMP/hold.json" holding)" = True ] || { echo "hold said: $E2E_OUT"; return 1; }
    held=$(jget "$E2E_TMP/hold.json" hold_pos)
    last_frame_is 1 'status=1 wd=0 ' || return 1
    after_sim_seconds 2 || return 1
    near "$(truth_val 1 theta)" "$held" 0.05 || { echo "2 s after hold --then hold exited"; return 1; }
    # --then lock: locked at the end; the load then moves the joint away.
    e2e_run "$J288" --port "$DEV" move --id 1 --pos 0.3 --duration 2 --then lock "${M[@]}"
    [ "$E2E_RC" -eq 0 ] || { echo "move --then lock: exit $E2E_RC: $E2E_ERR"; return 1; }
    grep -q "; servo locked$" <<<"$E2E_OUT" || { echo "move --then lock said: $E2E_OUT"; return 1; }
    last_frame_is 1 'status=0 ' || return 1
    falls_from 1 0.3 || return 1
    stop_sim
}

# A signal is an abort: lock, whatever --then says (the default hold included).
t_signal_locks() {
    local pid rc i n
    start_sim ms --ids 1 --start-angle 1:0 "${LOAD[@]}" --quiet || return 1
    "$J288" --port "$DEV" move --id 1 --pos 2 --speed 0.2 --duration "$(e2e_scaled 30)" --then hold "${M[@]}" >"$E2E_TMP/sig.out" 2>"$E2E_TMP/sig.err" &
    pid=$!
    for i in $(seq 1 "$(e2e_scaled 200)"); do
        n=$(foc_frames 1 2>/dev/null)
        [ "${n:-0}" -ge 5 ] && break
        sleep 0.05
    done
    kill -TERM "$pid"
    wait_exit "$pid" "$(e2e_scaled 20)"; rc=$?
    [ "$rc" -eq 143 ] || { echo "move after SIGTERM: exit $rc: $(cat "$E2E_TMP/sig.err")"; return 1; }
    last_frame_is 1 'status=0 ' || return 1
    grep -q "servo locked" "$E2E_TMP/sig.out" || { echo "said: $(cat "$E2E_TMP/sig.out")"; return 1; }
    stop_sim
}

run_check move_ends_holding_under_load t_move_holds
run_check signal_locks_whatever_then t_signal_locks
# Refused before anything is sent (no device needed).
expect_bad torque_then_hold_refused 2 "--then hold: torque ends with lock" \
    "$J288" --port /nonexistent torque --id 1 --tau 0.1 --then hold
expect_bad keep_and_then_exclusive 2 "--keep and --then exclude each other" \
    "$J288" --port /nonexistent move --id 1 --pos 0.1 --keep --then lock
expect_bad then_bad_value 2 "--then" "$J288" --port /nonexistent move --id 1 --pos 0.1 --then float
e2e_summary
