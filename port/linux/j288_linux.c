/*
 * j288_linux.c - the Linux port (see j288_linux.h for the contract).
 *
 * termios2 is used instead of <termios.h> because only TCSETS2 with BOTHER sets an arbitrary
 * rate such as 6,000,000; the two struct termios definitions clash, so <termios.h> is not
 * included here.
 */
#define _GNU_SOURCE 1 /* ppoll, flock, realpath, snprintf under -std=c99 */

#include "j288_linux.h"

#include <asm/termbits.h>
#include <linux/serial.h>
#include <sys/ioctl.h>

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <poll.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <time.h>
#include <unistd.h>

/* A write that makes no progress for this long means the adapter is stuck. */
#define WRITE_STALL_MS 200
/* While a transaction is pending, run() wakes at least this often to let the bus check its
 * reply deadline even if the engine arms no timer. */
#define RUN_SLICE_US 1000u
/* With a stop flag set, never sleep longer than this, so a signal that lands just before a
 * sleep is noticed promptly. */
#define STOP_SLICE_US 20000u

static void set_err(j288_linux_t *lp, const char *fmt, ...) __attribute__((format(printf, 2, 3)));

static void set_err(j288_linux_t *lp, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    (void)vsnprintf(lp->err, sizeof lp->err, fmt, ap);
    va_end(ap);
}

static void add_notice(j288_linux_t *lp, const char *fmt, ...)
    __attribute__((format(printf, 2, 3)));

static void add_notice(j288_linux_t *lp, const char *fmt, ...)
{
    size_t used = strlen(lp->notice);
    size_t room = sizeof lp->notice - used;
    va_list ap;
    int n;
    if (room < 2u)
        return;
    va_start(ap, fmt);
    n = vsnprintf(lp->notice + used, room - 1u, fmt, ap);
    va_end(ap);
    if (n < 0)
        return;
    used = strlen(lp->notice);
    lp->notice[used] = '\n';
    lp->notice[used + 1u] = '\0';
}

uint32_t j288_linux_now_us(void)
{
    struct timespec ts;
    (void)clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint32_t)((uint64_t)ts.tv_sec * 1000000u + (uint64_t)ts.tv_nsec / 1000u);
}

/* Signed distance from now to t in the bus's wrapping microsecond clock. */
static int32_t us_until(uint32_t t, uint32_t now)
{
    return (int32_t)(t - now);
}

/* ---- open: exclusivity ------------------------------------------------------------------ */

/* Who holds a flock() on the file with this device and inode? /proc/locks lists
 * "n: FLOCK ADVISORY WRITE pid maj:min:inode start end". 0 when unknown. */
static long lock_holder_pid(dev_t fs_dev, ino_t ino)
{
    FILE *f = fopen("/proc/locks", "r");
    char line[256];
    long found = 0;
    if (f == NULL)
        return 0;
    while (found == 0 && fgets(line, sizeof line, f) != NULL) {
        char kind[16], mode[16], rw[16];
        long pid;
        unsigned maj, min;
        unsigned long inode;
        const char *p = strchr(line, ':');
        if (p == NULL)
            continue;
        if (sscanf(p + 1, "%15s %15s %15s %ld %x:%x:%lu", kind, mode, rw, &pid, &maj, &min,
                   &inode) != 7)
            continue;
        if (maj == major(fs_dev) && min == minor(fs_dev) && (ino_t)inode == ino && pid > 0)
            found = pid;
    }
    (void)fclose(f);
    return found;
}

static int report_in_use(j288_linux_t *lp, const char *dev, int fd)
{
    struct stat st;
    long pid = 0;
    int ok = (fd >= 0) ? fstat(fd, &st) : stat(dev, &st);
    if (ok == 0)
        pid = lock_holder_pid(st.st_dev, st.st_ino);
    if (pid > 0 && pid != (long)getpid())
        set_err(lp, "%s is in use by PID %ld (another program holds the bus)", dev, pid);
    else if (pid > 0)
        set_err(lp, "%s is already open in this process", dev);
    else
        set_err(lp, "%s is in use by another program (held exclusively; no lock holder found)",
                dev);
    return J288_ERR_BUSY;
}

static int take_exclusive(j288_linux_t *lp, const char *dev)
{
    int rc;
    do {
        rc = flock(lp->fd, LOCK_EX | LOCK_NB);
    } while (rc != 0 && errno == EINTR);
    if (rc != 0) {
        if (errno == EWOULDBLOCK)
            return report_in_use(lp, dev, lp->fd);
        set_err(lp, "%s: cannot lock: %s", dev, strerror(errno));
        return J288_ERR_PORT;
    }
    /* TIOCEXCL makes further open() calls fail with EBUSY (except for root, which the
     * flock above still stops). */
    if (ioctl(lp->fd, TIOCEXCL, NULL) != 0) {
        if (errno == ENOTTY || errno == EINVAL) {
            set_err(lp, "%s is not a serial device", dev);
            return J288_ERR_BAD_CONFIG;
        }
        set_err(lp, "%s: cannot get exclusive access: %s", dev, strerror(errno));
        return J288_ERR_PORT;
    }
    return J288_OK;
}

/* ---- open: line settings ----------------------------------------------------------------- */

bool j288_linux_baud_ok(uint32_t asked, uint32_t got)
{
    uint32_t diff = (got > asked) ? got - asked : asked - got;
    /* 64-bit products: asked * 100 overflows 32 bits above 42.9 Mbaud. */
    return asked != 0u && got != 0u &&
           (uint64_t)diff * 100u <= (uint64_t)asked * J288_LINUX_BAUD_TOLERANCE_PCT;
}

static int set_raw_baud(j288_linux_t *lp, const char *dev, uint32_t baud)
{
    struct termios2 t;
    uint32_t got;
    if (ioctl(lp->fd, TCGETS2, &t) != 0) {
        if (errno == ENOTTY || errno == EINVAL) {
            set_err(lp, "%s is not a serial device", dev);
            return J288_ERR_BAD_CONFIG;
        }
        set_err(lp, "%s: cannot read line settings: %s", dev, strerror(errno));
        return J288_ERR_PORT;
    }
    t.c_iflag &= ~(tcflag_t)(IGNBRK | BRKINT | PARMRK | ISTRIP | INLCR | IGNCR | ICRNL | IXON |
                             IXOFF | IXANY | INPCK | IGNPAR);
    t.c_oflag &= ~(tcflag_t)OPOST;
    t.c_lflag &= ~(tcflag_t)(ECHO | ECHONL | ICANON | ISIG | IEXTEN);
    t.c_cflag &= ~(tcflag_t)(CSIZE | PARENB | CSTOPB | CRTSCTS | CBAUD | (CBAUD << IBSHIFT));
    t.c_cflag |= (tcflag_t)(CS8 | CREAD | CLOCAL | BOTHER | (BOTHER << IBSHIFT));
    t.c_ispeed = baud;
    t.c_ospeed = baud;
    /* VMIN 1: a non-blocking read with no data then says EAGAIN, so that 0 means hang-up. */
    t.c_cc[VMIN] = 1;
    t.c_cc[VTIME] = 0;
    if (ioctl(lp->fd, TCSETS2, &t) != 0) {
        set_err(lp, "%s: cannot set %lu baud: %s", dev, (unsigned long)baud, strerror(errno));
        return (errno == EINVAL) ? J288_ERR_BAD_CONFIG : J288_ERR_PORT;
    }
    if (ioctl(lp->fd, TCGETS2, &t) != 0) {
        set_err(lp, "%s: cannot read back line settings: %s", dev, strerror(errno));
        return J288_ERR_PORT;
    }
    got = (uint32_t)t.c_ospeed;
    if (!j288_linux_baud_ok(baud, got)) {
        set_err(lp, "%s: the adapter cannot do %lu baud (it reports %lu)", dev, (unsigned long)baud,
                (unsigned long)got);
        return J288_ERR_BAD_CONFIG;
    }
    lp->baud_actual = got;
    return J288_OK;
}

/* Bounded string copy that always terminates (cap > 0). */
static void copy_str(char *out, size_t cap, const char *in)
{
    size_t n = strlen(in);
    if (n >= cap)
        n = cap - 1u;
    memcpy(out, in, n);
    out[n] = '\0';
}

/* The kernel name of the tty (ttyUSB0) behind dev, which may be a symlink. */
static void tty_name(const char *dev, char *out, size_t cap)
{
    char real[PATH_MAX];
    const char *base;
    if (realpath(dev, real) == NULL)
        copy_str(real, sizeof real, dev);
    base = strrchr(real, '/');
    base = (base != NULL) ? base + 1 : real;
    copy_str(out, cap, base);
}

static void check_latency_timer(j288_linux_t *lp, const char *name)
{
    char path[192];
    FILE *f;
    int ms = -1;
    (void)snprintf(path, sizeof path, "/sys/bus/usb-serial/devices/%s/latency_timer", name);
    f = fopen(path, "r");
    if (f == NULL)
        return; /* not an FTDI-class adapter */
    if (fscanf(f, "%d", &ms) != 1)
        ms = -1;
    (void)fclose(f);
    if (ms > 1)
        add_notice(lp,
                   "note: %s: USB latency timer is %d ms; for fast replies run: "
                   "echo 1 | sudo tee %s",
                   name, ms, path);
}

static void try_low_latency(j288_linux_t *lp, const char *dev)
{
    struct serial_struct ss;
    char name[64];
    int rc = ioctl(lp->fd, TIOCGSERIAL, &ss);
    if (rc == 0) {
        ss.flags = (int)((unsigned)ss.flags | (unsigned)ASYNC_LOW_LATENCY);
        rc = ioctl(lp->fd, TIOCSSERIAL, &ss);
    }
    if (rc == 0) {
        lp->low_latency = true;
    } else {
        int e = errno;
        add_notice(lp, "note: %s: low-latency mode not available (%s%s); continuing", dev,
                   strerror(e),
                   (e == ENOTTY) ? ": normal for pseudo-terminals and some adapters" : "");
    }
    tty_name(dev, name, sizeof name);
    check_latency_timer(lp, name);
}

static void reset_object(j288_linux_t *lp)
{
    memset(lp, 0, sizeof *lp);
    lp->fd = -1;
}

int j288_linux_open(j288_linux_t *lp, const char *dev, uint32_t baud,
                    const j288_linux_options_t *opt)
{
    int rc;
    if (lp == NULL)
        return J288_ERR_NULL;
    reset_object(lp);
    if (dev == NULL) {
        set_err(lp, "no device given");
        return J288_ERR_NULL;
    }
    if (opt != NULL)
        lp->opt = *opt;
    if (lp->opt.margin_us == 0u)
        lp->opt.margin_us = J288_LINUX_DEFAULT_MARGIN_US;
    if (lp->opt.idle_us == 0u)
        lp->opt.idle_us = J288_LINUX_DEFAULT_IDLE_US;
    lp->baud = (baud == 0u) ? J288_DEFAULT_BAUD : baud;
    copy_str(lp->dev, sizeof lp->dev, dev);

    do {
        lp->fd = open(dev, O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    } while (lp->fd < 0 && errno == EINTR);
    if (lp->fd < 0) {
        int e = errno;
        if (e == EBUSY)
            return report_in_use(lp, dev, -1);
        if (e == ENOENT)
            set_err(lp, "%s: no such device (adapter unplugged? simulator not running?)", dev);
        else if (e == EACCES)
            set_err(lp, "%s: permission denied (add yourself to group dialout, or a udev rule)",
                    dev);
        else
            set_err(lp, "%s: cannot open: %s", dev, strerror(e));
        return J288_ERR_OFFLINE;
    }
    rc = take_exclusive(lp, dev);
    if (rc == J288_OK)
        rc = set_raw_baud(lp, dev, lp->baud);
    if (rc != J288_OK) {
        (void)ioctl(lp->fd, TIOCNXCL, NULL);
        (void)close(lp->fd); /* also drops our flock */
        lp->fd = -1;
        return rc;
    }
    if (!lp->opt.no_low_latency)
        try_low_latency(lp, dev);
    /* Bytes queued before we came (a previous program's replies) are not ours. */
    (void)ioctl(lp->fd, TCFLSH, TCIOFLUSH);
    return J288_OK;
}

void j288_linux_close(j288_linux_t *lp)
{
    if (lp == NULL || lp->fd < 0)
        return;
    /* The exclusive flag belongs to the tty, not to our descriptor: clear it, or the next
     * program is refused while someone else (the simulator) keeps the tty open. The unused
     * argument is given: without it memcheck sees whatever the register held. */
    (void)ioctl(lp->fd, TIOCNXCL, NULL);
    (void)flock(lp->fd, LOCK_UN);
    (void)close(lp->fd);
    lp->fd = -1;
    lp->bus = NULL;
    lp->baud_actual = 0;
}

/* ---- I/O ----------------------------------------------------------------------------------- */

static bool errno_means_gone(int e)
{
    return e == EIO || e == ENXIO || e == ENODEV || e == EBADF || e == EPIPE;
}

/* Report the device's disappearance once: to the bus and in the error text. */
static void mark_gone(j288_linux_t *lp, const char *what, int e)
{
    if (lp->gone)
        return;
    lp->gone = true;
    if (e != 0)
        set_err(lp, "%s vanished (%s: %s): adapter unplugged or simulator exited", lp->dev, what,
                strerror(e));
    else
        set_err(lp, "%s vanished (%s): adapter unplugged or simulator exited", lp->dev, what);
    if (lp->bus != NULL)
        j288_bus_on_error(lp->bus, J288_LINE_GONE);
}

/* Sleep in ppoll until the fd has input (or hang-up) or timeout_us passes. Returns 1 when
 * the fd wants reading, 0 on timeout or a signal, -1 when the device is gone. */
static int wait_readable(j288_linux_t *lp, uint32_t timeout_us)
{
    struct pollfd pfd;
    struct timespec ts;
    int rc;
    pfd.fd = lp->fd;
    pfd.events = POLLIN;
    pfd.revents = 0;
    ts.tv_sec = (time_t)(timeout_us / 1000000u);
    ts.tv_nsec = (long)(timeout_us % 1000000u) * 1000L;
    rc = ppoll(&pfd, 1, &ts, NULL);
    if (rc < 0) {
        if (errno == EINTR) {
            lp->stats.eintr++;
            return 0; /* let the caller look at its flags; the bus loses nothing */
        }
        mark_gone(lp, "poll", errno);
        return -1;
    }
    if (rc == 0)
        return 0;
    if ((pfd.revents & POLLNVAL) != 0) {
        mark_gone(lp, "poll", EBADF);
        return -1;
    }
    return 1; /* POLLIN, POLLHUP or POLLERR: read() tells which */
}

/* Read everything available. Returns bytes delivered (>= 0), or -1 when the device is gone.
 * deliver false: drop them (stale input before a transmit). */
static int drain_input(j288_linux_t *lp, bool deliver)
{
    uint8_t buf[256];
    int total = 0;
    for (;;) {
        ssize_t n = read(lp->fd, buf, sizeof buf);
        if (n > 0) {
            total += (int)n;
            if (deliver) {
                lp->stats.rx_bytes += (uint32_t)n;
                if (lp->bus != NULL)
                    j288_bus_on_rx(lp->bus, buf, (size_t)n);
            } else {
                lp->stats.flushed_bytes += (uint32_t)n;
            }
            if ((size_t)n < sizeof buf)
                return total;
            continue;
        }
        if (n == 0) {
            /* VMIN is 1, so a 0 from a non-blocking read is a hang-up, not "no data". */
            mark_gone(lp, "end of file", 0);
            return -1;
        }
        if (errno == EINTR) {
            lp->stats.eintr++;
            continue;
        }
        if (errno == EAGAIN || errno == EWOULDBLOCK)
            return total;
        if (errno_means_gone(errno)) {
            mark_gone(lp, "read", errno);
            return -1;
        }
        set_err(lp, "%s: read failed: %s", lp->dev, strerror(errno));
        return total;
    }
}

static int write_all(j288_linux_t *lp, const uint8_t *data, size_t len)
{
    size_t done = 0;
    while (done < len) {
        ssize_t n = write(lp->fd, data + done, len - done);
        if (n > 0) {
            if ((size_t)n < len - done)
                lp->stats.partial_writes++;
            done += (size_t)n;
            continue;
        }
        if (n < 0 && errno == EINTR) {
            lp->stats.eintr++;
            continue;
        }
        if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
            struct pollfd pfd;
            int rc;
            pfd.fd = lp->fd;
            pfd.events = POLLOUT;
            pfd.revents = 0;
            rc = poll(&pfd, 1, WRITE_STALL_MS);
            if (rc < 0 && errno == EINTR) {
                lp->stats.eintr++;
                continue;
            }
            if (rc == 0) {
                set_err(lp, "%s: write stalled for %d ms", lp->dev, WRITE_STALL_MS);
                return J288_ERR_PORT;
            }
            if (rc > 0 && (pfd.revents & (POLLHUP | POLLERR | POLLNVAL)) != 0 &&
                (pfd.revents & POLLOUT) == 0) {
                mark_gone(lp, "write", EIO);
                return J288_ERR_OFFLINE;
            }
            continue;
        }
        if (n < 0 && errno_means_gone(errno)) {
            mark_gone(lp, "write", errno);
            return J288_ERR_OFFLINE;
        }
        set_err(lp, "%s: write failed: %s", lp->dev, (n < 0) ? strerror(errno) : "no progress");
        return J288_ERR_PORT;
    }
    lp->stats.tx_bytes += (uint32_t)len;
    return J288_OK;
}

/* ---- port operations ------------------------------------------------------------------------ */

static int port_start_tx(void *ctx, const uint8_t *data, size_t len)
{
    j288_linux_t *lp = ctx;
    bool was_gone = lp->gone;
    int rc = J288_ERR_OFFLINE;
    if (lp->fd < 0)
        return J288_ERR_PORT;
    /* Nothing received before this command can be its reply: drop it here, where it cannot
     * be mistaken for one. */
    if (!was_gone && drain_input(lp, false) >= 0)
        rc = write_all(lp, data, len);
    if (rc == J288_ERR_OFFLINE) {
        /* The attempt learns of it through the bus's line-gone event, which ends it with
         * J288_ERR_OFFLINE at once (an error return would read as a generic J288_ERR_PORT).
         * mark_gone() sent the event if the loss was found just now; a device lost
         * earlier needs one for this attempt. */
        if (was_gone && lp->bus != NULL)
            j288_bus_on_error(lp->bus, J288_LINE_GONE);
        return J288_OK;
    }
    if (rc != J288_OK)
        return rc;
    lp->idle_pending = false;
    /* write() returning means the bytes are with the driver; the bus's reply budget counts
     * from the start of transmit and its margin covers the USB path. */
    if (lp->bus != NULL)
        j288_bus_on_tx_done(lp->bus);
    return J288_OK;
}

static uint32_t port_now_us(void *ctx)
{
    (void)ctx;
    return j288_linux_now_us();
}

static void port_arm_timeout(void *ctx, uint32_t deadline_us)
{
    j288_linux_t *lp = ctx;
    lp->timer_us = deadline_us;
    lp->timer_armed = true;
}

/* Deliver the timer and idle events that are due. Returns true if one was delivered. */
static bool deliver_due(j288_linux_t *lp, uint32_t now)
{
    bool any = false;
    if (lp->timer_armed && us_until(lp->timer_us, now) <= 0) {
        lp->timer_armed = false;
        if (lp->bus != NULL)
            j288_bus_on_timer(lp->bus);
        any = true;
    }
    if (lp->idle_pending && us_until(lp->last_rx_us + lp->opt.idle_us, now) <= 0) {
        lp->idle_pending = false;
        if (lp->bus != NULL)
            j288_bus_on_rx_idle(lp->bus);
        any = true;
    }
    return any;
}

