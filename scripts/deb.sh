#!/usr/bin/env bash
# usage: [BUILD=build] scripts/deb.sh build|check    (make deb, make deb-check; CI step deb)
# build: libj288-0, libj288-dev, j288-tools, j288-dds, python3-j288 into $BUILD/deb/ with
#   debhelper, from a copy of the tree with a debian/changelog of the one version; lintian
#   without errors; only j288-dds depends on Cyclone DDS (libddsc).
# check: then apt install them for real (root or sudo: CI, or a machine you may change), check
#   j288 --version, j288-dds --version, pkg-config, find_package(j288) (test/cmake_consumer),
#   j288-dds's systemd unit (systemd-analyze verify, offline),
#   import j288 and the completion, purge them and check that none of their files is left.
set -euo pipefail
cd "$(dirname "$0")/.."
mode=${1:-build}
for t in dpkg-buildpackage:dpkg-dev dh:debhelper lintian:lintian fakeroot:fakeroot help2man:help2man; do
    bash scripts/need.sh "${t%%:*}" "${t##*:}" || exit $(($? == 1 ? 0 : 1))
done
BUILD=${BUILD:-build}
out=$BUILD/deb
version=$(sed -n 's/.*J288_VERSION_STRING "\(.*\)"/\1/p' lib/include/j288/j288.h)
src=$out/src/j288-$version
rm -rf "$out" && mkdir -p "$src" && out=$(cd "$out" && pwd) && src=$out/src/j288-$version
quiet() { "$@" >"$out/last.log" 2>&1 || { tail -n 40 "$out/last.log" >&2; return 1; }; }

# The sources without build products (whatever BUILD is, nothing under build/ is a source).
tar -cf - --exclude=./build --exclude=./.git --exclude="./$BUILD" --exclude='*.egg-info' \
    --exclude=./python/j288/libj288.so --exclude=__pycache__ . | tar -xf - -C "$src"
printf 'j288 (%s) unstable; urgency=medium\n\n  * Release %s (CHANGELOG.md).\n\n -- %s  %s\n' "$version" \
    "$version" "$(sed -n 's/^Maintainer: //p' debian/control)" "$(date -R)" >"$src/debian/changelog"
# (noddebs: the five packages, without the -dbgsym ones)
(cd "$src" && DEB_BUILD_OPTIONS="noddebs ${DEB_BUILD_OPTIONS:-}" quiet dpkg-buildpackage -b -us -uc -j2)
mv "$out"/src/*.deb "$out"/src/*.changes "$out"/src/*.buildinfo "$out"/
ls "$out"/*.deb
lintian --suppress-tags initial-upload-closes-no-bugs "$out"/*.changes 2>&1 |
    { grep -v '^running with root privileges' || true; } | tee "$out/lintian.txt"
! grep -q '^E: ' "$out/lintian.txt" || { echo "deb: lintian reports errors" >&2; exit 1; }
echo "lintian: no errors"
for p in j288-tools j288-dds; do dpkg-deb -f "$out/${p}_${version}_"*.deb Depends | sed "s/^/$p: /"; done |
    tee "$out/depends.txt"
[ "$(grep -c libddsc "$out/depends.txt")" = 1 ] && grep -q '^j288-dds: .*libddsc' "$out/depends.txt" ||
    { echo "deb: libddsc must be a dependency of j288-dds alone" >&2; exit 1; }
# j288-dds ships its systemd unit (debian/j288-dds@.service, docs/dds.md "Running on a robot")
dpkg-deb -c "$out/j288-dds_${version}_"*.deb >"$out/j288-dds.files" # (grep -q on a pipe: SIGPIPE)
grep -q ' ./lib/systemd/system/j288-dds@.service$' "$out/j288-dds.files" ||
    { echo "deb: j288-dds lacks lib/systemd/system/j288-dds@.service" >&2; exit 1; }
[ "$mode" = check ] || exit 0

sudo=
[ "$(id -u)" -eq 0 ] || sudo=sudo
pkgs=(libj288-0 libj288-dev j288-tools j288-dds python3-j288)
for p in "${pkgs[@]}"; do dpkg-deb -c "$out/${p}_${version}_"*.deb; done |
    awk '{ sub(/^\./, "", $6); sub(/\/$/, "", $6) } $1 !~ /^d/ || $6 ~ /\/j288$/ { print $6 }' | sort >"$out/files.txt"
trap '$sudo apt-get purge -y -qq "${pkgs[@]}" >/dev/null 2>&1 || true' EXIT
quiet $sudo apt-get install -y -o DPkg::Lock::Timeout=300 --no-install-recommends "$out"/*.deb
for tool in j288 j288-dds; do
    [ "$(cd / && $tool --version)" = "$tool $version" ] || { echo "deb: $tool --version: $($tool --version)" >&2; exit 1; }
done
[ "$(pkg-config --modversion j288)" = "$version" ] || { echo "deb: pkg-config says $(pkg-config --modversion j288)" >&2; exit 1; }
quiet cmake -S test/cmake_consumer -B "$out/consumer"
quiet cmake --build "$out/consumer"
echo "find_package(j288): $("$out/consumer/j288_consumer")"
# the unit as installed, its ExecStart and man page included (no systemd needs to run)
unit_out=$(systemd-analyze verify /lib/systemd/system/j288-dds@.service 2>&1) && [ -z "$unit_out" ] ||
    { echo "deb: systemd-analyze verify j288-dds@.service: $unit_out" >&2; exit 1; }
echo "systemd-analyze verify /lib/systemd/system/j288-dds@.service: clean"
py=$(cd / && env -u J288_LIB -u PYTHONPATH -u PYTHONDONTWRITEBYTECODE $sudo /usr/bin/python3 -c 'import j288; print(j288.__file__, j288.__version__)')
[ "$py" = "/usr/lib/python3/dist-packages/j288/__init__.py $version" ] || { echo "deb: python: $py" >&2; exit 1; }
echo "python3 -c 'import j288': $py"
out_c=$(bash test/e2e/completion.sh /usr/share/bash-completion/completions/j288 2>&1) ||
    { echo "deb: the completion: $out_c" >&2; exit 1; }
echo "bash completion: $(tail -n 2 <<<"$out_c" | head -n 1)"
quiet $sudo apt-get purge -y -o DPkg::Lock::Timeout=300 "${pkgs[@]}"
trap - EXIT
left=$(while read -r f; do if [ -e "$f" ] || [ -L "$f" ]; then echo "$f"; fi; done <"$out/files.txt")
[ -z "$left" ] || { echo "deb: left after purge: $left" >&2; exit 1; }
echo "purged: none of the $(wc -l <"$out/files.txt") files left"
