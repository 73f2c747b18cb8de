# Helpers for the joint-frame end-to-end scripts (test/e2e/joint_*.sh; sourced, not run): the
# j288 tool against j288-sim, checked against the simulator's --truth file (the true output
# angle theta and rotor phase c of every servo). Sourcing it starts the script: the shared
# libraries, a scratch folder and the EXIT trap that stops every simulator.
# Every process is bounded by timeout and killed by the EXIT trap; waits poll, bounded (times
# scaled by TEST_TIME_SCALE, see lib_e2e.sh); no check depends on the machine's speed (a move
# is given ample time, and the checks are on where it ended).
# shellcheck shell=bash
cd "$(dirname "$0")/../.."
. test/e2e/lib_e2e.sh
e2e_need_python
SIM_DIR=$E2E_TMP
. test/e2e/lib_sim.sh
# (3 retries: a simulator starved past the margin twice in a row, seen at load 18, is not a
# failure of what these scripts check; every check is on where the joint ended)
M=(--margin-us 250000 --retries 3)
# A move's --duration is a bound ("$(e2e_scaled 10)"; 1-2.5 s cut moves short on a loaded
# machine, exit 1); it ends once settled within ARRIVE (rad, rad/s): below the checks' 0.005
# and above the simulator's steady error at the default kp (friction: some 3 mrad).
ARRIVE=(--arrive 0.004)
E2E_CMD_TIMEOUT=60
CMD_TIMEOUT=$(e2e_scaled 60)

trap 'sim_cleanup TERM' EXIT
trap 'exit 130' INT TERM
need_built "$J288" "$SIM"

# start_sim NAME [sim options...]: a simulator on $E2E_TMP/NAME.pty, logging frames to
# NAME.log and its truth to NAME.truth; sets SIM_PID, DEV, TRUTH and SLOG. No SIM_WRAP (no
# timeout wrapper): the signals (SIGWINCH, SIGPWR) must reach the simulator itself.
start_sim() {
    TRUTH=$E2E_TMP/$1.truth
    SLOG=$E2E_TMP/$1.log
    sim_start_linked "$1" --exit-after "$(e2e_scaled 300)" --truth "$TRUTH" "${@:2}"
}

# wait_settled ID: up to 20 s for servo ID's true angle to stop changing.
wait_settled() {
    local prev= cur i
    for i in $(seq 1 "$(e2e_scaled 100)"); do
        truth_now || return 1
        cur=$(truth_val "$1" theta)
        [ -n "$prev" ] && near "$cur" "$prev" 0.000001 >/dev/null && return 0
        prev=$cur
        sleep 0.2
    done
    echo "servo $1 did not come to rest"; return 1
}
# wait_power_on: the truth file says the power cycle is over.
wait_power_on() {
    local i
    for i in $(seq 1 "$(e2e_scaled 400)"); do
        grep -q 'reason=power-on$' "$TRUTH" && return 0
        sleep 0.05
    done
    echo "no power-on"; return 1
}
# jget FILE KEY: a top-level scalar of the tool's one-line JSON, booleans as True/False, empty
# when absent or null (sed, not a python3 start per value: those took a second each on a
# loaded machine). The keys asked for are unique in the object.
jget() {
    sed -n 's/.*"'"$2"'": \([^,}]*\).*/\1/p' "$1" | sed 's/^true$/True/; s/^false$/False/; s/^null$//'
}
# calc EXPR: a number (awk arithmetic).
calc() { awk "BEGIN { printf \"%.12g\\n\", $1 }"; }
# status_json ID [more options]: status --json into $E2E_TMP/st.json.
status_json() {
    local id=$1; shift
    timeout -k 2 "$CMD_TIMEOUT" "$J288" --port "$DEV" status --id "$id" --json "${M[@]}" "$@" >"$E2E_TMP/st.json" 2>"$E2E_TMP/st.err"
}
status_joint() { # NAME CONFIG: status --joint NAME --config CONFIG (the port from the file)
    timeout -k 2 "$CMD_TIMEOUT" "$J288" status --joint "$1" --config "$2" --json "${M[@]}" >"$E2E_TMP/st.json" 2>"$E2E_TMP/st.err" ||
        { echo "status --joint $1: exit $?: $(cat "$E2E_TMP/st.err")"; return 1; }
}
# (watchdog off: a tool starved for 1 s on a loaded machine tripped it mid-move; the checks are
# on where the joint ends, the watchdog has its own tests)
move_joint() { # NAME CONFIG MOVE-OPTIONS...: move --joint NAME --config CONFIG, quiet unless it fails
    local name=$1 cfg=$2; shift 2
    timeout -k 2 "$CMD_TIMEOUT" "$J288" move --joint "$name" --config "$cfg" --watchdog off "${ARRIVE[@]}" "${M[@]}" "$@" >/dev/null 2>"$E2E_TMP/mv.err" ||
        { echo "move --joint $name $*: exit $?: $(cat "$E2E_TMP/mv.err")"; return 1; }
}
foc_frames() { grep -c "id=$1 status=1 " "$SLOG"; }
# config NAME BODY...: a robot config on this simulator's bus with one joint (BODY lines).
config() {
    local f=$E2E_TMP/$1.yaml; shift
    { echo "# robot for the joint tests"
      echo "buses:"
      echo "  - name: main            # the simulator"
      echo "    port: $DEV"
      echo "    margin_us: 250000"
      echo "joints:"
      local l; for l in "$@"; do echo "$l"; done; } >"$f"
    echo "$f"
}

# Each check runs in this shell (the expect_bad inside count themselves); its own messages go
# to a file and become the failure's reason.
run_check() { # NAME FUNCTION ARGS...
    local name=$1; shift
    if "$@" >"$E2E_TMP/check.out" 2>&1; then
        grep -E "^$E2E_NAME:" "$E2E_TMP/check.out"
        e2e_pass "$name"
    else
        grep -E "^$E2E_NAME:" "$E2E_TMP/check.out"
        e2e_fail "$name" "$(grep -Ev "^$E2E_NAME:" "$E2E_TMP/check.out" | head -c 1500)"
    fi
}
