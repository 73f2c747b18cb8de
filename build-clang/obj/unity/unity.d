build-clang/obj/unity/unity.o: build-clang/unity/unity.c \
  build-clang/unity/unity.h build-clang/unity/unity_internals.h

build-clang/unity/unity.h:

build-clang/unity/unity_internals.h:
