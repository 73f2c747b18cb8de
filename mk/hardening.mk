# mk/hardening.mk - issue 6: fuzzing, sanitizers, valgrind, static analysis, symbol check,
# big-endian and 32-bit runs, coverage and the fault soak. Owner: hardening.
#
#   make fuzz            each libFuzzer target for FUZZ_SECONDS (default 30) with ASan+UBSan
#   make fuzz-ci         the same, 60 s each (what .ci/run calls)
#   make fuzz-corpus     regenerate the committed seed corpora from test/vectors
#   make test-asan       the whole host test suite built with ASan+UBSan (no recovery)
#   make test-valgrind   the host test binaries, and the e2e scripts' j288 / j288-sim, under memcheck
#   make lint            cppcheck (+ MISRA C:2012 addon) and clang-tidy over lib/, vs baseline
#   make check-symbols   lib/ references no allocator, stdio or process-exit symbol
#   make test-be         unit tests built for s390x (big-endian) and run under qemu-s390x
#   make test-32         unit tests built for armhf (32-bit) and run under qemu-arm
#   make coverage        gcov line/branch coverage of lib/ from the unit tests (gcovr, enforced)
#   make soak            fault soak: >= 100000 transactions against j288-sim on a pty
#   make soak-short      the CI variant
# Tools are installed by scripts/ci-install.sh; outside CI a missing tool is skipped with a
# notice (scripts/hard-need.sh), with CI=true it is a failure.

HARD_NEED := bash scripts/hard-need.sh
# $(call HARD_REQUIRE,tool,packages): in a recipe line, skip the rest of the line (status 0)
# when the tool is missing outside CI, fail when it is missing with CI=true.
HARD_REQUIRE = $(HARD_NEED) $(1) $(2) || { [ $$? -eq 1 ] && exit 0; exit 1; }
# Sub-builds reuse this build's Unity instead of fetching it again.
HARD_SUBMAKE = UNITY_DIR=$(abspath $(UNITY)) $(MAKE) --no-print-directory

# ---------------------------------------------------------------------------------------------
# Fuzzing
FUZZ_SECONDS ?= 30
FUZZ_CC ?= clang-14
FUZZ_SAN := -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined
FUZZ_CFLAGS := -std=c99 -g -O1 $(FUZZ_SAN) -Ilib/include -Itest/fuzz -Itest/support
# A target is test/fuzz/fuzz_<name>.c; an optional test/fuzz/fuzz_<name>.mk-style list of
# extra sources comes from FUZZ_EXTRA_<name> below.
FUZZ_NAMES := $(sort $(patsubst test/fuzz/fuzz_%.c,%,$(wildcard test/fuzz/fuzz_*.c)))
FUZZ_BINS := $(FUZZ_NAMES:%=$(BUILD)/fuzz/fuzz_%)
FUZZ_DICT := test/fuzz/j288.dict

# Per-target extras: sources (libFuzzer build), objects (replay build), preprocessor flags.
# The CLI target links the tool's parsers as functions (hexparse.c, args.c), not by exec.
FUZZ_EXTRA_cli := examples/cli/hexparse.c examples/cli/args.c
FUZZ_EXTRA_OBJ_cli := $(OBJ)/examples/cli/hexparse.o $(OBJ)/examples/cli/args.o
FUZZ_CPPFLAGS_cli = -Iexamples/cli $(CLI_CPPFLAGS)

