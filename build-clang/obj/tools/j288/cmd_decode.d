build-clang/obj/tools/j288/cmd_decode.o: tools/j288/cmd_decode.c \
  tools/j288/args.h host/j288_range.h lib/include/j288/config.h \
  tools/j288/cli.h lib/include/j288/j288.h lib/include/j288/error.h \
  lib/include/j288/crc32.h lib/include/j288/frame.h \
  lib/include/j288/units.h lib/include/j288/parser.h \
  lib/include/j288/port.h lib/include/j288/bus.h \
  lib/include/j288/sched.h lib/include/j288/joint.h \
  lib/include/j288/jointq.h tools/j288/frameview.h tools/j288/json.h \
  tools/j288/hexparse.h

tools/j288/args.h:

host/j288_range.h:

lib/include/j288/config.h:

tools/j288/cli.h:

lib/include/j288/j288.h:

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

tools/j288/frameview.h:

tools/j288/json.h:

tools/j288/hexparse.h:
