build-clang/obj/port/desktop/j288_serial.o: port/desktop/j288_serial.c \
  port/desktop/j288_serial_os.h port/desktop/j288_serial.h \
  lib/include/j288/bus.h lib/include/j288/config.h \
  lib/include/j288/crc32.h lib/include/j288/error.h \
  lib/include/j288/frame.h lib/include/j288/parser.h \
  lib/include/j288/port.h port/linux/j288_linux.h

port/desktop/j288_serial_os.h:

port/desktop/j288_serial.h:

lib/include/j288/bus.h:

lib/include/j288/config.h:

lib/include/j288/crc32.h:

lib/include/j288/error.h:

lib/include/j288/frame.h:

lib/include/j288/parser.h:

lib/include/j288/port.h:

port/linux/j288_linux.h:
