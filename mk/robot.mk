# The multi-bus runner (host/j288_robot.c) and its tests.
#   $(ROBOT_OBJ)       the runner; link with $(CONFIG_OBJ), $(LINUX_A), $(LIB_A) and the yaml libs
#   test/linux/test_robot.c   several j288-sim buses from one loop (HOST_TESTS)
#   test/e2e/cli_robot.sh     j288 --config FILE log|status|hold|stop (TEST_SCRIPTS)
#   test/e2e/host_stack.sh    a second session after a stop, every front end (TEST_SCRIPTS)
#   test/e2e/cli_robust.sh    a lost bus, reconnection and signals through the tool (TEST_SCRIPTS)
# (the runner, its wait over every bus the port's, j288_serial_wait_any(); the loop's real
# time and timing: host/j288_rt.c, its OS part host/j288_rt_linux.c)
ROBOT_OBJ := $(OBJ)/host/j288_robot.o $(OBJ)/host/j288_rt.o $(OBJ)/host/j288_rt_linux.o

ROBOT_TEST := $(BUILD)/test/test_robot
# (alloc_count.o: malloc and its family replaced by counting ones, for the cycle's promise of none)
$(ROBOT_TEST): $(OBJ)/test/linux/test_robot.o $(OBJ)/test/linux/alloc_count.o $(SIM_PROCESS_OBJ) $(ROBOT_OBJ) $(CONFIG_OBJ) $(UNITY_OBJ) $(LINUX_A) $(LIB_A) \
    $(YAML_ENV)
	$(LINK)

HOST_TESTS += $(ROBOT_TEST)

# The real-time module alone: histograms, the pacing rule, the set-up through its seam.
RT_TEST := $(BUILD)/test/test_rt
$(RT_TEST): $(OBJ)/test/linux/test_rt.o $(OBJ)/host/j288_rt.o $(OBJ)/host/j288_rt_linux.o \
    $(UNITY_OBJ) $(LIB_A)
	$(LINK)
HOST_TESTS += $(RT_TEST)
TEST_DEPS += $(SIM_BIN)

# The j288 tool's bus commands use the runner (cli_bus.h includes it) and the config reader.
$(J288_BIN): $(ROBOT_OBJ) $(CONFIG_OBJ)
# (the archives again after them: the tool's link rule lists its own prerequisites first)
$(J288_BIN): LDFLAGS_COMMON += $(LINUX_A) $(LIB_A) $(call yaml_var,YAML_LIBS)
TEST_SCRIPTS += test/e2e/cli_robot.sh
# --realtime, --cpu and the loop's timing in the tool's reports (test/e2e/cli_realtime.sh)
TEST_SCRIPTS += test/e2e/cli_realtime.sh
TEST_DEPS += $(J288_BIN)
# One host stack: a second session after every form of stop holds a loaded joint (the CLI's
# forms and Python's; the Python ones use the shared library, which python.mk adds).
TEST_SCRIPTS += test/e2e/host_stack.sh
# Issue 29 through the tool: a lost bus is exit 1, a restarted simulator's joints held again,
# SIGHUP and SIGQUIT lock (robot forms, a one-servo loop, top).
TEST_SCRIPTS += test/e2e/cli_robust.sh
