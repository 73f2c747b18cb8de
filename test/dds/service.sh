#!/usr/bin/env bash
# j288-dds as a systemd service, without systemd (none runs in CI or here), in a private
# network namespace (lib_dds.sh), against one j288-sim bus:
# - debian/j288-dds@.service passes `systemd-analyze verify` (its ExecStart pointed at the
#   built bridge) without a single warning;
# - the bridge started as the unit starts it (its ExecStart, %i the config name, /etc moved
#   into a temporary directory, $J288_DDS_OPTIONS from the instance's environment file) under
#   a fake systemd: NOTIFY_SOCKET, an AF_UNIX datagram socket this test reads, and
#   WATCHDOG_USEC. It says READY=1 with a status once it runs, then WATCHDOG=1 again and again
#   with a cycle count that grows (the pings come from the cycling loop), and STOPPING=1 at
#   SIGTERM, after which it locks every bus and exits 0 (no restart: Restart=on-failure).
set -u
cd "$(dirname "$0")/../.."
. test/dds/lib_dds.sh
dds_netns "$0" "$@"
dds_e2e_setup
if ! command -v systemd-analyze >/dev/null; then
    [ "${CI:-}" = true ] && { echo "error: systemd-analyze missing (CI=true: a failure); install: systemd"; exit 1; }
    echo "notice: skipping $0: systemd-analyze missing (Debian: systemd)"; exit 0
fi
UNIT=debian/j288-dds@.service
ETC=$SIM_DIR/etc
mkdir -p "$ETC/j288" "$SIM_DIR/unit"

start_sims 1 --exit-after 300 --truth "$SIM_DIR/truth.{k}" --log "$SIM_DIR/log.{k}"
robot_config 1 "$ETC/j288/robot.yaml" 250000 20 1
echo "J288_DDS_OPTIONS=--domain $DDS_DOMAIN --rate 200" >"$ETC/j288/robot.env"

t_unit_verifies() {
    local out
    sed "s|/usr/bin/j288-dds|$(cd "$(dirname "$DDS")" && pwd)/j288-dds|" "$UNIT" >"$SIM_DIR/unit/j288-dds@.service"
    out=$(systemd-analyze verify --man=no "$SIM_DIR/unit/j288-dds@.service" 2>&1) ||
        { echo "systemd-analyze verify: $out"; return 1; }
    [ -z "$out" ] || { echo "systemd-analyze verify warns: $out"; return 1; }
    grep -qx 'Type=notify' "$UNIT" && grep -q '^WatchdogSec=' "$UNIT" && grep -qx 'Restart=on-failure' "$UNIT"
}

# notify_log: the datagrams that reached the fake NOTIFY_SOCKET, one a line (\n as |)
notify_listen() {
    python3 -c '
import socket, sys, time
s = socket.socket(socket.AF_UNIX, socket.SOCK_DGRAM)
s.bind(sys.argv[1])
s.settimeout(1.0)
end = time.time() + 120
with open(sys.argv[2], "w") as out:
    while time.time() < end:
        try:
            d = s.recv(4096)
        except socket.timeout:
            continue
        out.write(d.decode().replace("\n", "|") + "\n")
        out.flush()' "$SIM_DIR/notify" "$SIM_DIR/notify.log" &
    LISTENER=$!
    BG_PIDS+=("$LISTENER")
    local i
    for i in $(seq 1 100); do [ -S "$SIM_DIR/notify" ] && return 0; sleep 0.05; done
    echo "the fake NOTIFY_SOCKET did not appear"; return 1
}
# wait_notify REGEX [COUNT]: COUNT (1) datagrams match the extended regex, within 20 s scaled.
wait_notify() {
    local i
    for i in $(seq 1 "$(e2e_scaled 200)"); do
        [ "$(grep -Ec "$1" "$SIM_DIR/notify.log" 2>/dev/null)" -ge "${2:-1}" ] && return 0
        sleep 0.1
    done
    echo "not sent to NOTIFY_SOCKET ${2:-1} times: $1"; cat "$SIM_DIR/notify.log"; cat "$SIM_DIR/bridge.err"; return 1
}

t_service_notifies() {
    local line cmd pid cycles
    notify_listen || return 1
    # the unit's command line, as systemd would run it for j288-dds@robot
    line=$(sed -n 's/^ExecStart=//p' "$UNIT")
    line=${line//%i/robot}
    line=${line//\/etc\/j288/$ETC\/j288}
    line=${line/\/usr\/bin\/j288-dds/$DDS}
    # shellcheck disable=SC1090,SC2086
    (while IFS='=' read -r k v; do export "$k=$v"; done <"$ETC/j288/robot.env" # as systemd reads it
     cmd=$(eval "echo $line")
     NOTIFY_SOCKET=$SIM_DIR/notify WATCHDOG_USEC=300000 exec $cmd) 2>"$SIM_DIR/bridge.err" &
    pid=$!
    BRIDGE_PID=$pid
    BG_PIDS+=("$pid")
    wait_notify '^READY=1\|STATUS=3 joints on 1 buses, domain [0-9]+, rt/joint_states' || return 1
    wait_notify '^WATCHDOG=1\|STATUS=[0-9]+ cycles/s, [0-9]+ cycles' 3 || return 1
    cycles=$(sed -n 's/^WATCHDOG=1|STATUS=[0-9]* cycles\/s, \([0-9]*\) cycles.*/\1/p' "$SIM_DIR/notify.log")
    sort -n -c <<<"$cycles" && [ "$(sort -un <<<"$cycles" | wc -l)" -eq "$(wc -l <<<"$cycles")" ] ||
        { echo "the cycle count did not grow from ping to ping: $cycles"; return 1; }
    : >"$SIM_DIR/log.0"
    kill -TERM $pid
    wait_exit $pid 30 || { echo "exit $? after SIGTERM"; return 1; }
    wait_notify '^STOPPING=1\|STATUS=SIGTERM' && locked_all 0
}

e2e_check unit_verifies t_unit_verifies
e2e_check service_notifies t_service_notifies
e2e_summary
