build-clang/obj/test/linux/sim_process.o: test/linux/sim_process.c \
  test/linux/sim_process.h build-clang/unity/unity.h \
  build-clang/unity/unity_internals.h

test/linux/sim_process.h:

build-clang/unity/unity.h:

build-clang/unity/unity_internals.h:
