#!/usr/bin/env bash
# End-to-end tests of the offline `j288` frame calculator: encode and decode of the spec's
# worked frames and of every golden vector in test/vectors/ (made by the independent Python
# generator), JSON validity, help, and every bad-input case (one stderr line, empty stdout,
# non-zero exit). Run from the repository root with BIN set (make test does this).
set -u
cd "$(dirname "$0")/../.."
. test/e2e/lib_e2e.sh
e2e_need_python
trap e2e_cleanup_tmp EXIT

if [ ! -x "$J288" ]; then
    echo "$J288 not built (make BUILD=... $J288)"; exit 1
fi

# --- the spec's worked frames --------------------------------------------------------------
LOCK0=feee80000000000000000000000000001d99fb6e
FOC3=feee9300000000005f14000000050032a64b303f
REPLY3_SPACED="fc ee 13 24 29 30 00 05 d7 ff 5f 14 00 00 00 00 00 00 e8 03 00 00 49 c2 3b ee"

expect_ok encode_worked_lock "$LOCK0" "$J288" encode --id 0 --mode lock
expect_ok encode_worked_lock_explicit "$LOCK0" "$J288" encode --id=0 --mode=lock --watchdog=on \
    --tau-raw 0 --speed-raw 0 --pos-raw 0 --kp-raw 0 --kd-raw 0
expect_ok encode_worked_foc "$FOC3" "$J288" encode --id 3 --pos-raw 5215 --kp-raw 1280 --kd-raw 12800
expect_ok encode_worked_foc_hex_values "$FOC3" "$J288" encode --id 0x3 --pos-raw 0x145f \
    --kp-raw 0x500 --kd-raw 0x3200 --mode foc
# SI on the rotor side: 0.001 N*m/rad = 1280 LSB, 0.0001 N*m*s/rad = 12800 LSB,
# 5215 LSB = 0.99996 rad (rounding to nearest).
expect_ok encode_worked_foc_si_rotor "$FOC3" "$J288" encode --id 3 --side rotor --pos 0.99996 \
    --kp 0.001 --kd 0.0001
# ... and on the output side (gear 288.35: angles / N, gains * N^2); --side may come last.
expect_ok encode_worked_foc_si_output "$FOC3" "$J288" encode --id 3 --pos 0.0034678 \
    --kp 83.14572 --kd 8.314572 --side output

expect_true decode_worked_lock_json bash -c "
    '$J288' decode --json $LOCK0 | python3 -c '
import json, sys
o = json.load(sys.stdin)
want = dict(frame=\"command\", id=0, mode=0, watchdog=1, tau_raw=0, speed_raw=0, pos_raw=0,
            kp_raw=0, kd_raw=0)
bad = {k: (o.get(k), v) for k, v in want.items() if o.get(k) != v}
sys.exit(str(bad) if bad else 0)'"
expect_true decode_worked_foc_json bash -c "
    '$J288' decode --json '${FOC3}' | python3 -c '
import json, sys
o = json.load(sys.stdin)
want = dict(frame=\"command\", id=3, mode=1, watchdog=1, tau_raw=0, speed_raw=0, pos_raw=5215,
            kp_raw=1280, kd_raw=12800)
