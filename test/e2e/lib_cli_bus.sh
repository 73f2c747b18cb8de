# Sourced by cli_bus.sh and cli_bus_faults.sh: the bus commands' end-to-end tests share the
# simulator, the reply margins and the checks below. Nothing here depends on the machine's
# speed (CI runs them on a loaded 2-core machine, and `make test-valgrind` under valgrind): a
# command that must get replies from a healthy servo runs with a reply margin of $BIG_MARGIN
# us (a miss then means a fault, not a slow host); checks count replies and frames, never
# time taken; waits poll for what they expect, bounded.
. test/e2e/lib_e2e.sh
e2e_need_python
SIM_DIR=$E2E_TMP
. test/e2e/lib_sim.sh
# A bound for a simulator left behind, never reached while the script runs: the script's own
# limit (300 s, scaled). A fixed 120 s ended the main simulator mid-script under memcheck on a
# loaded machine ("no such device" from port_in_use on).
SIM_WRAP=(timeout -k 2 "$(e2e_scaled 300)")
# (1 s: beside stress-ng --cpu 2 the simulator went unscheduled for 0.3-1.6 s at times, and a
# 250 ms margin failed a command's start-up read; it costs nothing where the reply comes.)
BIG_MARGIN=1000000
M=(--margin-us "$BIG_MARGIN")
# Where the simulator drops replies on purpose, each drop costs a margin: 250 ms there.
MF=(--margin-us 250000)
# Where absent ids are asked too (log's probe sweeps), each miss costs a margin: 50 ms where a
# retry is allowed for. A scan that must find every servo gets the 1 s margin, no retry, and
# only ids 0-4 (two absent: 2 s): a loaded machine starved the simulator past both tries of
# 50 ms, past a single 250 ms, and (once in ten loaded runs) past 500 ms, while 500 ms for
# all 12 absent ids of the default range already cost 6 s a scan.
M50=(--margin-us 50000)
MSCAN=(--ids 0,1,2,3,4 --margin-us "$BIG_MARGIN" --retries 0)

trap 'sim_cleanup TERM' EXIT
trap 'exit 130' INT TERM
need_built "$J288" "$SIM"

# start_sim NAME [sim options...]: a quiet simulator serving on $E2E_TMP/NAME.pty, logging
# received commands to $E2E_TMP/NAME.log; sets SIM_PID and DEV.
start_sim() { sim_start_linked "$1" --quiet "${@:2}"; }

# json_check NAME PYTHON_EXPR: evaluate a Python assertion block on $E2E_OUT (parsed as o).
json_check() {
    local name=$1 code=$2
    if [ "$E2E_RC" -ne 0 ]; then
        e2e_fail "$name" "exit $E2E_RC: $E2E_ERR"
        return
    fi
    if printf '%s' "$E2E_OUT" | python3 -c "
import json, sys
o = json.load(sys.stdin)
$code" >"$E2E_TMP/chk" 2>&1; then
        e2e_pass "$name"
    else
        e2e_fail "$name" "$(tail -n 3 "$E2E_TMP/chk") -- output: ${E2E_OUT:0:300}"
    fi
}

# wait_for_log FILE REGEX [SECONDS [FROM_LINE]]: until a line of the simulator log after
# line FROM_LINE (default 0) matches (default bound 20 s; returns as soon as one does).
wait_for_log() {
    local i n=$(( ${3:-20} * 20 )) from=${4:-0}
    for i in $(seq 1 $n); do
        tail -n +$((from + 1)) "$1" 2>/dev/null | grep -Eq "$2" && return 0
        sleep 0.05
    done
    return 1
}
log_lines() { grep -c '' "$1" 2>/dev/null || echo 0; }

