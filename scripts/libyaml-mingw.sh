#!/usr/bin/env bash
# usage: scripts/libyaml-mingw.sh DIR CC
# libyaml for the Windows cross build (Debian packages no mingw-w64 libyaml): Debian's own
# libyaml source package (scripts/apt-source.sh; no root, /etc/apt untouched) cross-compiled
# with CC into DIR/libyaml.a, static (YAML_DECLARE_STATIC: nothing to ship beside j288.exe).
# Writes DIR/libyaml.env as mk/tools.mk does for the host (YAML_CFLAGS, YAML_LIBS). When the
# source cannot be fetched: both empty and one line saying so; the config reader then builds
# as its stubs, which refuse robot config files with a message that says why.
# Delete DIR to build again.
set -euo pipefail
[ $# -eq 2 ] || { echo "usage: scripts/libyaml-mingw.sh DIR CC" >&2; exit 2; }
mkdir -p "$1"
dir=$(cd "$1" && pwd)
cc=$2
result() { # CFLAGS LIBS
    printf 'YAML_CFLAGS=%s\nYAML_LIBS=%s\n' "$1" "$2" >"$dir/libyaml.env.tmp"
    mv "$dir/libyaml.env.tmp" "$dir/libyaml.env"
}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

if [ ! -f "$dir/libyaml.a" ]; then
    if ! bash "$(dirname "$0")/apt-source.sh" libyaml "$work/src" >"$work/fetch.log" 2>&1; then
        result "" ""
        echo "libyaml (Windows): Debian's libyaml source not fetched: robot config files are refused by j288.exe"
        exit 0
    fi
    tar -xzf "$work"/src/libyaml_*.orig.tar.gz -C "$work"
    src=$(dirname "$(find "$work" -path '*/src/api.c' | head -n 1)")
    top=$(dirname "$src")
    ver() { sed -n "s/^set (YAML_VERSION_$1 \([0-9]*\))/\1/p" "$top/CMakeLists.txt"; }
    major=$(ver MAJOR) minor=$(ver MINOR) patch=$(ver PATCH)
    mkdir -p "$dir/include" "$work/obj"
    for c in "$src"/*.c; do
        # Third-party code: its own warnings are not ours to fix.
        "$cc" -std=gnu99 -O2 -w -DYAML_DECLARE_STATIC -DYAML_VERSION_MAJOR="$major" \
            -DYAML_VERSION_MINOR="$minor" -DYAML_VERSION_PATCH="$patch" \
            -DYAML_VERSION_STRING="\"$major.$minor.$patch\"" -I"$top/include" \
            -c "$c" -o "$work/obj/$(basename "$c" .c).o"
    done
    ar=${cc%gcc}ar
    "$ar" rcs "$dir/libyaml.a.tmp" "$work"/obj/*.o
    cp "$top/include/yaml.h" "$dir/include/"
    mv "$dir/libyaml.a.tmp" "$dir/libyaml.a"
    basename "$work"/src/libyaml_*.dsc .dsc >"$dir/.package"
    echo "libyaml (Windows): Debian's $(cat "$dir/.package") cross-built into $dir/libyaml.a"
fi
result "-DJ288_HAVE_LIBYAML -DYAML_DECLARE_STATIC -I$dir/include" "$dir/libyaml.a"
