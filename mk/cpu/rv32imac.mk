# RV32IMAC (32-bit RISC-V: integer multiply/divide, atomics, compressed; no FPU), the class of
# ESP32-C3, CH32V and GD32VF103: soft-float ABI ilp32, the SI API in soft double.
# -misa-spec=2.2 keeps the CSR instructions (the benchmarks read minstret) in the base ISA.
CPUS += rv32
CPU_rv32_TOOLCHAIN := riscv
CPU_rv32_DESC := RV32IMAC
CPU_rv32_FLAGS := -march=rv32imac -misa-spec=2.2 -mabi=ilp32 --specs=picolibc.specs
CPU_rv32_DEFS :=
# QEMU's generic virt board, its RV32 core; RAM from 0x80000000 (test/target/mem_virt_rv32.ld).
CPU_rv32_QEMU := virt:rv32
CPU_rv32_LD := mem_virt_rv32.ld

# ---- the riscv toolchain: Debian's riscv64-unknown-elf GCC (multilib, rv32 included) with
# picolibc, whose semihosting crt0 and stdio stand in for the Cortex-M startup and newlib's
# rdimon (picolibc.specs is in the core flags: it gives the compiler its headers too). QEMU starts the image itself (-bios none: no firmware).
TC_riscv_CC := riscv64-unknown-elf-gcc
TC_riscv_AR := riscv64-unknown-elf-ar
TC_riscv_NM := riscv64-unknown-elf-nm
TC_riscv_SIZE := riscv64-unknown-elf-size
TC_riscv_PACKAGES := gcc-riscv64-unknown-elf picolibc-riscv64-unknown-elf
TC_riscv_QEMU := qemu-system-riscv32
TC_riscv_QEMU_PACKAGES := qemu-system-misc
TC_riscv_QEMU_FLAGS := -bios none
TC_riscv_STARTUP :=
TC_riscv_SEMIHOST_LDFLAGS := --oslib=semihost --crt0=semihost
TC_riscv_BARE_LDFLAGS := --crt0=minimal
