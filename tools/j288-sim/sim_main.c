/*
 * j288-sim - a simulated J288 servo bus on a pseudo-terminal.
 *
 * Prints the pty's path on stdout (one line), serves the servos until SIGINT/SIGTERM (or
 * --exit-after), then closes the pty master (clients see the device vanish), removes the
 * --link symlink and prints one statistics line on stderr. SIGUSR1 switches the injected
 * wire faults off, SIGUSR2 on again, SIGPWR power-cycles every servo, SIGWINCH writes the
 * --truth file (the handlers only record the wish; the loop applies it). The servo physics
 * and protocol live in servo_model.c; this file is the I/O: the pty, timing of replies,
 * options, signals, the log, the truth file.
 */
#define _GNU_SOURCE 1 /* posix_openpt, ppoll, sigaction under -std=c99 */

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <termios.h>
#include <time.h>
#include <unistd.h>

#include "j288/j288.h"
#include "servo_model.h"

#define QUEUE_LEN  64u
#define CHUNK_MAX  32u
#define TICK_US    10000u /* model advance when the line is quiet */
#define NAP_US     1000u  /* no client has the pty open: look again this often */
#define MAX_CYCLES 16u    /* --power-cycle-after entries */

typedef struct {
    uint64_t at_us;
    size_t len;
    uint8_t data[CHUNK_MAX];
} chunk_t;

/* A --power-cycle-after entry. */
typedef struct {
    uint64_t at_us;
    uint16_t ids; /* 0: every servo */
} cycle_t;

typedef struct {
    int master;
    uint64_t t0_ns;
    chunk_t q[QUEUE_LEN];
    size_t qlen;
    uint64_t queue_full;
    uint64_t lost_no_client;
    bool echo;
    bool quiet;
    FILE *log;
    const char *truth; /* --truth target, or NULL */
    unsigned long truth_seq;
    const cycle_t *cycle; /* --power-cycle-after entries, in time order */
    size_t ncycles, next_cycle;
    uint32_t power_off_us;
    bool power_on_pending; /* a truth line is due when the cycled servos are back */
    uint64_t power_on_us;
} sim_io_t;

static volatile sig_atomic_t g_stop;          /* set by SIGINT/SIGTERM/SIGHUP */
static volatile sig_atomic_t g_faults_on = 1; /* SIGUSR1: 0, SIGUSR2: 1; the last one wins */
static volatile sig_atomic_t g_power_cycle;   /* SIGPWR: power-cycle every servo */
static volatile sig_atomic_t g_truth_wanted;  /* SIGWINCH: write the --truth file */

static void on_signal(int sig)
{
    (void)sig;
    g_stop = 1;
}

/* Async-signal-safe: one store each; serve() acts on it. */
static void on_power_signal(int sig)
{
    (void)sig;
    g_power_cycle = 1;
}

static void on_truth_signal(int sig)
{
    (void)sig;
    g_truth_wanted = 1;
}

/* Async-signal-safe: one store; serve() applies it before it reads the next bytes. */
static void on_fault_signal(int sig)
{
    g_faults_on = (sig == SIGUSR2) ? 1 : 0;
}

static void die(const char *fmt, ...) __attribute__((format(printf, 1, 2), noreturn));

static void die(const char *fmt, ...)
{
    va_list ap;
    fputs("j288-sim: ", stderr);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
    exit(2);
}

static uint64_t mono_ns(void)
{
    struct timespec ts;
    (void)clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec;
}

static uint64_t sim_now_us(const sim_io_t *io)
{
    return (mono_ns() - io->t0_ns) / 1000u;
}

/* ---- options ------------------------------------------------------------------------------ */

typedef struct {
    uint16_t ids;
    const char *link;
    const char *log;
    const char *truth;
    double exit_after;
    uint32_t faults[J288_MAX_SERVOS];
    uint16_t fault_set;
    double phase[J288_MAX_SERVOS];
    uint16_t phase_set;
    double angle[J288_MAX_SERVOS];
    uint16_t angle_set;
    cycle_t cycle[MAX_CYCLES]; /* in time order */
    size_t ncycles;
    bool quiet;
    bool echo;
    j288_sim_bus_config_t bus;
    j288_sim_params_t prm;
} options_t;

static void usage(FILE *f)
{
    fputs("usage: j288-sim [options]\n"
          "A simulated J288 servo bus on a pseudo-terminal. Prints the pty path on stdout\n"
          "(one line), serves until SIGINT/SIGTERM or --exit-after, then closes the pty and\n"
          "prints a statistics line on stderr.\n"
          "\n"
          "  --ids LIST          servo ids on the bus, e.g. 1,2,3 (default 1), 0-14\n"
          "  --link PATH         also place a symlink to the pty at PATH (removed on exit)\n"
          "  --voltage V         supply voltage (default 24)\n"
          "  --ambient C         ambient temperature (default 25)\n"
          "  --load-inertia J    extra inertia on each output shaft, kg m^2 (default 0)\n"
          "  --load-torque NM    constant torque on each output shaft, N m (default 0)\n"
          "  --turnaround-us N   extra reply delay (default 0: at once;\n"
          "                      the pty adds tens of microseconds itself)\n"
          "  --echo              send every received byte straight back, as a single-wire\n"
          "                      adapter that hears its own transmit does\n"
          "  --log FILE          one line per received command frame ('-' = stderr)\n"
          "  --exit-after S      exit after S seconds (for tests)\n"
          "  --quiet             no messages but errors and the statistics line\n"
          "  --version           print the version (the library's) and exit\n"
          "fault injection (deterministic for a given --seed and command sequence):\n"
          "  --seed N            random seed (default 1)\n"
          "  --drop P            probability a reply is not sent\n"
          "  --corrupt P         probability one byte of a reply is changed\n"
          "  --late P            probability a reply is delayed by --late-us\n"
          "  --late-us N         delay of a late reply (default 50000)\n"
          "  --noise P           probability of 1-8 noise bytes ahead of a reply\n"
          "  --dup ID            a second servo also answers to ID (repeatable)\n"
          "  --fault ID:BITS     servo ID reports fault bits BITS (e.g. 0x200; repeatable)\n",
          f);
    /* In parts: C99 compilers need only take string literals of 4095 characters. */
    fputs("joint (the rotor angle is r = N * theta + c, N = 288.35; a reply's position is\n"
          "p = r - 2 pi k with k such that p starts in [0, 2 pi) at power-up; OutPos is the\n"
          "output shaft angle theta in 8192 counts per turn):\n"
          "  --phase ID:RAD      rotor phase c of servo ID, fixed at assembly (default: drawn\n"
          "                      from --seed in [0, 2 pi)); repeatable\n"
          "  --start-angle ID:RAD  output angle theta of servo ID at start (default: drawn from\n"
          "                      --seed in [-pi, pi)); it labels the turns that c goes with;\n"
          "                      repeatable\n"
          "  --backlash RAD      play between the gear and the output shaft, output rad\n"
          "                      (default 0): the shaft follows only when the gear pushes it\n"
          "                      or the load (--load-torque) drives it\n"
          "  --truth FILE        write every servo's truth to FILE ('-' = stderr) at start\n"
          "                      (before the pty path line), on SIGWINCH, when power-cycled\n"
          "                      servos go off and when they are back, and at exit; the file\n"
          "                      is replaced atomically. A line '# j288-sim truth seq=N\n"
          "                      t=SECONDS reason=start|request|power-off|power-on|exit',\n"
          "                      then per servo 'id= theta= theta_gear= c= k= p= r= out_pos=\n"
          "                      powered= cycles=' (angles in rad; theta_gear is theta\n"
          "                      without the play: r = N * theta_gear + c = p + 2 pi k)\n"
          "power cycles (the turn count is lost: p restarts inside [0, 2 pi); theta and c are\n"
          "kept; the servo is deaf and silent while off, then in lock with the watchdog off):\n"
          "  --power-cycle-after S[:IDS]  power-cycle servos IDS (e.g. 1,3; default all) S\n"
          "                      seconds after start; repeatable (up to 16)\n"
          "  --power-off-ms N    how long a power-cycled servo stays off (default 100)\n"
          "  SIGPWR              power-cycle every servo now. Unless --quiet, each cycle\n"
          "                      prints 'j288-sim: power cycle: servos ... off for N ms'.\n",
          f);
    fputs("switching faults while running:\n"
          "  SIGUSR1             wire faults off: no drop, corrupt, late, noise or duplicate-id\n"
          "                      replies from the next command on (a reply already delayed by\n"
          "                      --late still arrives when due); --fault bits are servo state\n"
          "                      and stay. Unless --quiet, prints 'j288-sim: faults off: stats:\n"
          "                      ...' (the statistics line so far) when it takes effect.\n"
          "  SIGUSR2             wire faults on again as configured ('faults on: stats: ...').\n"
          "                      A signal that changes nothing prints nothing.\n"
          "  SIGWINCH            write the --truth file now (reason=request)\n"
          "  SIGHUP              like SIGTERM: a simulator whose terminal is gone stops\n"
          "log lines: SECONDS HEX20 then 'id=N status=N wd=0|1 tau= speed= pos= kp= kd='\n"
          "for a good frame, or 'bad-crc id=N' for a frame whose CRC failed.\n",
          f);
}

static double parse_double(const char *opt, const char *s, double lo, double hi)
{
    char *end;
    double v;
    errno = 0;
    v = strtod(s, &end);
    if (errno != 0 || end == s || *end != '\0' || !(v >= lo && v <= hi))
        die("%s: '%s' is not a number in [%g, %g]", opt, s, lo, hi);
    return v;
}

static unsigned long parse_ulong(const char *opt, const char *s, unsigned long max, int base)
{
    char *end;
    unsigned long v;
    errno = 0;
    if (*s == '-')
        die("%s: '%s' must not be negative", opt, s);
    v = strtoul(s, &end, base);
    if (errno != 0 || end == s || *end != '\0' || v > max)
        die("%s: '%s' is not an integer in [0, %lu]", opt, s, max);
    return v;
}

static uint16_t parse_id_list(const char *opt, const char *s)
{
    uint16_t ids = 0;
    char buf[128];
    char *tok, *save = NULL;
    if (strlen(s) >= sizeof buf)
        die("%s: list too long", opt);
    strcpy(buf, s);
    for (tok = strtok_r(buf, ",", &save); tok != NULL; tok = strtok_r(NULL, ",", &save))
        ids = (uint16_t)(ids | (1u << parse_ulong(opt, tok, J288_MAX_ID, 10)));
    if (ids == 0u)
        die("%s: no id given", opt);
    return ids;
}

/* "ID:VALUE": the id; *value points at VALUE inside buf (cap bytes). */
static uint8_t parse_id_colon(const char *opt, const char *s, char *buf, size_t cap,
                              const char *what, const char **value)
{
    char *colon;
    if (strlen(s) >= cap)
        die("%s: '%s' too long", opt, s);
    strcpy(buf, s);
    colon = strchr(buf, ':');
    if (colon == NULL)
        die("%s: expected ID:%s, got '%s'", opt, what, s);
    *colon = '\0';
    *value = colon + 1;
    return (uint8_t)parse_ulong(opt, buf, J288_MAX_ID, 10);
}

static void parse_fault(options_t *o, const char *s)
{
    char buf[64];
    const char *v;
    uint8_t id = parse_id_colon("--fault", s, buf, sizeof buf, "BITS", &v);
    o->faults[id] = (uint32_t)parse_ulong("--fault", v, 0xFFFFFFFFul, 0);
    o->fault_set = (uint16_t)(o->fault_set | (1u << id));
}

/* --phase / --start-angle ID:RAD into vals[id], marking it in *set. */
static void parse_joint_angle(const char *opt, const char *s, double *vals, uint16_t *set)
{
    char buf[64];
    const char *v;
    uint8_t id = parse_id_colon(opt, s, buf, sizeof buf, "RAD", &v);
    vals[id] = parse_double(opt, v, -1000.0, 1000.0);
    *set = (uint16_t)(*set | (1u << id));
}

/* --power-cycle-after S[:IDS], kept in time order (equal times keep their order). */
static void parse_cycle(options_t *o, const char *s)
{
    char buf[128];
    char *colon;
    cycle_t c;
    size_t i;
    if (o->ncycles == MAX_CYCLES)
        die("--power-cycle-after: at most %u", MAX_CYCLES);
    if (strlen(s) >= sizeof buf)
        die("--power-cycle-after: '%s' too long", s);
    strcpy(buf, s);
    colon = strchr(buf, ':');
    if (colon != NULL)
        *colon = '\0';
    c.at_us = (uint64_t)(parse_double("--power-cycle-after", buf, 0.0, 86400.0) * 1e6);
    c.ids = (colon != NULL) ? parse_id_list("--power-cycle-after", colon + 1) : 0u;
    i = o->ncycles;
    while (i > 0u && o->cycle[i - 1u].at_us > c.at_us) {
        o->cycle[i] = o->cycle[i - 1u];
        i--;
    }
    o->cycle[i] = c;
    o->ncycles++;
}

static bool takes_value(const char *opt)
{
    static const char *const names[] = {
        "--ids",          "--link",        "--log",           "--voltage",     "--ambient",
        "--load-inertia", "--load-torque", "--turnaround-us", "--exit-after",  "--seed",
        "--drop",         "--corrupt",     "--late",          "--late-us",     "--noise",
        "--dup",          "--fault",       "--phase",         "--start-angle", "--backlash",
        "--truth",        "--power-off-ms", "--power-cycle-after"};
    size_t i;
    for (i = 0; i < sizeof names / sizeof names[0]; i++)
        if (strcmp(opt, names[i]) == 0)
            return true;
    return false;
}

