/*
 * j288_linux.h - the Linux port: a serial device (USB-to-single-wire adapter, or the
 * simulator's pseudo-terminal) driving one j288 bus.
 *
 * What it does
 * - Opens the device in raw mode, 8N1, at any baud (6,000,000 by default) through termios2
 *   (BOTHER), and reads the rate back: an adapter that cannot do it is a clear error.
 * - Exclusive access: an advisory flock() on the device plus TIOCEXCL, so a second program
 *   gets "in use by PID n" (the PID is looked up in /proc/locks) and never interleaves frames.
 * - Low latency, best effort: tries ASYNC_LOW_LATENCY and reads the USB-serial latency timer
 *   in sysfs; what it cannot set becomes a one-line notice (j288_linux_notices()), never an
 *   error. Pseudo-terminals and some CH343-class adapters refuse ASYNC_LOW_LATENCY (ENOTTY).
 * - Non-blocking I/O with ppoll() and CLOCK_MONOTONIC; partial reads and writes, EINTR, and a
 *   vanished device (unplugged adapter, simulator exited: POLLHUP / EIO) are handled. A
 *   vanished device is reported once to the bus as j288_bus_on_error(bus, J288_LINE_GONE),
 *   then every wait() and start_tx() fails at once with J288_ERR_OFFLINE (no busy loop), and
 *   j288_linux_error() says what happened.
 *
 * Typical use (single thread; see also the run helpers below):
 *
 *   j288_linux_t lp;
 *   j288_bus_t bus;
 *   if (j288_linux_open(&lp, "/dev/ttyUSB0", 0, NULL) != J288_OK) {
 *       fprintf(stderr, "j288: %s\n", j288_linux_error(&lp));
 *       return 1;
 *   }
 *   fputs(j288_linux_notices(&lp), stderr);          // optional, "" when nothing to say
 *   j288_linux_bus_init(&lp, &bus, NULL);            // recommended Linux bus config
 *   int rc = j288_bus_transfer_blocking(&bus, &cmd, &txn);
 *   if (rc == J288_ERR_OFFLINE || j288_linux_offline(&lp))
 *       fprintf(stderr, "j288: %s\n", j288_linux_error(&lp));
 *   j288_linux_close(&lp);
 *
 * Threading: one thread owns a j288_linux_t and its bus; no lock is needed or provided.
 * The object is caller-allocated, holds no heap memory and must not move while open.
 * Error results are the library's codes (j288/error.h); the text is in j288_linux_error().
 */
#ifndef J288_LINUX_H
#define J288_LINUX_H

#include <signal.h>
#include <stdbool.h>
#include <stdint.h>

#include "j288/bus.h"
#include "j288/port.h"
#include "j288/sched.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Host latency margin for the reply deadline over USB: an FTDI adapter with its default
 * 16 ms latency timer needs most of it; lower it (j288_linux_options_t.margin_us) on a
 * pseudo-terminal or an adapter with a 1 ms timer. */
#define J288_LINUX_DEFAULT_MARGIN_US 20000u
/* Quiet time after received bytes before the port reports line idle to the bus. Longer than
 * a USB frame so that a reply split over two USB packets is not cut. */
#define J288_LINUX_DEFAULT_IDLE_US 2000u
/* Largest accepted difference between the requested and the read-back baud rate, percent. */
#define J288_LINUX_BAUD_TOLERANCE_PCT 3u

#define J288_LINUX_MSG_LEN 320u

/* All-zero means defaults. */
typedef struct {
    uint32_t margin_us;  /* reply margin for j288_linux_bus_config(); 0: 20 ms */
    uint32_t idle_us;    /* line-idle report after bytes; 0: 2 ms */
    bool echo;           /* the adapter hears its own transmit (many single-wire ones
                            do): the bus then checks and skips our echoed command */
    bool no_low_latency; /* do not try ASYNC_LOW_LATENCY / the latency timer check */
} j288_linux_options_t;

/* Port counters (the bus keeps its own in j288_bus_stats()). */
typedef struct {
    uint32_t tx_bytes;
    uint32_t rx_bytes;
    uint32_t flushed_bytes;  /* bytes found waiting before a transmit: dropped, since no
                                reply can precede its command */
    uint32_t partial_writes; /* write() calls that took fewer bytes than offered */
    uint32_t eintr;          /* system calls interrupted by a signal and resumed */
    uint32_t waits;
} j288_linux_stats_t;

typedef struct j288_linux {
    /* Private: use the functions below. */
    int fd;
    j288_bus_t *bus;
    j288_linux_options_t opt;
    uint32_t baud;        /* requested */
    uint32_t baud_actual; /* read back from the driver */
    bool gone;            /* the device vanished */
    bool idle_pending;    /* bytes were delivered and no idle reported since */
    bool timer_armed;
    bool low_latency; /* ASYNC_LOW_LATENCY accepted */
    uint32_t last_rx_us;
    uint32_t timer_us;
    const volatile sig_atomic_t *stop_flag;
    j288_linux_stats_t stats;
    char dev[128];
    char err[J288_LINUX_MSG_LEN];
    char notice[2u * J288_LINUX_MSG_LEN];
} j288_linux_t;

/*
 * Open dev (e.g. "/dev/ttyUSB0", "/dev/serial/by-id/...", the simulator's pty) at baud
 * (0: J288_DEFAULT_BAUD), raw 8N1, exclusive, input flushed. opt may be NULL (defaults).
 * Returns J288_OK or, with a one-line reason in j288_linux_error():
 *   J288_ERR_NULL        lp or dev NULL
 *   J288_ERR_OFFLINE     the device does not exist or cannot be opened (permission, ...)
 *   J288_ERR_BUSY        another program holds the bus ("in use by PID n")
 *   J288_ERR_BAD_CONFIG  not a serial device, or the adapter cannot do this baud rate
 *   J288_ERR_PORT        another termios/ioctl failure
 * On failure nothing stays open. lp need not be initialised before; after a failure
 * j288_linux_error() stays valid and j288_linux_close() is harmless.
 */
int j288_linux_open(j288_linux_t *lp, const char *dev, uint32_t baud,
                    const j288_linux_options_t *opt);

/* Release the lock and the exclusive mode and close. Safe on a closed or failed lp, and
 * twice. A bus bound to lp must not be used afterwards. */
void j288_linux_close(j288_linux_t *lp);

/* The port operations (start_tx, now_us, wait, arm_timeout); ctx is the j288_linux_t.
 * Prefer j288_linux_bus_init(), which also tells the port which bus to feed. */
extern const j288_port_t j288_linux_port;

/* The recommended bus configuration for this port: the opened baud, turnaround and guard
 * defaults, margin_us from the options (20 ms by default), echo from the options, no retries.
 * Adjust fields afterwards as needed. */
void j288_linux_bus_config(const j288_linux_t *lp, j288_bus_config_t *cfg);

/* Bind bus to this port and initialise it: cfg NULL means j288_linux_bus_config(). Returns
 * j288_bus_init()'s result (J288_ERR_NULL when lp or bus is NULL). One bus per port. */
int j288_linux_bus_init(j288_linux_t *lp, j288_bus_t *bus, const j288_bus_config_t *cfg);

/* Monotonic microseconds (CLOCK_MONOTONIC), wrapping at 2^32 like the bus's clock. */
uint32_t j288_linux_now_us(void);

/* Let the run helpers return J288_ERR_ABORTED soon after *flag becomes non-zero (e.g. set
 * by a SIGINT handler installed without SA_RESTART). NULL: no flag. */
void j288_linux_set_stop_flag(j288_linux_t *lp, const volatile sig_atomic_t *flag);

/* Flags for j288_linux_run(). */
#define J288_LINUX_RUN_UNTIL_IDLE                                                                  \
    0x1u                                /* return as soon as the bus (and the scheduler, when      \
                                           given) has nothing in progress */
#define J288_LINUX_RUN_IGNORE_STOP 0x2u /* ignore the stop flag: for flushing a stop frame */

/*
 * Drive the bus from the calling thread until until_us (a j288_linux_now_us() time, at most
 * 35 minutes ahead): poll the scheduler (or, with s NULL, the bound bus), sleep in the port
 * until bytes arrive or a deadline passes, repeat. Never spins: with nothing to do it
 * sleeps until until_us; while a transaction is pending it wakes at least every 1 ms.
 * Returns J288_OK at until_us (or, with J288_LINUX_RUN_UNTIL_IDLE, when idle),
 * J288_ERR_TIMEOUT when UNTIL_IDLE was asked and until_us came first, J288_ERR_ABORTED when
 * the stop flag is set, J288_ERR_OFFLINE when the device vanished, J288_ERR_NULL (lp, or no
 * bus bound). Thread only.
 */
int j288_linux_run(j288_linux_t *lp, j288_sched_t *s, uint32_t until_us, unsigned flags);

/* One scheduler sweep, start to end: j288_sched_start_sweep() then run until it ends.
 * timeout_us bounds the whole (0: 1 s). Returns J288_OK, or j288_sched_start_sweep()'s
 * error, or j288_linux_run()'s (J288_ERR_TIMEOUT, _ABORTED, _OFFLINE). Thread only. */
int j288_linux_sweep(j288_linux_t *lp, j288_sched_t *s, uint32_t timeout_us);

/* ---- for a loop that waits on several ports at once (the host layer's j288_host_wait()) ---
 * Such a loop sleeps in one call over every port's descriptor, then lets each port that has
 * bytes (or a due event) service itself; the port's reading, flushing and vanished-device
 * handling stay here. Thread only. */

/* The device's descriptor, to wait on for input; -1 when closed or gone. */
int j288_linux_fd(const j288_linux_t *lp);

/* The earliest time (j288_linux_now_us() clock) at which the port has an event to deliver to
 * its bus (the bus's reply deadline, the line-idle report): true and *at_us set, or false
 * when none is pending (or lp/at_us is NULL). A loop must not sleep past it. */
bool j288_linux_next_deadline(const j288_linux_t *lp, uint32_t *at_us);

/* Read what the device has and deliver the events that are due, without sleeping: the
 * port's wait() with a deadline of now. J288_OK, J288_ERR_OFFLINE (the device vanished:
 * reported to the bus, j288_linux_error() says why), J288_ERR_NULL. */
int j288_linux_service(j288_linux_t *lp);

/* The last error, one line without a trailing newline ("" if none). Never NULL. */
const char *j288_linux_error(const j288_linux_t *lp);

/* Notices from open (low latency refused, latency timer advice): zero or more lines, each
 * ending in '\n'; "" when there is nothing to say. Never NULL. */
const char *j288_linux_notices(const j288_linux_t *lp);

/* Whether a read-back rate `got` is close enough to the requested `asked`: got is not 0 and
 * differs from asked by at most J288_LINUX_BAUD_TOLERANCE_PCT percent of asked (the boundary
 * itself is accepted). False for asked 0. j288_linux_open() refuses a device for which this is
 * false ("the adapter cannot do N baud"). Pure; callable from any thread. */
bool j288_linux_baud_ok(uint32_t asked, uint32_t got);

/* The baud rate the driver reports after open (0 when closed). */
uint32_t j288_linux_baud(const j288_linux_t *lp);

/* True once the device has vanished; the port must then be closed (and reopened). */
bool j288_linux_offline(const j288_linux_t *lp);

/* Port counters; never NULL for a non-NULL lp. */
const j288_linux_stats_t *j288_linux_stats(const j288_linux_t *lp);

#ifdef __cplusplus
}
#endif

#endif /* J288_LINUX_H */
