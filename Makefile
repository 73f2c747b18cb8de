# j288 - the build and the test suite (GNU Make; CMake in CMakeLists.txt serves consumers).
#   make            library, tools, example and host tests into build/
#   make test       every host test          make demo      the CLI against the simulator
#   make install    PREFIX=/usr/local, DESTDIR honoured (CMake's install)  make uninstall
#   make help       the other targets
# This file holds what every area shares; mk/*.mk add an area each, mk/cpu/*.mk a CPU each.

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
# Every compile writes its object's header dependencies beside it (X.d, included below): touching
# a header rebuilds the objects that include it, and only those.
DEPFLAGS := -MMD -MP
CFLAGS_COMMON := $(CSTD) $(WARN) $(OPT) $(DEPFLAGS) $(EXTRA_CFLAGS)
LDFLAGS_COMMON := $(EXTRA_LDFLAGS)

BIN := $(BUILD)/bin
OBJ := $(BUILD)/obj

# "tool X is needed": $(call REQUIRE,tool,packages) at the start of a recipe line skips the
# rest of the line (status 0) with a notice when the tool is missing, fails with CI=true.
NEED := bash scripts/need.sh
REQUIRE = $(NEED) $(1) $(2) || { [ $$? -eq 1 ] && exit 0; exit 1; }

