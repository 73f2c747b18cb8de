#!/usr/bin/env bash
# usage: scripts/apt-source.sh PACKAGE DEST
# Download Debian's source package PACKAGE (its .dsc and tarballs, unpacked by nobody) into
# DEST without root and without touching /etc/apt: a private apt state whose deb-src lines are
# derived from this system's own sources (no mirror host hard-coded). Used for what Debian
# carries but does not package for us: Unity (inside cjson's source, scripts/fetch-unity.sh),
# libyaml for the Windows cross build (scripts/libyaml-mingw.sh).
set -euo pipefail
[ $# -eq 2 ] || { echo "usage: scripts/apt-source.sh PACKAGE DEST" >&2; exit 2; }
pkg=$1
mkdir -p "$2"
dest=$(cd "$2" && pwd)
command -v apt-get >/dev/null || { echo "apt-source: no apt-get" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/lists/partial" "$work/parts"
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
apt-get "${opts[@]}" -qq update >"$work/update.log" 2>&1 ||
    { cat "$work/update.log" >&2; echo "apt-source: apt-get update failed" >&2; exit 1; }
(cd "$dest" && apt-get "${opts[@]}" -qq source --download-only "$pkg" >"$work/src.log" 2>&1) ||
    { cat "$work/src.log" >&2; echo "apt-source: could not fetch Debian's $pkg source" >&2; exit 1; }
