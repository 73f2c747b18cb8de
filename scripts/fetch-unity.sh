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

command -v apt-get >/dev/null || { echo "unity: no apt-get; set UNITY_DIR to a Unity checkout" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/lists/partial" "$work/parts" "$work/src"
# deb-src lines derived from this system's own sources (no mirror host hard-coded).
{
    for f in /etc/apt/sources.list /etc/apt/sources.list.d/*.list; do
        [ -f "$f" ] && grep -E '^[[:space:]]*deb[[:space:]]' "$f" | sed -E 's/^[[:space:]]*deb[[:space:]]/deb-src /'
    done
} > "$work/sources.list" 2>/dev/null || true
for f in /etc/apt/sources.list.d/*.sources; do
    [ -f "$f" ] || continue
    # deb822: rewrite "Types: deb" stanzas to deb-src.
    sed -E 's/^Types:.*/Types: deb-src/' "$f" > "$work/parts/$(basename "$f")"
done
opts=(-o Dir::Etc::SourceList="$work/sources.list" -o Dir::Etc::SourceParts="$work/parts"
      -o Dir::State::Lists="$work/lists" -o Dir::Cache::pkgcache= -o Dir::Cache::srcpkgcache=
      -o APT::Sandbox::User="$(id -un)" -o Debug::NoLocking=1)
apt-get "${opts[@]}" -qq update >"$work/update.log" 2>&1 || { cat "$work/update.log" >&2; echo "unity: apt-get update failed" >&2; exit 1; }
(cd "$work/src" && apt-get "${opts[@]}" -qq source --download-only cjson >"$work/src.log" 2>&1) ||
    { cat "$work/src.log" >&2; echo "unity: could not fetch Debian's cjson source (it carries Unity)" >&2; exit 1; }
tarball=$(ls "$work"/src/cjson_*.orig.tar.* 2>/dev/null | head -n1)
[ -n "$tarball" ] || { echo "unity: cjson source has no orig tarball" >&2; exit 1; }
tar -xf "$tarball" -C "$work/src" --wildcards '*/tests/unity/src/*'
srcdir=$(dirname "$(find "$work/src" -path '*/tests/unity/src/unity.c' | head -n1)")
install_from "$srcdir"
echo "unity: fetched from Debian's cjson source package ($(basename "$tarball"))"
