#!/usr/bin/env bash
# j288 top against j288-sim, on a real terminal: tmux runs it in a detached session on a
# private server (-L), capture-pane reads the screen, send-keys presses q and Ctrl-C. Checked:
# every joint's row (angle, temperatures, a fault by name, a silent joint), the bus counters,
# the screen refreshing (the cycle count grows), q and Ctrl-C ending it (exit 0 / 130) with
# the broadcast lock logged by the simulator after the key, one plain frame without a terminal
# (a pipe, --once), the bus form (--port: the servos that answer), and bad arguments.
# tmux missing: the checks that need it are skipped with a notice, unless CI=true (then they
# fail: scripts/ci-install.sh installs tmux). Run from the repo root with BIN set (make test
# does). Waits poll, bounded; nothing depends on the machine's speed.
set -u
cd "$(dirname "$0")/../.."
. test/e2e/lib_e2e.sh
SIM_DIR=$E2E_TMP
. test/e2e/lib_sim.sh
# Each session gets a server of its own (socket j288-top-PID-N): a session started while the
# last one's server was still exiting met "server exited unexpectedly" on a loaded machine.
TOP_N=0
TMUX_SOCK=j288-top-$$-$TOP_N
tmux_do() { tmux -L "$TMUX_SOCK" -f /dev/null "$@"; }
cleanup() {
    local n
    [ "$BASHPID" = "$$" ] || return 0
    if command -v tmux >/dev/null; then
        for n in $(seq 0 "$TOP_N"); do
            tmux -L "j288-top-$$-$n" kill-server 2>/dev/null
            rm -f "${TMUX_TMPDIR:-/tmp}/tmux-$(id -u)/j288-top-$$-$n"
        done
    fi
    sim_cleanup TERM
}
trap cleanup EXIT
need_built "$J288" "$SIM"

sim_start_linked top --ids 1,2 --quiet --exit-after "$(e2e_scaled 120)" --fault 2:0x200 || exit 1
CFG=$E2E_TMP/robot.yaml
printf 'buses:\n  - {name: left, port: %s, margin_us: 250000}\njoints:\n  - {name: hip, id: 1}\n  - {name: knee, id: 2}\n  - {name: ankle, id: 7}\n' \
    "$DEV" >"$CFG"

# broadcasts: the simulator's count of broadcast locks so far.
broadcasts() { grep -c ' id=15 status=0 ' "$SIM_DIR/top.log"; }
# wait_broadcast N: up to 20 s for more than N broadcast locks.
wait_broadcast() {
    for _ in $(seq 1 400); do [ "$(broadcasts)" -gt "$1" ] && return 0; sleep 0.05; done
    echo "no broadcast lock after the key"; return 1
}

# ---- without a terminal -----------------------------------------------------------------------
t_pipe_one_frame() {
    "$J288" top --config "$CFG" >"$E2E_TMP/out" 2>"$E2E_TMP/err" || { cat "$E2E_TMP/err"; return 1; }
    grep -Eq '^hip +left +1 \* +-?[0-9]+\.[0-9]{4} ' "$E2E_TMP/out" &&
        grep -Eq '^knee +left +2 \* .* winding over-temperature$' "$E2E_TMP/out" &&
        grep -Eq '^ankle +left +7 - +silent$' "$E2E_TMP/out" &&
        grep -Eq '^left +up +[0-9]+ ' "$E2E_TMP/out" || { cat "$E2E_TMP/out"; return 1; }
    ! grep -q $'\033' "$E2E_TMP/out" || { echo "escape codes in a pipe"; return 1; }
    # The port's notices (a pty refuses low-latency mode) on stderr, not in the frame; none
    # under J288_QUIET=1 (the harness sets it).
    [ ! -s "$E2E_TMP/err" ] || { echo "stderr under J288_QUIET: $(cat "$E2E_TMP/err")"; return 1; }
    env -u J288_QUIET "$J288" top --config "$CFG" >"$E2E_TMP/out" 2>"$E2E_TMP/err" || return 1
    grep -q '^note: .*low-latency mode not available' "$E2E_TMP/err" &&
        ! grep -q '^note: ' "$E2E_TMP/out" || { cat "$E2E_TMP/err"; return 1; }
}
t_port_form() {
    # (the servos present and one absent, each looked for once at the start: a 1 s margin, as
    # every exchange that must succeed here; 250 ms missed servo 1 beside stress-ng --cpu 2)
    "$J288" top --port "$DEV" --ids 1,2,5 --once --margin-us 1000000 >"$E2E_TMP/out" 2>"$E2E_TMP/err" ||
        { cat "$E2E_TMP/err"; return 1; }
    [ "$(grep -Ec '^id[0-9]+ ' "$E2E_TMP/out")" -eq 2 ] && grep -Eq '^id1 +bus +1 \* ' "$E2E_TMP/out" &&
        grep -Eq '^id2 +bus +2 \* ' "$E2E_TMP/out" || { cat "$E2E_TMP/out"; return 1; }
}
run_t() { if "$2" >"$E2E_TMP/t.out" 2>&1; then e2e_pass "$1"; else e2e_fail "$1" "$(head -c 1500 "$E2E_TMP/t.out")"; fi; }
run_t pipe_one_frame t_pipe_one_frame
run_t port_form t_port_form
expect_bad no_bus 2 '^j288 top: no bus: give --config FILE or --port DEV' env -u J288_PORT "$J288" top
expect_bad json_refused 2 '^j288 top: --json: top draws a screen' "$J288" top --config "$CFG" --json
expect_bad bad_rate 2 '^j288 top: --rate: 0 is out of range' "$J288" top --config "$CFG" --rate 0
expect_bad no_servo 1 '^j288 top: no servo answered on ' "$J288" top --port "$DEV" --ids 9 --once --margin-us 20000

# ---- on a terminal (tmux) ---------------------------------------------------------------------
if ! command -v tmux >/dev/null; then
    if [ "${CI:-}" = true ]; then
        e2e_fail tmux "tmux is not installed (scripts/ci-install.sh installs it)"
    else
        echo "cli_top: tmux not installed: the terminal checks are skipped (apt-get install tmux)"
    fi
    e2e_summary
    exit $?
fi

# start_top: j288 top in a fresh tmux session; its exit status goes to top.rc.
start_top() {
    rm -f "$E2E_TMP/top.rc"
    TOP_N=$((TOP_N + 1))
    TMUX_SOCK=j288-top-$$-$TOP_N
    tmux_do new-session -d -s top -x 150 -y 30 \
        "env -u J288_QUIET '$J288' top --config '$CFG' --interval 0.1 --rate 50; echo \$? >'$E2E_TMP/top.rc'"
}
screen() { tmux_do capture-pane -p -t top 2>/dev/null; }
# wait_screen REGEX: up to 30 s for the screen to show a line matching REGEX.
wait_screen() {
    for _ in $(seq 1 600); do screen | grep -Eq -- "$1" && return 0; sleep 0.05; done
    echo "never on screen: /$1/"; screen; return 1
}
cycle_now() { screen | sed -n 's/^j288 top .* cycle \([0-9]*\) .*/\1/p'; }
skipped_now() { screen | sed -n 's/^timing: .* \([0-9]*\) periods skipped.*/\1/p'; }
# top_stall: SIGSTOP j288 top (the pane's shell's child) for 0.5 s.
top_stall() {
    local pane pid
    pane=$(tmux_do display -p -t top '#{pane_pid}')
    pid=$(cat "/proc/$pane/task/$pane/children" 2>/dev/null)
    pid=${pid%% *}
    [ -n "$pid" ] || { echo "j288 top's pid not found"; return 1; }
    kill -STOP "$pid"; sleep 0.5; kill -CONT "$pid"
}
# wait_rc WANT: up to 30 s for top to exit, with status WANT.
wait_rc() {
    for _ in $(seq 1 600); do [ -s "$E2E_TMP/top.rc" ] && break; sleep 0.05; done
    [ "$(cat "$E2E_TMP/top.rc" 2>/dev/null)" = "$1" ] || { echo "exit '$(cat "$E2E_TMP/top.rc" 2>/dev/null)', want $1"; return 1; }
}

t_live_screen_and_q() {
    local c1 c2 before skipped_before
    start_top
    wait_screen '^hip +left +1 \* +-?[0-9]+\.[0-9]{4} +-?[0-9.]+ +-?[0-9.]+ +25\.0 +[0-9]+\.[0-9] +24\.0 ' || return 1
    wait_screen '^knee +left +2 \* .* winding over-temperature$' || return 1
    wait_screen '^ankle +left +7 - +silent$' || return 1
    wait_screen '^left +up +[0-9]+ +[0-9]+ ' || return 1
    wait_screen 'q or Ctrl-C quits' || return 1
    wait_screen '^note: .*low-latency mode not available' || return 1 # the port's notices, on screen
    # Redrawn in place: the cycle count grows, the header stays on the first line.
    c1=$(cycle_now)
    for _ in $(seq 1 600); do c2=$(cycle_now); [ -n "$c2" ] && [ "$c2" -gt "${c1:-0}" ] && break; sleep 0.05; done
    [ -n "$c2" ] && [ "$c2" -gt "${c1:-0}" ] || { echo "cycle $c1 -> $c2: not refreshed"; return 1; }
    screen | head -n1 | grep -q '^j288 top ' || { echo "header not on top"; screen; return 1; }
    # The loop's timing (docs/realtime.md): on screen, and a stall provoked (the tool stopped
    # for 0.5 s, 25 periods at 50 Hz) counted there: a deadline missed, periods skipped.
    wait_screen '^timing: [0-9]+ cycles at 50 Hz \(normal priority\): ' || return 1
    wait_screen '^timing: wake-up lateness p50 [0-9]+ us, p99 [0-9]+ us, p99.9 [0-9]+ us, max ' || return 1
    wait_screen '^timing: cycle duration p50 [0-9]+ us, ' || return 1
    skipped_before=$(skipped_now)
    top_stall || return 1
    for _ in $(seq 1 600); do
        [ "$(skipped_now)" -ge $((${skipped_before:-0} + 10)) ] && break; sleep 0.05
    done
    [ "$(skipped_now)" -ge $((${skipped_before:-0} + 10)) ] ||
        { echo "the stall's periods not skipped: ${skipped_before:-?} -> $(skipped_now)"; screen; return 1; }
    before=$(broadcasts)
    tmux_do send-keys -t top q
    wait_rc 0 && wait_broadcast "$before"
}
t_ctrl_c() {
    local before
    start_top
    wait_screen '^hip +left +1 \* ' || return 1
    before=$(broadcasts)
    tmux_do send-keys -t top C-c
    wait_rc 130 && wait_broadcast "$before"
}
run_t live_screen_and_q t_live_screen_and_q
run_t ctrl_c t_ctrl_c
e2e_summary
