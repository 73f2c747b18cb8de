#!/usr/bin/env bash
# j288.exe (the CLI cross-built for Windows) under Wine against j288-sim, checked against the
# simulator's truth: scan, status --json, move (where the servo really ended), log --csv,
# Ctrl-C during a move (every driven servo locked, exit 130), a robot config with two buses,
# what is Linux-only (zero/calibrate writing the config back, top, jog) refused with the reason,
# $J288_BAUD (for --port and for a config's buses), and 6 Mbps refused with a clear error
# (Wine leaves a pseudo-terminal at 38400 above 4 Mbps). COM11 and COM12 (names above COM9 take the \\.\ form) are the prefix's
# dosdevices symlinks to the simulators' ptys.
# Run by scripts/windows-test.sh (WINEPREFIX set, a wineserver running; it stops it) as
#   test/e2e/windows_cli.sh J288_EXE
# Correctness only: replies get a 250 ms margin, waits are bounded, nothing is timed.
set -u
cd "$(dirname "$0")/../.."
EXE=$1
. test/e2e/lib_e2e.sh
e2e_need_python
SIM_DIR=$E2E_TMP
. test/e2e/lib_sim.sh
trap 'sim_cleanup TERM; rm -f "$WINEPREFIX"/dosdevices/com1[12]' EXIT
E2E_CMD_TIMEOUT=60
M=(--margin-us 250000 --retries 1)
export J288_BAUD=4000000

