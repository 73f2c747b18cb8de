# The DDS bridge (tools/j288-dds, docs/dds.md) and its tests, built when Cyclone DDS is there
# (Debian: cyclonedds-dev cyclonedds-tools, i.e. libddsc, its pkg-config file and idlc).
#   make dds           $(DDS_BIN): build/bin/j288-dds (also built by `make` when found); with
#                      libsystemd (Debian: libsystemd-dev) it talks to systemd (sd_notify:
#                      READY, WATCHDOG), without it a one-line notice (CI=true: an error)
#   test/dds/*.sh      the namespace guard, golden XCDR1 bytes, the unitree crc and the type
#                      hashes, the bridge end to end (ROS 2 and both unitree modes; soft limits
#                      and a wheel: limits_e2e.sh), the service under a fake systemd, each in a
#                      private network namespace (TEST_SCRIPTS)
#   make test-dds      those tests alone (CI's test-dds step)
#   make test-dds-fastdds  a Fast DDS peer (ROS 2's default middleware) against the bridge, lo
#                      with and without multicast (CI's test-fastdds step; Debian:
#                      libfastrtps-dev fastddsgen g++; not in make test: its build is C++)
#   make bench-dds     cycles/s with and without DDS, command-to-wire latency, DDS's CPU share,
#                      and the state rate at 500 Hz idle, under load and under a flood
# Without Cyclone DDS: a one-line notice and nothing else (CI=true: an error). CMake builds and
# installs the bridge too (cmake/j288_tools.cmake): make install, make deb (package j288-dds,
# with its systemd unit debian/j288-dds@.service).
# The IDL in tools/j288-dds/idl is compiled by idlc into $(DDS_GEN) (-t: no XTypes type
# information, so that peers match on the type name as ROS 2's rmw_cyclonedds does; the
# sequences bounded, sensor_msgs.idl). The test peer has the same IDL as ROS 2 declares it
# (-DJ288_DDS_AS_ROS2: unbounded), twice: without type information ($(DDS_TEST_PEER), as
# rmw_cyclonedds) and with it ($(DDS_TEST_PEER)_xt, as a peer whose types carry XTypes
# information), both of which the bridge must match.
.PHONY: dds dds-missing dds-no-systemd test-dds bench-dds test-dds-fastdds
DDS_FOUND := $(shell pkg-config --exists CycloneDDS 2>/dev/null && command -v idlc >/dev/null 2>&1 && echo yes)
DDS_SYSTEMD := $(shell pkg-config --exists libsystemd 2>/dev/null && echo yes)
DDS_BIN := $(BIN)/j288-dds
DDS_GEN := $(BUILD)/dds/gen
DDS_IDL_NAMES := builtin_interfaces std_msgs sensor_msgs diagnostic_msgs unitree_go unitree_hg
DDS_IDL := $(DDS_IDL_NAMES:%=tools/j288-dds/idl/%.idl)
DDS_GEN_OBJ := $(DDS_IDL_NAMES:%=$(OBJ)/dds/gen/%.o)
DDS_GEN_HDR := $(DDS_IDL_NAMES:%=$(DDS_GEN)/%.h)
# the test peers' types: ROS 2's (unbounded), without and with XTypes type information
DDS_GEN_ROS2 := $(BUILD)/dds/gen-ros2
DDS_GEN_XT := $(BUILD)/dds/gen-xt
DDS_ROS2_OBJ := $(DDS_IDL_NAMES:%=$(OBJ)/dds/gen-ros2/%.o)
DDS_XT_OBJ := $(DDS_IDL_NAMES:%=$(OBJ)/dds/gen-xt/%.o)
DDS_CPPFLAGS_BASE := $(TOOL_CPPFLAGS) -Itools/j288-dds $(shell pkg-config --cflags CycloneDDS 2>/dev/null)
DDS_CPPFLAGS := $(DDS_CPPFLAGS_BASE) -I$(DDS_GEN)
DDS_LIBS := $(shell pkg-config --libs CycloneDDS 2>/dev/null)
DDS_TOOL_OBJ := $(addprefix $(OBJ)/tools/j288-dds/,bridge.o diag.o unitree_crc.o typehash.o service.o)
DDS_TEST_PEER := $(BUILD)/test/dds_peer
DDS_GOLDEN := $(BUILD)/test/dds_golden
DDS_TESTS := test/dds/netns_guard.sh test/dds/golden.sh test/dds/bridge_e2e.sh test/dds/input_e2e.sh \
    test/dds/unitree_e2e.sh test/dds/service.sh test/dds/loss_e2e.sh test/dds/limits_e2e.sh
DDS_PEERS := $(DDS_TEST_PEER) $(DDS_TEST_PEER)_xt $(DDS_GOLDEN)

ifeq ($(DDS_FOUND),yes)
# idlc writes NAME.c and NAME.h; the .c stands for both. Three sets: the bridge's, the peers'.
$(DDS_GEN)/%.c: tools/j288-dds/idl/%.idl $(DDS_IDL)
	@mkdir -p $(@D)
	idlc -t -I tools/j288-dds/idl -o $(DDS_GEN) $<
$(DDS_GEN_ROS2)/%.c: tools/j288-dds/idl/%.idl $(DDS_IDL)
	@mkdir -p $(@D)
	idlc -t -DJ288_DDS_AS_ROS2 -I tools/j288-dds/idl -o $(DDS_GEN_ROS2) $<
$(DDS_GEN_XT)/%.c: tools/j288-dds/idl/%.idl $(DDS_IDL)
	@mkdir -p $(@D)
	idlc -DJ288_DDS_AS_ROS2 -I tools/j288-dds/idl -o $(DDS_GEN_XT) $<
$(DDS_GEN)/%.h: $(DDS_GEN)/%.c ;
$(DDS_GEN_ROS2)/%.h: $(DDS_GEN_ROS2)/%.c ;
$(DDS_GEN_XT)/%.h: $(DDS_GEN_XT)/%.c ;

# Generated code: C99, not held to the project's warning set (it is idlc's).
$(OBJ)/dds/gen/%.o: $(DDS_GEN)/%.c $(DDS_GEN_HDR)
	@mkdir -p $(@D)
	$(CC) $(CSTD) $(OPT) $(EXTRA_CFLAGS) $(DDS_CPPFLAGS) -c $< -o $@
$(OBJ)/dds/gen-ros2/%.o: $(DDS_GEN_ROS2)/%.c $(DDS_IDL_NAMES:%=$(DDS_GEN_ROS2)/%.h)
	@mkdir -p $(@D)
	$(CC) $(CSTD) $(OPT) $(EXTRA_CFLAGS) $(DDS_CPPFLAGS_BASE) -I$(DDS_GEN_ROS2) -c $< -o $@
$(OBJ)/dds/gen-xt/%.o: $(DDS_GEN_XT)/%.c $(DDS_IDL_NAMES:%=$(DDS_GEN_XT)/%.h)
	@mkdir -p $(@D)
	$(CC) $(CSTD) $(OPT) $(EXTRA_CFLAGS) $(DDS_CPPFLAGS_BASE) -I$(DDS_GEN_XT) -c $< -o $@

# The bridge's and the tests' objects need idlc's headers first; their programs link Cyclone's
# library. The peer (test/dds/dds_peer.c) shares nothing with the bridge but the IDL, and
# unitree's crc it computes its own way.
$(OBJ)/tools/j288-dds/%.o $(OBJ)/test/dds/dds_golden.o: CPPFLAGS_OBJ = $(DDS_CPPFLAGS)
$(OBJ)/test/dds/dds_peer.o: CPPFLAGS_OBJ = $(DDS_CPPFLAGS_BASE) -I$(DDS_GEN_ROS2)
$(OBJ)/tools/j288-dds/main.o $(DDS_TOOL_OBJ) $(OBJ)/test/dds/dds_golden.o: $(DDS_GEN_HDR)
$(OBJ)/test/dds/dds_peer.o: $(DDS_IDL_NAMES:%=$(DDS_GEN_ROS2)/%.h)
$(OBJ)/test/dds/xt/dds_peer.o: test/dds/dds_peer.c $(DDS_IDL_NAMES:%=$(DDS_GEN_XT)/%.h)
	@mkdir -p $(@D)
	$(CC) $(DDS_CPPFLAGS_BASE) -I$(DDS_GEN_XT) $(CFLAGS_COMMON) -c $< -o $@
$(DDS_BIN) $(DDS_PEERS): LDFLAGS_COMMON += $(DDS_LIBS)

ifeq ($(DDS_SYSTEMD),yes)
$(OBJ)/tools/j288-dds/service.o: CPPFLAGS_OBJ = $(DDS_CPPFLAGS) -DJ288_DDS_SYSTEMD=1 \
    $(shell pkg-config --cflags libsystemd)
$(DDS_BIN): LDFLAGS_COMMON += $(shell pkg-config --libs libsystemd)
else
# Without libsystemd the bridge builds without sd_notify (service.h), and says so.
$(DDS_BIN): | dds-no-systemd
dds-no-systemd:
	@if [ "$${CI:-}" = true ]; then \
	    echo "error: libsystemd not found (CI=true: a failure); install: libsystemd-dev" >&2; exit 1; fi
	@echo "notice: j288-dds built without systemd support (READY, WATCHDOG); install with: apt-get install -y --no-install-recommends libsystemd-dev" >&2
endif

$(DDS_BIN): $(OBJ)/tools/j288-dds/main.o $(DDS_TOOL_OBJ) $(DDS_GEN_OBJ) $(ROBOT_OBJ) $(CONFIG_OBJ) \
    $(LINUX_A) $(LIB_A) $(YAML_ENV)
	$(LINK)
$(DDS_TEST_PEER): $(OBJ)/test/dds/dds_peer.o $(DDS_ROS2_OBJ)
	$(LINK)
$(DDS_TEST_PEER)_xt: $(OBJ)/test/dds/xt/dds_peer.o $(DDS_XT_OBJ)
	$(LINK)
# The golden-bytes program: Cyclone's serialization, the crc of unitree_crc.c and the type
# hashes of typehash.c. Cyclone's serdata header pulls in its atomics, which use GNU asm:
# gnu99 for that one file.
$(OBJ)/test/dds/dds_golden.o: CFLAGS_COMMON += -std=gnu99
$(DDS_GOLDEN): $(OBJ)/test/dds/dds_golden.o $(OBJ)/tools/j288-dds/unitree_crc.o \
    $(OBJ)/tools/j288-dds/typehash.o $(DDS_GEN_OBJ) $(LIB_A)
	$(LINK)

dds: $(DDS_BIN)
ALL_TARGETS += $(DDS_BIN) $(DDS_PEERS)
TEST_DEPS += $(DDS_BIN) $(DDS_PEERS) $(SIM_BIN)
TEST_SCRIPTS += $(DDS_TESTS)

test-dds: $(DDS_BIN) $(DDS_PEERS) $(SIM_BIN)
	$(call RUN_TESTS,$(DDS_TESTS))

bench-dds: $(DDS_BIN) $(DDS_PEERS) $(SIM_BIN) $(J288_BIN) $(BUILD)/bench/write_stamp.so
	BUILD=$(BUILD) bash scripts/bench-dds.sh

# The Fast DDS peer (test/dds/fastdds_peer.cpp): fastddsgen's C++ types from the same IDL as
# ROS 2 declares it (its preprocessor given -DJ288_DDS_AS_ROS2 through a wrapper), built at
# -O0 (a test program: the build is the cost), the generated code without our warning set.
DDS_FASTDDS := $(shell command -v fastddsgen >/dev/null 2>&1 && command -v $(CXX) >/dev/null 2>&1 && \
    [ -f /usr/include/fastdds/dds/domain/DomainParticipant.hpp ] && echo yes)
FASTDDS_GEN := $(BUILD)/dds/gen-fastdds
FASTDDS_PEER := $(BUILD)/test/fastdds_peer
FASTDDS_IDL_NAMES := builtin_interfaces std_msgs sensor_msgs
FASTDDS_OBJ := $(foreach n,$(FASTDDS_IDL_NAMES),$(OBJ)/dds/gen-fastdds/$(n).o $(OBJ)/dds/gen-fastdds/$(n)PubSubTypes.o)
ifeq ($(DDS_FASTDDS),yes)
$(FASTDDS_GEN)/stamp: $(FASTDDS_IDL_NAMES:%=tools/j288-dds/idl/%.idl)
	@mkdir -p $(@D)
	printf '#!/bin/sh\nexec cpp -DJ288_DDS_AS_ROS2 "$$@"\n' >$(@D)/cpp-ros2 && chmod +x $(@D)/cpp-ros2
	fastddsgen -ppPath $(@D)/cpp-ros2 -I tools/j288-dds/idl -d $(@D) -replace $^ >$(@D)/fastddsgen.log
	touch $@
$(FASTDDS_GEN)/%.cxx: $(FASTDDS_GEN)/stamp ;
$(OBJ)/dds/gen-fastdds/%.o: $(FASTDDS_GEN)/%.cxx
	@mkdir -p $(@D)
	$(CXX) -std=c++11 -O0 -w -I$(FASTDDS_GEN) -c $< -o $@
$(OBJ)/test/dds/fastdds_peer.o: test/dds/fastdds_peer.cpp $(FASTDDS_GEN)/stamp
	@mkdir -p $(@D)
	$(CXX) -std=c++11 -O0 -Wall -Wextra -Werror -I$(FASTDDS_GEN) -c $< -o $@
$(FASTDDS_PEER): $(OBJ)/test/dds/fastdds_peer.o $(FASTDDS_OBJ)
	@mkdir -p $(@D)
	$(CXX) $^ -o $@ -lfastrtps -lfastcdr
test-dds-fastdds: $(DDS_BIN) $(DDS_TEST_PEER) $(FASTDDS_PEER) $(SIM_BIN)
	$(call RUN_TESTS,test/dds/fastdds_e2e.sh)
else
test-dds-fastdds:
	@if [ "$${CI:-}" = true ]; then \
	    echo "error: Fast DDS not found (CI=true: a failure); install: libfastrtps-dev fastddsgen g++" >&2; exit 1; fi
	@echo "notice: skipping the Fast DDS peer test, Fast DDS not found; install with: apt-get install -y --no-install-recommends libfastrtps-dev fastddsgen g++" >&2
endif
else
dds dds-missing test-dds bench-dds test-dds-fastdds:
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
