/*
 * j288_windows.c - the Windows side of the desktop serial port (j288_windows.h; the contract
 * is j288_serial.h, the interface j288_serial_os.h): open, line settings, read, write, wait.
 *
 * One overlapped read of ONE byte is kept in flight with the timeouts "return what is
 * queued, else wait for the first byte, at most J288_WINDOWS_READ_SLICE_MS": its event is what
 * a wait (one port's, or j288_serial_wait_any()'s over several) sleeps on, so that a reply
 * wakes the thread at once, with no WaitCommEvent (which Wine cannot cancel). When it
 * completes, the bytes queued behind it (ClearCommError's count) are read at once. One byte,
 * because Wine's overlapped read does not return early with what came: a read of 256 bytes
 * waited for all 256 (measured under Wine 8.0: ten replies per read, every transaction timed
 * out). Reads are never cancelled except at close.
 */
#ifndef _WIN32_WINNT
#define _WIN32_WINNT 0x0600 /* CancelIoEx: Vista and later */
#endif

#include "j288_serial_os.h"

#include <mmsystem.h>

#include <stdint.h>
#include <stdio.h>
#include <string.h>

/* A write that does not complete in this long means the adapter is stuck. */
#define WRITE_STALL_MS 200u

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

/* The device vanished (j288_serial_gone()), with the system's word for why. */
static void gone(j288_serial_t *sp, const char *what, DWORD e)
{
    char t[160];
    j288_serial_gone(sp, what, win_text(e, t, sizeof t));
}

uint32_t j288_serial_now_us(void)
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

/* Milliseconds for a Win32 wait, rounded up so that a short wait does not become a spin. */
static DWORD wait_ms(uint32_t us)
{
    if (us > (uint32_t)INT32_MAX)
        us = (uint32_t)INT32_MAX;
    return (DWORD)((us + 999u) / 1000u);
}

/* ---- names -------------------------------------------------------------------------------- */

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
    char la[sizeof((j288_serial_t *)0)->dev + 4u], lb[sizeof la];
    return a != NULL && b != NULL && j288_windows_device_path(a, la, sizeof la) &&
           j288_windows_device_path(b, lb, sizeof lb) && _stricmp(la, lb) == 0;
}

bool j288_serial_same_device(const j288_serial_t *sp, const char *dev)
{
    return sp != NULL && sp->os.h != INVALID_HANDLE_VALUE &&
           j288_windows_same_device(dev, sp->dev);
}

/* ---- open ---------------------------------------------------------------------------------- */

void j288_serial_os_reset(j288_serial_t *sp)
{
    sp->os.h = INVALID_HANDLE_VALUE;
}

bool j288_serial_os_is_open(const j288_serial_t *sp)
{
    return sp->os.h != INVALID_HANDLE_VALUE;
}

static int open_error(j288_serial_t *sp, DWORD e)
{
    char t[160];
    if (e == ERROR_FILE_NOT_FOUND || e == ERROR_PATH_NOT_FOUND) {
        j288_serial_set_err(sp, "%s: no such port (adapter unplugged? see Device Manager > Ports)",
                            sp->dev);
        return J288_ERR_OFFLINE;
    }
    if (e == ERROR_ACCESS_DENIED || e == ERROR_SHARING_VIOLATION) {
        j288_serial_set_err(sp, "%s is in use by another program (a COM port opens only once)",
                            sp->dev);
        return J288_ERR_BUSY;
    }
    j288_serial_set_err(sp, "%s: cannot open: %s", sp->dev, win_text(e, t, sizeof t));
    return J288_ERR_OFFLINE;
}

static int make_events(j288_serial_t *sp)
{
    char t[160];
    sp->os.rx_event = CreateEventA(NULL, TRUE, FALSE, NULL);
    sp->os.tx_event = CreateEventA(NULL, TRUE, FALSE, NULL);
    if (sp->os.rx_event == NULL || sp->os.tx_event == NULL) {
        j288_serial_set_err(sp, "cannot create events (%s)", win_text(GetLastError(), t, sizeof t));
        return J288_ERR_PORT;
    }
    return J288_OK;
}

static void release_handles(j288_serial_t *sp)
{
    if (sp->os.h != INVALID_HANDLE_VALUE) {
        (void)CloseHandle(sp->os.h);
        (void)timeEndPeriod(1);
    }
    if (sp->os.rx_event != NULL)
        (void)CloseHandle(sp->os.rx_event);
    if (sp->os.tx_event != NULL)
        (void)CloseHandle(sp->os.tx_event);
    sp->os.h = INVALID_HANDLE_VALUE;
    sp->os.rx_event = NULL;
    sp->os.tx_event = NULL;
}

int j288_serial_os_open(j288_serial_t *sp, const char *dev)
{
    char path[sizeof sp->dev + 4u];
    int rc;
    if (strlen(dev) >= sizeof sp->dev || !j288_windows_device_path(dev, path, sizeof path)) {
        j288_serial_set_err(sp, "device name too long (%lu characters at most)",
                            (unsigned long)(sizeof sp->dev - 1u));
        return J288_ERR_BAD_CONFIG;
    }
    sp->os.h = CreateFileA(path, GENERIC_READ | GENERIC_WRITE, 0 /* exclusive */, NULL,
                           OPEN_EXISTING, FILE_FLAG_OVERLAPPED, NULL);
    if (sp->os.h == INVALID_HANDLE_VALUE)
        return open_error(sp, GetLastError());
    /* Timer waits (reply deadlines, idle) at 1 ms instead of the default 15.6 ms tick. */
    (void)timeBeginPeriod(1);
    rc = make_events(sp);
    if (rc != J288_OK)
        release_handles(sp);
    return rc;
}

static int set_timeouts(j288_serial_t *sp)
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
    if (!SetCommTimeouts(sp->os.h, &to)) {
        j288_serial_set_err(sp, "%s: cannot set timeouts (%s)", sp->dev,
                            win_text(GetLastError(), t, sizeof t));
        return J288_ERR_PORT;
    }
    return J288_OK;
}

int j288_serial_os_set_line(j288_serial_t *sp, uint32_t baud, uint32_t *got)
{
    DCB dcb;
    char t[160];
    memset(&dcb, 0, sizeof dcb);
    dcb.DCBlength = sizeof dcb;
    if (!GetCommState(sp->os.h, &dcb)) {
        j288_serial_set_err(sp, "%s is not a serial port (%s)", sp->dev,
                            win_text(GetLastError(), t, sizeof t));
        return J288_ERR_BAD_CONFIG;
    }
    /* Raw 8N1: no flow control, no character substitution, errors do not abort I/O. */
    dcb.BaudRate = baud;
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
    if (!SetCommState(sp->os.h, &dcb)) {
        j288_serial_set_err(sp, "%s: the driver refuses %lu baud (%s)", sp->dev,
                            (unsigned long)baud, win_text(GetLastError(), t, sizeof t));
        return J288_ERR_BAD_CONFIG;
    }
    if (!GetCommState(sp->os.h, &dcb)) {
        j288_serial_set_err(sp, "%s: cannot read back line settings (%s)", sp->dev,
                            win_text(GetLastError(), t, sizeof t));
        return J288_ERR_PORT;
    }
    *got = (uint32_t)dcb.BaudRate;
    return set_timeouts(sp);
}

void j288_serial_os_ready(j288_serial_t *sp)
{
    (void)SetupComm(sp->os.h, 4096, 4096); /* a hint; drivers may keep their own sizes */
    /* Bytes queued before we came (a previous program's replies) are not ours. */
    (void)PurgeComm(sp->os.h, PURGE_RXCLEAR | PURGE_TXCLEAR);
}

void j288_serial_os_close(j288_serial_t *sp)
{
    if (sp->os.rx_pending) {
        /* The read writes into *sp: it must be over before we return. It ends by itself
         * within its timeout if the cancel is not honoured. */
        (void)CancelIoEx(sp->os.h, &sp->os.rx_ov);
        (void)WaitForSingleObject(sp->os.rx_event, 2u * J288_WINDOWS_READ_SLICE_MS);
        sp->os.rx_pending = false;
    }
    release_handles(sp);
}

/* ---- I/O ----------------------------------------------------------------------------------- */

/* Put the one-byte read in flight if none is. Returns 0, or -1 when the device is gone. */
static int start_read(j288_serial_t *sp)
{
    DWORD e;
    if (sp->os.rx_pending)
        return 0;
    memset(&sp->os.rx_ov, 0, sizeof sp->os.rx_ov);
    sp->os.rx_ov.hEvent = sp->os.rx_event;
    sp->stats.reads++;
    /* Done at once (TRUE) or pending: either way the event tells, and the read takes the
     * result from the OVERLAPPED. */
    if (ReadFile(sp->os.h, &sp->os.rx_byte, 1, NULL, &sp->os.rx_ov) ||
        (e = GetLastError()) == ERROR_IO_PENDING) {
        sp->os.rx_pending = true;
        return 0;
    }
    if (e == ERROR_TIMEOUT) { /* Wine: the read's timeout passed at once */
        sp->stats.empty_reads++;
        return 0;
    }
    gone(sp, "read", e);
    return -1;
}

/* Bytes in the driver's queue (0 when it cannot say). */
static DWORD queued(const j288_serial_t *sp)
{
    COMSTAT st;
    DWORD errs;
    memset(&st, 0, sizeof st);
    return ClearCommError(sp->os.h, &errs, &st) ? st.cbInQue : 0u;
}

int j288_serial_os_wait_input(j288_serial_t *sp, uint32_t timeout_us)
{
    DWORD ms = wait_ms(timeout_us);
    /* Bytes that came while no read was in flight (after a transmit, before the next wait)
     * are read at once, synchronously: a read started now may complete only later (under
     * Wine, through its server), after a due deadline has been judged. */
    if (!sp->os.rx_pending && queued(sp) > 0u)
        return 1;
    if (start_read(sp) < 0)
        return -1;
    if (sp->os.rx_pending)
        (void)WaitForSingleObject(sp->os.rx_event, ms);
    else if (ms > 0u)
        Sleep(ms); /* the read ended at once (ERROR_TIMEOUT): do not spin */
    return 1;      /* whatever the wait said, the read's own status tells */
}

/* Read what the driver has queued into buf from `have` on (the bytes are there: the read
 * completes at once). Returns the new count, or -1 when gone. */
static int read_queued(j288_serial_t *sp, uint8_t *buf, DWORD have, size_t cap)
{
    DWORD n = 0, want, in_queue = (have < cap) ? queued(sp) : 0u;
    OVERLAPPED ov;
    if (in_queue == 0u)
        return (int)have;
    want = (DWORD)(cap - have);
    if (in_queue < want)
        want = in_queue;
    memset(&ov, 0, sizeof ov);
    ov.hEvent = sp->os.tx_event; /* free: no write is in flight while we read */
    if (!ReadFile(sp->os.h, buf + have, want, NULL, &ov) && GetLastError() != ERROR_IO_PENDING) {
        gone(sp, "read", GetLastError());
        return -1;
    }
    if (!GetOverlappedResult(sp->os.h, &ov, &n, TRUE) && GetLastError() != ERROR_TIMEOUT) {
        gone(sp, "read", GetLastError());
        return -1;
    }
    return (int)(have + n);
}

int j288_serial_os_read(j288_serial_t *sp, uint8_t *buf, size_t cap)
{
    DWORD n = 0;
    DWORD e;
    if (!sp->os.rx_pending)
        return read_queued(sp, buf, 0u, cap);
    if (!GetOverlappedResult(sp->os.h, &sp->os.rx_ov, &n, FALSE)) {
        e = GetLastError();
        if (e == ERROR_IO_INCOMPLETE)
            return 0;
        sp->os.rx_pending = false;
        /* The read's own timeout: Windows reports success with 0 bytes, Wine ERROR_TIMEOUT. */
        if (e == ERROR_TIMEOUT) {
            sp->stats.empty_reads++;
            return 0;
        }
        gone(sp, "read", e);
        return -1;
    }
    sp->os.rx_pending = false;
    if (n == 0u) {
        sp->stats.empty_reads++;
        return 0;
    }
    buf[0] = sp->os.rx_byte;
    return read_queued(sp, buf, 1u, cap);
}

int j288_serial_os_write(j288_serial_t *sp, const uint8_t *data, size_t len)
{
    DWORD n = 0;
    DWORD e = ERROR_SUCCESS;
    BOOL ok;
    char t[160];
    memset(&sp->os.tx_ov, 0, sizeof sp->os.tx_ov);
    sp->os.tx_ov.hEvent = sp->os.tx_event;
    ok = WriteFile(sp->os.h, data, (DWORD)len, NULL, &sp->os.tx_ov);
    if (!ok && (e = GetLastError()) == ERROR_IO_PENDING) {
        /* The driver's write timeout ends it first; this bound is for a driver that hangs. */
        if (WaitForSingleObject(sp->os.tx_event, 2u * WRITE_STALL_MS) != WAIT_OBJECT_0) {
            (void)CancelIoEx(sp->os.h, &sp->os.tx_ov);
            (void)WaitForSingleObject(sp->os.tx_event, WRITE_STALL_MS);
            j288_serial_set_err(sp, "%s: write stalled for %u ms", sp->dev, 2u * WRITE_STALL_MS);
            return J288_ERR_PORT;
        }
        ok = TRUE;
    }
    if (ok && !GetOverlappedResult(sp->os.h, &sp->os.tx_ov, &n, FALSE)) {
        ok = FALSE;
        e = GetLastError();
    }
    if (!ok) {
        gone(sp, "write", e);
        return J288_ERR_OFFLINE;
    }
    if ((size_t)n != len) {
        j288_serial_set_err(sp, "%s: write timed out after %lu of %lu bytes (%s)", sp->dev,
                            (unsigned long)n, (unsigned long)len,
                            win_text(ERROR_TIMEOUT, t, sizeof t));
        return J288_ERR_PORT;
    }
    return J288_OK;
}

/* ---- several ports at once ------------------------------------------------------------------ */

/* Make sure a read is in flight and return the event set when it completes (set already when
 * it ended at once); NULL when the port is closed or gone. */
static HANDLE read_event(j288_serial_t *sp)
{
    if (sp == NULL || sp->os.h == INVALID_HANDLE_VALUE || sp->gone)
        return NULL;
    if (start_read(sp) < 0)
        return NULL;
    if (!sp->os.rx_pending) /* ended empty at once (Wine): look again next round */
        (void)SetEvent(sp->os.rx_event);
    return sp->os.rx_event;
}

unsigned j288_serial_wait_any(j288_serial_t *const ports[], unsigned n, uint32_t timeout_us,
                              bool ready[])
{
    HANDLE ev[J288_SERIAL_WAIT_MAX];
    unsigned who[J288_SERIAL_WAIT_MAX];
    DWORD count = 0, i;
    DWORD ms = wait_ms(timeout_us);
    unsigned k, got = 0;
    if (n > J288_SERIAL_WAIT_MAX)
        n = J288_SERIAL_WAIT_MAX;
    for (k = 0; k < n; k++) {
        HANDLE h = read_event(ports[k]);
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
