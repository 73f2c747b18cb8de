#!/usr/bin/env bash
# The joint frame's refusals end to end: limits refused with nothing sent, a joint just beyond
# its limits brought back (far beyond: refused), fault bit 12 (output encoder), a wrong phase
# reported as a mismatch, and the robot config's errors on the command line.
# Run from the repo root with BIN set (make test does); helpers in test/e2e/lib_joint.sh.
set -u
. "$(dirname "$0")/lib_joint.sh"

# ---- refusals: nothing is sent ---------------------------------------------------------------
t_limits() {
    local cfg frames
    start_sim lim --ids 1 --start-angle 1:0.2 --quiet || return 1
    cfg=$(config l "  - name: j" "    id: 1" "    limits: [-0.5, 0.5]" "    max_torque: 1.0" "    max_speed: 2.0")
    frames=$(wc -l <"$SLOG")
    expect_bad limits_pos_refused 2 "^j288 move: joint j: --pos 0.8: target position outside the joint's limits \[-0.5, 0.5\]; nothing sent$" \
        "$J288" move --joint j --config "$cfg" --pos 0.8
    expect_bad limits_default_range 2 "target position outside the joint's limits \[-3.14159, 3.14159\]" \
        "$J288" --port "$DEV" move --id 1 --pos 4
    expect_bad limits_torque_refused 2 "target torque beyond the joint's limit \(1 N\*m\)" \
        "$J288" torque --joint j --config "$cfg" --tau 1.5
    expect_bad limits_speed_refused 2 "target speed beyond the joint's limit \(2 rad/s\)" \
        "$J288" move --joint j --config "$cfg" --pos 0.3 --speed 3
    [ "$(wc -l <"$SLOG")" = "$frames" ] || { echo "frames were sent"; return 1; }
    stop_sim
}
# A joint just beyond its limits (a zero taken at a hard stop, a load that pushed it out) can be
# moved and held back inside: the ramp starts at the nearest limit. Far beyond, move refuses
# and sends no FOC frame.
t_beyond_limit() {
    local cfg
    start_sim beyond --ids 1 --start-angle 1:0.2 --quiet || return 1
    cfg=$(config b "  - name: j" "    id: 1" "    zero: 0.202" "    limits: [0.0, 0.5]")
    status_joint j "$cfg" || return 1
    [ "$(jget "$E2E_TMP/st.json" beyond_limit)" = True ] || { cat "$E2E_TMP/st.json"; return 1; }
    timeout -k 2 "$CMD_TIMEOUT" "$J288" log --joint j --config "$cfg" --hold --rate 50 --duration 0.2 "${M[@]}" >"$E2E_TMP/lh.out" 2>&1 ||
        { echo "log --hold beyond the limit: $(cat "$E2E_TMP/lh.out")"; return 1; }
    # calibrate from there: the motion starts at the limit and stays inside.
    timeout -k 2 "$CMD_TIMEOUT" "$J288" calibrate --joint j --config "$cfg" "${M[@]}" >"$E2E_TMP/cal.out" 2>&1 ||
        { echo "calibrate at the limit: $(cat "$E2E_TMP/cal.out")"; return 1; }
    grep -q '^    phase: ' "$cfg" || { echo "no phase written: $(cat "$cfg")"; return 1; }
    move_joint j "$cfg" --pos 0.1 --speed 1 --duration "$(e2e_scaled 10)" || return 1
    truth_now && near "$(truth_val 1 theta)" 0.302 0.005 || return 1
    cfg=$(config b2 "  - name: j" "    id: 1" "    zero: 0.5" "    limits: [0.0, 0.5]")
    expect_bad beyond_limit_far_refused 2 "^j288 move: joint j: at -0.19[0-9]* rad, 0.19[0-9]* rad outside its limits \\[0, 0.5\\] \\(more than 0.05\\): move it inside by hand or with --side output; servo locked$" \
        "$J288" move --joint j --config "$cfg" --pos 0.1 "${M[@]}"
    [ "$(foc_frames 1)" -gt 0 ] || { echo "the first move sent no FOC frame"; return 1; }
    local before; before=$(foc_frames 1)
    expect_bad beyond_limit_far_hold_refused 2 "outside its limits" "$J288" hold --joint j --config "$cfg" --duration 0.2 "${M[@]}"
    [ "$(foc_frames 1)" = "$before" ] || { echo "a FOC frame was sent"; return 1; }
    stop_sim
}
t_encoder_fault() {
    start_sim fault --ids 1 --fault 1:0x1000 --quiet || return 1
    status_json 1 || { cat "$E2E_TMP/st.err"; return 1; }
    [ "$(jget "$E2E_TMP/st.json" joint_known)" = False ] && [ "$(jget "$E2E_TMP/st.json" encoder_fault)" = True ] &&
        [ -z "$(jget "$E2E_TMP/st.json" joint_pos)" ] || { cat "$E2E_TMP/st.json"; return 1; }
    grep -q 'note: servo 1: output encoder fault (fault bit 12)' "$E2E_TMP/st.err" || { cat "$E2E_TMP/st.err"; return 1; }
    expect_bad encoder_fault_move_refused 1 '^j288 move: servo 1: output encoder fault \(fault bit 12\): the joint angle is unknown$' \
        "$J288" --port "$DEV" move --id 1 --pos 0 "${M[@]}"
    [ "$(foc_frames 1)" = 0 ] || { echo "a FOC frame was sent"; return 1; }
    stop_sim
}
t_wrong_phase() {
    local cfg c wrong
    start_sim phase --ids 1 --phase 1:1.0 --start-angle 1:0.4 --quiet || return 1
    c=$(truth_val 1 c)
    wrong=$(calc "$c + 2.0")
    cfg=$(config p "  - name: j" "    id: 1" "    phase: $wrong")
    status_joint j "$cfg" || { cat "$E2E_TMP/st.err"; return 1; }
    [ "$(jget "$E2E_TMP/st.json" joint_known)" = False ] && [ "$(jget "$E2E_TMP/st.json" cal_mismatch)" = True ] ||
        { cat "$E2E_TMP/st.json"; return 1; }
    grep -q 'calibrated phase disagrees with the output encoder' "$E2E_TMP/st.err" || { cat "$E2E_TMP/st.err"; return 1; }
    expect_bad wrong_phase_move_refused 1 '^j288 move: joint j: calibrated phase disagrees with the output encoder: ' \
        "$J288" move --joint j --config "$cfg" --pos 0.5
    [ "$(foc_frames 1)" = 0 ] || { echo "a FOC frame was sent"; return 1; }
    # The right phase (the truth's) is taken.
    cfg=$(config p2 "  - name: j" "    id: 1" "    phase: $c")
    status_joint j "$cfg" && [ "$(jget "$E2E_TMP/st.json" joint_calibrated)" = True ] &&
        near "$(jget "$E2E_TMP/st.json" joint_pos)" 0.4 0.00001 || { cat "$E2E_TMP/st.json"; return 1; }
    stop_sim
}

# ---- the config on the command line -----------------------------------------------------------
t_config_errors() {
    local cfg bad
    start_sim cfg --ids 1 --quiet || return 1
    cfg=$(config e "  - name: j" "    id: 1")
    expect_bad joint_unknown 2 "^j288 status: .*e.yaml: no joint named 'k'$" "$J288" status --joint k --config "$cfg"
    expect_bad joint_needs_config 2 '^j288 status: --joint j needs --config FILE' "$J288" --port "$DEV" status --joint j
    expect_bad id_and_joint 2 'exclude each other' "$J288" status --joint j --id 1 --config "$cfg"
    bad=$E2E_TMP/bad.yaml
    printf 'joints:\n  - name: j\n    id: 1\n    limits: [1, 0]\n' >"$bad"
    expect_bad config_bad_line 2 "^j288 move: $bad:4: " "$J288" --port "$DEV" move --config "$bad" --joint j --pos 0
    # --id with --config takes the file's joint for that id (its limits apply).
    printf 'joints:\n  - name: j\n    id: 1\n    limits: [-0.1, 0.1]\n' >"$E2E_TMP/id.yaml"
    expect_bad config_by_id 2 'limits \[-0.1, 0.1\]' "$J288" --port "$DEV" move --config "$E2E_TMP/id.yaml" --id 1 --pos 0.5
    # scan and stop take the port from the file, stop the servo from the joint's name.
    # (id 1 alone at a 1 s margin: a loaded machine starved the simulator past 50 ms, and
    # scan has no retry; the default range would cost a margin for each of 14 absent ids)
    e2e_run "$J288" scan --config "$cfg" --ids 1 --margin-us 1000000
    [ "$E2E_RC" -eq 0 ] && grep -q '^1 servo answered on ' <<<"$E2E_OUT" || { echo "scan: $E2E_OUT $E2E_ERR"; return 1; }
    expect_ok stop_by_joint 'servo 1 locked (mode lock)' "$J288" stop --joint j --config "$cfg"
    # Two buses use id 1: --id needs --port to say which (or --joint); the file's port is used.
    printf 'buses:\n  - {name: a, port: %s}\n  - {name: b, port: /nonexistent/j288}\njoints:\n  - {name: ja, bus: a, id: 1, limits: [-0.1, 0.1]}\n  - {name: jb, bus: b, id: 1}\n' "$DEV" >"$E2E_TMP/two.yaml"
    expect_bad config_id_two_buses 2 'id 1 is used on 2 buses: name the joint with --joint or the bus with --port' \
        "$J288" status --config "$E2E_TMP/two.yaml" --id 1
    expect_bad config_id_by_port 2 'joint ja: --pos 0.5: .*\[-0.1, 0.1\]' \
        "$J288" --port "$DEV" move --config "$E2E_TMP/two.yaml" --id 1 --pos 0.5
    status_joint ja "$E2E_TMP/two.yaml" || return 1
    # Without a config joint, zero and calibrate print the value.
    e2e_run "$J288" --port "$DEV" zero --id 1 "${M[@]}"
    [ "$E2E_RC" -eq 0 ] && grep -q "^servo 1: zero -\?[0-9.]* rad (put 'zero: " <<<"$E2E_OUT" || { echo "zero: $E2E_OUT $E2E_ERR"; return 1; }
    # (the default motion: a 0.04 rad one left too few samples for the fit on a loaded machine)
    e2e_run "$J288" --port "$DEV" calibrate --id 1 "${M[@]}"
    [ "$E2E_RC" -eq 0 ] && grep -q "^put 'phase: " <<<"$E2E_OUT" || { echo "calibrate: $E2E_OUT $E2E_ERR"; return 1; }
    # A relative port is the config file's folder's, wherever the tool runs.
    mkdir -p "$E2E_TMP/robot" && ln -sf "$DEV" "$E2E_TMP/robot/bus0"
    printf 'buses:\n  - {name: a, port: bus0, margin_us: 250000}\njoints:\n  - {name: j, id: 1}\n' >"$E2E_TMP/robot/robot.yaml"
    status_joint j "$E2E_TMP/robot/robot.yaml" || return 1
    # A read-only config: zero and calibrate refuse before sending anything (root too).
    local frames
    cp "$cfg" "$E2E_TMP/ro.yaml" && chmod 444 "$E2E_TMP/ro.yaml"
    frames=$(grep -c 'id=1 ' "$SLOG")
    expect_bad zero_read_only 1 "^j288 zero: $E2E_TMP/ro.yaml: read-only: .*; nothing was sent\$" \
        "$J288" zero --joint j --config "$E2E_TMP/ro.yaml"
    expect_bad calibrate_read_only 1 "^j288 calibrate: $E2E_TMP/ro.yaml: read-only: " \
        "$J288" calibrate --joint j --config "$E2E_TMP/ro.yaml"
    [ "$(grep -c 'id=1 ' "$SLOG")" = "$frames" ] || { echo "frames sent to a read-only config's joint"; return 1; }
    stop_sim
}

for t in t_limits t_beyond_limit t_encoder_fault t_wrong_phase t_config_errors; do
    run_check "${t#t_}" "$t"
done
e2e_summary
