#!/usr/bin/env bash
# usage: [BUILD=build] [BIN=$BUILD/bin] [J288_LIB=$BUILD/lib/libj288.so] [PYTEST_PYTHON=python]
#        scripts/python-test.sh
# The Python package's tests (python/tests, pytest) against j288-sim, with this build's
# shared library ($J288_LIB). The interpreter: $PYTEST_PYTHON, else the first of python3 and
# /usr/bin/python3 (Debian's, where python3-pytest installs) that has pytest. Without pytest:
# a notice and success; with CI=true a failure. A library built with a sanitizer cannot be
# loaded into the interpreter (its runtime must come first): skipped with a notice.
set -u
cd "$(dirname "$0")/.."
BIN=${BIN:-${BUILD:-build}/bin}
py=
for cand in ${PYTEST_PYTHON:-} python3 /usr/bin/python3; do
    if command -v "$cand" >/dev/null 2>&1 && "$cand" -c 'import pytest' 2>/dev/null; then
        py=$cand
        break
    fi
done
if [ -z "$py" ]; then
    if [ "${CI:-}" = true ]; then
        echo "error: pytest not found (CI=true: a missing tool is a failure); install: python3-pytest" >&2
        exit 1
    fi
    echo "notice: skipping the Python tests, pytest not found; install with: apt-get install -y --no-install-recommends python3-pytest" >&2
    exit 0
fi
export J288_LIB=${J288_LIB:-${BUILD:-build}/lib/libj288.so}
[ -f "$J288_LIB" ] || { echo "python-test: $J288_LIB missing (make shared)" >&2; exit 1; }
J288_LIB=$(cd "$(dirname "$J288_LIB")" && pwd)/$(basename "$J288_LIB")
if readelf -d "$J288_LIB" 2>/dev/null | grep -qE 'lib(asan|ubsan|tsan)'; then
    echo "notice: skipping the Python tests: $J288_LIB is built with a sanitizer" >&2
    exit 0
fi
export J288_SIM=${J288_SIM:-$BIN/j288-sim}
exec env PYTHONPATH=python PYTHONDONTWRITEBYTECODE=1 "$py" -m pytest -q -p no:cacheprovider python/tests
