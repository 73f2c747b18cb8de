#!/usr/bin/env bash
# usage: [BUILD=build] [DURATION=30] [RATE=1000] [PRIO=80] [CPU=1] [PARTS="loop dds"]
#        [LOADS="idle stress"] [MODES="normal realtime"] [OLD_BIN=DIR] [TRACE=1] [COUNT=300]
#        scripts/bench-rt.sh                                                  (make bench-rt)
# The robot loop's timing against the machine's own floor, side by side in one run
# (docs/realtime.md, docs/performance.md "Real time"). Needs the machine to itself: not in CI.
#
# loop: 4 j288-sim buses x 3 servos (pseudo-terminals), `j288 --config F log --rate RATE` for
#   DURATION s, idle and beside `stress-ng --cpu 2`, without and with --realtime=PRIO, pinned to
#   CPU in both; cyclictest (rt-tests) at SCHED_FIFO PRIO on the same CPU at the same moment, at
#   the loop's period. Printed: the loop's wake-up lateness p50 / p99 / p99.9 / max and each as
#   a ratio to cyclictest's, cycles/s, deadlines missed, periods skipped, cycles cut, cycle
#   duration p99.9, and the buses' "stopped answering" events.
#   OLD_BIN=DIR (a build of an older tree, e.g. 2af1ea0's build/bin): the same four runs of
#   both tools with --csv (the old one under chrt/taskset for "realtime": it has no option),
#   old against new: cycles/s, late restarts or missed deadlines, bus events, worst cycle, and
#   the p99.9 of the jitter of cycle starts (|start interval - period|) from the CSV.
#   TRACE=1 (root, tracefs): the kernel worker's share. With --realtime beside stress-ng, the
#   delay of every tty flush (workqueue_queue_work -> workqueue_execute_start of
#   flush_to_ldisc: the kworker that moves a pty's, or a USB adapter's, bytes to the reader);
#   then the two tunings of docs/realtime.md: stress-ng at nice 19 (the rest at a lower CPU
#   weight), and every unbound kworker under SCHED_FIFO PRIO-1 (re-applied every half second,
#   as the pool makes new workers; put back after).
# dds: j288-dds at RATE on the same buses, in a private network namespace: command to wire (a
#   peer's dds_write of a joint_command to the write() of the first frame carrying it, stamped
#   by test/bench/write_stamp.so), p50 / p99 / p99.9 / max over COUNT commands, idle and beside
#   stress-ng, without and with --realtime, and the ratio to cyclictest's at the same moment.
# The simulators stand for servos, which no load on the computer delays: they run under
# SCHED_FIFO PRIO-10 in every run (where allowed). Wall-clock figures on a shared machine: say
# what else ran; compare the columns of one run.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build}
BIN=${BIN:-$BUILD/bin}
DURATION=${DURATION:-30}
RATE=${RATE:-1000}
PRIO=${PRIO:-80}
CPU=${CPU:-1}
COUNT=${COUNT:-300}
PARTS=${PARTS:-loop dds}
LOADS=${LOADS:-idle stress}
MODES=${MODES:-normal realtime}
SIM_PRIO=$((PRIO - 10))
PERIOD_US=$((1000000 / RATE))
if [ "${1:-}" = dds-inside ]; then # the bridge's part, re-run in a private network namespace
    . test/dds/lib_dds.sh
    # root: a network namespace alone (`unshare -n`), so that SCHED_FIFO stays allowed (in the
    # user namespace of `unshare -rn` it needs RLIMIT_RTPRIO, which root may not be able to
    # raise); others: lib_dds.sh's `unshare -rn`
    if ! dds_private_netns && [ "$(id -u)" = 0 ] && [ "${J288_DDS_NETNS:-}" != $$ ] &&
        unshare -n true 2>/dev/null; then
        J288_DDS_NETNS=$$ exec unshare -n bash "$0" "$@"
    fi
    dds_netns "$0" "$@"
fi

need() { command -v "$1" >/dev/null || { echo "bench-rt: $1 missing (apt-get install -y $2)" >&2; exit 1; }; }
need cyclictest rt-tests
need stress-ng stress-ng
need python3 python3
[ -x "$BIN/j288" ] && [ -x "$BIN/j288-sim" ] || { echo "bench-rt: make all first" >&2; exit 1; }
FIFO=(chrt -f "$SIM_PRIO")
chrt -f "$SIM_PRIO" true 2>/dev/null || { FIFO=(); echo "bench-rt: no SCHED_FIFO here (ulimit -r): simulators at normal priority" >&2; }

tmp=$(mktemp -d)
SIM_DIR=$tmp
. test/e2e/lib_sim.sh
trap 'sim_cleanup TERM' EXIT

# ---- helpers ----------------------------------------------------------------------------------

