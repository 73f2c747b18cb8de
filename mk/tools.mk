# The Linux port and the programs built on it:
#   $(LINUX_A)     libj288_linux.a, the desktop serial port on Linux (port/desktop's core over
#                  port/linux, termios2): -Iport/desktop -Iport/linux, link it before $(LIB_A)
#   $(CONFIG_OBJ)  the robot config reader (port/linux, libyaml)
#   $(J288_BIN)    tools/j288: offline frame calculator and bus commands over the Linux port
#   $(SIM_BIN)     tools/j288-sim: simulated servos on a pseudo-terminal
#   $(BIN)/linux-status   examples/linux: the library's smallest Linux program
#   make demo      the README's first command: j288 against j288-sim (scripts/demo.sh)
#   make vectors   regenerate the golden vectors from tools/vectors/gen_vectors.py
.PHONY: linux cli sim demo vectors

LINUX_CPPFLAGS := $(CPPFLAGS_LIB) -Iport/desktop -Iport/linux
HOST_CPPFLAGS := $(LINUX_CPPFLAGS) -Ihost
$(OBJ)/port/linux/%.o $(OBJ)/port/desktop/%.o: CPPFLAGS_OBJ = $(LINUX_CPPFLAGS)
$(OBJ)/host/%.o: CPPFLAGS_OBJ = $(HOST_CPPFLAGS)

$(LINUX_A): $(OBJ)/port/desktop/j288_serial.o $(OBJ)/port/linux/j288_linux.o
	@mkdir -p $(@D)
	rm -f $@
	$(AR) rcs $@ $^

# The tools are POSIX programs (signals, realpath, popen for gnuplot); lib/ stays pure C99.
TOOL_CPPFLAGS := $(HOST_CPPFLAGS) -D_XOPEN_SOURCE=700
J288_SRC := $(sort $(wildcard tools/j288/*.c))
$(OBJ)/tools/j288/%.o: CPPFLAGS_OBJ = $(TOOL_CPPFLAGS)

$(J288_BIN): $(J288_SRC:%.c=$(OBJ)/%.o) $(CONFIG_OBJ) $(LINUX_A) $(LIB_A) $(YAML_ENV)
	$(LINK)

# The simulator: servo_model.c (servos and bus, no I/O) and sim_main.c (the pty front end).
SIM_MODEL_OBJ := $(OBJ)/tools/j288-sim/servo_model.o
$(OBJ)/tools/j288-sim/%.o: CPPFLAGS_OBJ = $(CPPFLAGS_LIB) -Itools/j288-sim

$(SIM_BIN): $(SIM_MODEL_OBJ) $(OBJ)/tools/j288-sim/sim_main.o $(LIB_A)
	$(LINK)

# The robot config reader (host/j288_robot_config.c, not in the archive: it needs
# libyaml). pkg-config's yaml-0.1 (Debian's libyaml-dev), checked to link with $(CC), gives the
# flags written into $(YAML_ENV); without it the reader builds as stubs that say so. Users:
# $(CONFIG_OBJ) (the reader and the number syntax it shares with the tool's options,
# $(NUMBER_OBJ)), and $(call yaml_var,YAML_LIBS) in a recipe. Delete the file to look again.
YAML_ENV := $(BUILD)/libyaml/libyaml.env
yaml_var = $$(sed -n 's/^$(1)=//p' $(YAML_ENV))
NUMBER_OBJ := $(OBJ)/host/j288_number.o
CONFIG_OBJ := $(OBJ)/host/j288_robot_config.o $(NUMBER_OBJ)

$(YAML_ENV):
	@mkdir -p $(@D)
	@if c=$$(pkg-config --cflags yaml-0.1 2>/dev/null) && l=$$(pkg-config --libs yaml-0.1) && \
	    printf '#include <yaml.h>\nint main(void) { yaml_parser_t p; return !yaml_parser_initialize(&p); }\n' | \
	    $(CC) $(EXTRA_CFLAGS) $$c -x c - -x none $(EXTRA_LDFLAGS) $$l -o $(@D)/probe 2>/dev/null; then \
	    printf 'YAML_CFLAGS=-DJ288_HAVE_LIBYAML %s\nYAML_LIBS=%s\n' "$$c" "$$l" >$@; \
	else printf 'YAML_CFLAGS=\nYAML_LIBS=\n' >$@; \
	    echo "libyaml: not found: building without robot config support (install libyaml-dev)"; fi

$(OBJ)/host/j288_robot_config.o: $(YAML_ENV)

EXAMPLE_LINUX := $(BIN)/linux-status
$(OBJ)/examples/linux/%.o: CPPFLAGS_OBJ = $(TOOL_CPPFLAGS)

$(EXAMPLE_LINUX): $(OBJ)/examples/linux/main.o $(LINUX_A) $(LIB_A)
	$(LINK)

linux: $(LINUX_A)
cli: $(J288_BIN)
sim: $(SIM_BIN)
ALL_TARGETS += $(LINUX_A) $(J288_BIN) $(SIM_BIN) $(EXAMPLE_LINUX)

# Builds only what it runs (no Unity, no download: a compiler and make suffice).
demo: $(J288_BIN) $(SIM_BIN)
	BUILD=$(BUILD) BIN=$(BIN) bash scripts/demo.sh

# Commit the result together with the generator change; `make test` checks they agree.
vectors:
	$(PYTHON) tools/vectors/gen_vectors.py --out test/vectors
