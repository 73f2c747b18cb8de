build-clang/obj/test/linux/test_robot.o: test/linux/test_robot.c \
  build-clang/unity/unity.h build-clang/unity/unity_internals.h \
  test/linux/alloc_count.h lib/include/j288/j288.h \
  lib/include/j288/config.h lib/include/j288/error.h \
  lib/include/j288/crc32.h lib/include/j288/frame.h \
  lib/include/j288/units.h lib/include/j288/parser.h \
  lib/include/j288/port.h lib/include/j288/bus.h \
  lib/include/j288/sched.h lib/include/j288/joint.h \
  lib/include/j288/jointq.h host/j288_robot.h port/desktop/j288_serial.h \
  port/linux/j288_linux.h host/j288_robot_config.h host/j288_rt.h \
  test/linux/sim_process.h

build-clang/unity/unity.h:

build-clang/unity/unity_internals.h:

test/linux/alloc_count.h:

lib/include/j288/j288.h:

lib/include/j288/config.h:

lib/include/j288/error.h:

lib/include/j288/crc32.h:

lib/include/j288/frame.h:

lib/include/j288/units.h:

lib/include/j288/parser.h:

lib/include/j288/port.h:

lib/include/j288/bus.h:

lib/include/j288/sched.h:

lib/include/j288/joint.h:

lib/include/j288/jointq.h:

host/j288_robot.h:

port/desktop/j288_serial.h:

port/linux/j288_linux.h:

host/j288_robot_config.h:

host/j288_rt.h:

test/linux/sim_process.h:
