/* j288_rt_os.h - private to the real-time module: the half of j288_rt_setup_with() each OS
 * file implements (host/j288_rt_linux.c, host/j288_rt_win32.c). j288_rt.c has checked the
 * arguments (o and st not NULL, the priority 0-99) and cleared st (cpu -1) before calling it.
 * The same contract as j288_rt_setup_with() otherwise. */
#ifndef J288_RT_OS_H
#define J288_RT_OS_H

#include "j288_rt.h"

int j288_rt_os_setup(const j288_rt_options_t *o, const j288_rt_sys_t *sys, j288_rt_status_t *st);

#endif
