build-clang/obj/lib/src/bus.o: lib/src/bus.c lib/include/j288/bus.h \
  lib/include/j288/config.h lib/include/j288/crc32.h \
  lib/include/j288/error.h lib/include/j288/frame.h \
  lib/include/j288/parser.h lib/include/j288/port.h lib/src/bus_priv.h \
  lib/src/hints.h lib/src/frame_priv.h lib/src/crc32_priv.h \
  lib/src/bytes.h lib/src/parser_priv.h

lib/include/j288/bus.h:

lib/include/j288/config.h:

lib/include/j288/crc32.h:

lib/include/j288/error.h:

lib/include/j288/frame.h:

lib/include/j288/parser.h:

lib/include/j288/port.h:

lib/src/bus_priv.h:

lib/src/hints.h:

lib/src/frame_priv.h:

lib/src/crc32_priv.h:

lib/src/bytes.h:

lib/src/parser_priv.h:
