# The multi-bus runner (host/j288_robot.c) and its tests.
#   $(ROBOT_OBJ)       the runner; link with $(CONFIG_OBJ), $(LINUX_A), $(LIB_A) and the yaml libs
#   test/linux/test_robot.c   several j288-sim buses from one loop (HOST_TESTS)
#   test/e2e/cli_robot.sh     j288 --config FILE log|status|hold|stop (TEST_SCRIPTS)
ROBOT_OBJ := $(OBJ)/host/j288_robot.o

$(ROBOT_OBJ): host/j288_robot.c
	@mkdir -p $(@D)
	$(CC) $(HOST_CPPFLAGS) $(CFLAGS_COMMON) -c $< -o $@

ROBOT_TEST := $(BUILD)/test/test_robot
$(OBJ)/test/linux/test_robot.o: test/linux/test_robot.c $(UNITY)/unity.c
	@mkdir -p $(@D)
	$(CC) $(TEST_CPPFLAGS) -Iport/linux -Ihost -DJ288_SIM_DEFAULT='"$(SIM_BIN)"' $(CFLAGS_COMMON) -c $< -o $@

$(ROBOT_TEST): $(OBJ)/test/linux/test_robot.o $(SIM_PROCESS_OBJ) $(ROBOT_OBJ) $(CONFIG_OBJ) $(UNITY_OBJ) $(LINUX_A) $(LIB_A) \
    $(YAML_ENV)
	@mkdir -p $(@D)
	$(CC) $(CFLAGS_COMMON) $(filter-out $(YAML_ENV),$^) -o $@ $(LDFLAGS_COMMON) $(call yaml_var,YAML_LIBS) -lm

HOST_TESTS += $(ROBOT_TEST)
ALL_TARGETS += $(ROBOT_TEST)
TEST_DEPS += $(SIM_BIN)

# The j288 tool's robot commands (tools/j288/cmd_robot.c) use the runner and the config reader.
$(J288_BIN): $(ROBOT_OBJ) $(CONFIG_OBJ)
# (the archives again after them: the tool's link rule lists its own prerequisites first)
$(J288_BIN): LDFLAGS_COMMON += $(LINUX_A) $(LIB_A) $(call yaml_var,YAML_LIBS)
TEST_SCRIPTS += test/e2e/cli_robot.sh
TEST_DEPS += $(J288_BIN)
