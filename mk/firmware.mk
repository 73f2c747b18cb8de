# The STM32 port's build checks and the flashable firmware against ST's real HAL:
#   make firmware      examples/stm32_hal for its boards, against ST's sources fetched by
#                      scripts/fetch-st.sh into build/st/ (skipped with a notice without them)
# CI builds the port and the example against the HAL stub only (`make arm`, mk/target.mk).

# J288_STM32_DCACHE=1 on a core without a data cache stops with an #error that says why.
TEST_SCRIPTS += test/stm32/dcache_needs_a_cache.sh

# ---- make firmware: examples/stm32_hal per board, against ST's HAL in ST_DIR ---------------
# Per board <b> (examples/stm32_hal/<b>/ holds board.c, main.h, the HAL configuration and the
# linker script): FW_<b>_FAMILY (f4, g4: the fetch-st.sh family), FW_<b>_DEVICE (ST's device
# define; its lower case names ST's startup file), FW_<b>_HAL (the HAL modules compiled).
ST_DIR ?= build/st
FW_BOARDS := nucleo_f446re nucleo_g474re
FW_nucleo_f446re_FAMILY := f4
FW_nucleo_f446re_DEVICE := STM32F446xx
FW_nucleo_f446re_LD := stm32f446re.ld
FW_nucleo_f446re_HAL := hal hal_cortex hal_rcc hal_rcc_ex hal_gpio hal_dma hal_dma_ex hal_uart \
    hal_tim hal_tim_ex hal_crc hal_pwr hal_pwr_ex hal_flash hal_flash_ex
FW_nucleo_g474re_FAMILY := g4
FW_nucleo_g474re_DEVICE := STM32G474xx
FW_nucleo_g474re_LD := stm32g474re.ld
FW_nucleo_g474re_HAL := hal hal_cortex hal_rcc hal_rcc_ex hal_gpio hal_dma hal_dma_ex hal_uart \
    hal_uart_ex hal_tim hal_tim_ex hal_crc hal_crc_ex hal_pwr hal_pwr_ex hal_flash hal_flash_ex
# Our code keeps every warning (ST's headers are system headers); ST's sources get none.
FW_APP_SRC := examples/stm32_hal/main.c examples/stm32_hal/board_common.c examples/stm32_hal/nucleo_common/board_nucleo.c \
    port/stm32_hal/j288_stm32.c $(LIB_SRC)
FW_ELFS := $(foreach b,$(FW_BOARDS),$(BUILD)/firmware/$(b)/j288_$(b).elf)

# $(call ST_CC,board,includes): the Cortex-M4F compiler against ST's HAL and CMSIS of the
# board's family, with the board's HAL configuration (examples/stm32_hal/<board>) and includes.
ST_CC = $(call CPU_CC,m4f) -D$(FW_$(1)_DEVICE) -DUSE_HAL_DRIVER -Iexamples/stm32_hal/$(1) $(2) -Iport/stm32_hal \
    $(CPPFLAGS_LIB) -isystem $(ST_DIR)/stm32$(FW_$(1)_FAMILY)xx_hal_driver/Inc \
    -isystem $(ST_DIR)/cmsis_device_$(FW_$(1)_FAMILY)/Include -isystem $(ST_DIR)/cmsis_core/Include \
    -g $(DEPFLAGS) -ffunction-sections -fdata-sections
# $(call ST_HAL_SRC,board): ST's sources of the board's HAL modules, and its system file.
ST_HAL_SRC = $(FW_$(1)_HAL:%=$(ST_DIR)/stm32$(FW_$(1)_FAMILY)xx_hal_driver/Src/stm32$(FW_$(1)_FAMILY)xx_%.c) \
    $(ST_DIR)/cmsis_device_$(FW_$(1)_FAMILY)/Source/Templates/system_stm32$(FW_$(1)_FAMILY)xx.c
# $(call ST_OBJ_RULES,dir,compiler): our X.c into dir/app/X.o with every warning, ST's sources
# into dir/st/ with none (ST's headers are system headers; its code is not ours to fix).
define ST_OBJ_RULES
$(1)/app/%.o: %.c
	@mkdir -p $$(@D)
	$(2) $(CSTD) $(WARN) -c $$< -o $$@
$(1)/st/%.o: $(ST_DIR)/%.c
	@mkdir -p $$(@D)
	$(2) -std=gnu11 -w -c $$< -o $$@
endef

# $(call FW_RULES,board)
define FW_RULES
FW_$(1)_OBJ := $(patsubst %.c,$(BUILD)/firmware/$(1)/app/%.o,$(FW_APP_SRC) examples/stm32_hal/$(1)/board.c) \
    $(patsubst $(ST_DIR)/%.c,$(BUILD)/firmware/$(1)/st/%.o,$(call ST_HAL_SRC,$(1))) $(BUILD)/firmware/$(1)/st/startup.o
$(call ST_OBJ_RULES,$(BUILD)/firmware/$(1),$(call ST_CC,$(1),-Iexamples/stm32_hal) -Os)
$(BUILD)/firmware/$(1)/st/startup.o: $(ST_DIR)/cmsis_device_$(FW_$(1)_FAMILY)/Source/Templates/gcc/startup_$(shell echo $(FW_$(1)_DEVICE) | tr A-Z a-z).s
	@mkdir -p $$(@D)
	$(call ST_CC,$(1),-Iexamples/stm32_hal) -Os -x assembler-with-cpp -c $$< -o $$@
$(BUILD)/firmware/$(1)/j288_$(1).elf: $$(FW_$(1)_OBJ) examples/stm32_hal/$(1)/$(FW_$(1)_LD)
	$(call TC,m4f,CC) $(CPU_m4f_FLAGS) --specs=nano.specs --specs=nosys.specs -Wl,--gc-sections \
	    -Wl,-Map=$$(@:.elf=.map) -T examples/stm32_hal/$(1)/$(FW_$(1)_LD) $$(FW_$(1)_OBJ) -o $$@ -lm
	arm-none-eabi-objcopy -O binary $$@ $$(@:.elf=.bin)
	@$(call TC,m4f,SIZE) $$@ | awk 'NR==2 { printf "$(1): flash %d bytes (text+data), RAM %d bytes (data+bss, stack reserve included)\n", $$$$1+$$$$2, $$$$2+$$$$3 }'
endef
$(foreach b,$(FW_BOARDS),$(eval $(call FW_RULES,$(b))))

.PHONY: firmware firmware-build
# Builds each board whose family's sources are in ST_DIR (scripts/fetch-st.sh f4 is enough for
# the reference board) and names the others; skips with a notice when none is (CI never
# fetches them).
FW_HAVE = [ -f $(ST_DIR)/cmsis_core/.tag ] && [ -f $(ST_DIR)/stm32$(1)xx_hal_driver/.tag ] && \
    [ -f $(ST_DIR)/cmsis_device_$(1)/.tag ]
firmware:
	@$(call REQUIRE_TC,m4f); \
	 elfs=; \
	 $(foreach b,$(FW_BOARDS),if $(call FW_HAVE,$(FW_$(b)_FAMILY)); then \
	     elfs="$$elfs $(BUILD)/firmware/$(b)/j288_$(b).elf"; \
	 else echo "firmware: $(b) skipped: ST's $(FW_$(b)_FAMILY) sources are not in $(ST_DIR)"; fi;) \
	 if [ -z "$$elfs" ]; then \
	     echo "firmware: skipped: ST's sources are not in $(ST_DIR)."; \
	     echo "          Fetch them with: bash scripts/fetch-st.sh   (ST_MIRROR=dir for a local mirror)"; \
	     exit 0; fi; \
	 $(MAKE) --no-print-directory firmware-build FW_BUILD="$$elfs"

# Then the port against ST's headers where the stub cannot stand in: J288_STM32_DCACHE=1
# stops with its #error on the F4 and builds on the H7 (when fetched); and the stub's constants
# against ST's, per family fetched (test/stm32/stub_matches_st.sh, also in `make test`).
FW_BUILD ?= $(FW_ELFS)
firmware-build: $(FW_BUILD)
	@if $(call FW_HAVE,f4); then \
	     ST_DIR=$(ST_DIR) ARM_CC=$(call TC,m4f,CC) CC="$(CC)" bash test/stm32/dcache_needs_a_cache.sh; fi
	@ST_DIR=$(ST_DIR) BUILD=$(BUILD) CC="$(CC)" bash test/stm32/stub_matches_st.sh

# ---- make bench-stm32-hal: what the port adds per transaction, on F4 and G4 -------------------
# test/stm32/hal_bench.c on Cortex-M4 under QEMU (-icount), built against ST's headers and HAL
# of each family fetched in ST_DIR, with its NUCLEO's HAL configuration; the F4 is required (a
# notice without it), the G4 runs when fetched.
HB_FAMILIES := f4 g4
HB_f4_BOARD := nucleo_f446re
HB_g4_BOARD := nucleo_g474re
HB_APP := test/stm32/hal_bench.c port/stm32_hal/j288_stm32.c $(LIB_SRC) $(call TC,m4f,STARTUP)

# $(call HB_RULES,opt,family)
define HB_RULES
$(call ST_OBJ_RULES,$(BUILD)/bench-stm32-hal/$(2)-$(1),$(call ST_CC,$(HB_$(2)_BOARD),-Itest/support) -$(1))
$(BUILD)/bench-stm32-hal/hal_bench_$(2)_$(1).elf: $(HB_APP:%.c=$(BUILD)/bench-stm32-hal/$(2)-$(1)/app/%.o) \
    $(patsubst $(ST_DIR)/%.c,$(BUILD)/bench-stm32-hal/$(2)-$(1)/st/%.o,$(call ST_HAL_SRC,$(HB_$(2)_BOARD)))
	$(call TC,m4f,CC) $(call TGT_LINK_FLAGS,m4f,SEMIHOST,$(CPU_m4f_LD)) $$^ -o $$@ -lm
endef
$(foreach f,$(HB_FAMILIES),$(foreach o,O2 Os,$(eval $(call HB_RULES,$(o),$(f)))))

.PHONY: bench-stm32-hal
bench-stm32-hal:
	@$(call REQUIRE_TC,m4f,QEMU); \
	 if ! $(call FW_HAVE,f4); then \
	     echo "bench-stm32-hal: skipped: ST's F4 sources are not in $(ST_DIR) (bash scripts/fetch-st.sh f4)"; \
	     exit 0; fi; \
	 fams=f4; if $(call FW_HAVE,g4); then fams="f4 g4"; \
	 else echo "bench-stm32-hal: G4 skipped: ST's G4 sources are not in $(ST_DIR)"; fi; \
	 for f in $$fams; do \
	    $(MAKE) --no-print-directory $(BUILD)/bench-stm32-hal/hal_bench_$${f}_O2.elf \
	        $(BUILD)/bench-stm32-hal/hal_bench_$${f}_Os.elf || exit 1; \
	    for o in O2 Os; do \
	       echo "$$f: Cortex-M4F ($(CPU_m4f_QEMU), QEMU -icount shift=0), -$$o:"; \
	       $(call QEMU_BENCH,m4f,$(BUILD)/bench-stm32-hal/hal_bench_$${f}_$$o.elf) || exit 1; echo; \
	    done; \
	 done