bad = {k: (o.get(k), v) for k, v in want.items() if o.get(k) != v}
assert abs(o[\"rotor\"][\"kp_nm_per_rad\"] - 0.001) < 1e-12, o
assert abs(o[\"output\"][\"kp_nm_per_rad\"] - 0.001 * 288.35**2) < 1e-6, o
sys.exit(str(bad) if bad else 0)'"
expect_true decode_worked_reply_json bash -c "
    '$J288' decode --json $REPLY3_SPACED | python3 -c '
import json, sys
o = json.load(sys.stdin)
want = dict(frame=\"reply\", id=3, mode=1, watchdog=0, case_temp_c=36, winding_temp_c=41,
            voltage_raw=48, torque_raw=1280, speed_raw=-41, pos_raw=5215, faults=0,
            out_pos_raw=1000, warnings=0, voltage_v=24, fault_names=[])
bad = {k: (o.get(k), v) for k, v in want.items() if o.get(k) != v}
assert abs(o[\"output\"][\"torque_nm\"] - 1280 / 256000 * 288.35) < 1e-9, o
sys.exit(str(bad) if bad else 0)'"
expect_true decode_reply_human bash -c "
    out=\$('$J288' decode $REPLY3_SPACED) || exit 1
    grep -q 'reply frame' <<<\"\$out\" && grep -Eq 'voltage +48 \\(24.0 V\\)' <<<\"\$out\" &&
    grep -Eq 'out_pos +1000' <<<\"\$out\" && grep -Eq 'faults +0x00000000 \\(none\\)' <<<\"\$out\""
expect_true decode_command_human bash -c "
    out=\$('$J288' decode $FOC3) || exit 1
    grep -q 'command frame' <<<\"\$out\" && grep -Eq '^  kp +1280 +0.001 N\\*m/rad +83.1457' <<<\"\$out\""
# Separators and prefixes a capture may carry; standard input.
expect_true decode_separators bash -c "
    a=\$('$J288' decode --json 0xfe,0xee,0x80,0x0,0x0,0x0,0x0,0x0,0x0,0x0,0x0,0x0,0x0,0x0,0x0,0x0,0x1d,0x99,0xfb,0x6e 2>&1) ||
    a=fail
    b=\$('$J288' decode --json FE:EE:80:00:00:00:00:00:00:00:00:00:00:00:00:00:1D:99:FB:6E)
    c=\$(echo '$REPLY3_SPACED' | '$J288' decode --json -)
    [ \"\$a\" = \"\$b\" ] && grep -q '\"frame\": \"reply\"' <<<\"\$c\""

# A reply carrying every fault bit (22 named + unknown ones) and every warning bit: names in
# the JSON, computed by Python's own CRC so that the C CRC is not trusted.
expect_true decode_fault_names bash -c "
    hex=\$(python3 - <<'PY'
def crc_core(words):
    crc = 0xFFFFFFFF
    for w in words:
        crc ^= w
        for _ in range(32):
            crc = ((crc << 1) ^ 0x04C11DB7) & 0xFFFFFFFF if crc & 0x80000000 else (crc << 1) & 0xFFFFFFFF
    return crc
b = bytearray(26)
b[0:2] = b'\\xfc\\xee'
b[2] = 0x11; b[3] = 0xF6; b[4] = 200; b[5] = 255      # id 1 FOC, -10 C case, 127.5 V
b[14:18] = (0xFFFFFFFF).to_bytes(4, 'little')
b[18:20] = (0xE000 | 8191).to_bytes(2, 'little')
words = [int.from_bytes(b[i:i+4], 'little') for i in range(2, 22, 4)]
b[22:26] = crc_core(words).to_bytes(4, 'little')
print(b.hex())
PY
)
    '$J288' decode --json \$hex | python3 -c '
import json, sys
o = json.load(sys.stdin)
assert o[\"faults\"] == 0xFFFFFFFF and len(o[\"fault_names\"]) == 32, o
assert o[\"fault_names\"][0] == \"over-current\", o[\"fault_names\"][0]
assert o[\"fault_names\"][18].startswith(\"communication\"), o[\"fault_names\"][18]
assert o[\"fault_names\"][22].startswith(\"unknown fault\"), o[\"fault_names\"][22]
assert o[\"warnings\"] == 7 and o[\"out_pos_raw\"] == 8191 and o[\"case_temp_c\"] == -10, o
assert o[\"voltage_v\"] == 127.5 and o[\"warning_names\"][0].startswith(\"low-voltage\"), o
'"

# JSON validity as `python3 -m json.tool` sees it, for a command and a reply.
expect_true json_tool_command bash -c "'$J288' decode --json $FOC3 | python3 -m json.tool >/dev/null"
expect_true json_tool_reply bash -c "'$J288' decode --json $REPLY3_SPACED | python3 -m json.tool >/dev/null"

# --- golden vectors -------------------------------------------------------------------------
if ls test/vectors/* >/dev/null 2>&1; then
    expect_true golden_vectors python3 test/e2e/cli_vectors.py "$J288" test/vectors
else
    echo "note: test/vectors/ is empty; only the spec's worked frames were checked"
fi

# --- help -----------------------------------------------------------------------------------
for c in "" encode decode scan status hold move torque stop log plot; do
    expect_true "help_${c:-main}" bash -c "out=\$('$J288' $c --help) && grep -q 'usage: j288' <<<\"\$out\""
done
expect_true help_command_form bash -c "'$J288' help encode | grep -q 'usage: j288 encode'"

# --- bad input: one line on stderr, nothing on stdout, non-zero exit ------------------------
LOCK_BAD_CRC=feee80000000000000000000000000001d99fb6f
expect_bad decode_not_hex 1 'not hex' "$J288" decode feee8g
expect_bad decode_not_hex_stdin 1 'not hex' bash -c "printf 'fe ee zz' | '$J288' decode -"
expect_bad decode_odd_length 1 'odd number of hex digits' "$J288" decode feee800
expect_bad decode_wrong_length_cmd 1 'wrong length: 19 bytes' "$J288" decode ${LOCK0:0:38}
expect_bad decode_wrong_length_cmd_long 1 'wrong length: 21 bytes' "$J288" decode ${LOCK0}00
expect_bad decode_wrong_length_reply 1 'wrong length: 25 bytes' "$J288" decode ${REPLY3_SPACED% ee}
expect_bad decode_wrong_length_other 1 'wrong length: 3 bytes' "$J288" decode 010203
expect_bad decode_wrong_header 1 'wrong header fe ef' "$J288" decode feef${LOCK0:4}
expect_bad decode_crc_mismatch 1 'CRC mismatch' "$J288" decode $LOCK_BAD_CRC
expect_bad decode_crc_mismatch_payload 1 'CRC mismatch' "$J288" decode feee81${LOCK0:6}
expect_bad decode_reply_crc_mismatch 1 'CRC mismatch' "$J288" decode ${REPLY3_SPACED/ 24 / 25 }
expect_bad decode_empty 1 'no hex digits' "$J288" decode " "
expect_bad decode_no_arg 2 'no frame given' "$J288" decode
expect_bad decode_unknown_option 2 "unknown option '--jsn'" "$J288" decode --jsn $LOCK0
expect_bad decode_json_value 2 'takes no value' "$J288" decode --json=1 $LOCK0
expect_bad encode_missing_id 2 '--id is required' "$J288" encode
expect_bad encode_missing_value 2 'option --id needs a value' "$J288" encode --id
expect_bad encode_missing_value_last 2 'option --kd-raw needs a value' "$J288" encode --id 1 --kd-raw
expect_bad encode_unknown_option 2 "unknown option '--speeed'" "$J288" encode --id 1 --speeed 3
expect_bad encode_positional 2 "unexpected argument" "$J288" encode --id 1 extra
expect_bad encode_id_range 2 '--id: 16 is out of range 0..15' "$J288" encode --id 16
expect_bad encode_id_negative 2 '--id: -1 is out of range' "$J288" encode --id -1
expect_bad encode_id_garbage 2 "--id: '3x' is not a whole number" "$J288" encode --id 3x
expect_bad encode_id_space 2 "is not a whole number" "$J288" encode --id " 3"
expect_bad encode_id_empty 2 "is not a whole number" "$J288" encode --id=
expect_bad encode_id_hex_garbage 2 "is not a whole number" "$J288" encode --id 0x
expect_bad encode_mode_bad 2 "--mode: 'run' is not lock or foc" "$J288" encode --id 1 --mode run
expect_bad encode_watchdog_bad 2 "--watchdog: 'yes' is not off or on" "$J288" encode --id 1 --watchdog yes
expect_bad encode_side_bad 2 "--side: 'left'" "$J288" encode --id 1 --side left --pos 1
expect_bad encode_tau_raw_range 2 '--tau-raw: 32768 is out of range -32768..32767' "$J288" encode --id 1 --tau-raw 32768
expect_bad encode_speed_raw_range 2 '--speed-raw: -32769 is out of range' "$J288" encode --id 1 --speed-raw -32769
expect_bad encode_pos_raw_range 2 '--pos-raw: 2147483648 is out of range' "$J288" encode --id 1 --pos-raw 2147483648
expect_bad encode_pos_raw_huge 2 '--pos-raw: .* is out of range' "$J288" encode --id 1 --pos-raw 99999999999999999999999
expect_bad encode_kp_raw_negative 2 '--kp-raw: -1 is negative' "$J288" encode --id 1 --kp-raw -1
expect_bad encode_kd_raw_range 2 '--kd-raw: 32768 is out of range 0..32767' "$J288" encode --id 1 --kd-raw 32768
expect_bad encode_tau_si_range 2 '--tau: 37 is out of range' "$J288" encode --id 1 --tau 37
expect_bad encode_tau_si_rotor_range 2 '--tau: 0.2 is out of range .*rotor side' "$J288" encode --id 1 --tau 0.2 --side rotor
expect_bad encode_pos_si_range 2 '--pos: .* is out of range' "$J288" encode --id 1 --pos 1e7
expect_bad encode_kp_si_negative 2 '--kp: -0.5 is negative' "$J288" encode --id 1 --kp -0.5
expect_bad encode_kd_si_range 2 '--kd: 30 is out of range' "$J288" encode --id 1 --kd 30
expect_bad encode_si_garbage 2 "--speed: '1.5rad' is not a number" "$J288" encode --id 1 --speed 1.5rad
expect_bad encode_si_nan 2 "--tau: 'nan' is not a number" "$J288" encode --id 1 --tau nan
expect_bad encode_si_inf 2 "--pos: 'inf' is not a number" "$J288" encode --id 1 --pos inf
expect_bad encode_si_overflow 2 "--pos: 1e999 is out of range" "$J288" encode --id 1 --pos 1e999
expect_bad encode_field_twice 2 '--tau-raw: the field is already set' "$J288" encode --id 1 --tau 0.1 --tau-raw 3
# A ramp speed must be above 0 (the sign is not a direction: --pos gives that); refused
# before any device is needed.
expect_bad move_speed_negative 2 '^j288 move: --speed: -1 is not above 0' env -u J288_PORT "$J288" move --id 1 --pos 0.5 --speed -1
expect_bad move_speed_zero 2 '^j288 move: --speed: 0 is not above 0' env -u J288_PORT "$J288" move --id 1 --pos 0.5 --speed 0
expect_bad no_command 2 'no command given' "$J288"
expect_bad unknown_command 2 "unknown command 'frob'" "$J288" frob
expect_bad global_unknown_option 2 "unknown option '--prot'" "$J288" --prot x scan
expect_bad global_baud_garbage 2 "--baud: '6M' is not a whole number" "$J288" --baud 6M scan
# One number syntax with the robot config file (host/j288_number.h): no hexadecimal reals.
expect_bad encode_hex_real 2 "--pos: '0x1p1' is not a number" "$J288" encode --id 1 --pos 0x1p1
# One udev rule, installed the same way by every page that mentions it.
udev_rule_everywhere() {
    local install='sudo cp docs/99-j288.rules /etc/udev/rules.d/ && sudo udevadm control --reload && sudo udevadm trigger'
    local f
    grep -q '^SUBSYSTEM=="tty", .*GROUP="dialout"' docs/99-j288.rules || return 1
    for f in README.md docs/porting.md docs/troubleshooting.md tools/j288/README.md; do
        grep -qF -- "$install" "$f" || { echo "$f: no '$install'"; return 1; }
        ! grep -q 'ATTRS{idVendor}' "$f" || { echo "$f: a udev rule of its own"; return 1; }
    done
}
expect_true udev_rule_everywhere udev_rule_everywhere

e2e_summary