# ---- the library -----------------------------------------------------------------------------
LIB_SRC := $(sort $(wildcard lib/src/*.c))
LIB_OBJ := $(LIB_SRC:%.c=$(OBJ)/%.o)
LIB_A := $(BUILD)/lib/libj288.a

# What the fragments build and use (named here so that any fragment can depend on them).
LINUX_A := $(BUILD)/lib/libj288_linux.a
J288_BIN := $(BIN)/j288
SIM_BIN := $(BIN)/j288-sim

# ---- the test suite --------------------------------------------------------------------------
# Unity (fetched, never committed; see scripts/fetch-unity.sh).
UNITY := $(BUILD)/unity
UNITY_OBJ := $(OBJ)/unity/unity.o
UNITY_DEFS := -DUNITY_INCLUDE_DOUBLE -DUNITY_SUPPORT_64
UNITY_CFLAGS := -std=c99 -O1 -g -I$(UNITY) $(UNITY_DEFS) $(DEPFLAGS) $(EXTRA_CFLAGS)

# Shared test helpers, linked into every host unit test.
TEST_SUPPORT_SRC := $(sort $(wildcard test/support/*.c))
TEST_SUPPORT_OBJ := $(TEST_SUPPORT_SRC:%.c=$(OBJ)/%.o)
TEST_CPPFLAGS := $(CPPFLAGS_LIB) -I$(UNITY) -Itest/support -Itest/vectors $(UNITY_DEFS)

# test/unit/test_*.c -> build/test/test_*: each a plain main() with RUN_TEST lines.
UNIT_TEST_SRC := $(sort $(wildcard test/unit/test_*.c))
UNIT_TESTS := $(UNIT_TEST_SRC:test/unit/%.c=$(BUILD)/test/%)

# Fragments append: HOST_TESTS (binaries `make test` runs), TEST_SCRIPTS (shell tests run
# after them from the repository root, with BUILD, BIN and CC in the environment), TEST_DEPS
# (what the scripts need), ALL_TARGETS (what `make` builds besides HOST_TESTS; the CRC
# variants' sub-builds are left to `make test`).
HOST_TESTS := $(UNIT_TESTS)
TEST_SCRIPTS :=
TEST_DEPS :=
ALL_TARGETS := $(LIB_A)

.PHONY: all lib test test-host unit-tests unity clean help install uninstall
.DEFAULT_GOAL := all
.SECONDARY:

# Each fragment may use what the ones before it define.
include $(sort $(wildcard mk/cpu/*.mk))
include mk/tools.mk mk/tests.mk mk/target.mk mk/bench.mk mk/hardening.mk mk/firmware.mk
include mk/robot.mk mk/release.mk mk/python.mk mk/dds.mk mk/windows.mk

all: $(ALL_TARGETS) $(filter-out $(BUILD)/crc-%,$(HOST_TESTS))

# The header dependencies of every object built so far (DEPFLAGS).
-include $(shell find $(BUILD) -name '*.d' 2>/dev/null)

lib: $(LIB_A)

# Every host object X.c -> $(OBJ)/X.o, and every host program, by these two recipes. An object
# takes its folder's preprocessor flags from CPPFLAGS_OBJ (pattern-specific, set beside the
# folder's programs; the most specific pattern wins); an object or program that depends on
# $(YAML_ENV) gets libyaml's flags.
CPPFLAGS_OBJ = $(CPPFLAGS_LIB)
YAML_IF_USED = $(if $(filter $(YAML_ENV),$^),$(call yaml_var,YAML_$(1)))
define COMPILE
@mkdir -p $(@D)
$(CC) $(CPPFLAGS_OBJ) $(call YAML_IF_USED,CFLAGS) $(CFLAGS_COMMON) -c $< -o $@
endef
define LINK
@mkdir -p $(@D)
$(CC) $(CFLAGS_COMMON) $(filter %.o %.a,$^) -o $@ $(LDFLAGS_COMMON) $(call YAML_IF_USED,LIBS) -lm
endef
$(OBJ)/%.o: %.c
	$(COMPILE)
# (test objects need Unity's header: fetched first)
$(OBJ)/test/%.o: test/%.c $(UNITY)/unity.c
	$(COMPILE)
$(OBJ)/test/%.o: CPPFLAGS_OBJ = $(TEST_CPPFLAGS)

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

$(BUILD)/test/%: $(OBJ)/test/unit/%.o $(TEST_SUPPORT_OBJ) $(UNITY_OBJ) $(LIB_A)
	$(LINK)

# $(call RUN_TESTS,tests...): the runner, with what the test scripts expect to find.
TEST_ENV = BUILD=$(BUILD) BIN=$(BIN) CC="$(CC)" J288_CFLAGS="$(filter-out $(DEPFLAGS),$(CFLAGS_COMMON))" \
    J288_LDFLAGS="$(LDFLAGS_COMMON)"
RUN_TESTS = $(TEST_ENV) bash scripts/run-tests.sh $(1)

unit-tests: $(UNIT_TESTS)
	$(call RUN_TESTS,$(UNIT_TESTS))

test: $(HOST_TESTS) $(TEST_DEPS)
	$(call RUN_TESTS,$(HOST_TESTS) $(TEST_SCRIPTS))

# Every program and test built, the compiled tests run (not the scripts, which drive the
# same programs end to end): CI's second compiler (test-clang).
test-host: $(HOST_TESTS) $(TEST_DEPS) $(ALL_TARGETS)
	$(call RUN_TESTS,$(HOST_TESTS))

# make test N times in a row, with stress-ng --cpu LOAD beside it (scripts/test-loop.sh).
N ?= 10
LOAD ?= 0
.PHONY: test-loop
test-loop: $(HOST_TESTS) $(TEST_DEPS)
	BUILD=$(BUILD) bash scripts/test-loop.sh $(N) $(LOAD)

# ---- install ---------------------------------------------------------------------------------
# CMake's install (cmake/j288_install.cmake) from $(CMAKE_BUILD) for PREFIX under DESTDIR;
# uninstall removes what it listed ($(INSTALLED)) and the j288 directories left empty.
PREFIX ?= /usr/local
CMAKE_BUILD := $(BUILD)/cmake
INSTALLED := $(CMAKE_BUILD)/installed.txt
install:
	@$(call REQUIRE,cmake,cmake); \
	 cmake -S . -B $(CMAKE_BUILD) -DCMAKE_INSTALL_PREFIX=$(PREFIX) $(CMAKE_FLAGS) >/dev/null && \
	 cmake --build $(CMAKE_BUILD) -j2 && DESTDIR=$(DESTDIR) cmake --install $(CMAKE_BUILD) && \
	 { sed 's|^|$(DESTDIR)|' $(CMAKE_BUILD)/install_manifest.txt; echo; } | grep . >$(INSTALLED)

uninstall:
	@[ -f $(INSTALLED) ] || { echo "uninstall: $(INSTALLED) missing: nothing installed from here"; exit 1; }
	tr '\n' '\0' <$(INSTALLED) | xargs -0 rm -f
	sed -n 's|^\(.*/j288\)/[^/]*$$|\1|p' $(INSTALLED) | sort -u | xargs -r rmdir --ignore-fail-on-non-empty
	rm $(INSTALLED)

clean:
	rm -rf $(BUILD)

help:
	@echo "make                build library, tools, example and host tests into $(BUILD)/"
	@echo "make test           every host test (fetches Unity on first use)"
	@echo "make demo           the CLI against the built-in servo simulator"
	@echo "make test-loop      make test N times (10), stress-ng --cpu LOAD (0) beside it"
	@echo "make install        cmake --install: libraries, headers, CMake package, j288.pc, j288,"
	@echo "                    j288-sim, man pages, completion, Python package (PREFIX, DESTDIR)"
	@echo "make uninstall      removes what make install installed"
	@echo "make shared python  libj288.so; and a copy in python/j288 (the Python package in place)"
	@echo "make arm            lib/ for each Cortex-M, size table, STM32 example, port template"
	@echo "make windows        j288.exe, j288.dll, libraries and tests for Windows (mingw-w64)"
	@echo "make test-windows   those tests and j288.exe against the simulator under Wine"
	@echo "make firmware       STM32 firmware per board against ST's HAL (bash scripts/fetch-st.sh first)"
	@echo "make test-target    unit tests on each CPU under QEMU ($(CPUS))"
	@echo "make size           flash, RAM and stack per module on Cortex-M0 and M4F"
	@echo "make bench          bus timing model and instruction counts (bench-* for one)"
	@echo "make test-asan test-valgrind test-be test-32 coverage lint check-symbols check-abi"
	@echo "make fuzz soak      (hardening: docs/security.md)"
