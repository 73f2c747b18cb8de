/* `j288 top`: a live view of every joint of a bus or a robot config and of the bus counters,
 * built on the runner (host/j288_robot.h): its cycles, its joint states, its statistics. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli_bus.h"
#include "frameview.h"
#include "live.h"
#include "tplot.h"

static const char top_help[] =
    "usage: j288 top (--config FILE | --port DEV [--ids LIST]) [--once] [--rate HZ]\n"
    "                [--interval S] [--plot JOINTS] [--realtime[=PRIO]] [--cpu N]\n"
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
    "  --plot JOINTS    plot these joints (up to 4, by name: idN without --config) live\n"
    "                   below the table, in braille characters (a UTF-8 terminal, SSH too):\n"
    "                   v switches between angle, speed and torque\n"
    "Columns: fresh is * when the joint answered in the latest cycle, ? when its angle is not\n"
    "known yet, - when it never answered. Counters: docs/troubleshooting.md says what each\n"
    "means.\n"
    "Exit status: 0 quit with q, or one frame printed; 1 no servo answered, a device or\n"
    "config error, every bus gone; 2 bad arguments; 130/143/129/131 stopped by\n"
    "SIGINT/SIGTERM/SIGHUP/SIGQUIT.\n"
    "\n" CLI_BUS_RT_HELP "\n" CLI_BUS_COMMON_HELP;

#define TOP_ACQUIRE_CYCLES 200u /* the most cycles --once waits for every angle */
#define TOP_SCAN_CYCLES    5u   /* cycles that tell which of --ids answer */

enum { OPT_ONCE = 0, OPT_RATE, OPT_INTERVAL, OPT_IDS, OPT_PLOT };

#define TOP_PLOT_MAX 4u /* joints plotted */

typedef struct {
    bool once;
    double rate_hz, interval_s;
    uint32_t ids; /* bit per id to look for (--port without --config) */
    const char *plot; /* --plot: joint names, comma-separated */
} top_args_t;

/* The live plot: for each plotted joint its angle, speed and torque (series 3 k + 0, 1, 2). */
typedef struct {
    unsigned n;
    unsigned joint[TOP_PLOT_MAX];
    unsigned view; /* 0 angle, 1 speed, 2 torque */
    cli_tplot_t tp;
} top_plot_t;

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
    case OPT_PLOT:
        a->plot = v;
        return 0;
    default:
        return 1;
    }
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
    for (b = 0; b <= j288_robot_nbuses(r); b++) { /* and last, the real-time set-up's */
        const char *n;
        for (n = b < j288_robot_nbuses(r) ? j288_robot_notices(r, b) : j288_robot_rt_notice(r);
             *n != '\0'; n++) {
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

/* One frame: the header, the port's notices (on a terminal), the loop's timing, the joints,
 * the buses. */
static void print_frame(FILE *f, const j288_robot_t *r, const char *source, bool ansi)
{
    j288_robot_stats_t rs;
    (void)j288_robot_stats(r, &rs);
    fprintf(f, "j288 top  %s  cycle %lu (%lu complete), last %lu us%s\n", source,
            (unsigned long)rs.cycles, (unsigned long)rs.complete_cycles,
            (unsigned long)rs.last_cycle_us, ansi ? "  q or Ctrl-C quits" : "");
    if (ansi)
        print_notices(f, r, "\n");
    cli_print_timing(f, r);
    fputs("\n", f);
    print_joints(f, r, "\n");
    fputs("\n", f);
    print_buses(f, r, "\n");
}

/* The plotted joints' names and the view, then the plot in the rows left. */
static void print_plot(FILE *f, const j288_robot_t *r, const top_plot_t *pl, const top_args_t *a,
                       unsigned cols, unsigned rows_left)
{
    static const char *const views[] = {"angle, rad", "speed, rad/s", "torque, N*m"};
    static const double min_span[] = {0.01, 0.1, 0.01};
    uint32_t mask = 0;
    unsigned k;
    fprintf(f, "\nplot: %s of", views[pl->view]);
    for (k = 0; k < pl->n; k++) {
        mask |= (uint32_t)1u << (3u * k + pl->view);
        fprintf(f, " %s", j288_robot_joint_name(r, pl->joint[k]));
    }
    fputs("  (v: angle, speed, torque)\n", f);
    if (rows_left > 3u)
        cli_live_plot(f, &pl->tp, mask, cols, rows_left - 3u > 16u ? 16u : rows_left - 3u,
                      min_span[pl->view],
                      (double)(2u * (cols - 11u) * pl->tp.per_column) / a->rate_hz, true);
}

/* On a terminal: the frame drawn in place, cut to the terminal (no wrapping, no scrolling). */
static void draw_live(const j288_robot_t *r, const char *source, const top_plot_t *pl,
                      const top_args_t *a)
{
    cli_live_frame_t fr;
    unsigned cols, rows;
    cli_live_size(&cols, &rows);
    if (!cli_live_frame_begin(&fr))
        return;
    print_frame(fr.f, r, source, true);
    if (pl->n != 0u) {
        unsigned used = 9u + j288_robot_njoints(r) + j288_robot_nbuses(r); /* (3: timing) */
        print_plot(fr.f, r, pl, a, cols, rows > used ? rows - used : 0u);
    }
    cli_live_frame_show(&fr, cols, rows);
}

/* ---- the bus without a config ---------------------------------------------------------------- */

/* Open the bus with every id of a->ids, see which answer in a few cycles, and reopen it with
 * those only (an absent id would cost its reply deadline in every cycle). */
static int open_bus_ids(j288_robot_t *r, const cli_bus_opts_t *o, const top_args_t *a,
                        const j288_robot_options_t *ro)
{
    static j288_robot_config_t cfg;
    uint32_t answered = 0;
    unsigned j, k;
    int rc;
    cli_live_bus_config(o->port, a->ids, &cfg);
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
    cli_live_bus_config(o->port, answered, &cfg);
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

/* Every cycle: the plotted joints' angle, speed and torque (NaN while unknown). */
static void plot_cycle(void *user, j288_robot_t *r, const j288_robot_cycle_t *c)
{
    top_plot_t *pl = user;
    double v[CLI_TPLOT_MAX_SERIES];
    unsigned k;
    (void)c;
    if (pl->n == 0u)
        return;
    for (k = 0; k < CLI_TPLOT_MAX_SERIES; k++)
        v[k] = NAN;
    for (k = 0; k < pl->n; k++) {
        j288_robot_state_t st;
        (void)j288_robot_read(r, pl->joint[k], &st);
        if (st.known && st.fresh) {
            v[3u * k] = st.pos;
            v[3u * k + 1u] = st.speed;
            v[3u * k + 2u] = st.torque;
        }
    }
    cli_tplot_add(&pl->tp, v);
}

/* --plot's names into joint indices (the runner's); 0, or -1 after an error line. */
static int plot_joints(const j288_robot_t *r, const char *names, const top_args_t *a,
                       top_plot_t *pl)
{
    char buf[256];
    char *name, *save = NULL;
    memset(pl, 0, sizeof *pl);
    if (names == NULL)
        return 0;
    (void)snprintf(buf, sizeof buf, "%s", names);
    for (name = strtok_r(buf, ",", &save); name != NULL; name = strtok_r(NULL, ",", &save)) {
        int j = j288_robot_find_joint(r, name);
        if (j < 0) {
            cli_error("--plot: no joint '%s'%s", name,
                      j288_robot_njoints(r) != 0u && strncmp(j288_robot_joint_name(r, 0), "id", 2) == 0
                          ? " among the servos that answered (names are idN)"
                          : "");
            return -1;
        }
        if (pl->n == TOP_PLOT_MAX) {
            cli_error("--plot: at most %u joints", TOP_PLOT_MAX);
            return -1;
        }
        pl->joint[pl->n++] = (unsigned)j;
    }
    /* 20 columns a second: a screen 80 cells wide spans about 7 s */
    cli_tplot_init(&pl->tp, 3u * pl->n, (unsigned)(a->rate_hz / 20.0 + 0.5));
    return 0;
}

/* Redraw every interval until q or a signal (a bus gone is shown, and reopened when it
 * reappears at its path); v cycles the plot. */
static int live(j288_robot_t *r, const top_args_t *a, const char *source, top_plot_t *pl)
{
    uint32_t period_us = (uint32_t)(1e6 / a->rate_hz + 0.5);
    uint32_t interval_us = (uint32_t)(a->interval_s * 1e6 + 0.5);
    bool quit = false;
    int rc;
    (void)cli_live_raw();
    fputs("\033[H\033[2J", stdout);
    do {
        int key;
        rc = j288_robot_run(r, period_us, 0, interval_us);
        while ((key = cli_live_key()) != CLI_KEY_NONE) {
            if (key == 'q' || key == 'Q')
                quit = true;
            else if (key == 'v')
                pl->view = (pl->view + 1u) % 3u;
        }
        draw_live(r, source, pl, a);
    } while (rc == J288_OK && !quit);
    cli_live_restore();
    return rc;
}

int cli_cmd_top(int argc, char **argv, const cli_global_t *g)
{
    static const cli_opt_t opts[] = {{"--once", false, OPT_ONCE},
                                     {"--rate", true, OPT_RATE},
                                     {"--interval", true, OPT_INTERVAL},
                                     {"--ids", true, OPT_IDS},
                                     {"--plot", true, OPT_PLOT},
                                     CLI_BUS_RT_OPTS,
                                     CLI_BUS_COMMON_OPTS,
                                     {NULL, false, 0}};
    static j288_robot_t robot; /* large: not on the stack */
    static top_plot_t plot;
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
    if (o.port == NULL && getenv("J288_PORT") != NULL && getenv("J288_PORT")[0] != '\0')
        o.port = getenv("J288_PORT");
    if (o.config == NULL && o.port == NULL) {
        cli_error("no bus: give --config FILE or --port DEV (or set $J288_PORT)");
        return CLI_EXIT_USAGE;
    }
    memset(&ro, 0, sizeof ro);
    memset(&plot, 0, sizeof plot);
    ro.port = o.port;
    if (cli_bus_baud(o.baud, &ro.baud) != 0)
        return CLI_EXIT_USAGE;
    ro.on_cycle = plot_cycle;
    ro.user = &plot;
    ro.margin_us = o.margin_us;
    ro.echo = o.echo;
    ro.retries = (uint8_t)(o.retries > 0 ? o.retries : 0);
    cli_bus_rt_options(&o, &ro);
    cli_signals_install();
    rc = (o.config != NULL) ? j288_robot_open_file(&robot, o.config, &ro)
                            : open_bus_ids(&robot, &o, &a, &ro);
    if (rc != J288_OK) {
        if (rc != J288_ERR_TIMEOUT && rc != J288_ERR_ABORTED)
            cli_error("%s", j288_robot_error(&robot));
        j288_robot_close(&robot);
        return cli_stop_signal != 0 ? cli_signal_exit_code()
                                    : (rc == J288_ERR_BAD_ARG ? CLI_EXIT_USAGE : CLI_EXIT_FAIL);
    }
    j288_robot_set_stop_flag(&robot, &cli_stop_signal);
    if (plot_joints(&robot, a.plot, &a, &plot) != 0) {
        j288_robot_close(&robot);
        return CLI_EXIT_USAGE;
    }
    ansi = !a.once && isatty(STDOUT_FILENO);
    if (!ansi)
        print_notices(stderr, &robot, "\n");
    rc = ansi ? live(&robot, &a, o.config != NULL ? o.config : o.port, &plot)
              : acquire_angles(&robot);
    if (!ansi && rc != J288_ERR_ABORTED) {
        print_frame(stdout, &robot, o.config != NULL ? o.config : o.port, false);
        (void)fflush(stdout);
    }
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
