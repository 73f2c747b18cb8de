build-clang/obj/tools/j288/hexparse.o: tools/j288/hexparse.c \
  tools/j288/hexparse.h

tools/j288/hexparse.h:
