# Builds for the CPUs of mk/cpu/*.mk:
#   make arm           lib/ per Cortex-M configuration with a size table, the STM32 firmware
#                      example, the port template for Cortex-M0
#   make test-target   every unit test and the STM32 port test on every CPU, under QEMU
#   make size          flash, RAM and stack per module on Cortex-M0 and M4F (test/target/)
# The benchmarks on these CPUs are in mk/bench.mk.

# ---- toolchains (a CPU fragment names one in CPU_<cpu>_TOOLCHAIN) ----------------------------
TC_arm_CC := arm-none-eabi-gcc
TC_arm_AR := arm-none-eabi-ar
TC_arm_NM := arm-none-eabi-nm
TC_arm_SIZE := arm-none-eabi-size
TC_arm_PACKAGES := gcc-arm-none-eabi libnewlib-arm-none-eabi
TC_arm_QEMU := qemu-system-arm
TC_arm_QEMU_PACKAGES := qemu-system-arm
# Options of the toolchain's QEMU before the machine's own (none here; RISC-V: -bios none).
TC_arm_QEMU_FLAGS :=
# The vector table and reset code of the images run under QEMU (tests, benchmarks).
TC_arm_STARTUP := test/target/startup.c
# Images that print through semihosting (tests, benchmarks), and images with no I/O.
TC_arm_SEMIHOST_LDFLAGS := -nostartfiles --specs=nano.specs --specs=rdimon.specs
TC_arm_BARE_LDFLAGS := -nostartfiles --specs=nano.specs --specs=nosys.specs

# $(call TC,cpu,X): TC_<the CPU's toolchain>_X.
TC = $(TC_$(CPU_$(1)_TOOLCHAIN)_$(2))
# The compiler for a CPU with its core flags and configuration, and the flags of every
# target build.
CPU_CC = $(call TC,$(1),CC) $(CPU_$(1)_FLAGS) $(CPU_$(1)_DEFS)
TGT_CFLAGS := $(CSTD) $(WARN) $(DEPFLAGS) -ffunction-sections -fdata-sections
# $(call TGT_LINK_FLAGS,cpu,SEMIHOST|BARE,memory map in test/target/)
TGT_LINK_FLAGS = $(CPU_$(1)_FLAGS) $(call TC,$(1),$(2)_LDFLAGS) -Wl,--gc-sections -Ltest/target -T $(3)
# $(call QEMU_CMD,cpu,machine:model): the CPU's QEMU with semihosting on.
QEMU_CMD = $(call TC,$(1),QEMU) -M $(word 1,$(subst :, ,$(2))) -cpu $(word 2,$(subst :, ,$(2))) \
    $(call TC,$(1),QEMU_FLAGS) -nographic -monitor none -serial none -semihosting-config enable=on,target=native
# $(call REQUIRE_TC,cpus,[QEMU]): REQUIRE the compilers (and QEMUs) of these CPUs' toolchains.
REQUIRE_TC = $(foreach t,$(sort $(foreach c,$(1),$(CPU_$(c)_TOOLCHAIN))),\
    $(call REQUIRE,$(TC_$(t)_CC),$(TC_$(t)_PACKAGES)); \
    $(if $(2),$(call REQUIRE,$(TC_$(t)_QEMU),$(TC_$(t)_QEMU_PACKAGES));)) true

# $(call TGT_OBJ_RULE,dir,cpu,flags): objects $(BUILD)/dir/obj/X.o from X.c for cpu, with flags
# on top of the CPU's and TGT_CFLAGS.
define TGT_OBJ_RULE
$(BUILD)/$(1)/obj/%.o: %.c
	@mkdir -p $$(@D)
	$(call CPU_CC,$(2)) $(TGT_CFLAGS) $(3) -c $$< -o $$@
endef

# ---- make arm ---------------------------------------------------------------------------------
# lib/ at -Os, one archive per build <name>: <cpu> [configuration]:
#   m0      J288_CONFIG_SI=0: raw integers only, for FPU-less parts (no soft-float library)
#   m0-si   the SI API in soft double: it builds, and the size table shows what it costs
#   m4f     SI in float; checked to call no soft-float helper (__aeabi_d*, __aeabi_f*, 64-bit
#           integer <-> float): all SI maths stays on the FPU
ARMLIB_BUILDS := m0 m0-si m4f
ARMLIB_m0 := m0 -DJ288_CONFIG_SI=0
ARMLIB_m0-si := m0 -DJ288_CONFIG_SI=1
ARMLIB_m4f := m4f
ARMLIB_NAMES := $(notdir $(basename $(LIB_SRC)))
ARMLIB_ARCHIVES := $(ARMLIB_BUILDS:%=$(BUILD)/arm/%/libj288.a)
ARMLIB_SOFTFLOAT_RE := __aeabi_([df][a-z]|[df]2|u?[il]2[df])
# The port template, standalone, for the smallest core.
ARM_TEMPLATE_OBJ := $(BUILD)/arm/m0/obj/port/template/j288_port_template.o

define ARMLIB_RULES
$(eval $(call TGT_OBJ_RULE,arm/$(1),$(firstword $(ARMLIB_$(1))),-Os $(CPPFLAGS_LIB) $(wordlist 2,9,$(ARMLIB_$(1)))))
$(BUILD)/arm/$(1)/libj288.a: $(LIB_SRC:%.c=$(BUILD)/arm/$(1)/obj/%.o)
	rm -f $$@
	$(call TC,$(firstword $(ARMLIB_$(1))),AR) rcs $$@ $$^
endef
$(foreach b,$(ARMLIB_BUILDS),$(eval $(call ARMLIB_RULES,$(b))))

.PHONY: arm arm-build port-template stm32-example
arm:
	@$(call REQUIRE_TC,m0 m4f); $(MAKE) --no-print-directory arm-build

arm-build: $(ARMLIB_ARCHIVES) $(ARM_TEMPLATE_OBJ) stm32-example
	@$(foreach b,$(ARMLIB_BUILDS),echo; echo "== lib/ for $(b): $(strip $(CPU_$(firstword $(ARMLIB_$(b)))_FLAGS) \
	    $(CPU_$(firstword $(ARMLIB_$(b)))_DEFS) $(wordlist 2,9,$(ARMLIB_$(b)))) -Os"; \
	    (cd $(BUILD)/arm/$(b)/obj/lib/src && $(call TC,$(firstword $(ARMLIB_$(b))),SIZE) -t $(ARMLIB_NAMES:%=%.o)) | sed 's/(TOTALS)/TOTAL/';)
	@if $(call TC,m4f,NM) -u $(BUILD)/arm/m4f/obj/lib/src/*.o | grep -Eq '$(ARMLIB_SOFTFLOAT_RE)'; then \
	    echo "arm: m4f objects call soft-float helpers:" >&2; \
	    $(call TC,m4f,NM) -u -A $(BUILD)/arm/m4f/obj/lib/src/*.o | grep -E '$(ARMLIB_SOFTFLOAT_RE)' >&2; exit 1; fi
	@echo; echo "arm: m4f calls no soft-float helper; archives: $(ARMLIB_ARCHIVES)"

# The port template must keep compiling: for Cortex-M0 here, on the host in its unit test
# (test/unit/test_port_template.c includes it and drives a bus through its interrupt glue).
port-template:
	@$(call REQUIRE_TC,m0); $(MAKE) --no-print-directory $(ARM_TEMPLATE_OBJ)

# ---- the STM32 firmware example (Cortex-M4F), linked against the HAL stub ---------------------
STM32_EX_ELF := $(BUILD)/stm32-example/stm32_hal_example.elf
STM32_EX_SRC := $(wildcard examples/stm32_hal/*.c) port/stm32_hal/j288_stm32.c \
                test/stm32/stub/stm32_hal_stub.c $(LIB_SRC)
$(eval $(call TGT_OBJ_RULE,stm32-example,m4f,-Os -g $(CPPFLAGS_LIB) -Iport/stm32_hal \
    -Itest/stm32/stub -Iexamples/stm32_hal -DJ288_CONFIG_CRC_BACKEND=J288_CRC_BACKEND_NIBBLE))

$(STM32_EX_ELF): $(STM32_EX_SRC:%.c=$(BUILD)/stm32-example/obj/%.o) examples/stm32_hal/stm32f407.ld \
    $(wildcard examples/stm32_hal/*.h)
	$(call TC,m4f,CC) $(CPU_m4f_FLAGS) $(TC_arm_BARE_LDFLAGS) -Wl,--gc-sections -Wl,-Map=$(@:.elf=.map) \
	    -T examples/stm32_hal/stm32f407.ld $(filter %.o,$^) -o $@ -lm
	$(call TC,m4f,SIZE) $@

stm32-example: $(STM32_EX_ELF)

# ---- make test-target: the unit tests on each CPU under QEMU (semihosting) --------------------
# Every test/unit/test_*.c, and the STM32 port against the fake HAL, built for every CPU.
TGT_CPPFLAGS := $(TEST_CPPFLAGS) -Iport/stm32_hal -Itest/stm32/stub -Itest/stm32 $(STM32_TEST_DEFS)
TGT_UNIT_NAMES := $(notdir $(basename $(UNIT_TEST_SRC)))
TGT_COMMON_SRC := $(LIB_SRC) $(TEST_SUPPORT_SRC)
TGT_STM32_SRC := test/stm32/test_stm32_port.c test/stm32/fake_hal.c port/stm32_hal/j288_stm32.c

# Link $(3) from objects $(2) for CPU $(1). A CPU with a small board (CPU_<cpu>_SMALL_LD) is
# linked for it first; an image over that board's RAM is linked for the CPU's standard
# machine instead, and <elf>.qemu then names that machine for the runner.
TGT_LINK = rm -f $(3).qemu; $(call TC,$(1),CC) $(call TGT_LINK_FLAGS,$(1),SEMIHOST,$(or \
    $(CPU_$(1)_SMALL_LD),$(CPU_$(1)_LD))) $(2) -o $(3) -lm $(if $(CPU_$(1)_SMALL_LD),2>/dev/null || \
    { echo "$(3): over the RAM of $(CPU_$(1)_SMALL_QEMU); linked for $(CPU_$(1)_QEMU)"; \
      $(call TC,$(1),CC) $(call TGT_LINK_FLAGS,$(1),SEMIHOST,$(CPU_$(1)_LD)) $(2) -o $(3) -lm && \
      echo "$(CPU_$(1)_QEMU)" > $(3).qemu; })

define TGT_CPU_RULES
$(eval $(call TGT_OBJ_RULE,target/$(1),$(1),-O2 -g $(TGT_CPPFLAGS)))
$(BUILD)/target/$(1)/obj/unity.o: $(UNITY)/unity.c
	@mkdir -p $$(@D)
	$(call CPU_CC,$(1)) -std=c99 -O2 -g $(DEPFLAGS) -ffunction-sections -I$(UNITY) $(UNITY_DEFS) -c $$< -o $$@

TGT_$(1)_LIBOBJ := $(patsubst %.c,$(BUILD)/target/$(1)/obj/%.o,$(TGT_COMMON_SRC) $(call TC,$(1),STARTUP)) \
    $(BUILD)/target/$(1)/obj/unity.o
$(BUILD)/target/$(1)/test_%.elf: $(BUILD)/target/$(1)/obj/test/unit/test_%.o $$(TGT_$(1)_LIBOBJ) \
    test/target/sections.ld $(addprefix test/target/,$(CPU_$(1)_LD) $(CPU_$(1)_SMALL_LD))
	$$(call TGT_LINK,$(1),$$(filter %.o,$$^),$$@)

$(BUILD)/target/$(1)/test_stm32_port.elf: $(TGT_STM32_SRC:%.c=$(BUILD)/target/$(1)/obj/%.o) \
    $$(TGT_$(1)_LIBOBJ) test/target/sections.ld $(addprefix test/target/,$(CPU_$(1)_LD) $(CPU_$(1)_SMALL_LD))
	$$(call TGT_LINK,$(1),$$(filter %.o,$$^),$$@)

TGT_$(1)_ELFS := $(TGT_UNIT_NAMES:%=$(BUILD)/target/$(1)/%.elf) $(BUILD)/target/$(1)/test_stm32_port.elf
TGT_ALL_ELFS += $$(TGT_$(1)_ELFS)
TGT_RUN_SPECS += $$(foreach e,$$(TGT_$(1)_ELFS),$(1):$(call TGT_QEMU_WORD,$(1)):$(or $(CPU_$(1)_SMALL_QEMU),$(CPU_$(1)_QEMU)):$$(e))
endef
# The CPU's QEMU and its options as one word for scripts/run-target.sh ('+' for spaces).
TGT_EMPTY :=
TGT_QEMU_WORD = $(subst $(TGT_EMPTY) $(TGT_EMPTY),+,$(strip $(call TC,$(1),QEMU) $(call TC,$(1),QEMU_FLAGS)))
TGT_ALL_ELFS :=
TGT_RUN_SPECS :=
$(foreach c,$(CPUS),$(eval $(call TGT_CPU_RULES,$(c))))

.PHONY: test-target target-tests
target-tests: $(TGT_ALL_ELFS)

# Builds what it can (-k): an image that does not build is reported as a failure by the
# runner, and the others still run. The CPUs of the ARM toolchain are required; a CPU of
# another toolchain (RISC-V) whose compiler or QEMU is missing is skipped with a notice
# outside CI (an error in CI, as every missing tool).
# $(call TGT_IF_TC,cpu,shell words): run the words when the CPU's compiler and QEMU are there.
TGT_IF_TC = if $(NEED) $(call TC,$(1),CC) $(call TC,$(1),PACKAGES) && \
    $(NEED) $(call TC,$(1),QEMU) $(call TC,$(1),QEMU_PACKAGES); then $(2); \
    elif [ $$? -ne 1 ]; then exit 1; fi;
TGT_REQUIRED_CPUS := $(foreach c,$(CPUS),$(if $(filter arm,$(CPU_$(c)_TOOLCHAIN)),$(c)))
test-target: $(UNITY)/unity.c
	@$(call REQUIRE_TC,$(TGT_REQUIRED_CPUS),QEMU); \
	 cpus=""; elfs=""; specs=""; \
	 $(foreach c,$(CPUS),$(call TGT_IF_TC,$(c),cpus="$$cpus $(c)"; elfs="$$elfs $(TGT_$(c)_ELFS)"; \
	    specs="$$specs $(filter $(c):%,$(TGT_RUN_SPECS))")) \
	 rm -f $$elfs; \
	 $(MAKE) --no-print-directory -k $$elfs >$(BUILD)/target-build.log 2>&1 || \
	    { echo "test-target: some images did not build (see $(BUILD)/target-build.log):"; \
	      grep -E 'error:|Error [0-9]' $(BUILD)/target-build.log | head -n 20 | sed 's/^/    /'; }; \
	 echo "test-target: $$(echo $$elfs | wc -w) images: $(TGT_UNIT_NAMES) test_stm32_port on$$cpus"; \
	 bash scripts/run-target.sh $$specs

# ---- make size: flash/RAM per module and stack per public call, M0 and M4F at -Os -------------
SIZE_CPUS := m0 m4f
SIZE_BACKENDS := table slice4 nibble hw
SIZE_table_DEFS := -DJ288_CONFIG_CRC_BACKEND=J288_CRC_BACKEND_TABLE -DJ288_STM32_HW_CRC=0
SIZE_slice4_DEFS := -DJ288_CONFIG_CRC_BACKEND=J288_CRC_BACKEND_SLICE4 -DJ288_STM32_HW_CRC=0
SIZE_nibble_DEFS := -DJ288_CONFIG_CRC_BACKEND=J288_CRC_BACKEND_NIBBLE -DJ288_STM32_HW_CRC=0
SIZE_hw_DEFS := -DJ288_CONFIG_CRC_BACKEND=J288_CRC_BACKEND_HW \
                -DJ288_CONFIG_CRC_HW_FUNCTION=j288_stm32_crc32_default
# The smallest Cortex-M0 build: CRC unit, raw integers only (no SI API, no soft float).
SIZE_hw-nosi_DEFS := $(SIZE_hw_DEFS) -DJ288_CONFIG_SI=0
# The FPU-less robot: the same, with the joint core (integers) for 15 joints on the
# scheduler (j288/jointq.h); size_report.py fails if soft float shows up in its map.
SIZE_hw-jointq_DEFS := $(SIZE_hw-nosi_DEFS) -DSIZE_PROBE_JOINTQ=1
SIZE_SRC := $(LIB_SRC) port/stm32_hal/j288_stm32.c test/stm32/stub/stm32_hal_stub.c \
            test/target/size_probe.c

# $(1): CPU, $(2): backend
define SIZE_RULES
$(eval $(call TGT_OBJ_RULE,size/$(1)-$(2),$(1),$(SIZE_$(2)_DEFS) $(CPPFLAGS_LIB) -Iport/stm32_hal \
    -Itest/stm32/stub -Wcast-align=strict -Os -fstack-usage -fcallgraph-info=su))
$(BUILD)/size/$(1)-$(2)/probe.elf: $(SIZE_SRC:%.c=$(BUILD)/size/$(1)-$(2)/obj/%.o) test/target/sections.ld \
    test/target/$(CPU_$(1)_LD)
	$(call TC,$(1),CC) $(call TGT_LINK_FLAGS,$(1),BARE,$(CPU_$(1)_LD)) -Wl,-Map=$$(@D)/probe.map \
	    $$(filter %.o,$$^) -o $$@ -lm
SIZE_DIRS += $(BUILD)/size/$(1)-$(2)
endef
SIZE_DIRS :=
$(foreach c,$(SIZE_CPUS),$(foreach b,$(SIZE_BACKENDS),$(eval $(call SIZE_RULES,$(c),$(b)))))
$(eval $(call SIZE_RULES,m0,hw-nosi))
$(eval $(call SIZE_RULES,m0,hw-jointq))

.PHONY: size size-build
size:
	@$(call REQUIRE_TC,$(SIZE_CPUS)); $(MAKE) --no-print-directory size-build

size-build: $(SIZE_DIRS:%=%/probe.elf)
	@$(PYTHON) test/target/size_report.py $(SIZE_DIRS)
