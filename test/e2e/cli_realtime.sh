#!/usr/bin/env bash
# The j288 tool's real time and its loop's timing (host/j288_rt.h, docs/realtime.md) against
# j288-sim: the timing lines and the "timing" JSON object of log (one bus and the robot form),
# hold and move, present and consistent (every cycle ended by a wait slept to its deadline or
# missed it; percentiles ordered); a stall provoked (SIGSTOP) and counted (a deadline missed,
# the periods it covered skipped, the stall seen in the lateness or a cycle's duration);
# --realtime --cpu in effect where the rights are (root), refused with the fix named and the
# loop running on where they are not (RLIMIT_RTPRIO 0, no CAP_SYS_NICE: the kernel's EPERM);
# bad values refused. Nothing depends on the machine's speed: the only bounds are those the
# provocation itself guarantees (a process stopped 0.3 s is at least 0.3 s late).
set -u
cd "$(dirname "$0")/../.."
. test/e2e/lib_cli_bus.sh

start_sim rt --ids 1,2,3 --exit-after "$(e2e_scaled 240)" || exit 1
RT_LOG=$E2E_TMP/rt.log
# Replies get a 1 s margin and two re-sends, as everywhere a reply must come (a simulator starved
# beside stress-ng missed the pty's default 5 ms in a loaded run): nothing here waits on it
# where the reply comes.
M=(--margin-us 1000000 --retries 2)
robot_config_one() { # a robot config of the one simulator, three joints
    printf 'buses:\n  - {name: leg, port: %s, margin_us: 1000000}\njoints:\n' "$DEV"
    printf '  - {name: j%s, bus: leg, id: %s}\n' 1 1 2 2 3 3
}
robot_config_one >"$E2E_TMP/robot.yaml"

# timing_ok [EXTRA PYTHON]: $E2E_OUT's "timing" object is consistent (o: the whole JSON, t: its
# timing), then the extra assertions.
TIMING_OK='
t = o["timing"]
assert t["lateness_us"]["count"] + t["missed_deadlines"] == t["cycles"], t
assert t["duration_us"]["count"] == t["cycles"], t
for h in (t["lateness_us"], t["duration_us"]):
    assert h["p50"] <= h["p99"] <= h["p99_9"] <= h["max"], t
'

# ---- log on one bus ---------------------------------------------------------------------------
e2e_run "$J288" --port "$DEV" log "${M[@]}" --id 1,2,3 --rate 200 --duration 0.5
t_log_text() {
    [ "$E2E_RC" -eq 0 ] || { echo "exit $E2E_RC: $E2E_ERR"; return 1; }
    local cycles
    cycles=$(sed -n 's/^log: \([0-9]*\) cycles.*/\1/p' <<<"$E2E_OUT")
    grep -Eq "^timing: $cycles cycles at 200 Hz \(normal priority\): [0-9]+ deadlines missed, [0-9]+ periods skipped, 0 cycles cut at their bound$" <<<"$E2E_OUT" &&
        grep -Eq '^timing: wake-up lateness p50 [0-9]+ us, p99 [0-9]+ us, p99.9 [0-9]+ us, max [0-9]+ us \([0-9]+ wake-ups\)$' <<<"$E2E_OUT" &&
        grep -Eq '^timing: cycle duration p50 [0-9]+ us, p99 [0-9]+ us, p99.9 [0-9]+ us, max [0-9]+ us$' <<<"$E2E_OUT" ||
        { echo "$E2E_OUT"; return 1; }
}
e2e_check log_timing_text t_log_text

# A stall provoked in the middle of the cycles: j288 log stopped for 0.3 s (60 periods).
t_log_forced_miss() {
    local pid n
    n=$(log_lines "$RT_LOG")
    "$J288" --port "$DEV" log "${M[@]}" --id 1 --rate 200 --duration "$(e2e_scaled 2)" --json >"$E2E_TMP/out" 2>"$E2E_TMP/err" &
    pid=$!
    # into the cycles: 40 frames after the start's few sweeps
    for _ in $(seq 1 "$(e2e_scaled 400)"); do [ "$(log_lines "$RT_LOG")" -gt $((n + 40)) ] && break; sleep 0.05; done
    kill -STOP "$pid"; sleep 0.3; kill -CONT "$pid"
    wait_exit "$pid" || { echo "log failed: $(cat "$E2E_TMP/err")"; return 1; }
    E2E_RC=0 E2E_OUT=$(cat "$E2E_TMP/out")
    python3 -c "import json, sys
o = json.load(sys.stdin)
$TIMING_OK
assert t['missed_deadlines'] >= 1 and t['skipped_periods'] >= 30, t
assert t['lateness_us']['max'] >= 200000 or t['duration_us']['max'] >= 200000, t
assert o['missed_deadlines'] == t['missed_deadlines'] and o['skipped_ticks'] == t['skipped_periods'], o
assert t['period_us'] == 5000 and t['cycles'] == o['cycles'], t" <<<"$E2E_OUT" || { echo "$E2E_OUT"; return 1; }
}
e2e_check log_forced_miss t_log_forced_miss

# ---- the robot form, hold and move ------------------------------------------------------------
e2e_run "$J288" --config "$E2E_TMP/robot.yaml" log --rate 200 --duration 0.5 --json
json_check robot_log_timing_json "$TIMING_OK
assert t['period_us'] == 5000 and t['cycles'] in (o['cycles'] - 1, o['cycles']), (o, t)
assert t['priority'] == 0 and t['cpu'] == -1 and not t['memory_locked'], t"
e2e_run "$J288" --config "$E2E_TMP/robot.yaml" hold --rate 200 --duration 0.3
t_robot_hold_text() {
    [ "$E2E_RC" -eq 0 ] && grep -Eq '^timing: [0-9]+ cycles at 200 Hz \(normal priority\): ' <<<"$E2E_OUT" &&
        grep -q '^timing: wake-up lateness p50 ' <<<"$E2E_OUT" || { echo "$E2E_RC: $E2E_OUT $E2E_ERR"; return 1; }
}
e2e_check robot_hold_timing_text t_robot_hold_text
e2e_run "$J288" --port "$DEV" hold "${M[@]}" --id 2 --rate 200 --duration 0.3
t_hold_text() {
    [ "$E2E_RC" -eq 0 ] && grep -Eq '^timing: [0-9]+ cycles at 200 Hz \(normal priority\): ' <<<"$E2E_OUT" &&
        grep -q '^timing: cycle duration p50 ' <<<"$E2E_OUT" || { echo "$E2E_RC: $E2E_OUT $E2E_ERR"; return 1; }
}
e2e_check hold_timing_text t_hold_text
e2e_run "$J288" --port "$DEV" move "${M[@]}" --id 3 --pos 0.2 --speed 0.5 --rate 200 --duration 0.3 --json
E2E_RC=0 # (cut short by --duration: exit 1, the report all the same)
json_check move_timing_json "$TIMING_OK
assert t['period_us'] == 5000 and t['cycles'] in (o['commands'] - 1, o['commands']), (o, t)
assert o['overruns'] == t['missed_deadlines'], (o, t)"

# ---- --realtime and --cpu ---------------------------------------------------------------------
t_realtime_in_effect() {
    # where the rights are (CI runs as root): SCHED_FIFO, the CPU, memory locked; elsewhere
    # the refusal (next check)
    env -u J288_QUIET "$J288" --port "$DEV" log "${M[@]}" --id 1 --rate 200 --duration 0.2 --realtime --cpu 0 \
        >"$E2E_TMP/out" 2>"$E2E_TMP/err" || { cat "$E2E_TMP/err"; return 1; }
    if ! grep -q 'refused' "$E2E_TMP/err"; then
        grep -Eq '^timing: [0-9]+ cycles at 200 Hz \(SCHED_FIFO 80, CPU 0, memory locked\)' "$E2E_TMP/out"
    else
        grep -Eq '^timing: [0-9]+ cycles at 200 Hz \(normal priority, CPU 0' "$E2E_TMP/out"
    fi || { cat "$E2E_TMP/out" "$E2E_TMP/err"; return 1; }
}
e2e_check realtime_in_effect t_realtime_in_effect
# ASan intercepts mlockall() and returns 0 without locking: under it the memory refusal
# cannot show, and is not looked for.
if ldd "$J288" 2>/dev/null | grep -q libasan; then MEMLOCK_REFUSAL='^real time:' MEMLOCK_SAID='(, memory locked)?'; else
    MEMLOCK_REFUSAL='^real time: memory not locked' MEMLOCK_SAID=''; fi
t_realtime_refused_runs_on() { # FORM...: the refusal explained, the loop runs on
    env -u J288_QUIET "${WITHOUT_RT_RIGHTS[@]}" "$J288" "$@" --rate 200 --duration 0.2 --realtime=70 \
        >"$E2E_TMP/out" 2>"$E2E_TMP/err" || { echo "exit $?: $(cat "$E2E_TMP/err")"; return 1; }
    grep -q '^real time: SCHED_FIFO priority 70 refused (Operation not permitted): the loop runs at normal priority' "$E2E_TMP/err" &&
        grep -q 'ulimit -r 70' "$E2E_TMP/err" && grep -q '/etc/security/limits.d' "$E2E_TMP/err" &&
        grep -q 'CAP_SYS_NICE' "$E2E_TMP/err" && grep -q "$MEMLOCK_REFUSAL" "$E2E_TMP/err" ||
        { cat "$E2E_TMP/err"; return 1; }
    grep -Eq "^timing: [1-9][0-9]* cycles at 200 Hz \\(normal priority$MEMLOCK_SAID\\)" "$E2E_TMP/out" || { cat "$E2E_TMP/out"; return 1; }
}
e2e_check realtime_refused_runs_on t_realtime_refused_runs_on --port "$DEV" log "${M[@]}" --id 1
e2e_check robot_realtime_refused_runs_on t_realtime_refused_runs_on --config "$E2E_TMP/robot.yaml" log
expect_bad realtime_zero 2 '^j288 log: --realtime: 0 is out of range 1..99$' \
    "$J288" --port "$DEV" log "${M[@]}" --id 1 --realtime=0
expect_bad realtime_needs_equals 2 "unexpected argument '90'" "$J288" --port "$DEV" log "${M[@]}" --id 1 --realtime 90
expect_bad cpu_not_allowed 2 '^j288 log: real time: CPU 1023 is not one this process may run on \(allowed: ' \
    "$J288" --port "$DEV" log "${M[@]}" --id 1 --cpu 1023
expect_bad robot_cpu_not_allowed 2 'CPU 1023 is not one this process may run on' \
    "$J288" --config "$E2E_TMP/robot.yaml" hold --cpu 1023
expect_bad cpu_not_a_number 2 "^j288 hold: --cpu: 'x' is not a whole number$" "$J288" --port "$DEV" hold "${M[@]}" --id 1 --cpu x
e2e_summary
