#!/usr/bin/env bash
# Find libyaml for the robot config reader (host/j288_robot_config.c) and write what the build
# needs into DIR/libyaml.env, one VAR=value per line (read by mk/tools.mk and mk/tests.mk):
#   YAML_FOUND=1 or 0
#   YAML_CFLAGS=-DJ288_HAVE_LIBYAML [-I<include dir>]   (empty when not found)
#   YAML_LIBS=-lyaml, or <dir>/libyaml.a                     (empty when not found)
# Order: the system's libyaml (Debian's libyaml-dev; a compile-and-link probe with CC), else
# Debian's libyaml-dev fetched without root (apt-get download with a private apt state, as
# scripts/fetch-unity.sh does; /etc/apt untouched) and unpacked with dpkg-deb -x into DIR/root,
# linking its static libyaml.a (nothing needed at run time), else none: one line says the build
# goes on without robot-config support. Delete DIR to probe again (e.g. after installing).
# Usage: scripts/libyaml.sh [--no-system] DIR [CC]   (--no-system: skip the system probe)
set -euo pipefail
use_system=1
if [ "${1:-}" = --no-system ]; then use_system=0; shift; fi
[ $# -ge 1 ] || { echo "usage: scripts/libyaml.sh [--no-system] DIR [CC]" >&2; exit 2; }
dir=$1
cc=${2:-cc}
mkdir -p "$dir"
dir=$(cd "$dir" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

cat >"$work/probe.c" <<'EOF'
#include <yaml.h>
int main(void)
{
    yaml_parser_t p;
    if (!yaml_parser_initialize(&p))
        return 1;
    yaml_parser_delete(&p);
    return 0;
}
EOF
probe() { # CFLAGS LIBS: compiles and links?
    # shellcheck disable=SC2086
    $cc -std=c99 $1 "$work/probe.c" $2 -o "$work/probe" >/dev/null 2>&1
}
result() { # FOUND CFLAGS LIBS
    printf 'YAML_FOUND=%s\nYAML_CFLAGS=%s\nYAML_LIBS=%s\n' "$1" "$2" "$3" >"$dir/libyaml.env.tmp"
    mv "$dir/libyaml.env.tmp" "$dir/libyaml.env"
}

if [ $use_system -eq 1 ] && probe "" -lyaml; then
    result 1 "-DJ288_HAVE_LIBYAML" "-lyaml"
    exit 0
fi

# A copy fetched earlier into DIR/root, else Debian's package now.
fetch() {
    command -v apt-get >/dev/null && command -v dpkg-deb >/dev/null || return 1
    mkdir -p "$work/lists/partial" "$work/parts" "$work/archives/partial" "$work/deb"
    {
        for f in /etc/apt/sources.list /etc/apt/sources.list.d/*.list; do
            [ -f "$f" ] && grep -E '^[[:space:]]*deb[[:space:]]' "$f"
        done
    } >"$work/sources.list" 2>/dev/null || true
    for f in /etc/apt/sources.list.d/*.sources; do
        [ -f "$f" ] && cp "$f" "$work/parts/"
    done
    local opts=(-o Dir::Etc::SourceList="$work/sources.list" -o Dir::Etc::SourceParts="$work/parts"
        -o Dir::State::Lists="$work/lists" -o Dir::Cache::pkgcache= -o Dir::Cache::srcpkgcache=
        -o Dir::Cache::Archives="$work/archives" -o APT::Sandbox::User="$(id -un)"
        -o Debug::NoLocking=1)
    apt-get "${opts[@]}" -qq update >"$work/apt.log" 2>&1 || return 1
    (cd "$work/deb" && apt-get "${opts[@]}" -qq download libyaml-dev) >>"$work/apt.log" 2>&1 || return 1
    rm -rf "$dir/root"
    dpkg-deb -x "$work"/deb/libyaml-dev_*.deb "$dir/root" || return 1
    basename "$work"/deb/libyaml-dev_*.deb >"$dir/root/.package"
}
local_copy() { # sets inc, lib from DIR/root; true when they are there
    inc=$dir/root/usr/include
    lib=$(find "$dir/root" -name libyaml.a 2>/dev/null | head -n 1)
    [ -f "$inc/yaml.h" ] && [ -n "$lib" ]
}
if local_copy || { fetch && local_copy; }; then
    if probe "-I$inc" "$lib"; then
        result 1 "-DJ288_HAVE_LIBYAML -I$inc" "$lib"
        echo "libyaml: using Debian's $(cat "$dir/root/.package" 2>/dev/null || echo libyaml-dev) unpacked in $dir/root"
        exit 0
    fi
fi
result 0 "" ""
echo "libyaml: not found and not fetched: building without robot config support (install libyaml-dev)"
