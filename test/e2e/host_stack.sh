#!/usr/bin/env bash
# One host stack (issue 18): every front end drives the servos through the host layer, under
# one watchdog policy. The main check: after a first session of each form (the CLI's
# single-servo commands, its robot form, Ctrl-C, Python's Bus and Robot `with` blocks) and
# 1.5 s of silence, a second session holds a loaded joint (j288-sim --load-torque 2): the
# stop went out with the watchdog bit 0, so no servo tripped in the silence. Before, every
# stop sent the bit 1: 1 s later the servos tripped, and the next session's commands were
# ignored while every call reported success (the joint fell by metres of rotor travel).
# Then the rest of what a new user met: the port's notice on stderr, plot to an unwritable
# path, stop --json, the robot log's CSV that plot reads.
# Run from the repo root with BIN set (make test does); PYTHON and J288_LIB for the Python
# forms (skipped with a notice when python3 cannot load the library). Waits are bounded.
set -u
cd "$(dirname "$0")/../.."
. test/e2e/lib_e2e.sh
SIM_DIR=$E2E_TMP
. test/e2e/lib_sim.sh
trap 'sim_cleanup KILL' EXIT
need_built "$J288" "$SIM"
PY=${PYTHON:-python3}
export J288_LIB=${J288_LIB:-$BUILD/lib/libj288.so}
export PYTHONPATH=${J288_PYTHON_DIR:-$PWD/python}${PYTHONPATH:+:$PYTHONPATH}
SILENCE=1.5 # longer than the servo's 1 s watchdog: the scenario, not a bound
SAG_MAX=0.1 # rad: kp 20 against 2 N*m holds within 0.1 rad; a tripped servo falls freely

logged() { # FILE NEEDLE: wait (bounded, 20 s) until the simulator has logged it
    for _ in $(seq 1 400); do grep -q -- "$2" "$1" 2>/dev/null && return 0; sleep 0.05; done
    return 1
}

# A fresh simulator with one loaded servo (id 1) and a config without gains (the defaults).
fresh_sim() {
    [ -n "${SIM_PID:-}" ] && stop_sim "$SIM_PID"
    sim_start_linked "$1" --ids 1 --load-torque 2 --exit-after 120 || return 1
    LOG=$SIM_DIR/$1.log
    CFG=$SIM_DIR/$1.yaml
    printf 'buses:\n  - {name: b, port: %s, margin_us: 250000}\njoints:\n  - {name: hip, bus: b, id: 1}\n' \
        "$DEV" >"$CFG"
}

# second_hold: the second session after the silence: the robot form's hold (by log --hold,
# which writes the positions), exit 0, and the joint held: its last angle within SAG_MAX of
# the hold pose.
second_hold() {
    sleep "$SILENCE"
    "$J288" --config "$CFG" log --hold --duration 1 --rate 200 --csv "$SIM_DIR/h.csv" \
        >"$SIM_DIR/h.out" 2>"$SIM_DIR/h.err" || { echo "log --hold: $(cat "$SIM_DIR/h.err")"; return 1; }
    # Columns by name: the pose held (pos_des_rad; a CSV without it: the first angle).
    awk -F, -v max="$SAG_MAX" '
        NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }
        $col["pos_rad"] != "" && (col["ok"] ? $col["ok"] : $col["fresh"]) == 1 {
            last = $col["pos_rad"]; if (first == "") first = last
            des = col["pos_des_rad"] ? $col["pos_des_rad"] : first }
        END { sag = des - last; if (sag < 0) sag = -sag; print "sag " sag " rad";
              exit !(last != "" && sag < max) }' "$SIM_DIR/h.csv"
}

t_after_cli_single() {
    fresh_sim single || return 1
    "$J288" --port "$DEV" hold --id 1 --duration 0.3 --rate 200 >/dev/null || return 1
    "$J288" --port "$DEV" stop >/dev/null || return 1
    logged "$LOG" ' id=15 status=0 wd=0' || return 1
    second_hold
}

t_after_cli_robot() {
    fresh_sim robot || return 1
    "$J288" --config "$CFG" hold --duration 0.3 >/dev/null || return 1
    "$J288" --config "$CFG" stop >/dev/null || return 1
    second_hold
}

t_after_ctrl_c() {
    fresh_sim ctrlc || return 1
    "$J288" --config "$CFG" hold >/dev/null 2>&1 &
    local pid=$!
    BG_PIDS+=("$pid")
    logged "$LOG" ' id=1 status=1 wd=1' || return 1
    kill -INT "$pid"
    wait_exit "$pid" 20
    [ $? -eq 130 ] || return 1
    second_hold
}

have_python() { "$PY" -c 'import j288' 2>/dev/null; }

# py_second_bus: a second Python session's Bus(port).command(1, pos=X, kp=20, kd=1), repeated
# for 1 s, drives the joint to X (within the load's sag).
py_second_bus() {
    sleep "$SILENCE"
    "$PY" - "$DEV" <<'EOF'
import sys, time, j288
with j288.Bus(sys.argv[1], margin_us=250000) as bus:
    p = bus.status(1).pos
    x = p - 0.5 if p > 0 else p + 0.5  # joint frame: within [-pi, pi]
    end = time.monotonic() + 1.0
    while time.monotonic() < end:
        st = bus.command(1, pos=x, kp=20, kd=1)
        time.sleep(0.005)
    print("pos", st.pos, "target", x, "mode", st.mode)
    sys.exit(0 if st.mode == 1 and abs(st.pos - x) < 0.2 else 1)
EOF
}

t_after_python_bus() {
    have_python || { echo "notice: python3 cannot load j288: skipped"; return 0; }
    fresh_sim pybus || return 1
    "$PY" - "$DEV" <<'EOF' || return 1
import sys, j288
with j288.Bus(sys.argv[1], margin_us=250000) as bus:
    p = bus.status(1).pos
    for _ in range(20):
        bus.command(1, pos=p, kp=20, kd=1)
EOF
    py_second_bus && second_hold
}

t_after_python_robot() {
    have_python || { echo "notice: python3 cannot load j288: skipped"; return 0; }
    fresh_sim pyrobot || return 1
    "$PY" - "$CFG" <<'EOF' || return 1
import sys, j288
with j288.Robot(sys.argv[1]) as robot:
    for _ in range(100):
        robot.cycle()
        if all(robot.read()[3]):
            break
    robot.hold()
    for _ in range(20):
        robot.cycle()
EOF
    second_hold && py_second_bus
}

# The port's notices (a pseudo-terminal refuses low-latency mode) reach stderr once, without
# J288_VERBOSE (J288_QUIET=1, as the other checks set it, silences them).
t_notice_once() {
    fresh_sim notice || return 1
    J288_QUIET= "$J288" --port "$DEV" status --id 1 >/dev/null 2>"$SIM_DIR/n.err" || return 1
    [ "$(grep -c '^note: .*low-latency' "$SIM_DIR/n.err")" -eq 1 ] || return 1
    J288_QUIET= "$J288" --config "$CFG" status >/dev/null 2>"$SIM_DIR/n.err" || return 1
    [ "$(grep -c '^note: .*low-latency' "$SIM_DIR/n.err")" -eq 1 ]
}

# The robot log's CSV is the single-servo log's format, which plot reads; plot to a path it
# cannot write fails with a message (gnuplot, refused, wrote the PNG to the terminal).
t_robot_csv_and_plot() {
    fresh_sim csv || return 1
    "$J288" --config "$CFG" log --duration 0.2 --csv "$SIM_DIR/r.csv" >/dev/null || return 1
    head -n1 "$SIM_DIR/r.csv" | grep -q '^time_s,id,ok,pos_rad,.*,pos_des_rad,joint,bus,cycle$' || return 1
    grep -q '^[0-9.]*,1,1,[-0-9.]*,.*,hip,b,[0-9]*$' "$SIM_DIR/r.csv" || return 1
    "$J288" plot "$SIM_DIR/r.csv" --png /proc/j288-no/x.png >"$SIM_DIR/p.out" 2>"$SIM_DIR/p.err"
    [ $? -eq 1 ] && grep -q 'cannot write /proc/j288-no/x.png' "$SIM_DIR/p.err" && [ ! -s "$SIM_DIR/p.out" ]
}

t_robot_stop_json() {
    fresh_sim stopjson || return 1
    [ "$("$J288" --config "$CFG" stop --json)" = '{"stopped": "all", "buses": 1, "sent": 1}' ]
}

for t in after_cli_single after_cli_robot after_ctrl_c after_python_bus after_python_robot \
    notice_once robot_csv_and_plot robot_stop_json; do
    e2e_check "$t" "t_$t"
done
e2e_summary
