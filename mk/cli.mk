# The j288 command-line tool (examples/cli) and its end-to-end tests (test/e2e/cli_*.sh).
# Owner: cli. `make demo` lives in mk/demo.mk.

CLI_SRC := $(sort $(wildcard examples/cli/*.c))
CLI_OBJ := $(CLI_SRC:%.c=$(OBJ)/%.o)
CLI_HDR := $(wildcard examples/cli/*.h)
# The tool is a POSIX program (signals, poll, fork for gnuplot); lib/ stays pure C99.
CLI_CPPFLAGS := $(CPPFLAGS_LIB) -D_POSIX_C_SOURCE=200809L

$(OBJ)/examples/cli/%.o: examples/cli/%.c $(CLI_HDR) $(LIB_HDR)
	@mkdir -p $(@D)
	$(CC) $(CLI_CPPFLAGS) $(CFLAGS_COMMON) -c $< -o $@

$(BIN)/j288: $(CLI_OBJ) $(LIB_A)
	@mkdir -p $(@D)
	$(CC) $(CFLAGS_COMMON) $^ -o $@ $(LDFLAGS_COMMON) -lm

.PHONY: cli
cli: $(BIN)/j288

ALL_TARGETS += $(BIN)/j288
TEST_DEPS += $(BIN)/j288
TEST_SCRIPTS += test/e2e/cli_offline.sh