# sim NAME COMn [sim options...]: a simulator on COMn, its truth in NAME.truth (TRUTH).
sim() {
    local name=$1 com=$2; shift 2
    TRUTH=$E2E_TMP/$name.truth
    sim_start_linked "$name" --ids 1,2,3 --quiet --exit-after 240 --truth "$TRUTH" "$@" || return 1
    ln -sfn "$DEV" "$WINEPREFIX/dosdevices/$com"
}
j288() { e2e_run wine "$EXE" "$@"; E2E_OUT=${E2E_OUT//$'\r'/}; E2E_ERR=${E2E_ERR//$'\r'/}; }
jval() { python3 -c 'import json, sys; print(json.loads(sys.argv[1])[sys.argv[2]])' "$1" "$2"; }

sim a com11 || exit 1
SIM_A=$SIM_PID TRUTH_A=$TRUTH LOG_A=$E2E_TMP/a.log
sim b com12 --seed 7 || exit 1

t_6mbps_refused() {
    J288_BAUD= j288 --port COM11 scan
    [ "$E2E_RC" -eq 1 ] && [[ "$E2E_ERR" == *"cannot do 6000000 baud (it reports 38400)"* ]] ||
        { echo "exit $E2E_RC: $E2E_ERR"; return 1; }
    J288_BAUD=fast j288 --port COM11 scan
    [ "$E2E_RC" -eq 2 ] && [[ "$E2E_ERR" == *'$J288_BAUD'* ]] || { echo "exit $E2E_RC: $E2E_ERR"; return 1; }
}
t_scan() {
    j288 --port COM11 scan "${M[@]}"
    [ "$E2E_RC" -eq 0 ] || { echo "exit $E2E_RC: $E2E_ERR"; return 1; }
    [ "$(printf '%s\n' "$E2E_OUT" | grep -cE '^[123] +lock ')" -eq 3 ] &&
        [[ "$E2E_OUT" == *"3 servos answered on COM11"* ]] || { echo "$E2E_OUT"; return 1; }
}
t_status_json() {
    j288 --port COM11 status --id 2 --json "${M[@]}"
    [ "$E2E_RC" -eq 0 ] || { echo "exit $E2E_RC: $E2E_ERR"; return 1; }
    [ "$(jval "$E2E_OUT" id)" = 2 ] && [ "$(jval "$E2E_OUT" joint_known)" = True ] || return 1
    SIM_PID=$SIM_A TRUTH=$TRUTH_A
    truth_now || return 1
    near "$(jval "$E2E_OUT" joint_pos)" "$(truth_val 2 theta)" 0.0004 "$TWO_PI"
}
t_move_reaches_target() {
    # --watchdog off: a loaded machine stalling Wine for a second would trip it (exit 1); the
    # check is where the servo ends, through Wine's serial path.
    j288 --port COM11 move --id 1 --pos 1.2345 --speed 4 --duration 2.5 --watchdog off --then lock --json "${M[@]}"
    [ "$E2E_RC" -eq 0 ] || { echo "exit $E2E_RC: $E2E_ERR"; return 1; }
    SIM_PID=$SIM_A TRUTH=$TRUTH_A
    truth_now || return 1
    near "$(truth_val 1 theta)" 1.2345 0.005 "$TWO_PI" || return 1
    logged "$LOG_A" ' id=1 status=0 wd=0' # locked at the end
}
t_log_csv() {
    local csv=$E2E_TMP/log.csv
    j288 --port COM11 log --id 1,2,3 --rate 100 --duration 1 --csv "$(winepath -w "$csv")" "${M[@]}"
    [ "$E2E_RC" -eq 0 ] || { echo "exit $E2E_RC: $E2E_ERR"; return 1; }
    head -n1 "$csv" | grep -q '^time_s,' || { head -n2 "$csv"; return 1; }
    local id
    for id in 1 2 3; do
        [ "$(tr -d '\r' <"$csv" | awk -F, -v id="$id" 'NR > 1 && $2 == id' | wc -l)" -ge 5 ] ||
            { echo "servo $id: too few rows"; head -n3 "$csv"; return 1; }
    done
}
t_ctrl_c_locks() {
    local pid rc
    : >"$LOG_A"
    timeout -k 5 60 wine "$EXE" --port COM11 move --id 3 --pos 2.5 --speed 0.2 --duration 30 \
        --watchdog off "${M[@]}" >"$E2E_TMP/cc.out" 2>&1 &
    pid=$!
    logged "$LOG_A" ' id=3 status=1' || { echo "never moved"; kill -KILL "$pid"; return 1; }
    kill -INT "$pid" # timeout hands it to wine, which raises CTRL_C_EVENT in the program
    wait_exit "$pid"; rc=$?
    [ $rc -eq 130 ] || { echo "exit $rc: $(cat "$E2E_TMP/cc.out")"; return 1; }
    [ "$(tail -n1 "$LOG_A" | grep -c ' id=3 status=0 ')" -eq 1 ] || { tail -n2 "$LOG_A"; return 1; }
}
t_robot_two_buses() {
    local cfg=$E2E_TMP/robot.yaml
    { echo "buses:"
      echo "  - {name: left, port: COM11, baud: 4000000, margin_us: 250000}"
      echo "  - {name: right, port: COM12, baud: 4000000, margin_us: 250000}"
      echo "joints:"
      for j in 1 2 3; do echo "  - {name: left_$j, bus: left, id: $j, kp: 2, kd: 0.05}"; done
      for j in 1 2 3; do echo "  - {name: right_$j, bus: right, id: $j, kp: 2, kd: 0.05}"; done
    } >"$cfg"
    j288 --config "$(winepath -w "$cfg")" status
    [ "$E2E_RC" -eq 0 ] || { echo "exit $E2E_RC: $E2E_ERR"; return 1; }
    [ "$(printf '%s\n' "$E2E_OUT" | grep -c ' known ')" -eq 6 ] &&
        printf '%s\n' "$E2E_OUT" | grep -q '^right_3 ' || { echo "$E2E_OUT"; return 1; }
    j288 --config "$(winepath -w "$cfg")" log --rate 100 --duration 0.5 --json
    [ "$E2E_RC" -eq 0 ] && [[ "$E2E_OUT" == *'"joints": 6, "buses": 2'* ]] ||
        { echo "exit $E2E_RC: $E2E_OUT $E2E_ERR"; return 1; }
    # Writing a config back is POSIX-only: refused with the reason, before anything is sent.
    : >"$LOG_A"
    j288 zero --joint left_1 --config "$(winepath -w "$cfg")"
    [ "$E2E_RC" -ne 0 ] && [[ "$E2E_ERR" == *"not available on Windows"* ]] && [ ! -s "$LOG_A" ] ||
        { echo "zero: exit $E2E_RC: $E2E_ERR"; return 1; }
    j288 top --once --config "$(winepath -w "$cfg")"
    [ "$E2E_RC" -eq 2 ] && [[ "$E2E_ERR" == *"not available on Windows"* ]] ||
        { echo "top: exit $E2E_RC: $E2E_ERR"; return 1; }
    # The same port twice under two names is refused before anything is opened.
    sed 's/port: COM12/port: \\\\.\\com11/' "$cfg" >"$E2E_TMP/twice.yaml"
    j288 --config "$(winepath -w "$E2E_TMP/twice.yaml")" status
    [ "$E2E_RC" -eq 1 ] && [[ "$E2E_ERR" == *"same device"* ]] || { echo "exit $E2E_RC: $E2E_ERR"; return 1; }
}

t_config_takes_env_baud() {
    # A config whose buses give no baud takes $J288_BAUD (4000000 here, Wine's most), as --port
    # does (2af1ea0 opened them at 6000000: "cannot do 6000000 baud"); jog says it is POSIX-only.
    local cfg=$E2E_TMP/nobaud.yaml
    printf 'buses:\n  - {name: left, port: COM11, margin_us: 250000}\njoints:\n  - {name: hip, id: 1}\n' >"$cfg"
    j288 --config "$(winepath -w "$cfg")" status
    [ "$E2E_RC" -eq 0 ] && [[ "$E2E_OUT" == *"hip "*" known "* ]] || { echo "exit $E2E_RC: $E2E_OUT $E2E_ERR"; return 1; }
    j288 jog --config "$(winepath -w "$cfg")"
    [ "$E2E_RC" -eq 2 ] && [[ "$E2E_ERR" == *"not available on Windows"* ]] || { echo "jog: exit $E2E_RC: $E2E_ERR"; return 1; }
}

e2e_check 6mbps_refused_clearly t_6mbps_refused
e2e_check config_takes_env_baud t_config_takes_env_baud
e2e_check scan t_scan
e2e_check status_json_against_truth t_status_json
e2e_check move_reaches_target t_move_reaches_target
e2e_check log_csv t_log_csv
e2e_check ctrl_c_locks_the_servo t_ctrl_c_locks
e2e_check robot_config_two_buses t_robot_two_buses
e2e_summary
