#!/usr/bin/env bash
# End-to-end tests of the `j288` bus commands against the simulator (j288-sim on a pty):
# every command on a healthy bus, the safe stop on SIGINT/SIGTERM (the simulator's --log must
# show the lock frames), a port already in use, a device that vanishes (the simulator exits),
# a missing device and a silent bus; injected faults are in cli_bus_faults.sh. Every process
# started here is bounded by timeout and killed by the EXIT trap.
set -u
cd "$(dirname "$0")/../.."
. test/e2e/lib_cli_bus.sh

# ---------------------------------------------------------------------------------------------
start_sim main --ids 1,2,3 --fault 3:0x200 || exit 1
MAIN=$DEV MAIN_LOG=$E2E_TMP/main.log MAIN_PID=$SIM_PID

e2e_run "$J288" --port "$MAIN" scan "${MSCAN[@]}"
if [ $E2E_RC -eq 0 ] && grep -Eq '^1 +lock' <<<"$E2E_OUT" && grep -Eq '^2 ' <<<"$E2E_OUT" &&
    grep -Eq '^3 .*winding over-temperature' <<<"$E2E_OUT" && grep -q '3 servos answered' <<<"$E2E_OUT"; then
    e2e_pass scan_human
else
    e2e_fail scan_human "rc $E2E_RC out '$E2E_OUT' err '$E2E_ERR' (the simulator logged $(log_lines "$MAIN_LOG") frames)"
fi
# --ids: ids 0 and 4 asked (absent), nothing beyond them (a starved simulator logs late)
only_ids_0_to_4_asked() {
    grep -q 'id=0 ' "$MAIN_LOG" && wait_for_log "$MAIN_LOG" 'id=4 ' &&
        ! grep -Eq 'id=([5-9]|1[0-4]) ' "$MAIN_LOG"
}
expect_true scan_ids_addressed only_ids_0_to_4_asked
expect_bad scan_ids_bad 2 '--ids' "$J288" --port "$MAIN" scan --ids 1,15

e2e_run "$J288" scan --port "$MAIN" --json "${MSCAN[@]}"
expect_true scan_json_tool bash -c "printf '%s' '$E2E_OUT' | python3 -m json.tool >/dev/null"
json_check scan_json '
assert isinstance(o, list) and [s["id"] for s in o] == [1, 2, 3], o
for s in o:
    for k in ("id", "mode", "case_temp_c", "voltage_v", "faults"):
        assert k in s, (k, s)
assert o[2]["faults"] == 0x200 and o[0]["faults"] == 0, o
assert o[0]["voltage_v"] == 24.0, o[0]'

# status: the same keys as `decode --json` of a reply.
e2e_run "$J288" decode --json fcee132429300005d7ff5f14000000000000e803000049c23bee
DECODE_KEYS=$(printf '%s' "$E2E_OUT" | python3 -c 'import json,sys; print(" ".join(sorted(json.load(sys.stdin))))')
e2e_run "$J288" --port "$MAIN" status --id 3 --json "${M[@]}"
json_check status_json "
want = set('$DECODE_KEYS'.split())
assert want <= set(o), sorted(want - set(o))
assert o['id'] == 3 and o['frame'] == 'reply' and o['faults'] == 0x200, o
assert 'winding over-temperature' in o['fault_names'], o['fault_names']"
e2e_run "$J288" --port "$MAIN" status --id 2 "${M[@]}"
if [ $E2E_RC -eq 0 ] && grep -q 'servo 2 on' <<<"$E2E_OUT" && grep -Eq 'voltage +48 \(24.0 V\)' <<<"$E2E_OUT"; then
    e2e_pass status_human
else
    e2e_fail status_human "rc $E2E_RC out '$E2E_OUT' err '$E2E_ERR'"
fi
expect_bad status_absent_servo 1 'no reply from servo 9' "$J288" --port "$MAIN" status --id 9
expect_bad status_missing_id 2 '--id N or --joint NAME is required' "$J288" --port "$MAIN" status
expect_bad status_bad_id 2 '--id: 15 is out of range 0..14' "$J288" --port "$MAIN" status --id 15
expect_bad status_unknown_option 2 "unknown option '--ids'" "$J288" --port "$MAIN" status --ids 1
expect_bad status_bad_margin 2 '--margin-us' "$J288" --port "$MAIN" status --id 1 --margin-us 0

# stop: addressed (confirmed) and broadcast; the simulator sees the lock frames.
: >"$MAIN_LOG.mark"
expect_ok stop_one "servo 1 locked (mode lock)" "$J288" --port "$MAIN" stop --id 1 "${M[@]}"
expect_ok stop_all "lock broadcast to every servo on $MAIN" "$J288" --port "$MAIN" stop
expect_true stop_frames_seen wait_for_log "$MAIN_LOG" 'id=15 status=0'

# hold / move / torque with a duration: FOC frames with the watchdog on, then a lock.
e2e_run "$J288" --port "$MAIN" hold --id 1 --duration 0.3 --rate 200 "${M[@]}"
if [ $E2E_RC -eq 0 ] && grep -q 'servo locked' <<<"$E2E_OUT"; then e2e_pass hold_runs; else
    e2e_fail hold_runs "rc $E2E_RC out '$E2E_OUT' err '$E2E_ERR'"; fi
expect_true hold_sends_foc_with_watchdog grep -Eq 'id=1 status=1 wd=1 .*kp=[1-9]' "$MAIN_LOG"
expect_true hold_ends_with_lock bash -c "grep 'id=1 ' '$MAIN_LOG' | tail -n 1 | grep -q 'status=0'"

# The output side keeps its old meaning: rotor / N, counted from where the rotor started at
# power-up (so first, while servo 2 is near there).
# (--duration bounds the move; --arrive ends it once settled: 10 s would be 2000 commands)
e2e_run "$J288" --port "$MAIN" move --id 2 --side output --pos 0.2 --speed 1 --duration "$(e2e_scaled 10)" --arrive 0.01 --json "${M[@]}"
json_check move_output_side '
assert o["ended"] == "done" and o["side"] == "output", o
pos = o["last_reply"]["output"]["pos_rad"]
assert abs(pos - o["target_pos"]) < 0.02, (pos, o["target_pos"])
assert abs(o["target_pos"] - 0.2) < 1e-3, o
assert o["commands"] < 1000, o["commands"]'
# The joint frame (the default): the move ends at joint angle 0.2 wherever the servo started,
# and holds there (--then hold, the default: one last hold with the watchdog bit 0).
e2e_run "$J288" --port "$MAIN" move --id 2 --pos 0.2 --speed 5 --duration "$(e2e_scaled 10)" --arrive 0.01 --json "${M[@]}"
json_check move_reaches_target '
assert o["ended"] == "done" and o["locked"] is False and o["side"] == "joint", o
assert o["holding"] is True and abs(o["hold_pos"] - 0.2) < 1e-9, o
assert o["joint_known"] is True, o
assert abs(o["joint_pos"] - 0.2) < 0.02, o["joint_pos"]
assert abs(o["target_pos"] - 0.2) < 1e-9, o
# A healthy servo and the long margin: a failed refresh is a fault (one is tolerated, for a
# machine frozen longer than the margin).
assert o["commands"] >= 1 and o["replies"] + o["failures"] == o["commands"], o
assert o["failures"] <= max(1, o["commands"] // 20), o'
expect_true move_ends_holding bash -c "grep 'id=2 ' '$MAIN_LOG' | tail -n 1 | grep -q 'status=1 wd=0 '"
# --arrive not met by --duration: the ramp is there, the servo is not (kp 1 against the
# simulator's friction leaves some 50 mrad): cut short, said so, exit 1; --then lock locks.
e2e_run "$J288" --port "$MAIN" move --id 2 --pos 0.3 --speed 5 --kp 1 --arrive 0.001 --duration 0.5 --then lock "${M[@]}"
if [ $E2E_RC -eq 1 ] && grep -q '^cut short by --duration: .*servo locked' <<<"$E2E_OUT" &&
    grep -q 'before the servo settled within --arrive of --pos 0.3 (servo locked)' <<<"$E2E_ERR"; then
    e2e_pass move_arrive_not_settled; else
    e2e_fail move_arrive_not_settled "rc $E2E_RC out '$E2E_OUT' err '$E2E_ERR'"; fi

# (cut short by --duration: said so, exit 1; the last target stays in force with --keep)
e2e_run "$J288" --port "$MAIN" move --id 2 --pos 10 --side rotor --speed 50 --duration 0.5 --keep "${M[@]}"
if [ $E2E_RC -eq 1 ] && grep -q '^cut short by --duration: .*last command left in force' <<<"$E2E_OUT" &&
    grep -q 'before reaching --pos 10 (last target left in force)' <<<"$E2E_ERR"; then e2e_pass move_keep; else
    e2e_fail move_keep "rc $E2E_RC out '$E2E_OUT' err '$E2E_ERR'"; fi
expect_true move_keep_no_lock bash -c "grep 'id=2 ' '$MAIN_LOG' | tail -n 1 | grep -q 'status=1'"

e2e_run "$J288" --port "$MAIN" torque --id 3 --tau 0.5 --duration 0.2 "${M[@]}"
if [ $E2E_RC -eq 0 ]; then e2e_pass torque_runs; else e2e_fail torque_runs "rc $E2E_RC err '$E2E_ERR'"; fi
# 0.5 N*m on the output side = 0.5 / 288.35 * 256000 = 444 LSB rotor.
expect_true torque_frames grep -Eq 'id=3 status=1 wd=1 tau=444 speed=0 pos=[-0-9]+ kp=0 kd=0' "$MAIN_LOG"
expect_bad torque_out_of_range 2 '--tau' "$J288" --port "$MAIN" torque --id 3 --tau 100
expect_bad move_missing_pos 2 '--pos is required' "$J288" --port "$MAIN" move --id 3
expect_bad move_negative_speed 2 '^j288 move: --speed: -1 is not above 0' "$J288" --port "$MAIN" move --id 3 --pos 0.5 --speed -1
expect_bad move_negative_gain 2 '--kp: -1 is negative' "$J288" --port "$MAIN" move --id 3 --pos 0 --kp -1
expect_bad hold_bad_rate 2 '--rate' "$J288" --port "$MAIN" hold --id 1 --rate 0
expect_bad hold_absent_servo 1 'no reply from servo 7' "$J288" --port "$MAIN" hold --id 7 --duration 0.1

# log: CSV rows, summary, JSON.
CSV=$E2E_TMP/log.csv
e2e_run "$J288" --port "$MAIN" log --id 1,2,3 --rate 200 --duration 0.5 --swing 0.1 --csv "$CSV" --json "${M[@]}"
# Counters, not speed: a slow machine runs fewer cycles (and skips ticks) but never more
# than the 100 ticks of 0.5 s at 200 Hz; with the long margin a healthy servo's failure is a
# fault (one each is tolerated, for a machine frozen longer than the margin).
json_check log_json "
assert 1 <= o['cycles'] <= 100 and o['achieved_hz'] > 0, o
assert o['cycles'] + o['skipped_ticks'] <= o['elapsed_s'] * 200 + 1, o
assert o['bus']['transactions'] >= 3 * o['cycles'], o
assert [s['id'] for s in o['servos']] == [1, 2, 3], o
assert all(s['replies'] + s['failures'] == o['cycles'] for s in o['servos']), o
assert all(s['failures'] <= max(1, o['cycles'] // 20) for s in o['servos']), o
assert all('tracking_rms_rad' in s for s in o['servos']), o
import csv
rows = list(csv.DictReader(open('$CSV')))
assert len(rows) == 3 * o['cycles'] == o['csv_rows'], (len(rows), o['cycles'])
need = 'time_s id ok pos_rad speed_rad_s torque_nm case_temp_c winding_temp_c voltage_v faults latency_us'
assert set(need.split()) <= set(rows[0]), rows[0].keys()
assert {r['id'] for r in rows} == {'1', '2', '3'}
assert all(float(r['voltage_v']) == 24.0 for r in rows if r['ok'] == '1')
assert sum(r['ok'] == '1' for r in rows) == sum(s['replies'] for s in o['servos']), o
assert [int(r['faults']) for r in rows if r['id'] == '3' and r['ok'] == '1'][0] == 0x200
ts = [float(r['time_s']) for r in rows if r['ok'] == '1']
assert ts == sorted(ts), 'reply times out of order'"
expect_true log_ends_with_locks bash -c "for i in 1 2 3; do grep \"id=\$i \" '$MAIN_LOG' | tail -n 1 | grep -q 'status=0' || exit 1; done"
e2e_run "$J288" --port "$MAIN" log --id 1,2 --rate 100 --duration 0.2 "${M[@]}"
if [ $E2E_RC -eq 0 ] && grep -q 'achieved' <<<"$E2E_OUT" && grep -q 'missed deadlines' <<<"$E2E_OUT" &&
    grep -q '^bus: ' <<<"$E2E_OUT"; then e2e_pass log_human; else
    e2e_fail log_human "rc $E2E_RC out '$E2E_OUT' err '$E2E_ERR'"; fi
expect_bad log_missing_id 2 '--id is required' "$J288" --port "$MAIN" log --rate 10 --duration 0.1
expect_bad log_bad_id_list 2 "--id: 'x' is not a whole number" "$J288" --port "$MAIN" log --id 1,x
expect_bad log_duplicate_id 2 'listed twice' "$J288" --port "$MAIN" log --id 1,1
expect_bad log_absent_servo 1 'no reply from servo 4' "$J288" --port "$MAIN" log --id 1,4 --duration 0.1 "${M50[@]}"
expect_bad log_hold_and_swing 2 'exclude each other' "$J288" --port "$MAIN" log --id 1 --hold --swing 1
expect_bad log_unwritable_csv 1 'cannot write' "$J288" --port "$MAIN" log --id 1 --duration 0.1 --csv /nonexistent/dir/x.csv

# plot: a PNG with gnuplot, else a one-line notice and exit 3.
if command -v gnuplot >/dev/null 2>&1; then
    e2e_run "$J288" plot "$CSV" --png "$E2E_TMP/log.png"
    if [ $E2E_RC -eq 0 ] && [ -s "$E2E_TMP/log.png" ] && head -c 8 "$E2E_TMP/log.png" | grep -q PNG; then
        e2e_pass plot_png; else e2e_fail plot_png "rc $E2E_RC err '$E2E_ERR'"; fi
elif [ "${CI:-}" = true ]; then
    e2e_fail plot_png "gnuplot is required in CI (apt-get install gnuplot-nox)"
else
    echo "note: gnuplot not installed; the PNG path is not tested (apt-get install gnuplot-nox)"
    expect_bad plot_without_gnuplot 3 'gnuplot is not installed' "$J288" plot "$CSV" --png "$E2E_TMP/log.png"
fi
expect_bad plot_without_gnuplot_on_path 3 'gnuplot is not installed' env PATH=/nonexistent "$J288" plot "$CSV" --png "$E2E_TMP/x.png"
expect_bad plot_not_a_log 1 'is not a CSV written by j288 log' "$J288" plot "$MAIN_LOG" --png "$E2E_TMP/x.png"
expect_bad plot_missing_png 2 'usage: j288 plot' "$J288" plot "$CSV"

# ---- safe stop on SIGINT / SIGTERM -----------------------------------------------------------
# safe_stop NAME SIGNAL WANT_RC IDS CMD...: run a moving command in the background until the
# simulator has seen FOC frames for every id, signal it, and check that it exits promptly
# with WANT_RC and that the last frame each id received is a lock. (--foreground: timeout
# passes the signal to the command alone. Without it, timeout also signals its process group
# and follows with SIGCONT; a SIGCONT that lands while an ASan build's leak check stops the
# process at exit can leave it stopped until -k kills it: exit 137 under make test-asan.)
safe_stop() {
    local name=$1 sig=$2 want=$3 ids=$4; shift 4
    local id pid rc ok=1 why="" from
    from=$(log_lines "$MAIN_LOG")
    timeout --foreground -k 2 "$(e2e_scaled 60)" "$@" >"$E2E_TMP/bg.out" 2>"$E2E_TMP/bg.err" &
    pid=$!
    BG_PIDS+=("$pid")
    for id in ${ids//,/ }; do
        wait_for_log "$MAIN_LOG" "id=$id status=1 wd=1" 20 "$from" || { ok=0; why="no FOC frame for $id"; }
    done
    sleep 0.1
    kill -"$sig" "$pid"
    wait "$pid"; rc=$?
    if [ $ok -eq 1 ] && [ $rc -ne "$want" ]; then ok=0; why="exit $rc, want $want: $(cat "$E2E_TMP/bg.err")"; fi
    for id in ${ids//,/ }; do
        if ! grep "id=$id " "$MAIN_LOG" | tail -n 1 | grep -q 'status=0'; then
            ok=0; why="$why; last frame to $id is not a lock: $(grep "id=$id " "$MAIN_LOG" | tail -n 1)"
        fi
    done
    if [ $ok -eq 1 ]; then e2e_pass "$name"; else e2e_fail "$name" "$why"; fi
}
safe_stop sigint_hold INT 130 1 "$J288" --port "$MAIN" hold --id 1 "${M[@]}"
safe_stop sigterm_hold TERM 143 2 "$J288" --port "$MAIN" hold --id 2 --rate 1000 "${M[@]}"
safe_stop sigint_move INT 130 3 "$J288" --port "$MAIN" move --id 3 --pos 3 --speed 0.5 "${M[@]}"
safe_stop sigint_torque INT 130 1 "$J288" --port "$MAIN" torque --id 1 --tau 0.2 "${M[@]}"
safe_stop sigint_log INT 130 1,2,3 "$J288" --port "$MAIN" log --id 1,2,3 --rate 500 --duration 30 --swing 0.5 "${M[@]}"
safe_stop sigterm_log TERM 143 1,3 "$J288" --port "$MAIN" log --id 1,3 --rate 1000 --duration 30 --hold "${M[@]}"

# ---- port in use -----------------------------------------------------------------------------
from=$(log_lines "$MAIN_LOG")
timeout -k 2 "$(e2e_scaled 60)" "$J288" --port "$MAIN" hold --id 1 "${M[@]}" >/dev/null 2>&1 &
HOLDER=$!
BG_PIDS+=("$HOLDER")
wait_for_log "$MAIN_LOG" 'id=1 status=1' 20 "$from"
# The holder is j288 under `timeout`: the PID named must be that child of $HOLDER.
expect_bad port_in_use 1 "in use by PID [0-9]+" "$J288" --port "$MAIN" status --id 2
named=$(grep -Eo 'PID [0-9]+' <<<"$E2E_ERR" | grep -Eo '[0-9]+')
expect_true port_in_use_names_holder test "$(awk '{print $4}' "/proc/${named:-0}/stat" 2>/dev/null)" = "$HOLDER"
kill -INT "$HOLDER"; wait "$HOLDER"
expect_ok port_free_again "servo 2 locked (mode lock)" "$J288" --port "$MAIN" stop --id 2 "${M[@]}"

# ---- missing, wrong and silent devices ---------------------------------------------------------
expect_bad no_device 2 'no device' env -u J288_PORT "$J288" status --id 1
expect_bad missing_device 1 'nonexistent' "$J288" --port "$E2E_TMP/nonexistent" scan
expect_bad not_a_serial_device 1 'null' "$J288" --port /dev/null status --id 1
e2e_run env J288_PORT="$MAIN" "$J288" status --id 1 --json "${M[@]}"
json_check port_from_environment 'assert o["id"] == 1'
stop_sim "$MAIN_PID"

start_sim silent --ids 1 --drop 1 || exit 1
SECONDS_BEFORE=$SECONDS
expect_bad silent_bus_scan 1 'no servo answered .*ids 0-14 tried' "$J288" --port "$DEV" scan
expect_bad silent_bus_status 1 'no reply from servo 1' "$J288" --port "$DEV" status --id 1
expect_bad silent_bus_log 1 'no reply from servo 1' "$J288" --port "$DEV" log --id 1 --rate 100 --duration 0.2
expect_bad silent_bus_hold 1 'no reply from servo 1' "$J288" --port "$DEV" hold --id 1
# A hang bound, not a speed test (each command is also bounded by e2e_run's timeout): the four
# give up after their reply windows, a fraction of a second each even under valgrind.
expect_true silent_bus_never_hangs test $((SECONDS - SECONDS_BEFORE)) -lt 60
stop_sim "$SIM_PID"

# ---- vanished device: the simulator exits under a running command ------------------------------
start_sim vanish --ids 1 || exit 1
timeout -k 2 "$(e2e_scaled 60)" "$J288" --port "$DEV" hold --id 1 "${M[@]}" >"$E2E_TMP/bg.out" 2>"$E2E_TMP/bg.err" &
pid=$!
BG_PIDS+=("$pid")
wait_for_log "$E2E_TMP/vanish.log" 'id=1 status=1'
stop_sim "$SIM_PID"
wait "$pid"; rc=$?
if [ $rc -eq 1 ] && [ "$(grep -c '' "$E2E_TMP/bg.err")" -eq 1 ] && grep -Eqi 'vanished|gone|hang' "$E2E_TMP/bg.err"; then
    e2e_pass vanished_during_hold
else
    e2e_fail vanished_during_hold "exit $rc, stderr: $(cat "$E2E_TMP/bg.err")"
fi
start_sim vanish2 --ids 1,2 || exit 1
timeout -k 2 "$(e2e_scaled 60)" "$J288" --port "$DEV" log --id 1,2 --rate 500 --duration 40 --csv "$E2E_TMP/v.csv" "${M[@]}" >"$E2E_TMP/bg.out" 2>"$E2E_TMP/bg.err" &
pid=$!
BG_PIDS+=("$pid")
wait_for_log "$E2E_TMP/vanish2.log" 'id=2 status=0'
sleep 0.2
stop_sim "$SIM_PID"
wait "$pid"; rc=$?
if [ $rc -eq 1 ] && [ "$(grep -c '' "$E2E_TMP/bg.err")" -eq 1 ] && [ ! -s "$E2E_TMP/bg.out" ]; then
    e2e_pass vanished_during_log
else
    e2e_fail vanished_during_log "exit $rc, stderr: $(cat "$E2E_TMP/bg.err") stdout: $(head -c 200 "$E2E_TMP/bg.out")"
fi

e2e_summary
