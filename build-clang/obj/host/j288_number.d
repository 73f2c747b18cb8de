build-clang/obj/host/j288_number.o: host/j288_number.c host/j288_number.h

host/j288_number.h:
