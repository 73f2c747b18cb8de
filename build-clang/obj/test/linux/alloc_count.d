build-clang/obj/test/linux/alloc_count.o: test/linux/alloc_count.c \
  test/linux/alloc_count.h

test/linux/alloc_count.h:
