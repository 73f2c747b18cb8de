# The release artefacts beside the static library:
#   $(SO_LIB)      build/lib/libj288.so: lib/ + the Linux port + the robot config reader and the
#                  multi-bus runner, position-independent, linked with libyaml (what the Python
#                  package loads; C programs may link it too)
#   make shared    that
# The one version: J288_VERSION_STRING in lib/include/j288/j288.h (Makefile's J288_VERSION).
.PHONY: shared

# (read here as well: the Makefile's own definition comes after the fragments)
J288_VERSION := $(shell sed -n 's/.*J288_VERSION_STRING "\(.*\)"/\1/p' lib/include/j288/j288.h)
J288_VERSION_MAJOR := $(word 1,$(subst ., ,$(J288_VERSION)))
SO_NAME := libj288.so.$(J288_VERSION_MAJOR)
SO_LIB := $(BUILD)/lib/libj288.so
SO_REAL := $(BUILD)/lib/libj288.so.$(J288_VERSION)
SO_SRC := $(LIB_SRC) port/linux/j288_linux.c host/j288_robot.c host/j288_robot_config.c
SO_OBJ := $(SO_SRC:%.c=$(OBJ)/pic/%.o)

$(OBJ)/pic/%.o: %.c $(YAML_ENV)
	@mkdir -p $(@D)
	$(CC) -fPIC $(HOST_CPPFLAGS) $(call yaml_var,YAML_CFLAGS) $(CFLAGS_COMMON) -c $< -o $@

$(SO_REAL): $(SO_OBJ) $(YAML_ENV)
	@mkdir -p $(@D)
	$(CC) -shared -Wl,-soname,$(SO_NAME) $(CFLAGS_COMMON) $(SO_OBJ) -o $@ $(LDFLAGS_COMMON) \
	    $(call yaml_var,YAML_LIBS) -lm

$(SO_LIB): $(SO_REAL)
	ln -sf $(notdir $(SO_REAL)) $(BUILD)/lib/$(SO_NAME)
	ln -sf $(SO_NAME) $@

# j288.pc for `make install`: cmake/j288.pc.in with its prefix relative to ${pcfiledir}, so
# that it holds wherever the files land (PREFIX, DESTDIR) or are moved; `cmake --install`
# writes the same. $(call PC_GEN,libdir,includedir,out): both relative to PREFIX.
PC_UP = $(shell printf '%s' '$(1)/pkgconfig' | sed 's|[^/][^/]*|..|g')
PC_GEN = sed -e 's|@PREFIX@|$${pcfiledir}/$(call PC_UP,$(1))|g' -e 's|@LIBDIR@|$${prefix}/$(1)|g' \
    -e 's|@INCLUDEDIR@|$${prefix}/$(2)|g' -e 's|@J288_VERSION@|$(J288_VERSION)|g' cmake/j288.pc.in >$(3)

shared: $(SO_LIB)
ALL_TARGETS += $(SO_LIB)

# What `make install` adds to the static library, headers, CMake package and tools (the
# Makefile's install rule): the shared library and its links, the Linux port's and the
# runner's headers, pkg-config file, the Python package (with _installed.py: where its
# prefix's shared library is, relative to the package).
PYTHONDIR ?= $(PREFIX)/lib/python3/dist-packages
PORT_HDR := port/linux/j288_linux.h host/j288_robot.h host/j288_robot_config.h
.PHONY: install-release
install-release: $(SO_LIB)
	install -d $(DESTDIR)$(LIBDIR)/pkgconfig $(DESTDIR)$(INCLUDEDIR)/j288 $(DESTDIR)$(PYTHONDIR)/j288
	install -m 755 $(SO_REAL) $(DESTDIR)$(LIBDIR)/
	ln -sf $(notdir $(SO_REAL)) $(DESTDIR)$(LIBDIR)/$(SO_NAME)
	ln -sf $(SO_NAME) $(DESTDIR)$(LIBDIR)/libj288.so
	install -m 644 $(PORT_HDR) $(DESTDIR)$(INCLUDEDIR)/j288/
	$(call PC_GEN,$(patsubst $(PREFIX)/%,%,$(LIBDIR)),$(patsubst $(PREFIX)/%,%,$(INCLUDEDIR)),$(DESTDIR)$(LIBDIR)/pkgconfig/j288.pc)
	install -m 644 python/j288/*.py python/j288/py.typed $(DESTDIR)$(PYTHONDIR)/j288/
	printf '# Written by make install: the shared library, relative to this package.\nLIBRARY = "%s"\n' \
	    "$$(realpath -m -s --relative-to=$(PYTHONDIR)/j288 $(LIBDIR)/$(SO_NAME))" \
	    >$(DESTDIR)$(PYTHONDIR)/j288/_installed.py
install: install-release
