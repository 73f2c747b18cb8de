# Engine (lib/src/bus.c, lib/src/sched.c): the bus timing model.
#   make bench        every benchmark; this fragment adds bench-bus
#   make bench-bus    sweep time for 1, 4 and 15 servos against the pure wire time, on the
#                     fake port's virtual clock (6 Mbps 8N1, servo turnaround
#                     ENGINE_BENCH_TURNAROUND, in us); with valgrind, host instructions per
#                     transaction inside the library (callgrind). See docs/performance.md.
ENGINE_BENCH := $(BIN)/bus_timing
ENGINE_BENCH_TURNAROUND ?= 0 10 20 50
# -fno-inline keeps the benchmark's entry points visible to callgrind; lib/ stays as built.
ENGINE_BENCH_CFLAGS := $(CSTD) $(WARN) -O2 -g -fno-inline $(EXTRA_CFLAGS)

$(ENGINE_BENCH): test/bench/bus_timing.c test/support/fake_port.c test/support/fake_port.h $(LIB_A)
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS_LIB) -Itest/support $(ENGINE_BENCH_CFLAGS) test/bench/bus_timing.c \
	    test/support/fake_port.c $(LIB_A) -o $@ $(LDFLAGS_COMMON)

ALL_TARGETS += $(ENGINE_BENCH)

.PHONY: bench bench-bus
bench: bench-bus
bench-bus: $(ENGINE_BENCH)
	BIN=$(BIN) BUILD=$(BUILD) ENGINE_BENCH_TURNAROUND="$(ENGINE_BENCH_TURNAROUND)" \
	    bash test/bench/bus_bench.sh

# The port template must keep compiling (host; and Cortex-M0 when arm-none-eabi-gcc is there):
# test/unit/test_port_template.c includes it and drives a bus through its interrupt glue.
.PHONY: port-template
port-template: $(LIB_A)
	@mkdir -p $(OBJ)/port/template
	$(CC) $(CPPFLAGS_LIB) $(CFLAGS_COMMON) -c port/template/j288_port_template.c \
	    -o $(OBJ)/port/template/j288_port_template.o
	@if command -v arm-none-eabi-gcc >/dev/null 2>&1; then \
	    echo "arm-none-eabi-gcc -mcpu=cortex-m0 ... port/template/j288_port_template.c"; \
	    arm-none-eabi-gcc -mcpu=cortex-m0 -mthumb -Os $(CSTD) $(WARN) $(CPPFLAGS_LIB) -c \
	        port/template/j288_port_template.c -o $(OBJ)/port/template/j288_port_template.m0.o; \
	elif [ "$$CI" = true ]; then echo "port-template: arm-none-eabi-gcc not found" >&2; exit 1; \
	else echo "port-template: skipping the Cortex-M0 build; install gcc-arm-none-eabi"; fi
$(OBJ)/test/unit/test_port_template.o: port/template/j288_port_template.c \
    port/template/j288_port_template.h

# Engine cost on Cortex-M under QEMU -icount (instructions per transaction, port ops empty):
#   make bench-bus-target   needs arm-none-eabi-gcc and qemu-system-arm (Debian packages
#                           gcc-arm-none-eabi libnewlib-arm-none-eabi qemu-system-arm)
ENGINE_TGT_DIR := $(BUILD)/bench-bus-target
ENGINE_TGT_m4 := -mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16 -DJ288_CONFIG_SI_FLOAT=1
ENGINE_TGT_m0 := -mcpu=cortex-m0 -mthumb -mfloat-abi=soft
ENGINE_TGT_QEMU_m4 := -M mps2-an386 -cpu cortex-m4
ENGINE_TGT_QEMU_m0 := -M mps2-an385 -cpu cortex-m3
# Images per core and optimisation: the default CRC backend (table), and slicing-by-4 (s4).
ENGINE_TGT_CRC_table :=
ENGINE_TGT_CRC_s4 := -DJ288_CONFIG_CRC_BACKEND=J288_CRC_BACKEND_SLICE4
ENGINE_TGT_ELFS := $(foreach c,m0 m4,$(foreach o,O2 Os,$(foreach v,table s4,\
                     $(ENGINE_TGT_DIR)/bus_target_$(c)_$(o)_$(v).elf)))

$(ENGINE_TGT_DIR)/bus_target_%.elf: test/bench/bus_target.c test/target/startup.c $(LIB_SRC) $(LIB_HDR)
	@mkdir -p $(@D)
	arm-none-eabi-gcc $(ENGINE_TGT_$(word 1,$(subst _, ,$*))) -$(word 2,$(subst _, ,$*)) -g \
	    $(ENGINE_TGT_CRC_$(word 3,$(subst _, ,$*))) \
	    $(CSTD) $(WARN) -ffunction-sections -fdata-sections $(CPPFLAGS_LIB) \
	    test/bench/bus_target.c test/target/startup.c $(LIB_SRC) \
	    -nostartfiles --specs=nano.specs --specs=rdimon.specs -Wl,--gc-sections -Ltest/target \
	    -T mem_mps2.ld -o $@ -lm

.PHONY: bench-bus-target
bench: bench-bus-target
bench-bus-target:
	@if ! command -v arm-none-eabi-gcc >/dev/null 2>&1 || ! command -v qemu-system-arm >/dev/null 2>&1; then \
	    if [ "$$CI" = true ]; then echo "bench-bus-target: arm-none-eabi-gcc or qemu-system-arm missing" >&2; exit 1; fi; \
	    echo "bench-bus-target: skipped; install gcc-arm-none-eabi libnewlib-arm-none-eabi qemu-system-arm"; \
	    exit 0; fi; \
	 $(MAKE) --no-print-directory BUILD=$(BUILD) $(ENGINE_TGT_ELFS) >/dev/null && \
	 for c in m0 m4; do for o in O2 Os; do for v in table s4; do \
	    echo "Cortex-$$c -$$o (QEMU -icount shift=0), instructions per transaction:"; \
	    if [ $$c = m4 ]; then q="$(ENGINE_TGT_QEMU_m4)"; else q="$(ENGINE_TGT_QEMU_m0)"; fi; \
	    timeout 120 qemu-system-arm $$q -icount shift=0 -nographic -monitor none -serial none \
	        -semihosting-config enable=on,target=native \
	        -kernel $(ENGINE_TGT_DIR)/bus_target_$${c}_$${o}_$$v.elf || exit 1; \
	 done; done; done
