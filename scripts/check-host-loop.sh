#!/usr/bin/env bash
# One host stack (issue 18): the front ends (the j288 tool, the Python package, j288-dds) drive servos
# only through the host layer (host/j288_robot.h), which has the one bus loop; the desktop
# serial port keeps none (issue 28); and the host layer reads no private field of the port (it
# has accessors). Fails naming each offending line. Tests are exempt (they exercise the lower
# layers on purpose).
set -u
cd "$(dirname "$0")/.."
status=0
loops='j288_sched_start_sweep|j288_sched_poll|j288_bus_transfer_blocking|j288_bus_poll|j288_bus_submit'
if grep -nE "\\b($loops)\\b" tools/j288/*.c tools/j288/*.h tools/j288-dds/*.c tools/j288-dds/*.h python/j288/*.py; then
    echo "check-host-loop: a front end runs a bus loop of its own (use host/j288_robot.h)" >&2
    status=1
fi
if grep -nE "\\b($loops|j288_sched_[a-z_]+)\\b" port/desktop/*.c port/linux/*.c port/windows/*.c; then
    echo "check-host-loop: the desktop serial port runs a bus loop (the host layer has the one)" >&2
    status=1
fi
if grep -nE '\bserial(\.|->)[a-z_]+' host/*.c; then
    echo "check-host-loop: the host layer reads the port's private fields (use its accessors)" >&2
    status=1
fi
[ $status -eq 0 ] && echo "check-host-loop: ok"
exit $status
