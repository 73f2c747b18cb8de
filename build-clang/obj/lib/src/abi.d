build-clang/obj/lib/src/abi.o: lib/src/abi.c lib/include/j288/bus.h \
  lib/include/j288/config.h lib/include/j288/crc32.h \
  lib/include/j288/error.h lib/include/j288/frame.h \
  lib/include/j288/parser.h lib/include/j288/port.h

lib/include/j288/bus.h:

lib/include/j288/config.h:

lib/include/j288/crc32.h:

lib/include/j288/error.h:

lib/include/j288/frame.h:

lib/include/j288/parser.h:

lib/include/j288/port.h:
