/*
 * j288_serial.h - a j288 bus on a desktop computer's serial port: one API for Linux
 * (port/linux, termios2) and Windows (port/windows, Win32), one core (port/desktop/
 * j288_serial.c) over a small OS interface (j288_serial_os.h: open, line settings, read,
 * write, wait). A USB-to-single-wire adapter, or the simulator's pseudo-terminal.
 *
 * What it does (the OS's part is in j288_linux.h / j288_windows.h)
 * - Opens the device raw, 8N1, exclusive, at any baud (6,000,000 by default), and reads the
 *   rate back: an adapter or driver that cannot do it is a clear error, never a silent
 *   fallback. Input queued before the open is dropped.
 * - Feeds the bus: the bytes that come (j288_bus_on_rx), a line-idle report a quiet
 *   J288_SERIAL_DEFAULT_IDLE_US after them, the reply deadline the bus arms
 *   (j288_bus_on_timer), transmit done when the OS has taken the bytes. Bytes found waiting
 *   before a transmit are dropped (no reply precedes its command), and bytes already waiting
 *   go to the bus before a due deadline is judged (a host that wakes late does not time out
 *   a reply that came in time).
 * - A vanished device (unplugged adapter, simulator exited) is reported once to the bus as
 *   j288_bus_on_error(bus, J288_LINE_GONE), then every wait() and start_tx() fails at once
 *   with J288_ERR_OFFLINE (no busy loop), and j288_serial_error() says what happened.
 *
 * Typical use (single thread; a robot's loop over several buses is host/j288_robot.h):
 *
 *   j288_serial_t sp;
 *   j288_bus_t bus;
 *   if (j288_serial_open(&sp, "/dev/ttyUSB0", 0, NULL) != J288_OK) {   // or "COM5"
 *       fprintf(stderr, "j288: %s\n", j288_serial_error(&sp));
 *       return 1;
 *   }
 *   fputs(j288_serial_notices(&sp), stderr);          // optional, "" when nothing to say
 *   j288_serial_bus_init(&sp, &bus, NULL);            // recommended bus config
 *   int rc = j288_bus_transfer_blocking(&bus, &cmd, &txn);
 *   if (rc == J288_ERR_OFFLINE || j288_serial_offline(&sp))
 *       fprintf(stderr, "j288: %s\n", j288_serial_error(&sp));
 *   j288_serial_close(&sp);
 *
 * Threading: one thread owns a j288_serial_t and its bus; no lock is needed or provided
 * (j288_serial_now_us() and the pure functions: any thread). The object is caller-allocated,
 * holds no heap memory (only the OS's handles) and must not move while open (Windows: a read
 * in flight writes into it). Results are the library's codes (j288/error.h); the text is in
 * j288_serial_error().
 */
#ifndef J288_SERIAL_H
#define J288_SERIAL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "j288/bus.h"
#include "j288/port.h"

/* The OS's part of the object, j288_serial_os_t (private). */
#ifdef _WIN32
#include "j288_windows.h"
#else
#include "j288_linux.h"
#endif

#ifdef __cplusplus
extern "C" {
#endif

/* Host latency margin for the reply deadline over USB: an FTDI adapter with its default
 * 16 ms latency timer needs most of it; lower it (j288_serial_options_t.margin_us) on a
 * pseudo-terminal or an adapter with a 1 ms timer. */
#define J288_SERIAL_DEFAULT_MARGIN_US 20000u
/* Quiet time after received bytes before the port reports line idle to the bus. Longer than
 * a USB frame so that a reply split over two USB packets is not cut. */
#define J288_SERIAL_DEFAULT_IDLE_US 2000u
/* Largest accepted difference between the requested and the read-back baud rate, percent. */
#define J288_SERIAL_BAUD_TOLERANCE_PCT 3u
/* Room for the error text (and for each line of the notices). */
#define J288_SERIAL_MSG_LEN 320u
/* Most ports j288_serial_wait_any() waits on at once. */
#define J288_SERIAL_WAIT_MAX 16u

/* All-zero means defaults. */
typedef struct {
    uint32_t margin_us;  /* reply margin for j288_serial_bus_config(); 0: 20 ms */
    uint32_t idle_us;    /* line-idle report after bytes; 0: 2 ms */
    bool echo;           /* the adapter hears its own transmit (many single-wire ones do):
                            the bus then checks and skips our echoed command */
    bool no_low_latency; /* Linux: do not try ASYNC_LOW_LATENCY / the latency timer check.
                            Windows: nothing to switch (the FTDI latency timer is a driver
                            setting: j288_windows.h) */
} j288_serial_options_t;

/* Port counters (the bus keeps its own in j288_bus_stats()). */
typedef struct {
    uint32_t tx_bytes;
    uint32_t rx_bytes;
    uint32_t flushed_bytes;  /* bytes found waiting before a transmit: dropped, since no
                                reply can precede its command */
    uint32_t waits;          /* the port's wait() calls (blocking helpers, service) */
    uint32_t partial_writes; /* Linux: write() calls that took fewer bytes than offered */
    uint32_t eintr;          /* Linux: system calls interrupted by a signal and resumed */
    uint32_t reads;          /* Windows: overlapped reads issued */
    uint32_t empty_reads;    /* Windows: of which ended on their timeout (0 bytes, or
                                ERROR_TIMEOUT under Wine) */
} j288_serial_stats_t;

typedef struct j288_serial {
    /* Private: use the functions below. */
    j288_serial_os_t os;  /* the descriptor or handles (j288_linux.h, j288_windows.h) */
    j288_bus_t *bus;
    j288_serial_options_t opt;
    uint32_t baud;        /* requested */
    uint32_t baud_actual; /* read back from the driver */
    bool gone;            /* the device vanished */
    bool idle_pending;    /* bytes were delivered and no idle reported since */
    bool timer_armed;
    uint32_t last_rx_us;
    uint32_t timer_us;
    j288_serial_stats_t stats;
    char dev[128];
    char err[J288_SERIAL_MSG_LEN];
    char notice[2u * J288_SERIAL_MSG_LEN];
} j288_serial_t;

/*
 * Open dev at baud (0: J288_DEFAULT_BAUD), raw 8N1, exclusive, input flushed. dev is a path
 * on Linux ("/dev/ttyUSB0", "/dev/serial/by-id/...", the simulator's pty), a COM port on
 * Windows ("COM5", "\\.\COM12"). opt may be NULL (defaults). Returns J288_OK or, with a
 * one-line reason in j288_serial_error():
 *   J288_ERR_NULL        sp or dev NULL
 *   J288_ERR_OFFLINE     the device does not exist or cannot be opened (permission, ...)
 *   J288_ERR_BUSY        another program holds the bus (Linux: "in use by PID n")
 *   J288_ERR_BAD_CONFIG  not a serial device, a name too long (Windows), or the adapter
 *                        cannot do this baud rate (refused, or another rate read back)
 *   J288_ERR_PORT        another OS failure
 * On failure nothing stays open. sp need not be initialised before; after a failure
 * j288_serial_error() stays valid and j288_serial_close() is harmless.
 */
int j288_serial_open(j288_serial_t *sp, const char *dev, uint32_t baud,
                     const j288_serial_options_t *opt);

/* Release the exclusive hold and close (Windows: cancel the read in flight, waiting at most
 * its timeout for it). Safe on a closed or failed sp, and twice. A bus bound to sp must not be
 * used afterwards. */
void j288_serial_close(j288_serial_t *sp);

/* The port operations (start_tx, now_us, arm_timeout, wait); ctx is the j288_serial_t.
 * Prefer j288_serial_bus_init(), which also tells the port which bus to feed. */
extern const j288_port_t j288_serial_port;

/* The recommended bus configuration for this port: the opened baud, turnaround and guard
 * defaults, margin_us from the options (20 ms by default), echo from the options, no retries.
 * Adjust fields afterwards as needed. */
void j288_serial_bus_config(const j288_serial_t *sp, j288_bus_config_t *cfg);

/* Bind bus to this port and initialise it: cfg NULL means j288_serial_bus_config(). Returns
 * j288_bus_init()'s result (J288_ERR_NULL when sp or bus is NULL). One bus per port. */
int j288_serial_bus_init(j288_serial_t *sp, j288_bus_t *bus, const j288_bus_config_t *cfg);

/* Monotonic microseconds (Linux CLOCK_MONOTONIC, Windows QueryPerformanceCounter), wrapping
 * at 2^32 like the bus's clock. Any thread. */
uint32_t j288_serial_now_us(void);

/* ---- for a loop that drives the bus itself (host/j288_robot.c: one loop over several ports)
 * Such a loop polls its buses, sleeps in j288_serial_wait_any() over every port, then lets
 * each port that is ready, or has a due deadline, service itself; reading, flushing and the
 * vanished-device handling stay in the port. Thread only. */

/* The earliest time (j288_serial_now_us() clock) at which the port has an event to deliver
 * to its bus (the bus's reply deadline, the line-idle report): true and *at_us set, or false
 * when none is pending (or sp/at_us is NULL). A loop must not sleep past it. */
bool j288_serial_next_deadline(const j288_serial_t *sp, uint32_t *at_us);

/* Read what the device has and deliver the events that are due, without sleeping: the
 * port's wait() with a deadline of now. J288_OK, J288_ERR_OFFLINE (the device vanished:
 * reported to the bus, j288_serial_error() says why), J288_ERR_NULL. */
int j288_serial_service(j288_serial_t *sp);

/* Sleep until one of ports[0..n-1] (open, not gone) has input or a hang-up to report, or
 * timeout_us has passed (Windows: rounded up to whole milliseconds), or a signal came (Linux).
 * ready[i] is set for each port to service (then call j288_serial_service() on it), cleared
 * for the others; closed or gone ports are never ready. Returns how many are ready (0:
 * timeout or signal). n may be 0 (a plain bounded sleep); at most J288_SERIAL_WAIT_MAX
 * ports (the rest are not waited on). Linux: one ppoll() over the descriptors; Windows: one
 * WaitForMultipleObjects() over the reads in flight. */
unsigned j288_serial_wait_any(j288_serial_t *const ports[], unsigned n, uint32_t timeout_us,
                              bool ready[]);

/* Whether opening dev would open the device sp has open (Linux: the same device node, through
 * any symlink; Windows: the same COM name, "COM5" and "\\.\com5" alike). False when sp is
 * closed or dev cannot be examined (then the open reports it). */
bool j288_serial_same_device(const j288_serial_t *sp, const char *dev);

/* ---- inspection (thread only, except the pure j288_serial_baud_ok()) */

/* The last error, one line without a trailing newline ("" if none). Never NULL. */
const char *j288_serial_error(const j288_serial_t *sp);

/* Notices from open (Linux: low latency refused, latency timer advice): zero or more lines,
 * each ending in '\n'; "" when there is nothing to say. Never NULL. */
const char *j288_serial_notices(const j288_serial_t *sp);

/* The name sp was opened with ("" before any open). Never NULL. */
const char *j288_serial_device(const j288_serial_t *sp);

/* Whether a read-back rate `got` is close enough to the requested `asked`: got is not 0 and
 * differs from asked by at most J288_SERIAL_BAUD_TOLERANCE_PCT percent of asked (the boundary
 * itself is accepted). False for asked 0. j288_serial_open() refuses a device for which this
 * is false ("the adapter cannot do N baud"). Pure; any thread. */
bool j288_serial_baud_ok(uint32_t asked, uint32_t got);

/* The baud rate the driver reports after open (0 when closed). */
uint32_t j288_serial_baud(const j288_serial_t *sp);

/* True once the device has vanished; the port must then be closed (and reopened). */
bool j288_serial_offline(const j288_serial_t *sp);

/* Port counters; never NULL for a non-NULL sp. */
const j288_serial_stats_t *j288_serial_stats(const j288_serial_t *sp);

#ifdef __cplusplus
}
#endif

#endif /* J288_SERIAL_H */
