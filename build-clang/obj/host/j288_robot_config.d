build-clang/obj/host/j288_robot_config.o: host/j288_robot_config.c \
  host/j288_robot_config.h lib/include/j288/joint.h \
  lib/include/j288/config.h lib/include/j288/frame.h \
  lib/include/j288/crc32.h lib/include/j288/error.h \
  lib/include/j288/jointq.h lib/include/j288/sched.h \
  lib/include/j288/bus.h lib/include/j288/parser.h \
  lib/include/j288/port.h lib/include/j288/units.h host/j288_number.h \
  host/j288_range.h

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

host/j288_number.h:

host/j288_range.h:
