# The host test suite besides test/unit/ (whose test_*.c the Makefile picks up by itself).
# Every binary here lands in HOST_TESTS and every script in TEST_SCRIPTS: `make test` runs
# them all, and the sanitizer and valgrind runs (mk/hardening.mk) run the same lists.
#   test/cli/          the j288 tool's helpers, linked with the helper objects (not main())
#   test/sim/          the simulator's servo model
#   test/linux/        the Linux port over a real pty served by j288-sim, the robot config reader
#   test/stm32/        the STM32 port against a fake HAL, with the real engine
#   crc-<backend>/     the codec tests again with each compile-time CRC backend
#   test/fuzz/         every fuzz target replaying its committed corpus
#   scripts            test/e2e/*.sh (tools and example end to end), the golden vectors'
#                      drift check, test/abi/check-abi.sh (layout options must match to link)

# ---- the j288 tool's helpers -----------------------------------------------------------------
CLI_TEST := $(BUILD)/test/test_cli_helpers
$(OBJ)/test/cli/%.o: CPPFLAGS_OBJ = $(TEST_CPPFLAGS) -Itools/j288 $(TOOL_CPPFLAGS)

# The captured error stream both tool tests check (test/cli/cli_capture.c).
CLI_CAPTURE_OBJ := $(OBJ)/test/cli/cli_capture.o

$(CLI_TEST): $(OBJ)/test/cli/test_cli_helpers.o $(CLI_CAPTURE_OBJ) \
    $(addprefix $(OBJ)/tools/j288/,args.o hexparse.o json.o frameview.o report.o) $(NUMBER_OBJ) \
    $(UNITY_OBJ) $(LIB_A)
	$(LINK)

# The live plot of jog and top (tools/j288/tplot.c) against series worked out by hand.
CLI_TPLOT_TEST := $(BUILD)/test/test_cli_tplot
$(CLI_TPLOT_TEST): $(OBJ)/test/cli/test_cli_tplot.o $(OBJ)/tools/j288/tplot.o $(UNITY_OBJ) $(LIB_A)
	$(LINK)
HOST_TESTS += $(CLI_TPLOT_TEST)

# The tool's robot config and joint selection (cli_joint.c), with the bus plumbing it calls.
CLI_JOINT_TEST := $(BUILD)/test/test_cli_joint
$(OBJ)/test/cli/test_cli_joint.o: $(YAML_ENV)

$(CLI_JOINT_TEST): $(OBJ)/test/cli/test_cli_joint.o $(CLI_CAPTURE_OBJ) \
    $(addprefix $(OBJ)/tools/j288/,cli_joint.o cli_bus.o args.o json.o report.o) \
    $(OBJ)/host/j288_robot.o $(OBJ)/host/j288_rt.o $(OBJ)/host/j288_rt_linux.o $(CONFIG_OBJ) \
    $(UNITY_OBJ) $(LINUX_A) $(LIB_A) $(YAML_ENV)
	$(LINK)
HOST_TESTS += $(CLI_JOINT_TEST)

# ---- the codec tests with each CRC backend (J288_CONFIG_CRC_BACKEND) -------------------------
# slice4, nibble, bitwise, and HW through J288_CONFIG_CRC_HW_FUNCTION (a stand-in in
# test/support). Each is a sub-build in $(BUILD)/crc-<backend>, one sub-make building all its
# binaries.
CODEC_CRC_VARIANTS := slice4 nibble bitwise hw
CODEC_CRC_FLAGS_slice4 := -DJ288_CONFIG_CRC_BACKEND=J288_CRC_BACKEND_SLICE4
CODEC_CRC_FLAGS_nibble := -DJ288_CONFIG_CRC_BACKEND=J288_CRC_BACKEND_NIBBLE
CODEC_CRC_FLAGS_bitwise := -DJ288_CONFIG_CRC_BACKEND=J288_CRC_BACKEND_BITWISE
CODEC_CRC_FLAGS_hw := -DJ288_CONFIG_CRC_BACKEND=J288_CRC_BACKEND_HW \
                      -DJ288_CONFIG_CRC_HW_FUNCTION=codec_hw_crc_stub
CODEC_CRC_TEST_NAMES := test_crc32 test_frame test_parser
.PHONY: codec-force
codec-force:
$(CODEC_CRC_TEST_NAMES:%=$(BUILD)/crc-\%/test/%): $(UNITY)/unity.c codec-force
	@$(MAKE) --no-print-directory BUILD=$(BUILD)/crc-$* UNITY_DIR=$(abspath $(UNITY)) CC=$(CC) \
	    EXTRA_CFLAGS='$(EXTRA_CFLAGS) $(CODEC_CRC_FLAGS_$*)' $(CODEC_CRC_TEST_NAMES:%=$(BUILD)/crc-$*/test/%)

# ---- fuzz targets replaying their corpus -----------------------------------------------------
# Every test/fuzz/fuzz_<name>.c also builds with the normal compiler as a plain program that
# runs test/fuzz/corpus/<name>, so that every host, sanitizer and cross run re-checks the
# invariants on the seeds and on saved crash inputs. FUZZ_EXTRA_<name>: the target's extra
# sources (the cli target links the tool's parsers as functions, not by exec).
FUZZ_NAMES := $(sort $(patsubst test/fuzz/fuzz_%.c,%,$(wildcard test/fuzz/fuzz_*.c)))
FUZZ_REPLAY_TESTS := $(FUZZ_NAMES:%=$(BUILD)/test/fuzz_replay_%)
FUZZ_EXTRA_cli := tools/j288/hexparse.c tools/j288/args.c host/j288_number.c
FUZZ_CPPFLAGS_cli := -Itools/j288 $(TOOL_CPPFLAGS)
# The config target links the reader and libyaml.
FUZZ_EXTRA_config := host/j288_robot_config.c host/j288_number.c
FUZZ_CPPFLAGS_config := -Ihost
$(OBJ)/test/fuzz/fuzz_config.o $(BUILD)/test/fuzz_replay_config: $(YAML_ENV)

# (their own rules: the flags depend on the target's name, $*)
$(OBJ)/test/fuzz/replay_%.o: CPPFLAGS_OBJ = -Itest/fuzz -DFUZZ_CORPUS_DIR='"test/fuzz/corpus/$*"'
$(OBJ)/test/fuzz/replay_%.o: test/fuzz/replay_main.c
	$(COMPILE)
$(OBJ)/test/fuzz/fuzz_%.o: CPPFLAGS_OBJ = $(CPPFLAGS_LIB) -Itest/fuzz -Itest/support $(FUZZ_CPPFLAGS_$*)
$(OBJ)/test/fuzz/fuzz_%.o: test/fuzz/fuzz_%.c
	$(COMPILE)

$(BUILD)/test/fuzz_replay_%: $(OBJ)/test/fuzz/fuzz_%.o $(OBJ)/test/fuzz/replay_%.o $(LIB_A)
	$(LINK)
$(foreach n,$(FUZZ_NAMES),$(eval $(BUILD)/test/fuzz_replay_$(n): $(FUZZ_EXTRA_$(n):%.c=$(OBJ)/%.o)))

# ---- the Linux port, the simulator's model, the STM32 port -----------------------------------
LINUX_PORT_TEST := $(BUILD)/test/test_linux_port
$(OBJ)/test/linux/%.o $(OBJ)/test/desktop/%.o: CPPFLAGS_OBJ = $(TEST_CPPFLAGS) -Iport/desktop -Iport/linux -Ihost \
    -Itest/desktop -DJ288_SIM_DEFAULT='"$(SIM_BIN)"' \
    -DJ288_EXAMPLE_CONFIG='"examples/robot.yaml"'

# j288-sim as a child process, for the tests that drive it (test/linux/sim_process.c).
SIM_PROCESS_OBJ := $(OBJ)/test/linux/sim_process.o

