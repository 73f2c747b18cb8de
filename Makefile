# j288 - plain-Make host build. `make` builds the library, tools and tests into build/;
# `make test` runs every host test; `make demo` runs the CLI against the built-in simulator.
# Areas add their own rules in mk/*.mk (included below); this file holds what they share.

BUILD ?= build
CC ?= cc
ifeq ($(origin CC),default)
CC := cc
endif
AR ?= ar
PYTHON ?= python3

WARN := -Wall -Wextra -Wpedantic -Wconversion -Wshadow -Werror
CSTD := -std=c99
OPT ?= -O2 -g
CPPFLAGS_LIB := -Ilib/include
CFLAGS_COMMON := $(CSTD) $(WARN) $(OPT) $(EXTRA_CFLAGS)
LDFLAGS_COMMON := $(EXTRA_LDFLAGS)

BIN := $(BUILD)/bin
OBJ := $(BUILD)/obj

LIB_SRC := $(sort $(wildcard lib/src/*.c))
LIB_OBJ := $(LIB_SRC:%.c=$(OBJ)/%.o)
LIB_A := $(BUILD)/lib/libj288.a
LIB_HDR := $(wildcard lib/include/j288/*.h lib/src/*.h)

# Unity (fetched, never committed; see scripts/fetch-unity.sh).
UNITY := $(BUILD)/unity
UNITY_OBJ := $(OBJ)/unity/unity.o
UNITY_CFLAGS := -std=c99 -O1 -g -I$(UNITY) -DUNITY_INCLUDE_DOUBLE -DUNITY_SUPPORT_64 $(EXTRA_CFLAGS)

# Shared test helpers, linked into every host unit test.
TEST_SUPPORT_SRC := $(sort $(wildcard test/support/*.c))
TEST_SUPPORT_OBJ := $(TEST_SUPPORT_SRC:%.c=$(OBJ)/%.o)
TEST_CPPFLAGS := $(CPPFLAGS_LIB) -I$(UNITY) -Itest/support -Itest/vectors -DUNITY_INCLUDE_DOUBLE -DUNITY_SUPPORT_64

# test/unit/test_*.c -> build/test/test_*: each a plain main() with RUN_TEST lines.
UNIT_TEST_SRC := $(sort $(wildcard test/unit/test_*.c))
UNIT_TESTS := $(UNIT_TEST_SRC:test/unit/%.c=$(BUILD)/test/%)

# Fragments append: HOST_TESTS (binaries run by `make test`), TEST_SCRIPTS (shell tests run
# after them, from the repo root, with BUILD and BIN in the environment), ALL_TARGETS.
HOST_TESTS := $(UNIT_TESTS)
TEST_SCRIPTS :=
ALL_TARGETS := $(LIB_A) $(UNIT_TESTS)

.PHONY: all lib test unit-tests unity clean help
.DEFAULT_GOAL := all
.SECONDARY:

include $(sort $(wildcard mk/*.mk))

all: $(ALL_TARGETS)

lib: $(LIB_A)

$(OBJ)/lib/%.o: lib/%.c $(LIB_HDR)
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS_LIB) $(CFLAGS_COMMON) -c $< -o $@

$(LIB_A): $(LIB_OBJ)
	@mkdir -p $(@D)
	rm -f $@
	$(AR) rcs $@ $^

$(UNITY)/unity.c:
	bash scripts/fetch-unity.sh $(UNITY)

unity: $(UNITY)/unity.c

$(UNITY_OBJ): $(UNITY)/unity.c
	@mkdir -p $(@D)
	$(CC) $(UNITY_CFLAGS) -c $< -o $@

$(OBJ)/test/%.o: test/%.c $(LIB_HDR) $(UNITY)/unity.c $(wildcard test/support/*.h test/vectors/*.h)
	@mkdir -p $(@D)
	$(CC) $(TEST_CPPFLAGS) $(CFLAGS_COMMON) -c $< -o $@

$(BUILD)/test/%: $(OBJ)/test/unit/%.o $(TEST_SUPPORT_OBJ) $(UNITY_OBJ) $(LIB_A)
	@mkdir -p $(@D)
	$(CC) $(CFLAGS_COMMON) $^ -o $@ $(LDFLAGS_COMMON) -lm

unit-tests: $(UNIT_TESTS)
	BUILD=$(BUILD) bash scripts/run-tests.sh $(UNIT_TESTS)

test: $(HOST_TESTS) $(TEST_DEPS)
	BUILD=$(BUILD) BIN=$(BIN) bash scripts/run-tests.sh $(HOST_TESTS) $(TEST_SCRIPTS)

clean:
	rm -rf $(BUILD)

help:
	@echo "make            build library, tools and host tests into $(BUILD)/"
	@echo "make test       run every host test (fetches Unity on first use)"
	@echo "make demo       the CLI against the built-in servo simulator"
	@echo "make arm        cross-build lib/ for Cortex-M0 and Cortex-M4F, size table"
	@echo "see mk/*.mk for the other targets"
