# mk/linux.mk - the Linux termios2 port (port/linux) and its test against the simulator.
#   $(LINUX_A)                   libj288_linux.a: link it before $(LIB_A)
#   $(BUILD)/test/test_linux_port  Unity test over a real pty served by $(BIN)/j288-sim
# Users: -Iport/linux, #include "j288_linux.h", link $(LINUX_A) $(LIB_A).

LINUX_SRC := port/linux/j288_linux.c
LINUX_HDR := port/linux/j288_linux.h
LINUX_OBJ := $(LINUX_SRC:%.c=$(OBJ)/%.o)
LINUX_A := $(BUILD)/lib/libj288_linux.a
LINUX_CPPFLAGS := $(CPPFLAGS_LIB) -Iport/linux
LINUX_PORT_TEST := $(BUILD)/test/test_linux_port

$(OBJ)/port/linux/%.o: port/linux/%.c $(LINUX_HDR) $(LIB_HDR)
	@mkdir -p $(@D)
	$(CC) $(LINUX_CPPFLAGS) $(CFLAGS_COMMON) -c $< -o $@

$(LINUX_A): $(LINUX_OBJ)
	@mkdir -p $(@D)
	rm -f $@
	$(AR) rcs $@ $^

$(OBJ)/test/linux/%.o: test/linux/%.c $(LINUX_HDR) $(LIB_HDR) $(UNITY)/unity.c
	@mkdir -p $(@D)
	$(CC) $(TEST_CPPFLAGS) -Iport/linux -DJ288_SIM_DEFAULT='"$(BIN)/j288-sim"' \
	    $(CFLAGS_COMMON) -c $< -o $@

$(LINUX_PORT_TEST): $(OBJ)/test/linux/test_linux_port.o $(UNITY_OBJ) $(LINUX_A) $(LIB_A)
	@mkdir -p $(@D)
	$(CC) $(CFLAGS_COMMON) $^ -o $@ $(LDFLAGS_COMMON) -lm

.PHONY: linux
linux: $(LINUX_A)

ALL_TARGETS += $(LINUX_A)
ifneq ($(wildcard test/linux/test_linux_port.c),)
ALL_TARGETS += $(LINUX_PORT_TEST)
HOST_TESTS += $(LINUX_PORT_TEST)
TEST_DEPS += $(BIN)/j288-sim
endif

# The robot config reader (port/linux/j288_robot_config.c, not in the archive: it needs libyaml).
# scripts/libyaml.sh finds libyaml (the system's, else Debian's package fetched into
# $(BUILD)/libyaml) and writes the flags into $(YAML_ENV); without it the reader builds as
# stubs that say so. Users: $(CONFIG_OBJ) and $(call yaml_var,YAML_LIBS) in a recipe.
YAML_ENV := $(BUILD)/libyaml/libyaml.env
yaml_var = $$(sed -n 's/^$(1)=//p' $(YAML_ENV))
CONFIG_OBJ := $(OBJ)/port/linux/j288_robot_config.o
CONFIG_TEST := $(BUILD)/test/test_robot_config

$(YAML_ENV):
	bash scripts/libyaml.sh $(BUILD)/libyaml "$(CC)"

$(CONFIG_OBJ): port/linux/j288_robot_config.c port/linux/j288_robot_config.h $(YAML_ENV)
	@mkdir -p $(@D)
	$(CC) $(LINUX_CPPFLAGS) $(call yaml_var,YAML_CFLAGS) $(CFLAGS_COMMON) -c $< -o $@

$(OBJ)/test/linux/test_robot_config.o: test/linux/test_robot_config.c port/linux/j288_robot_config.h \
                                 $(UNITY)/unity.c $(YAML_ENV)
	@mkdir -p $(@D)
	$(CC) $(TEST_CPPFLAGS) -Iport/linux $(call yaml_var,YAML_CFLAGS) $(CFLAGS_COMMON) -c $< -o $@

$(CONFIG_TEST): $(OBJ)/test/linux/test_robot_config.o $(CONFIG_OBJ) $(UNITY_OBJ)
	@mkdir -p $(@D)
	$(CC) $(CFLAGS_COMMON) $^ -o $@ $(LDFLAGS_COMMON) $(call yaml_var,YAML_LIBS) -lm

ifneq ($(wildcard test/linux/test_robot_config.c),)
ALL_TARGETS += $(CONFIG_TEST)
HOST_TESTS += $(CONFIG_TEST)
endif

# `make bench-linux`: round-trip latency and sweep rate over the simulator's pty (indicative
# wall-clock figures; see docs/performance.md).
LINUX_BENCH := $(BUILD)/bench/bench_linux_port
$(LINUX_BENCH): $(OBJ)/test/linux/bench_linux_port.o $(LINUX_A) $(LIB_A)
	@mkdir -p $(@D)
	$(CC) $(CFLAGS_COMMON) $^ -o $@ $(LDFLAGS_COMMON) -lm

.PHONY: bench-linux
bench-linux: $(LINUX_BENCH) $(BIN)/j288-sim
	$(LINUX_BENCH) $(BIN)/j288-sim 5000
ALL_TARGETS += $(LINUX_BENCH)
