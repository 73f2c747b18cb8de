# Helpers for the DDS test scripts (sourced): keep every packet on this machine. dds_netns
# re-runs the calling script inside a private network namespace (`unshare -rn`: a user and a
# network namespace, no privilege needed, only a loopback interface, brought up here), and
# points Cyclone DDS at a loopback-only configuration as well, on a test-specific domain id
# (DDS_DOMAIN). Without unshare (or user namespaces), the script is skipped with a notice;
# with CI=true that is a failure.
# shellcheck shell=bash

DDS_DOMAIN=${DDS_DOMAIN:-87}

# dds_netns "$0" "$@": call first thing; returns inside the namespace.
dds_netns() {
    if [ "${J288_DDS_NETNS:-}" != 1 ]; then
        if ! unshare -rn true 2>/dev/null; then
            if [ "${CI:-}" = true ]; then
                echo "error: unshare -rn fails here (CI=true: a failure): user namespaces needed" >&2
                exit 1
            fi
            echo "notice: skipping $1: unshare -rn (user namespaces) not available" >&2
            exit 0
        fi
        J288_DDS_NETNS=1 exec unshare -rn bash "$@"
    fi
    ip link set lo up 2>/dev/null || { echo "cannot bring lo up in the namespace"; exit 1; }
    export CYCLONEDDS_URI='<CycloneDDS><Domain><General><Interfaces><NetworkInterface name="lo"/></Interfaces></General></Domain></CycloneDDS>'
    export DDS_DOMAIN
}
