/*
 * j288_host_port.h - the serial port under the host layer (the runner, the tools): the Linux
 * port (port/linux, termios2) on Linux, the Windows port (port/windows, Win32 serial) on
 * Windows. The host code is written against the Linux port's names; on Windows these names
 * stand for the Windows port's functions and types, which take the same arguments and keep the
 * same contracts (j288_windows.h follows j288_linux.h name for name). Include this, not
 * j288_linux.h, in code that builds for both.
 */
#ifndef J288_HOST_PORT_H
#define J288_HOST_PORT_H

#ifdef _WIN32
#include "j288_windows.h"

typedef j288_windows_t j288_linux_t;
typedef j288_windows_options_t j288_linux_options_t;
typedef j288_windows_stats_t j288_linux_stats_t;
#define J288_LINUX_DEFAULT_MARGIN_US J288_WINDOWS_DEFAULT_MARGIN_US
#define J288_LINUX_DEFAULT_IDLE_US   J288_WINDOWS_DEFAULT_IDLE_US
#define J288_LINUX_RUN_UNTIL_IDLE    J288_WINDOWS_RUN_UNTIL_IDLE
#define J288_LINUX_RUN_IGNORE_STOP   J288_WINDOWS_RUN_IGNORE_STOP
#define j288_linux_port              j288_windows_port
#define j288_linux_open              j288_windows_open
#define j288_linux_close             j288_windows_close
#define j288_linux_bus_config        j288_windows_bus_config
#define j288_linux_bus_init          j288_windows_bus_init
#define j288_linux_now_us            j288_windows_now_us
#define j288_linux_set_stop_flag     j288_windows_set_stop_flag
#define j288_linux_run               j288_windows_run
#define j288_linux_sweep             j288_windows_sweep
#define j288_linux_service           j288_windows_service
#define j288_linux_next_deadline     j288_windows_next_deadline
#define j288_linux_error             j288_windows_error
#define j288_linux_notices           j288_windows_notices
#define j288_linux_baud_ok           j288_windows_baud_ok
#define j288_linux_baud              j288_windows_baud
#define j288_linux_offline           j288_windows_offline
#define j288_linux_stats             j288_windows_stats
#else
#include "j288_linux.h"
#endif

#endif /* J288_HOST_PORT_H */
