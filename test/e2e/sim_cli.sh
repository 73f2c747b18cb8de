#!/usr/bin/env bash
# j288-sim as a program: --help, argument errors, the pty path line, --link, --log, exit on
# SIGINT/SIGTERM and --exit-after with the statistics line, nothing left behind, the
# fault switch (SIGUSR1 off, SIGUSR2 on) seen through the j288 tool's status command, and
# the joint: --phase/--start-angle, the --truth file (start, SIGWINCH, power cycles, exit)
# against what the j288 tool reads, power cycles (SIGPWR, --power-cycle-after).
# Run with BIN set (make test does); J288_SIM and J288 may name other
# binaries (make test-valgrind points them at test/e2e/valgrind-wrap.sh).
# No check depends on the machine's speed: waits poll for what they expect, bounded (10-30 s),
# and the status exchanges that must succeed use a 250 ms (status) or 1 s (JSON) reply margin.
set -u
cd "$(dirname "$0")/../.."
. test/e2e/lib_e2e.sh
SIM_DIR=$E2E_TMP
. test/e2e/lib_sim.sh
trap 'sim_cleanup KILL' EXIT

# Start the simulator in the background; sets SIM_PID, SIM_PTY (waits for the path line).
start_sim() {
    "$SIM" "$@" >"$E2E_TMP/out" 2>"$E2E_TMP/err" &
    SIM_PID=$!
    SIM_PIDS+=("$SIM_PID")
    SIM_PTY=
    for _ in $(seq 1 600); do # up to 30 s
        SIM_PTY=$(head -n1 "$E2E_TMP/out" 2>/dev/null)
        [ -n "$SIM_PTY" ] && break
        sleep 0.05
    done
}

t_help() {
    local opt
    for opt in --ids --exit-after --phase --start-angle --backlash --truth --power-cycle-after \
        --power-off-ms SIGPWR SIGWINCH; do
        "$SIM" --help | grep -q -- "$opt" || { echo "--help does not mention $opt"; return 1; }
    done
}
t_bad_option() {
    "$SIM" --bogus >/dev/null 2>"$E2E_TMP/e"; local rc=$?
    [ $rc -eq 2 ] && [ "$(wc -l <"$E2E_TMP/e")" -eq 1 ] && grep -q "unknown option '--bogus'" "$E2E_TMP/e"
}
t_bad_ids() {
    "$SIM" --ids 1,15 >/dev/null 2>"$E2E_TMP/e"; [ $? -eq 2 ] && grep -q -- '--ids' "$E2E_TMP/e" || return 1
    "$SIM" --ids 1 --dup 2 >/dev/null 2>"$E2E_TMP/e"; [ $? -eq 2 ] && grep -q -- '--dup' "$E2E_TMP/e" || return 1
    "$SIM" --drop 1.5 >/dev/null 2>"$E2E_TMP/e"; [ $? -eq 2 ] && grep -q -- '--drop' "$E2E_TMP/e"
}
t_path_link_exit_after() {
    # Long enough that the link is still there when looked at on a loaded machine.
    start_sim --ids 1,2,3 --link "$E2E_TMP/bus" --exit-after 3 || return 1
    [[ "$SIM_PTY" == /dev/pts/* ]] || return 1
    [ -c "$SIM_PTY" ] && [ -L "$E2E_TMP/bus" ] && [ "$(readlink "$E2E_TMP/bus")" = "$SIM_PTY" ] || return 1
    wait_exit "$SIM_PID" 20 || return 1
    [ ! -e "$E2E_TMP/bus" ] && grep -q '^j288-sim: stats: ' "$E2E_TMP/err"
}
t_signals() {
    local sig rc
    for sig in TERM INT; do
        start_sim --exit-after "$(e2e_scaled 120)" || return 1
        [ -n "$SIM_PTY" ] || { echo "SIG$sig: no path line: $(cat "$E2E_TMP/err")"; return 1; }
        kill -s "$sig" "$SIM_PID"
        wait_exit "$SIM_PID" 20
        rc=$?
        [ $rc -eq 0 ] && grep -q '^j288-sim: stats: ' "$E2E_TMP/err" ||
            { echo "SIG$sig: exit $rc, stderr: $(cat "$E2E_TMP/err")"; return 1; }
    done
}
# wait_file FILE PATTERN: up to 30 s (a loaded machine, or valgrind) for a line of FILE to
# match the extended regex; returns as soon as one does.
wait_file() {
    for _ in $(seq 1 600); do
        grep -Eq "$2" "$1" 2>/dev/null && return 0
        sleep 0.05
    done
    return 1
}
t_log_frames() {
    start_sim --ids 0 --log "$E2E_TMP/log" --exit-after 60 || return 1
    stty -F "$SIM_PTY" raw -echo || return 1
    # The protocol's worked lock frame for servo 0, then the same with a broken CRC; each
    # written once the simulator has logged the one before (it may be slow to read).
    printf '\xfe\xee\x80\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x1d\x99\xfb\x6e' >"$SIM_PTY"
    wait_file "$E2E_TMP/log" 'feee80000000000000000000000000001d99fb6e id=0 status=0 wd=1 ' ||
        { echo "the lock frame was not logged"; return 1; }
    printf '\xfe\xee\x80\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x1d\x99\xfb\x6f' >"$SIM_PTY"
    wait_file "$E2E_TMP/log" ' bad-crc id=0$' || { echo "the bad frame was not logged"; return 1; }
    kill -s TERM "$SIM_PID"; wait_exit "$SIM_PID" 20 || return 1
    [ "$(grep -c '' "$E2E_TMP/log")" -eq 2 ] &&
        grep -q 'commands 1 .*bad-crc 1 ' "$E2E_TMP/err" && grep -q ' replies 1 ' "$E2E_TMP/err"
}
# wait_err PATTERN: up to 20 s for a line of the simulator's stderr to match.
wait_err() {
    for _ in $(seq 1 400); do
        grep -Eq "$1" "$E2E_TMP/err" && return 0
        sleep 0.05
    done
    return 1
}
# status_ok / status_fails: status of servo 1, no retries (status_ok with a 1 s margin: a
# slow machine must not make a good exchange fail). A status that gets replies takes 8
# exchanges (the joint angle's start); one whose first exchange fails stops there.
status_ok() {
    timeout 30 "$J288" --port "$SIM_PTY" status --id 1 --retries 0 --margin-us 1000000 >/dev/null 2>"$E2E_TMP/st"
}
status_fails() {
    timeout 30 "$J288" --port "$SIM_PTY" status --id 1 --retries 0 >/dev/null 2>"$E2E_TMP/st"
    [ $? -eq 1 ] && grep -q 'no reply from servo 1' "$E2E_TMP/st"
}
# Every reply dropped: status times out; after SIGUSR1 it succeeds (acknowledged with the
# statistics so far); after SIGUSR2 it times out again.
t_fault_switch() {
    [ -x "$J288" ] || { echo "$J288 not built"; return 1; }
    start_sim --ids 1 --drop 1 --exit-after "$(e2e_scaled 120)" || return 1
    status_fails || { echo "status succeeded with --drop 1"; return 1; }
    kill -s USR1 "$SIM_PID"
    wait_err '^j288-sim: faults off: stats: .* replies 0 dropped 1 ' || { echo "no ack"; return 1; }
    status_ok || { echo "status failed after SIGUSR1: $(cat "$E2E_TMP/st")"; return 1; }
    status_ok || return 1
    kill -s USR2 "$SIM_PID"
    wait_err '^j288-sim: faults on: stats: .* replies 16 dropped 1 ' || return 1
    status_fails || { echo "status succeeded after SIGUSR2"; return 1; }
    kill -s TERM "$SIM_PID"; wait_exit "$SIM_PID" 20 || return 1
    grep -q '^j288-sim: stats: .* commands 18 .* replies 16 dropped 2 ' "$E2E_TMP/err"
}
# A reply delayed before SIGUSR1 still goes out when due (counted as sent, nothing lost); it
# does not disturb the clean exchanges after the switch. The test keeps the pty open (fd 9,
# raw), so that the status client's exit is no hang-up (which drops what was queued for the
# departed client), and waits for the late reply's 26 bytes on it: a condition, not a sleep.
# The delay (3 s, scaled, at most the simulator's 10 s) is far beyond the stalls of a loaded
# machine: the failing status must have given up long before the reply comes.
t_fault_switch_late_in_flight() {
    local late_s=$(($(e2e_scaled 3) < 10 ? $(e2e_scaled 3) : 10)) rc
    [ -x "$J288" ] || { echo "$J288 not built"; return 1; }
    start_sim --ids 1 --late 1 --late-us "${late_s}000000" --exit-after "$(e2e_scaled 120)" || return 1
    exec 9<>"$SIM_PTY" && stty raw -echo <&9 || return 1
    status_fails || { echo "status succeeded with the reply $late_s s late"; return 1; }
    kill -s USR1 "$SIM_PID"
    wait_err '^j288-sim: faults off: stats: .* late 1 ' || { echo "no ack"; return 1; }
    status_ok || { echo "status failed after SIGUSR1: $(cat "$E2E_TMP/st")"; return 1; }
    timeout "$((late_s + $(e2e_scaled 20)))" head -c 26 <&9 >"$E2E_TMP/late"; rc=$?
    exec 9<&-
    [ $rc -eq 0 ] && [ "$(wc -c <"$E2E_TMP/late")" -eq 26 ] || { echo "the late reply never came"; return 1; }
    status_ok || { echo "status failed after the late reply: $(cat "$E2E_TMP/st")"; return 1; }
    kill -s TERM "$SIM_PID"; wait_exit "$SIM_PID" 20 || return 1
    grep -q '^j288-sim: stats: .* commands 17 .* replies 17 dropped 0 corrupted 0 late 1 .* lost 0 ' "$E2E_TMP/err"
}

# ---- the joint and the truth file ---------------------------------------------------------
# truth_val FILE ID KEY: the value of KEY on servo ID's line of a --truth file.
truth_val() {
    awk -v id="$2" -v key="$3" '$1 == "id=" id {
        for (i = 2; i <= NF; i++) { n = index($i, "="); if (substr($i, 1, n - 1) == key) print substr($i, n + 1) } }' "$1"
}
# json_int NAME: the integer field NAME of the status JSON in $E2E_TMP/json.
json_int() { grep -o "\"$1\": -\?[0-9]*" "$E2E_TMP/json" | head -n1 | sed 's/.*: //'; }
# status_json ID: one status exchange as JSON into $E2E_TMP/json. The margin is the tool's
# largest, 1 s (it ends with the reply): on a loaded machine the simulator is at times held
# up past 250 ms, and these exchanges must succeed.
status_json() {
    timeout 30 "$J288" --port "$SIM_PTY" status --id "$1" --retries 0 --margin-us 1000000 --json \
        >"$E2E_TMP/json" 2>"$E2E_TMP/st"
}
# The count a 13-bit encoder gives for output angle $1, and the reply's raw position for $1 rad.
out_pos_of() { awk -v t="$1" 'BEGIN { pi = atan2(0, -1); f = t / (2 * pi); f -= int(f); if (f < 0) f += 1; print int(f * 8192) }'; }
pos_raw_of() { awk -v p="$1" 'BEGIN { pi = atan2(0, -1); v = p * 32768 / (2 * pi); print (v < 0) ? -int(-v + 0.5) : int(v + 0.5) }'; }

# --phase and --start-angle give the truth at start (written before the path line); the tool
# reads the OutPos and rotor position it implies; SIGWINCH and the exit rewrite the file.
t_truth_start() {
    [ -x "$J288" ] || { echo "$J288 not built"; return 1; }
    local f=$E2E_TMP/truth
    rm -f "$f"
    start_sim --ids 1,2 --phase 1:2.5 --start-angle 1:-1.25 --truth "$f" --quiet --exit-after "$(e2e_scaled 120)" || return 1
    [ "$(head -n1 "$f")" = "# j288-sim truth seq=1 t=0.000000 reason=start" ] || { echo "header: $(head -n1 "$f")"; return 1; }
    [ "$(grep -c '^id=' "$f")" -eq 2 ] || return 1
    [ "$(truth_val "$f" 1 c)" = 2.500000000 ] && [ "$(truth_val "$f" 1 theta)" = -1.250000000 ] || return 1
    [ "$(truth_val "$f" 1 out_pos)" = "$(out_pos_of -1.25)" ] || { echo "out_pos $(truth_val "$f" 1 out_pos)"; return 1; }
    awk -v p="$(truth_val "$f" 1 p)" 'BEGIN { exit !(p >= 0 && p < 2 * atan2(0, -1)) }' || return 1
    status_json 1 || { echo "status failed: $(cat "$E2E_TMP/st")"; return 1; }
    [ "$(json_int out_pos_raw)" = "$(truth_val "$f" 1 out_pos)" ] || { echo "out_pos_raw $(json_int out_pos_raw)"; return 1; }
    [ "$(json_int pos_raw)" = "$(pos_raw_of "$(truth_val "$f" 1 p)")" ] || { echo "pos_raw $(json_int pos_raw)"; return 1; }
    kill -s WINCH "$SIM_PID"
    wait_file "$f" '^# j288-sim truth seq=2 t=[0-9.]+ reason=request$' || { echo "no request truth"; return 1; }
    [ "$(truth_val "$f" 1 c)" = 2.500000000 ] || return 1
    kill -s TERM "$SIM_PID"; wait_exit "$SIM_PID" 20 || return 1
    grep -Eq '^# j288-sim truth seq=3 t=[0-9.]+ reason=exit$' "$f" && [ ! -e "$f.tmp" ] &&
        grep -q ' power-cycles 0$' "$E2E_TMP/err"
}
# Same seed, same servos; another seed, others.
t_truth_deterministic() {
    local s
    for s in 5 5 6; do
        "$SIM" --ids 1,2,3 --seed $s --truth "$E2E_TMP/t$s" --exit-after 0.01 --quiet >/dev/null 2>&1 || return 1
        grep '^id=' "$E2E_TMP/t$s" >>"$E2E_TMP/all$s"
    done
    [ "$(grep -c '^id=' "$E2E_TMP/all5")" -eq 6 ] && [ "$(sed -n 1,3p "$E2E_TMP/all5")" = "$(sed -n 4,6p "$E2E_TMP/all5")" ] &&
        ! cmp -s <(sed -n 1,3p "$E2E_TMP/all5") "$E2E_TMP/all6"
}
# SIGPWR: every servo off for --power-off-ms, the truth written when they go off and when they
# are back; the turn count is lost: a servo moved several rotor turns reports p inside
# [0, 2 pi) again, with the same OutPos, and k took the turns.
t_power_cycle_signal() {
    [ -x "$J288" ] || { echo "$J288 not built"; return 1; }
    local f=$E2E_TMP/truth k0
    rm -f "$f"
    start_sim --ids 1,2 --truth "$f" --power-off-ms 200 --exit-after "$(e2e_scaled 120)" || return 1
    k0=$(truth_val "$f" 1 k)
    # (watchdog off: a loaded machine that starves the tool for 1 s must not trip it here)
    timeout 30 "$J288" --port "$SIM_PTY" move --id 1 --pos 20 --side rotor --speed 50 --duration 1.5 \
        --watchdog off --retries 1 --margin-us 250000 >/dev/null 2>"$E2E_TMP/st" || { echo "move failed: $(cat "$E2E_TMP/st")"; return 1; }
    status_json 1 || return 1
    [ "$(json_int pos_raw)" -gt 32768 ] || { echo "the move did not turn the rotor: $(json_int pos_raw)"; return 1; }
    kill -s PWR "$SIM_PID"
    wait_err '^j288-sim: power cycle: servos 1 2 off for 200 ms$' || { echo "no power cycle message"; return 1; }
    wait_file "$f" 'reason=power-on$' || { echo "no power-on truth"; return 1; }
    [ "$(truth_val "$f" 1 powered)" = 1 ] && [ "$(truth_val "$f" 1 cycles)" = 1 ] &&
        [ "$(truth_val "$f" 2 cycles)" = 1 ] || { cat "$f"; return 1; }
    # (the rotor was past one turn, pos_raw above: at least that turn is lost; on a loaded
    # machine the move may end short of its 3 turns)
    [ "$(truth_val "$f" 1 k)" -gt "$k0" ] || { echo "k $k0 -> $(truth_val "$f" 1 k)"; return 1; }
    status_json 1 || { echo "status failed after the power cycle: $(cat "$E2E_TMP/st")"; return 1; }
    [ "$(json_int pos_raw)" -ge 0 ] && [ "$(json_int pos_raw)" -lt 32768 ] || { echo "pos_raw $(json_int pos_raw)"; return 1; }
    [ "$(json_int pos_raw)" = "$(pos_raw_of "$(truth_val "$f" 1 p)")" ] &&
        [ "$(json_int out_pos_raw)" = "$(truth_val "$f" 1 out_pos)" ] || { cat "$E2E_TMP/json" "$f"; return 1; }
    grep -q '"mode_name": "lock"' "$E2E_TMP/json" && grep -q '"watchdog": 0' "$E2E_TMP/json" || return 1
    kill -s TERM "$SIM_PID"; wait_exit "$SIM_PID" 20 || return 1
    grep -q ' power-cycles 2$' "$E2E_TMP/err"
}
# --power-cycle-after 0:1 with a minute off: servo 1 is silent, servo 2 answers.
t_power_cycle_option() {
    [ -x "$J288" ] || { echo "$J288 not built"; return 1; }
    local f=$E2E_TMP/truth
    rm -f "$f"
    start_sim --ids 1,2 --truth "$f" --power-cycle-after 0:1 --power-off-ms 60000 --quiet --exit-after "$(e2e_scaled 120)" || return 1
    wait_file "$f" 'reason=power-off$' || { echo "no power-off truth"; return 1; }
    [ "$(truth_val "$f" 1 powered)" = 0 ] && [ "$(truth_val "$f" 2 powered)" = 1 ] || { cat "$f"; return 1; }
    status_fails || { echo "servo 1 answered while off"; return 1; }
    status_json 2 || { echo "servo 2 did not answer: $(cat "$E2E_TMP/st")"; return 1; }
    kill -s TERM "$SIM_PID"; wait_exit "$SIM_PID" 20 || return 1
    grep -q ' power-cycles 1$' "$E2E_TMP/err"
}
t_joint_bad_values() {
    local args
    for args in "--phase 3:1|--phase names an id" "--phase 1|--phase: expected ID:RAD" \
        "--start-angle 1:x|--start-angle: 'x' is not a number" "--backlash 2|--backlash" \
        "--power-cycle-after 1:4|--power-cycle-after names an id" \
        "--power-cycle-after -1|--power-cycle-after" "--power-off-ms 70000|--power-off-ms" \
        "--truth $E2E_TMP/no/such/dir/t|--truth $E2E_TMP/no/such/dir/t.tmp: No such file"; do
        # shellcheck disable=SC2086
        "$SIM" --ids 1 ${args%%|*} --exit-after 1 >/dev/null 2>"$E2E_TMP/e"; local rc=$?
        [ $rc -eq 2 ] && grep -qF -- "${args#*|}" "$E2E_TMP/e" || { echo "${args%%|*}: rc $rc: $(cat "$E2E_TMP/e")"; return 1; }
    done
}

t_link_refuses_file() {
    echo keep >"$E2E_TMP/file"
    "$SIM" --link "$E2E_TMP/file" --exit-after 1 >/dev/null 2>"$E2E_TMP/e"; local rc=$?
    [ $rc -eq 2 ] && [ "$(cat "$E2E_TMP/file")" = keep ]
}

e2e_check help t_help
e2e_check bad_option t_bad_option
e2e_check bad_values t_bad_ids
e2e_check path_link_exit_after t_path_link_exit_after
e2e_check signals t_signals
e2e_check log_frames t_log_frames
e2e_check link_refuses_file t_link_refuses_file
e2e_check fault_switch t_fault_switch
e2e_check fault_switch_late_in_flight t_fault_switch_late_in_flight
e2e_check joint_bad_values t_joint_bad_values
e2e_check truth_start t_truth_start
e2e_check truth_deterministic t_truth_deterministic
e2e_check power_cycle_signal t_power_cycle_signal
e2e_check power_cycle_option t_power_cycle_option

e2e_summary
