#!/usr/bin/env bash
# Golden bytes: what Cyclone DDS serializes for a sensor_msgs JointState_, a unitree_go
# LowCmd_ (with the crc of tools/j288-dds/unitree_crc.c) and a std_msgs Header_, and the crc
# of a unitree_go LowState_ and of unitree_hg's LowCmd_ and LowState_ (build/test/dds_golden),
# against the bytes test/dds/golden.py computes from the XCDR1 rules and unitree's crc32_core;
# the ROS 2 type hashes of tools/j288-dds/typehash.c against test/dds/typehash.py's, computed
# from the IDL. Inside a private network namespace (lib_dds.sh).
set -u
cd "$(dirname "$0")/../.."
. test/dds/lib_dds.sh
dds_netns "$0" "$@"
BUILD=${BUILD:-build}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
python3 test/dds/golden.py >"$tmp/expected" || exit 1
python3 test/dds/typehash.py tools/j288-dds/idl | sed 's/^/typehash /' >>"$tmp/expected" || exit 1
"$BUILD/test/dds_golden" "$DDS_DOMAIN" >"$tmp/got" 2>"$tmp/err" || { cat "$tmp/err"; exit 1; }
fail=0
for name in lowcmd_crc lowstate_crc hg_lowcmd_crc hg_lowstate_crc joint_state lowcmd header \
    $(sed -n 's/^typehash \([^ ]*\) .*/typehash \1/p' "$tmp/expected" | tr ' ' '@'); do
    name=${name//@/ }
    want=$(sed -n "s|^$name ||p" "$tmp/expected")
    got=$(sed -n "s|^$name ||p" "$tmp/got")
    if [ -n "$want" ] && [ "$want" = "$got" ]; then
        echo "PASS golden $name (${#want} hex digits)"
    else
        echo "FAIL golden $name"; echo "  expected $want"; echo "  cyclone  $got"; fail=1
    fi
done
exit $fail
