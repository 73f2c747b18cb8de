# Hardening: fuzzing, sanitizers, valgrind, static analysis, the symbol check, big-endian and
# 32-bit runs, coverage and the fault soak (docs/security.md).
#   make fuzz            every libFuzzer target for FUZZ_SECONDS (default 30) with ASan+UBSan,
#                        as many at once as make's -j allows
#   make fuzz-ci         the same, 10 s each (what .ci/run calls; the corpora replay in make test)
#   make fuzz-corpus     regenerate the committed seed corpora from test/vectors
#   make test-asan       the whole host test suite built with ASan+UBSan (no recovery)
#   make test-valgrind   the host test binaries, and the scripts' j288 / j288-sim, under memcheck
#   make lint            cppcheck (+ MISRA C:2012 addon) and clang-tidy over lib/, vs baseline
#   make check-symbols   lib/ (host and every `make arm` archive) references no allocator,
#                        stdio or process-exit symbol
#   make test-be         unit tests built for s390x (big-endian) and run under qemu-s390x
#   make test-32         unit tests built for armhf (32-bit) and run under qemu-arm
#   make coverage        gcov line/branch coverage of lib/ from the unit tests, and line coverage of
#                        port/stm32_hal per model of the silicon from its suite (gcovr, enforced)
#   make soak            fault soak: >= 100000 transactions against j288-sim on a pty
#   make soak-short      the CI variant, under valgrind memcheck when it is there
# Outside CI a missing tool skips its target with a notice; with CI=true it is a failure.

# Sub-builds reuse this build's Unity instead of fetching it again. (A recipe line that runs
# one through a variable starts with + so that it shares make's job slots.)
SUBMAKE = UNITY_DIR=$(abspath $(UNITY)) $(MAKE) --no-print-directory

# ---- fuzzing ---------------------------------------------------------------------------------
FUZZ_SECONDS ?= 30
FUZZ_CC ?= clang-14
FUZZ_CFLAGS := -std=c99 -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined \
    -Ilib/include -Itest/fuzz -Itest/support
# (one compile of every source: the headers listed by hand)
$(BUILD)/fuzz/fuzz_%: test/fuzz/fuzz_%.c $(LIB_SRC) $(wildcard lib/include/j288/*.h lib/src/*.h test/support/*.h \
    test/vectors/*.h test/fuzz/*.h tools/j288/*.[ch] host/j288_number.[ch] host/j288_robot_config.[ch])
	@mkdir -p $(@D)
	$(FUZZ_CC) $(FUZZ_CFLAGS) $(FUZZ_CPPFLAGS_$*) $(call YAML_IF_USED,CFLAGS) $< $(FUZZ_EXTRA_$*) $(LIB_SRC) -o $@ \
	    $(call YAML_IF_USED,LIBS) -lm
# The config target's flags come from libyaml's probe (mk/tools.mk).
$(BUILD)/fuzz/fuzz_config: $(YAML_ENV)

.PHONY: fuzz fuzz-ci fuzz-all fuzz-corpus $(FUZZ_NAMES:%=fuzz-run-%)
fuzz:
	@$(call REQUIRE,$(FUZZ_CC),clang-14 libclang-rt-14-dev); \
	 $(MAKE) --no-print-directory --output-sync=target fuzz-all && echo "fuzz: all targets clean"

fuzz-all: $(FUZZ_NAMES:%=fuzz-run-%)

$(FUZZ_NAMES:%=fuzz-run-%): fuzz-run-%: $(BUILD)/fuzz/fuzz_%
	@bash scripts/fuzz.sh $* $(FUZZ_SECONDS) $(BUILD)/fuzz

fuzz-ci:
	@$(MAKE) --no-print-directory fuzz FUZZ_SECONDS=10

fuzz-corpus:
	$(PYTHON) test/fuzz/make_corpus.py

# ---- sanitizers and valgrind -----------------------------------------------------------------
SAN_FLAGS := -fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer
# VALGRIND_ORIGINS=no (CI) leaves out --track-origins, which about doubles memcheck's cost
# and only says where an uninitialised value came from: rerun a failure with it.
VALGRIND_ORIGINS ?= yes
VALGRIND := valgrind -q --error-exitcode=1 --leak-check=full --show-leak-kinds=all \
    --errors-for-leak-kinds=definite,indirect,possible --track-origins=$(VALGRIND_ORIGINS)

.PHONY: test-asan test-valgrind
# (Every 4th golden vector through the tool: each ASan run of j288 costs a third of a second,
# and all of them run in make test and test-clang.)
test-asan: $(UNITY)/unity.c
	+J288_E2E_VECTOR_STRIDE=4 ASAN_OPTIONS=detect_leaks=1:abort_on_error=0:detect_stack_use_after_return=1:strict_string_checks=1 \
	UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
	    $(SUBMAKE) BUILD=$(BUILD)/asan EXTRA_CFLAGS="$(SAN_FLAGS)" EXTRA_LDFLAGS="$(SAN_FLAGS)" test

test-valgrind:
	@$(call REQUIRE,valgrind,valgrind); \
	 $(MAKE) --no-print-directory $(HOST_TESTS) $(TEST_DEPS) && \
	 VALGRIND="$(VALGRIND)" $(TEST_ENV) bash scripts/test-valgrind.sh "$(HOST_TESTS)" "$(VALGRIND_SCRIPTS)"

# The scripts run with j288 and j288-sim under memcheck: all but the DDS bridge's and
# Python's, whose programs under test (j288-dds; libj288.so inside python3) are not wrapped
# (test-asan checks the bridge) and whose simulators run the same code as every other script's.
# host_stack.sh neither: its robot forms run under memcheck in cli_robot.sh and cli_robust.sh.
VALGRIND_SCRIPTS = $(filter-out $(DDS_TESTS) scripts/python-test.sh test/e2e/host_stack.sh,$(TEST_SCRIPTS))

# ---- static analysis and the symbol check ----------------------------------------------------
.PHONY: lint check-symbols
lint:
	BUILD=$(BUILD) bash scripts/lint.sh

# The host archive, and every `make arm` archive when arm-none-eabi-gcc is there.
check-symbols: $(LIB_A)
	bash scripts/check-symbols.sh $(LIB_A)
	@$(call REQUIRE_TC,m0 m4f); $(MAKE) --no-print-directory $(ARMLIB_ARCHIVES) >/dev/null && \
	 for a in $(ARMLIB_ARCHIVES); do bash scripts/check-symbols.sh $$a $(TC_arm_NM) || exit 1; done

# ---- big-endian and 32-bit: the unit tests and the corpus replays under qemu-user ------------
# The sub-build asserts the compiler's byte order / pointer size first.
CROSS_TESTS := $(UNIT_TESTS) $(FUZZ_REPLAY_TESTS)
CROSS_be := s390x-linux-gnu gcc-s390x-linux-gnu libc6-dev-s390x-cross qemu-s390x \
    '^\#define __BYTE_ORDER__ __ORDER_BIG_ENDIAN__$$'
CROSS_32 := arm-linux-gnueabihf gcc-arm-linux-gnueabihf libc6-dev-armhf-cross qemu-arm \
    '^\#define __SIZEOF_POINTER__ 4$$'

.PHONY: test-be test-32 cross-run
test-be test-32: test-%: $(UNITY)/unity.c
	+@set -- $(CROSS_$*); \
	 $(call REQUIRE,$$1-gcc,$$2 $$3); $(call REQUIRE,$$4,qemu-user); \
	 $$1-gcc -dM -E - </dev/null | grep -q "$$5" || { echo "$$1-gcc: not the expected ABI" >&2; exit 1; }; \
	 $(SUBMAKE) BUILD=$(BUILD)/$* CC=$$1-gcc AR=$$1-ar CROSS_WRAPPER="$$4 -L /usr/$$1" cross-run

cross-run: $(CROSS_TESTS)
	TEST_WRAPPER="$(CROSS_WRAPPER)" $(call RUN_TESTS,$(CROSS_TESTS))

# ---- coverage of lib/ from the unit tests (the unit tests' claim, not the replays') ----------
# Excluded lines carry GCOVR_EXCL_LINE with the reason beside them.
COVERAGE_LINE ?= 100
COVERAGE_BRANCH ?= 95
COVERAGE_TESTS ?= $(UNIT_TESTS)

# The STM32 port: each build of its suite (mk/tests.mk: test:objdir) covers one model's lines.
COVERAGE_STM32_LINE ?= 98
COVERAGE_STM32 := test_stm32_port:stm32host test_stm32_port_g4:stm32host-g4 \
    test_stm32_port_h7:stm32host-h7 test_stm32_port_m7r0p1:stm32host-m7r0p1

.PHONY: coverage coverage-run
coverage: $(UNITY)/unity.c
	+@$(call REQUIRE,gcovr,gcovr); \
	 $(SUBMAKE) BUILD=$(BUILD)/cov OPT="-O0 -g" EXTRA_CFLAGS=--coverage EXTRA_LDFLAGS=--coverage coverage-run

coverage-run: $(COVERAGE_TESTS) $(STM32_FAMILY_TESTS)
	find $(BUILD) -name '*.gcda' -delete
	$(call RUN_TESTS,$(COVERAGE_TESTS))
	@mkdir -p $(BUILD)/coverage
	gcovr --root . --filter 'lib/' --exclude-unreachable-branches --fail-under-line $(COVERAGE_LINE) \
	    --fail-under-branch $(COVERAGE_BRANCH) --print-summary --html-details $(BUILD)/coverage/index.html $(OBJ)/lib
	@echo "coverage: HTML report in $(BUILD)/coverage/index.html"
	@for v in $(COVERAGE_STM32); do t=$${v%%:*}; d=$${v#*:}; \
	    find $(OBJ)/$$d -name '*.gcda' -delete; \
	    $(BUILD)/test/$$t >$(BUILD)/coverage/$$t.log 2>&1 || { cat $(BUILD)/coverage/$$t.log; exit 1; }; \
	    echo "coverage: port/stm32_hal, $$t:"; \
	    gcovr --root . --filter 'port/stm32_hal/' --fail-under-line $(COVERAGE_STM32_LINE) --print-summary \
	        $(OBJ)/$$d | grep -E '^lines:|j288_stm32.c' || exit 1; \
	done

# ---- fault soak (test/soak/): the Linux port and scheduler against j288-sim, faults on, then
# off in the same simulator (SIGUSR1): the next sweep must be all healthy. Under memcheck the
# reply margin is wider, since valgrind slows the host side down.
SOAK_TXNS ?= 100000
SOAK_SHORT_TXNS ?= 10000
SOAK_BIN := $(BUILD)/soak/soak

$(OBJ)/test/soak/%.o: CPPFLAGS_OBJ = $(LINUX_CPPFLAGS) -Itest/desktop
$(SOAK_BIN): $(OBJ)/test/soak/soak.o $(SERIAL_LOOP_OBJ) $(LINUX_A) $(LIB_A)
	$(LINK)

.PHONY: soak soak-short
soak: $(SOAK_BIN) $(SIM_BIN)
	$(SOAK_BIN) $(SIM_BIN) --txns $(SOAK_TXNS)

soak-short: $(SOAK_BIN) $(SIM_BIN)
	@if $(NEED) valgrind valgrind; then \
	   echo "soak-short: under valgrind memcheck"; \
	   $(VALGRIND) $(SOAK_BIN) $(SIM_BIN) --txns $(SOAK_SHORT_TXNS) --margin-us 50000; \
	 else \
	   [ $$? -eq 1 ] || exit 1; $(SOAK_BIN) $(SIM_BIN) --txns $(SOAK_SHORT_TXNS); \
	 fi

ALL_TARGETS += $(SOAK_BIN)
