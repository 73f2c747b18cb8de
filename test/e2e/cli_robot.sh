#!/usr/bin/env bash
# j288 --config FILE log|status|hold|stop over several simulated buses: every joint's status,
# a log with its CSV and JSON summary, the broadcast stop on every bus, Ctrl-C during hold
# (every bus locked, exit 130), a bus that stops answering during a log and a bus whose
# simulator exits (the others go on, the tool names the bus), the bad
# configs (a bus or an id twice, a device that is gone) and the dispatch (--id still picks
# the one-servo command). Run from the repo root with BIN set (make test does); J288_SIM and
# J288 may name other binaries (make test-valgrind points them at valgrind-wrap.sh).
# No check depends on the machine's speed: replies get a 1 s margin, waits are bounded.
set -u
cd "$(dirname "$0")/../.."
. test/e2e/lib_e2e.sh
SIM_DIR=$E2E_TMP
. test/e2e/lib_sim.sh
trap 'sim_cleanup KILL' EXIT

start_sims 3 --exit-after "$(e2e_scaled 120)" --log "$E2E_TMP/log.{k}"
# (1 s margins: a bus lost is exit 1 (issue 29), and three sweeps of a simulator starved past
# 250 ms margins would take a bus down; a long margin costs nothing where the replies come)
robot_config 3 "$E2E_TMP/robot.yaml" 1000000 2 0.05

t_status() {
    "$J288" --config "$E2E_TMP/robot.yaml" status >"$E2E_TMP/out" 2>"$E2E_TMP/err" || return 1
    [ "$(grep -c ' known ' "$E2E_TMP/out")" -eq 9 ] && grep -q '^leg2_3 ' "$E2E_TMP/out" || return 1
    "$J288" --config "$E2E_TMP/robot.yaml" status --json >"$E2E_TMP/json" || return 1
    [ "$(grep -o '"known": true' "$E2E_TMP/json" | wc -l)" -eq 9 ]
}
t_log_csv_json() {
    "$J288" --config "$E2E_TMP/robot.yaml" log --rate 200 --duration 0.3 --csv "$E2E_TMP/log.csv" \
        >"$E2E_TMP/out" 2>"$E2E_TMP/err" || return 1
    grep -q '^robot: [0-9]* cycles' "$E2E_TMP/out" && grep -q '^bus leg1: ' "$E2E_TMP/out" || return 1
    head -n1 "$E2E_TMP/log.csv" | grep -q '^time_s,id,ok,pos_rad,.*,joint,bus,cycle$' || return 1
    # A row per joint per cycle (counted, not timed: a loaded machine ran 3 cycles in 0.3 s
    # where 5 rows of one joint were once asked for), the joint's answered ones complete.
    local cycles
    cycles=$(sed -n 's/^robot: \([0-9]*\) cycles.*/\1/p' "$E2E_TMP/out")
    [ "${cycles:-0}" -ge 1 ] && [ "$(grep -c ',leg1_2,leg1,[0-9]*$' "$E2E_TMP/log.csv")" -eq "$cycles" ] &&
        grep -q '^[0-9.]*,2,1,[-0-9.]*,.*,leg1_2,leg1,[0-9]*$' "$E2E_TMP/log.csv" ||
        { echo "cycles '$cycles': $(head -n 3 "$E2E_TMP/log.csv")"; return 1; }
    # The same after the command: j288 log --config FILE
    "$J288" log --config "$E2E_TMP/robot.yaml" --rate 0 --duration 0.2 --json >"$E2E_TMP/json" || return 1
    grep -q '"joints": 9, "buses": 3' "$E2E_TMP/json"
}
t_hold_and_stop() {
    : >"$E2E_TMP/log.0"
    "$J288" --config "$E2E_TMP/robot.yaml" hold --duration 0.3 >"$E2E_TMP/out" 2>"$E2E_TMP/err" || return 1
    logged "$E2E_TMP/log.0" ' id=2 status=1 wd=1' || return 1
    local k
    for k in 0 1 2; do : >"$E2E_TMP/log.$k"; done
    "$J288" --config "$E2E_TMP/robot.yaml" stop >"$E2E_TMP/out" 2>&1 || return 1
    grep -q 'broadcast lock sent on 3 of 3 buses' "$E2E_TMP/out" || return 1
    for k in 0 1 2; do logged "$E2E_TMP/log.$k" ' id=15 status=0 wd=0' || return 1; done
}
t_sigint_stops_every_bus() {
    local k pid rc
    timeout --foreground -k 2 60 "$J288" --config "$E2E_TMP/robot.yaml" hold >"$E2E_TMP/out" 2>"$E2E_TMP/err" &
    pid=$!
    for _ in $(seq 1 600); do grep -q 'status=1' "$E2E_TMP/log.2" 2>/dev/null && break; sleep 0.05; done
    for k in 0 1 2; do : >"$E2E_TMP/log.$k"; done
    sleep 0.2
    kill -INT "$pid"
    wait_exit "$pid"; rc=$?
    [ $rc -eq 130 ] || { echo "exit $rc"; return 1; }
    for k in 0 1 2; do logged "$E2E_TMP/log.$k" ' id=15 status=0 wd=0' || return 1; done
}
t_bad_configs() {
    printf 'buses:\n  - {name: a, port: %s}\n  - {name: a, port: /dev/null}\njoints:\n  - {name: j, bus: a, id: 1}\n' \
        "$E2E_TMP/bus.0" >"$E2E_TMP/twice.yaml"
    "$J288" --config "$E2E_TMP/twice.yaml" status >"$E2E_TMP/out" 2>"$E2E_TMP/err"; [ $? -eq 1 ] || return 1
    [ ! -s "$E2E_TMP/out" ] && grep -q "twice.yaml:3" "$E2E_TMP/err" || return 1
    printf 'buses:\n  - {name: a, port: %s}\njoints:\n  - {name: j, bus: a, id: 1}\n  - {name: k, bus: a, id: 1}\n' \
        "$E2E_TMP/bus.0" >"$E2E_TMP/ids.yaml"
    "$J288" --config "$E2E_TMP/ids.yaml" log 2>"$E2E_TMP/err"; [ $? -eq 1 ] && grep -q "ids.yaml:5" "$E2E_TMP/err" || return 1
    printf 'buses:\n  - {name: a, port: /dev/j288-no-such}\njoints:\n  - {name: j, bus: a, id: 1}\n' >"$E2E_TMP/gone.yaml"
    "$J288" --config "$E2E_TMP/gone.yaml" status 2>"$E2E_TMP/err"; [ $? -eq 1 ] || return 1
    grep -q "bus 'a': /dev/j288-no-such" "$E2E_TMP/err" || return 1
    "$J288" --config "$E2E_TMP/robot.yaml" log --rate -1 2>"$E2E_TMP/err"; [ $? -eq 2 ] || return 1
    "$J288" --config "$E2E_TMP/robot.yaml" log --help | grep -q 'every bus and joint'
}
t_dispatch_by_id() {
    # With --id the one-servo command runs (its own errors), not the robot's.
    "$J288" --config "$E2E_TMP/robot.yaml" status --id 99 >"$E2E_TMP/out" 2>"$E2E_TMP/err"; [ $? -eq 2 ] || return 1
    grep -q -- '--id' "$E2E_TMP/err"
}
t_one_bus_stops_answering() {
    # Simulator 2 freezes during a log: the tool names the bus that stopped answering, the
    # other buses' joints stay fresh to the last cycle, the run ends on time and its summary
    # says which bus and joints were left behind; a bus lost is exit 1 (issue 29).
    # (leg2 with a short margin, as a USB adapter's: until it is down, cycles wait for it;
    # leg0 and leg1 with 2 s, a bound that ends with the reply: on a loaded machine their
    # simulators are at times held up past 250 ms, and one missed reply would list their
    # joints as stale in the summary, which the check below rightly counts as a failure)
    local pid rc
    sed -e '/name: leg2,/s/margin_us: 1000000/margin_us: 20000/' \
        -e '/name: leg[01],/s/margin_us: 1000000/margin_us: 2000000/' "$E2E_TMP/robot.yaml" >"$E2E_TMP/stall.yaml"
    "$J288" --config "$E2E_TMP/stall.yaml" log --rate 100 --duration 3 --csv "$E2E_TMP/stall.csv" \
        >"$E2E_TMP/out" 2>"$E2E_TMP/err" &
    pid=$!
    # (frozen once the run's cycles have begun: the start found every joint's angle)
    for _ in $(seq 1 400); do
        [ -f "$E2E_TMP/stall.csv" ] && [ "$(wc -l <"$E2E_TMP/stall.csv")" -gt 30 ] && break
        sleep 0.05
    done
    kill -STOP "$SIM_PID_2"
    wait_exit "$pid"; rc=$?
    kill -CONT "$SIM_PID_2"
    [ $rc -eq 1 ] || { echo "exit $rc"; return 1; }
    grep -q "^j288: bus 'leg2' stopped answering" "$E2E_TMP/err" || return 1
    grep -q "^j288 log: bus 'leg2' lost during the command (exit 1)$" "$E2E_TMP/err" || return 1
    grep -q '^bus leg2: .*, not answering$' "$E2E_TMP/out" && grep -q '^joint leg2_1: ' "$E2E_TMP/out" || return 1
    ! grep -q '^bus leg[01]: .*not answering' "$E2E_TMP/out" || return 1
    # A joint of leg0 or leg1 listed as stale: only for a time-out on its own bus (a loaded
    # machine may starve a simulator past its margin once), or in the one cycle cut at the 1 s
    # limit (a host starved that long: 0.8-1 s was seen beside stress-ng), never for leg2's
    # freeze (which would leave them stale cycle after cycle).
    local cut=0
    grep -Eq '^robot: .*worst cycle (1[0-9]{6}|[2-9][0-9]{6}) us' "$E2E_TMP/out" && cut=1
    for k in 0 1; do
        grep -q "^bus leg$k: .* [1-9][0-9]* timeouts" "$E2E_TMP/out" && continue
        ! grep -Eq "^joint leg${k}_.*stale in ([2-9]|[1-9][0-9]+)$" "$E2E_TMP/out" &&
            { [ $cut -eq 1 ] || ! grep -q "^joint leg${k}_" "$E2E_TMP/out"; } ||
            { echo "leg$k's joints stale without a time-out of their own:"; cat "$E2E_TMP/out"; return 1; }
    done
    # leg0 answered on after leg2's last reply (its last fresh cycle is later); leg2 ends stale.
    last_fresh() {
        awk -F, -v j="$1" 'NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }
            $col["joint"] == j && $col["ok"] == 1 { c = $col["cycle"] } END { print c + 0 }' "$E2E_TMP/stall.csv"
    }
    [ "$(last_fresh leg0_1)" -gt "$(last_fresh leg2_1)" ] &&
        [ "$(grep ',leg2_1,' "$E2E_TMP/stall.csv" | tail -n1 | cut -d, -f3)" = 0 ]
}
t_one_bus_gone() {
    local k
    kill -TERM "$SIM_PID_1"; wait_exit "$SIM_PID_1" >/dev/null
    "$J288" --config "$E2E_TMP/robot.yaml" log --rate 0 --duration 0.5 >"$E2E_TMP/out" 2>"$E2E_TMP/err"
    # The device is gone at open: a clear error naming the bus, exit 1.
    [ $? -eq 1 ] && grep -q "bus 'leg1'" "$E2E_TMP/err" || { echo "log: $(cat "$E2E_TMP/err")"; return 1; }
    # stop still reaches the other buses.
    for k in 0 2; do : >"$E2E_TMP/log.$k"; done
    "$J288" --config "$E2E_TMP/robot.yaml" stop >"$E2E_TMP/out" 2>"$E2E_TMP/err"
    [ $? -eq 1 ] && grep -q 'broadcast lock sent on 2 of 3 buses' "$E2E_TMP/out" &&
        grep -q "^j288 stop: bus 'leg1': " "$E2E_TMP/err" || { echo "stop: $(cat "$E2E_TMP/out" "$E2E_TMP/err")"; return 1; }
    for k in 0 2; do logged "$E2E_TMP/log.$k" ' id=15 status=0 wd=0' || { echo "no lock on leg$k"; return 1; }; done
}

e2e_check status t_status
e2e_check log_csv_json t_log_csv_json
e2e_check hold_and_stop t_hold_and_stop
e2e_check sigint_stops_every_bus t_sigint_stops_every_bus
e2e_check bad_configs t_bad_configs
e2e_check dispatch_by_id t_dispatch_by_id
e2e_check one_bus_stops_answering t_one_bus_stops_answering
e2e_check one_bus_gone t_one_bus_gone
e2e_summary
