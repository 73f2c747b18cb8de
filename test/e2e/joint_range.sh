#!/usr/bin/env bash
# The joint frame end to end across the output encoder's wrap in both directions, with
# direction -1, and a power cycle while hold drives the joint.
# Run from the repo root with BIN set (make test does); helpers in test/e2e/lib_joint.sh.
set -u
. "$(dirname "$0")/lib_joint.sh"

# ---- ranges across the output encoder's wrap -------------------------------------------------
# Limits [-0.5, 0.5] around theta = 0 (OutPos 8191 | 0): down across the wrap and up again.
t_wrap_around_zero() {
    local cfg
    start_sim wrap0 --ids 1 --start-angle 1:0.01 --quiet || return 1
    cfg=$(config w0 "  - name: j" "    id: 1" "    limits: [-0.5, 0.5]")
    status_joint j "$cfg" || return 1
    near "$(jget "$E2E_TMP/st.json" joint_pos)" 0.01 0.0004 || return 1
    move_joint j "$cfg" --pos -0.03 --speed 1 --duration "$(e2e_scaled 10)" || return 1
    truth_now && near "$(truth_val 1 theta)" -0.03 0.005 || return 1
    status_joint j "$cfg" && near "$(jget "$E2E_TMP/st.json" joint_pos)" -0.03 0.005 || return 1
    move_joint j "$cfg" --pos 0.03 --speed 1 --duration "$(e2e_scaled 10)" || return 1
    truth_now && near "$(truth_val 1 theta)" 0.03 0.005 || return 1
    stop_sim
}
# Limits [5.8, 6.8]: a joint at theta 0.3 reads 6.58, not 0.3; a move to 6.2 crosses the wrap.
t_wrap_high_range() {
    local cfg
    start_sim wrap1 --ids 1 --start-angle 1:0.3 --quiet || return 1
    cfg=$(config w1 "  - name: j" "    id: 1" "    limits: [5.8, 6.8]")
    status_joint j "$cfg" || return 1
    near "$(jget "$E2E_TMP/st.json" joint_pos)" "$(calc '0.3 + 2 * atan2(0, -1)')" 0.0004 || return 1
    move_joint j "$cfg" --pos 6.2 --speed 1 --duration "$(e2e_scaled 10)" || return 1
    truth_now && near "$(truth_val 1 theta)" "$(calc '6.2 - 2 * atan2(0, -1)')" 0.005 || return 1
    status_joint j "$cfg" && near "$(jget "$E2E_TMP/st.json" joint_pos)" 6.2 0.005 || return 1
    # log: the CSV in the joint frame; a swing leaving the limits is refused before it starts.
    "$J288" log --config "$cfg" --joint j --rate 50 --duration 0.2 --csv "$E2E_TMP/w1.csv" "${M[@]}" >/dev/null || return 1
    python3 -c '
import csv, sys
rows = [r for r in csv.DictReader(open(sys.argv[1])) if r["ok"] == "1"]
assert rows and all(abs(float(r["pos_rad"]) - 6.2) < 0.005 for r in rows), rows[:3]' "$E2E_TMP/w1.csv" || return 1
    expect_bad log_swing_refused 2 "^j288 log: joint j: --swing to [0-9.]*: target position outside the joint's limits \[5.8, 6.8\]" \
        "$J288" log --config "$cfg" --id 1 --swing 1 --duration 1 "${M[@]}"
    stop_sim
}
# direction -1, zero 0.1: q = -(theta - 0.1).
t_direction() {
    local cfg
    start_sim dir --ids 1 --start-angle 1:0.05 --quiet || return 1
    cfg=$(config d "  - name: j" "    id: 1" "    direction: -1" "    zero: 0.1" "    limits: [-0.5, 0.5]")
    status_joint j "$cfg" && near "$(jget "$E2E_TMP/st.json" joint_pos)" 0.05 0.0004 || return 1
    move_joint j "$cfg" --pos 0.2 --speed 1 --duration "$(e2e_scaled 10)" || return 1
    truth_now && near "$(truth_val 1 theta)" -0.1 0.005 || return 1
    stop_sim
}

# A power cycle while hold drives the joint: the rotor restarts inside [0, 2 pi) (here some 45
# turns from where it was), the joint sees its angle lost, locks the servo and fails.
t_power_cycle_while_driving() {
    local pid i rc n0
    start_sim drive --ids 1 --start-angle 1:0 --power-off-ms 100 --quiet || return 1
    # (--duration bounds the move, which ends once settled: 1 s cut it short on a loaded machine;
    # the watchdog off, as move_joint's: a positioning move, on a machine that may starve it)
    "$J288" --port "$DEV" move --id 1 --pos 1.0 --speed 4 --duration "$(e2e_scaled 10)" "${ARRIVE[@]}" --watchdog off "${M[@]}" >/dev/null ||
        { echo "move to 1.0 failed"; return 1; }
    n0=$(foc_frames 1) # the move's: hold's own 200 are waited for (not a total, which a
    # slower move once reached alone, so that the power cycle came before hold drove)
    timeout -k 2 "$CMD_TIMEOUT" "$J288" --port "$DEV" hold --id 1 --duration 30 "${M[@]}" >"$E2E_TMP/hold.out" 2>"$E2E_TMP/hold.err" &
    pid=$!
    for i in $(seq 1 "$(e2e_scaled 400)"); do [ "$(foc_frames 1)" -gt $((n0 + 200)) ] && break; sleep 0.05; done
    kill -s PWR "$SIM_PID"
    wait "$pid"; rc=$?
    [ "$rc" = 1 ] || { echo "hold exit $rc: $(cat "$E2E_TMP/hold.err")"; return 1; }
    grep -q '^j288 hold: servo 1: the joint angle was lost .*; lock sent$' "$E2E_TMP/hold.err" ||
        { echo "hold: $(cat "$E2E_TMP/hold.err")"; return 1; }
    [ ! -s "$E2E_TMP/hold.out" ] || { echo "stdout: $(cat "$E2E_TMP/hold.out")"; return 1; }
    grep 'id=1 ' "$SLOG" | tail -n 1 | grep -q 'status=0' || { echo "last frame not a lock"; return 1; }
    # And the angle is found again, right, after the power cycle (once the joint, locked while
    # the stale command moved it, has come to rest).
    wait_settled 1 || return 1
    status_json 1 && truth_now && near "$(jget "$E2E_TMP/st.json" joint_pos)" "$(truth_val 1 theta)" 0.0004 6.283185307179586 ||
        { echo "after the power cycle: $(cat "$E2E_TMP/st.json" "$E2E_TMP/st.err" 2>/dev/null)"; return 1; }
    stop_sim
}

for t in t_wrap_around_zero t_wrap_high_range t_direction t_power_cycle_while_driving; do
    run_check "${t#t_}" "$t"
done
e2e_summary
