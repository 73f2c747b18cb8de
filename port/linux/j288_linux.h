/*
 * j288_linux.h - the Linux side of the desktop serial port (j288_serial.h, which includes
 * this: include that). A serial device (USB-to-single-wire adapter, or the simulator's
 * pseudo-terminal) under the core of port/desktop; this file opens, sets the line, reads,
 * writes and waits.
 *
 * - Opens the device in raw mode, 8N1, non-blocking, at any baud through termios2 (BOTHER),
 *   and reads the rate back (the core refuses a rate more than 3 % off).
 * - Exclusive access: an advisory flock() on the device plus TIOCEXCL, so a second program
 *   gets "in use by PID n" (the PID is looked up in /proc/locks) and never interleaves frames.
 * - Low latency, best effort: tries ASYNC_LOW_LATENCY and reads the USB-serial latency timer
 *   in sysfs; what it cannot set becomes a one-line notice (j288_serial_notices()), never an
 *   error. Pseudo-terminals and some CH343-class adapters refuse ASYNC_LOW_LATENCY (ENOTTY).
 * - ppoll() and CLOCK_MONOTONIC; partial reads and writes and EINTR are handled (counted in
 *   j288_serial_stats()); POLLHUP / EIO / end of file mean the device vanished.
 */
#ifndef J288_LINUX_H
#define J288_LINUX_H

#include <stdbool.h>

/* The Linux part of a j288_serial_t. Private. */
typedef struct {
    int fd;           /* -1 when closed */
    bool low_latency; /* ASYNC_LOW_LATENCY accepted */
} j288_serial_os_t;

#endif /* J288_LINUX_H */
