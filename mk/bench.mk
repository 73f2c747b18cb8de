# Benchmarks: figures for docs/performance.md, printed, never enforced.
#   make bench              bench-bus and bench-bus-target
#   make bench-bus          sweep time for 1, 4 and 15 servos against the wire time on the fake
#                           port's virtual clock (servo turnaround ENGINE_BENCH_TURNAROUND us);
#                           with valgrind, host instructions per transaction (callgrind)
#   make bench-codec        host instructions per call of the codec's hot paths (callgrind)
#   make bench-linux        round trip and sweep rate over the simulator's pty (wall clock)
#   make bench-target       instructions per codec transaction on Cortex-M4F and RV32 (QEMU
#                           -icount)
#   make bench-bus-target   instructions per engine transaction on Cortex-M0, M4F and RV32
#                           (QEMU)
#   make bench-rt           the robot loop's wake-up lateness against cyclictest's, side by
#                           side, idle and beside stress-ng, with and without --realtime; the
#                           bridge's command-to-wire latency the same way (scripts/bench-rt.sh:
#                           its variables; needs rt-tests, stress-ng and the machine to itself:
#                           not in CI)
.PHONY: bench bench-bus bench-codec bench-linux bench-target bench-bus-target bench-rt
bench: bench-bus bench-bus-target

# ---- host ------------------------------------------------------------------------------------
ENGINE_BENCH := $(BIN)/bus_timing
ENGINE_BENCH_TURNAROUND ?= 0 10 20 50
# -fno-inline keeps the benchmark's entry points visible to callgrind; lib/ stays as built.
$(ENGINE_BENCH): test/bench/bus_timing.c test/support/fake_port.c test/support/fake_port.h $(LIB_A)
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS_LIB) -Itest/support $(CSTD) $(WARN) -O2 -g -fno-inline $(EXTRA_CFLAGS) \
	    test/bench/bus_timing.c test/support/fake_port.c $(LIB_A) -o $@ $(LDFLAGS_COMMON)

bench-bus: $(ENGINE_BENCH)
	BIN=$(BIN) BUILD=$(BUILD) ENGINE_BENCH_TURNAROUND="$(ENGINE_BENCH_TURNAROUND)" \
	    bash test/bench/bus_bench.sh

CODEC_BENCH := $(BUILD)/bench/codec_bench
CODEC_BENCH_N ?= 20000
$(OBJ)/test/bench/%.o: CPPFLAGS_OBJ = $(CPPFLAGS_LIB)
$(CODEC_BENCH): $(OBJ)/test/bench/codec_bench.o $(LIB_A)
	$(LINK)

bench-codec: $(CODEC_BENCH)
	@$(call REQUIRE,valgrind,valgrind); \
	 bash scripts/bench-codec.sh $(CODEC_BENCH) $(CODEC_BENCH_N) "$(CC), $(OPT)"

LINUX_BENCH := $(BUILD)/bench/bench_linux_port
$(LINUX_BENCH): $(OBJ)/test/linux/bench_linux_port.o $(SERIAL_LOOP_OBJ) $(LINUX_A) $(LIB_A)
	$(LINK)

bench-linux: $(LINUX_BENCH) $(SIM_BIN)
	$(LINUX_BENCH) $(SIM_BIN) 5000

ALL_TARGETS += $(ENGINE_BENCH) $(LINUX_BENCH)

# (the bridge's part when Cyclone DDS is there: mk/dds.mk, read after this file)
bench-rt: $(J288_BIN) $(SIM_BIN)
	@$(MAKE) --no-print-directory $(if $(filter yes,$(DDS_FOUND)),$(DDS_BIN) $(DDS_TEST_PEER) \
	    $(BUILD)/bench/write_stamp.so,$(J288_BIN)) >/dev/null
	BUILD=$(BUILD) bash scripts/bench-rt.sh

# ---- Cortex-M under QEMU -icount shift=0 (one instruction per ns) ----------------------------
# $(call QEMU_BENCH,cpu,elf): run elf on the CPU's standard machine, instruction-counted.
QEMU_BENCH = timeout 120 $(call QEMU_CMD,$(1),$(CPU_$(1)_QEMU)) -icount shift=0 -kernel $(2)
BENCH_OPTS := O2 Os

# $(call BENCH_IMAGE,name,cpu,sources,flags,opt): $(BUILD)/bench-target/name_opt.elf for cpu.
define BENCH_IMAGE
$(eval $(call TGT_OBJ_RULE,bench-target/$(1)_$(5),$(2),-$(5) -g $(CPPFLAGS_LIB) $(4)))
$(BUILD)/bench-target/$(1)_$(5).elf: $(3:%.c=$(BUILD)/bench-target/$(1)_$(5)/obj/%.o) \
    test/target/sections.ld test/target/$(CPU_$(2)_LD)
	$(call TC,$(2),CC) $(call TGT_LINK_FLAGS,$(2),SEMIHOST,$(CPU_$(2)_LD)) $$(filter %.o,$$^) -o $$@ -lm
endef

# The codec per CRC backend on Cortex-M4F and RV32, the STM32 port's CRC unit path included (its
# HAL stubbed: the CPU's share).
BENCH_CODEC_CPUS := m4f rv32
BENCH_CODEC_SRC = $(LIB_SRC) port/stm32_hal/j288_stm32.c test/stm32/stub/stm32_hal_stub.c \
    test/target/bench.c $(call TC,$(1),STARTUP)
$(foreach c,$(BENCH_CODEC_CPUS),$(foreach o,$(BENCH_OPTS),$(eval $(call BENCH_IMAGE,codec_$(c),$(c),\
    $(call BENCH_CODEC_SRC,$(c)),-Iport/stm32_hal -Itest/stm32/stub -DJ288_STUB_OMIT_CRC,$(o)))))

# The ARM CPUs are required; another toolchain's CPU is skipped with a notice when its tools
# are missing outside CI (TGT_IF_TC, mk/target.mk).
BENCH_COMMA := ,
BENCH_REQUIRE = $(call REQUIRE_TC,$(foreach c,$(1),$(if $(filter arm,$(CPU_$(c)_TOOLCHAIN)),$(c))),QEMU)

bench-target:
	@$(call BENCH_REQUIRE,$(BENCH_CODEC_CPUS)); \
	 $(foreach c,$(BENCH_CODEC_CPUS),$(call TGT_IF_TC,$(c),\
	    $(MAKE) --no-print-directory $(BENCH_OPTS:%=$(BUILD)/bench-target/codec_$(c)_%.elf) >/dev/null && \
	    for o in $(BENCH_OPTS); do \
	        echo "$(CPU_$(c)_DESC) ($(CPU_$(c)_QEMU)$(BENCH_COMMA) QEMU -icount shift=0)$(BENCH_COMMA) -$$o:"; \
	        $(call QEMU_BENCH,$(c),$(BUILD)/bench-target/codec_$(c)_$$o.elf) || exit 1; echo; \
	    done))

# The bus engine and the scheduler, port operations empty, with the default CRC backend (table),
# with slicing-by-4 (s4) and with a CRC unit as the compile-time backend (hw; hwi inlined).
BENCH_BUS_CPUS := m0 m4f rv32
BENCH_BUS_CRCS := table s4 hw hwi
BENCH_BUS_CRC_table :=
BENCH_BUS_CRC_s4 := -DJ288_CONFIG_CRC_BACKEND=J288_CRC_BACKEND_SLICE4
# hw: the CRC unit model of test/bench/bus_target.c as the compile-time backend
BENCH_BUS_CRC_hw := -DJ288_CONFIG_CRC_BACKEND=J288_CRC_BACKEND_HW \
    -DJ288_CONFIG_CRC_HW_FUNCTION=bench_crc_unit
# hwi: the same, its function static inline in a user configuration (test/bench/hw_inline)
BENCH_BUS_CRC_hwi := -DJ288_USER_CONFIG -Itest/bench/hw_inline
$(foreach c,$(BENCH_BUS_CPUS),$(foreach v,$(BENCH_BUS_CRCS),$(foreach o,$(BENCH_OPTS),$(eval \
    $(call BENCH_IMAGE,bus_$(c)_$(v),$(c),test/bench/bus_target.c $(call TC,$(c),STARTUP) $(LIB_SRC),\
    $(BENCH_BUS_CRC_$(v)),$(o))))))

bench-bus-target:
	@$(call BENCH_REQUIRE,$(BENCH_BUS_CPUS)); \
	 $(foreach c,$(BENCH_BUS_CPUS),$(call TGT_IF_TC,$(c),\
	    $(MAKE) --no-print-directory $(foreach v,$(BENCH_BUS_CRCS),$(BENCH_OPTS:%=$(BUILD)/bench-target/bus_$(c)_$(v)_%.elf)) >/dev/null && \
	    for o in $(BENCH_OPTS); do for v in $(BENCH_BUS_CRCS); do \
	        echo "$(CPU_$(c)_DESC) -$$o$(BENCH_COMMA) CRC $$v ($(CPU_$(c)_QEMU)$(BENCH_COMMA) QEMU -icount shift=0)$(BENCH_COMMA) instructions per transaction:"; \
	        $(call QEMU_BENCH,$(c),$(BUILD)/bench-target/bus_$(c)_$${v}_$$o.elf) || exit 1; \
	    done; done))
