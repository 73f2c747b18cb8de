/*
 * j288_linux.c - the Linux side of the desktop serial port (j288_linux.h; the contract is
 * j288_serial.h, the interface j288_serial_os.h): open, line settings, read, write, wait.
 *
 * termios2 is used instead of <termios.h> because only TCSETS2 with BOTHER sets an arbitrary
 * rate such as 6,000,000; the two struct termios definitions clash, so <termios.h> is not
 * included here.
 */
#define _GNU_SOURCE 1 /* ppoll, flock, realpath, snprintf under -std=c99 */

#include "j288_serial_os.h"

#include <asm/termbits.h>
#include <linux/serial.h>
#include <sys/ioctl.h>

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <poll.h>
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

uint32_t j288_serial_now_us(void)
{
    struct timespec ts;
    (void)clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint32_t)((uint64_t)ts.tv_sec * 1000000u + (uint64_t)ts.tv_nsec / 1000u);
}

static struct timespec timespec_of(uint32_t us)
{
    struct timespec ts;
    ts.tv_sec = (time_t)(us / 1000000u);
    ts.tv_nsec = (long)(us % 1000000u) * 1000L;
    return ts;
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

static int report_in_use(j288_serial_t *sp, const char *dev, int fd)
{
    struct stat st;
    long pid = 0;
    int ok = (fd >= 0) ? fstat(fd, &st) : stat(dev, &st);
    if (ok == 0)
        pid = lock_holder_pid(st.st_dev, st.st_ino);
    if (pid > 0 && pid != (long)getpid())
        j288_serial_set_err(sp, "%s is in use by PID %ld (another program holds the bus)", dev, pid);
    else if (pid > 0)
        j288_serial_set_err(sp, "%s is already open in this process", dev);
    else
        j288_serial_set_err(sp, "%s is in use by another program (held exclusively; no lock holder found)",
                dev);
    return J288_ERR_BUSY;
}

static int take_exclusive(j288_serial_t *sp, const char *dev)
{
    int rc;
    do {
        rc = flock(sp->os.fd, LOCK_EX | LOCK_NB);
    } while (rc != 0 && errno == EINTR);
    if (rc != 0) {
        if (errno == EWOULDBLOCK)
            return report_in_use(sp, dev, sp->os.fd);
        j288_serial_set_err(sp, "%s: cannot lock: %s", dev, strerror(errno));
        return J288_ERR_PORT;
    }
    /* TIOCEXCL makes further open() calls fail with EBUSY (except for root, which the
     * flock above still stops). */
    if (ioctl(sp->os.fd, TIOCEXCL, NULL) != 0) {
        if (errno == ENOTTY || errno == EINVAL) {
            j288_serial_set_err(sp, "%s is not a serial device", dev);
            return J288_ERR_BAD_CONFIG;
        }
        j288_serial_set_err(sp, "%s: cannot get exclusive access: %s", dev, strerror(errno));
        return J288_ERR_PORT;
    }
    return J288_OK;
}


/* ---- open ---------------------------------------------------------------------------------- */

void j288_serial_os_reset(j288_serial_t *sp)
{
    sp->os.fd = -1;
}

bool j288_serial_os_is_open(const j288_serial_t *sp)
{
    return sp->os.fd >= 0;
}

int j288_serial_os_open(j288_serial_t *sp, const char *dev)
{
    int rc;
    do {
        sp->os.fd = open(dev, O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
    } while (sp->os.fd < 0 && errno == EINTR);
    if (sp->os.fd < 0) {
        int e = errno;
        if (e == EBUSY)
            return report_in_use(sp, dev, -1);
        if (e == ENOENT)
            j288_serial_set_err(sp, "%s: no such device (adapter unplugged? simulator not running?)",
                                dev);
        else if (e == EACCES)
            j288_serial_set_err(
                sp, "%s: permission denied (add yourself to group dialout, or a udev rule)", dev);
        else
            j288_serial_set_err(sp, "%s: cannot open: %s", dev, strerror(e));
        return J288_ERR_OFFLINE;
    }
    rc = take_exclusive(sp, dev);
    if (rc != J288_OK)
        j288_serial_os_close(sp);
    return rc;
}

int j288_serial_os_set_line(j288_serial_t *sp, uint32_t baud, uint32_t *got)
{
    struct termios2 t;
    int e;
    if (ioctl(sp->os.fd, TCGETS2, &t) != 0) {
        e = errno;
        if (e == ENOTTY || e == EINVAL) {
            j288_serial_set_err(sp, "%s is not a serial device", sp->dev);
            return J288_ERR_BAD_CONFIG;
        }
        j288_serial_set_err(sp, "%s: cannot read line settings: %s", sp->dev, strerror(e));
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
    if (ioctl(sp->os.fd, TCSETS2, &t) != 0) {
        e = errno;
        j288_serial_set_err(sp, "%s: cannot set %lu baud: %s", sp->dev, (unsigned long)baud,
                            strerror(e));
        return (e == EINVAL) ? J288_ERR_BAD_CONFIG : J288_ERR_PORT;
    }
    if (ioctl(sp->os.fd, TCGETS2, &t) != 0) {
        j288_serial_set_err(sp, "%s: cannot read back line settings: %s", sp->dev,
                            strerror(errno));
        return J288_ERR_PORT;
    }
    *got = (uint32_t)t.c_ospeed;
    return J288_OK;
}

/* ---- open: tuning -------------------------------------------------------------------------- */

/* The kernel name of the tty (ttyUSB0) behind dev, which may be a symlink. */
static void tty_name(const char *dev, char *out, size_t cap)
{
    char real[PATH_MAX];
    const char *base;
    if (realpath(dev, real) == NULL)
        j288_serial_copy_str(real, sizeof real, dev);
    base = strrchr(real, '/');
    base = (base != NULL) ? base + 1 : real;
    j288_serial_copy_str(out, cap, base);
}

static void check_latency_timer(j288_serial_t *sp, const char *name)
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
        j288_serial_add_notice(sp,
                   "note: %s: USB latency timer is %d ms; for fast replies run: "
                   "echo 1 | sudo tee %s",
                   name, ms, path);
}

static void try_low_latency(j288_serial_t *sp, const char *dev)
{
    struct serial_struct ss;
    char name[64];
    int rc = ioctl(sp->os.fd, TIOCGSERIAL, &ss);
    if (rc == 0) {
        ss.flags = (int)((unsigned)ss.flags | (unsigned)ASYNC_LOW_LATENCY);
        rc = ioctl(sp->os.fd, TIOCSSERIAL, &ss);
    }
    if (rc == 0) {
        sp->os.low_latency = true;
    } else {
        int e = errno;
        j288_serial_add_notice(sp, "note: %s: low-latency mode not available (%s%s); continuing", dev,
                   strerror(e),
                   (e == ENOTTY) ? ": normal for pseudo-terminals and some adapters" : "");
    }
    tty_name(dev, name, sizeof name);
    check_latency_timer(sp, name);
}


void j288_serial_os_ready(j288_serial_t *sp)
{
    if (!sp->opt.no_low_latency)
        try_low_latency(sp, sp->dev);
    /* Bytes queued before we came (a previous program's replies) are not ours. */
    (void)ioctl(sp->os.fd, TCFLSH, TCIOFLUSH);
}

void j288_serial_os_close(j288_serial_t *sp)
{
    if (sp->os.fd < 0)
        return;
    /* The exclusive flag belongs to the tty, not to our descriptor: clear it, or the next
     * program is refused while someone else (the simulator) keeps the tty open. The unused
     * argument is given: without it memcheck sees whatever the register held. */
    (void)ioctl(sp->os.fd, TIOCNXCL, NULL);
    (void)flock(sp->os.fd, LOCK_UN);
    (void)close(sp->os.fd);
    sp->os.fd = -1;
}

bool j288_serial_same_device(const j288_serial_t *sp, const char *dev)
{
    struct stat sd, so;
    return sp != NULL && dev != NULL && sp->os.fd >= 0 && stat(dev, &sd) == 0 &&
           fstat(sp->os.fd, &so) == 0 && sd.st_rdev == so.st_rdev && sd.st_ino == so.st_ino &&
           sd.st_dev == so.st_dev;
}

/* ---- I/O ----------------------------------------------------------------------------------- */

static bool errno_means_gone(int e)
{
    return e == EIO || e == ENXIO || e == ENODEV || e == EBADF || e == EPIPE;
}

int j288_serial_os_wait_input(j288_serial_t *sp, uint32_t timeout_us)
{
    struct pollfd pfd;
    struct timespec ts = timespec_of(timeout_us);
    int rc;
    pfd.fd = sp->os.fd;
    pfd.events = POLLIN;
    pfd.revents = 0;
    rc = ppoll(&pfd, 1, &ts, NULL);
    if (rc < 0) {
        if (errno == EINTR) {
            sp->stats.eintr++;
            return 0; /* let the caller look at its flags; the bus loses nothing */
        }
        j288_serial_gone(sp, "poll", strerror(errno));
        return -1;
    }
    if (rc == 0)
        return 0;
    if ((pfd.revents & POLLNVAL) != 0) {
        j288_serial_gone(sp, "poll", strerror(EBADF));
        return -1;
    }
    return 1; /* POLLIN, POLLHUP or POLLERR: read() tells which */
}

int j288_serial_os_read(j288_serial_t *sp, uint8_t *buf, size_t cap)
{
    for (;;) {
        ssize_t n = read(sp->os.fd, buf, cap);
        if (n > 0)
            return (int)n;
        if (n == 0) {
            /* VMIN is 1, so a 0 from a non-blocking read is a hang-up, not "no data". */
            j288_serial_gone(sp, "end of file", NULL);
            return -1;
        }
        if (errno == EINTR) {
            sp->stats.eintr++;
            continue;
        }
        if (errno == EAGAIN || errno == EWOULDBLOCK)
            return 0;
        if (errno_means_gone(errno)) {
            j288_serial_gone(sp, "read", strerror(errno));
            return -1;
        }
        j288_serial_set_err(sp, "%s: read failed: %s", sp->dev, strerror(errno));
        return 0;
    }
}

/* Wait (bounded) until the device takes more output. 0: go on, or an error code. */
static int wait_writable(j288_serial_t *sp)
{
    struct pollfd pfd;
    int rc;
    pfd.fd = sp->os.fd;
    pfd.events = POLLOUT;
    pfd.revents = 0;
    rc = poll(&pfd, 1, WRITE_STALL_MS);
    if (rc < 0 && errno == EINTR) {
        sp->stats.eintr++;
        return 0;
    }
    if (rc == 0) {
        j288_serial_set_err(sp, "%s: write stalled for %d ms", sp->dev, WRITE_STALL_MS);
        return J288_ERR_PORT;
    }
    if (rc > 0 && (pfd.revents & (POLLHUP | POLLERR | POLLNVAL)) != 0 &&
        (pfd.revents & POLLOUT) == 0) {
        j288_serial_gone(sp, "write", strerror(EIO));
        return J288_ERR_OFFLINE;
    }
    return 0;
}

int j288_serial_os_write(j288_serial_t *sp, const uint8_t *data, size_t len)
{
    size_t done = 0;
    while (done < len) {
        ssize_t n = write(sp->os.fd, data + done, len - done);
        int rc;
        if (n > 0) {
            if ((size_t)n < len - done)
                sp->stats.partial_writes++;
            done += (size_t)n;
            continue;
        }
        if (n < 0 && errno == EINTR) {
            sp->stats.eintr++;
            continue;
        }
        if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) {
            rc = wait_writable(sp);
            if (rc != 0)
                return rc;
            continue;
        }
        if (n < 0 && errno_means_gone(errno)) {
            j288_serial_gone(sp, "write", strerror(errno));
            return J288_ERR_OFFLINE;
        }
        j288_serial_set_err(sp, "%s: write failed: %s", sp->dev,
                            (n < 0) ? strerror(errno) : "no progress");
        return J288_ERR_PORT;
    }
    return J288_OK;
}

/* ---- several ports at once ------------------------------------------------------------------ */

unsigned j288_serial_wait_any(j288_serial_t *const ports[], unsigned n, uint32_t timeout_us,
                              bool ready[])
{
    struct pollfd pfd[J288_SERIAL_WAIT_MAX];
    unsigned who[J288_SERIAL_WAIT_MAX];
    struct timespec ts = timespec_of(timeout_us);
    nfds_t nfds = 0;
    unsigned i, got = 0;

    for (i = 0; i < n && i < J288_SERIAL_WAIT_MAX; i++) {
        const j288_serial_t *sp = ports[i];
        ready[i] = false;
        if (sp == NULL || sp->os.fd < 0 || sp->gone)
            continue;
        pfd[nfds].fd = sp->os.fd;
        pfd[nfds].events = POLLIN;
        pfd[nfds].revents = 0;
        who[nfds] = i;
        nfds++;
    }
    if (ppoll(pfd, nfds, &ts, NULL) <= 0)
        return 0; /* timeout, or a signal */
    for (i = 0; i < (unsigned)nfds; i++) {
        if (pfd[i].revents != 0) {
            ready[who[i]] = true;
            got++;
        }
    }
    return got;
}
