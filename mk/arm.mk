# `make arm`: cross-compile lib/ (every lib/src/*.c) with arm-none-eabi-gcc at -Os with the
# warning set and -Werror, for each core below, and print a size table (text/data/bss per
# object, per core) with arm-none-eabi-size. Objects and archives go to $(BUILD)/arm/<core>/.
#   m0      Cortex-M0, soft float, J288_CONFIG_SI=0: raw integers only, the configuration meant
#           for FPU-less parts (no soft-float library is pulled in by the SI API)
#   m0-si   Cortex-M0, soft float, SI API in double: proves it builds, shows what it costs
#   m4f     Cortex-M4F, hard float (fpv4-sp-d16), J288_CONFIG_SI_FLOAT=1; checked to call no
#           soft-float helper (__aeabi_d*, __aeabi_f*, 64-bit int <-> float): all SI maths
#           stays on the FPU and no floating-point library code is linked in
ARM_CC ?= arm-none-eabi-gcc
ARM_SIZE ?= arm-none-eabi-size
ARM_NM ?= arm-none-eabi-nm
ARM_AR ?= arm-none-eabi-ar

ARMLIB_CORES := m0 m0-si m4f
ARMLIB_m0_FLAGS := -mcpu=cortex-m0 -mthumb -mfloat-abi=soft -DJ288_CONFIG_SI=0
ARMLIB_m0-si_FLAGS := -mcpu=cortex-m0 -mthumb -mfloat-abi=soft -DJ288_CONFIG_SI=1
ARMLIB_m4f_FLAGS := -mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16 \
    -DJ288_CONFIG_SI=1 -DJ288_CONFIG_SI_FLOAT=1
ARMLIB_CFLAGS := -std=c99 $(WARN) -Os -ffunction-sections -fdata-sections $(ARM_EXTRA_CFLAGS)
ARMLIB_NAMES := $(notdir $(basename $(LIB_SRC)))
# libgcc's floating-point helpers: double ops, float ops, and 64-bit integer <-> float/double.
ARMLIB_SOFTFLOAT_RE := __aeabi_([df][a-z]|[df]2|u?[il]2[df])

define ARMLIB_CORE_RULES
$(BUILD)/arm/$(1)/%.o: lib/src/%.c $(LIB_HDR)
	@mkdir -p $$(@D)
	$(ARM_CC) $(ARMLIB_$(1)_FLAGS) $(CPPFLAGS_LIB) $(ARMLIB_CFLAGS) -c $$< -o $$@

$(BUILD)/arm/$(1)/libj288.a: $(ARMLIB_NAMES:%=$(BUILD)/arm/$(1)/%.o)
	rm -f $$@
	$(ARM_AR) rcs $$@ $$^
endef
$(foreach c,$(ARMLIB_CORES),$(eval $(call ARMLIB_CORE_RULES,$(c))))

ARMLIB_ARCHIVES := $(ARMLIB_CORES:%=$(BUILD)/arm/%/libj288.a)

.PHONY: arm arm-lib arm-check-tools
arm-check-tools:
	@command -v $(ARM_CC) >/dev/null 2>&1 || { \
	    if [ "$$CI" = true ]; then echo "arm: $(ARM_CC) not found (CI=true: failure); install gcc-arm-none-eabi" >&2; exit 1; fi; \
	    echo "arm: skipping, $(ARM_CC) not found; install with: apt-get install -y --no-install-recommends gcc-arm-none-eabi libnewlib-arm-none-eabi" >&2; \
	    exit 0; }

arm-lib: arm-check-tools
	@if command -v $(ARM_CC) >/dev/null 2>&1; then $(MAKE) --no-print-directory BUILD=$(BUILD) arm-lib-build; fi

.PHONY: arm-lib-build
arm-lib-build: $(ARMLIB_ARCHIVES)
	@$(foreach c,$(ARMLIB_CORES),echo; echo "== lib/ for $(c): $(strip $(ARMLIB_$(c)_FLAGS)) -Os"; \
	    (cd $(BUILD)/arm/$(c) && $(ARM_SIZE) -t $(ARMLIB_NAMES:%=%.o)) | sed 's/(TOTALS)/TOTAL/';)
	@if $(ARM_NM) -u $(BUILD)/arm/m4f/*.o | grep -Eq '$(ARMLIB_SOFTFLOAT_RE)'; then \
	    echo "arm: m4f objects call soft-float helpers:" >&2; \
	    $(ARM_NM) -u -A $(BUILD)/arm/m4f/*.o | grep -E '$(ARMLIB_SOFTFLOAT_RE)' >&2; exit 1; fi
	@echo; echo "arm: m4f calls no soft-float helper; archives: $(ARMLIB_ARCHIVES)"

arm: arm-lib
