# Windows: cross-built with mingw-w64, tested under Wine (docs: README "Windows").
#   make windows        into $(WIN): j288.exe (the CLI), j288.dll with its import library
#                       libj288.dll.a (lib/ + port/windows + the runner and config reader),
#                       libj288.a (lib/), libj288_windows.a (port/desktop + port/windows), every test/unit
#                       program, the Windows port's test, a benchmark; all -Werror
#   make test-windows   every unit test program under Wine, then the Windows port and j288.exe
#                       end to end against j288-sim through Wine's COM mapping
#                       (scripts/windows-test.sh): a private prefix under $(WIN)/wine, the
#                       Wine server stopped at the end
#   make bench-windows  the port's benchmark under Wine (indicative only: Wine's serial layer)
# Without the cross compiler (or Wine, for the tests) they skip with a notice; CI=true fails.
.PHONY: windows windows-build test-windows bench-windows

WIN_CC ?= x86_64-w64-mingw32-gcc
WIN_AR ?= x86_64-w64-mingw32-ar
WIN := $(BUILD)/windows
WIN_OBJ := $(WIN)/obj
# $(DEPFLAGS): each object's header dependencies beside it (X.d, included by the Makefile).
WIN_CFLAGS := $(CSTD) $(WARN) $(OPT) $(DEPFLAGS)
WIN_CPPFLAGS := $(CPPFLAGS_LIB) -Iport/desktop -Iport/windows
# winmm: timeBeginPeriod (1 ms timer waits) in the port.
WIN_LIBS := -lwinmm

WIN_LIB_A := $(WIN)/libj288.a
WIN_PORT_A := $(WIN)/libj288_windows.a
WIN_DLL := $(WIN)/j288.dll
WIN_IMPLIB := $(WIN)/libj288.dll.a
WIN_UNIT_TESTS := $(UNIT_TEST_SRC:test/unit/%.c=$(WIN)/test/%.exe)
WIN_PORT_TEST := $(WIN)/test/test_windows_port.exe
WIN_BENCH := $(WIN)/bench/bench_windows_port.exe

# The host's COMPILE and LINK recipes (Makefile) with the cross compiler and these flags: every
# target under $(WIN) takes them (pattern-specific), each folder its CPPFLAGS_OBJ.
$(WIN)/%: CC = $(WIN_CC)
$(WIN)/%: CFLAGS_COMMON = $(WIN_CFLAGS)
$(WIN)/%: LDFLAGS_COMMON =
$(WIN)/%: YAML_ENV = $(WIN_YAML_ENV)
$(WIN_OBJ)/%.o: %.c
	$(COMPILE)
$(WIN_OBJ)/test/%.o: test/%.c $(UNITY)/unity.c
	$(COMPILE)
$(WIN_OBJ)/port/%.o: CPPFLAGS_OBJ = $(WIN_CPPFLAGS)
$(WIN_OBJ)/test/%.o: CPPFLAGS_OBJ = $(TEST_CPPFLAGS) -Iport/desktop -Iport/windows -Itest/desktop

$(WIN_LIB_A): $(LIB_SRC:%.c=$(WIN_OBJ)/%.o)
	@mkdir -p $(@D)
	rm -f $@
	$(WIN_AR) rcs $@ $^

WIN_PORT_OBJ := $(WIN_OBJ)/port/desktop/j288_serial.o $(WIN_OBJ)/port/windows/j288_windows.o
$(WIN_PORT_A): $(WIN_PORT_OBJ)
	@mkdir -p $(@D)
	rm -f $@
	$(WIN_AR) rcs $@ $^

# ---- the host layer and the CLI: j288.exe ----------------------------------------------------
# The runner, the config reader and tools/j288 over the Windows port (port/desktop/j288_serial.h),
# with Debian's libyaml source cross-built (scripts/libyaml-mingw.sh; without it the reader's
# stubs refuse config files). C99 printf (%zu, %lld) from mingw-w64's own stdio.
# -Wno-float-conversion: mingw-w64's isfinite/isnan/signbit macros type-check a float branch
# for every double argument; the Linux builds of the same code keep the warning.
WIN_TOOL_CPPFLAGS := $(WIN_CPPFLAGS) -Ihost -Itools/j288 -D__USE_MINGW_ANSI_STDIO=1
WIN_TOOL_CFLAGS := $(WIN_CFLAGS) -Wno-float-conversion
WIN_YAML_ENV := $(WIN)/libyaml/libyaml.env
WIN_HOST_OBJ := $(WIN_OBJ)/host/j288_robot.o $(WIN_OBJ)/host/j288_robot_config.o \
    $(WIN_OBJ)/host/j288_number.o
# j288 top and jog are POSIX terminal programs (their screen: live.c): tools/j288/windows/
# says so instead.
WIN_J288_OBJ := $(patsubst %.c,$(WIN_OBJ)/%.o,$(filter-out tools/j288/cmd_top.c \
    tools/j288/cmd_jog.c tools/j288/live.c,$(J288_SRC)) tools/j288/windows/cmd_top.c \
    tools/j288/windows/cmd_jog.c)
WIN_J288 := $(WIN)/j288.exe

$(WIN_YAML_ENV):
	bash scripts/libyaml-mingw.sh $(WIN)/libyaml $(WIN_CC)

$(WIN_OBJ)/host/%.o $(WIN_OBJ)/tools/j288/%.o $(WIN_J288): CPPFLAGS_OBJ = $(WIN_TOOL_CPPFLAGS)
$(WIN_OBJ)/host/%.o $(WIN_OBJ)/tools/j288/%.o $(WIN_J288): CFLAGS_COMMON = $(WIN_TOOL_CFLAGS)
$(WIN_HOST_OBJ): $(WIN_YAML_ENV)
$(WIN_J288) $(WIN_DLL) $(WIN_IMPLIB) $(WIN_BENCH): LDFLAGS_COMMON = $(WIN_LIBS)

$(WIN_J288): $(WIN_J288_OBJ) $(WIN_HOST_OBJ) $(WIN_PORT_A) $(WIN_LIB_A) $(WIN_YAML_ENV)
	$(LINK)

# The DLL exports every global symbol of lib/ and the port (no __declspec in the headers:
# mingw's linker exports all when none is marked); programs link the import library.
# It holds the runner and the config reader too: what the Python package binds.
WIN_DLL_OBJ := $(LIB_SRC:%.c=$(WIN_OBJ)/%.o) $(WIN_PORT_OBJ) $(WIN_HOST_OBJ)
$(WIN_DLL) $(WIN_IMPLIB) &: $(WIN_DLL_OBJ) $(WIN_YAML_ENV)
	@mkdir -p $(@D)
	$(WIN_CC) -shared $(WIN_CFLAGS) $(WIN_DLL_OBJ) -o $(WIN_DLL) \
	    -Wl,--out-implib,$(WIN_IMPLIB) $(call YAML_IF_USED,LIBS) $(WIN_LIBS)

# ---- tests and benchmark ---------------------------------------------------------------------
WIN_UNITY_OBJ := $(WIN_OBJ)/unity/unity.o
$(WIN_UNITY_OBJ): $(UNITY)/unity.c
	@mkdir -p $(@D)
	$(WIN_CC) $(UNITY_CFLAGS) -c $< -o $@

WIN_TEST_SUPPORT_OBJ := $(TEST_SUPPORT_SRC:%.c=$(WIN_OBJ)/%.o)
$(WIN)/test/%.exe: $(WIN_OBJ)/test/unit/%.o $(WIN_TEST_SUPPORT_OBJ) $(WIN_UNITY_OBJ) $(WIN_LIB_A)
	$(LINK)

# The port's test goes through the DLL (its import library): that checks the DLL too.
WIN_SERIAL_LOOP_OBJ := $(WIN_OBJ)/test/desktop/serial_loop.o
$(WIN_PORT_TEST): $(WIN_OBJ)/test/windows/test_windows_port.o $(WIN_SERIAL_LOOP_OBJ) \
    $(WIN_OBJ)/test/desktop/serial_checks.o $(WIN_UNITY_OBJ) $(WIN_IMPLIB)
	$(LINK)

$(WIN_BENCH): $(WIN_OBJ)/test/windows/bench_windows_port.o $(WIN_SERIAL_LOOP_OBJ) $(WIN_PORT_A) $(WIN_LIB_A)
	$(LINK)

WIN_ALL := $(WIN_LIB_A) $(WIN_PORT_A) $(WIN_DLL) $(WIN_IMPLIB) $(WIN_UNIT_TESTS) $(WIN_PORT_TEST) \
    $(WIN_BENCH)
WIN_ALL += $(WIN_J288)

windows-build: $(WIN_ALL)

WIN_NEED_CC = $(call REQUIRE,$(WIN_CC),gcc-mingw-w64-x86-64-win32)
WIN_NEED_WINE = $(call REQUIRE,wine,wine wine64)

windows:
	@$(WIN_NEED_CC); $(MAKE) --no-print-directory windows-build

test-windows:
	@$(WIN_NEED_CC); $(WIN_NEED_WINE); \
	 $(MAKE) --no-print-directory windows-build $(SIM_BIN) && \
	 WIN=$(WIN) SIM=$(SIM_BIN) bash scripts/windows-test.sh $(WIN_UNIT_TESTS)

bench-windows:
	@$(WIN_NEED_CC); $(WIN_NEED_WINE); \
	 $(MAKE) --no-print-directory windows-build $(SIM_BIN) && \
	 WIN=$(WIN) SIM=$(SIM_BIN) bash scripts/windows-test.sh --bench
