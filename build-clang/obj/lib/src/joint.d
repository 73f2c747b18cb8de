build-clang/obj/lib/src/joint.o: lib/src/joint.c lib/include/j288/joint.h \
  lib/include/j288/config.h lib/include/j288/frame.h \
  lib/include/j288/crc32.h lib/include/j288/error.h \
  lib/include/j288/jointq.h lib/include/j288/sched.h \
  lib/include/j288/bus.h lib/include/j288/parser.h \
  lib/include/j288/port.h lib/include/j288/units.h lib/src/hints.h \
  lib/src/jointq_priv.h

lib/include/j288/joint.h:

lib/include/j288/config.h:

lib/include/j288/frame.h:

lib/include/j288/crc32.h:

lib/include/j288/error.h:

lib/include/j288/jointq.h:

lib/include/j288/sched.h:

lib/include/j288/bus.h:

lib/include/j288/parser.h:

lib/include/j288/port.h:

lib/include/j288/units.h:

lib/src/hints.h:

lib/src/jointq_priv.h:
