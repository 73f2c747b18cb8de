build-clang/obj/tools/j288/tplot.o: tools/j288/tplot.c tools/j288/tplot.h

tools/j288/tplot.h:
