# The j288 command-line tool (examples/cli) and its end-to-end tests (test/e2e/cli_*.sh).
# Owner: cli. `make demo` lives in mk/demo.mk.
#   $(BIN)/j288    offline frame calculator + bus commands over the Linux port
#   make cli       just the tool

CLI_SRC := $(sort $(wildcard examples/cli/*.c))
CLI_OBJ := $(CLI_SRC:%.c=$(OBJ)/%.o)
CLI_HDR := $(wildcard examples/cli/*.h)
# Spelled out rather than $(LINUX_A): mk/linux.mk is included after this file, and a rule's
# prerequisites are expanded when it is read. The rule that builds it lives there.
CLI_LINUX_A := $(BUILD)/lib/libj288_linux.a
# The tool is a POSIX program (signals, realpath, popen for gnuplot); lib/ stays pure C99.
CLI_CPPFLAGS := $(CPPFLAGS_LIB) -Iport/linux -D_XOPEN_SOURCE=700

$(OBJ)/examples/cli/%.o: examples/cli/%.c $(CLI_HDR) $(LIB_HDR) port/linux/j288_linux.h
	@mkdir -p $(@D)
	$(CC) $(CLI_CPPFLAGS) $(CFLAGS_COMMON) -c $< -o $@

$(BIN)/j288: $(CLI_OBJ) $(CLI_LINUX_A) $(LIB_A)
	@mkdir -p $(@D)
	$(CC) $(CFLAGS_COMMON) $^ -o $@ $(LDFLAGS_COMMON) -lm

.PHONY: cli
cli: $(BIN)/j288

# Unity test of the tool's helpers (test/cli/): linked with the helper objects, not main().
CLI_TEST := $(BUILD)/test/test_cli_helpers
CLI_TEST_DEPS := $(addprefix $(OBJ)/examples/cli/,args.o hexparse.o json.o frameview.o report.o)

$(OBJ)/test/cli/%.o: test/cli/%.c $(CLI_HDR) $(LIB_HDR) $(UNITY)/unity.c
	@mkdir -p $(@D)
	$(CC) $(TEST_CPPFLAGS) -Iexamples/cli -Iport/linux -D_XOPEN_SOURCE=700 $(CFLAGS_COMMON) \
	    -c $< -o $@

$(CLI_TEST): $(OBJ)/test/cli/test_cli_helpers.o $(CLI_TEST_DEPS) $(UNITY_OBJ) $(LIB_A)
	@mkdir -p $(@D)
	$(CC) $(CFLAGS_COMMON) $^ -o $@ $(LDFLAGS_COMMON) -lm

ALL_TARGETS += $(BIN)/j288 $(CLI_TEST)
HOST_TESTS += $(CLI_TEST)
TEST_DEPS += $(BIN)/j288 $(BIN)/j288-sim
TEST_SCRIPTS += test/e2e/cli_offline.sh test/e2e/cli_bus.sh