# test/desktop/: the bus loop the port tests (and benchmarks, the soak) drive a port with, and
# the checks every OS's port test runs alike.
SERIAL_LOOP_OBJ := $(OBJ)/test/desktop/serial_loop.o

$(LINUX_PORT_TEST): $(OBJ)/test/linux/test_linux_port.o $(SIM_PROCESS_OBJ) $(SERIAL_LOOP_OBJ) \
    $(OBJ)/test/desktop/serial_checks.o $(UNITY_OBJ) $(LINUX_A) $(LIB_A)
	$(LINK)

CONFIG_TEST := $(BUILD)/test/test_robot_config
$(OBJ)/test/linux/test_robot_config.o: $(YAML_ENV)

$(CONFIG_TEST): $(OBJ)/test/linux/test_robot_config.o $(CONFIG_OBJ) $(UNITY_OBJ) $(LIB_A) $(YAML_ENV)
	$(LINK)

SIM_MODEL_TEST := $(BUILD)/test/test_sim_model
$(OBJ)/test/sim/%.o: CPPFLAGS_OBJ = $(TEST_CPPFLAGS) -Itools/j288-sim

$(SIM_MODEL_TEST): $(OBJ)/test/sim/test_sim_model.o $(SIM_MODEL_OBJ) $(UNITY_OBJ) $(LIB_A)
	$(LINK)

# The joint against the simulator's physics in simulated time: soft limits in every mode, a
# wheel (the simulator's truth, not the library's view).
JOINT_SIM_TEST := $(BUILD)/test/test_joint_sim
$(JOINT_SIM_TEST): $(OBJ)/test/sim/test_joint_sim.o $(SIM_MODEL_OBJ) $(TEST_SUPPORT_OBJ) $(UNITY_OBJ) \
    $(LIB_A)
	$(LINK)


# The port against the fake HAL (test/stm32/fake_hal.c, every register access watched:
# J288_STUB_FAKE), with a 64-byte receive buffer (a transaction's echo and reply then cross the
# half, complete and wrap points) and the bytes handed to the bus watched (test_rx_sink); the
# target tests use the same. Four builds, one per model of the silicon: the F4 (SR/DR USART,
# DMA streams), the G4 (ISR/ICR, channels, DMAMUX), the H7 (ISR/ICR, streams, DMAMUX, a
# Cortex-M7 with J288_STM32_DCACHE=1), and the H7 again as a Cortex-M7 r0p1 with
# J288_STM32_DCACHE=0 (the cache-on refusal, erratum 837070).
STM32_TEST_DEFS := -DJ288_STUB_FAKE -DJ288_STM32_RX_BUF_SIZE=64u -DJ288_STM32_BOUNCE_SIZE=32u -DJ288_STM32_MAX_BUSES=2u \
    -DJ288_STM32_RX_SINK=test_rx_sink
STM32_TEST_SRC := port/stm32_hal/j288_stm32.c test/stm32/fake_hal.c test/stm32/test_stm32_port.c

# $(call STM32_HOST_TEST,name,objdir,defs): test_stm32_port built with the stub's defs.
define STM32_HOST_TEST
$$(OBJ)/$(2)/%.o: CPPFLAGS_OBJ = $$(TEST_CPPFLAGS) -Iport/stm32_hal -Itest/stm32/stub -Itest/stm32 \
    $$(STM32_TEST_DEFS) $(3)
$$(OBJ)/$(2)/%.o: %.c $$(UNITY)/unity.c
	$$(COMPILE)
$$(BUILD)/test/$(1): $$(STM32_TEST_SRC:%.c=$$(OBJ)/$(2)/%.o) $$(UNITY_OBJ) $$(LIB_A)
	$$(LINK)
endef
STM32_FAMILY_TESTS := $(BUILD)/test/test_stm32_port $(BUILD)/test/test_stm32_port_g4 \
    $(BUILD)/test/test_stm32_port_h7 $(BUILD)/test/test_stm32_port_m7r0p1
$(eval $(call STM32_HOST_TEST,test_stm32_port,stm32host,-DJ288_STUB_F4))
$(eval $(call STM32_HOST_TEST,test_stm32_port_g4,stm32host-g4,-DJ288_STUB_G4))
$(eval $(call STM32_HOST_TEST,test_stm32_port_h7,stm32host-h7,-DJ288_STUB_H7 -DJ288_STM32_DCACHE=1))
$(eval $(call STM32_HOST_TEST,test_stm32_port_m7r0p1,stm32host-m7r0p1,-DJ288_STUB_H7 -D__CM7_REV=0x0001U))
# The stub's constants against ST's headers, per family, where scripts/fetch-st.sh fetched them
# (a notice for each family that is not there: CI has no network).
TEST_SCRIPTS += test/stm32/stub_matches_st.sh

# ---- the lists -------------------------------------------------------------------------------
HOST_TESTS += $(CLI_TEST) $(foreach v,$(CODEC_CRC_VARIANTS),$(CODEC_CRC_TEST_NAMES:%=$(BUILD)/crc-$(v)/test/%)) \
    $(FUZZ_REPLAY_TESTS) $(LINUX_PORT_TEST) $(CONFIG_TEST) $(SIM_MODEL_TEST) $(JOINT_SIM_TEST) $(STM32_FAMILY_TESTS)
TEST_SCRIPTS += test/e2e/cli_offline.sh test/e2e/cli_bus.sh test/e2e/cli_bus_faults.sh tools/vectors/check-drift.sh \
    test/e2e/sim_cli.sh test/e2e/example_linux.sh test/abi/check-abi.sh
# The joint frame end to end against the simulator's truth (the tool, the config, the sim),
# in three scripts that run side by side (test/e2e/lib_joint.sh).
TEST_SCRIPTS += test/e2e/joint_seed.sh test/e2e/joint_range.sh test/e2e/joint_refuse.sh
# Soft limits for the tool's torque (issue 29): it stops at a limit, the frames without limits refused.
TEST_SCRIPTS += test/e2e/joint_limits.sh
# j288 top on a terminal (tmux: capture-pane, send-keys) and through a pipe; j288 jog's every
# key and its live plot against the CSV it logged.
TEST_SCRIPTS += test/e2e/cli_top.sh test/e2e/cli_jog.sh
# What a new user tripped on: options before the command, one range per quantity named by
# its source, $J288_BAUD for config buses, stop naming its bus, duplicate ids, the man page.
TEST_SCRIPTS += test/e2e/cli_usability.sh
# How move, hold and torque leave the servo after exit (move holds, --then lock releases),
# against the simulator's truth under a load.
TEST_SCRIPTS += test/e2e/cli_move_hold.sh

# The scripts' own process helpers (whom they signal, what their cleanup removes).
TEST_SCRIPTS += test/e2e/lib_sim_check.sh
# The bash completion (tools/completion/j288.bash) against the tools' --help.
TEST_SCRIPTS += test/e2e/completion.sh
TEST_DEPS += $(J288_BIN) $(SIM_BIN) $(EXAMPLE_LINUX) $(LIB_A)

# make docs-check: every j288 and j288-sim command the docs show, run against the simulator
# (docs/architecture.md, "Commands in the docs"), and the READMEs' make demo output against
# make demo. A CI step of its own (once, about 20 s), not in `make test`, which CI runs five
# times over (compilers, sanitizers, valgrind) for what is a check of the docs.
.PHONY: docs-check
docs-check: $(J288_BIN) $(SIM_BIN)
	$(call RUN_TESTS,test/e2e/docs_run.sh)

.PHONY: check-abi vectors-check
check-abi: $(LIB_A)
	$(call RUN_TESTS,test/abi/check-abi.sh)
vectors-check:
	$(call RUN_TESTS,tools/vectors/check-drift.sh)
