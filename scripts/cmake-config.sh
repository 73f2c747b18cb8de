#!/usr/bin/env bash
# usage: scripts/cmake-config.sh DIR VERSION LIBDIR INCLUDEDIR [DEFINES]
# `make install`'s CMake package config: j288Config.cmake and j288ConfigVersion.cmake in DIR
# (<prefix>/LIBDIR/cmake/j288), filled from cmake/*.cmake.in as cmake/j288_install.cmake does
# for `cmake --install`. LIBDIR and INCLUDEDIR are relative to the prefix; DEFINES is the
# ;-list of J288_CONFIG_* definitions the library was built with (empty: config.h's defaults).
set -euo pipefail
dir=$1 version=$2 libdir=$3 includedir=$4 defines=${5:-}
case "$libdir$includedir" in /*) echo "cmake-config: LIBDIR and INCLUDEDIR must be under PREFIX" >&2; exit 1 ;; esac
up=$(printf '%s' "$libdir/cmake/j288" | sed 's|[^/][^/]*|..|g')
major=${version%%.*}
minor=$(printf '%s' "$version" | cut -d. -f2)
mkdir -p "$dir"
for f in j288Config j288ConfigVersion; do
    sed -e "s|@J288_CONFIG_TO_PREFIX@|$up|g" -e "s|@J288_LIBDIR@|$libdir|g" \
        -e "s|@J288_INCLUDEDIR@|$includedir|g" -e "s|@J288_DEFINES@|$defines|g" \
        -e "s|@J288_VERSION@|$version|g" -e "s|@J288_VERSION_MAJOR@|$major|g" \
        -e "s|@J288_VERSION_MINOR@|$minor|g" "cmake/$f.cmake.in" >"$dir/$f.cmake"
    chmod 644 "$dir/$f.cmake"
done