# sims_up: four simulators (FIFO), their config in $tmp/robot.yaml
sims_up() {
    local k
    SIM_PIDS=()
    for k in 0 1 2 3; do
        "${FIFO[@]}" "$BIN/j288-sim" --ids 1,2,3 --quiet --exit-after 900 --link "$tmp/bus.$k" \
            --log "$tmp/log.$k" >"$tmp/pty.$k" 2>/dev/null &
        SIM_PIDS+=($!)
    done
    for k in 0 1 2 3; do
        for _ in $(seq 1 200); do [ -L "$tmp/bus.$k" ] && break; sleep 0.05; done
    done
    robot_config 4 "$tmp/robot.yaml" 5000 20 1
}
sims_down() { stop_pids TERM "${SIM_PIDS[@]}"; SIM_PIDS=(); }

# load_on LOAD: stress-ng beside (LOAD stress) for the run and a margin, or nothing
load_on() {
    LOAD_PID=
    if [ "$1" = stress ]; then
        nice -n "${LOAD_NICE:-0}" stress-ng --cpu 2 --timeout $((DURATION + 15)) >/dev/null 2>&1 &
        LOAD_PID=$!
        BG_PIDS+=("$LOAD_PID")
        sleep 1
    fi
}
load_off() { [ -z "$LOAD_PID" ] || stop_pids TERM "$LOAD_PID"; }

# cyclictest_on NAME: the machine's floor at PRIO on CPU, DURATION s, histogram to $tmp/NAME.ct
cyclictest_on() {
    cyclictest -m -p "$PRIO" -a "$CPU" -i "$PERIOD_US" -D "$DURATION" -q -h 200000 \
        --json="$tmp/$1.ct" >/dev/null 2>&1 &
    CT_PID=$!
    BG_PIDS+=("$CT_PID")
}

# ---- the loop ---------------------------------------------------------------------------------

# loop_run NAME LOAD MODE: the loop (MODE normal or realtime) beside LOAD, with cyclictest
loop_run() {
    local name=$1 rt=()
    [ "$3" = realtime ] && rt=(--realtime="$PRIO")
    sims_up
    load_on "$2"
    cyclictest_on "$name"
    "$BIN/j288" --config "$tmp/robot.yaml" log --rate "$RATE" --duration "$DURATION" --json \
        --cpu "$CPU" "${rt[@]}" >"$tmp/$name.json" 2>"$tmp/$name.err" || true
    wait "$CT_PID" || true
    load_off
    sims_down
    echo "$name $2 $3 $(grep -c 'stopped answering' "$tmp/$name.err" || true) $(cat /proc/loadavg | cut -d' ' -f1)" >>"$tmp/loop.rows"
}

# old_run NAME LOAD MODE BIN: the same with --csv, the old tool under chrt/taskset for realtime
csv_run() {
    local name=$1 pre=() rt=() bin=$4
    if [ "$3" = realtime ]; then
        if [ "$bin" = "$BIN" ]; then rt=(--realtime="$PRIO" --cpu "$CPU"); else pre=(chrt -f "$PRIO" taskset -c "$CPU"); fi
    else
        if [ "$bin" = "$BIN" ]; then rt=(--cpu "$CPU"); else pre=(taskset -c "$CPU"); fi
    fi
    sims_up
    load_on "$2"
    "${pre[@]}" "$bin/j288" --config "$tmp/robot.yaml" log --rate "$RATE" --duration "$DURATION" \
        --csv "$tmp/$name.csv" "${rt[@]}" >"$tmp/$name.out" 2>"$tmp/$name.err" || true
    load_off
    sims_down
    echo "$name $2 $3 $(grep -c 'stopped answering' "$tmp/$name.err" || true)" >>"$tmp/csv.rows"
}

# ---- the kernel worker (TRACE=1) --------------------------------------------------------------

TR=/sys/kernel/tracing
trace_run() { # NAME [nice]: the loop with --realtime beside stress-ng, tty flushes traced
    local name=$1 inst=$TR/instances/j288-bench-rt
    mkdir -p "$inst"
    echo 65536 >"$inst/buffer_size_kb"
    echo 1 >"$inst/events/workqueue/workqueue_queue_work/enable"
    echo 1 >"$inst/events/workqueue/workqueue_execute_start/enable"
    echo 1 >"$inst/events/sched/sched_wakeup/enable"
    echo >"$inst/trace"
    sims_up
    LOAD_NICE=${2:-0} load_on stress
    echo 1 >"$inst/tracing_on"
    "$BIN/j288" --config "$tmp/robot.yaml" log --rate "$RATE" --duration "$DURATION" --json \
        --cpu "$CPU" --realtime="$PRIO" >"$tmp/$name.json" 2>"$tmp/$name.err" || true
    echo 0 >"$inst/tracing_on"
    load_off
    sims_down
    grep -E 'workqueue_(queue_work|execute_start).*flush_to_ldisc' "$inst/trace" >"$tmp/$name.trace" || true
    echo 0 >"$inst/events/workqueue/enable"
    echo 0 >"$inst/events/sched/enable"
    rmdir "$inst" 2>/dev/null || true
    echo "$name $(grep -c 'stopped answering' "$tmp/$name.err" || true)" >>"$tmp/trace.rows"
}
# every unbound kworker (kworker/u*: they run the tty flushes) not yet real-time, under
# SCHED_FIFO PRIO-1 (the loop above them, the simulators below); the pids in $tmp/raised
raise_unbound_workers() {
    local f pid
    for f in /proc/[0-9]*/comm; do
        { read -r c <"$f"; } 2>/dev/null || continue
        case $c in kworker/u*) ;; *) continue ;; esac
        pid=${f#/proc/}; pid=${pid%/comm}
        [ "$(chrt -p "$pid" 2>/dev/null | sed -n 's/.*policy: *SCHED_\([A-Z]*\).*/\1/p')" = FIFO ] && continue
        chrt -f -p $((PRIO - 1)) "$pid" 2>/dev/null && echo "$pid" >>"$tmp/raised"
    done
}

# ---- the bridge -------------------------------------------------------------------------------

dds_run() { # NAME LOAD MODE (inside the namespace)
    local name=$1 rt=()
    [ "$3" = realtime ] && rt=(--realtime="$PRIO")
    sims_up
    load_on "$2"
    cyclictest_on "$name"
    J288_WRITE_STAMP=$tmp/$name.stamps LD_PRELOAD=$PWD/$BUILD/bench/write_stamp.so \
        "$BIN/j288-dds" --config "$tmp/robot.yaml" --domain "$DDS_DOMAIN" --rate "$RATE" \
        --timeout 1000 --cpu "$CPU" "${rt[@]}" 2>"$tmp/$name.err" &
    local bp=$!
    BG_PIDS+=("$bp")
    for _ in $(seq 1 30); do
        "$BUILD/test/dds_peer" states --timeout 1 >"$tmp/first" 2>/dev/null && ! grep -q nan "$tmp/first" && break
    done
    "$BUILD/test/dds_peer" latency --count "$COUNT" --hz 50 leg0_1 0.30 0.35 >"$tmp/$name.sent"
    sleep 0.5
    kill -INT "$bp"; wait "$bp" || true
    cp "$tmp/log.0" "$tmp/$name.log0"
    wait "$CT_PID" || true
    load_off
    sims_down
    echo "$name $2 $3" >>"$tmp/dds.rows"
}

# ---- run --------------------------------------------------------------------------------------
if [ "${1:-}" = dds-inside ]; then # (in the namespace now) the rows and files go to $2
    [ -f "$BUILD/bench/write_stamp.so" ] && [ -x "$BUILD/test/dds_peer" ] && [ -x "$BIN/j288-dds" ] ||
        { echo "bench-rt: make dds build/bench/write_stamp.so first" >&2; exit 1; }
    : >"$tmp/dds.rows"
    for load in $LOADS; do for mode in $MODES; do
        dds_run "dds-$load-$mode" "$load" "$mode"
    done; done
    cp "$tmp"/dds-* "$tmp/dds.rows" "$2"/
    exit 0
fi

echo "bench-rt: $(nproc) CPUs, $(uname -r), loop and cyclictest on CPU $CPU at SCHED_FIFO $PRIO," \
     "simulators at $( [ ${#FIFO[@]} -gt 0 ] && echo "SCHED_FIFO $SIM_PRIO" || echo "normal priority"), $DURATION s a run at $RATE Hz"
echo "bench-rt: before: load $(cut -d' ' -f1-3 /proc/loadavg); busiest other processes:"
ps -eo pcpu,comm --sort=-pcpu | sed -n '2,6p' | sed 's/^/    /'
: >"$tmp/loop.rows"; : >"$tmp/csv.rows"; : >"$tmp/trace.rows"; : >"$tmp/dds.rows"
case " $PARTS " in *" loop "*)
    for load in $LOADS; do for mode in $MODES; do
        loop_run "loop-$load-$mode" "$load" "$mode"
    done; done
    if [ -n "${OLD_BIN:-}" ]; then
        for load in $LOADS; do for mode in $MODES; do
            csv_run "new-$load-$mode" "$load" "$mode" "$BIN"
            csv_run "old-$load-$mode" "$load" "$mode" "$OLD_BIN"
        done; done
    fi
    if [ "${TRACE:-0}" = 1 ]; then
        mountpoint -q "$TR" || mount -t tracefs nodev "$TR"
        : >"$tmp/raised"
        trace_run trace-default
        trace_run trace-nice 19
        ( while :; do raise_unbound_workers; sleep 0.5; done ) &
        RAISER=$!
        BG_PIDS+=("$RAISER")
        trace_run trace-raised
        stop_pids TERM "$RAISER"
        # back to normal: the kworkers serve everyone
        for pid in $(sort -u "$tmp/raised"); do chrt -o -p 0 "$pid" 2>/dev/null || true; done
    fi
    ;;
esac
case " $PARTS " in *" dds "*)
    if [ -x "$BIN/j288-dds" ]; then
        bash "$0" dds-inside "$tmp" || echo "bench-rt: the bridge's part failed (above)" >&2
    else
        echo "bench-rt: no j288-dds (make dds): the bridge's rows skipped" >&2
    fi
    ;;
esac
echo "bench-rt: after: load $(cut -d' ' -f1-3 /proc/loadavg)"
python3 scripts/bench-rt-report.py "$tmp" "$PERIOD_US"
