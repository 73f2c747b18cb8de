/*
 * j288_serial_os.h - the OS interface under the desktop serial core (not installed, not API):
 * what an OS file (port/linux/j288_linux.c, port/windows/j288_windows.c) provides to the core
 * (port/desktop/j288_serial.c), and what the core provides to it. As tinyusb's osal.h and
 * DynamixelSDK's PortHandler split it: the OS file opens, sets the line, reads, writes and
 * waits; the core owns everything the bus sees (deadlines, idle, the stale-byte flush, the
 * vanished device, the bus set-up and the accessors), once for every OS.
 *
 * An OS file also defines the public j288_serial_now_us(), j288_serial_wait_any() and
 * j288_serial_same_device() (j288_serial.h), and the type j288_serial_os_t in its header.
 * Every call below is thread only, on an sp the caller owns.
 */
#ifndef J288_SERIAL_OS_H
#define J288_SERIAL_OS_H

#include "j288_serial.h"

/* ---- provided by the OS file */

/* Mark sp->os closed in an object whose bytes are all zero (Linux: fd -1). */
void j288_serial_os_reset(j288_serial_t *sp);

/* Whether the device is open (gone or not). */
bool j288_serial_os_is_open(const j288_serial_t *sp);

/* Open dev exclusively for reading and writing, without waiting on any call. sp->dev holds
 * the name (perhaps truncated: use dev for the OS call), sp->opt the options. Returns J288_OK,
 * or J288_ERR_OFFLINE / _BUSY / _BAD_CONFIG / _PORT with sp->err set and nothing left open. */
int j288_serial_os_open(j288_serial_t *sp, const char *dev);

/* Raw 8N1 at baud, no flow control; *got: the rate the driver reads back. J288_OK, or
 * J288_ERR_BAD_CONFIG (not a serial device, the rate refused) / J288_ERR_PORT with sp->err
 * set. The core checks *got (j288_serial_baud_ok()) and closes on any failure. */
int j288_serial_os_set_line(j288_serial_t *sp, uint32_t baud, uint32_t *got);

/* After a good open and line setting: best-effort tuning (Linux: low latency unless
 * opt.no_low_latency, with a notice for what it cannot do) and the input queued before we
 * came dropped. */
void j288_serial_os_ready(j288_serial_t *sp);

/* Release everything j288_serial_os_open() took; harmless when closed. */
void j288_serial_os_close(j288_serial_t *sp);

/* Wait up to timeout_us (0: only look) for input. 1: there may be input (or a hang-up that
 * the read will find); 0: none, or a signal came; -1: the device is gone (reported with
 * j288_serial_gone()). */
int j288_serial_os_wait_input(j288_serial_t *sp, uint32_t timeout_us);

/* Take what has arrived into buf (at most cap bytes), without waiting. Returns the count
 * (0: nothing yet), or -1 when the device is gone (reported). A read error that does not mean
 * "gone" sets sp->err and returns what it has. */
int j288_serial_os_read(j288_serial_t *sp, uint8_t *buf, size_t cap);

/* Write all len bytes (bounded: a stuck adapter is an error, not a hang). J288_OK once the
 * OS has them, J288_ERR_OFFLINE when the device is gone (reported), J288_ERR_PORT with
 * sp->err set otherwise. */
int j288_serial_os_write(j288_serial_t *sp, const uint8_t *data, size_t len);

/* ---- provided by the core */

/* sp->err, printf-style. */
void j288_serial_set_err(j288_serial_t *sp, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

/* One line (without its '\n') appended to sp->notice, printf-style; dropped when full. */
void j288_serial_add_notice(j288_serial_t *sp, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

/* The device vanished: said once, in sp->err ("DEV vanished (what: why): ...", why may be
 * NULL) and to the bus (J288_LINE_GONE); later calls fail at once with J288_ERR_OFFLINE. */
void j288_serial_gone(j288_serial_t *sp, const char *what, const char *why);

/* Copy in to out (cap > 0), truncated, always terminated. */
void j288_serial_copy_str(char *out, size_t cap, const char *in);

#endif /* J288_SERIAL_OS_H */
