build-clang/obj/lib/src/strerror.o: lib/src/strerror.c \
  lib/include/j288/error.h

lib/include/j288/error.h:
