# Helpers for the DDS test scripts (sourced): keep every packet on this machine. dds_netns
# re-runs the calling script inside a private network namespace (`unshare -rn`: a user and a
# network namespace, no privilege needed, only a loopback interface, brought up here), and
# points Cyclone DDS at a loopback-only configuration as well, on a test-specific domain id
# (DDS_DOMAIN). Without unshare (or user namespaces), the script is skipped with a notice;
# with CI=true that is a failure.
# shellcheck shell=bash

DDS_DOMAIN=${DDS_DOMAIN:-87}

# dds_private_netns: true when this process is in a network namespace of its own with
# nothing but lo (read from the system, never from the environment: an inherited variable
# would have the root user's `ip link` act on the host's lo). /proc/net is the caller's
# namespace's; /proc/1/ns/net may be unreadable inside a user namespace, and is then skipped.
dds_private_netns() {
    local self init
    [ "$(awk -F: 'NR > 2 { gsub(/ /, "", $1); print $1 }' /proc/net/dev)" = lo ] || return 1
    self=$(readlink /proc/self/ns/net 2>/dev/null)
    init=$(readlink /proc/1/ns/net 2>/dev/null)
    [ -n "$self" ] && [ "$self" != "$init" ]
}

# dds_netns "$0" "$@": call first thing; returns inside the namespace.
dds_netns() {
    if ! dds_private_netns; then
        # unshare execs in place: J288_DDS_NETNS holding our own pid means this process ran
        # unshare already (an inherited value holds another's pid and is ignored)
        if [ "${J288_DDS_NETNS:-}" = $$ ]; then
            echo "error: $1: not in a private network namespace after unshare -rn" >&2
            exit 1
        fi
        if ! unshare -rn true 2>/dev/null; then
            if [ "${CI:-}" = true ]; then
                echo "error: unshare -rn fails here (CI=true: a failure): user namespaces needed" >&2
                exit 1
            fi
            echo "notice: skipping $1: unshare -rn (user namespaces) not available" >&2
            exit 0
        fi
        J288_DDS_NETNS=$$ exec unshare -rn bash "$@"
    fi
    # multicast on lo: the namespace is ours alone, and Cyclone's discovery then runs as usual
    ip link set lo up multicast on 2>/dev/null || { echo "cannot bring lo up in the namespace"; exit 1; }
    export CYCLONEDDS_URI='<CycloneDDS><Domain><General><Interfaces><NetworkInterface name="lo"/></Interfaces></General></Domain></CycloneDDS>'
    export DDS_DOMAIN
}

# ---- the bridge against simulators ----

# dds_e2e_setup: after dds_netns, for the end-to-end scripts: BUILD, BIN, the e2e and
# simulator helpers (test/e2e/lib_e2e.sh, lib_sim.sh; SIM_DIR is E2E_TMP), PEER and DDS, and
# the traps (every process stopped, a frozen simulator resumed first, at exit).
dds_e2e_setup() {
    BUILD=${BUILD:-build}
    BIN=${BIN:-$BUILD/bin}
    . test/e2e/lib_e2e.sh
    SIM_DIR=$E2E_TMP
    . test/e2e/lib_sim.sh
    PEER=$BUILD/test/dds_peer
    PEER_ARGS=()
    BRIDGE_WRAP=()
    DDS=$BIN/j288-dds
    trap 'kill -CONT "${SIM_PID_1:-}" 2>/dev/null; sim_cleanup TERM' EXIT
    trap 'exit 130' INT TERM
    need_built "$DDS" "$PEER" "$SIM"
}

# near A B TOL: |A - B| <= TOL, angles compared modulo 2 pi.
near() {
    awk -v a="$1" -v b="$2" -v t="$3" 'BEGIN { p = 6.283185307179586; d = a - b; d -= p * int(d / p)
        if (d < 0) d += p; if (d > p / 2) d = p - d; exit !(d <= t) }'
}

# truth K ID [S]: servo ID's true output angle on simulator K (asks for it with SIGWINCH and
# waits until the truth file is rewritten, up to S seconds, default 8, scaled). Fails (a
# message, no angle) when the file is not rewritten: a stale angle would let a check pass on
# old data. Callers check its status. The bound is the clock's, not a count of polls (400 polls
# of a nominal 20 ms took 25 s on a loaded machine).
truth() {
    local f=$SIM_DIR/truth.$1 seq pid s=$(e2e_scaled "${3:-8}") end
    eval "pid=\$SIM_PID_$1"
    seq=$(sed -n '1s/.*seq=\([0-9]*\).*/\1/p' "$f" 2>/dev/null)
    kill -s WINCH "$pid"
    end=$((${EPOCHREALTIME//[!0-9]/} + s * 1000000))
    while [ "${EPOCHREALTIME//[!0-9]/}" -lt "$end" ]; do
        if [ "$(sed -n '1s/.*seq=\([0-9]*\).*/\1/p' "$f" 2>/dev/null)" != "$seq" ]; then
            awk -v id="$2" '$1 == "id=" id { sub("theta=", "", $2); print $2; found = 1 }
                END { exit !found }' "$f"
            return
        fi
        sleep 0.02
    done
    echo "simulator $1 did not rewrite $f in $s s" >&2
    return 1
}

# start_bridge OPTIONS...: j288-dds (after the command prefix BRIDGE_WRAP, none by default: it
# must exec the bridge, as prlimit does) on $SIM_DIR/robot.yaml (stderr in $SIM_DIR/bridge.err), once
# it publishes known angles (diagnostics in unitree mode: LowState_ cannot say) (up to 30 s; the peer reads with PEER_ARGS, e.g. --ns NS); sets
# BRIDGE_PID. A bridge still running from a failed check is stopped first.
start_bridge() {
    [ -n "${BRIDGE_PID:-}" ] && kill -0 "$BRIDGE_PID" 2>/dev/null && stop_bridge
    "${BRIDGE_WRAP[@]}" "$DDS" --config "$SIM_DIR/robot.yaml" --domain "$DDS_DOMAIN" "$@" \
        2>"$SIM_DIR/bridge.err" &
    BRIDGE_PID=$!
    BG_PIDS+=("$BRIDGE_PID")
    local i
    for i in $(seq 1 30); do
        if [ "${UNITREE:-0}" = 1 ]; then
            "$PEER" "${PEER_ARGS[@]}" diag --timeout 2 >"$SIM_DIR/first" 2>/dev/null &&
                grep -q 'angle_known=true' "$SIM_DIR/first" &&
                ! grep -q 'angle_known=false' "$SIM_DIR/first" && return 0
        else
            "$PEER" "${PEER_ARGS[@]}" states --timeout 1 >"$SIM_DIR/first" 2>/dev/null &&
                ! grep -q nan "$SIM_DIR/first" && return 0
        fi
        kill -0 "$BRIDGE_PID" 2>/dev/null || break
    done
    echo "the bridge did not publish: $(cat "$SIM_DIR/bridge.err")"
    return 1
}

# stop_bridge: SIGINT, and its exit status (124: still running after 30 s).
stop_bridge() {
    kill -INT "$BRIDGE_PID" 2>/dev/null
    wait_exit "$BRIDGE_PID" 30
}

# wait_err PATTERN [SECONDS]: the bridge's stderr matches the extended regex (up to 10 s).
wait_err() {
    local i
    for i in $(seq 1 $((${2:-10} * 20))); do
        grep -Eq "$1" "$SIM_DIR/bridge.err" && return 0
        sleep 0.05
    done
    echo "not on the bridge's stderr: $1"; cat "$SIM_DIR/bridge.err"; return 1
}

# wait_diag PATTERN...: the bridge's diagnostics (read with the peer into $SIM_DIR/diag) hold a
# line matching each basic regex, within 10 s scaled: the bridge counts a command when it takes
# it, which under memcheck on a busy machine is well after the peer has sent it.
wait_diag() {
    local i p ok
    for i in $(seq 1 "$(e2e_scaled 50)"); do
        ok=1
        "$PEER" diag >"$SIM_DIR/diag" || ok=0
        for p in "$@"; do [ $ok -eq 1 ] && { grep -q "$p" "$SIM_DIR/diag" || ok=0; }; done
        [ $ok -eq 1 ] && return 0
        sleep 0.2
    done
    echo "not in the diagnostics: $*"; cat "$SIM_DIR/diag"; return 1
}

# reported_once CAUSE: exactly one stderr line for that refusal cause.
reported_once() {
    local n
    n=$(grep -c "command refused: $1" "$SIM_DIR/bridge.err")
    [ "$n" -eq 1 ] || { echo "'$1' reported $n times"; return 1; }
}

# wait_truth K ID TARGET [SECONDS]: servo ID of simulator K reaches TARGET (0.01 rad) and
# stays there (two readings 0.2 s apart).
wait_truth() {
    local i t near_before=0
    for i in $(seq 1 $((${4:-20} * 5))); do
        t=$(truth "$1" "$2") || return 1
        if near "$t" "$3" 0.01; then
            [ $near_before = 1 ] && return 0
            near_before=1
        else
            near_before=0
        fi
        sleep 0.2
    done
    echo "servo $2 on simulator $1 at $t, not $3"; return 1
}

# still K ID: servo ID of simulator K does not move over half a second (0.005 rad).
still() {
    local a b
    a=$(truth "$1" "$2") && sleep 0.5 && b=$(truth "$1" "$2") || return 1
    near "$a" "$b" 0.005 || { echo "servo $2 on simulator $1 moved: $a -> $b"; return 1; }
}

# comes_to_rest K ID: servo ID of simulator K is still (as above) within about 10 s: a held
# joint that was moving settles, however slowly a loaded machine runs the simulator; one that
# keeps moving fails with still's message.
comes_to_rest() {
    local i
    for i in $(seq 1 19); do
        still "$1" "$2" >/dev/null && return 0
    done
    still "$1" "$2"
}

# locked_all K...: simulator K's log got the broadcast lock (id 15, status 0) with the
# watchdog bit 0 (a locked servo needs no watchdog; the runner's policy), waiting (bounded) for
# the simulator to read it: a broadcast has no reply, and the bridge may have exited before the
# simulator ran again (lib_e2e.sh's logged).
locked_all() {
    local k
    for k in "$@"; do
        logged "$SIM_DIR/log.$k" ' id=15 status=0 wd=0' || { echo "no broadcast lock on bus $k"; return 1; }
    done
}
