#!/usr/bin/env bash
# usage: [BUILD=build] scripts/pip-check.sh   (make pip-check; CI step pip)
# pip without network (Debian's setuptools and wheel: --system-site-packages): a fresh venv,
# `pip install --no-build-isolation .`, `import j288` from outside the tree (the venv's copy
# with its libj288.so, the header's version) scanning j288-sim, pytest against that installed
# package (no J288_LIB, no python/ on the path), a wheel from `python3 -m build` with the library.
set -euo pipefail
cd "$(dirname "$0")/.."
/usr/bin/python3 -c 'import venv, build, pytest, wheel, setuptools' 2>/dev/null ||
    bash scripts/need.sh python3-build-modules python3-venv python3-build python3-pytest \
        python3-wheel python3-setuptools || exit $(($? == 1 ? 0 : 1))
BUILD=${BUILD:-build}
root=$BUILD/pip
rm -rf "$root" && mkdir -p "$root" && root=$(cd "$root" && pwd)
sim=$(cd "${BIN:-$BUILD/bin}" && pwd)/j288-sim
version=$(sed -n 's/.*J288_VERSION_STRING "\(.*\)"/\1/p' lib/include/j288/j288.h)
quiet() { "$@" >"$root/last.log" 2>&1 || { cat "$root/last.log" >&2; return 1; }; }

/usr/bin/python3 -m venv --system-site-packages "$root/v"
quiet "$root/v/bin/pip" install --no-build-isolation --no-index .
site=$("$root/v/bin/python" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')
out=$(cd / && env -u J288_LIB -u PYTHONPATH "$root/v/bin/python" -c 'import j288; print(j288.__file__, j288.__version__)')
[ "$out" = "$site/j288/__init__.py $version" ] || { echo "pip-check: imported '$out'" >&2; exit 1; }
echo "pip install: $out"

timeout 60 "$sim" --ids 1,2,3 --link "$root/bus" --quiet --exit-after 60 >"$root/sim.out" 2>"$root/sim.err" &
sim_pid=$!
trap 'kill $sim_pid 2>/dev/null || true; wait $sim_pid 2>/dev/null || true' EXIT
for _ in $(seq 1 600); do [ -s "$root/sim.out" ] && break; sleep 0.05; done
out=$(cd / && env -u J288_LIB "$root/v/bin/python" -c \
    'import sys, j288; print(sorted(j288.Bus(sys.argv[1], margin_us=250000).scan()))' "$root/bus")
[ "$out" = "[1, 2, 3]" ] || { echo "pip-check: scan printed '$out'" >&2; exit 1; }
echo "installed package scans j288-sim: $out"

# pytest from its own directory, so that only the installed package can be imported.
# A failure shows its report; a pass, the summary line.
(cd python/tests && env -u J288_LIB PYTHONPATH= J288_SIM="$sim" BIN="$(dirname "$sim")" PYTHONDONTWRITEBYTECODE=1 \
    "$root/v/bin/python" -m pytest -q -p no:cacheprovider --import-mode=append . \
    >"$root/pytest.log" 2>&1) || { cat "$root/pytest.log" >&2; exit 1; }
tail -n 1 "$root/pytest.log"

quiet /usr/bin/python3 -m build --wheel --no-isolation --outdir "$root/dist" .
whl=$(ls "$root"/dist/j288-"$version"-*.whl)
grep -q ' j288/libj288.so$' <<<"$(unzip -l "$whl")" || { echo "pip-check: $whl lacks libj288.so" >&2; exit 1; }
echo "wheel: $(basename "$whl") with j288/libj288.so"
