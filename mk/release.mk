# The release artefacts beside the static library:
#   $(SO_LIB)      build/lib/libj288.so: lib/ + the Linux port + the robot config reader and the
#                  multi-bus runner, position-independent, linked with libyaml (what the Python
#                  package loads; C programs may link it too)
#   make shared    that
# The one version: J288_VERSION_STRING in lib/include/j288/j288.h ($(J288_VERSION)).
.PHONY: shared

J288_VERSION := $(shell sed -n 's/.*J288_VERSION_STRING "\(.*\)"/\1/p' lib/include/j288/j288.h)
J288_VERSION_MAJOR := $(word 1,$(subst ., ,$(J288_VERSION)))
SO_NAME := libj288.so.$(J288_VERSION_MAJOR)
SO_LIB := $(BUILD)/lib/libj288.so
SO_REAL := $(BUILD)/lib/libj288.so.$(J288_VERSION)
SO_SRC := $(LIB_SRC) port/desktop/j288_serial.c port/linux/j288_linux.c host/j288_robot.c \
    host/j288_rt.c host/j288_rt_linux.c host/j288_robot_config.c host/j288_number.c
SO_OBJ := $(SO_SRC:%.c=$(OBJ)/pic/%.o)

$(OBJ)/pic/%.o: CPPFLAGS_OBJ = -fPIC $(HOST_CPPFLAGS)
$(OBJ)/pic/%.o: %.c $(YAML_ENV)
	$(COMPILE)

$(SO_REAL): LDFLAGS_COMMON += -shared -Wl,-soname,$(SO_NAME)
$(SO_REAL): $(SO_OBJ) $(YAML_ENV)
	$(LINK)

$(SO_LIB): $(SO_REAL)
	ln -sf $(notdir $(SO_REAL)) $(BUILD)/lib/$(SO_NAME)
	ln -sf $(SO_NAME) $@

shared: $(SO_LIB)
ALL_TARGETS += $(SO_LIB)

# The Debian packages (debian/, scripts/deb.sh): make deb builds them into $(BUILD)/deb and runs
# lintian; make deb-check also installs them with apt, checks them and purges them.
.PHONY: deb deb-check
deb:
	BUILD=$(BUILD) bash scripts/deb.sh build
deb-check:
	BUILD=$(BUILD) bash scripts/deb.sh check
