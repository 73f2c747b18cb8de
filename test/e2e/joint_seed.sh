#!/usr/bin/env bash
# The joint frame end to end, per seed: the angle without configuration (the output encoder
# angle wrapped to [-pi, pi)), `move --pos X` ending at joint angle X, power cycles (the angle
# the same before and after, uncalibrated and calibrated), `calibrate` and `zero` written back
# into the robot config. Phases and start angles are drawn by the simulator from each seed
# (J288_JOINT_SEEDS, default three fixed ones, so a failure is reproducible: it names its seed).
# Run from the repo root with BIN set (make test does); helpers in test/e2e/lib_joint.sh.
set -u
. "$(dirname "$0")/lib_joint.sh"

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
        awk -v q="$q" 'BEGIN { pi = atan2(0, -1); exit !(-pi <= q && q < pi) }' ||
            { echo "seed $seed: $q not in [-pi, pi)"; return 1; }
    done
    # move --pos X ends at joint angle X (the servo's own control: a few mrad).
    target=$(python3 -c 'import random, sys; random.seed(int(sys.argv[1])); print(round(random.uniform(-2.5, 2.5), 4))' "$seed")
    e2e_run "$J288" --port "$DEV" move --id 1 --pos "$target" --speed 4 --duration "$(e2e_scaled 10)" "${ARRIVE[@]}" --watchdog off --json "${M[@]}"
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
    # Calibrated: the rotor's resolution, and the same across a power cycle (once the joint
    # has come to rest after the calibration's motion: on a loaded machine it still moved).
    wait_settled 1 || return 1
    status_joint hip "$cfg" || { echo "seed $seed: $(cat "$E2E_TMP/st.err")"; return 1; }
    [ "$(jget "$E2E_TMP/st.json" joint_calibrated)" = True ] || { cat "$E2E_TMP/st.json"; return 1; }
    before=$(jget "$E2E_TMP/st.json" joint_pos)
    truth_now || return 1
    near "$before" "$(truth_val 1 theta)" 0.0001 || { echo "seed $seed: calibrated vs truth"; return 1; }
    kill -s PWR "$SIM_PID"
    sleep 0.05
    for _ in $(seq 1 "$(e2e_scaled 400)"); do [ "$(grep -c 'reason=power-on$' "$TRUTH")" -ge 1 ] && [ "$(truth_val 1 cycles)" = 2 ] && break; sleep 0.05; done
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

SEEDS=${J288_JOINT_SEEDS:-"11 12 13"}
for s in $SEEDS; do
    run_check "seed_$s" t_seed "$s"
done
e2e_summary
