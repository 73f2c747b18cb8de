#!/usr/bin/env bash
# usage: scripts/check-consumers.sh   (from anywhere; build trees under $BUILD/consumers)
# The ways a project takes j288, each built and run (test/cmake_consumer encodes the
# protocol's worked frame): find_package(j288) after `cmake --install --prefix` and after
# `make install PREFIX=/usr DESTDIR=...` (the same install; the tools installed with them must
# run, with their man pages and bash completion), `make uninstall` leaving nothing of it,
# add_subdirectory, and the library cross-built with cmake/arm-none-eabi.cmake for Cortex-M4F
# and Cortex-M0 (SI off), and a pkg-config consumer (test/e2e/pkgconfig_consumer.c, against
# the shared library of both installs). Every install's j288, j288-sim, j288-dds (with Cyclone
# DDS) and j288.pc, and the Python package (imported with PYTHONPATH alone), say the header's
# version. Needs cmake; the cross build needs arm-none-eabi-gcc, the pkg-config consumer
# pkg-config.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/need.sh cmake cmake || exit $(($? == 1 ? 0 : 1))
root=${BUILD:-build}/consumers
rm -rf "$root" && mkdir -p "$root" && root=$(cd "$root" && pwd)
jobs=$(nproc 2>/dev/null || echo 2)
quiet() { "$@" >"$root/last.log" 2>&1 || { cat "$root/last.log" >&2; return 1; }; }
version=$(sed -n 's/.*J288_VERSION_STRING "\(.*\)"/\1/p' lib/include/j288/j288.h)
# same_version WHAT TEXT: TEXT ends in the header's version.
same_version() {
    case "$2" in *" $version" | "$version") ;;
        *) echo "check-consumers: $1 says '$2', the header $version" >&2; exit 1 ;; esac
}

# consumer NAME SOURCE PROGRAM CMAKE_ARGS...: configure and build the CMake project SOURCE, run
# its PROGRAM.
consumer() {
    local name=$1 src=$2 exe=$3; shift 3
    quiet cmake -S "$src" -B "$root/$name" "$@"
    quiet cmake --build "$root/$name" -j "$jobs"
    echo "$name: $(env -u LD_LIBRARY_PATH "$root/$name/$exe")"
}
# The consumers: test/cmake_consumer (j288::j288), and test/e2e/pkgconfig_consumer.c (the
# library, the Linux port and the runner) built against the target j288::robot.
cmake_consumer() { consumer "$1" test/cmake_consumer j288_consumer "${@:2}"; }
robot_consumer() { consumer "$1" "$root/robot-consumer" robot_consumer "${@:2}"; }
mkdir -p "$root/robot-consumer"
cat >"$root/robot-consumer/CMakeLists.txt" <<EOF
cmake_minimum_required(VERSION 3.13)
project(j288_robot_consumer LANGUAGES C)
if(J288_SOURCE_DIR)
    set(J288_BUILD_TOOLS ON)
    add_subdirectory("\${J288_SOURCE_DIR}" j288)
else()
    find_package(j288 0.1 REQUIRED)
endif()
add_executable(robot_consumer "$PWD/test/e2e/pkgconfig_consumer.c")
target_link_libraries(robot_consumer PRIVATE j288::robot)
EOF
# installed PREFIX LIBDIR: what an install must hold, then a find_package consumer against it.
installed() {
    local p=$1 l=$2 f
    for f in include/j288/j288.h include/j288/j288_robot.h include/j288/j288_serial.h include/j288/j288_rt.h \
        $l/libj288.a $l/libj288.so \
        $l/pkgconfig/j288.pc $l/cmake/j288/j288Config.cmake bin/j288 bin/j288-sim \
        share/man/man1/j288.1 share/man/man1/j288-sim.1 share/bash-completion/completions/j288; do
        [ -f "$p/$f" ] || { echo "check-consumers: $p/$f not installed" >&2; exit 1; }
    done
    grep -q '^\.TH J288 "1"' "$p/share/man/man1/j288.1" && grep -q 'calibrate' "$p/share/man/man1/j288.1" ||
        { echo "check-consumers: $p/share/man/man1/j288.1 is not j288's man page" >&2; exit 1; }
    out=$(PATH=$p/bin:$PATH bash test/e2e/completion.sh "$p/share/bash-completion/completions/j288" 2>&1) ||
        { echo "check-consumers: the installed completion: $out" >&2; exit 1; }
    same_version "$p/bin/j288 --version" "$("$p/bin/j288" --version 2>&1)"
    same_version "$p/bin/j288-sim --version" "$("$p/bin/j288-sim" --version 2>&1)"
    if pkg-config --exists CycloneDDS 2>/dev/null; then # the DDS bridge: built where Cyclone DDS is
        grep -q '^\.TH J288-DDS "1"' "$p/share/man/man1/j288-dds.1" ||
            { echo "check-consumers: $p/share/man/man1/j288-dds.1 is not j288-dds's man page" >&2; exit 1; }
        same_version "$p/bin/j288-dds --version" "$("$p/bin/j288-dds" --version 2>&1)"
    fi
    cmake_consumer "find_package-$(basename "$p")" -DCMAKE_PREFIX_PATH="$p"
    robot_consumer "find_package-robot-$(basename "$p")" -DCMAKE_PREFIX_PATH="$p"
    pkgconfig_consumer "$p" "$l"
}
# pkgconfig_consumer PREFIX: build test/e2e/pkgconfig_consumer.c with pkg-config's flags for
# the j288.pc under PREFIX and run it against that prefix's shared library.
pkgconfig_consumer() {
    local p=$1 exe=$root/pkgconfig-$(basename "$1") pc=$1/$2/pkgconfig
    if ! command -v pkg-config >/dev/null 2>&1; then
        bash scripts/need.sh pkg-config pkg-config || { [ $? -eq 1 ] && return 0; exit 1; }
    fi
    quiet ${CC:-cc} -std=c99 -Wall -Wextra -Werror test/e2e/pkgconfig_consumer.c -o "$exe" \
        $(PKG_CONFIG_PATH="$pc" pkg-config --cflags --libs j288)
    local out
    out=$(LD_LIBRARY_PATH="$p/$2" "$exe")
    echo "pkg-config-$(basename "$p"): $out"
    same_version "$pc/j288.pc" "$(PKG_CONFIG_PATH="$pc" pkg-config --modversion j288)"
}
# installed_python PREFIX: the package the install puts in PREFIX/lib/python3/dist-packages
# loads the shared library of its own prefix, with PYTHONPATH and nothing else set (each of
# python3 and Debian's /usr/bin/python3 that exists).
installed_python() {
    local p=$1 py out
    for py in python3 /usr/bin/python3; do
        command -v "$py" >/dev/null 2>&1 || continue
        out=$(cd / && env -u LD_LIBRARY_PATH -u J288_LIB PYTHONPATH="$p/lib/python3/dist-packages" \
            PYTHONDONTWRITEBYTECODE=1 "$py" -c 'import j288; print(j288.__file__, j288.__version__)' 2>&1) ||
            { echo "check-consumers: $py cannot import the installed package: $out" >&2; exit 1; }
        case "$out" in "$p/"*) ;; *) echo "check-consumers: $py imported $out, not $p's" >&2; exit 1 ;; esac
        same_version "python ($py) j288.__version__" "$out"
        echo "python-$(basename "$p") ($py): j288 $version"
    done
}

# make install with Debian's prefix (the libraries in the multiarch directory), the same tree
# installed with cmake --install --prefix elsewhere, then make uninstall.
mk=(make -j"$jobs" BUILD="$root/make" PREFIX=/usr DESTDIR="$root/make-destdir")
quiet "${mk[@]}" install
libdir=lib/$(gcc -print-multiarch 2>/dev/null || echo .)
installed "$root/make-destdir/usr" "$libdir"
installed_python "$root/make-destdir/usr"
quiet cmake --install "$root/make/cmake" --prefix "$root/cmake-prefix"
installed "$root/cmake-prefix" "$libdir"
installed_python "$root/cmake-prefix"
quiet "${mk[@]}" uninstall
left=$(cd "$root/make-destdir" && find . ! -type d -o -name j288)
[ -z "$left" ] || { echo "check-consumers: make uninstall left: $left" >&2; exit 1; }
echo "make uninstall: nothing left of $(wc -l <"$root/make/cmake/install_manifest.txt") files"
cmake_consumer add_subdirectory -DJ288_SOURCE_DIR="$PWD"
robot_consumer add_subdirectory-robot -DJ288_SOURCE_DIR="$PWD"

bash scripts/need.sh arm-none-eabi-gcc gcc-arm-none-eabi || exit $(($? == 1 ? 0 : 1))
for cpu in cortex-m4f cortex-m0; do
    args=(-DCMAKE_TOOLCHAIN_FILE=cmake/arm-none-eabi.cmake -DCMAKE_BUILD_TYPE=MinSizeRel -DJ288_CPU=$cpu)
    [ $cpu = cortex-m0 ] && args+=(-DJ288_CONFIG_SI=OFF)
    quiet cmake -S . -B "$root/$cpu" "${args[@]}"
    quiet cmake --build "$root/$cpu" -j "$jobs"
    echo "$cpu: $(arm-none-eabi-size -t "$root/$cpu/lib/libj288.a" | tail -n 1)"
done
echo "check-consumers: ok"
