#!/usr/bin/env bash
# j288-dds --unitree and --unitree-hg end to end, in a private network namespace (lib_dds.sh):
# one j288-sim bus of three servos, the bridge in unitree_sdk2 mode, and test/dds/dds_peer on
# rt/lowstate and rt/lowcmd. unitree_go (Go2, B2, H1): motors 0-2 carry the simulator's true
# angles (0.002 rad), the others are zero, and the crc is right (the peer computes it unitree's
# way); a LowCmd_ moves a motor, in mode 1 and in mode 0x0A (B2's, H1's stronger motors);
# silence holds it; a bad crc and an unknown motor mode are refused with nothing sent, reported
# once; the endpoints carry the type hashes test/dds/typehash.py computes; Ctrl-C locks the
# bus. unitree_hg (G1, H1-2): the state with its crc, case and winding temperatures, voltage
# and mode_pr; a LowCmd_ moves a motor; the type hashes.
set -u
cd "$(dirname "$0")/../.."
. test/dds/lib_dds.sh
dds_netns "$0" "$@"
dds_e2e_setup
UNITREE=1

start_sims 1 --exit-after 600 --truth "$SIM_DIR/truth.{k}" --log "$SIM_DIR/log.{k}"
robot_config 1 "$SIM_DIR/robot.yaml" 250000 20 1

# lowstate_is_the_truth [--hg] MODE_FIELD: the peer's LowState_ (into $SIM_DIR/ls) has a right
# crc, motors 0-2 at the simulator's true angles (0.002 rad), and motors beyond the config at
# zero (q, and the mode in field MODE_FIELD of the peer's line)
lowstate_is_the_truth() {
    local m got want mf=${*: -1}
    "$PEER" "${@:1:$#-1}" lowstate >"$SIM_DIR/ls" || { echo "no lowstate"; return 1; }
    grep -q "^crc ok " "$SIM_DIR/ls" || { echo "lowstate crc wrong: $(grep ^crc "$SIM_DIR/ls")"; return 1; }
    for m in 0 1 2; do
        got=$(awk -v m=$m '$1 == "motor" && $2 == m { print $3 }' "$SIM_DIR/ls")
        want=$(truth 0 $((m + 1))) || return 1
        near "$got" "$want" 0.002 || { echo "motor $m: published $got, true $want"; return 1; }
    done
    [ "$(awk -v f="$mf" '$1 == "motor" && $2 >= 3 && ($3 != 0 || $f != 0)' "$SIM_DIR/ls" | wc -l)" -eq 0 ] ||
        { echo "motors beyond the config are not zero"; return 1; }
}
t_lowstate_is_the_truth() {
    lowstate_is_the_truth 6 && grep -q '^power_v 24.00$' "$SIM_DIR/ls"
}
t_lowcmd_moves_a_motor() {
    "$PEER" lowcmd --for 30 --hz 50 1 1 -0.4 0 0 20 1 & local p=$!
    wait_truth 0 2 -0.4 20 || { kill $p; return 1; }
    "$PEER" lowstate >"$SIM_DIR/ls" && kill $p; wait $p 2>/dev/null
    awk '$1 == "motor" && $2 == 1 { exit !($7 == 1) }' "$SIM_DIR/ls" ||
        { echo "motor 1 not in mode 1 while commanded"; return 1; }
}
t_silence_holds() {
    wait_err 'joint leg0_2: no command for 100 ms: holding where it is' || return 1
    comes_to_rest 0 2
}
# bad_lowcmd CAUSE ARGS...: sent 10 times, refused, reported once, motor 2 does not move.
bad_lowcmd() {
    local cause=$1 before after; shift
    before=$(truth 0 3) || return 1
    "$PEER" lowcmd --count 10 --hz 100 "$@" || return 1
    wait_err "command refused: $cause" || return 1
    sleep 0.2
    reported_once "$cause" || return 1
    after=$(truth 0 3) || return 1
    near "$before" "$after" 0.002 || { echo "motor 2 moved: $before -> $after"; return 1; }
}
t_mode_0x0a() {
    # unitree_sdk2's B2 and H1 programs drive their stronger motors in mode 0x0A (2af1ea0:
    # "motor mode not 0 or 1: motor 0 mode 10")
    "$PEER" lowcmd --for 30 --hz 50 0 10 0.35 0 0 20 1 & local p=$!
    wait_truth 0 1 0.35 20; local rc=$?
    kill $p 2>/dev/null; wait $p 2>/dev/null
    return $rc
}
t_bad_crc() { bad_lowcmd 'bad crc' --bad-crc 2 1 1.0 0 0 20 1; }
t_bad_mode() { bad_lowcmd 'motor mode not 0, 1 or 0x0A' 2 7 1.0 0 0 20 1; }
# type_hashes STATE CMD: the bridge's rt/lowstate and rt/lowcmd endpoints carry the hashes
# test/dds/typehash.py computes from the IDL for those types (2af1ea0: no USER_DATA)
type_hashes() {
    local hs hc pkg=${1%%/*}
    python3 test/dds/typehash.py tools/j288-dds/idl >"$SIM_DIR/hashes" || return 1
    hs=$(awk -v t="$1" '$1 == t { print $2 }' "$SIM_DIR/hashes")
    hc=$(awk -v t="$2" '$1 == t { print $2 }' "$SIM_DIR/hashes")
    "$PEER" endpoints >"$SIM_DIR/endpoints" || { cat "$SIM_DIR/endpoints"; return 1; }
    grep -qx "pub rt/lowstate $pkg::msg::dds_::LowState_ typehash=$hs;" "$SIM_DIR/endpoints" &&
        grep -qx "sub rt/lowcmd $pkg::msg::dds_::LowCmd_ typehash=$hc;" "$SIM_DIR/endpoints" ||
        { echo "the bridge's endpoints:"; cat "$SIM_DIR/endpoints"; return 1; }
}
t_go_type_hashes() { type_hashes unitree_go/msg/LowState unitree_go/msg/LowCmd; }
t_hg_lowstate_is_the_truth() {
    PEER_ARGS=(--hg)
    start_bridge --unitree-hg; local rc=$?
    PEER_ARGS=()
    [ $rc -eq 0 ] || return 1
    lowstate_is_the_truth --hg 7 || return 1
    # case and winding temperatures (j288-sim's ambient is 25 deg C; a servo warms as it works),
    # the supply voltage
    awk '$1 == "motor" && $2 <= 2 { split($6, t, ","); if (!(t[1] >= 20 && t[1] <= 60 && t[2] >= 20 && t[2] <= 60 && $8 == "24.00")) bad = 1 } END { exit bad }' "$SIM_DIR/ls" ||
        { echo "temperatures or voltage:"; grep '^motor [012] ' "$SIM_DIR/ls"; return 1; }
    grep -q '^mode_pr 0$' "$SIM_DIR/ls"
}
t_hg_lowcmd_moves_a_motor() {
    DDS_PEER_MODE_PR=1 "$PEER" --hg lowcmd --for 30 --hz 50 2 1 -0.3 0 0 20 1 & local p=$!
    wait_truth 0 3 -0.3 20 || { kill $p; return 1; }
    "$PEER" --hg lowstate >"$SIM_DIR/ls" && kill $p; wait $p 2>/dev/null
    awk '$1 == "motor" && $2 == 2 { exit !($7 == 1) }' "$SIM_DIR/ls" && grep -q '^mode_pr 1$' "$SIM_DIR/ls" ||
        { echo "motor 2 not in mode 1, or mode_pr not echoed"; grep '^motor 2 \|^mode_pr' "$SIM_DIR/ls"; return 1; }
}
t_hg_type_hashes() { type_hashes unitree_hg/msg/LowState unitree_hg/msg/LowCmd; }
t_nan() { bad_lowcmd 'NaN or infinite value' 2 1 nan 0 0 20 1; }
t_ctrl_c_locks() {
    : >"$SIM_DIR/log.0"
    stop_bridge || { echo "exit $?"; return 1; }
    locked_all 0
}

start_bridge --unitree || exit 1
e2e_check lowstate_is_the_truth t_lowstate_is_the_truth
e2e_check lowcmd_moves_a_motor t_lowcmd_moves_a_motor
e2e_check silence_holds t_silence_holds
e2e_check mode_0x0a t_mode_0x0a
e2e_check bad_crc t_bad_crc
e2e_check bad_mode t_bad_mode
e2e_check nan t_nan
e2e_check go_type_hashes t_go_type_hashes
e2e_check ctrl_c_locks t_ctrl_c_locks
e2e_check hg_lowstate_is_the_truth t_hg_lowstate_is_the_truth
e2e_check hg_lowcmd_moves_a_motor t_hg_lowcmd_moves_a_motor
e2e_check hg_type_hashes t_hg_type_hashes
e2e_check hg_ctrl_c_locks t_ctrl_c_locks
e2e_summary
