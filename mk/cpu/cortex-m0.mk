# Cortex-M0 (ARMv6-M, no FPU): soft-float ABI; the SI API, when built, is soft double.
# (A CPU fragment names the CPU in CPUS and gives, once, what every build for it uses:
# toolchain (TC_<name>_* in mk/target.mk, or in the fragment for a new one), a name for the
# benchmarks' headings (DESC), core flags,
# the configuration they go with, the QEMU machine and the memory map in test/target/ of
# the images run there.)
CPUS += m0
CPU_m0_TOOLCHAIN := arm
CPU_m0_DESC := Cortex-M0
CPU_m0_FLAGS := -mcpu=cortex-m0 -mthumb -mfloat-abi=soft
CPU_m0_DEFS :=
# QEMU has no MPS2 board with a Cortex-M0: mps2-an385's Cortex-M3 runs ARMv6-M code as is.
CPU_m0_QEMU := mps2-an385:cortex-m3
CPU_m0_LD := mem_mps2.ld
# Test images that fit the micro:bit's 16K RAM run on its real Cortex-M0 model instead.
CPU_m0_SMALL_QEMU := microbit:cortex-m0
CPU_m0_SMALL_LD := mem_microbit.ld
