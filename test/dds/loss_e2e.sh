#!/usr/bin/env bash
# Issue 29 through j288-dds, in a private network namespace (lib_dds.sh): two j288-sim buses of
# three servos each on links, the bridge, test/dds/dds_peer. Checked: SIGHUP locks every bus
# and exits 0 (2af1ea0: killed, 129, nothing sent); a bus whose simulator exits publishes NaN
# for its joints (the other bus its true angles) and rt/diagnostics names it and when; the
# simulator started again at the same --link is reopened, its joints published again at the
# new simulator's true angles, and a command moves one; every bus gone: the bridge stays up,
# publishing NaN and saying so, and takes a bus back; with --exit-when-gone it exits 1.
# Every wait polls and is bounded.
set -u
cd "$(dirname "$0")/../.."
. test/dds/lib_dds.sh
dds_netns "$0" "$@"
dds_e2e_setup

SIM_OPTS=(--exit-after 300)
start_sims 2 "${SIM_OPTS[@]}" --truth "$SIM_DIR/truth.{k}" --log "$SIM_DIR/log.{k}"
robot_config 2 "$SIM_DIR/robot.yaml" 250000 20 1

# restart_sim K [sim options]: simulator K again at its link (its truth and log anew).
restart_sim() {
    local k=$1; shift
    rm -f "$SIM_DIR/pty.$k"
    "$SIM" --ids 1,2,3 --quiet --link "$SIM_DIR/bus.$k" "${SIM_OPTS[@]}" --truth "$SIM_DIR/truth.$k" \
        --log "$SIM_DIR/log.$k" "$@" >"$SIM_DIR/pty.$k" 2>/dev/null &
    SIM_PIDS+=($!)
    eval "SIM_PID_$k=$!"
    for _ in $(seq 1 "$(e2e_scaled 600)"); do
        [ -s "$SIM_DIR/pty.$k" ] && [ -L "$SIM_DIR/bus.$k" ] && return 0
        sleep 0.05
    done
    echo "simulator $k did not start again"; return 1
}
kill_sim() { local p; eval "p=\$SIM_PID_$1"; stop_sim "$p"; }
# both_sims: each simulator running (one an earlier check left stopped started again), so that
# a check that failed midway does not fail the next ones.
both_sims() {
    local k p
    for k in 0 1; do
        eval "p=\$SIM_PID_$k"
        own_child "$p" && [ -L "$SIM_DIR/bus.$k" ] || restart_sim "$k" || return 1
    done
}
# value JOINT: its published angle in the latest $SIM_DIR/states.
value() { awk -v n="$1" '$1 == n { print $2 }' "$SIM_DIR/states"; }
# wait_states TEST: up to 20 s (scaled) for a joint_states sample for which TEST (a function
# over $SIM_DIR/states) holds.
wait_states() {
    for _ in $(seq 1 "$(e2e_scaled 40)"); do
        "$PEER" states --timeout 1 >"$SIM_DIR/states" 2>/dev/null && "$1" && return 0
        sleep 0.2
    done
    echo "no such state ($1):"; cat "$SIM_DIR/states"; return 1
}
leg1_nan() { [ "$(grep -c '^leg1_[123] nan nan nan$' "$SIM_DIR/states")" -eq 3 ]; }
leg0_numbers() { ! grep -q '^leg0_.*nan' "$SIM_DIR/states" && grep -q '^leg0_1 ' "$SIM_DIR/states"; }
lost_leg1() { leg1_nan && leg0_numbers; }
all_nan() { [ "$(grep -c '^leg[01]_[123] nan nan nan$' "$SIM_DIR/states")" -eq 6 ]; }
leg1_back() { ! grep -q '^leg1_.*nan' "$SIM_DIR/states" && grep -q '^leg1_1 ' "$SIM_DIR/states"; }

t_sighup_locks() {
    local rc
    both_sims || return 1
    start_bridge || return 1
    : >"$SIM_DIR/log.0"; : >"$SIM_DIR/log.1"
    kill -HUP "$BRIDGE_PID"
    wait_exit "$BRIDGE_PID" 30; rc=$?
    [ $rc -eq 0 ] || { echo "exit $rc (want 0)"; return 1; }
    locked_all 0 1 && grep -q 'SIGHUP: every bus locked' "$SIM_DIR/bridge.err"
}
t_lost_bus_is_nan_and_comes_back() {
    local got want
    both_sims || return 1
    start_bridge || return 1
    kill_sim 1
    wait_err "bus 'leg1' vanished" 20 || return 1
    wait_states lost_leg1 || return 1
    wait_diag '^status j288-dds: bus leg1|2|gone: its device vanished at 20[0-9-]*T[0-9:.]*Z' \
        '^j288-dds: bus leg1|lost_at=20[0-9-]*T[0-9:.]*Z$' \
        '^status j288-dds: bridge|2|bus leg1 vanished at 20.*: its joints publish NaN$' || return 1
    restart_sim 1 --start-angle 1:0.7 || return 1
    wait_err "bus 'leg1' is back" 20 || return 1
    wait_states leg1_back || return 1
    got=$(value leg1_1); want=$(truth 1 1) || return 1
    near "$got" "$want" 0.002 && near "$got" 0.7 0.01 || { echo "leg1_1 published $got, true $want"; return 1; }
    wait_diag '^j288-dds: bus leg1|reopens=1$' || return 1
    "$PEER" command --for 30 --hz 50 leg1_1 0.4 - - & local p=$!
    wait_truth 1 1 0.4 20; local rc=$?
    kill $p 2>/dev/null; wait $p 2>/dev/null
    [ $rc -eq 0 ] && stop_bridge
}
t_every_bus_gone_stays_up() {
    both_sims || return 1
    start_bridge || return 1
    kill_sim 0; kill_sim 1
    wait_err 'every bus is gone: the bridge stays up' 20 || return 1
    kill -0 "$BRIDGE_PID" 2>/dev/null || { echo "the bridge exited: $(cat "$SIM_DIR/bridge.err")"; return 1; }
    wait_states all_nan || return 1
    wait_diag '^status j288-dds: bridge|2|every bus is gone' || return 1
    restart_sim 1 || return 1
    wait_err "bus 'leg1' is back" 20 && wait_states leg1_back || return 1
    restart_sim 0 || return 1
    wait_err "bus 'leg0' is back" 20 && stop_bridge
}
t_exit_when_gone() {
    local rc
    both_sims || return 1
    start_bridge --exit-when-gone || return 1
    kill_sim 1; kill_sim 0
    wait_exit "$BRIDGE_PID" 30; rc=$?
    [ $rc -eq 1 ] && grep -q 'every bus is gone (--exit-when-gone)' "$SIM_DIR/bridge.err" ||
        { echo "exit $rc: $(cat "$SIM_DIR/bridge.err")"; return 1; }
}

e2e_check sighup_locks t_sighup_locks
e2e_check lost_bus_is_nan_and_comes_back t_lost_bus_is_nan_and_comes_back
e2e_check every_bus_gone_stays_up t_every_bus_gone_stays_up
e2e_check exit_when_gone t_exit_when_gone
e2e_summary
