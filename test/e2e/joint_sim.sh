#!/usr/bin/env bash
# The joint frame end to end: the j288 tool against j288-sim, checked against the simulator's
# --truth file (the true output angle theta and rotor phase c of every servo). Phases and
# start angles are drawn by the simulator from each seed (J288_JOINT_SEEDS, default three
# fixed ones, so a failure is reproducible: it names its seed). Covered: the angle without
# configuration (the output encoder angle wrapped to [-pi, pi)), `move --pos X` ending at
# joint angle X, power cycles (the angle the same before and after, uncalibrated and
# calibrated), `calibrate` and `zero` written back into the robot config, ranges across the
# output encoder's wrap in both directions (and direction -1), limits refused with nothing
# sent, a joint just beyond its limits brought back (far beyond: refused), fault bit 12
# (output encoder), and a wrong phase reported as a mismatch.
# Run from the repo root with BIN set (make test does). Every process is bounded by timeout
# and killed by the EXIT trap; waits poll, bounded; no check depends on the machine's speed
# (a move is given ample time, and the checks are on where it ended).
set -u
cd "$(dirname "$0")/../.."
. test/e2e/lib_e2e.sh
e2e_need_python
SIM_DIR=$E2E_TMP
. test/e2e/lib_sim.sh
SEEDS=${J288_JOINT_SEEDS:-"11 12 13"}
M=(--margin-us 250000 --retries 1)
E2E_CMD_TIMEOUT=60

trap 'sim_cleanup TERM' EXIT
trap 'exit 130' INT TERM
need_built "$J288" "$SIM"

# start_sim NAME [sim options...]: a simulator on $E2E_TMP/NAME.pty, logging frames to
# NAME.log and its truth to NAME.truth; sets SIM_PID, DEV, TRUTH and SLOG. No SIM_WRAP (no
# timeout wrapper): the signals (SIGWINCH, SIGPWR) must reach the simulator itself.
start_sim() {
    TRUTH=$E2E_TMP/$1.truth
    SLOG=$E2E_TMP/$1.log
    sim_start_linked "$1" --exit-after 300 --truth "$TRUTH" "${@:2}"
}

# wait_settled ID: up to 20 s for servo ID's true angle to stop changing.
wait_settled() {
    local prev= cur i
    for i in $(seq 1 100); do
        truth_now || return 1
        cur=$(truth_val "$1" theta)
        [ -n "$prev" ] && near "$cur" "$prev" 0.000001 >/dev/null && return 0
        prev=$cur
        sleep 0.2
    done
    echo "servo $1 did not come to rest"; return 1
}
# wait_power_on: the truth file says the power cycle is over.
wait_power_on() {
    local i
    for i in $(seq 1 400); do
        grep -q 'reason=power-on$' "$TRUTH" && return 0
        sleep 0.05
    done
    echo "no power-on"; return 1
}
# jget FILE KEY: a top-level JSON value (empty when absent).
jget() { python3 -c 'import json,sys; o=json.load(open(sys.argv[1])); v=o.get(sys.argv[2]); print("" if v is None else v)' "$1" "$2"; }
# status_json ID [more options]: status --json into $E2E_TMP/st.json.
status_json() {
    local id=$1; shift
    timeout -k 2 60 "$J288" --port "$DEV" status --id "$id" --json "${M[@]}" "$@" >"$E2E_TMP/st.json" 2>"$E2E_TMP/st.err"
}
status_joint() { # NAME CONFIG: status --joint NAME --config CONFIG (the port from the file)
    timeout -k 2 60 "$J288" status --joint "$1" --config "$2" --json "${M[@]}" >"$E2E_TMP/st.json" 2>"$E2E_TMP/st.err" ||
        { echo "status --joint $1: exit $?: $(cat "$E2E_TMP/st.err")"; return 1; }
}
move_joint() { # NAME CONFIG MOVE-OPTIONS...: move --joint NAME --config CONFIG, quiet unless it fails
    local name=$1 cfg=$2; shift 2
    timeout -k 2 60 "$J288" move --joint "$name" --config "$cfg" "${M[@]}" "$@" >/dev/null 2>"$E2E_TMP/mv.err" ||
        { echo "move --joint $name $*: exit $?: $(cat "$E2E_TMP/mv.err")"; return 1; }
}
foc_frames() { grep -c "id=$1 status=1 " "$SLOG"; }
# config NAME BODY...: a robot config on this simulator's bus with one joint (BODY lines).
config() {
    local f=$E2E_TMP/$1.yaml; shift
    { echo "# robot for the joint tests"
      echo "buses:"
      echo "  - name: main            # the simulator"
      echo "    port: $DEV"
      echo "    margin_us: 250000"
      echo "joints:"
      local l; for l in "$@"; do echo "$l"; done; } >"$f"
    echo "$f"
}

# ---- per seed: no configuration, move, power cycle, calibrate, zero -------------------------
t_seed() {
    local seed=$1 id theta target q before after cfg phase c zero
    start_sim "s$seed" --ids 1,2,3 --seed "$seed" --quiet --power-off-ms 150 || return 1
    # Without configuration: the output encoder angle wrapped to [-pi, pi), within half a count.
    truth_now || return 1
    for id in 1 2 3; do
        status_json "$id" || { echo "status $id: $(cat "$E2E_TMP/st.err")"; return 1; }
        [ "$(jget "$E2E_TMP/st.json" joint_known)" = True ] || { cat "$E2E_TMP/st.json"; return 1; }
        q=$(jget "$E2E_TMP/st.json" joint_pos)
        theta=$(truth_val "$id" theta)
        near "$q" "$theta" 0.0004 "$TWO_PI" || { echo "seed $seed id $id: status"; return 1; }
        python3 -c 'import sys, math; q = float(sys.argv[1]); sys.exit(not (-math.pi <= q < math.pi))' "$q" ||
            { echo "seed $seed: $q not in [-pi, pi)"; return 1; }
    done
    # move --pos X ends at joint angle X (the servo's own control: a few mrad).
    target=$(python3 -c 'import random, sys; random.seed(int(sys.argv[1])); print(round(random.uniform(-2.5, 2.5), 4))' "$seed")
    e2e_run "$J288" --port "$DEV" move --id 1 --pos "$target" --speed 4 --duration 2.5 --json "${M[@]}"
    [ "$E2E_RC" -eq 0 ] || { echo "seed $seed: move: $E2E_ERR"; return 1; }
    truth_now || return 1
    near "$(truth_val 1 theta)" "$target" 0.005 "$TWO_PI" || { echo "seed $seed: move to $target ended off"; return 1; }
    # A power cycle: the same angle before and after (uncalibrated: within one count).
    status_json 1 || return 1
    before=$(jget "$E2E_TMP/st.json" joint_pos)
    kill -s PWR "$SIM_PID"
    wait_power_on || return 1
    status_json 1 || { echo "seed $seed: status after power-on: $(cat "$E2E_TMP/st.err")"; return 1; }
    after=$(jget "$E2E_TMP/st.json" joint_pos)
    near "$before" "$after" 0.0008 || { echo "seed $seed: power cycle, uncalibrated"; return 1; }
    truth_now || return 1
    near "$after" "$(truth_val 1 theta)" 0.0004 "$TWO_PI" || { echo "seed $seed: after power cycle"; return 1; }
    # calibrate writes the phase; it is the simulator's c (labelled in [-pi, pi)).
    cfg=$(config "c$seed" "  - name: hip             # servo 1" "    id: 1" "    limits: [-3, 3]") || return 1
    e2e_run "$J288" calibrate --joint hip --config "$cfg" --json
    [ "$E2E_RC" -eq 0 ] || { echo "seed $seed: calibrate: $E2E_ERR"; return 1; }
    phase=$(sed -n 's/^    phase: //p' "$cfg")
    c=$(truth_val 1 c)
    near "$phase" "$c" 0.02 "$TWO_PI" || { echo "seed $seed: phase $phase vs c $c"; return 1; }
    grep -q '^  - name: hip             # servo 1$' "$cfg" || { echo "comment lost"; return 1; }
    # Calibrated: the rotor's resolution, and the same across a power cycle.
    status_joint hip "$cfg" || { echo "seed $seed: $(cat "$E2E_TMP/st.err")"; return 1; }
    [ "$(jget "$E2E_TMP/st.json" joint_calibrated)" = True ] || { cat "$E2E_TMP/st.json"; return 1; }
    before=$(jget "$E2E_TMP/st.json" joint_pos)
    truth_now || return 1
    near "$before" "$(truth_val 1 theta)" 0.0001 || { echo "seed $seed: calibrated vs truth"; return 1; }
    kill -s PWR "$SIM_PID"
    sleep 0.05
    for _ in $(seq 1 400); do [ "$(grep -c 'reason=power-on$' "$TRUTH")" -ge 1 ] && [ "$(truth_val 1 cycles)" = 2 ] && break; sleep 0.05; done
    truth_now || return 1
    [ "$(truth_val 1 cycles)" = 2 ] && [ "$(truth_val 1 powered)" = 1 ] || { echo "second power cycle"; return 1; }
    status_joint hip "$cfg" || return 1
    after=$(jget "$E2E_TMP/st.json" joint_pos)
    near "$before" "$after" 0.00005 || { echo "seed $seed: power cycle, calibrated"; return 1; }
    # zero writes the pose as joint angle 0.
    e2e_run "$J288" zero --joint hip --config "$cfg" --json
    [ "$E2E_RC" -eq 0 ] || { echo "seed $seed: zero: $E2E_ERR"; return 1; }
    zero=$(sed -n 's/^    zero: //p' "$cfg")
    truth_now || return 1
    near "$zero" "$(truth_val 1 theta)" 0.0001 || { echo "seed $seed: zero $zero"; return 1; }
    status_joint hip "$cfg" || return 1
    near "$(jget "$E2E_TMP/st.json" joint_pos)" 0 0.0001 || { echo "seed $seed: after zero"; return 1; }
    stop_sim
}

