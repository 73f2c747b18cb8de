# The DDS bridge (tools/j288-dds, docs/dds.md) and its tests, built when Cyclone DDS is there
# (Debian: cyclonedds-dev cyclonedds-tools, i.e. libddsc, its pkg-config file and idlc).
#   make dds           $(DDS_BIN): build/bin/j288-dds (also built by `make` when found)
#   test/dds/*.sh      the namespace guard, golden XCDR1 bytes and the unitree crc, and the
#                      bridge end to end, each
#                      in a private network namespace (TEST_SCRIPTS)
#   make test-dds      those tests alone (CI's test-dds step)
#   make bench-dds     cycles/s with and without DDS, command-to-wire latency, DDS's CPU share
# Without Cyclone DDS: a one-line notice and nothing else (CI=true: an error). CMake builds and
# installs the bridge too (cmake/j288_tools.cmake): make install, make deb (package j288-dds).
# The IDL in tools/j288-dds/idl is compiled by idlc into $(DDS_GEN) (-t: no XTypes type
# information, so that peers match on the type name as ROS 2's rmw_cyclonedds does).
.PHONY: dds dds-missing test-dds bench-dds
DDS_FOUND := $(shell pkg-config --exists CycloneDDS 2>/dev/null && command -v idlc >/dev/null 2>&1 && echo yes)
DDS_BIN := $(BIN)/j288-dds
DDS_GEN := $(BUILD)/dds/gen
DDS_IDL_NAMES := builtin_interfaces std_msgs sensor_msgs diagnostic_msgs unitree_go
DDS_IDL := $(DDS_IDL_NAMES:%=tools/j288-dds/idl/%.idl)
DDS_GEN_OBJ := $(DDS_IDL_NAMES:%=$(OBJ)/dds/gen/%.o)
DDS_GEN_HDR := $(DDS_IDL_NAMES:%=$(DDS_GEN)/%.h)
DDS_CPPFLAGS := $(TOOL_CPPFLAGS) -Itools/j288-dds -I$(DDS_GEN) $(shell pkg-config --cflags CycloneDDS 2>/dev/null)
DDS_LIBS := $(shell pkg-config --libs CycloneDDS 2>/dev/null)
DDS_TOOL_OBJ := $(addprefix $(OBJ)/tools/j288-dds/,bridge.o diag.o unitree_crc.o)
DDS_TEST_PEER := $(BUILD)/test/dds_peer
DDS_GOLDEN := $(BUILD)/test/dds_golden
DDS_TESTS := test/dds/netns_guard.sh test/dds/golden.sh test/dds/bridge_e2e.sh test/dds/unitree_e2e.sh

ifeq ($(DDS_FOUND),yes)
# idlc writes NAME.c and NAME.h; the .c stands for both.
$(DDS_GEN)/%.c: tools/j288-dds/idl/%.idl $(DDS_IDL)
	@mkdir -p $(@D)
	idlc -t -I tools/j288-dds/idl -o $(DDS_GEN) $<
$(DDS_GEN)/%.h: $(DDS_GEN)/%.c ;

# Generated code: C99, not held to the project's warning set (it is idlc's).
$(OBJ)/dds/gen/%.o: $(DDS_GEN)/%.c $(DDS_GEN_HDR)
	@mkdir -p $(@D)
	$(CC) $(CSTD) $(OPT) $(EXTRA_CFLAGS) $(DDS_CPPFLAGS) -c $< -o $@

# The bridge's and the tests' objects (the test peer, test/dds/dds_peer.c, shares nothing with
# the bridge but the IDL) need idlc's headers first; their programs link Cyclone's library.
$(OBJ)/tools/j288-dds/%.o $(OBJ)/test/dds/%.o: CPPFLAGS_OBJ = $(DDS_CPPFLAGS)
$(OBJ)/tools/j288-dds/main.o $(DDS_TOOL_OBJ) $(OBJ)/test/dds/dds_peer.o $(OBJ)/test/dds/dds_golden.o: \
    $(DDS_GEN_HDR)
$(DDS_BIN) $(DDS_TEST_PEER) $(DDS_GOLDEN): LDFLAGS_COMMON += $(DDS_LIBS)

$(DDS_BIN): $(OBJ)/tools/j288-dds/main.o $(DDS_TOOL_OBJ) $(DDS_GEN_OBJ) $(ROBOT_OBJ) $(CONFIG_OBJ) \
    $(LINUX_A) $(LIB_A) $(YAML_ENV)
	$(LINK)
$(DDS_TEST_PEER): $(OBJ)/test/dds/dds_peer.o $(DDS_GEN_OBJ)
	$(LINK)
# The golden-bytes program: Cyclone's serialization, and the crc of unitree_crc.c. Cyclone's
# serdata header pulls in its atomics, which use GNU asm: gnu99 for that one file.
$(OBJ)/test/dds/dds_golden.o: CFLAGS_COMMON += -std=gnu99
$(DDS_GOLDEN): $(OBJ)/test/dds/dds_golden.o $(OBJ)/tools/j288-dds/unitree_crc.o $(DDS_GEN_OBJ) $(LIB_A)
	$(LINK)

dds: $(DDS_BIN)
ALL_TARGETS += $(DDS_BIN) $(DDS_TEST_PEER) $(DDS_GOLDEN)
TEST_DEPS += $(DDS_BIN) $(DDS_TEST_PEER) $(DDS_GOLDEN) $(SIM_BIN)
TEST_SCRIPTS += $(DDS_TESTS)

test-dds: $(DDS_BIN) $(DDS_TEST_PEER) $(DDS_GOLDEN) $(SIM_BIN)
	$(call RUN_TESTS,$(DDS_TESTS))

bench-dds: $(DDS_BIN) $(DDS_TEST_PEER) $(SIM_BIN) $(J288_BIN) $(BUILD)/bench/write_stamp.so
	BUILD=$(BUILD) bash scripts/bench-dds.sh
else
dds dds-missing test-dds bench-dds:
	@if [ "$${CI:-}" = true ]; then \
	    echo "error: Cyclone DDS not found (CI=true: a failure); install: cyclonedds-dev cyclonedds-tools" >&2; exit 1; fi
	@echo "notice: skipping j288-dds and its tests, Cyclone DDS not found; install with: apt-get install -y --no-install-recommends cyclonedds-dev cyclonedds-tools" >&2
ALL_TARGETS += dds-missing
TEST_DEPS += dds-missing
endif

# The benchmark's write() stamper (test/bench/write_stamp.c), preloaded into the bridge.
$(BUILD)/bench/write_stamp.so: test/bench/write_stamp.c
	@mkdir -p $(@D)
	$(CC) -O2 -shared -fPIC $< -o $@ -ldl