static void parse_args(options_t *o, int argc, char **argv)
{
    int i;
    memset(o, 0, sizeof *o);
    o->ids = 1u << 1;
    o->bus.seed = 1u;
    o->bus.turnaround_us = 0u;
    o->bus.power_off_us = 100000u;
    j288_sim_params_default(&o->prm);
    for (i = 1; i < argc; i++) {
        const char *a = argv[i];
        const char *v = (i + 1 < argc) ? argv[i + 1] : NULL;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            usage(stdout);
            exit(0);
        }
        if (strcmp(a, "--version") == 0) {
            printf("j288-sim %s\n", J288_VERSION_STRING);
            exit(0);
        }
        if (strcmp(a, "--quiet") == 0) {
            o->quiet = true;
            continue;
        }
        if (strcmp(a, "--echo") == 0) {
            o->echo = true;
            continue;
        }
        if (strncmp(a, "--", 2) != 0)
            die("unexpected argument '%s' (see --help)", a);
        if (!takes_value(a))
            die("unknown option '%s' (see --help)", a);
        if (v == NULL)
            die("%s needs a value (see --help)", a);
        i++;
        if (strcmp(a, "--ids") == 0)
            o->ids = parse_id_list(a, v);
        else if (strcmp(a, "--link") == 0)
            o->link = v;
        else if (strcmp(a, "--log") == 0)
            o->log = v;
        else if (strcmp(a, "--voltage") == 0)
            o->prm.voltage = parse_double(a, v, 0.0, 127.5);
        else if (strcmp(a, "--ambient") == 0)
            o->prm.ambient_c = parse_double(a, v, -40.0, 120.0);
        else if (strcmp(a, "--load-inertia") == 0)
            o->prm.load_inertia = parse_double(a, v, 0.0, 100.0);
        else if (strcmp(a, "--load-torque") == 0)
            o->prm.load_torque = parse_double(a, v, -100.0, 100.0);
        else if (strcmp(a, "--turnaround-us") == 0)
            o->bus.turnaround_us = (uint32_t)parse_ulong(a, v, 10000000ul, 10);
        else if (strcmp(a, "--exit-after") == 0)
            o->exit_after = parse_double(a, v, 0.0, 86400.0);
        else if (strcmp(a, "--seed") == 0)
            o->bus.seed = (uint64_t)parse_ulong(a, v, 0xFFFFFFFFul, 0);
        else if (strcmp(a, "--drop") == 0)
            o->bus.drop = parse_double(a, v, 0.0, 1.0);
        else if (strcmp(a, "--corrupt") == 0)
            o->bus.corrupt = parse_double(a, v, 0.0, 1.0);
        else if (strcmp(a, "--late") == 0)
            o->bus.late = parse_double(a, v, 0.0, 1.0);
        else if (strcmp(a, "--late-us") == 0)
            o->bus.late_us = (uint32_t)parse_ulong(a, v, 10000000ul, 10);
        else if (strcmp(a, "--noise") == 0)
            o->bus.noise = parse_double(a, v, 0.0, 1.0);
        else if (strcmp(a, "--dup") == 0)
            o->bus.dup_ids = (uint16_t)(o->bus.dup_ids | parse_id_list(a, v));
        else if (strcmp(a, "--fault") == 0)
            parse_fault(o, v);
        else if (strcmp(a, "--phase") == 0)
            parse_joint_angle(a, v, o->phase, &o->phase_set);
        else if (strcmp(a, "--start-angle") == 0)
            parse_joint_angle(a, v, o->angle, &o->angle_set);
        else if (strcmp(a, "--backlash") == 0)
            o->prm.backlash = parse_double(a, v, 0.0, 1.0);
        else if (strcmp(a, "--truth") == 0)
            o->truth = v;
        else if (strcmp(a, "--power-cycle-after") == 0)
            parse_cycle(o, v);
        else if (strcmp(a, "--power-off-ms") == 0)
            o->bus.power_off_us = (uint32_t)(parse_ulong(a, v, 60000ul, 10) * 1000u);
        else
            die("unknown option '%s' (see --help)", a);
    }
    if ((o->bus.dup_ids & ~o->ids) != 0u)
        die("--dup names an id that is not in --ids");
    if ((o->fault_set & ~o->ids) != 0u)
        die("--fault names an id that is not in --ids");
    if ((o->phase_set & ~o->ids) != 0u)
        die("--phase names an id that is not in --ids");
    if ((o->angle_set & ~o->ids) != 0u)
        die("--start-angle names an id that is not in --ids");
    for (i = 0; i < (int)o->ncycles; i++)
        if ((o->cycle[i].ids & ~o->ids) != 0u)
            die("--power-cycle-after names an id that is not in --ids");
}

/* ---- output queue ----------------------------------------------------------------------- */

static void queue_send(void *user, uint64_t at_us, const uint8_t *data, size_t len)
{
    sim_io_t *io = user;
    size_t i;
    if (len > CHUNK_MAX || io->qlen == QUEUE_LEN) {
        io->queue_full++;
        return;
    }
    /* Keep the queue in time order; equal times keep their order. */
    i = io->qlen;
    while (i > 0u && io->q[i - 1u].at_us > at_us) {
        io->q[i] = io->q[i - 1u];
        i--;
    }
    io->q[i].at_us = at_us;
    io->q[i].len = len;
    memcpy(io->q[i].data, data, len);
    io->qlen++;
}

static void queue_pop(sim_io_t *io)
{
    memmove(&io->q[0], &io->q[1], (io->qlen - 1u) * sizeof io->q[0]);
    io->qlen--;
}

/* Write what is due. A client that went away loses its replies. */
static void flush_due(sim_io_t *io, uint64_t now_us)
{
    while (io->qlen > 0u && io->q[0].at_us <= now_us) {
        ssize_t n = write(io->master, io->q[0].data, io->q[0].len);
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK))
            return; /* the client is not reading; try again later */
        if (n < 0) {
            io->lost_no_client++;
        } else if ((size_t)n < io->q[0].len) {
            memmove(io->q[0].data, io->q[0].data + n, io->q[0].len - (size_t)n);
            io->q[0].len -= (size_t)n;
            continue;
        }
        queue_pop(io);
    }
}

/* The statistics line, after label ("stats" at exit, "faults off: stats" on a switch). */
static void print_stats(const sim_io_t *io, const j288_sim_bus_t *bus, const char *label)
{
    const j288_sim_stats_t *st = &bus->stats;
    fprintf(stderr,
            "j288-sim: %s: bytes %llu commands %llu broadcast %llu bad-crc %llu "
            "other-ids %llu replies %llu dropped %llu corrupted %llu late %llu noise %llu "
            "duplicates %llu watchdog-trips %llu garbage-bytes %lu lost %llu power-cycles %llu\n",
            label, (unsigned long long)st->bytes, (unsigned long long)st->commands,
            (unsigned long long)st->broadcasts, (unsigned long long)st->bad_crc,
            (unsigned long long)st->for_others, (unsigned long long)st->replies,
            (unsigned long long)st->dropped, (unsigned long long)st->corrupted,
            (unsigned long long)st->late, (unsigned long long)st->noise,
            (unsigned long long)st->duplicates, (unsigned long long)st->watchdog_trips,
            (unsigned long)j288_parser_stats(&bus->parser)->garbage_bytes,
            (unsigned long long)(io->lost_no_client + io->queue_full),
            (unsigned long long)st->power_cycles);
    fflush(stderr);
}

/* Apply a SIGUSR1/SIGUSR2 wish. Replies already queued (a late one) are left to arrive. */
static void apply_fault_switch(const sim_io_t *io, j288_sim_bus_t *bus)
{
    bool on = (g_faults_on != 0);
    if (on == !bus->faults_off)
        return;
    j288_sim_bus_set_faults(bus, on);
    if (!io->quiet)
        print_stats(io, bus, on ? "faults on: stats" : "faults off: stats");
}

/* ---- truth and power cycles ---------------------------------------------------------------- */

static void print_truth(FILE *f, const j288_sim_bus_t *bus, unsigned long seq, uint64_t now_us,
                        const char *reason)
{
    uint8_t id;
    fprintf(f, "# j288-sim truth seq=%lu t=%llu.%06llu reason=%s\n", seq,
            (unsigned long long)(now_us / 1000000u), (unsigned long long)(now_us % 1000000u),
            reason);
    for (id = 0; id < J288_MAX_SERVOS; id++) {
        j288_sim_truth_t t;
        if ((bus->present & (1u << id)) == 0u)
            continue;
        j288_sim_servo_truth(&bus->servo[id], &t);
        fprintf(f,
                "id=%u theta=%.9f theta_gear=%.9f c=%.9f k=%ld p=%.9f r=%.9f out_pos=%u "
                "powered=%u cycles=%lu\n",
                (unsigned)id, t.theta, t.theta_gear, t.c, t.k, t.p, t.r, (unsigned)t.out_pos,
                t.powered ? 1u : 0u, (unsigned long)t.power_cycles);
    }
}

/* The model at now_us into the --truth target, replaced atomically (a reader never sees half
 * a file). False, with a message, when it cannot be written. */
static bool write_truth(sim_io_t *io, j288_sim_bus_t *bus, uint64_t now_us, const char *reason)
{
    char tmp[4096];
    FILE *f;
    if (io->truth == NULL)
        return true;
    j288_sim_bus_advance(bus, now_us);
    io->truth_seq++;
    if (strcmp(io->truth, "-") == 0) {
        print_truth(stderr, bus, io->truth_seq, now_us, reason);
        fflush(stderr);
        return true;
    }
    if ((size_t)snprintf(tmp, sizeof tmp, "%s.tmp", io->truth) >= sizeof tmp) {
        fprintf(stderr, "j288-sim: --truth %s: path too long\n", io->truth);
        return false;
    }
    f = fopen(tmp, "w");
    if (f == NULL) {
        fprintf(stderr, "j288-sim: --truth %s: %s\n", tmp, strerror(errno));
        return false;
    }
    print_truth(f, bus, io->truth_seq, now_us, reason);
    if (fclose(f) != 0 || rename(tmp, io->truth) != 0) {
        fprintf(stderr, "j288-sim: --truth %s: %s\n", io->truth, strerror(errno));
        (void)unlink(tmp);
        return false;
    }
    return true;
}

