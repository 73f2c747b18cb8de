build-clang/obj/tools/j288/json.o: tools/j288/json.c tools/j288/json.h

tools/j288/json.h:
