build-clang/obj/lib/src/frame.o: lib/src/frame.c lib/include/j288/frame.h \
  lib/include/j288/crc32.h lib/include/j288/config.h \
  lib/include/j288/error.h lib/src/frame_priv.h lib/src/crc32_priv.h \
  lib/src/bytes.h lib/src/hints.h

lib/include/j288/frame.h:

lib/include/j288/crc32.h:

lib/include/j288/config.h:

lib/include/j288/error.h:

lib/src/frame_priv.h:

lib/src/crc32_priv.h:

lib/src/bytes.h:

lib/src/hints.h:
