# Helpers for the scripts that drive one of j288's live screens (top, jog) on a real terminal
# (sourced after lib_e2e.sh and lib_sim.sh, with TMUX_NAME set, e.g. "top"): tmux runs the
# program in a detached session, capture-pane reads the screen, send-keys presses keys. Each
# session gets a tmux server of its own (socket j288-NAME-PID-N): a session started while the
# last one's server was still exiting met "server exited unexpectedly" on a loaded machine.
# The program's exit status lands in $E2E_TMP/NAME.rc and its pane stays (what it printed last
# can be read) until tmux_cleanup, which the script's EXIT trap calls. Every wait polls,
# bounded (scaled by TEST_TIME_SCALE); nothing depends on the machine's speed.
# shellcheck shell=bash

TMUX_N=0
TMUX_SOCK=j288-$TMUX_NAME-$$-0
tmux_do() { tmux -u -L "$TMUX_SOCK" -f /dev/null "$@"; }

# tmux_cleanup: every server this script started, and its socket (a no-op in a subshell).
tmux_cleanup() {
    local n
    [ "$BASHPID" = "$$" ] || return 0
    command -v tmux >/dev/null || return 0
    for n in $(seq 0 "$TMUX_N"); do
        tmux -L "j288-$TMUX_NAME-$$-$n" kill-server 2>/dev/null
        rm -f "${TMUX_TMPDIR:-/tmp}/tmux-$(id -u)/j288-$TMUX_NAME-$$-$n"
    done
}

# tmux_need: without tmux, the script ends here (its summary printed) with a notice, or with
# CI=true a failure (scripts/ci-install.sh installs tmux).
tmux_need() {
    command -v tmux >/dev/null && return 0
    if [ "${CI:-}" = true ]; then
        e2e_fail tmux "tmux is not installed (scripts/ci-install.sh installs it)"
    else
        echo "$E2E_NAME: tmux not installed: the terminal checks are skipped (apt-get install tmux)"
    fi
    e2e_summary
    exit $?
}

# tmux_start COLS ROWS COMMAND: COMMAND (a shell line) in a fresh session COLS x ROWS.
tmux_start() {
    rm -f "$E2E_TMP/$TMUX_NAME.rc"
    TMUX_N=$((TMUX_N + 1))
    TMUX_SOCK=j288-$TMUX_NAME-$$-$TMUX_N
    tmux_do new-session -d -s "$TMUX_NAME" -x "$1" -y "$2" \
        "$3; echo \$? >'$E2E_TMP/$TMUX_NAME.rc'; read -r _"
}
screen() { tmux_do capture-pane -p -t "$TMUX_NAME" 2>/dev/null; }
press() { tmux_do send-keys -t "$TMUX_NAME" "$@"; }
# wait_screen REGEX: up to 30 s for the screen to show a line matching REGEX.
wait_screen() {
    for _ in $(seq 1 "$(e2e_scaled 600)"); do screen | grep -Eq -- "$1" && return 0; sleep 0.05; done
    echo "never on screen: /$1/"; screen; return 1
}
# wait_rc WANT: up to 30 s for the program to exit, with status WANT (else the screen shows
# what it said last).
wait_rc() {
    local rc=$E2E_TMP/$TMUX_NAME.rc
    for _ in $(seq 1 "$(e2e_scaled 600)"); do [ -s "$rc" ] && break; sleep 0.05; done
    [ "$(cat "$rc" 2>/dev/null)" = "$1" ] || { echo "exit '$(cat "$rc" 2>/dev/null)', want $1"; screen; return 1; }
}
# broadcasts LOG: the broadcast locks the simulator logged so far; wait_broadcast LOG N: up to
# 20 s for more than N.
broadcasts() { grep -c ' id=15 status=0 ' "$1"; }
wait_broadcast() {
    for _ in $(seq 1 "$(e2e_scaled 400)"); do [ "$(broadcasts "$1")" -gt "$2" ] && return 0; sleep 0.05; done
    echo "no broadcast lock after the key"; return 1
}
# narrow_screen_ok COLS FIRST ROW NEXT: no line of the screen is wider than COLS characters,
# the first line starts with FIRST, and the line after the one starting with ROW starts with
# NEXT (a row that wrapped would push the next one down).
narrow_screen_ok() {
    local LC_ALL=C.UTF-8 l # (${#l} counts characters: a braille cell is one)
    screen | head -n1 | grep -q "^$2" || { echo "header not on top"; screen; return 1; }
    while IFS= read -r l; do
        [ "${#l}" -le "$1" ] || { echo "longer than $1: $l"; return 1; }
    done < <(screen)
    screen | grep -A1 -- "^$3" | tail -n1 | grep -q -- "^$4" || { echo "the $3 row wrapped"; screen; return 1; }
}
