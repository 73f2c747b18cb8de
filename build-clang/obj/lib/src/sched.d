build-clang/obj/lib/src/sched.o: lib/src/sched.c lib/include/j288/sched.h \
  lib/include/j288/bus.h lib/include/j288/config.h \
  lib/include/j288/crc32.h lib/include/j288/error.h \
  lib/include/j288/frame.h lib/include/j288/parser.h \
  lib/include/j288/port.h lib/include/j288/units.h lib/src/bus_priv.h \
  lib/src/hints.h lib/src/frame_priv.h lib/src/crc32_priv.h \
  lib/src/bytes.h

lib/include/j288/sched.h:

lib/include/j288/bus.h:

lib/include/j288/config.h:

lib/include/j288/crc32.h:

lib/include/j288/error.h:

lib/include/j288/frame.h:

lib/include/j288/parser.h:

lib/include/j288/port.h:

lib/include/j288/units.h:

lib/src/bus_priv.h:

lib/src/hints.h:

lib/src/frame_priv.h:

lib/src/crc32_priv.h:

lib/src/bytes.h:
