#!/usr/bin/env bash
# usage: scripts/run-target.sh CPU:QEMU:MACHINE:MODEL:ELF...
# `make test-target`: run each test image under its QEMU system emulator (e.g.
# m0:qemu-system-arm:microbit:cortex-m0:build/target/m0/test_bus.elf) with semihosting. QEMU
# may carry the emulator's own options joined by '+' (qemu-system-riscv32+-bios+none). Each
# image becomes a small script, CPU/TEST.sh, that scripts/run-tests.sh runs and reports (side
# by side, "N passed, N failed" at the end): an image passes when QEMU exits 0 after a Unity
# summary; one that did not build fails.
set -u
per_test_timeout=${TARGET_TIMEOUT:-120}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
names=()
for spec in "$@"; do
    IFS=: read -r core qemu machine cpu elf <<<"$spec"
    # An image too big for its board's RAM names the machine it was linked for instead.
    [ -f "$elf.qemu" ] && IFS=: read -r machine cpu <"$elf.qemu"
    name=$core/$(basename "$elf" .elf).sh
    mkdir -p "$dir/$core"
    cat >"$dir/$name" <<EOF
[ -f '$PWD/$elf' ] || { echo "$elf did not build"; exit 1; }
echo "machine $machine"
out=\$(timeout -k 5 $per_test_timeout ${qemu//+/ } -M $machine -cpu $cpu -nographic -monitor none \\
    -serial none -semihosting-config enable=on,target=native -kernel '$PWD/$elf' 2>&1)
rc=\$?
echo "\$out"
[ \$rc -ne 127 ] || echo "CPU fault (exit 127)"
grep -Eq '^[0-9]+ Tests [0-9]+ Failures [0-9]+ Ignored' <<<"\$out" || { echo "no Unity summary"; exit 1; }
exit \$rc
EOF
    names+=("$name")
done
cd "$dir" && bash "$OLDPWD/scripts/run-tests.sh" "${names[@]}"
