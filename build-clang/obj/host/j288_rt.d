build-clang/obj/host/j288_rt.o: host/j288_rt.c host/j288_rt.h \
  lib/include/j288/error.h host/j288_rt_os.h

host/j288_rt.h:

lib/include/j288/error.h:

host/j288_rt_os.h:
