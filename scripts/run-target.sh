#!/usr/bin/env bash
# usage: scripts/run-target.sh CPU:QEMU:MACHINE:MODEL:ELF...
# `make test-target`: run each test image under its QEMU system emulator (e.g.
# m0:qemu-system-arm:microbit:cortex-m0:build/target/m0/test_bus.elf) with semihosting. QEMU
# may carry the emulator's own options joined by '+' (qemu-system-riscv32+-bios+none). Prints
# each image's Unity summary and ends with "N passed, N failed"; the exit status says whether
# all passed.
set -u
per_test_timeout=${TARGET_TIMEOUT:-120}
passed=0 failed=0 failed_names=()
for spec in "$@"; do
    IFS=: read -r core qemu machine cpu elf <<<"$spec"
    IFS=+ read -r -a qemu_cmd <<<"$qemu"
    # An image too big for its board's RAM names the machine it was linked for instead.
    [ -f "$elf.qemu" ] && IFS=: read -r machine cpu <"$elf.qemu"
    name="$core/$(basename "$elf" .elf)"
    if [ ! -f "$elf" ]; then
        failed=$((failed + 1))
        failed_names+=("$name")
        echo "FAIL  $name  did not build"
        continue
    fi
    log=$(mktemp)
    timeout -k 5 "$per_test_timeout" "${qemu_cmd[@]}" -M "$machine" -cpu "$cpu" -nographic \
        -monitor none -serial none -semihosting-config enable=on,target=native \
        -kernel "$elf" >"$log" 2>&1
    rc=$?
    summary=$(grep -E '^[0-9]+ Tests [0-9]+ Failures [0-9]+ Ignored' "$log" | tail -n1)
    if [ $rc -eq 0 ] && [ -n "$summary" ]; then
        passed=$((passed + 1))
        echo "PASS  $name ($machine)  $summary"
    else
        failed=$((failed + 1))
        failed_names+=("$name")
        case $rc in
            124) why="timed out after ${per_test_timeout}s" ;;
            127) why="CPU fault (exit 127)" ;;
            *) why="exit $rc" ;;
        esac
        echo "FAIL  $name ($machine)  $why  ${summary}"
        grep -E ':FAIL' "$log" | head -n 20 | sed 's/^/      /'
        tail -n 5 "$log" | sed 's/^/    | /'
    fi
    rm -f "$log"
done
echo
[ $failed -gt 0 ] && echo "failed: ${failed_names[*]}"
echo "$passed passed, $failed failed"
[ $failed -eq 0 ]
