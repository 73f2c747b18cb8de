/*
 * j288_serial.c - the desktop serial core (see j288_serial.h for the contract): what Linux
 * and Windows share, written once over the OS interface of j288_serial_os.h.
 */
#include "j288_serial_os.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

/* The most bytes taken from the OS per read (a reply is 26; more only after a long sleep). */
#define READ_CHUNK 256u

/* Signed distance from now to t in the bus's wrapping microsecond clock. */
static int32_t us_until(uint32_t t, uint32_t now)
{
    return (int32_t)(t - now);
}

/* ---- for the OS files ---------------------------------------------------------------------- */

void j288_serial_set_err(j288_serial_t *sp, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    (void)vsnprintf(sp->err, sizeof sp->err, fmt, ap);
    va_end(ap);
}

void j288_serial_add_notice(j288_serial_t *sp, const char *fmt, ...)
{
    size_t used = strlen(sp->notice);
    size_t room = sizeof sp->notice - used;
    va_list ap;
    int n;
    if (room < 2u)
        return;
    va_start(ap, fmt);
    n = vsnprintf(sp->notice + used, room - 1u, fmt, ap);
    va_end(ap);
    if (n < 0)
        return;
    used = strlen(sp->notice);
    sp->notice[used] = '\n';
    sp->notice[used + 1u] = '\0';
}

void j288_serial_gone(j288_serial_t *sp, const char *what, const char *why)
{
    if (sp->gone)
        return;
    sp->gone = true;
    if (why != NULL)
        j288_serial_set_err(sp, "%s vanished (%s: %s): adapter unplugged or simulator exited",
                            sp->dev, what, why);
    else
        j288_serial_set_err(sp, "%s vanished (%s): adapter unplugged or simulator exited",
                            sp->dev, what);
    if (sp->bus != NULL)
        j288_bus_on_error(sp->bus, J288_LINE_GONE);
}

void j288_serial_copy_str(char *out, size_t cap, const char *in)
{
    size_t n = strlen(in);
    if (n >= cap)
        n = cap - 1u;
    memcpy(out, in, n);
    out[n] = '\0';
}

/* ---- open and close --------------------------------------------------------------------------- */

bool j288_serial_baud_ok(uint32_t asked, uint32_t got)
{
    uint32_t diff = (got > asked) ? got - asked : asked - got;
    /* 64-bit products: asked * 100 overflows 32 bits above 42.9 Mbaud. */
    return asked != 0u && got != 0u &&
           (uint64_t)diff * 100u <= (uint64_t)asked * J288_SERIAL_BAUD_TOLERANCE_PCT;
}

static void reset_object(j288_serial_t *sp)
{
    memset(sp, 0, sizeof *sp);
    j288_serial_os_reset(sp);
}

/* The line at sp->baud, read back: J288_OK and baud_actual set, or an error (sp->err). */
static int set_line(j288_serial_t *sp, const char *dev)
{
    uint32_t got = 0;
    int rc = j288_serial_os_set_line(sp, sp->baud, &got);
    if (rc != J288_OK)
        return rc;
    if (!j288_serial_baud_ok(sp->baud, got)) {
        j288_serial_set_err(sp, "%s: the adapter cannot do %lu baud (it reports %lu)", dev,
                            (unsigned long)sp->baud, (unsigned long)got);
        return J288_ERR_BAD_CONFIG;
    }
    sp->baud_actual = got;
    return J288_OK;
}

int j288_serial_open(j288_serial_t *sp, const char *dev, uint32_t baud,
                     const j288_serial_options_t *opt)
{
    int rc;
    if (sp == NULL)
        return J288_ERR_NULL;
    reset_object(sp);
    if (dev == NULL) {
        j288_serial_set_err(sp, "no device given");
        return J288_ERR_NULL;
    }
    if (opt != NULL)
        sp->opt = *opt;
    if (sp->opt.margin_us == 0u)
        sp->opt.margin_us = J288_SERIAL_DEFAULT_MARGIN_US;
    if (sp->opt.idle_us == 0u)
        sp->opt.idle_us = J288_SERIAL_DEFAULT_IDLE_US;
    sp->baud = (baud == 0u) ? J288_DEFAULT_BAUD : baud;
    j288_serial_copy_str(sp->dev, sizeof sp->dev, dev);
    rc = j288_serial_os_open(sp, dev);
    if (rc != J288_OK)
        return rc;
    rc = set_line(sp, dev);
    if (rc != J288_OK) {
        j288_serial_os_close(sp);
        sp->baud_actual = 0;
        return rc;
    }
    j288_serial_os_ready(sp);
    return J288_OK;
}

void j288_serial_close(j288_serial_t *sp)
{
    if (sp == NULL || !j288_serial_os_is_open(sp))
        return;
    j288_serial_os_close(sp);
    sp->bus = NULL;
    sp->baud_actual = 0;
}

/* ---- input ---------------------------------------------------------------------------------- */

/* Take everything the OS has: to the bus (deliver) or dropped (stale input before a
 * transmit). Returns the byte count, or -1 when the device is gone. */
static int drain(j288_serial_t *sp, bool deliver)
{
    uint8_t buf[READ_CHUNK];
    int total = 0;
    for (;;) {
        int n = j288_serial_os_read(sp, buf, sizeof buf);
        if (n < 0)
            return -1;
        if (n > 0 && deliver) {
            sp->stats.rx_bytes += (uint32_t)n;
            if (sp->bus != NULL)
                j288_bus_on_rx(sp->bus, buf, (size_t)n);
        } else if (n > 0) {
            sp->stats.flushed_bytes += (uint32_t)n;
        }
        total += n;
        if ((size_t)n < sizeof buf)
            return total;
    }
}

/* Wait up to timeout_us for input and hand what comes to the bus. Returns the bytes (0:
 * none), or -1 when the device is gone. */
static int take_input(j288_serial_t *sp, uint32_t timeout_us)
{
    int n = j288_serial_os_wait_input(sp, timeout_us);
    if (n > 0)
        n = drain(sp, true);
    if (n > 0) {
        sp->idle_pending = true;
        sp->last_rx_us = j288_serial_now_us();
    }
    return n;
}

/* ---- port operations ------------------------------------------------------------------------ */

static int port_start_tx(void *ctx, const uint8_t *data, size_t len)
{
    j288_serial_t *sp = ctx;
    bool was_gone = sp->gone;
    int rc = J288_ERR_OFFLINE;
    if (!j288_serial_os_is_open(sp))
        return J288_ERR_PORT;
    /* Nothing received before this command can be its reply: drop it here, where it cannot
     * be mistaken for one. */
    if (!was_gone && drain(sp, false) >= 0)
        rc = j288_serial_os_write(sp, data, len);
    if (rc == J288_ERR_OFFLINE) {
        /* The attempt learns of it through the bus's line-gone event, which ends it with
         * J288_ERR_OFFLINE at once (an error return would read as a generic J288_ERR_PORT).
         * j288_serial_gone() sent the event if the loss was found just now; a device lost
         * earlier needs one for this attempt. */
        if (was_gone && sp->bus != NULL)
            j288_bus_on_error(sp->bus, J288_LINE_GONE);
        return J288_OK;
    }
    if (rc != J288_OK)
        return rc;
    sp->stats.tx_bytes += (uint32_t)len;
    sp->idle_pending = false;
    /* The OS has the bytes; the bus's reply budget counts from the start of transmit and its
     * margin covers the USB path. */
    if (sp->bus != NULL)
        j288_bus_on_tx_done(sp->bus);
    return J288_OK;
}

static uint32_t port_now_us(void *ctx)
{
    (void)ctx;
    return j288_serial_now_us();
}

static void port_arm_timeout(void *ctx, uint32_t deadline_us)
{
    j288_serial_t *sp = ctx;
    sp->timer_us = deadline_us;
    sp->timer_armed = true;
}

/* Deliver the timer and idle events that are due. Returns true if one was delivered. */
static bool deliver_due(j288_serial_t *sp, uint32_t now)
{
    bool any = false;
    if (sp->timer_armed && us_until(sp->timer_us, now) <= 0) {
        sp->timer_armed = false;
        if (sp->bus != NULL)
            j288_bus_on_timer(sp->bus);
        any = true;
    }
    if (sp->idle_pending && us_until(sp->last_rx_us + sp->opt.idle_us, now) <= 0) {
        sp->idle_pending = false;
        if (sp->bus != NULL)
            j288_bus_on_rx_idle(sp->bus);
        any = true;
    }
    return any;
}

static int port_wait(void *ctx, uint32_t until_us)
{
    j288_serial_t *sp = ctx;
    uint32_t now = j288_serial_now_us();
    int32_t left = us_until(until_us, now);
    uint32_t at;
    int n;
    if (!j288_serial_os_is_open(sp) || sp->gone)
        return J288_ERR_OFFLINE;
    sp->stats.waits++;
    if (j288_serial_next_deadline(sp, &at) && us_until(at, now) <= 0) {
        /* Bytes already here go to the bus before a deadline is judged (the engine takes its
         * events before its deadline too): a host that wakes past the deadline, on a loaded
         * machine, must not time out a reply that came in time and then count it as stale
         * bytes in the next window. */
        if (take_input(sp, 0u) < 0)
            return J288_ERR_OFFLINE;
        now = j288_serial_now_us();
    }
    if (deliver_due(sp, now))
        return J288_OK;
    if (left < 0)
        left = 0;
    if (j288_serial_next_deadline(sp, &at) && us_until(at, now) < left)
        left = us_until(at, now); /* (in the future: none was due) */
    n = take_input(sp, (uint32_t)left);
    if (n < 0)
        return J288_ERR_OFFLINE;
    if (n == 0)
        (void)deliver_due(sp, j288_serial_now_us());
    return J288_OK;
}

/* No start_rx (the receiver is always on), no set_dir (the adapter switches direction
 * itself), no crc32, no lock/unlock (one thread owns the port and its bus). */
const j288_port_t j288_serial_port = {
    .start_tx = port_start_tx,
    .now_us = port_now_us,
    .arm_timeout = port_arm_timeout, /* wait() wakes at the deadline */
    .wait = port_wait,
};

/* ---- the bus -------------------------------------------------------------------------------- */

void j288_serial_bus_config(const j288_serial_t *sp, j288_bus_config_t *cfg)
{
    if (cfg == NULL)
        return;
    memset(cfg, 0, sizeof *cfg);
    if (sp == NULL)
        return;
    cfg->baud = (sp->baud_actual != 0u) ? sp->baud_actual : sp->baud;
    cfg->margin_us =
        (sp->opt.margin_us != 0u) ? sp->opt.margin_us : J288_SERIAL_DEFAULT_MARGIN_US;
    cfg->echo = sp->opt.echo;
}

int j288_serial_bus_init(j288_serial_t *sp, j288_bus_t *bus, const j288_bus_config_t *cfg)
{
    j288_bus_config_t def;
    if (sp == NULL || bus == NULL)
        return J288_ERR_NULL;
    if (cfg == NULL) {
        j288_serial_bus_config(sp, &def);
        cfg = &def;
    }
    sp->bus = bus;
    return j288_bus_init(bus, &j288_serial_port, sp, cfg);
}

bool j288_serial_next_deadline(const j288_serial_t *sp, uint32_t *at_us)
{
    bool any = false;
    uint32_t at = 0;
    if (sp == NULL || at_us == NULL)
        return false;
    if (sp->timer_armed) {
        at = sp->timer_us;
        any = true;
    }
    if (sp->idle_pending) {
        uint32_t idle_at = sp->last_rx_us + sp->opt.idle_us;
        if (!any || us_until(idle_at, at) < 0)
            at = idle_at;
        any = true;
    }
    if (any)
        *at_us = at;
    return any;
}

int j288_serial_service(j288_serial_t *sp)
{
    if (sp == NULL)
        return J288_ERR_NULL;
    return port_wait(sp, j288_serial_now_us());
}

/* ---- inspection ------------------------------------------------------------------------------ */

const char *j288_serial_error(const j288_serial_t *sp)
{
    return (sp == NULL) ? "no port" : sp->err;
}

const char *j288_serial_notices(const j288_serial_t *sp)
{
    return (sp == NULL) ? "" : sp->notice;
}

const char *j288_serial_device(const j288_serial_t *sp)
{
    return (sp == NULL) ? "" : sp->dev;
}

uint32_t j288_serial_baud(const j288_serial_t *sp)
{
    return (sp == NULL || !j288_serial_os_is_open(sp)) ? 0u : sp->baud_actual;
}

bool j288_serial_offline(const j288_serial_t *sp)
{
    return sp == NULL || sp->gone;
}

const j288_serial_stats_t *j288_serial_stats(const j288_serial_t *sp)
{
    return (sp == NULL) ? NULL : &sp->stats;
}
