/*
 * j288_windows.h - the Windows side of the desktop serial port (j288_serial.h, which includes
 * this: include that). A Win32 serial port (COM1 ... COM256: a USB-to-single-wire adapter's
 * virtual COM port) under the core of port/desktop; this file opens, sets the line, reads,
 * writes and waits.
 *
 * - Opens "COMn" (or "\\.\COMn"; the short name is turned into the long form, which every
 *   COM number needs above COM9) with CreateFile, exclusive (share mode 0: a second program
 *   gets "in use by another program"; Windows does not say which one), overlapped.
 * - SetCommState: raw 8N1, no flow control, the requested baud rate handed to the driver as
 *   is. A driver that refuses the rate (SetCommState fails) or reads back another one is a
 *   clear error (J288_ERR_BAD_CONFIG), never a silent fallback.
 * - Read timeouts "return what is queued, else wait for the first byte" (ReadIntervalTimeout
 *   and ReadTotalTimeoutMultiplier MAXDWORD, ReadTotalTimeoutConstant
 *   J288_WINDOWS_READ_SLICE_MS): one overlapped ReadFile of one byte is kept in flight, so
 *   that an event handle says "bytes are there" (j288_serial_wait_any() waits for several
 *   ports in one WaitForMultipleObjects()). A read that ends on its own timeout completes
 *   with 0 bytes on Windows and with ERROR_TIMEOUT under Wine: both mean "nothing yet". No
 *   WaitCommEvent (a pending one cannot be cancelled under Wine).
 * - Overlapped WriteFile, waited for (bounded) before the bus hears "transmit done".
 * - QueryPerformanceCounter for the bus's microsecond clock; timeBeginPeriod(1) while a port
 *   is open, so that waits on reply deadlines wake within a millisecond.
 * - A read or write failing with an I/O error (USB adapter unplugged) means the device
 *   vanished.
 *
 * Latency: an FTDI adapter's driver holds received bytes up to its latency timer (16 ms by
 * default; Device Manager > the COM port > Port Settings > Advanced > Latency Timer, set 1).
 * The default reply margin (20 ms) covers the default timer; lower margin_us after lowering it.
 */
#ifndef J288_WINDOWS_H
#define J288_WINDOWS_H

#ifndef WIN32_LEAN_AND_MEAN
#define WIN32_LEAN_AND_MEAN
#endif
#include <windows.h>

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ReadTotalTimeoutConstant of the read kept in flight: with no byte for this long it
 * completes empty and is issued again (a bound on how long close() waits for it, too). */
#define J288_WINDOWS_READ_SLICE_MS 100u

/* The Windows part of a j288_serial_t. Private. */
typedef struct {
    HANDLE h;        /* INVALID_HANDLE_VALUE when closed */
    HANDLE rx_event; /* manual-reset, the read's */
    HANDLE tx_event; /* manual-reset, the write's */
    OVERLAPPED rx_ov;
    OVERLAPPED tx_ov;
    bool rx_pending; /* a ReadFile into rx_byte is in flight */
    uint8_t rx_byte;
} j288_serial_os_t;

/* "COM5" -> "\\.\COM5" (names already in the long form, or other paths, unchanged) into out.
 * Returns false when it does not fit in cap. Pure; any thread. */
bool j288_windows_device_path(const char *dev, char *out, size_t cap);

/* Whether two names ("COM5", "\\.\com5") name the same port: equal in the long form, case
 * ignored (Windows' device names are). False when either is NULL or too long. Pure. */
bool j288_windows_same_device(const char *a, const char *b);

#ifdef __cplusplus
}
#endif

#endif /* J288_WINDOWS_H */
