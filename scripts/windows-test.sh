#!/usr/bin/env bash
# usage: WIN=build/windows SIM=build/bin/j288-sim scripts/windows-test.sh [--bench] UNIT_TEST.exe...
# The Windows build under Wine (make test-windows, make bench-windows):
#  1. a private Wine prefix, $WIN/wine (created on first use, 10-30 s; never ~/.wine), headless
#     (DISPLAY unset), quiet (WINEDEBUG=-all), one wineserver for the whole run whose output
#     goes to $WIN/wineserver.log (it prints its object table when a pty it holds hangs up);
#  2. every unit test program given, under wine (scripts/run-tests.sh with TEST_WRAPPER=wine);
#  3. the Windows port end to end: j288-sim on pseudo-terminals, the prefix's dosdevices/comN
#     symlinked to them, test_windows_port.exe (through j288.dll) on COM5..COM8, and the frames
#     it sent compared byte for byte with what the simulator logged;
#  4. $WIN/j288.exe end to end (test/e2e/windows_cli.sh), and
#     j288.dll exporting every function the Python package binds (test/windows/dll_exports.py);
#  5. a CMake consumer (test/cmake_consumer, add_subdirectory) cross-built with
#     cmake/mingw-w64.cmake and run under wine (skipped with a notice without cmake);
#  6. the Wine server stopped (also on failure or interruption).
# --bench runs bench_windows_port.exe against one simulator instead of 2 and 3.
set -euo pipefail
cd "$(dirname "$0")/.."
WIN=${WIN:-build/windows}
SIM=${SIM:-build/bin/j288-sim}
bench=false
if [ "${1:-}" = --bench ]; then bench=true; shift; fi

mkdir -p "$WIN"
WIN=$(cd "$WIN" && pwd) # BUILD may be relative or absolute
export WINEPREFIX=$WIN/wine WINEDEBUG=-all WINEDLLOVERRIDES="mscoree,mshtml="
# j288.dll for the programs linked with its import library.
export WINEPATH="Z:${WIN//\//\\}"
unset DISPLAY WAYLAND_DISPLAY

tmp=$(mktemp -d /tmp/j288-wine.XXXXXX)
SIM_DIR=$tmp BIN=$(dirname "$SIM")
# lib_sim.sh scales its bounds with lib_e2e.sh's e2e_scaled (TEST_TIME_SCALE).
# shellcheck source=test/e2e/lib_e2e.sh
. test/e2e/lib_e2e.sh
# shellcheck source=test/e2e/lib_sim.sh
. test/e2e/lib_sim.sh
stop_wine() {
    local rc=$?
    sim_cleanup TERM
    e2e_cleanup_tmp
    rm -f "$WINEPREFIX"/dosdevices/com[5-8]
    wineserver -k 2>/dev/null || true
    wineserver -w 2>/dev/null || true
    exit $rc
}
trap stop_wine EXIT

if [ ! -f "$WINEPREFIX/system.reg" ]; then
    echo "wine: creating the prefix $WINEPREFIX"
    wineboot -i >"$tmp/wineboot.log" 2>&1 || { cat "$tmp/wineboot.log"; exit 1; }
fi
# One server for the run, its chatter in a file (not in our output or pipes).
wineserver -p 30 </dev/null >>"$WIN/wineserver.log" 2>&1 || true # (or one is running already)

if $bench; then
    sim_start_linked bench --ids 1,2,3 --quiet --exit-after 600
    ln -sfn "$DEV" "$WINEPREFIX/dosdevices/com5"
    wine "$WIN/bench/bench_windows_port.exe" COM5 "${BENCH_N:-5000}"
    exit 0
fi

echo "== unit tests under wine"
# A failing unit test does not stop the end-to-end checks: one run shows everything.
unit_rc=0
TEST_WRAPPER=wine bash scripts/run-tests.sh "$@" || unit_rc=1

echo "== the Windows port against j288-sim through COM5..COM8"
sim_start_linked clean --ids 1,2,3 --quiet --exit-after 280
ln -sfn "$DEV" "$WINEPREFIX/dosdevices/com5"
sim_start_linked silent --ids 1 --drop 1 --quiet --exit-after 280
ln -sfn "$DEV" "$WINEPREFIX/dosdevices/com6"
sim_start_linked echo --ids 1 --echo --quiet --exit-after 280
ln -sfn "$DEV" "$WINEPREFIX/dosdevices/com7"
# Stopped below once the test talks to it (the test waits for that, bounded).
sim_start_linked vanish --ids 1 --quiet --exit-after 280
vanish_pid=$SIM_PID
ln -sfn "$DEV" "$WINEPREFIX/dosdevices/com8"
txlog_win=$(winepath -w "$tmp/tx.log")
timeout -k 5 240 wine "$WIN/test/test_windows_port.exe" COM5 COM6 COM7 COM8 "$txlog_win" &
test_pid=$!
while kill -0 "$test_pid" 2>/dev/null && [ ! -s "$tmp/vanish.log" ]; do sleep 0.05; done
stop_sim "$vanish_pid" || true
wait "$test_pid"

# Byte-exact: the simulator's log of received frames (TIME HEX ...) against what was sent.
# The byte-exact test is the first to talk to COM5 after the open tests (which send nothing).
n=$(wc -l <"$tmp/tx.log")
[ "$n" -gt 0 ] || { echo "FAIL: no frames logged by the test"; exit 1; }
awk -v n="$n" 'NR <= n {print $2}' "$tmp/clean.log" >"$tmp/rx.log"
tr -d '\r' <"$tmp/tx.log" >"$tmp/tx.unix"
if cmp -s "$tmp/tx.unix" "$tmp/rx.log"; then
    echo "PASS  byte-exact: the $n frames sent are the $n frames j288-sim received"
else
    echo "FAIL  byte-exact: frames differ:"; diff "$tmp/tx.unix" "$tmp/rx.log" | head -n 5
    exit 1
fi

echo "== j288.exe end to end (test/e2e/windows_cli.sh)"
bash test/e2e/windows_cli.sh "$WIN/j288.exe"
# The Python package on Windows loads j288.dll: it must export what the package binds.
python3 test/windows/dll_exports.py "$WIN/j288.dll" "${WIN_OBJDUMP:-x86_64-w64-mingw32-objdump}"

echo "== a CMake consumer cross-built with cmake/mingw-w64.cmake"
if bash scripts/need.sh cmake cmake; then
    cmake -S test/cmake_consumer -B "$WIN/cmake-consumer" -DJ288_SOURCE_DIR="$PWD" \
        -DCMAKE_TOOLCHAIN_FILE="$PWD/cmake/mingw-w64.cmake" >"$tmp/cmake.log" 2>&1 &&
        cmake --build "$WIN/cmake-consumer" -j 2 >>"$tmp/cmake.log" 2>&1 ||
        { cat "$tmp/cmake.log"; exit 1; }
    out=$(wine "$WIN/cmake-consumer/j288_consumer.exe" | tr -d '\r')
    echo "PASS  cmake consumer under wine: $out"
else
    [ $? -eq 1 ] || exit 1
fi
[ $unit_rc -eq 0 ] || { echo "FAIL  unit tests under wine (above)"; exit 1; }
