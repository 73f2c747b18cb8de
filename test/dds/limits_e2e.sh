#!/usr/bin/env bash
# Issue 29's soft limits and continuous joints through j288-dds, in a private network namespace
# (lib_dds.sh): one j288-sim bus of four servos, the bridge, test/dds/dds_peer. What is checked
# is the simulator's truth (its --truth file), not the bridge's view:
# - a +1 rad/s rt/joint_command toward a soft limit (limits [-0.4, 0.4]) stops within 0.05 rad
#   of it, and the hold that follows the silence keeps it there; a velocity command back is
#   taken; an effort toward the other limit stops there too (2af1ea0: carried through, then
#   "locked", the hold refused, commands back refused);
# - a joint found 0.2 rad beyond its range (more than a hold may pull) takes a velocity and an
#   effort command back toward it, and comes in;
# - docs/dds.md's wheel ({name: [wheel], velocity: [2.0]}, continuous: true, from 3 rad) runs
#   past pi and keeps going, its published angle never wrapped (2af1ea0: stopped at pi and
#   locked, every later command refused).
# Every wait polls and is bounded; the runs are a few seconds of wall clock each.
set -u
cd "$(dirname "$0")/../.."
. test/dds/lib_dds.sh
dds_netns "$0" "$@"
dds_e2e_setup

LO=-0.4
HI=0.4
NEAR=0.05 # rad: "stops within 0.05 rad of it"
start_sims 1 --exit-after 300 --ids 1,2,3,4 --start-angle 1:0 --start-angle 2:0.6 --start-angle 3:0.6 \
    --start-angle 4:3.0 --truth "$SIM_DIR/truth.{k}" --log "$SIM_DIR/log.{k}"
{ echo "buses:"
  echo "  - {name: leg0, port: $SIM_DIR/bus.0, margin_us: 250000}"
  echo "joints:"
  echo "  - {name: knee, bus: leg0, id: 1, limits: [$LO, $HI], kp: 20, kd: 1}"
  echo "  - {name: ankle, bus: leg0, id: 2, limits: [$LO, $HI], kp: 20, kd: 1}"
  echo "  - {name: toe, bus: leg0, id: 3, limits: [$LO, $HI], kp: 20, kd: 1}"
  echo "  - {name: wheel, bus: leg0, id: 4, continuous: true, kp: 20, kd: 1}"; } >"$SIM_DIR/robot.yaml"

# ge A B, le A B: A >= B, A <= B (reals).
ge() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a >= b) }'; }
le() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a <= b) }'; }
within() { awk -v a="$1" -v b="$2" -v t="$3" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(d <= t) }'; }

# drive SECONDS ID NAME POS VEL EFF: the peer sends that command at 50 Hz for SECONDS while the
# truth of servo ID is read as often as it comes; sets END (the truth after the peer stopped),
# MOST and LEAST (the extremes seen, END included).
drive() {
    local s=$1 id=$2 p t
    shift 2
    "$PEER" command --for "$s" --hz 50 "$@" >/dev/null & p=$!
    MOST=$(truth 0 "$id") || { kill $p; wait $p 2>/dev/null; return 1; }
    LEAST=$MOST
    while kill -0 $p 2>/dev/null; do
        t=$(truth 0 "$id") || { kill $p; wait $p 2>/dev/null; return 1; }
        ge "$t" "$MOST" && MOST=$t
        le "$t" "$LEAST" && LEAST=$t
    done
    wait $p
    END=$(truth 0 "$id") || return 1
    ge "$END" "$MOST" && MOST=$END
    le "$END" "$LEAST" && LEAST=$END
    return 0
}

t_velocity_stops_at_the_limit() {
    # the issue's: +1 rad/s toward the upper limit for 2 s (0.4 rad away: it would pass it
    # by 1.6 rad); then silence: the timeout's hold keeps it there
    drive 2 1 knee - 1.0 - || return 1
    echo "  knee, +1 rad/s for 2 s toward $HI: end $END, furthest $MOST"
    within "$END" "$HI" "$NEAR" && le "$MOST" "$(awk -v h="$HI" -v n="$NEAR" 'BEGIN { print h + n }')" ||
        { echo "knee not stopped at $HI: end $END, furthest $MOST"; tail -5 "$SIM_DIR/bridge.err"; return 1; }
    wait_err 'joint knee: no command for 100 ms: holding where it is' || return 1
    comes_to_rest 0 1 || return 1
    END=$(truth 0 1) || return 1
    within "$END" "$HI" "$NEAR" || { echo "knee held at $END, not at $HI"; return 1; }
}
t_velocity_back_is_taken() {
    drive 1 1 knee - -0.5 - || return 1
    echo "  knee, -0.5 rad/s for 1 s from the limit: end $END"
    le "$END" "$(awk -v h="$HI" 'BEGIN { print h - 0.2 }')" || { echo "knee did not come back: $END"; return 1; }
    ! grep -q 'command refused' "$SIM_DIR/bridge.err" || { cat "$SIM_DIR/bridge.err"; return 1; }
}
t_effort_stops_at_the_limit() {
    # 1 N*m toward the lower limit, no damping of its own (effort only: kp = kd = 0)
    drive 2 1 knee - - -1.0 || return 1
    echo "  knee, -1 N*m for 2 s toward $LO: end $END, furthest $LEAST"
    within "$END" "$LO" "$NEAR" && ge "$LEAST" "$(awk -v l="$LO" -v n="$NEAR" 'BEGIN { print l - n }')" ||
        { echo "knee not stopped at $LO: end $END, furthest $LEAST"; tail -5 "$SIM_DIR/bridge.err"; return 1; }
}
t_velocity_back_from_beyond() {
    # ankle starts at 0.6, 0.2 beyond its upper limit (a hold there is refused): a velocity
    # command toward the range is taken, and brings it in
    drive 1 2 ankle - -0.5 - || return 1
    echo "  ankle, from 0.6: -0.5 rad/s for 1 s: end $END"
    le "$END" "$(awk -v h="$HI" 'BEGIN { print h - 0.1 }')" ||
        { echo "ankle not brought back: $END; $(grep 'refused' "$SIM_DIR/bridge.err")"; return 1; }
    ! grep -q 'command refused' "$SIM_DIR/bridge.err" || { cat "$SIM_DIR/bridge.err"; return 1; }
}
t_effort_back_from_beyond() {
    # toe, likewise at 0.6: an effort toward the range (it then crosses it, and stops at the
    # lower limit)
    drive 1 3 toe - - -0.5 || return 1
    echo "  toe, from 0.6: -0.5 N*m for 1 s: end $END, least $LEAST"
    le "$END" "$(awk -v h="$HI" 'BEGIN { print h - 0.1 }')" &&
        ge "$LEAST" "$(awk -v l="$LO" -v n="$NEAR" 'BEGIN { print l - n }')" ||
        { echo "toe: end $END, least $LEAST; $(grep 'refused' "$SIM_DIR/bridge.err")"; return 1; }
    ! grep -q 'command refused' "$SIM_DIR/bridge.err" || { cat "$SIM_DIR/bridge.err"; return 1; }
}
# published NAME: its angle in the next rt/joint_states.
published() { "$PEER" states >"$SIM_DIR/states" && awk -v n="$1" '$1 == n { print $2 }' "$SIM_DIR/states"; }
t_wheel_runs_past_pi() {
    # docs/dds.md's example, from 3 rad: past pi by 1.5 rad (a whole second at 2 rad/s
    # beyond where 2af1ea0 stopped it), then still turning; the published angle not wrapped
    local p i t a b
    "$PEER" command --for 60 --hz 50 wheel - 2.0 - >/dev/null & p=$!
    for i in $(seq 1 "$(e2e_scaled 100)"); do
        t=$(truth 0 4) || break
        ge "$t" 4.64 && break
        kill -0 $p 2>/dev/null || break
        sleep 0.1
    done
    a=$(truth 0 4) && sleep 0.3 && b=$(truth 0 4) && t=$(published wheel); i=$?
    kill $p 2>/dev/null; wait $p 2>/dev/null
    [ $i -eq 0 ] || return 1
    echo "  wheel, 2 rad/s from 3: $a, 0.3 s later $b, published $t"
    ge "$a" 4.64 && ge "$b" "$(awk -v a="$a" 'BEGIN { print a + 0.2 }')" ||
        { echo "the wheel stopped: $a -> $b"; tail -5 "$SIM_DIR/bridge.err"; return 1; }
    ge "$t" 4.0 || { echo "published $t (wrapped?)"; return 1; }
    # silence: held where it is, its angle as the simulator has it (unwrapped)
    wait_err 'joint wheel: no command for 100 ms: holding where it is' || return 1
    comes_to_rest 0 4 || return 1
    a=$(truth 0 4) && t=$(published wheel) || return 1
    within "$t" "$a" 0.002 || { echo "wheel published $t, true $a"; return 1; }
    ! grep -q 'command refused' "$SIM_DIR/bridge.err" || { cat "$SIM_DIR/bridge.err"; return 1; }
}

start_bridge || exit 1
e2e_check velocity_stops_at_the_limit t_velocity_stops_at_the_limit
e2e_check velocity_back_is_taken t_velocity_back_is_taken
e2e_check effort_stops_at_the_limit t_effort_stops_at_the_limit
e2e_check velocity_back_from_beyond t_velocity_back_from_beyond
e2e_check effort_back_from_beyond t_effort_back_from_beyond
e2e_check wheel_runs_past_pi t_wheel_runs_past_pi
stop_bridge
e2e_summary