/* Power-cycle servos ids (0: all) at at_us; the truth follows at once and when they are back. */
static void power_cycle(sim_io_t *io, j288_sim_bus_t *bus, uint16_t ids, uint64_t at_us)
{
    uint8_t id;
    if (ids == 0u)
        ids = bus->present;
    (void)j288_sim_bus_power_cycle(bus, ids, at_us);
    if (!io->quiet) {
        fprintf(stderr, "j288-sim: power cycle: servos");
        for (id = 0; id < J288_MAX_SERVOS; id++)
            if ((ids & (1u << id)) != 0u)
                fprintf(stderr, " %u", (unsigned)id);
        fprintf(stderr, " off for %lu ms\n", (unsigned long)(io->power_off_us / 1000u));
        fflush(stderr);
    }
    (void)write_truth(io, bus, at_us, "power-off");
    if (!io->power_on_pending || io->power_on_us < at_us + io->power_off_us)
        io->power_on_us = at_us + io->power_off_us;
    io->power_on_pending = true;
}

/* Apply the power cycles and truth requests that are due at now_us. */
static void apply_power_and_truth(sim_io_t *io, j288_sim_bus_t *bus, uint64_t now_us)
{
    if (g_power_cycle) {
        g_power_cycle = 0;
        power_cycle(io, bus, 0u, now_us);
    }
    while (io->next_cycle < io->ncycles && io->cycle[io->next_cycle].at_us <= now_us) {
        power_cycle(io, bus, io->cycle[io->next_cycle].ids, io->cycle[io->next_cycle].at_us);
        io->next_cycle++;
    }
    if (io->power_on_pending && io->power_on_us <= now_us) {
        io->power_on_pending = false;
        (void)write_truth(io, bus, io->power_on_us, "power-on");
    }
    if (g_truth_wanted) {
        g_truth_wanted = 0;
        (void)write_truth(io, bus, now_us, "request");
    }
}

/* The next time apply_power_and_truth() has something to do, if before wake. */
static uint64_t power_wake(const sim_io_t *io, uint64_t wake)
{
    if (io->next_cycle < io->ncycles && io->cycle[io->next_cycle].at_us < wake)
        wake = io->cycle[io->next_cycle].at_us;
    if (io->truth != NULL && io->power_on_pending && io->power_on_us < wake)
        wake = io->power_on_us;
    return wake;
}

/* ---- log ------------------------------------------------------------------------------------ */

static void log_frame(void *user, uint64_t now_us, const uint8_t frame[J288_CMD_LEN],
                      const j288_cmd_raw_t *cmd)
{
    sim_io_t *io = user;
    unsigned i;
    if (io->log == NULL)
        return;
    fprintf(io->log, "%llu.%06llu ", (unsigned long long)(now_us / 1000000u),
            (unsigned long long)(now_us % 1000000u));
    for (i = 0; i < J288_CMD_LEN; i++)
        fprintf(io->log, "%02x", frame[i]);
    if (cmd != NULL)
        fprintf(io->log, " id=%u status=%u wd=%u tau=%d speed=%d pos=%ld kp=%d kd=%d\n",
                (unsigned)cmd->id, (unsigned)cmd->status, cmd->watchdog ? 1u : 0u, (int)cmd->tau,
                (int)cmd->speed, (long)cmd->pos, (int)cmd->kp, (int)cmd->kd);
    else
        fprintf(io->log, " bad-crc id=%u\n", (unsigned)(frame[2] & 0x0Fu));
    fflush(io->log);
}

/* ---- pty --------------------------------------------------------------------------------------
 */

static int open_pty(char *path, size_t cap)
{
    struct termios t;
    const char *name;
    int fd = posix_openpt(O_RDWR | O_NOCTTY);
    if (fd < 0)
        die("cannot create a pseudo-terminal: %s", strerror(errno));
    if (grantpt(fd) != 0 || unlockpt(fd) != 0)
        die("cannot unlock the pseudo-terminal: %s", strerror(errno));
    name = ptsname(fd);
    if (name == NULL || strlen(name) >= cap)
        die("cannot name the pseudo-terminal");
    strcpy(path, name);
    /* Raw from the start, so that nothing is echoed or translated before a client sets its
     * own mode (on a pty the master's settings are the slave's). */
    if (tcgetattr(fd, &t) == 0) {
        cfmakeraw(&t);
        (void)tcsetattr(fd, TCSANOW, &t);
    }
    if (fcntl(fd, F_SETFL, fcntl(fd, F_GETFL) | O_NONBLOCK) != 0)
        die("cannot make the pty non-blocking: %s", strerror(errno));
    (void)fcntl(fd, F_SETFD, FD_CLOEXEC);
    return fd;
}

static void place_link(const char *link, const char *target)
{
    struct stat st;
    if (lstat(link, &st) == 0) {
        if (!S_ISLNK(st.st_mode))
            die("--link %s: exists and is not a symlink; not replacing it", link);
        if (unlink(link) != 0)
            die("--link %s: cannot replace: %s", link, strerror(errno));
    }
    if (symlink(target, link) != 0)
        die("--link %s: %s", link, strerror(errno));
}

/* Remove the link only if it still points at our pty. */
static void remove_link(const char *link, const char *target)
{
    char buf[256];
    ssize_t n = readlink(link, buf, sizeof buf - 1u);
    if (n > 0) {
        buf[n] = '\0';
        if (strcmp(buf, target) == 0)
            (void)unlink(link);
    }
}

static void install_signals(sigset_t *run_mask)
{
    struct sigaction sa;
    sigset_t block;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = 0;
    (void)sigaction(SIGINT, &sa, NULL);
    (void)sigaction(SIGTERM, &sa, NULL);
    (void)sigaction(SIGHUP, &sa, NULL);
    sa.sa_handler = on_fault_signal;
    (void)sigaction(SIGUSR1, &sa, NULL);
    (void)sigaction(SIGUSR2, &sa, NULL);
    sa.sa_handler = on_power_signal;
    (void)sigaction(SIGPWR, &sa, NULL);
    sa.sa_handler = on_truth_signal;
    (void)sigaction(SIGWINCH, &sa, NULL);
    sa.sa_handler = SIG_IGN;
    (void)sigaction(SIGPIPE, &sa, NULL);
    /* Signals stay blocked except inside ppoll: no wake-up is lost between a check of
     * g_stop (or g_faults_on) and the sleep. */
    sigemptyset(&block);
    sigaddset(&block, SIGINT);
    sigaddset(&block, SIGTERM);
    sigaddset(&block, SIGHUP);
    sigaddset(&block, SIGUSR1);
    sigaddset(&block, SIGUSR2);
    sigaddset(&block, SIGPWR);
    sigaddset(&block, SIGWINCH);
    (void)sigprocmask(SIG_BLOCK, &block, run_mask);
    sigdelset(run_mask, SIGINT);
    sigdelset(run_mask, SIGTERM);
    sigdelset(run_mask, SIGHUP);
    sigdelset(run_mask, SIGUSR1);
    sigdelset(run_mask, SIGUSR2);
    sigdelset(run_mask, SIGPWR);
    sigdelset(run_mask, SIGWINCH);
}

static struct timespec ts_from_us(uint64_t us)
{
    struct timespec ts;
    ts.tv_sec = (time_t)(us / 1000000u);
    ts.tv_nsec = (long)(us % 1000000u) * 1000L;
    return ts;
}

/* Read what the client sent; false when no client has the pty open. */
static bool read_input(sim_io_t *io, j288_sim_bus_t *bus)
{
    uint8_t buf[512];
    for (;;) {
        ssize_t n = read(io->master, buf, sizeof buf);
        if (n > 0) {
            uint64_t now = sim_now_us(io);
            size_t off;
            /* The echo is on the wire before any reply can start. */
            for (off = 0; io->echo && off < (size_t)n; off += CHUNK_MAX)
                queue_send(io, now, buf + off,
                           ((size_t)n - off < CHUNK_MAX) ? (size_t)n - off : CHUNK_MAX);
            j288_sim_bus_feed(bus, buf, (size_t)n, now);
            continue;
        }
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK))
            return true;
        return false; /* EIO: the slave side is closed */
    }
}

/* Woken at now_us for a wake due at wake_us, with the host's bytes waiting: a wake that late
 * means this process was not scheduled (a loaded machine) while what the host sent sat unread
 * in the pty, so the watchdogs must not count the stretch as the host's silence. A late wake
 * with nothing waiting excuses nothing: the host was silent, and the small delays of every
 * tick on a loaded machine would otherwise add up and hold off a trip the host earned.
 * When within the stall the bytes came is unknown, so the whole stall is excused (no false
 * trip): a host silent for just over 1 s while this process was starved across the trip
 * time is not tripped. Tests that want a trip stay silent for several seconds. */
static void excuse_oversleep(j288_sim_bus_t *bus, bool input_waiting, uint64_t wake_us,
                             uint64_t now_us)
{
    if (input_waiting && now_us > wake_us)
        j288_sim_bus_excuse_stall(bus, wake_us, now_us);
}

static void serve(sim_io_t *io, j288_sim_bus_t *bus, uint64_t exit_at_us, const sigset_t *mask)
{
    uint64_t last_tick = 0;
    while (!g_stop) {
        uint64_t now = sim_now_us(io);
        uint64_t wake = now + TICK_US;
        struct pollfd pfd;
        struct timespec ts;
        int rc;
        if (exit_at_us != 0u && now >= exit_at_us)
            break;
        apply_fault_switch(io, bus);
        apply_power_and_truth(io, bus, now);
        flush_due(io, now);
        if (now - last_tick >= TICK_US) {
            j288_sim_bus_advance(bus, now);
            last_tick = now;
        }
        if (io->qlen > 0u && io->q[0].at_us < wake)
            wake = io->q[0].at_us;
        if (exit_at_us != 0u && exit_at_us < wake)
            wake = exit_at_us;
        wake = power_wake(io, wake);
        ts = ts_from_us(wake > now ? wake - now : 0u);
        pfd.fd = io->master;
        pfd.events = POLLIN;
        pfd.revents = 0;
        rc = ppoll(&pfd, 1, &ts, mask);
        if (rc < 0 && errno != EINTR)
            die("poll: %s", strerror(errno));
        excuse_oversleep(bus, rc > 0 && (pfd.revents & POLLIN) != 0, wake, sim_now_us(io));
        if (rc <= 0)
            continue;
        /* read() decides whether a client is there: the poll's hang-up may be stale (a
         * client that opened the pty since, and whose first command was just read). */
        if (!read_input(io, bus)) {
            /* No client: the master reports hang-up until one opens the pty. Nap rather
             * than spin; replies still queued for a departed client are dropped. */
            io->lost_no_client += io->qlen;
            io->qlen = 0;
            ts = ts_from_us(NAP_US);
            (void)ppoll(NULL, 0, &ts, mask);
        }
    }
}

int main(int argc, char **argv)
{
    options_t o;
    sim_io_t io;
    j288_sim_bus_t *bus;
    char path[128];
    sigset_t run_mask;
    uint64_t exit_at = 0;
    uint8_t id;

    parse_args(&o, argc, argv);
    memset(&io, 0, sizeof io);
    io.echo = o.echo;
    io.quiet = o.quiet;
    io.truth = o.truth;
    io.cycle = o.cycle;
    io.ncycles = o.ncycles;
    io.power_off_us = o.bus.power_off_us;
    bus = calloc(1, sizeof *bus);
    if (bus == NULL)
        die("out of memory");
    install_signals(&run_mask);
    /* Replies are timed in tens of microseconds: no 50 us timer slack on our sleeps. */
    (void)prctl(PR_SET_TIMERSLACK, 1ul, 0ul, 0ul, 0ul);
    if (o.log != NULL) {
        io.log = (strcmp(o.log, "-") == 0) ? stderr : fopen(o.log, "w");
        if (io.log == NULL)
            die("--log %s: %s", o.log, strerror(errno));
    }
    if (j288_sim_bus_init(bus, o.ids, &o.bus, &o.prm, queue_send, log_frame, &io) != 0)
        die("bad --ids");
    for (id = 0; id < J288_MAX_SERVOS; id++) {
        const j288_sim_servo_t *s = j288_sim_bus_servo(bus, id);
        if (s != NULL && ((o.phase_set | o.angle_set) & (1u << id)) != 0u)
            (void)j288_sim_bus_set_joint(
                bus, id, ((o.phase_set & (1u << id)) != 0u) ? o.phase[id] : s->c,
                ((o.angle_set & (1u << id)) != 0u) ? o.angle[id] : s->theta);
        if ((o.fault_set & (1u << id)) != 0u)
            (void)j288_sim_bus_inject_faults(bus, id, o.faults[id]);
    }
    /* Before the path line: whoever waits for it can read the truth at once. */
    if (!write_truth(&io, bus, 0u, "start"))
        exit(2);

    io.master = open_pty(path, sizeof path);
    if (o.link != NULL)
        place_link(o.link, path);
    io.t0_ns = mono_ns();
    if (o.exit_after > 0.0)
        exit_at = (uint64_t)(o.exit_after * 1e6);
    printf("%s\n", path);
    fflush(stdout);
    if (!o.quiet) {
        fprintf(stderr, "j288-sim: servos");
        for (id = 0; id < J288_MAX_SERVOS; id++)
            if ((o.ids & (1u << id)) != 0u)
                fprintf(stderr, " %u", (unsigned)id);
        fprintf(stderr, " on %s%s%s\n", path, o.link ? " -> " : "", o.link ? o.link : "");
    }

    serve(&io, bus, exit_at, &run_mask);

    /* The link goes first: once the master is closed the pty's number goes to the next
     * program that asks for one, and a client reopening the link (the runner's reconnection)
     * must find nothing there rather than that program's terminal. Closing the master then
     * hangs up the slave: a client sees its device vanish. */
    if (o.link != NULL)
        remove_link(o.link, path);
    (void)close(io.master);
    j288_sim_bus_advance(bus, sim_now_us(&io));
    (void)write_truth(&io, bus, sim_now_us(&io), "exit");
    print_stats(&io, bus, "stats");
    if (io.log != NULL && io.log != stderr)
        fclose(io.log);
    free(bus);
    return 0;
}
