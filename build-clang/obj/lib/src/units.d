build-clang/obj/lib/src/units.o: lib/src/units.c lib/include/j288/units.h \
  lib/include/j288/config.h lib/include/j288/frame.h \
  lib/include/j288/crc32.h lib/include/j288/error.h lib/src/hints.h

lib/include/j288/units.h:

lib/include/j288/config.h:

lib/include/j288/frame.h:

lib/include/j288/crc32.h:

lib/include/j288/error.h:

lib/src/hints.h:
