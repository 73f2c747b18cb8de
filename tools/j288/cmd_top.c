/* `j288 top`: a live view of every joint of a bus or a robot config and of the bus counters,
 * built on the runner (host/j288_robot.h): its cycles, its joint states, its statistics. */
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <termios.h>
#include <unistd.h>

#include "cli_bus.h"
#include "frameview.h"

static const char top_help[] =
    "usage: j288 top (--config FILE | --port DEV [--ids LIST]) [--once] [--rate HZ]\n"
    "                [--interval S]\n"
    "\n"
    "A live view: every joint's angle (rad, joint frame), speed (rad/s), torque (N*m), case\n"
    "and winding temperatures, voltage and faults, and each bus's counters, redrawn every\n"
    "--interval seconds on the terminal. q or Ctrl-C quits. With --config FILE, the file's\n"
    "joints on all its buses (its zero, direction, limits); with only --port, the servos of\n"
    "--ids (default 0-14) that answer at the start, each at its output encoder angle wrapped\n"
    "to [-pi, pi).\n"
    "There is no read-only query in the protocol: every refresh sends each servo lock, so\n"
    "the servos go limp, as with status. At the end the broadcast lock goes out on every bus\n"
    "(the runner's stop): nothing is left moving.\n"
    "When stdout is not a terminal, or with --once, it prints one frame (once every joint\n"
    "that answers has a known angle, after 5 to 200 cycles) and exits.\n"
    "  --once           one frame, then exit\n"
    "  --rate HZ        bus cycles per second, 1-2000 (default 100)\n"
    "  --interval S     seconds between redraws, 0.05-10 (default 0.2)\n"
    "  --ids LIST       (without --config) the ids to look for, e.g. 1,2,3 (default 0-14)\n"
    "Columns: fresh is * when the joint answered in the latest cycle, ? when its angle is not\n"
    "known yet, - when it never answered. Counters: docs/troubleshooting.md says what each\n"
    "means.\n"
    "Exit status: 0 quit with q, or one frame printed; 1 no servo answered, a device or\n"
    "config error; 2 bad arguments; 130/143/129/131 stopped by SIGINT/SIGTERM/SIGHUP/SIGQUIT.\n"
    "\n" CLI_BUS_COMMON_HELP;

#define TOP_ACQUIRE_CYCLES 200u /* the most cycles --once waits for every angle */
#define TOP_SCAN_CYCLES    5u   /* cycles that tell which of --ids answer */

enum { OPT_ONCE = 0, OPT_RATE, OPT_INTERVAL, OPT_IDS };

typedef struct {
    bool once;
    double rate_hz, interval_s;
    uint32_t ids; /* bit per id to look for (--port without --config) */
} top_args_t;

static int parse_top_opt(void *ctx, int key, const char *v)
{
    top_args_t *a = ctx;
    switch (key) {
    case OPT_ONCE:
        a->once = true;
        return 0;
    case OPT_RATE:
        return cli_parse_real_in("--rate", v, 1.0, 2000.0, &a->rate_hz);
    case OPT_INTERVAL:
        return cli_parse_real_in("--interval", v, 0.05, 10.0, &a->interval_s);
    case OPT_IDS:
        return cli_parse_id_list("--ids", v, J288_MAX_ID, &a->ids);
    default:
        return 1;
    }
}

/* ---- the terminal ---------------------------------------------------------------------------- */

static struct termios g_saved_tty;
static bool g_tty_raw;

/* Keys without Enter and without echo; Ctrl-C stays a signal (ISIG). */
static void tty_raw(void)
{
    struct termios t;
    if (!isatty(STDIN_FILENO) || tcgetattr(STDIN_FILENO, &g_saved_tty) != 0)
        return;
    t = g_saved_tty;
    t.c_lflag &= ~(tcflag_t)(ICANON | ECHO);
    t.c_cc[VMIN] = 0;
    t.c_cc[VTIME] = 0;
    g_tty_raw = tcsetattr(STDIN_FILENO, TCSANOW, &t) == 0;
}

static void tty_restore(void)
{
    if (g_tty_raw)
        (void)tcsetattr(STDIN_FILENO, TCSANOW, &g_saved_tty);
    g_tty_raw = false;
}

/* True when q (or Q) is waiting on stdin; other keys are dropped. */
static bool quit_pressed(void)
{
    struct pollfd p;
    char c;
    p.fd = STDIN_FILENO;
    p.events = POLLIN;
    p.revents = 0;
    while (g_tty_raw && poll(&p, 1, 0) == 1 && read(STDIN_FILENO, &c, 1) == 1)
        if (c == 'q' || c == 'Q')
            return true;
    return false;
}

/* ---- one frame ------------------------------------------------------------------------------- */

/* The ports' notices (latency timer advice, low latency refused), each line ending in eol;
 * nothing under J288_QUIET=1, as the other commands. */
static void print_notices(FILE *f, const j288_robot_t *r, const char *eol)
{
    const char *quiet = getenv("J288_QUIET");
    unsigned b;
    if (quiet != NULL && strcmp(quiet, "1") == 0)
        return;
    for (b = 0; b < j288_robot_nbuses(r); b++) {
        const char *n;
        for (n = j288_robot_notices(r, b); *n != '\0'; n++) {
            if (*n == '\n')
                fputs(eol, f);
            else
                fputc(*n, f);
        }
    }
}

/* The fresh column: answered in the latest cycle, angle unknown, or never answered. */
static char fresh_mark(const j288_robot_state_t *st, const j288_robot_joint_stats_t *js)
{
    if (js->servo.successes == 0u)
        return '-';
    if (!st->known)
        return '?';
    return st->fresh ? '*' : ' ';
}

static void print_joints(FILE *f, const j288_robot_t *r, const char *eol)
{
    unsigned j;
    fprintf(f, "%-16s %-8s %2s %1s %9s %9s %8s %6s %6s %6s %7s  %s%s", "joint", "bus", "id", "",
            "angle", "speed", "torque", "case", "wind", "volt", "latency", "faults", eol);
    fprintf(f, "%-16s %-8s %2s %1s %9s %9s %8s %6s %6s %6s %7s%s", "", "", "", "", "rad", "rad/s",
            "N*m", "C", "C", "V", "us", eol);
    for (j = 0; j < j288_robot_njoints(r); j++) {
        j288_robot_state_t st;
        j288_robot_joint_stats_t js;
        char faults[256];
        (void)j288_robot_read(r, j, &st);
        (void)j288_robot_joint_stats(r, j, &js);
        fprintf(f, "%-16.16s %-8.8s %2d %c", j288_robot_joint_name(r, j),
                j288_robot_bus_name(r, (unsigned)j288_robot_joint_bus(r, j)),
                j288_robot_joint_id(r, j), fresh_mark(&st, &js));
        if (js.servo.successes == 0u) {
            fprintf(f, " %9s%s", "silent", eol);
            continue;
        }
        fprintf(f, " %9.4f %9.3f %8.3f %6.1f %6.1f %6.1f %7lu  %s%s", st.pos, st.speed,
                st.torque, st.case_temp_c, st.winding_temp_c, st.voltage_v,
                (unsigned long)js.servo.last_latency_us,
                cli_fault_list(st.faults, faults, sizeof faults), eol);
    }
}

static void print_buses(FILE *f, const j288_robot_t *r, const char *eol)
{
    unsigned b;
    fprintf(f, "%-8s %-4s %8s %8s %7s %7s %6s %7s %6s %6s %6s %7s%s", "bus", "", "sweeps", "ok",
            "failed", "timeout", "crc", "wrongid", "collis", "line", "stale", "sweep", eol);
    for (b = 0; b < j288_robot_nbuses(r); b++) {
        j288_robot_bus_stats_t bs;
        const j288_bus_stats_t *w = j288_robot_bus_wire_stats(r, b);
        (void)j288_robot_bus_stats(r, b, &bs);
        if (w == NULL)
            continue;
        fprintf(f, "%-8.8s %-4s %8lu %8lu %7lu %7lu %6lu %7lu %6lu %6lu %6lu %5luus%s",
                j288_robot_bus_name(r, b), bs.gone ? "GONE" : (bs.up ? "up" : "DOWN"),
                (unsigned long)bs.sweeps, (unsigned long)w->ok, (unsigned long)w->failed,
                (unsigned long)w->timeouts, (unsigned long)w->crc_errors,
                (unsigned long)w->wrong_id, (unsigned long)w->collisions,
                (unsigned long)w->line_errors, (unsigned long)w->stale_bytes,
                (unsigned long)bs.last_sweep_us, eol);
    }
}

/* One frame. On a terminal each line ends by clearing the rest of it and the frame by
 * clearing below it, drawn from the top left: no flicker, no scrolling. */
static void draw(const j288_robot_t *r, const char *source, bool ansi)
{
    const char *eol = ansi ? "\033[K\n" : "\n";
    j288_robot_stats_t rs;
    (void)j288_robot_stats(r, &rs);
    if (ansi)
        fputs("\033[H", stdout);
    printf("j288 top  %s  cycle %lu (%lu complete), last %lu us%s%s", source,
           (unsigned long)rs.cycles, (unsigned long)rs.complete_cycles,
           (unsigned long)rs.last_cycle_us, ansi ? "  q or Ctrl-C quits" : "", eol);
    if (ansi)
        print_notices(stdout, r, eol);
    fputs(eol, stdout);
    print_joints(stdout, r, eol);
    fputs(eol, stdout);
    print_buses(stdout, r, eol);
    if (ansi)
        fputs("\033[J", stdout);
    (void)fflush(stdout);
}

/* ---- the bus without a config ---------------------------------------------------------------- */

/* A config with one bus on the common options' port (its baud, margin and echo come with the
 * runner's options) and a joint "idN" for every id in ids, at the defaults: the joint angle
 * is the output encoder's, wrapped. */
static void bus_config(const cli_bus_opts_t *o, uint32_t ids, j288_robot_config_t *cfg)
{
    j288_robot_config_bus_t *b = &cfg->bus[0];
    unsigned id;
    memset(cfg, 0, sizeof *cfg);
    cfg->nbuses = 1;
    (void)snprintf(b->name, sizeof b->name, "bus");
    (void)snprintf(b->port, sizeof b->port, "%s", o->port);
    for (id = 0; id <= J288_MAX_ID; id++) {
        j288_robot_config_joint_t *jt = &cfg->joint[cfg->njoints];
        if ((ids & (1ul << id)) == 0u)
            continue;
        (void)snprintf(jt->name, sizeof jt->name, "id%u", id);
        jt->bus = 0;
        jt->id = (uint8_t)id;
        jt->direction = 1;
        cfg->njoints++;
    }
}

/* Open the bus with every id of a->ids, see which answer in a few cycles, and reopen it with
 * those only (an absent id would cost its reply deadline in every cycle). */
static int open_bus_ids(j288_robot_t *r, const cli_bus_opts_t *o, const top_args_t *a,
                        const j288_robot_options_t *ro)
{
    static j288_robot_config_t cfg;
    uint32_t answered = 0;
    unsigned j, k;
    int rc;
    bus_config(o, a->ids, &cfg);
    if ((rc = j288_robot_open(r, &cfg, ro)) != J288_OK)
        return rc;
    for (k = 0; k < TOP_SCAN_CYCLES && cli_stop_signal == 0; k++)
        (void)j288_robot_cycle(r, 0, NULL);
    for (j = 0; j < j288_robot_njoints(r); j++) {
        j288_robot_joint_stats_t js;
        (void)j288_robot_joint_stats(r, j, &js);
        if (js.servo.successes != 0u)
            answered |= (uint32_t)1u << (unsigned)j288_robot_joint_id(r, j);
    }
    j288_robot_close(r);
    if (cli_stop_signal != 0)
        return J288_ERR_ABORTED;
    if (answered == 0u) {
        cli_error("no servo answered on %s", o->port);
        return J288_ERR_TIMEOUT;
    }
    bus_config(o, answered, &cfg);
    return j288_robot_open(r, &cfg, ro);
}

/* ---- the command ----------------------------------------------------------------------------- */

/* Cycles until every joint that answers has a known angle (at least TOP_SCAN_CYCLES, so that
 * a silent joint had its chances; at most TOP_ACQUIRE_CYCLES). */
static int acquire_angles(j288_robot_t *r)
{
    unsigned k, j;
    int rc = J288_OK;
    for (k = 0; k < TOP_ACQUIRE_CYCLES; k++) {
        bool all = true;
        rc = j288_robot_cycle(r, 0, NULL);
        if (rc == J288_ERR_ABORTED || rc == J288_ERR_OFFLINE)
            return rc;
        for (j = 0; j < j288_robot_njoints(r) && all; j++) {
            j288_robot_state_t st;
            j288_robot_joint_stats_t js;
            (void)j288_robot_read(r, j, &st);
            (void)j288_robot_joint_stats(r, j, &js);
            all = st.known || js.servo.successes == 0u;
        }
        if (all && k + 1u >= TOP_SCAN_CYCLES)
            return J288_OK;
    }
    return rc;
}

/* Redraw every interval until q, a signal or the loss of every bus. */
static int live(j288_robot_t *r, const top_args_t *a, const char *source)
{
    uint32_t period_us = (uint32_t)(1e6 / a->rate_hz + 0.5);
    uint32_t interval_us = (uint32_t)(a->interval_s * 1e6 + 0.5);
    int rc;
    tty_raw();
    fputs("\033[H\033[2J", stdout);
    do {
        rc = j288_robot_run(r, period_us, 0, interval_us);
        draw(r, source, true);
    } while (rc == J288_OK && !quit_pressed());
    tty_restore();
    return rc;
}

int cli_cmd_top(int argc, char **argv, const cli_global_t *g)
{
    static const cli_opt_t opts[] = {{"--once", false, OPT_ONCE},
                                     {"--rate", true, OPT_RATE},
                                     {"--interval", true, OPT_INTERVAL},
                                     {"--ids", true, OPT_IDS},
                                     CLI_BUS_COMMON_OPTS,
                                     {NULL, false, 0}};
    static j288_robot_t robot; /* large: not on the stack */
    top_args_t a;
    cli_bus_opts_t o;
    j288_robot_options_t ro;
    bool ansi;
    int ec, rc;

    memset(&a, 0, sizeof a);
    a.rate_hz = 100.0;
    a.interval_s = 0.2;
    a.ids = CLI_ALL_IDS;
    cli_bus_opts_init(&o, g);
    if (cli_parse_bus_args(argc, argv, opts, top_help, &o, parse_top_opt, &a, &ec) != 0)
        return ec;
    if (o.json) {
        cli_error("--json: top draws a screen; `j288 status --json` (one servo) or `j288 "
                  "--config FILE status --json` print a result");
        return CLI_EXIT_USAGE;
    }
    if (o.config == NULL && o.port == NULL) {
        cli_error("no bus: give --config FILE or --port DEV (or set $J288_PORT)");
        return CLI_EXIT_USAGE;
    }
    memset(&ro, 0, sizeof ro);
    ro.port = o.port;
    ro.baud = o.baud;
    ro.margin_us = o.margin_us;
    ro.echo = o.echo;
    ro.retries = (uint8_t)(o.retries > 0 ? o.retries : 0);
    cli_signals_install();
    rc = (o.config != NULL) ? j288_robot_open_file(&robot, o.config, &ro)
                            : open_bus_ids(&robot, &o, &a, &ro);
    if (rc != J288_OK) {
        if (rc != J288_ERR_TIMEOUT && rc != J288_ERR_ABORTED)
            cli_error("%s", j288_robot_error(&robot));
        j288_robot_close(&robot);
        return cli_stop_signal != 0 ? cli_signal_exit_code() : CLI_EXIT_FAIL;
    }
    j288_robot_set_stop_flag(&robot, &cli_stop_signal);
    ansi = !a.once && isatty(STDOUT_FILENO);
    if (!ansi)
        print_notices(stderr, &robot, "\n");
    rc = ansi ? live(&robot, &a, o.config != NULL ? o.config : o.port) : acquire_angles(&robot);
    if (!ansi && rc != J288_ERR_ABORTED)
        draw(&robot, o.config != NULL ? o.config : o.port, false);
    if (rc == J288_ERR_OFFLINE)
        cli_error("%s", j288_robot_error(&robot));
    /* Every servo was only ever sent lock; the broadcast lock leaves the whole bus so. */
    if (rc != J288_ERR_ABORTED)
        (void)j288_robot_stop(&robot);
    j288_robot_close(&robot);
    if (cli_stop_signal != 0)
        return cli_signal_exit_code();
    return rc == J288_ERR_OFFLINE ? CLI_EXIT_FAIL : CLI_EXIT_OK;
}
