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
