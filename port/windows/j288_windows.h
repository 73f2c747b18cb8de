/*
 * j288_windows.h - the Windows port: a Win32 serial port (COM1 ... COM256: a USB-to-single-wire
 * adapter's virtual COM port) driving one j288 bus. Its API follows port/linux's
 * (j288_linux.h) name for name, so that a host program takes either with the same calls.
 *
 * What it does
 * - Opens "COMn" (or "\\.\COMn"; the short name is turned into the long form, which every
 *   COM number needs above COM9) with CreateFile, exclusive (share mode 0: a second program
 *   gets "in use by another program"; Windows does not say which one), overlapped.
 * - SetCommState: raw 8N1, no flow control, the requested baud rate (6,000,000 by default)
 *   handed to the driver as is. A driver that refuses the rate (SetCommState fails) or reads
 *   back another one is a clear error (J288_ERR_BAD_CONFIG), never a silent fallback.
 * - Read timeouts "return what is queued, else wait for the first byte" (ReadIntervalTimeout
 *   and ReadTotalTimeoutMultiplier MAXDWORD, a bounded ReadTotalTimeoutConstant): one
 *   overlapped ReadFile is kept in flight, so that an event handle says "bytes are there"
 *   (j288_windows_read_event(): a host can wait for several buses in one
 *   WaitForMultipleObjects()). A read that ends on its own timeout completes with 0 bytes on
 *   Windows and with ERROR_TIMEOUT under Wine: both mean "nothing yet". No WaitCommEvent (a
 *   pending one cannot be cancelled under Wine).
 * - Overlapped WriteFile, waited for (bounded) before the bus hears "transmit done".
 * - QueryPerformanceCounter for the bus's microsecond clock.
 * - A vanished device (USB adapter unplugged: a read or write fails with an I/O error) is
 *   reported once to the bus as j288_bus_on_error(bus, J288_LINE_GONE), then every wait() and
 *   start_tx() fails at once with J288_ERR_OFFLINE, and j288_windows_error() says what
 *   happened.
 *
 * Typical use (single thread):
 *
 *   j288_windows_t wp;
 *   j288_bus_t bus;
 *   if (j288_windows_open(&wp, "COM5", 0, NULL) != J288_OK) {
 *       fprintf(stderr, "j288: %s\n", j288_windows_error(&wp));
 *       return 1;
 *   }
 *   j288_windows_bus_init(&wp, &bus, NULL);
 *   int rc = j288_bus_transfer_blocking(&bus, &cmd, &txn);
 *   j288_windows_close(&wp);
 *
 * Latency: an FTDI adapter's driver holds received bytes up to its latency timer (16 ms by
 * default; Device Manager > the COM port > Port Settings > Advanced > Latency Timer, set 1).
 * The default reply margin (20 ms) covers the default timer; lower margin_us after lowering it.
 *
 * Threading: one thread owns a j288_windows_t and its bus; the stop flag may be set from any
 * thread (a console control handler runs on its own thread). The object is caller-allocated,
 * holds no heap memory (only the port's handles) and must not move while open: an overlapped
 * read in flight writes into it. Error results are the library's codes (j288/error.h).
 */
#ifndef J288_WINDOWS_H
#define J288_WINDOWS_H

#ifndef WIN32_LEAN_AND_MEAN
#define WIN32_LEAN_AND_MEAN
#endif
#include <windows.h>

#include <signal.h>
#include <stdbool.h>
#include <stdint.h>

#include "j288/bus.h"
#include "j288/port.h"
#include "j288/sched.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Reply margin over USB (see Latency above). */
#define J288_WINDOWS_DEFAULT_MARGIN_US 20000u
/* Quiet time after received bytes before the port reports line idle to the bus: longer than
 * a USB frame, so that a reply split over two USB packets is not cut. */
#define J288_WINDOWS_DEFAULT_IDLE_US 2000u
/* Largest accepted difference between the requested and the read-back baud rate, percent. */
#define J288_WINDOWS_BAUD_TOLERANCE_PCT 3u
/* ReadTotalTimeoutConstant of the read kept in flight: with no byte for this long it
 * completes empty and is issued again (a bound on how long close() waits for it, too). */
#define J288_WINDOWS_READ_SLICE_MS 100u

#define J288_WINDOWS_MSG_LEN 320u
#define J288_WINDOWS_RX_BUF  256u

/* All-zero means defaults. */
typedef struct {
    uint32_t margin_us;  /* reply margin for j288_windows_bus_config(); 0: 20 ms */
    uint32_t idle_us;    /* line-idle report after bytes; 0: 2 ms */
    bool echo;           /* the adapter hears its own transmit: the bus checks and skips it */
    bool no_low_latency; /* accepted for the Linux port's options; nothing to switch here (the
                            FTDI latency timer is a driver setting: see Latency above) */
} j288_windows_options_t;

