# Cortex-M4F (ARMv7E-M, single-precision FPU fpv4-sp-d16): hard-float ABI, SI API in float
# so that it stays on the FPU.
CPUS += m4f
CPU_m4f_TOOLCHAIN := arm
CPU_m4f_DESC := Cortex-M4F
CPU_m4f_FLAGS := -mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16
CPU_m4f_DEFS := -DJ288_CONFIG_SI_FLOAT=1
CPU_m4f_QEMU := mps2-an386:cortex-m4
CPU_m4f_LD := mem_mps2.ld
