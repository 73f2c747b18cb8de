# Windows: cross-built with mingw-w64, tested under Wine (docs: README "Windows").
#   make windows        into $(WIN): j288.dll with its import library libj288.dll.a (lib/ +
#                       port/windows), libj288.a (lib/), libj288_windows.a (port/windows),
#                       every test/unit program, the Windows port's test, a benchmark; all with
#                       the full warning set and -Werror
#   make test-windows   every unit test program under Wine, then the Windows port end to end
#                       against j288-sim through Wine's COM mapping (scripts/windows-test.sh):
#                       a private prefix under $(WIN)/wine, the Wine server stopped at the end
#   make bench-windows  the port's benchmark under Wine (indicative only: Wine's serial layer)
# Without the cross compiler (or Wine, for the tests) they skip with a notice; CI=true fails.
.PHONY: windows windows-build test-windows bench-windows

WIN_CC ?= x86_64-w64-mingw32-gcc
WIN_AR ?= x86_64-w64-mingw32-ar
WIN := $(BUILD)/windows
WIN_OBJ := $(WIN)/obj
WIN_CFLAGS := $(CSTD) $(WARN) $(OPT)
WIN_CPPFLAGS := $(CPPFLAGS_LIB) -Iport/windows
# winmm: timeBeginPeriod (1 ms timer waits) in the port.
WIN_LIBS := -lwinmm

WIN_LIB_A := $(WIN)/libj288.a
WIN_PORT_A := $(WIN)/libj288_windows.a
WIN_DLL := $(WIN)/j288.dll
WIN_IMPLIB := $(WIN)/libj288.dll.a
WIN_PORT_HDR := port/windows/j288_windows.h
WIN_UNIT_TESTS := $(UNIT_TEST_SRC:test/unit/%.c=$(WIN)/test/%.exe)
WIN_PORT_TEST := $(WIN)/test/test_windows_port.exe
WIN_BENCH := $(WIN)/bench/bench_windows_port.exe

$(WIN_OBJ)/lib/%.o: lib/%.c $(LIB_HDR)
	@mkdir -p $(@D)
	$(WIN_CC) $(CPPFLAGS_LIB) $(WIN_CFLAGS) -c $< -o $@

$(WIN_OBJ)/port/windows/%.o: port/windows/%.c $(WIN_PORT_HDR) $(LIB_HDR)
	@mkdir -p $(@D)
	$(WIN_CC) $(WIN_CPPFLAGS) $(WIN_CFLAGS) -c $< -o $@

$(WIN_LIB_A): $(LIB_SRC:%.c=$(WIN_OBJ)/%.o)
	@mkdir -p $(@D)
	rm -f $@
	$(WIN_AR) rcs $@ $^

$(WIN_PORT_A): $(WIN_OBJ)/port/windows/j288_windows.o
	@mkdir -p $(@D)
	rm -f $@
	$(WIN_AR) rcs $@ $^

# The DLL exports every global symbol of lib/ and the port (no __declspec in the headers:
# mingw's linker exports all when none is marked); programs link the import library.
WIN_DLL_OBJ := $(LIB_SRC:%.c=$(WIN_OBJ)/%.o) $(WIN_OBJ)/port/windows/j288_windows.o
$(WIN_DLL) $(WIN_IMPLIB) &: $(WIN_DLL_OBJ)
	@mkdir -p $(@D)
	$(WIN_CC) -shared $(WIN_CFLAGS) $(WIN_DLL_OBJ) -o $(WIN_DLL) \
	    -Wl,--out-implib,$(WIN_IMPLIB) $(WIN_LIBS)

# ---- tests and benchmark ---------------------------------------------------------------------
WIN_UNITY_OBJ := $(WIN_OBJ)/unity/unity.o
$(WIN_UNITY_OBJ): $(UNITY)/unity.c
	@mkdir -p $(@D)
	$(WIN_CC) -std=c99 -O1 -g -I$(UNITY) $(UNITY_DEFS) -c $< -o $@

$(WIN_OBJ)/test/%.o: test/%.c $(TEST_HDR) $(WIN_PORT_HDR) $(UNITY)/unity.c
	@mkdir -p $(@D)
	$(WIN_CC) $(TEST_CPPFLAGS) -Iport/windows $(WIN_CFLAGS) -c $< -o $@

WIN_TEST_SUPPORT_OBJ := $(TEST_SUPPORT_SRC:%.c=$(WIN_OBJ)/%.o)
$(WIN)/test/%.exe: $(WIN_OBJ)/test/unit/%.o $(WIN_TEST_SUPPORT_OBJ) $(WIN_UNITY_OBJ) $(WIN_LIB_A)
	@mkdir -p $(@D)
	$(WIN_CC) $(WIN_CFLAGS) $^ -o $@

# The port's test goes through the DLL (its import library): that checks the DLL too.
$(WIN_PORT_TEST): $(WIN_OBJ)/test/windows/test_windows_port.o $(WIN_UNITY_OBJ) $(WIN_IMPLIB)
	@mkdir -p $(@D)
	$(WIN_CC) $(WIN_CFLAGS) $^ -o $@

$(WIN_BENCH): $(WIN_OBJ)/test/windows/bench_windows_port.o $(WIN_PORT_A) $(WIN_LIB_A)
	@mkdir -p $(@D)
	$(WIN_CC) $(WIN_CFLAGS) $^ -o $@ $(WIN_LIBS)

WIN_ALL := $(WIN_LIB_A) $(WIN_PORT_A) $(WIN_DLL) $(WIN_IMPLIB) $(WIN_UNIT_TESTS) $(WIN_PORT_TEST) \
    $(WIN_BENCH)

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
