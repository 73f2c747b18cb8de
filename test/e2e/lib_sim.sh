# Helpers for the scripts that drive j288-sim (sourced, not run): start simulators (each
# remembered in SIM_PIDS), stop them and clean up, wait for a process to end, and write a robot config
# over several simulators. The script sets BIN (where the binaries are) and SIM_DIR (a scratch
# folder) before sourcing; J288_SIM may name another simulator binary (make test-valgrind
# points it at test/e2e/valgrind-wrap.sh). Every wait polls and is bounded.
# shellcheck shell=bash

SIM=${J288_SIM:-$BIN/j288-sim}
SIM_PIDS=()
BG_PIDS=() # other processes the script starts in the background, stopped with the simulators
SIM_WRAP=() # a command prefix for sim_start_linked's simulators (e.g. timeout ...); none by default

# own_child PID: whether PID is still a child of this shell. A process of ours that has ended
# has been reaped, and its pid may already name another program's process (pids wrap within
# minutes while the tests run in parallel): that one must never be signalled.
own_child() {
    local stat
    { read -r stat <"/proc/$1/stat"; } 2>/dev/null || return 1
    stat=${stat##*) } # after the command name: state, then the parent's pid
    set -- $stat
    [ "${2:-}" = "$BASHPID" ]
}

# stop_pids SIGNAL PID...: send SIGNAL to every PID still a child of this shell, then reap
# them all. Always succeeds (an EXIT trap under set -e must get to its end).
stop_pids() {
    local sig=$1 p; shift
    for p in "$@"; do own_child "$p" && { kill -s "$sig" "$p" 2>/dev/null || true; }; done
    for p in "$@"; do wait "$p" 2>/dev/null || true; done
}

# sim_cleanup SIGNAL: for the script's EXIT trap: SIGNAL to every process in BG_PIDS and
# SIM_PIDS, all reaped, and SIM_DIR removed. Bash also runs the EXIT trap in a subshell killed
# by a signal: there it does nothing, so the script goes on with its files.
sim_cleanup() {
    [ "$BASHPID" = "$$" ] || return 0
    stop_pids "$1" "${BG_PIDS[@]}" "${SIM_PIDS[@]}"
    rm -rf "$SIM_DIR"
}

# need_built FILE...: exit 1, naming it, when a FILE is not an executable (not built yet).
need_built() {
    local f
    for f in "$@"; do
        [ -x "$f" ] || { echo "$f not built"; exit 1; }
    done
}

# stop_sim [PID]: SIGTERM to PID (default: the last simulator started) and its exit status.
stop_sim() {
    local p=${1:-$SIM_PID}
    own_child "$p" && kill -TERM "$p" 2>/dev/null
    wait "$p" 2>/dev/null
}

# wait_exit PID [SECONDS]: wait up to SECONDS (default 30) for PID to exit, returning as soon
# as it does; its exit status, or 124 on time-out.
wait_exit() {
    for _ in $(seq 1 $(e2e_scaled $((${2:-30} * 20)))); do
        if ! kill -0 "$1" 2>/dev/null; then wait "$1"; return $?; fi
        sleep 0.05
    done
    return 124
}

# sim_start_linked NAME [sim options...]: a simulator (under SIM_WRAP) serving on
# $SIM_DIR/NAME.pty, logging received commands to $SIM_DIR/NAME.log; sets SIM_PID and DEV.
# Fails, saying why, when it has not started within 30 s (a loaded machine, or valgrind).
sim_start_linked() {
    local name=$1; shift
    DEV=$SIM_DIR/$name.pty
    "${SIM_WRAP[@]}" "$SIM" --link "$DEV" --log "$SIM_DIR/$name.log" "$@" \
        >"$SIM_DIR/$name.out" 2>"$SIM_DIR/$name.err" &
    SIM_PID=$!
    SIM_PIDS+=("$SIM_PID")
    for _ in $(seq 1 "$(e2e_scaled 600)"); do
        [ -L "$DEV" ] && [ -s "$SIM_DIR/$name.out" ] && return 0
        sleep 0.05
    done
    echo "simulator $name did not start: $(cat "$SIM_DIR/$name.err")"
    return 1
}

# start_sims N [sim options...]: simulators 0..N-1 with servos 1, 2, 3, each serving on the
# link $SIM_DIR/bus.K (its pty path in $SIM_DIR/pty.K), its pid in SIM_PID_K; "{k}" in an
# option stands for K (--log "$d/log.{k}"). Waits (up to 30 s each) for the links. (Configs
# name the link: a simulator that exits removes it, where its /dev/pts number goes to the
# next pty opened, another test's simulator's when tests run side by side.)
start_sims() {
    local n=$1 k; shift
    for k in $(seq 0 $((n - 1))); do
        "$SIM" --ids 1,2,3 --quiet --link "$SIM_DIR/bus.$k" "${@//\{k\}/$k}" >"$SIM_DIR/pty.$k" 2>/dev/null &
        SIM_PIDS+=($!)
        eval "SIM_PID_$k=$!"
    done
    for k in $(seq 0 $((n - 1))); do
        for _ in $(seq 1 "$(e2e_scaled 600)"); do
            [ -s "$SIM_DIR/pty.$k" ] && [ -L "$SIM_DIR/bus.$k" ] && break
            sleep 0.05
        done
    done
}

# robot_config N FILE MARGIN_US KP KD: a robot config of the first N simulators of start_sims,
# bus legK on simulator K with joints legK_1..3 (servos 1, 2, 3) and the given gains.
robot_config() {
    local n=$1 k j
    { echo "buses:"
      for k in $(seq 0 $((n - 1))); do
          echo "  - {name: leg$k, port: $SIM_DIR/bus.$k, margin_us: $3}"
      done
      echo "joints:"
      for k in $(seq 0 $((n - 1))); do
          for j in 1 2 3; do echo "  - {name: leg${k}_$j, bus: leg$k, id: $j, kp: $4, kd: $5}"; done
      done; } >"$2"
}

# The simulator's truth (--truth FILE): TRUTH names the file, SIM_PID the simulator.
truth_seq() { sed -n '1s/^# j288-sim truth seq=\([0-9]*\) .*/\1/p' "$TRUTH" 2>/dev/null; }
# truth_now: ask the simulator for its truth (SIGWINCH) and wait until it is written.
truth_now() {
    local seq i
    seq=$(truth_seq)
    kill -s WINCH "$SIM_PID"
    for i in $(seq 1 "$(e2e_scaled 400)"); do
        [ "$(truth_seq)" != "$seq" ] && return 0
        sleep 0.05
    done
    echo "no truth written"; return 1
}
# truth_val ID KEY: the value of KEY on servo ID's line of the truth file.
truth_val() {
    awk -v id="$1" -v key="$2" '$1 == "id=" id {
        for (i = 2; i <= NF; i++) { n = index($i, "="); if (substr($i, 1, n - 1) == key) print substr($i, n + 1) } }' "$TRUTH"
}
# near A B TOL [PERIOD]: |A - B| <= TOL, modulo PERIOD when given (angles); a value that is
# not a number fails.
near() {
    awk -v a="$1" -v b="$2" -v tol="$3" -v p="${4:-0}" 'BEGIN {
        num = "^[-+]?([0-9]+[.]?[0-9]*|[.][0-9]+)([eE][-+]?[0-9]+)?$"
        if (a !~ num || b !~ num) exit 1
        d = a - b
        if (p > 0) { k = d / p; d -= p * (k >= 0 ? int(k + 0.5) : -int(-k + 0.5)) }
        exit !(d <= tol && -d <= tol) }' || { echo "|$1 - $2| > $3${4:+ (mod $4)}"; return 1; }
}
TWO_PI=6.283185307179586
