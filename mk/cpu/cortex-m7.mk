# Cortex-M7 (ARMv7E-M, double-precision FPU fpv5-d16): hard-float ABI, SI API in double.
CPUS += m7
CPU_m7_TOOLCHAIN := arm
CPU_m7_DESC := Cortex-M7
CPU_m7_FLAGS := -mcpu=cortex-m7 -mthumb -mfloat-abi=hard -mfpu=fpv5-d16
CPU_m7_DEFS :=
CPU_m7_QEMU := mps2-an500:cortex-m7
CPU_m7_LD := mem_mps2.ld
