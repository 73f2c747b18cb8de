#!/usr/bin/env bash
# usage: [UNITY_DIR=DIR] scripts/fetch-unity.sh [DEST]
# Put Unity (unity.c, unity.h, unity_internals.h) into DEST (default build/unity).
# Order of preference: UNITY_DIR (a Unity checkout or its src/ folder the user points at),
# a copy already fetched, then the unmodified Unity that Debian's cjson source package
# carries under tests/unity/ (fetched with a private apt configuration: no root, /etc/apt
# untouched). Unity is never committed to this repository.
set -euo pipefail
dest=${1:-build/unity}
mkdir -p "$dest"
dest=$(cd "$dest" && pwd)

have() { [ -f "$dest/unity.c" ] && [ -f "$dest/unity.h" ] && [ -f "$dest/unity_internals.h" ]; }

install_from() { # $1: a folder holding unity.c & co.
    cp "$1/unity.c" "$1/unity.h" "$1/unity_internals.h" "$dest/"
    # cJSON's copy points unity_internals.h at ../examples/unity_config.h; restore upstream's
    # optional form so that no config file is needed.
    sed -i 's|^#include "../examples/unity_config.h"|#ifdef UNITY_INCLUDE_CONFIG_H\n#include "unity_config.h"\n#endif|' \
        "$dest/unity_internals.h"
}

if [ -n "${UNITY_DIR:-}" ]; then
    for d in "$UNITY_DIR/src" "$UNITY_DIR"; do
        if [ -f "$d/unity.c" ]; then install_from "$d"; echo "unity: from UNITY_DIR ($d)"; exit 0; fi
    done
    echo "unity: UNITY_DIR=$UNITY_DIR holds no unity.c" >&2
    exit 1
fi
if have; then exit 0; fi

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
bash "$(dirname "$0")/apt-source.sh" cjson "$work/src" ||
    { echo "unity: could not fetch Debian's cjson source (it carries Unity); or set UNITY_DIR" >&2; exit 1; }
tarball=$(ls "$work"/src/cjson_*.orig.tar.* 2>/dev/null | head -n1)
[ -n "$tarball" ] || { echo "unity: cjson source has no orig tarball" >&2; exit 1; }
tar -xf "$tarball" -C "$work/src" --wildcards '*/tests/unity/src/*'
srcdir=$(dirname "$(find "$work/src" -path '*/tests/unity/src/unity.c' | head -n1)")
install_from "$srcdir"
echo "unity: fetched from Debian's cjson source package ($(basename "$tarball"))"
