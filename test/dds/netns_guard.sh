#!/usr/bin/env bash
# lib_dds.sh's namespace guard: a DDS test started with J288_DDS_NETNS=1 in its environment
# (inherited, not set by the guard) still runs in a private network namespace with only lo;
# the guard reads that from the system, never from the variable (as root, `ip link set lo`
# in the host's namespace would change the host's lo).
set -u
cd "$(dirname "$0")/../.."
. test/dds/lib_dds.sh
if [ "${1:-}" = probe ]; then
    dds_netns "$0" probe
    awk -F: 'NR > 2 { gsub(/ /, "", $1); printf "%s ", $1 }' /proc/net/dev
    readlink /proc/self/ns/net
    exit 0
fi
if dds_private_netns; then
    echo "PASS netns_guard: already in a private namespace here (nothing to tell apart)"; exit 0
fi
if ! unshare -rn true 2>/dev/null; then
    dds_netns "$0" # reports the skip (or, with CI=true, the failure)
fi
host_ns=$(readlink /proc/self/ns/net)
got=$(J288_DDS_NETNS=1 bash "$0" probe)
if [ "${got% *}" = lo ] && [ "${got##* }" != "$host_ns" ]; then
    echo "PASS netns_guard: inherited J288_DDS_NETNS=1, still private ($got)"
else
    echo "FAIL netns_guard: inherited J288_DDS_NETNS=1 ran with interfaces/namespace '$got' (this one: $host_ns)"
    exit 1
fi