# ---- ranges across the output encoder's wrap -------------------------------------------------
# Limits [-0.5, 0.5] around theta = 0 (OutPos 8191 | 0): down across the wrap and up again.
t_wrap_around_zero() {
    local cfg
    start_sim wrap0 --ids 1 --start-angle 1:0.01 --quiet || return 1
    cfg=$(config w0 "  - name: j" "    id: 1" "    limits: [-0.5, 0.5]")
    status_joint j "$cfg" || return 1
    near "$(jget "$E2E_TMP/st.json" joint_pos)" 0.01 0.0004 || return 1
    move_joint j "$cfg" --pos -0.03 --speed 1 --duration 1 || return 1
    truth_now && near "$(truth_val 1 theta)" -0.03 0.005 || return 1
    status_joint j "$cfg" && near "$(jget "$E2E_TMP/st.json" joint_pos)" -0.03 0.005 || return 1
    move_joint j "$cfg" --pos 0.03 --speed 1 --duration 1 || return 1
    truth_now && near "$(truth_val 1 theta)" 0.03 0.005 || return 1
    stop_sim
}
# Limits [5.8, 6.8]: a joint at theta 0.3 reads 6.58, not 0.3; a move to 6.2 crosses the wrap.
t_wrap_high_range() {
    local cfg
    start_sim wrap1 --ids 1 --start-angle 1:0.3 --quiet || return 1
    cfg=$(config w1 "  - name: j" "    id: 1" "    limits: [5.8, 6.8]")
    status_joint j "$cfg" || return 1
    near "$(jget "$E2E_TMP/st.json" joint_pos)" "$(python3 -c 'import math; print(0.3 + 2 * math.pi)')" 0.0004 || return 1
    move_joint j "$cfg" --pos 6.2 --speed 1 --duration 1.5 || return 1
    truth_now && near "$(truth_val 1 theta)" "$(python3 -c 'import math; print(6.2 - 2 * math.pi)')" 0.005 || return 1
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
    move_joint j "$cfg" --pos 0.2 --speed 1 --duration 1 || return 1
    truth_now && near "$(truth_val 1 theta)" -0.1 0.005 || return 1
    stop_sim
}

# A power cycle while hold drives the joint: the rotor restarts inside [0, 2 pi) (here some 45
# turns from where it was), the joint sees its angle lost, locks the servo and fails.
t_power_cycle_while_driving() {
    local pid i rc
    start_sim drive --ids 1 --start-angle 1:0 --power-off-ms 100 --quiet || return 1
    "$J288" --port "$DEV" move --id 1 --pos 1.0 --speed 4 --duration 1 "${M[@]}" >/dev/null || return 1
    timeout -k 2 60 "$J288" --port "$DEV" hold --id 1 --duration 30 "${M[@]}" >"$E2E_TMP/hold.out" 2>"$E2E_TMP/hold.err" &
    pid=$!
    for i in $(seq 1 400); do [ "$(foc_frames 1)" -gt 400 ] && break; sleep 0.05; done # the move's, then hold's
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
    status_json 1 && truth_now && near "$(jget "$E2E_TMP/st.json" joint_pos)" "$(truth_val 1 theta)" 0.0004 || return 1
    stop_sim
}

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
    timeout -k 2 60 "$J288" log --joint j --config "$cfg" --hold --rate 50 --duration 0.2 "${M[@]}" >"$E2E_TMP/lh.out" 2>&1 ||
        { echo "log --hold beyond the limit: $(cat "$E2E_TMP/lh.out")"; return 1; }
    # calibrate from there: the motion starts at the limit and stays inside.
    timeout -k 2 60 "$J288" calibrate --joint j --config "$cfg" "${M[@]}" >"$E2E_TMP/cal.out" 2>&1 ||
        { echo "calibrate at the limit: $(cat "$E2E_TMP/cal.out")"; return 1; }
    grep -q '^    phase: ' "$cfg" || { echo "no phase written: $(cat "$cfg")"; return 1; }
    move_joint j "$cfg" --pos 0.1 --speed 1 --duration 1 || return 1
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
    wrong=$(python3 -c 'import sys; print(float(sys.argv[1]) + 2.0)' "$c")
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
    e2e_run "$J288" scan --config "$cfg" --margin-us 50000
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
    e2e_run "$J288" --port "$DEV" calibrate --id 1 --range 0.04 --speed 0.04 "${M[@]}"
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

# Each check runs in this shell (the expect_bad inside count themselves); its own messages go
# to a file and become the failure's reason.
run_check() { # NAME FUNCTION ARGS...
    local name=$1; shift
    if "$@" >"$E2E_TMP/check.out" 2>&1; then
        grep -E '^joint_sim:' "$E2E_TMP/check.out"
        e2e_pass "$name"
    else
        grep -E '^joint_sim:' "$E2E_TMP/check.out"
        e2e_fail "$name" "$(grep -Ev '^joint_sim:' "$E2E_TMP/check.out" | head -c 1500)"
    fi
}
for s in $SEEDS; do
    run_check "seed_$s" t_seed "$s"
done
for t in t_wrap_around_zero t_wrap_high_range t_direction t_power_cycle_while_driving t_limits t_beyond_limit t_encoder_fault t_wrong_phase t_config_errors; do
    run_check "${t#t_}" "$t"
done
e2e_summary