/* Read and deliver what the device has, once it wants reading. Returns -1 when it is gone. */
static int take_input(j288_linux_t *lp)
{
    int n = drain_input(lp, true);
    if (n < 0)
        return -1;
    if (n > 0) {
        lp->idle_pending = true;
        lp->last_rx_us = j288_linux_now_us();
    }
    return 0;
}

static int port_wait(void *ctx, uint32_t until_us)
{
    j288_linux_t *lp = ctx;
    uint32_t now = j288_linux_now_us();
    int32_t left = us_until(until_us, now);
    uint32_t at;
    int rc;
    if (lp->fd < 0 || lp->gone)
        return J288_ERR_OFFLINE;
    lp->stats.waits++;
    if (j288_linux_next_deadline(lp, &at) && us_until(at, now) <= 0) {
        /* Bytes already here go to the bus before a deadline is judged (the engine takes its
         * events before its deadline too): a host that wakes past the deadline, on a loaded
         * machine, must not time out a reply that came in time and then count it as stale
         * bytes in the next window. */
        rc = wait_readable(lp, 0u);
        if (rc < 0 || (rc > 0 && take_input(lp) < 0))
            return J288_ERR_OFFLINE;
        now = j288_linux_now_us();
    }
    if (deliver_due(lp, now))
        return J288_OK;
    if (left < 0)
        left = 0;
    if (lp->timer_armed && us_until(lp->timer_us, now) < left)
        left = us_until(lp->timer_us, now);
    if (lp->idle_pending && us_until(lp->last_rx_us + lp->opt.idle_us, now) < left)
        left = us_until(lp->last_rx_us + lp->opt.idle_us, now);
    rc = wait_readable(lp, (uint32_t)left);
    if (rc < 0 || (rc > 0 && take_input(lp) < 0))
        return J288_ERR_OFFLINE;
    if (rc == 0)
        (void)deliver_due(lp, j288_linux_now_us());
    return J288_OK;
}

/* No start_rx (the receiver is always on), no set_dir (the adapter switches direction
 * itself), no crc32, no lock/unlock (one thread owns the port and its bus). */
const j288_port_t j288_linux_port = {
    .start_tx = port_start_tx,
    .now_us = port_now_us,
    .arm_timeout = port_arm_timeout, /* wait() wakes at the deadline */
    .wait = port_wait,
};

/* ---- bus glue and run helpers --------------------------------------------------------------- */

void j288_linux_bus_config(const j288_linux_t *lp, j288_bus_config_t *cfg)
{
    if (cfg == NULL)
        return;
    memset(cfg, 0, sizeof *cfg);
    if (lp == NULL)
        return;
    cfg->baud = (lp->baud_actual != 0u) ? lp->baud_actual : lp->baud;
    cfg->margin_us = (lp->opt.margin_us != 0u) ? lp->opt.margin_us : J288_LINUX_DEFAULT_MARGIN_US;
    cfg->echo = lp->opt.echo;
}

int j288_linux_bus_init(j288_linux_t *lp, j288_bus_t *bus, const j288_bus_config_t *cfg)
{
    j288_bus_config_t def;
    if (lp == NULL || bus == NULL)
        return J288_ERR_NULL;
    if (cfg == NULL) {
        j288_linux_bus_config(lp, &def);
        cfg = &def;
    }
    lp->bus = bus;
    return j288_bus_init(bus, &j288_linux_port, lp, cfg);
}

void j288_linux_set_stop_flag(j288_linux_t *lp, const volatile sig_atomic_t *flag)
{
    if (lp != NULL)
        lp->stop_flag = flag;
}

static bool work_pending(const j288_linux_t *lp, const j288_sched_t *s)
{
    if (s != NULL && j288_sched_busy(s))
        return true;
    return !j288_bus_is_idle(lp->bus);
}

int j288_linux_run(j288_linux_t *lp, j288_sched_t *s, uint32_t until_us, unsigned flags)
{
    if (lp == NULL || lp->bus == NULL)
        return J288_ERR_NULL;
    for (;;) {
        uint32_t now = j288_linux_now_us();
        uint32_t slice;
        bool pending;
        int rc;
        if (s != NULL)
            j288_sched_poll(s, now);
        else
            j288_bus_poll(lp->bus, now);
        if (lp->gone)
            return J288_ERR_OFFLINE;
        pending = work_pending(lp, s);
        if ((flags & J288_LINUX_RUN_UNTIL_IDLE) != 0u && !pending)
            return J288_OK;
        if ((flags & J288_LINUX_RUN_IGNORE_STOP) == 0u && lp->stop_flag != NULL &&
            *lp->stop_flag != 0)
            return J288_ERR_ABORTED;
        if (us_until(until_us, now) <= 0)
            return ((flags & J288_LINUX_RUN_UNTIL_IDLE) != 0u) ? J288_ERR_TIMEOUT : J288_OK;
        slice = (uint32_t)us_until(until_us, now);
        if (pending && slice > RUN_SLICE_US)
            slice = RUN_SLICE_US;
        if (lp->stop_flag != NULL && slice > STOP_SLICE_US)
            slice = STOP_SLICE_US;
        rc = port_wait(lp, now + slice);
        if (rc == J288_ERR_OFFLINE) {
            /* Let the bus and scheduler see the line-gone event before returning. */
            now = j288_linux_now_us();
            if (s != NULL)
                j288_sched_poll(s, now);
            else
                j288_bus_poll(lp->bus, now);
            return J288_ERR_OFFLINE;
        }
    }
}

int j288_linux_sweep(j288_linux_t *lp, j288_sched_t *s, uint32_t timeout_us)
{
    uint32_t now;
    int rc;
    if (lp == NULL || s == NULL || lp->bus == NULL)
        return J288_ERR_NULL;
    if (lp->gone)
        return J288_ERR_OFFLINE;
    now = j288_linux_now_us();
    rc = j288_sched_start_sweep(s, now);
    if (rc != J288_OK)
        return rc;
    if (timeout_us == 0u)
        timeout_us = 1000000u;
    return j288_linux_run(lp, s, now + timeout_us, J288_LINUX_RUN_UNTIL_IDLE);
}

/* ---- for a multi-port loop ------------------------------------------------------------------ */

int j288_linux_fd(const j288_linux_t *lp)
{
    return (lp == NULL || lp->gone) ? -1 : lp->fd;
}

bool j288_linux_next_deadline(const j288_linux_t *lp, uint32_t *at_us)
{
    bool any = false;
    uint32_t now = j288_linux_now_us(), at = 0;
    if (lp == NULL || at_us == NULL)
        return false;
    if (lp->timer_armed) {
        at = lp->timer_us;
        any = true;
    }
    if (lp->idle_pending) {
        uint32_t idle_at = lp->last_rx_us + lp->opt.idle_us;
        if (!any || us_until(idle_at, now) < us_until(at, now))
            at = idle_at;
        any = true;
    }
    if (any)
        *at_us = at;
    return any;
}

int j288_linux_service(j288_linux_t *lp)
{
    if (lp == NULL)
        return J288_ERR_NULL;
    return port_wait(lp, j288_linux_now_us());
}

/* ---- inspection --------------------------------------------------------------------------------
 */

const char *j288_linux_error(const j288_linux_t *lp)
{
    return (lp == NULL) ? "no port" : lp->err;
}

const char *j288_linux_notices(const j288_linux_t *lp)
{
    return (lp == NULL) ? "" : lp->notice;
}

uint32_t j288_linux_baud(const j288_linux_t *lp)
{
    return (lp == NULL || lp->fd < 0) ? 0u : lp->baud_actual;
}

bool j288_linux_offline(const j288_linux_t *lp)
{
    return lp == NULL || lp->gone;
}

const j288_linux_stats_t *j288_linux_stats(const j288_linux_t *lp)
{
    return (lp == NULL) ? NULL : &lp->stats;
}
