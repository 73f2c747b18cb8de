# mk/sim.mk - the servo simulator $(BIN)/j288-sim and the unit test of its model.
#   tools/sim/servo_model.c  servos and bus, no I/O (unit-tested by test/sim/test_sim_model.c)
#   tools/sim/sim_main.c     the pseudo-terminal front end

SIM_MODEL_OBJ := $(OBJ)/tools/sim/servo_model.o
SIM_OBJ := $(SIM_MODEL_OBJ) $(OBJ)/tools/sim/sim_main.o
SIM_BIN := $(BIN)/j288-sim
SIM_MODEL_TEST := $(BUILD)/test/test_sim_model

$(OBJ)/tools/sim/%.o: tools/sim/%.c tools/sim/servo_model.h $(LIB_HDR)
	@mkdir -p $(@D)
	$(CC) $(CPPFLAGS_LIB) -Itools/sim $(CFLAGS_COMMON) -c $< -o $@

$(SIM_BIN): $(SIM_OBJ) $(LIB_A)
	@mkdir -p $(@D)
	$(CC) $(CFLAGS_COMMON) $^ -o $@ $(LDFLAGS_COMMON) -lm

$(OBJ)/test/sim/%.o: test/sim/%.c tools/sim/servo_model.h $(LIB_HDR) $(UNITY)/unity.c
	@mkdir -p $(@D)
	$(CC) $(TEST_CPPFLAGS) -Itools/sim $(CFLAGS_COMMON) -c $< -o $@

$(SIM_MODEL_TEST): $(OBJ)/test/sim/test_sim_model.o $(SIM_MODEL_OBJ) $(UNITY_OBJ) $(LIB_A)
	@mkdir -p $(@D)
	$(CC) $(CFLAGS_COMMON) $^ -o $@ $(LDFLAGS_COMMON) -lm

.PHONY: sim
sim: $(SIM_BIN)

ALL_TARGETS += $(SIM_BIN)
TEST_DEPS += $(SIM_BIN)
ifneq ($(wildcard test/sim/test_sim_model.c),)
ALL_TARGETS += $(SIM_MODEL_TEST)
HOST_TESTS += $(SIM_MODEL_TEST)
endif
TEST_SCRIPTS += test/e2e/sim_cli.sh