$(BUILD)/fuzz/fuzz_%: test/fuzz/fuzz_%.c test/fuzz/fuzz_common.h $(LIB_SRC) $(LIB_HDR) \
                      $(wildcard test/fuzz/*.h examples/cli/*.c examples/cli/*.h)
	@mkdir -p $(@D)
	$(FUZZ_CC) $(FUZZ_CFLAGS) $(FUZZ_CPPFLAGS_$*) $< $(FUZZ_EXTRA_$*) $(LIB_SRC) -o $@ -lm

.PHONY: fuzz fuzz-ci fuzz-build fuzz-corpus
fuzz-build:
	@$(call HARD_REQUIRE,$(FUZZ_CC),clang-14 libclang-rt-14-dev); \
	 $(MAKE) --no-print-directory $(FUZZ_BINS)

# Each target runs for FUZZ_SECONDS over the committed seeds plus its own working corpus in
# the build folder (new inputs go there; the committed corpus stays small). A crash or a
# broken invariant stops with the input saved under $(BUILD)/fuzz/artifacts/.
fuzz:
	@$(call HARD_REQUIRE,$(FUZZ_CC),clang-14 libclang-rt-14-dev); \
	 $(MAKE) --no-print-directory $(FUZZ_BINS) && \
	 for t in $(FUZZ_NAMES); do \
	   mkdir -p $(BUILD)/fuzz/work/$$t $(BUILD)/fuzz/artifacts; \
	   echo "fuzz: $$t for $(FUZZ_SECONDS) s"; \
	   $(BUILD)/fuzz/fuzz_$$t -max_total_time=$(FUZZ_SECONDS) -timeout=10 -rss_limit_mb=2048 \
	     -dict=$(FUZZ_DICT) -print_final_stats=1 \
	     -artifact_prefix=$(BUILD)/fuzz/artifacts/$$t- \
	     $(BUILD)/fuzz/work/$$t test/fuzz/corpus/$$t > $(BUILD)/fuzz/$$t.log 2>&1; \
	   rc=$$?; grep -E '^stat::number_of_executed_units|^#[0-9]+.*DONE' $(BUILD)/fuzz/$$t.log | tail -n 2; \
	   if [ $$rc -ne 0 ]; then tail -n 40 $(BUILD)/fuzz/$$t.log; echo "fuzz: $$t FAILED"; exit 1; fi; \
	 done; echo "fuzz: all targets clean"

fuzz-ci:
	@$(MAKE) --no-print-directory fuzz FUZZ_SECONDS=60

fuzz-corpus:
	$(PYTHON) test/fuzz/make_corpus.py

# Corpus replay: every target also builds with the normal compiler as a plain program that
# runs its committed corpus, so `make test` (and every sanitizer/cross build) re-checks the
# invariants on the seeds and on saved crash inputs.
FUZZ_REPLAY_TESTS := $(FUZZ_NAMES:%=$(BUILD)/test/fuzz_replay_%)

$(OBJ)/test/fuzz/replay_%.o: test/fuzz/replay_main.c test/fuzz/fuzz_common.h
	@mkdir -p $(@D)
	$(CC) -Itest/fuzz -DFUZZ_CORPUS_DIR='"test/fuzz/corpus/$*"' $(CFLAGS_COMMON) -c $< -o $@

$(OBJ)/test/fuzz/fuzz_%.o: test/fuzz/fuzz_%.c $(LIB_HDR) $(wildcard test/fuzz/*.h test/support/*.h)
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS_LIB) -Itest/fuzz -Itest/support $(FUZZ_CPPFLAGS_$*) $(CFLAGS_COMMON) -c $< -o $@

$(BUILD)/test/fuzz_replay_%: $(OBJ)/test/fuzz/fuzz_%.o $(OBJ)/test/fuzz/replay_%.o $(LIB_A)
	@mkdir -p $(@D)
	$(CC) $(CFLAGS_COMMON) $^ -o $@ $(LDFLAGS_COMMON) -lm

# Extra objects of a target's replay (a rule without recipe adds prerequisites, and so $^).
$(BUILD)/test/fuzz_replay_cli: $(FUZZ_EXTRA_OBJ_cli)

HOST_TESTS += $(FUZZ_REPLAY_TESTS)
ALL_TARGETS += $(FUZZ_REPLAY_TESTS)

# ---------------------------------------------------------------------------------------------
# Sanitizers and valgrind
HARD_SAN_FLAGS := -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer
HARD_ASAN_ENV := ASAN_OPTIONS=detect_leaks=1:abort_on_error=0:detect_stack_use_after_return=1:strict_string_checks=1 \
                 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1

.PHONY: test-asan test-valgrind
test-asan: $(UNITY)/unity.c
	$(HARD_ASAN_ENV) $(HARD_SUBMAKE) BUILD=$(BUILD)/asan \
	    EXTRA_CFLAGS="$(HARD_SAN_FLAGS)" EXTRA_LDFLAGS="$(HARD_SAN_FLAGS)" test

HARD_VALGRIND := valgrind -q --error-exitcode=1 --leak-check=full --show-leak-kinds=all \
                 --errors-for-leak-kinds=definite,indirect,possible --track-origins=yes

# The test binaries under $(HARD_VALGRIND), then the e2e scripts (TEST_SCRIPTS) with j288 and
# j288-sim run under memcheck through test/e2e/valgrind-wrap.sh (symlinks in $(HARD_VG_E2E)/bin;
# reports in $(HARD_VG_E2E)/logs: any line but valgrind's notice about the tty ioctls it does
# not know (TIOCEXCL/TIOCNXCL) fails the run, the simulator's reports included). The golden
# vector checks there take every 20th vector (all of them run in `make test`).
# (Fragments included after this one add to HOST_TESTS: the list is taken at run time.)
HARD_VG_E2E = $(BUILD)/valgrind-e2e
test-valgrind:
	@$(call HARD_REQUIRE,valgrind,valgrind); \
	 $(MAKE) --no-print-directory $(HOST_TESTS) $(TEST_DEPS) && \
	 TEST_WRAPPER="$(HARD_VALGRIND)" BUILD=$(BUILD) BIN=$(BIN) bash scripts/run-tests.sh $(HOST_TESTS); \
	 rc=$$?; \
	 rm -rf $(HARD_VG_E2E) && mkdir -p $(HARD_VG_E2E)/bin $(HARD_VG_E2E)/logs && \
	 ln -s $(abspath test/e2e/valgrind-wrap.sh) $(HARD_VG_E2E)/bin/j288 && \
	 ln -s $(abspath test/e2e/valgrind-wrap.sh) $(HARD_VG_E2E)/bin/j288-sim && \
	 echo "test-valgrind: e2e scripts with j288 and j288-sim under memcheck" && \
	 J288=$(abspath $(HARD_VG_E2E))/bin/j288 J288_SIM=$(abspath $(HARD_VG_E2E))/bin/j288-sim \
	 J288_VALGRIND=$$(command -v valgrind) J288_VALGRIND_BIN=$(abspath $(BIN)) \
	 J288_VALGRIND_LOGS=$(abspath $(HARD_VG_E2E))/logs J288_E2E_VECTOR_STRIDE=20 \
	   BUILD=$(BUILD) BIN=$(BIN) bash scripts/run-tests.sh $(TEST_SCRIPTS) || rc=1; \
	 bad=$$(grep -lEv 'unhandled ioctl 0x|could cause spurious value errors|README_MISSING_SYSCALL_OR_IOCTL' \
	        $(HARD_VG_E2E)/logs/* 2>/dev/null | sort); \
	 if [ -n "$$bad" ]; then head -n 40 $$bad; echo "test-valgrind: memcheck errors in: $$bad"; rc=1; fi; \
	 echo "test-valgrind: $$(ls $(HARD_VG_E2E)/logs | wc -l) program runs checked by memcheck in the e2e scripts"; \
	 exit $$rc

# ---------------------------------------------------------------------------------------------
# Static analysis and the symbol check
.PHONY: lint check-symbols
lint:
	BUILD=$(BUILD) bash scripts/lint.sh

# The host archive, and lib/ built for Cortex-M0 (soft float: libgcc helpers only) when
# arm-none-eabi-gcc is there.
HARD_ARM_CC ?= arm-none-eabi-gcc
HARD_ARM_FLAGS := -mcpu=cortex-m0 -mthumb -Os -ffunction-sections -fdata-sections
HARD_ARM_A := $(BUILD)/hard-arm/libj288.a

$(BUILD)/hard-arm/%.o: lib/src/%.c $(LIB_HDR)
	@mkdir -p $(@D)
	$(HARD_ARM_CC) $(HARD_ARM_FLAGS) $(CPPFLAGS_LIB) $(CSTD) $(WARN) -c $< -o $@

$(HARD_ARM_A): $(LIB_SRC:lib/src/%.c=$(BUILD)/hard-arm/%.o)
	rm -f $@
	arm-none-eabi-ar rcs $@ $^

check-symbols: $(LIB_A)
	bash scripts/check-symbols.sh $(LIB_A)
	@$(call HARD_REQUIRE,$(HARD_ARM_CC),gcc-arm-none-eabi libnewlib-arm-none-eabi); \
	 $(MAKE) --no-print-directory $(HARD_ARM_A) && \
	 bash scripts/check-symbols.sh $(HARD_ARM_A) arm-none-eabi-nm

# ---------------------------------------------------------------------------------------------
# Big-endian and 32-bit: the unit tests and the corpus replays, cross-built and run under
# qemu-user. The sub-build asserts the compiler's byte order / pointer size first.
HARD_BE_CC ?= s390x-linux-gnu-gcc
HARD_BE_QEMU ?= qemu-s390x -L /usr/s390x-linux-gnu
HARD_32_CC ?= arm-linux-gnueabihf-gcc
HARD_32_QEMU ?= qemu-arm -L /usr/arm-linux-gnueabihf
HARD_CROSS_TESTS := $(UNIT_TESTS) $(FUZZ_REPLAY_TESTS)

.PHONY: test-be test-32 hard-cross-run
test-be: $(UNITY)/unity.c
	@$(call HARD_REQUIRE,$(HARD_BE_CC),gcc-s390x-linux-gnu libc6-dev-s390x-cross); \
	 $(call HARD_REQUIRE,qemu-s390x,qemu-user); \
	 $(HARD_BE_CC) -dM -E - </dev/null | grep -q '^#define __BYTE_ORDER__ __ORDER_BIG_ENDIAN__$$' \
	   || { echo "$(HARD_BE_CC) is not big-endian" >&2; exit 1; }; \
	 $(HARD_SUBMAKE) BUILD=$(BUILD)/be CC=$(HARD_BE_CC) AR=s390x-linux-gnu-ar \
	     HARD_WRAPPER="$(HARD_BE_QEMU)" hard-cross-run

test-32: $(UNITY)/unity.c
	@$(call HARD_REQUIRE,$(HARD_32_CC),gcc-arm-linux-gnueabihf libc6-dev-armhf-cross); \
	 $(call HARD_REQUIRE,qemu-arm,qemu-user); \
	 $(HARD_32_CC) -dM -E - </dev/null | grep -q '^#define __SIZEOF_POINTER__ 4$$' \
	   || { echo "$(HARD_32_CC) does not build 32-bit code" >&2; exit 1; }; \
	 $(HARD_SUBMAKE) BUILD=$(BUILD)/32 CC=$(HARD_32_CC) AR=arm-linux-gnueabihf-ar \
	     HARD_WRAPPER="$(HARD_32_QEMU)" hard-cross-run

hard-cross-run: $(HARD_CROSS_TESTS)
	TEST_WRAPPER="$(HARD_WRAPPER)" BUILD=$(BUILD) bash scripts/run-tests.sh $(HARD_CROSS_TESTS)

# ---------------------------------------------------------------------------------------------
# Coverage of lib/ from the unit tests (not the corpus replays: coverage is the unit tests'
# claim). Excluded lines carry GCOVR_EXCL_LINE with the reason beside them.
COVERAGE_LINE ?= 100
COVERAGE_BRANCH ?= 95
HARD_GCOVR := gcovr --root . --filter 'lib/' --exclude-unreachable-branches \
              --fail-under-line $(COVERAGE_LINE) --fail-under-branch $(COVERAGE_BRANCH)

.PHONY: coverage hard-cov-run
coverage: $(UNITY)/unity.c
	@$(call HARD_REQUIRE,gcovr,gcovr); \
	 $(HARD_SUBMAKE) BUILD=$(BUILD)/cov OPT="-O0 -g" EXTRA_CFLAGS=--coverage \
	     EXTRA_LDFLAGS=--coverage hard-cov-run

# Which tests count (override to widen, e.g. COVERAGE_TESTS='$(UNIT_TESTS) $(FUZZ_REPLAY_TESTS)').
COVERAGE_TESTS ?= $(UNIT_TESTS)

hard-cov-run: $(COVERAGE_TESTS)
	find $(BUILD) -name '*.gcda' -delete
	BUILD=$(BUILD) bash scripts/run-tests.sh $(COVERAGE_TESTS)
	@mkdir -p $(BUILD)/coverage
	$(HARD_GCOVR) --print-summary \
	    --html-details $(BUILD)/coverage/index.html $(OBJ)/lib
	@echo "coverage: HTML report in $(BUILD)/coverage/index.html"

# ---------------------------------------------------------------------------------------------
# Fault soak (test/soak/): the Linux port and scheduler against j288-sim on a pty, faults on,
# then switched off in the same simulator (SIGUSR1): the next sweep must be all healthy.
# soak-short runs under valgrind memcheck when it is there (leaks, invalid accesses), with a
# wider reply margin since valgrind slows the host side down.
SOAK_TXNS ?= 100000
SOAK_SHORT_TXNS ?= 10000
SOAK_BIN := $(BUILD)/soak/soak

# (mk/linux.mk is included after this file: its variables are spelled out here.)
$(OBJ)/test/soak/%.o: test/soak/%.c $(LIB_HDR) port/linux/j288_linux.h
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS_LIB) -Iport/linux $(CFLAGS_COMMON) -c $< -o $@

$(SOAK_BIN): $(OBJ)/test/soak/soak.o $(BUILD)/lib/libj288_linux.a $(LIB_A)
	@mkdir -p $(@D)
	$(CC) $(CFLAGS_COMMON) $^ -o $@ $(LDFLAGS_COMMON) -lm

.PHONY: soak soak-short
soak: $(SOAK_BIN) $(BIN)/j288-sim
	$(SOAK_BIN) $(BIN)/j288-sim --txns $(SOAK_TXNS)

soak-short: $(SOAK_BIN) $(BIN)/j288-sim
	@if command -v valgrind >/dev/null 2>&1; then \
	   echo "soak-short: under valgrind memcheck"; \
	   $(HARD_VALGRIND) $(SOAK_BIN) $(BIN)/j288-sim --txns $(SOAK_SHORT_TXNS) --margin-us 50000; \
	 else \
	   $(HARD_NEED) valgrind valgrind; [ $$? -eq 1 ] || exit 1; \
	   $(SOAK_BIN) $(BIN)/j288-sim --txns $(SOAK_SHORT_TXNS); \
	 fi

ALL_TARGETS += $(SOAK_BIN)
