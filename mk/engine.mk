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
