#!/usr/bin/env bash
# The scripts' process helpers (lib_sim.sh) themselves: only a live child of the script is
# ever signalled (a reaped child's pid may already be another program's), and the EXIT
# cleanup run by a subshell that a signal killed leaves the script's files and processes.
# Run from the repo root with BIN set (make test does).
set -u
. test/e2e/lib_e2e.sh
SIM_DIR=$E2E_TMP
. test/e2e/lib_sim.sh
trap 'sim_cleanup KILL' EXIT

# alive PID: PID exists and has not ended (a zombie waiting for its reaper has).
alive() {
    local stat
    { read -r stat <"/proc/$1/stat"; } 2>/dev/null || return 1
    stat=${stat##*) }
    [ "${stat%% *}" != Z ]
}

t_own_child() {
    sleep 30 &
    local live=$!
    BG_PIDS+=("$live")
    sleep 0 &
    local gone=$!
    wait "$gone"
    own_child "$live" || { echo "a running child is not recognised"; return 1; }
    ! own_child "$gone" || { echo "a reaped child is taken for ours"; return 1; }
    ! own_child "$PPID" || { echo "the parent is taken for a child"; return 1; }
    ! own_child 1 || { echo "init is taken for a child"; return 1; }
}
t_stop_pids_spares_others() {
    sleep 30 & # stands for another script's process: a child of a subshell, not of ours
    local mine=$! other
    BG_PIDS+=("$mine")
    other=$(sleep 30 >/dev/null 2>&1 & echo $!)
    stop_pids TERM "$other" "$mine"
    alive "$other" || { echo "another process was signalled"; return 1; }
    kill -TERM "$other"
    ! alive "$mine" || { echo "our own child was not stopped"; return 1; }
}
t_cleanup_in_a_subshell() {
    touch "$SIM_DIR/keep"
    (sim_cleanup KILL)
    (sleep 5) & local sub=$! # a subshell killed by a signal runs the EXIT trap itself
    sleep 0.2; kill -TERM "$sub"; wait "$sub"
    [ -f "$SIM_DIR/keep" ] || { echo "a subshell's cleanup removed the script's files"; return 1; }
}

e2e_check own_child t_own_child
e2e_check stop_pids_spares_others t_stop_pids_spares_others
e2e_check cleanup_in_a_subshell t_cleanup_in_a_subshell
e2e_summary
