# STM32 HAL port, its host test against the fake HAL, the firmware example, the unit tests on
# emulated Cortex-M (QEMU), and the Cortex-M size and speed reports. Owner: stm32.

STM32_PORT_DIR := port/stm32_hal
STM32_STUB_DIR := port/stm32_hal/stub
STM32_PORT_SRC := $(STM32_PORT_DIR)/j288_stm32.c

# ---- host test: the port against the fake HAL, with the real engine ---------------------
# Built with the D-cache maintenance on and a 32-byte receive buffer (a reply then crosses
# the half-transfer point), so that both paths are exercised.
STM32_TEST_DEFS := -DJ288_STM32_DCACHE=1 -DJ288_STM32_RX_BUF_SIZE=32u
STM32_TEST_CPPFLAGS := $(TEST_CPPFLAGS) -I$(STM32_PORT_DIR) -I$(STM32_STUB_DIR) -Itest/stm32 $(STM32_TEST_DEFS)
STM32_TEST_SRC := $(STM32_PORT_SRC) test/stm32/fake_hal.c test/stm32/test_stm32_port.c
STM32_TEST_OBJ := $(STM32_TEST_SRC:%.c=$(OBJ)/stm32host/%.o)
STM32_TEST_BIN := $(BUILD)/test/test_stm32_port
STM32_HDRS := $(wildcard $(STM32_PORT_DIR)/*.h $(STM32_STUB_DIR)/*.h test/stm32/*.h) $(LIB_HDR)

$(OBJ)/stm32host/%.o: %.c $(STM32_HDRS) $(UNITY)/unity.c
	@mkdir -p $(@D)
	$(CC) $(STM32_TEST_CPPFLAGS) $(CFLAGS_COMMON) -c $< -o $@

$(STM32_TEST_BIN): $(STM32_TEST_OBJ) $(UNITY_OBJ) $(LIB_A)
	@mkdir -p $(@D)
	$(CC) $(CFLAGS_COMMON) $^ -o $@ $(LDFLAGS_COMMON) -lm

HOST_TESTS += $(STM32_TEST_BIN)
ALL_TARGETS += $(STM32_TEST_BIN)

.PHONY: stm32-test
stm32-test: $(STM32_TEST_BIN)
	BUILD=$(BUILD) bash scripts/run-tests.sh $(STM32_TEST_BIN)

# ---- unit tests on the target instruction set (QEMU + semihosting) ----------------------
# Every test/unit/test_*.c plus the port test against the fake HAL, built for three cores.
# The micro:bit model (Cortex-M0) has 16K RAM; the images fit (checked by the linker script's
# stack/heap assertion).
ARM_CC ?= arm-none-eabi-gcc
ARM_SIZE ?= arm-none-eabi-size
TGT_CORES := m0 m4f m7
TGT_m0_FLAGS := -mcpu=cortex-m0 -mthumb -mfloat-abi=soft
TGT_m0_QEMU := microbit:cortex-m0
TGT_m0_MEM := mem_microbit.ld
TGT_m4f_FLAGS := -mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16 -DJ288_CONFIG_SI_FLOAT=1
TGT_m4f_QEMU := mps2-an386:cortex-m4
TGT_m4f_MEM := mem_mps2.ld
TGT_m7_FLAGS := -mcpu=cortex-m7 -mthumb -mfloat-abi=hard -mfpu=fpv5-d16
TGT_m7_QEMU := mps2-an500:cortex-m7
TGT_m7_MEM := mem_mps2.ld

TGT_CPPFLAGS := $(CPPFLAGS_LIB) -I$(UNITY) -Itest/support -Itest/vectors -I$(STM32_PORT_DIR) \
    -I$(STM32_STUB_DIR) -Itest/stm32 -DUNITY_INCLUDE_DOUBLE -DUNITY_SUPPORT_64 $(STM32_TEST_DEFS)
TGT_CFLAGS := -std=c99 $(WARN) -O2 -g -ffunction-sections -fdata-sections
TGT_LDFLAGS := -nostartfiles --specs=nano.specs --specs=rdimon.specs -Wl,--gc-sections -Ltest/target
TGT_UNIT_NAMES := $(notdir $(basename $(UNIT_TEST_SRC)))
TGT_COMMON_SRC := $(LIB_SRC) $(TEST_SUPPORT_SRC) test/target/startup.c
TGT_HDRS := $(LIB_HDR) $(STM32_HDRS) $(wildcard test/support/*.h test/vectors/*.h)

# Link $(3) from objects $(2) for core $(1). A Cortex-M0 image whose RAM does not fit the
# micro:bit's 16K is linked for the MPS2 memory map instead and runs, same ARMv6-M code, on
# the mps2-an385 machine (a Cortex-M3 executes the ARMv6-M instruction set unchanged); a
# file <elf>.qemu next to the image then names that machine, and the runner says so.
TGT_LINK = rm -f $(3).qemu; \
    $(ARM_CC) $(TGT_$(1)_FLAGS) $(TGT_LDFLAGS) -T $(TGT_$(1)_MEM) $(2) -o $(3) -lm $(if $(filter m0,$(1)),2>/dev/null || \
    { echo "$(3): over the micro:bit's 16K RAM; linked for mps2-an385 (M3 machine, M0 code)"; \
      $(ARM_CC) $(TGT_$(1)_FLAGS) $(TGT_LDFLAGS) -T mem_mps2.ld $(2) -o $(3) -lm && \
      echo "mps2-an385:cortex-m3" > $(3).qemu; })

# $(1): core
define TGT_CORE_RULES
$(BUILD)/target/$(1)/obj/%.o: %.c $(TGT_HDRS) $(UNITY)/unity.c
	@mkdir -p $$(@D)
	$(ARM_CC) $(TGT_$(1)_FLAGS) $(TGT_CPPFLAGS) $(TGT_CFLAGS) -c $$< -o $$@

$(BUILD)/target/$(1)/obj/unity.o: $(UNITY)/unity.c
	@mkdir -p $$(@D)
	$(ARM_CC) $(TGT_$(1)_FLAGS) -std=c99 -O2 -g -ffunction-sections -I$(UNITY) -DUNITY_INCLUDE_DOUBLE -DUNITY_SUPPORT_64 -c $$< -o $$@

$(BUILD)/target/$(1)/test_%.elf: $(BUILD)/target/$(1)/obj/test/unit/test_%.o $(TGT_COMMON_SRC:%.c=$(BUILD)/target/$(1)/obj/%.o) $(BUILD)/target/$(1)/obj/unity.o test/target/sections.ld test/target/$(TGT_$(1)_MEM)
	$$(call TGT_LINK,$(1),$$(filter %.o,$$^),$$@)

$(BUILD)/target/$(1)/test_stm32_port.elf: $(addprefix $(BUILD)/target/$(1)/obj/,test/stm32/test_stm32_port.o test/stm32/fake_hal.o port/stm32_hal/j288_stm32.o) $(TGT_COMMON_SRC:%.c=$(BUILD)/target/$(1)/obj/%.o) $(BUILD)/target/$(1)/obj/unity.o test/target/sections.ld test/target/$(TGT_$(1)_MEM)
	$$(call TGT_LINK,$(1),$$(filter %.o,$$^),$$@)

TGT_$(1)_ELFS := $(TGT_UNIT_NAMES:%=$(BUILD)/target/$(1)/%.elf) $(BUILD)/target/$(1)/test_stm32_port.elf
TGT_ALL_ELFS += $$(TGT_$(1)_ELFS)
TGT_RUN_SPECS += $$(foreach e,$$(TGT_$(1)_ELFS),$(1):$(TGT_$(1)_QEMU):$$(e))
endef
TGT_ALL_ELFS :=
TGT_RUN_SPECS :=
$(foreach c,$(TGT_CORES),$(eval $(call TGT_CORE_RULES,$(c))))

.PHONY: test-target target-tests
target-tests: $(TGT_ALL_ELFS)

# Builds what it can (-k): an image that does not build is reported as a failure by the
# runner, and the others still run.
test-target: $(UNITY)/unity.c
	@rm -f $(TGT_ALL_ELFS)
	@$(MAKE) --no-print-directory -k BUILD=$(BUILD) target-tests >$(BUILD)/target-build.log 2>&1 || \
	    { echo "test-target: some images did not build (see $(BUILD)/target-build.log):"; \
	      grep -E 'error:|Error [0-9]' $(BUILD)/target-build.log | head -n 20 | sed 's/^/    /'; }
	@echo "test-target: $(words $(TGT_ALL_ELFS)) images: $(TGT_UNIT_NAMES) test_stm32_port on $(TGT_CORES)"
	@bash test/target/run-target.sh $(TGT_RUN_SPECS)

# ---- firmware example (links against the stub; `make arm` builds it) --------------------
STM32_EX_DIR := examples/stm32_hal
STM32_EX_ELF := $(BUILD)/stm32/stm32_hal_example.elf
STM32_EX_FLAGS := -mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16 \
    -DJ288_CONFIG_SI_FLOAT=1 -DJ288_CONFIG_CRC_BACKEND=J288_CRC_BACKEND_NIBBLE
STM32_EX_CFLAGS := -std=c99 $(WARN) -Os -g -ffunction-sections -fdata-sections
STM32_EX_CPPFLAGS := $(CPPFLAGS_LIB) -I$(STM32_PORT_DIR) -I$(STM32_STUB_DIR) -I$(STM32_EX_DIR)
STM32_EX_SRC := $(wildcard $(STM32_EX_DIR)/*.c) $(STM32_PORT_SRC) $(STM32_STUB_DIR)/stm32_hal_stub.c $(LIB_SRC)
STM32_EX_OBJ := $(STM32_EX_SRC:%.c=$(BUILD)/stm32/example/obj/%.o)

$(BUILD)/stm32/example/obj/%.o: %.c $(STM32_HDRS) $(wildcard $(STM32_EX_DIR)/*.h)
	@mkdir -p $(@D)
	$(ARM_CC) $(STM32_EX_FLAGS) $(STM32_EX_CPPFLAGS) $(STM32_EX_CFLAGS) -c $< -o $@

$(STM32_EX_ELF): $(STM32_EX_OBJ) $(STM32_EX_DIR)/stm32f407.ld
	$(ARM_CC) $(STM32_EX_FLAGS) -nostartfiles --specs=nano.specs --specs=nosys.specs \
	    -Wl,--gc-sections -Wl,-Map=$(@:.elf=.map) -T $(STM32_EX_DIR)/stm32f407.ld \
	    $(filter %.o,$^) -o $@ -lm
	$(ARM_SIZE) $@

.PHONY: stm32-example
stm32-example: $(STM32_EX_ELF)
arm: stm32-example

# ---- bench-target: instructions per transaction on Cortex-M4 (QEMU -icount) -------------
# $(1): optimisation level tag (O2 / Os)
TGT_BENCH_FLAGS := -mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16 -DJ288_CONFIG_SI_FLOAT=1
TGT_BENCH_SRC := $(LIB_SRC) $(STM32_PORT_SRC) $(STM32_STUB_DIR)/stm32_hal_stub.c test/target/bench.c test/target/startup.c
define TGT_BENCH_RULES
$(BUILD)/bench/$(1)/obj/%.o: %.c $(TGT_HDRS)
	@mkdir -p $$(@D)
	$(ARM_CC) $(TGT_BENCH_FLAGS) $(CPPFLAGS_LIB) -I$(STM32_PORT_DIR) -I$(STM32_STUB_DIR) -DJ288_STUB_OMIT_CRC \
	    -std=c99 $(WARN) -$(1) -g -ffunction-sections -fdata-sections -c $$< -o $$@

$(BUILD)/bench/bench_m4_$(1).elf: $(TGT_BENCH_SRC:%.c=$(BUILD)/bench/$(1)/obj/%.o) test/target/sections.ld test/target/mem_mps2.ld
	$(ARM_CC) $(TGT_BENCH_FLAGS) $(TGT_LDFLAGS) -T mem_mps2.ld $$(filter %.o,$$^) -o $$@ -lm
endef
$(eval $(call TGT_BENCH_RULES,O2))
$(eval $(call TGT_BENCH_RULES,Os))

.PHONY: bench-target
bench-target: $(BUILD)/bench/bench_m4_O2.elf $(BUILD)/bench/bench_m4_Os.elf
	@command -v qemu-system-arm >/dev/null || { echo "bench-target: qemu-system-arm not found; install the Debian package qemu-system-arm" >&2; exit 1; }
	@for o in O2 Os; do \
	    echo "Cortex-M4 (mps2-an386, QEMU -icount shift=0), -$$o:"; \
	    timeout 120 qemu-system-arm -M mps2-an386 -cpu cortex-m4 -icount shift=0 -nographic -monitor none \
	        -serial none -semihosting-config enable=on,target=native -kernel $(BUILD)/bench/bench_m4_$$o.elf || exit 1; \
	    echo; \
	done

# ---- make size: flash/RAM per module and stack per public call, M0 and M4F at -Os --------
SIZE_CORES := m0 m4f
SIZE_BACKENDS := table slice4 nibble hw
SIZE_table_DEFS := -DJ288_CONFIG_CRC_BACKEND=J288_CRC_BACKEND_TABLE -DJ288_STM32_HW_CRC=0
SIZE_slice4_DEFS := -DJ288_CONFIG_CRC_BACKEND=J288_CRC_BACKEND_SLICE4 -DJ288_STM32_HW_CRC=0
SIZE_nibble_DEFS := -DJ288_CONFIG_CRC_BACKEND=J288_CRC_BACKEND_NIBBLE -DJ288_STM32_HW_CRC=0
SIZE_hw_DEFS := -DJ288_CONFIG_CRC_BACKEND=J288_CRC_BACKEND_HW -DJ288_CONFIG_CRC_HW_FUNCTION=j288_stm32_crc32_default
# The smallest Cortex-M0 build: CRC unit, raw integers only (no SI API, no soft float).
SIZE_hw-nosi_DEFS := $(SIZE_hw_DEFS) -DJ288_CONFIG_SI=0
SIZE_SRC := $(LIB_SRC) $(STM32_PORT_SRC) $(STM32_STUB_DIR)/stm32_hal_stub.c test/target/size_probe.c

# $(1): core, $(2): backend
define SIZE_RULES
$(BUILD)/size/$(1)-$(2)/obj/%.o: %.c $(TGT_HDRS)
	@mkdir -p $$(@D)
	$(ARM_CC) $(TGT_$(1)_FLAGS) $(SIZE_$(2)_DEFS) $(CPPFLAGS_LIB) -I$(STM32_PORT_DIR) -I$(STM32_STUB_DIR) \
	    -std=c99 $(WARN) -Wcast-align=strict -Os -ffunction-sections -fdata-sections -fstack-usage -fcallgraph-info=su -c $$< -o $$@

$(BUILD)/size/$(1)-$(2)/probe.elf: $(SIZE_SRC:%.c=$(BUILD)/size/$(1)-$(2)/obj/%.o) test/target/sections.ld test/target/mem_mps2.ld
	$(ARM_CC) $(TGT_$(1)_FLAGS) -nostartfiles --specs=nano.specs --specs=nosys.specs -Wl,--gc-sections \
	    -Wl,-Map=$$(@D)/probe.map -Ltest/target -T mem_mps2.ld $$(filter %.o,$$^) -o $$@ -lm
SIZE_DIRS += $(BUILD)/size/$(1)-$(2)
SIZE_ELFS += $(BUILD)/size/$(1)-$(2)/probe.elf
endef
SIZE_DIRS :=
SIZE_ELFS :=
$(foreach c,$(SIZE_CORES),$(foreach b,$(SIZE_BACKENDS),$(eval $(call SIZE_RULES,$(c),$(b)))))
$(eval $(call SIZE_RULES,m0,hw-nosi))

.PHONY: size
size: $(SIZE_ELFS)
	@$(PYTHON) test/target/size_report.py $(SIZE_DIRS)