/* Port counters (the bus keeps its own in j288_bus_stats()). */
typedef struct {
    uint32_t tx_bytes;
    uint32_t rx_bytes;
    uint32_t flushed_bytes; /* bytes found waiting before a transmit: dropped, since no reply
                               can precede its command */
    uint32_t reads;         /* overlapped reads issued */
    uint32_t empty_reads;   /* of which ended on their timeout: 0 bytes, or ERROR_TIMEOUT */
    uint32_t waits;
} j288_windows_stats_t;

typedef struct j288_windows {
    /* Private: use the functions below. */
    HANDLE h;        /* INVALID_HANDLE_VALUE when closed */
    HANDLE rx_event; /* manual-reset, the read's */
    HANDLE tx_event; /* manual-reset, the write's */
    OVERLAPPED rx_ov;
    OVERLAPPED tx_ov;
    bool rx_pending; /* a ReadFile into rx_buf is in flight */
    j288_bus_t *bus;
    j288_windows_options_t opt;
    uint32_t baud;        /* requested */
    uint32_t baud_actual; /* read back from the driver */
    bool gone;            /* the device vanished */
    bool idle_pending;    /* bytes were delivered and no idle reported since */
    bool timer_armed;
    uint32_t last_rx_us;
    uint32_t timer_us;
    const volatile sig_atomic_t *stop_flag;
    j288_windows_stats_t stats;
    uint8_t rx_buf[J288_WINDOWS_RX_BUF];
    char dev[128];
    char err[J288_WINDOWS_MSG_LEN];
    char notice[J288_WINDOWS_MSG_LEN];
} j288_windows_t;

/*
 * Open dev ("COM5", "\\.\COM12") at baud (0: J288_DEFAULT_BAUD), raw 8N1, exclusive, input
 * purged. opt may be NULL (defaults). Returns J288_OK or, with a one-line reason in
 * j288_windows_error():
 *   J288_ERR_NULL        wp or dev NULL
 *   J288_ERR_OFFLINE     no such port (adapter unplugged?), or it cannot be opened
 *   J288_ERR_BUSY        another program has the port open
 *   J288_ERR_BAD_CONFIG  not a serial port, a name too long, or the driver refuses the baud
 *                        rate (or reads back another one)
 *   J288_ERR_PORT        another Win32 failure (events, timeouts)
 * On failure nothing stays open. wp need not be initialised before; after a failure
 * j288_windows_error() stays valid and j288_windows_close() is harmless.
 */
int j288_windows_open(j288_windows_t *wp, const char *dev, uint32_t baud,
                      const j288_windows_options_t *opt);

/* Cancel the read in flight (waiting at most its timeout for it) and close. Safe on a closed
 * or failed wp, and twice. A bus bound to wp must not be used afterwards. */
void j288_windows_close(j288_windows_t *wp);

/* The port operations (start_tx, now_us, wait, arm_timeout); ctx is the j288_windows_t.
 * Prefer j288_windows_bus_init(), which also tells the port which bus to feed. */
extern const j288_port_t j288_windows_port;

/* The recommended bus configuration: the opened baud, margin_us and echo from the options,
 * no retries. Adjust fields afterwards as needed. */
void j288_windows_bus_config(const j288_windows_t *wp, j288_bus_config_t *cfg);

/* Bind bus to this port and initialise it: cfg NULL means j288_windows_bus_config(). Returns
 * j288_bus_init()'s result (J288_ERR_NULL when wp or bus is NULL). One bus per port. */
int j288_windows_bus_init(j288_windows_t *wp, j288_bus_t *bus, const j288_bus_config_t *cfg);

/* Monotonic microseconds (QueryPerformanceCounter), wrapping at 2^32 like the bus's clock.
 * Any thread. */
uint32_t j288_windows_now_us(void);

/* Let the run helpers return J288_ERR_ABORTED soon after *flag becomes non-zero (e.g. set
 * by a SetConsoleCtrlHandler routine). NULL: no flag. */
void j288_windows_set_stop_flag(j288_windows_t *wp, const volatile sig_atomic_t *flag);

/* Flags for j288_windows_run(): as J288_LINUX_RUN_*. */
#define J288_WINDOWS_RUN_UNTIL_IDLE  0x1u /* return once the bus (and scheduler) is idle */
#define J288_WINDOWS_RUN_IGNORE_STOP 0x2u /* ignore the stop flag: for flushing a stop frame */

/*
 * Drive the bus from the calling thread until until_us (a j288_windows_now_us() time, at most
 * 35 minutes ahead): poll the scheduler (or, with s NULL, the bound bus), sleep in the port
 * until bytes arrive or a deadline passes, repeat. While a transaction is pending it wakes at
 * least every 1 ms. Returns J288_OK at until_us (or, with J288_WINDOWS_RUN_UNTIL_IDLE, when
 * idle), J288_ERR_TIMEOUT when UNTIL_IDLE was asked and until_us came first,
 * J288_ERR_ABORTED when the stop flag is set, J288_ERR_OFFLINE when the device vanished,
 * J288_ERR_NULL (wp, or no bus bound). Thread only.
 */
int j288_windows_run(j288_windows_t *wp, j288_sched_t *s, uint32_t until_us, unsigned flags);

/* One scheduler sweep, start to end; timeout_us bounds the whole (0: 1 s). Returns J288_OK,
 * j288_sched_start_sweep()'s error, or j288_windows_run()'s. Thread only. */
int j288_windows_sweep(j288_windows_t *wp, j288_sched_t *s, uint32_t timeout_us);

/*
 * For a host waiting on several ports at once: make sure a read is in flight and return the
 * event that is set when it completes (bytes came, its timeout passed, or the device failed;
 * set already when input was queued). NULL when the port is closed or gone. After the wait,
 * call j288_windows_port.wait(wp, j288_windows_now_us()) for each port whose event is set: it
 * collects what is there and does not sleep with a deadline of now. Thread only.
 */
HANDLE j288_windows_read_event(j288_windows_t *wp);

/* Read what has come and deliver the events that are due, without sleeping: the port's
 * wait() with a deadline of now. J288_OK, J288_ERR_OFFLINE (the device vanished: reported to
 * the bus, j288_windows_error() says why), J288_ERR_NULL. Thread only. */
int j288_windows_service(j288_windows_t *wp);

/* The multi-bus wait (a host's one OS-specific call; Linux: one ppoll() over descriptors):
 * sleep until one of ports[0..n-1] (open, not gone) has input or has failed, or timeout_us
 * has passed (rounded up to whole milliseconds). ready[i] is set for each port to service
 * (then call j288_windows_service() on it), cleared for the others; closed or gone ports are
 * never ready. Returns how many are ready (0: timeout). n may be 0 (a plain bounded sleep).
 * At most J288_WINDOWS_WAIT_MAX ports. One WaitForMultipleObjects() over the ports' read
 * events. Thread only. */
#define J288_WINDOWS_WAIT_MAX 16u
unsigned j288_windows_wait_any(j288_windows_t *const ports[], unsigned n, uint32_t timeout_us,
                               bool ready[]);

/* The earliest time the port must be called again for its own timers (reply deadline armed
 * by the bus, line idle after bytes): sets *at_us and returns true, or false when none is due.
 * Thread only. */
bool j288_windows_next_deadline(const j288_windows_t *wp, uint32_t *at_us);

/* The last error, one line without a trailing newline ("" if none). Never NULL. */
const char *j288_windows_error(const j288_windows_t *wp);

/* Notices from open: zero or more lines, each ending in '\n'; "" when nothing. Never NULL. */
const char *j288_windows_notices(const j288_windows_t *wp);

/* Whether a read-back rate `got` is close enough to the requested `asked` (both non-zero,
 * within J288_WINDOWS_BAUD_TOLERANCE_PCT percent of asked). Pure; any thread. */
bool j288_windows_baud_ok(uint32_t asked, uint32_t got);

/* "COM5" -> "\\.\COM5" (names already in the long form, or other paths, unchanged) into out.
 * Returns false when it does not fit in cap. Pure; any thread. */
bool j288_windows_device_path(const char *dev, char *out, size_t cap);

/* Whether two names ("COM5", "\\.\com5") name the same port: equal in the long form, case
 * ignored (Windows' device names are). False when either is NULL or too long. Pure. */
bool j288_windows_same_device(const char *a, const char *b);

/* The name wp was opened with ("" before any open). Never NULL. */
const char *j288_windows_device(const j288_windows_t *wp);

/* The baud rate the driver reports after open (0 when closed). */
uint32_t j288_windows_baud(const j288_windows_t *wp);

/* True once the device has vanished; the port must then be closed (and reopened). */
bool j288_windows_offline(const j288_windows_t *wp);

/* Port counters; never NULL for a non-NULL wp. */
const j288_windows_stats_t *j288_windows_stats(const j288_windows_t *wp);

#ifdef __cplusplus
}
#endif

#endif /* J288_WINDOWS_H */
