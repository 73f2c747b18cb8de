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
