#!/usr/bin/env bash
# j288 top against j288-sim, on a real terminal: tmux runs it in a detached session on a
# private server (-L), capture-pane reads the screen, send-keys presses q and Ctrl-C. Checked:
# every joint's row (angle, temperatures, a fault by name, a silent joint), the bus counters,
# the screen refreshing (the cycle count grows), q and Ctrl-C ending it (exit 0 / 130) with
# the broadcast lock logged by the simulator after the key, one plain frame without a terminal
# (a pipe, --once), the bus form (--port or $J288_PORT: the servos that answer), a 40-column
# terminal (lines cut, never wrapped), --plot (braille on screen, v switching it), and bad
# arguments. The tmux plumbing is lib_tmux.sh's (tmux missing: those checks are skipped with a
# notice, unless CI=true). Run from the repo root with BIN set (make test does).
set -u
cd "$(dirname "$0")/../.."
. test/e2e/lib_e2e.sh
SIM_DIR=$E2E_TMP
. test/e2e/lib_sim.sh
TMUX_NAME=top
. test/e2e/lib_tmux.sh
trap 'tmux_cleanup; sim_cleanup TERM' EXIT
need_built "$J288" "$SIM"

sim_start_linked top --ids 1,2 --quiet --exit-after "$(e2e_scaled 120)" --fault 2:0x200 || exit 1
CFG=$E2E_TMP/robot.yaml
printf 'buses:\n  - {name: left, port: %s, margin_us: 250000}\njoints:\n  - {name: hip, id: 1}\n  - {name: knee, id: 2}\n  - {name: ankle, id: 7}\n' \
    "$DEV" >"$CFG"
# (the same without the silent ankle, whose reply deadline would slow every cycle down)
CFG2=$E2E_TMP/robot2.yaml
head -n 5 "$CFG" >"$CFG2"

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
t_port_from_env() {
    # $J288_PORT, as its own error says (2af1ea0 said "no bus" with it set)
    J288_PORT=$DEV "$J288" top --ids 1,2 --once --margin-us 1000000 >"$E2E_TMP/out" 2>"$E2E_TMP/err" ||
        { cat "$E2E_TMP/err"; return 1; }
    grep -Eq '^id1 +bus +1 \* ' "$E2E_TMP/out" || { cat "$E2E_TMP/out"; return 1; }
}
run_t() { if "$2" >"$E2E_TMP/t.out" 2>&1; then e2e_pass "$1"; else e2e_fail "$1" "$(head -c 1500 "$E2E_TMP/t.out")"; fi; }
run_t pipe_one_frame t_pipe_one_frame
run_t port_form t_port_form
run_t port_from_env t_port_from_env
expect_bad no_bus 2 '^j288 top: no bus: give --config FILE or --port DEV' env -u J288_PORT "$J288" top
expect_bad json_refused 2 '^j288 top: --json: top draws a screen' "$J288" top --config "$CFG" --json
expect_bad bad_rate 2 '^j288 top: --rate: 0 is out of range' "$J288" top --config "$CFG" --rate 0
expect_bad no_servo 1 '^j288 top: no servo answered on ' "$J288" top --port "$DEV" --ids 9 --once --margin-us 20000

# ---- on a terminal (tmux) ---------------------------------------------------------------------
tmux_need

# start_top [COLS [CONFIG [ARGS]]]: j288 top in a fresh tmux session (150 columns, or COLS) on
# CONFIG (default $CFG), with ARGS.
start_top() {
    tmux_start "${1:-150}" 30 "env -u J288_QUIET '$J288' top --config '${2:-$CFG}' --interval 0.1 --rate 50 ${3:-}"
}
cycle_now() { screen | sed -n 's/^j288 top .* cycle \([0-9]*\) .*/\1/p'; }
LOG=$SIM_DIR/top.log

t_live_screen_and_q() {
    local c1 c2 before
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
    before=$(broadcasts "$LOG")
    press q
    wait_rc 0 && wait_broadcast "$LOG" "$before"
}
t_ctrl_c() {
    local before
    start_top
    wait_screen '^hip +left +1 \* ' || return 1
    before=$(broadcasts "$LOG")
    press C-c
    wait_rc 130 && wait_broadcast "$LOG" "$before"
}
t_narrow_terminal() {
    # 40 columns: every line cut there, never wrapped (2af1ea0 wrapped each row over three
    # lines, pushing the header off the screen)
    start_top 40 "$CFG2"
    wait_screen '^hip +left +1 \* ' || return 1
    narrow_screen_ok 40 'j288 top ' 'hip ' 'knee ' || return 1
    press q
    wait_rc 0
}
t_live_plot() {
    # --plot: the joints' angles in braille below the table; v: speed, torque, angle
    start_top 150 "$CFG2" "--plot hip,knee"
    wait_screen '^plot: angle, rad of hip knee' || return 1
    # (a braille cell, U+2801-U+28FF, is e2 a0-a3 xx in UTF-8: matched as bytes)
    LC_ALL=C wait_screen $'^ +-?[0-9]+\\.[0-9]{4} \\|.*\xe2[\xa0-\xa3]' || return 1
    press v
    wait_screen '^plot: speed, rad/s of hip knee' || return 1
    press v
    wait_screen '^plot: torque, N\*m of hip knee' || return 1
    press q
    wait_rc 0
}
run_t live_screen_and_q t_live_screen_and_q
run_t ctrl_c t_ctrl_c
run_t narrow_terminal t_narrow_terminal
run_t live_plot t_live_plot
expect_bad plot_unknown_joint 2 "^j288 top: --plot: no joint 'elbow'" "$J288" top --config "$CFG" --once --plot elbow
e2e_summary
