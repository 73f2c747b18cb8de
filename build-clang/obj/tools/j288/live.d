build-clang/obj/tools/j288/live.o: tools/j288/live.c tools/j288/live.h \
  host/j288_robot_config.h lib/include/j288/joint.h \
  lib/include/j288/config.h lib/include/j288/frame.h \
  lib/include/j288/crc32.h lib/include/j288/error.h \
  lib/include/j288/jointq.h lib/include/j288/sched.h \
  lib/include/j288/bus.h lib/include/j288/parser.h \
  lib/include/j288/port.h lib/include/j288/units.h tools/j288/tplot.h \
  lib/include/j288/j288.h

tools/j288/live.h:

host/j288_robot_config.h:

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

tools/j288/tplot.h:

lib/include/j288/j288.h:
