#!/usr/bin/env bash
# The CMake side of CI, from the repository root:
#   1. configure + build the library, the host programs and every host test, check that ctest
#      registers exactly the tests `make test` runs (same names, `make test-list`), run ctest;
#   2. install to a temporary prefix and build/run a consumer with find_package(j288);
#   3. build/run the same consumer embedding j288 with add_subdirectory;
#   4. cross-configure and build the library with cmake/arm-none-eabi.cmake (Cortex-M0 soft
#      float and Cortex-M4F hard float).
# Build trees go under ${CMAKE_BUILD_ROOT:-build/cmake}. Needs cmake and a C compiler; step 4
# needs arm-none-eabi-gcc (skipped with a notice outside CI, a failure with CI=true).
set -euo pipefail
cd "$(dirname "$0")/.."
root=${CMAKE_BUILD_ROOT:-build/cmake}
jobs=$(nproc 2>/dev/null || echo 2)
mkdir -p "$root"
root=$(cd "$root" && pwd)

need() { # need TOOL PACKAGE
    command -v "$1" >/dev/null 2>&1 && return 0
    if [ "${CI:-}" = true ]; then echo "ci-cmake: $1 missing (apt-get install $2)" >&2; exit 1; fi
    echo "ci-cmake: skipping: $1 not found (install Debian package $2)"
    return 1
}
need cmake cmake || exit 0

# Unity: the one the user points at, else the copy a Make build already fetched, else CMake
# fetches its own (scripts/fetch-unity.sh).
unity_args=()
if [ -n "${UNITY_DIR:-}" ]; then
    unity_args=(-DUNITY_DIR="$UNITY_DIR")
elif [ -f "${BUILD:-build}/unity/unity.c" ]; then
    unity_args=(-DUNITY_DIR="$(cd "${BUILD:-build}/unity" && pwd)")
fi

echo "== cmake: host build and ctest"
# RelWithDebInfo without -DNDEBUG: the Makefile's -O2 -g.
cmake -S . -B "$root/host" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O2 -g" \
    "${unity_args[@]}" >/dev/null
cmake --build "$root/host" -j "$jobs"

# The two builds must run the same tests: compare the names, not just the counts.
make -s --no-print-directory BUILD="$root/make-list" test-list | sort >"$root/tests-make.txt"
(cd "$root/host" && ctest -N) | sed -n 's/^ *Test *#[0-9]*: //p' | sort >"$root/tests-ctest.txt"
n_make=$(wc -l <"$root/tests-make.txt")
n_ctest=$(wc -l <"$root/tests-ctest.txt")
if [ "$n_make" -eq 0 ] || ! cmp -s "$root/tests-make.txt" "$root/tests-ctest.txt"; then
    echo "ci-cmake: ctest registers $n_ctest tests, make test runs $n_make; they differ" \
         "(< only in make test-list, > only in ctest):" >&2
    diff "$root/tests-make.txt" "$root/tests-ctest.txt" >&2 || true
    exit 1
fi
echo "ci-cmake: ctest and make test run the same $n_ctest tests"
(cd "$root/host" && ctest --output-on-failure -j "$jobs")

echo "== cmake: install + find_package consumer"
prefix=$(mktemp -d)
work=$(mktemp -d)
trap 'rm -rf "$prefix" "$work"' EXIT
cmake --install "$root/host" --prefix "$prefix" >/dev/null
test -f "$prefix/include/j288/j288.h"
test -f "$prefix/lib/cmake/j288/j288Config.cmake" || test -f "$prefix/lib64/cmake/j288/j288Config.cmake"
cp -r test/cmake_consumer "$work/consumer"
cmake -S "$work/consumer" -B "$work/build-installed" -DCMAKE_PREFIX_PATH="$prefix" >/dev/null
cmake --build "$work/build-installed" -j "$jobs"
"$work/build-installed/j288_consumer"

echo "== cmake: add_subdirectory consumer"
cmake -S "$work/consumer" -B "$work/build-subdir" -DJ288_SOURCE_DIR="$PWD" >/dev/null
cmake --build "$work/build-subdir" -j "$jobs"
"$work/build-subdir/j288_consumer"

echo "== cmake: arm-none-eabi toolchain file"
if need arm-none-eabi-gcc gcc-arm-none-eabi; then
    cmake -S . -B "$root/arm-m4f" -DCMAKE_TOOLCHAIN_FILE=cmake/arm-none-eabi.cmake \
        -DCMAKE_BUILD_TYPE=MinSizeRel -DJ288_CONFIG_SI_FLOAT=ON >/dev/null
    cmake --build "$root/arm-m4f" -j "$jobs"
    cmake -S . -B "$root/arm-m0" -DCMAKE_TOOLCHAIN_FILE=cmake/arm-none-eabi.cmake \
        -DCMAKE_BUILD_TYPE=MinSizeRel -DJ288_ARM_FLAGS="-mcpu=cortex-m0 -mthumb -mfloat-abi=soft" \
        -DJ288_CONFIG_SI=OFF >/dev/null
    cmake --build "$root/arm-m0" -j "$jobs"
    arm-none-eabi-size -t "$root/arm-m4f/lib/libj288.a" | tail -n 1 | sed 's/^/  m4f total: /'
    arm-none-eabi-size -t "$root/arm-m0/lib/libj288.a" | tail -n 1 | sed 's/^/  m0  total: /'
fi
echo "ci-cmake: ok"
