build-clang/obj/lib/src/crc32.o: lib/src/crc32.c lib/include/j288/crc32.h \
  lib/include/j288/config.h lib/src/crc32_priv.h lib/src/bytes.h \
  lib/src/hints.h lib/include/j288/frame.h lib/include/j288/error.h

lib/include/j288/crc32.h:

lib/include/j288/config.h:

lib/src/crc32_priv.h:

lib/src/bytes.h:

lib/src/hints.h:

lib/include/j288/frame.h:

lib/include/j288/error.h:
