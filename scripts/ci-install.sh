#!/usr/bin/env bash
# usage: scripts/ci-install.sh
# Install every Debian package CI needs (idempotent: only what is missing is installed).
# One list; each area adds its packages here with a comment saying which target needs them.
set -euo pipefail

packages=(
    # build and host tests (Makefile, make test, make test CC=clang-14, make demo)
    make gcc clang-14 coreutils
    gnuplot-nox                     # make demo / cli_bus.sh plot test (PNG); CI treats it as required
    cmake                           # scripts/check-consumers.sh
    libyaml-dev                     # robot config reader (host/j288_robot_config.c, test_robot_config)
    gcc-arm-none-eabi libnewlib-arm-none-eabi  # make arm, test-target, size, check-symbols
    qemu-system-arm                 # make test-target, bench-target, bench-bus-target (Cortex-M)
    # hardening (mk/hardening.mk)
    clang-14 libclang-rt-14-dev     # make fuzz / fuzz-ci (libFuzzer, ASan, UBSan)
    valgrind                        # make test-valgrind
    cppcheck clang-tidy             # make lint (cppcheck's MISRA addon ships with cppcheck)
    gcovr                           # make coverage
    gcc-s390x-linux-gnu libc6-dev-s390x-cross        # make test-be (big-endian)
    gcc-arm-linux-gnueabihf libc6-dev-armhf-cross    # make test-32 (gcc-multilib conflicts
                                                     # with the s390x cross gcc in Debian 12)
    qemu-user                       # make test-be / test-32 (qemu-s390x, qemu-arm)
    binutils                        # make check-symbols (nm)
    python3                         # make fuzz-corpus, golden vectors
    # RISC-V (mk/cpu/rv32imac.mk): test-target and bench-bus-target on RV32 under QEMU
    gcc-riscv64-unknown-elf picolibc-riscv64-unknown-elf qemu-system-misc
    python3-pytest python3-numpy    # scripts/python-test.sh (make test: the Python package)
    pkg-config                      # libyaml (mk/tools.mk); check-consumers.sh; mk/dds.mk
    stress-ng                       # make test-loop LOAD=N (scripts/test-loop.sh: the suite beside a CPU load)
    tmux                            # test/e2e/cli_top.sh: j288 top on a terminal (required
                                    # under CI=true, skipped with a notice elsewhere)
    cyclonedds-dev cyclonedds-tools # j288-dds (mk/dds.mk): libddsc, its pkg-config file, idlc
    libsystemd-dev                  # j288-dds's sd_notify (READY, WATCHDOG; mk/dds.mk, make deb)
    systemd                         # systemd-analyze: test/dds/service.sh, make deb-check
    libfastrtps-dev fastddsgen g++  # make test-dds-fastdds: the Fast DDS peer (test/dds/fastdds_peer.cpp)
    iproute2 util-linux             # the DDS tests' private network namespace (ip, unshare)
    # Windows (mk/windows.mk): make windows cross-builds with mingw-w64, make test-windows runs
    # the programs under Wine (64-bit only: no i386 packages, no X server; ~200 MB)
    gcc-mingw-w64-x86-64-win32 wine wine64
    help2man                        # the man pages of j288 and j288-sim (cmake/j288_tools.cmake)
    python3-venv python3-setuptools python3-wheel python3-build  # make pip-check (no network)
    debhelper dpkg-dev fakeroot lintian  # make deb, make deb-check (debian/)
)

missing=()
for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
    echo "ci-install: all ${#packages[@]} packages present"
    exit 0
fi
echo "ci-install: installing ${missing[*]}"
sudo=
[ "$(id -u)" -eq 0 ] || sudo=sudo
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
