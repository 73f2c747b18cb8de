build-clang/obj/host/j288_rt_linux.o: host/j288_rt_linux.c host/j288_rt.h \
  lib/include/j288/error.h host/j288_rt_os.h

host/j288_rt.h:

lib/include/j288/error.h:

host/j288_rt_os.h:
