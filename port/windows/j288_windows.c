/*
 * j288_windows.c - the Windows port (see j288_windows.h for the contract).
 *
 * One overlapped read of ONE byte is kept in flight with the timeouts "return what is
 * queued, else wait for the first byte, at most J288_WINDOWS_READ_SLICE_MS": its event is what
 * wait() (and a multi-bus host) sleeps on, so that a reply wakes the thread at once, with no
 * WaitCommEvent (which Wine cannot cancel). When it completes, the bytes queued behind it
 * (ClearCommError's count) are read at once. One byte, because Wine's overlapped read does not
 * return early with what came: a read of 256 bytes waited for all 256 (measured under Wine
 * 8.0: ten replies per read, every transaction timed out). Reads are never cancelled except
 * at close.
 */
#ifndef _WIN32_WINNT
#define _WIN32_WINNT 0x0600 /* CancelIoEx: Vista and later */
#endif

#include "j288_windows.h"

#include <mmsystem.h>

#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

/* A write that does not complete in this long means the adapter is stuck. */
#define WRITE_STALL_MS 200u
/* While a transaction is pending, run() wakes at least this often to let the bus check its
 * reply deadline. */
#define RUN_SLICE_US 1000u
/* With a stop flag set, never sleep longer than this, so the flag is seen promptly. */
#define STOP_SLICE_US 20000u

static void set_err(j288_windows_t *wp, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

static void set_err(j288_windows_t *wp, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    (void)vsnprintf(wp->err, sizeof wp->err, fmt, ap);
    va_end(ap);
}

/* The system's text for a Win32 error code, one line, in buf. */
static const char *win_text(DWORD code, char *buf, size_t cap)
{
    DWORD n = FormatMessageA(FORMAT_MESSAGE_FROM_SYSTEM | FORMAT_MESSAGE_IGNORE_INSERTS, NULL, code,
                             0, buf, (DWORD)cap, NULL);
    while (n > 0u &&
           (buf[n - 1u] == '\n' || buf[n - 1u] == '\r' || buf[n - 1u] == '.' || buf[n - 1u] == ' '))
        n--;
    if (n == 0u)
        (void)snprintf(buf, cap, "error %lu", (unsigned long)code);
    else
        buf[n] = '\0';
    return buf;
}

uint32_t j288_windows_now_us(void)
{
    LARGE_INTEGER f, c;
    uint64_t freq, count;
    (void)QueryPerformanceFrequency(&f); /* never fails on XP and later */
    (void)QueryPerformanceCounter(&c);
    freq = (uint64_t)f.QuadPart;
    count = (uint64_t)c.QuadPart;
    /* Split so that count * 1e6 cannot overflow 64 bits. */
    return (uint32_t)((count / freq) * 1000000u + ((count % freq) * 1000000u) / freq);
}

/* Signed distance from now to t in the bus's wrapping microsecond clock. */
static int32_t us_until(uint32_t t, uint32_t now)
{
    return (int32_t)(t - now);
}

/* ---- open -------------------------------------------------------------------------------- */

bool j288_windows_baud_ok(uint32_t asked, uint32_t got)
{
    uint32_t diff = (got > asked) ? got - asked : asked - got;
    return asked != 0u && got != 0u &&
           (uint64_t)diff * 100u <= (uint64_t)asked * J288_WINDOWS_BAUD_TOLERANCE_PCT;
}

bool j288_windows_device_path(const char *dev, char *out, size_t cap)
{
    /* A bare name ("COM12", "CNCA0") is a device in the \\.\ namespace; CreateFile finds
     * COM1-COM9 without it, but no higher number. Anything with a separator is kept. */
    bool bare = strchr(dev, '\\') == NULL && strchr(dev, '/') == NULL;
    int n = snprintf(out, cap, "%s%s", bare ? "\\\\.\\" : "", dev);
    return n > 0 && (size_t)n < cap;
}

bool j288_windows_same_device(const char *a, const char *b)
{
    char la[sizeof((j288_windows_t *)0)->dev + 4u], lb[sizeof la];
    return a != NULL && b != NULL && j288_windows_device_path(a, la, sizeof la) &&
           j288_windows_device_path(b, lb, sizeof lb) && _stricmp(la, lb) == 0;
}

static int open_error(j288_windows_t *wp, DWORD e)
{
    char t[160];
    if (e == ERROR_FILE_NOT_FOUND || e == ERROR_PATH_NOT_FOUND) {
        set_err(wp, "%s: no such port (adapter unplugged? see Device Manager > Ports)", wp->dev);
        return J288_ERR_OFFLINE;
    }
    if (e == ERROR_ACCESS_DENIED || e == ERROR_SHARING_VIOLATION) {
        set_err(wp, "%s is in use by another program (a COM port opens only once)", wp->dev);
        return J288_ERR_BUSY;
    }
    set_err(wp, "%s: cannot open: %s", wp->dev, win_text(e, t, sizeof t));
    return J288_ERR_OFFLINE;
}

static int set_line(j288_windows_t *wp)
{
    DCB dcb;
    char t[160];
    memset(&dcb, 0, sizeof dcb);
    dcb.DCBlength = sizeof dcb;
    if (!GetCommState(wp->h, &dcb)) {
        set_err(wp, "%s is not a serial port (%s)", wp->dev, win_text(GetLastError(), t, sizeof t));
        return J288_ERR_BAD_CONFIG;
    }
    /* Raw 8N1: no flow control, no character substitution, errors do not abort I/O. */
    dcb.BaudRate = wp->baud;
    dcb.ByteSize = 8;
    dcb.Parity = NOPARITY;
    dcb.StopBits = ONESTOPBIT;
    dcb.fBinary = 1;
    dcb.fParity = 0;
    dcb.fOutxCtsFlow = 0;
    dcb.fOutxDsrFlow = 0;
    dcb.fDtrControl = DTR_CONTROL_ENABLE;
    dcb.fDsrSensitivity = 0;
    dcb.fTXContinueOnXoff = 1;
    dcb.fOutX = 0;
    dcb.fInX = 0;
    dcb.fErrorChar = 0;
    dcb.fNull = 0;
    dcb.fRtsControl = RTS_CONTROL_ENABLE;
    dcb.fAbortOnError = 0;
    if (!SetCommState(wp->h, &dcb)) {
        set_err(wp, "%s: the driver refuses %lu baud (%s)", wp->dev, (unsigned long)wp->baud,
                win_text(GetLastError(), t, sizeof t));
        return J288_ERR_BAD_CONFIG;
    }
    if (!GetCommState(wp->h, &dcb)) {
        set_err(wp, "%s: cannot read back line settings (%s)", wp->dev,
                win_text(GetLastError(), t, sizeof t));
        return J288_ERR_PORT;
    }
    if (!j288_windows_baud_ok(wp->baud, (uint32_t)dcb.BaudRate)) {
        set_err(wp, "%s: the adapter cannot do %lu baud (its driver reports %lu)", wp->dev,
                (unsigned long)wp->baud, (unsigned long)dcb.BaudRate);
        return J288_ERR_BAD_CONFIG;
    }
    wp->baud_actual = (uint32_t)dcb.BaudRate;
    return J288_OK;
}

static int set_timeouts(j288_windows_t *wp)
{
    COMMTIMEOUTS to;
    char t[160];
    /* MAXDWORD, MAXDWORD, constant: a read returns what is queued at once, else the first
     * byte(s) as soon as they come, else nothing after the constant. */
    to.ReadIntervalTimeout = MAXDWORD;
    to.ReadTotalTimeoutMultiplier = MAXDWORD;
    to.ReadTotalTimeoutConstant = J288_WINDOWS_READ_SLICE_MS;
    to.WriteTotalTimeoutMultiplier = 0;
    to.WriteTotalTimeoutConstant = WRITE_STALL_MS;
    if (!SetCommTimeouts(wp->h, &to)) {
        set_err(wp, "%s: cannot set timeouts (%s)", wp->dev, win_text(GetLastError(), t, sizeof t));
        return J288_ERR_PORT;
    }
    return J288_OK;
}

static void reset_object(j288_windows_t *wp)
{
    memset(wp, 0, sizeof *wp);
    wp->h = INVALID_HANDLE_VALUE;
}

static int make_events(j288_windows_t *wp)
{
    char t[160];
    wp->rx_event = CreateEventA(NULL, TRUE, FALSE, NULL);
    wp->tx_event = CreateEventA(NULL, TRUE, FALSE, NULL);
    if (wp->rx_event == NULL || wp->tx_event == NULL) {
        set_err(wp, "cannot create events (%s)", win_text(GetLastError(), t, sizeof t));
        return J288_ERR_PORT;
    }
    return J288_OK;
}

static void release_handles(j288_windows_t *wp)
{
    if (wp->h != INVALID_HANDLE_VALUE) {
        (void)CloseHandle(wp->h);
        (void)timeEndPeriod(1);
    }
    if (wp->rx_event != NULL)
        (void)CloseHandle(wp->rx_event);
    if (wp->tx_event != NULL)
        (void)CloseHandle(wp->tx_event);
    wp->h = INVALID_HANDLE_VALUE;
    wp->rx_event = NULL;
    wp->tx_event = NULL;
}

int j288_windows_open(j288_windows_t *wp, const char *dev, uint32_t baud,
                      const j288_windows_options_t *opt)
{
    char path[sizeof wp->dev + 4u];
    int rc;
    if (wp == NULL)
        return J288_ERR_NULL;
    reset_object(wp);
    if (dev == NULL) {
        set_err(wp, "no device given");
        return J288_ERR_NULL;
    }
    if (strlen(dev) >= sizeof wp->dev || !j288_windows_device_path(dev, path, sizeof path)) {
        set_err(wp, "device name too long (%lu characters at most)",
                (unsigned long)(sizeof wp->dev - 1u));
        return J288_ERR_BAD_CONFIG;
    }
    memcpy(wp->dev, dev, strlen(dev) + 1u);
    if (opt != NULL)
        wp->opt = *opt;
    if (wp->opt.margin_us == 0u)
        wp->opt.margin_us = J288_WINDOWS_DEFAULT_MARGIN_US;
    if (wp->opt.idle_us == 0u)
        wp->opt.idle_us = J288_WINDOWS_DEFAULT_IDLE_US;
    wp->baud = (baud == 0u) ? J288_DEFAULT_BAUD : baud;

    wp->h = CreateFileA(path, GENERIC_READ | GENERIC_WRITE, 0 /* exclusive */, NULL, OPEN_EXISTING,
                        FILE_FLAG_OVERLAPPED, NULL);
    if (wp->h == INVALID_HANDLE_VALUE)
        return open_error(wp, GetLastError());
    /* Timer waits (reply deadlines, idle) at 1 ms instead of the default 15.6 ms tick. */
    (void)timeBeginPeriod(1);
    rc = make_events(wp);
    if (rc == J288_OK)
        rc = set_line(wp);
    if (rc == J288_OK)
        rc = set_timeouts(wp);
    if (rc != J288_OK) {
        release_handles(wp);
        wp->baud_actual = 0;
        return rc;
    }
    (void)SetupComm(wp->h, 4096, 4096); /* a hint; drivers may keep their own sizes */
    /* Bytes queued before we came (a previous program's replies) are not ours. */
    (void)PurgeComm(wp->h, PURGE_RXCLEAR | PURGE_TXCLEAR);
    return J288_OK;
}

void j288_windows_close(j288_windows_t *wp)
{
    if (wp == NULL || wp->h == INVALID_HANDLE_VALUE)
        return;
    if (wp->rx_pending) {
        /* The read writes into *wp: it must be over before we return. It ends by itself
         * within its timeout if the cancel is not honoured. */
        (void)CancelIoEx(wp->h, &wp->rx_ov);
        (void)WaitForSingleObject(wp->rx_event, 2u * J288_WINDOWS_READ_SLICE_MS);
        wp->rx_pending = false;
    }
    release_handles(wp);
    wp->bus = NULL;
    wp->baud_actual = 0;
}

/* ---- I/O ----------------------------------------------------------------------------------- */

/* Report the device's disappearance once: to the bus and in the error text. */
static void mark_gone(j288_windows_t *wp, const char *what, DWORD e)
{
    char t[160];
    if (wp->gone)
        return;
    wp->gone = true;
    set_err(wp, "%s vanished (%s: %s): adapter unplugged?", wp->dev, what,
            win_text(e, t, sizeof t));
    if (wp->bus != NULL)
        j288_bus_on_error(wp->bus, J288_LINE_GONE);
}

/* Put the one-byte read in flight if none is. Returns 0, or -1 when the device is gone. */
static int start_read(j288_windows_t *wp)
{
    DWORD e;
    if (wp->rx_pending)
        return 0;
    memset(&wp->rx_ov, 0, sizeof wp->rx_ov);
    wp->rx_ov.hEvent = wp->rx_event;
    wp->stats.reads++;
    /* Done at once (TRUE) or pending: either way the event tells, and finish_read() takes
     * the result from the OVERLAPPED. */
    if (ReadFile(wp->h, wp->rx_buf, 1, NULL, &wp->rx_ov) ||
        (e = GetLastError()) == ERROR_IO_PENDING) {
        wp->rx_pending = true;
        return 0;
    }
    if (e == ERROR_TIMEOUT) { /* Wine: the read's timeout passed at once */
        wp->stats.empty_reads++;
        return 0;
    }
    mark_gone(wp, "read", e);
    return -1;
}

/* Read what the driver has queued behind the first byte into rx_buf from `have` on (the
 * bytes are there: the read completes at once). Returns the new count, or -1 when gone. */
static int read_queued(j288_windows_t *wp, DWORD have)
{
    COMSTAT st;
    DWORD errs, n = 0, want;
    OVERLAPPED ov;
    memset(&st, 0, sizeof st);
    if (!ClearCommError(wp->h, &errs, &st) || st.cbInQue == 0u)
        return (int)have;
    want = (DWORD)sizeof wp->rx_buf - have;
    if (st.cbInQue < want)
        want = st.cbInQue;
    memset(&ov, 0, sizeof ov);
    ov.hEvent = wp->tx_event; /* free: no write is in flight while we read */
    if (!ReadFile(wp->h, wp->rx_buf + have, want, NULL, &ov) &&
        GetLastError() != ERROR_IO_PENDING) {
        mark_gone(wp, "read", GetLastError());
        return -1;
    }
    if (!GetOverlappedResult(wp->h, &ov, &n, TRUE) && GetLastError() != ERROR_TIMEOUT) {
        mark_gone(wp, "read", GetLastError());
        return -1;
    }
    return (int)(have + n);
}

/* Take the result of a completed read, and what is queued behind its byte: hand the bytes to
 * the bus (deliver) or drop them. Returns the byte count (0: still pending, or ended empty),
 * or -1 when the device is gone. */
static int finish_read(j288_windows_t *wp, bool deliver)
{
    DWORD n = 0;
    DWORD e;
    int got;
    if (!wp->rx_pending)
        return 0;
    if (!GetOverlappedResult(wp->h, &wp->rx_ov, &n, FALSE)) {
        e = GetLastError();
        if (e == ERROR_IO_INCOMPLETE)
            return 0;
        wp->rx_pending = false;
        /* The read's own timeout: Windows reports success with 0 bytes, Wine ERROR_TIMEOUT. */
        if (e == ERROR_TIMEOUT) {
            wp->stats.empty_reads++;
            return 0;
        }
        mark_gone(wp, "read", e);
        return -1;
    }
    wp->rx_pending = false;
    if (n == 0u) {
        wp->stats.empty_reads++;
        return 0;
    }
    got = read_queued(wp, n);
    if (got < 0)
        return -1;
    if (deliver) {
        wp->stats.rx_bytes += (uint32_t)got;
        if (wp->bus != NULL)
            j288_bus_on_rx(wp->bus, wp->rx_buf, (size_t)got);
    } else {
        wp->stats.flushed_bytes += (uint32_t)got;
    }
    return got;
}

/* Drop whatever arrived before a transmit: the completed read's bytes and the driver's
 * queue (only when no read is in flight: one in flight would have taken them). */
static int drop_stale(j288_windows_t *wp)
{
    COMSTAT st;
    DWORD errs;
    if (finish_read(wp, false) < 0)
        return -1;
    if (!wp->rx_pending && ClearCommError(wp->h, &errs, &st) && st.cbInQue > 0u) {
        wp->stats.flushed_bytes += (uint32_t)st.cbInQue;
        (void)PurgeComm(wp->h, PURGE_RXCLEAR);
    }
    return 0;
}

static int write_all(j288_windows_t *wp, const uint8_t *data, size_t len)
{
    DWORD n = 0;
    DWORD e = ERROR_SUCCESS;
    BOOL ok;
    char t[160];
    memset(&wp->tx_ov, 0, sizeof wp->tx_ov);
    wp->tx_ov.hEvent = wp->tx_event;
    ok = WriteFile(wp->h, data, (DWORD)len, NULL, &wp->tx_ov);
    if (!ok && (e = GetLastError()) == ERROR_IO_PENDING) {
        /* The driver's write timeout ends it first; this bound is for a driver that hangs. */
        if (WaitForSingleObject(wp->tx_event, 2u * WRITE_STALL_MS) != WAIT_OBJECT_0) {
            (void)CancelIoEx(wp->h, &wp->tx_ov);
            (void)WaitForSingleObject(wp->tx_event, WRITE_STALL_MS);
            set_err(wp, "%s: write stalled for %u ms", wp->dev, 2u * WRITE_STALL_MS);
            return J288_ERR_PORT;
        }
        ok = TRUE;
    }
    if (ok && !GetOverlappedResult(wp->h, &wp->tx_ov, &n, FALSE)) {
        ok = FALSE;
        e = GetLastError();
    }
    if (!ok) {
        mark_gone(wp, "write", e);
        return J288_ERR_OFFLINE;
    }
    if ((size_t)n != len) {
        set_err(wp, "%s: write timed out after %lu of %lu bytes (%s)", wp->dev, (unsigned long)n,
                (unsigned long)len, win_text(ERROR_TIMEOUT, t, sizeof t));
        return J288_ERR_PORT;
    }
    wp->stats.tx_bytes += (uint32_t)len;
    return J288_OK;
}

/* ---- port operations ------------------------------------------------------------------------ */

static int port_start_tx(void *ctx, const uint8_t *data, size_t len)
{
    j288_windows_t *wp = ctx;
    bool was_gone = wp->gone;
    int rc = J288_ERR_OFFLINE;
    if (wp->h == INVALID_HANDLE_VALUE)
        return J288_ERR_PORT;
    if (!was_gone && drop_stale(wp) == 0)
        rc = write_all(wp, data, len);
    if (rc == J288_ERR_OFFLINE) {
        /* As on Linux: the attempt ends through the bus's line-gone event (J288_ERR_OFFLINE),
         * sent by mark_gone() just now, or here for a device lost earlier. */
        if (was_gone && wp->bus != NULL)
            j288_bus_on_error(wp->bus, J288_LINE_GONE);
        return J288_OK;
    }
    if (rc != J288_OK)
        return rc;
    wp->idle_pending = false;
    if (wp->bus != NULL)
        j288_bus_on_tx_done(wp->bus);
    return J288_OK;
}

static uint32_t port_now_us(void *ctx)
{
    (void)ctx;
    return j288_windows_now_us();
}

static void port_arm_timeout(void *ctx, uint32_t deadline_us)
{
    j288_windows_t *wp = ctx;
    wp->timer_us = deadline_us;
    wp->timer_armed = true;
}

bool j288_windows_next_deadline(const j288_windows_t *wp, uint32_t *at_us)
{
    bool any = false;
    uint32_t at = 0;
    if (wp == NULL || at_us == NULL)
        return false;
    if (wp->timer_armed) {
        at = wp->timer_us;
        any = true;
    }
    if (wp->idle_pending) {
        uint32_t idle_at = wp->last_rx_us + wp->opt.idle_us;
        if (!any || us_until(idle_at, at) < 0)
            at = idle_at;
        any = true;
    }
    *at_us = at;
    return any;
}

/* Deliver the timer and idle events that are due. Returns true if one was delivered. */
static bool deliver_due(j288_windows_t *wp, uint32_t now)
{
    bool any = false;
    if (wp->timer_armed && us_until(wp->timer_us, now) <= 0) {
        wp->timer_armed = false;
        if (wp->bus != NULL)
            j288_bus_on_timer(wp->bus);
        any = true;
    }
    if (wp->idle_pending && us_until(wp->last_rx_us + wp->opt.idle_us, now) <= 0) {
        wp->idle_pending = false;
        if (wp->bus != NULL)
            j288_bus_on_rx_idle(wp->bus);
        any = true;
    }
    return any;
}

/* Milliseconds for a Win32 wait, rounded up so that a short wait does not become a spin. */
static DWORD wait_ms(int32_t us)
{
    return (us <= 0) ? 0u : (DWORD)(((uint32_t)us + 999u) / 1000u);
}

/* Deliver what the read in flight has completed with. Returns the bytes (0: none yet), or -1
 * when the device is gone. */
static int take_input(j288_windows_t *wp)
{
    int n = finish_read(wp, true);
    if (n > 0) {
        wp->idle_pending = true;
        wp->last_rx_us = j288_windows_now_us();
    }
    return n;
}

static int port_wait(void *ctx, uint32_t until_us)
{
    j288_windows_t *wp = ctx;
    uint32_t now = j288_windows_now_us();
    int32_t left = us_until(until_us, now);
    uint32_t at;
    int n;
    if (wp->h == INVALID_HANDLE_VALUE || wp->gone)
        return J288_ERR_OFFLINE;
    wp->stats.waits++;
    if (j288_windows_next_deadline(wp, &at) && us_until(at, now) <= 0) {
        /* As on Linux: bytes already here go to the bus before a deadline is judged, so that
         * a host waking late does not time out a reply that came in time. */
        if (start_read(wp) < 0 || take_input(wp) < 0)
            return J288_ERR_OFFLINE;
        now = j288_windows_now_us();
    }
    if (deliver_due(wp, now))
        return J288_OK;
    if (j288_windows_next_deadline(wp, &at) && us_until(at, now) < left)
        left = us_until(at, now);
    if (start_read(wp) < 0)
        return J288_ERR_OFFLINE;
    if (wp->rx_pending)
        (void)WaitForSingleObject(wp->rx_event, wait_ms(left));
    else
        Sleep(wait_ms(left)); /* the read ended at once (ERROR_TIMEOUT): do not spin */
    n = take_input(wp);
    if (n < 0)
        return J288_ERR_OFFLINE;
    if (n == 0)
        (void)deliver_due(wp, j288_windows_now_us());
    return J288_OK;
}

HANDLE j288_windows_read_event(j288_windows_t *wp)
{
    if (wp == NULL || wp->h == INVALID_HANDLE_VALUE || wp->gone)
        return NULL;
    if (start_read(wp) < 0)
        return NULL;
    if (!wp->rx_pending) /* ended empty at once (Wine): look again next round */
        (void)SetEvent(wp->rx_event);
    return wp->rx_event;
}

int j288_windows_service(j288_windows_t *wp)
{
    if (wp == NULL)
        return J288_ERR_NULL;
    return port_wait(wp, j288_windows_now_us());
}

unsigned j288_windows_wait_any(j288_windows_t *const ports[], unsigned n, uint32_t timeout_us,
                               bool ready[])
{
    HANDLE ev[J288_WINDOWS_WAIT_MAX];
    unsigned who[J288_WINDOWS_WAIT_MAX];
    DWORD count = 0, i;
    DWORD ms = wait_ms((int32_t)(timeout_us > INT32_MAX ? INT32_MAX : timeout_us));
    unsigned k, got = 0;
    if (n > J288_WINDOWS_WAIT_MAX)
        n = J288_WINDOWS_WAIT_MAX;
    for (k = 0; k < n; k++) {
        HANDLE h = j288_windows_read_event(ports[k]);
        ready[k] = false;
        if (h == NULL)
            continue;
        ev[count] = h;
        who[count] = k;
        count++;
    }
    if (count == 0u) {
        Sleep(ms);
        return 0;
    }
    if (WaitForMultipleObjects(count, ev, FALSE, ms) == WAIT_TIMEOUT)
        return 0;
    /* It names only the first signalled event: look at each. */
    for (i = 0; i < count; i++) {
        if (WaitForSingleObject(ev[i], 0) == WAIT_OBJECT_0) {
            ready[who[i]] = true;
            got++;
        }
    }
    return got;
}

/* No start_rx (a read is always in flight), no set_dir (the adapter switches direction
 * itself), no crc32, no lock/unlock (one thread owns the port and its bus). */
const j288_port_t j288_windows_port = {
    .start_tx = port_start_tx,
    .now_us = port_now_us,
    .arm_timeout = port_arm_timeout, /* wait() wakes at the deadline */
    .wait = port_wait,
};

/* ---- bus glue and run helpers --------------------------------------------------------------- */

void j288_windows_bus_config(const j288_windows_t *wp, j288_bus_config_t *cfg)
{
    if (cfg == NULL)
        return;
    memset(cfg, 0, sizeof *cfg);
    if (wp == NULL)
        return;
    cfg->baud = (wp->baud_actual != 0u) ? wp->baud_actual : wp->baud;
    cfg->margin_us = (wp->opt.margin_us != 0u) ? wp->opt.margin_us : J288_WINDOWS_DEFAULT_MARGIN_US;
    cfg->echo = wp->opt.echo;
}

int j288_windows_bus_init(j288_windows_t *wp, j288_bus_t *bus, const j288_bus_config_t *cfg)
{
    j288_bus_config_t def;
    if (wp == NULL || bus == NULL)
        return J288_ERR_NULL;
    if (cfg == NULL) {
        j288_windows_bus_config(wp, &def);
        cfg = &def;
    }
    wp->bus = bus;
    return j288_bus_init(bus, &j288_windows_port, wp, cfg);
}

void j288_windows_set_stop_flag(j288_windows_t *wp, const volatile sig_atomic_t *flag)
{
    if (wp != NULL)
        wp->stop_flag = flag;
}

static bool work_pending(const j288_windows_t *wp, const j288_sched_t *s)
{
    if (s != NULL && j288_sched_busy(s))
        return true;
    return !j288_bus_is_idle(wp->bus);
}

static void poll_once(j288_windows_t *wp, j288_sched_t *s, uint32_t now)
{
    if (s != NULL)
        j288_sched_poll(s, now);
    else
        j288_bus_poll(wp->bus, now);
}

int j288_windows_run(j288_windows_t *wp, j288_sched_t *s, uint32_t until_us, unsigned flags)
{
    bool until_idle = (flags & J288_WINDOWS_RUN_UNTIL_IDLE) != 0u;
    bool see_stop =
        (flags & J288_WINDOWS_RUN_IGNORE_STOP) == 0u && wp != NULL && wp->stop_flag != NULL;
    if (wp == NULL || wp->bus == NULL)
        return J288_ERR_NULL;
    for (;;) {
        uint32_t now = j288_windows_now_us();
        uint32_t slice;
        bool pending;
        poll_once(wp, s, now);
        if (wp->gone)
            return J288_ERR_OFFLINE;
        pending = work_pending(wp, s);
        if (until_idle && !pending)
            return J288_OK;
        if (see_stop && *wp->stop_flag != 0)
            return J288_ERR_ABORTED;
        if (us_until(until_us, now) <= 0)
            return until_idle ? J288_ERR_TIMEOUT : J288_OK;
        slice = (uint32_t)us_until(until_us, now);
        if (pending && slice > RUN_SLICE_US)
            slice = RUN_SLICE_US;
        if (wp->stop_flag != NULL && slice > STOP_SLICE_US)
            slice = STOP_SLICE_US;
        if (port_wait(wp, now + slice) == J288_ERR_OFFLINE) {
            /* Let the bus and scheduler see the line-gone event before returning. */
            poll_once(wp, s, j288_windows_now_us());
            return J288_ERR_OFFLINE;
        }
    }
}

int j288_windows_sweep(j288_windows_t *wp, j288_sched_t *s, uint32_t timeout_us)
{
    uint32_t now;
    int rc;
    if (wp == NULL || s == NULL || wp->bus == NULL)
        return J288_ERR_NULL;
    if (wp->gone)
        return J288_ERR_OFFLINE;
    now = j288_windows_now_us();
    rc = j288_sched_start_sweep(s, now);
    if (rc != J288_OK)
        return rc;
    if (timeout_us == 0u)
        timeout_us = 1000000u;
    return j288_windows_run(wp, s, now + timeout_us, J288_WINDOWS_RUN_UNTIL_IDLE);
}

/* ---- inspection ---------------------------------------------------------------------------- */

const char *j288_windows_error(const j288_windows_t *wp)
{
    return (wp == NULL) ? "no port" : wp->err;
}

const char *j288_windows_notices(const j288_windows_t *wp)
{
    return (wp == NULL) ? "" : wp->notice;
}

const char *j288_windows_device(const j288_windows_t *wp)
{
    return (wp == NULL) ? "" : wp->dev;
}

uint32_t j288_windows_baud(const j288_windows_t *wp)
{
    return (wp == NULL || wp->h == INVALID_HANDLE_VALUE) ? 0u : wp->baud_actual;
}

bool j288_windows_offline(const j288_windows_t *wp)
{
    return wp == NULL || wp->gone;
}

const j288_windows_stats_t *j288_windows_stats(const j288_windows_t *wp)
{
    return (wp == NULL) ? NULL : &wp->stats;
}
