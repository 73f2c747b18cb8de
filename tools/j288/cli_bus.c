/* Shared plumbing of the bus commands; see cli_bus.h. */
#include "cli_bus.h"

#include <limits.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

volatile sig_atomic_t cli_stop_signal = 0;
unsigned cli_watchdog_trips = 0;

/* A pseudo-terminal (the simulator) answers in a few hundred microseconds, but a loaded
 * machine can stall either side for milliseconds; a USB adapter needs its latency timer
 * (the port's default). */
#define PTY_MARGIN_US 5000u
/* A lock is re-sent until its reply confirms it: at least LOCK_ATTEMPTS times, and for up to
 * LOCK_CONFIRM_US after the lock pass began. A fixed number of attempts (three transactions
 * of one to four reply budgets: 15-60 ms on a pty) was too short for a starved simulator, or
 * a busy computer's USB adapter, to answer, though it answers a moment later; the time bound
 * still reports a servo that never does. Half a second: well inside the servo's own 1 s
 * watchdog. */
#define LOCK_ATTEMPTS 3
#define LOCK_CONFIRM_US 500000u

void cli_bus_opts_init(cli_bus_opts_t *o, const cli_global_t *g)
{
    memset(o, 0, sizeof *o);
    o->port = g->port;
    o->baud = g->baud;
    o->config = g->config; /* `j288 --config F status --joint hip` as well */
    o->margin_us = g->margin_us;
    o->echo = g->echo;
    o->retries = g->has_retries ? (int)g->retries : -1;
    o->cpu = -1;
}

int cli_bus_common_opt(cli_bus_opts_t *o, int key, const char *value)
{
    double v;
    switch (key) {
    case CLI_OPT_PORT:
        o->port = value;
        return 0;
    case CLI_OPT_BAUD:
        if (cli_parse_qty(J288_QTY_BAUD, "--baud", value, &v) != 0) {
            return -1;
        }
        o->baud = (uint32_t)v;
        return 0;
    case CLI_OPT_MARGIN:
        if (cli_parse_qty(J288_QTY_MARGIN_US, "--margin-us", value, &v) != 0) {
            return -1;
        }
        o->margin_us = (uint32_t)v;
        return 0;
    case CLI_OPT_ECHO:
        o->echo = true;
        return 0;
    case CLI_OPT_RETRIES:
        if (cli_parse_qty(J288_QTY_RETRIES, "--retries", value, &v) != 0) {
            return -1;
        }
        o->retries = (int)v;
        return 0;
    case CLI_OPT_JSON:
        o->json = true;
        return 0;
    case CLI_OPT_CONFIG:
        o->config = value;
        return 0;
    case CLI_OPT_REALTIME:
    case CLI_OPT_CPU: {
        long long n = J288_RT_DEFAULT_PRIORITY;
        if (key == CLI_OPT_REALTIME) {
            if (value != NULL && cli_parse_int("--realtime", value, 1, 99, &n) != 0) {
                return -1;
            }
            o->realtime = (int)n;
        } else {
            if (cli_parse_int("--cpu", value, 0, 1023, &n) != 0) {
                return -1;
            }
            o->cpu = (int)n;
        }
        return 0;
    }
    default:
        return 1;
    }
}

static void on_signal(int sig)
{
    if (cli_stop_signal == 0) {
        cli_stop_signal = sig;
    }
}

#ifdef _WIN32
/* Ctrl-C and Ctrl-Break (and closing the console) run this on a thread of their own: record
 * the stop as SIGINT (SIGTERM for the others) for the command loops, which lock every bus
 * they drove. Closing the console ends the process a few seconds after this returns, so it
 * waits a little for the locks to go out. */
static BOOL WINAPI on_console_event(DWORD type)
{
    on_signal(type == CTRL_C_EVENT || type == CTRL_BREAK_EVENT ? SIGINT : SIGTERM);
    if (type == CTRL_CLOSE_EVENT || type == CTRL_LOGOFF_EVENT || type == CTRL_SHUTDOWN_EVENT)
        Sleep(2000);
    return TRUE; /* handled: the process goes on to its safe stop */
}

void cli_signals_install(void)
{
    (void)SetConsoleCtrlHandler(on_console_event, TRUE);
}
#else
/* A signal the tool was started ignoring stays ignored: nohup's SIGHUP, a background job's
 * SIGQUIT (the command then runs on, driving its servos as before: nothing is left loose). */
static void install_unless_ignored(int sig, const struct sigaction *sa)
{
    struct sigaction old;
    if (sigaction(sig, NULL, &old) == 0 && old.sa_handler == SIG_IGN)
        return;
    sigaction(sig, sa, NULL);
}

void cli_signals_install(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = 0; /* no SA_RESTART: a blocking call returns EINTR at once */
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    /* A closed terminal or SSH session (SIGHUP) and Ctrl-\ (SIGQUIT, whose default would
     * dump core) stop as SIGTERM does: their default actions leave the servos driven. */
    install_unless_ignored(SIGHUP, &sa);
    install_unless_ignored(SIGQUIT, &sa);
}
#endif

int cli_signal_exit_code(void)
{
#ifndef _WIN32
    if (cli_stop_signal == SIGHUP)
        return CLI_EXIT_SIGHUP;
    if (cli_stop_signal == SIGQUIT)
        return CLI_EXIT_SIGQUIT;
#endif
    return cli_stop_signal == SIGTERM ? CLI_EXIT_SIGTERM : CLI_EXIT_SIGINT;
}

#ifdef _WIN32
static bool is_pseudo_terminal(const char *dev)
{
    (void)dev; /* COM ports only (Wine maps them onto ptys, but says nothing of it) */
    return false;
}
#else
static bool is_pseudo_terminal(const char *dev)
{
    char real[PATH_MAX];
    if (realpath(dev, real) == NULL) {
        return false;
    }
    return strncmp(real, "/dev/pts/", 9) == 0;
}
#endif

void cli_print_notices(const char *notices)
{
    static bool printed;
    const char *quiet = getenv("J288_QUIET");
    if (quiet != NULL && strcmp(quiet, "1") == 0) {
        return;
    }
    if (!printed && notices != NULL && notices[0] != '\0') {
        fputs(notices, stderr);
        printed = true;
    }
}

void cli_report_watchdog(const char *what)
{
    cli_watchdog_trips++;
    cli_error("%s had tripped its watchdog (no command for 1 s): cleared, and the command "
              "sent again with the watchdog bit 0",
              what);
}

unsigned cli_report_lost_buses(const j288_robot_t *r)
{
    char names[256] = "";
    unsigned b, n = 0;
    for (b = 0; b < j288_robot_nbuses(r); b++) {
        j288_robot_bus_stats_t bs;
        if (j288_robot_bus_stats(r, b, &bs) != J288_OK || bs.down_events + bs.gone_events == 0u)
            continue;
        (void)snprintf(names + strlen(names), sizeof names - strlen(names), "%s'%s'",
                       n++ > 0u ? ", " : "", j288_robot_bus_name(r, b));
    }
    if (n > 0u)
        cli_error("%s %s lost during the command (exit 1)", n > 1u ? "buses" : "bus", names);
    return n;
}

int cli_bus_baud(uint32_t given, uint32_t *baud)
{
    const char *env = getenv("J288_BAUD");
    double v;
    *baud = given;
    if (given != 0u || env == NULL || env[0] == '\0')
        return 0;
    if (cli_parse_qty(J288_QTY_BAUD, "$J288_BAUD", env, &v) != 0)
        return -1;
    *baud = (uint32_t)v;
    return 0;
}

int cli_bus_open(cli_bus_t *b, const cli_bus_opts_t *o, int default_retries)
{
    static j288_robot_t robot; /* large, and one bus per process */
    j288_robot_options_t ro;
    const char *dev = o->port;
    uint32_t baud;
    int rc;

    memset(b, 0, sizeof *b);
    if (dev == NULL || dev[0] == '\0') {
        dev = getenv("J288_PORT");
    }
    if (dev == NULL || dev[0] == '\0') {
        cli_error("no device: give --port DEV (or set J288_PORT)");
        return CLI_EXIT_USAGE;
    }
    b->dev = dev;
    if (cli_bus_baud(o->baud, &baud) != 0)
        return CLI_EXIT_USAGE;
    b->robot = &robot;
    memset(&ro, 0, sizeof ro);
    ro.baud = baud;
    ro.echo = o->echo;
    ro.margin_us =
        o->margin_us != 0u ? o->margin_us : (is_pseudo_terminal(dev) ? PTY_MARGIN_US : 0u);
    ro.retries = (uint8_t)(o->retries >= 0 ? o->retries : default_retries);
    cli_bus_rt_options(o, &ro);
    rc = j288_robot_open_port(&robot, dev, &ro);
    if (rc != J288_OK) {
        cli_error("%s", cli_bus_error(b));
        return rc == J288_ERR_BAD_ARG ? CLI_EXIT_USAGE : CLI_EXIT_FAIL;
    }
    cli_print_notices(j288_robot_notices(&robot, 0));
    cli_print_rt_notice(&robot);
    j288_robot_set_stop_flag(&robot, &cli_stop_signal);
    b->open = true;
    return CLI_EXIT_OK;
}

void cli_bus_rt_options(const cli_bus_opts_t *o, j288_robot_options_t *ro)
{
    ro->realtime = (uint8_t)o->realtime;
    ro->pin_cpu = o->cpu >= 0;
    ro->cpu = (uint16_t)(o->cpu >= 0 ? o->cpu : 0);
}

void cli_print_rt_notice(const j288_robot_t *r)
{
    const char *quiet = getenv("J288_QUIET");
    if (quiet == NULL || strcmp(quiet, "1") != 0) {
        fputs(j288_robot_rt_notice(r), stderr);
    }
}

void cli_print_timing(FILE *f, const j288_robot_t *r)
{
    j288_rt_report_t rep;
    char text[640];
    if (j288_robot_timing(r, &rep) != J288_OK)
        return;
    fputs(j288_rt_format(&rep, text, sizeof text), f);
}

static void json_summary(cli_json_t *j, const char *key, const j288_rt_summary_t *s)
{
    cli_json_begin_object(j, key);
    cli_json_uint(j, "count", s->count);
    cli_json_uint(j, "p50", s->p50_us);
    cli_json_uint(j, "p99", s->p99_us);
    cli_json_uint(j, "p99_9", s->p999_us);
    cli_json_uint(j, "max", s->max_us);
    cli_json_end_object(j);
}

void cli_json_timing(cli_json_t *j, const j288_robot_t *r)
{
    j288_rt_report_t rep;
    if (j288_robot_timing(r, &rep) != J288_OK)
        return;
    cli_json_begin_object(j, "timing");
    cli_json_uint(j, "cycles", rep.cycles);
    cli_json_uint(j, "period_us", rep.period_us);
    cli_json_uint(j, "missed_deadlines", rep.missed);
    cli_json_uint(j, "skipped_periods", rep.skipped);
    cli_json_uint(j, "cut_cycles", rep.cut);
    json_summary(j, "lateness_us", &rep.lateness);
    json_summary(j, "duration_us", &rep.duration);
    cli_json_int(j, "priority", rep.priority);
    cli_json_int(j, "cpu", rep.cpu);
    cli_json_bool(j, "memory_locked", rep.memory_locked != 0u);
    cli_json_end_object(j);
}

const char *cli_bus_error(const cli_bus_t *b)
{
    /* the runner prefixes "bus 'bus': "; the port's own message is what the user needs */
    const char *msg = j288_robot_error(b->robot);
    const char *colon = strncmp(msg, "bus '", 5) == 0 ? strstr(msg, "': ") : NULL;
    return colon != NULL ? colon + 3 : msg;
}

void cli_bus_close(cli_bus_t *b)
{
    if (b->open) {
        /* Every servo driven confirmed its lock: no broadcast for the others on the bus. */
        if (b->driven == 0u)
            j288_robot_close_keep(b->robot);
        else
            j288_robot_close(b->robot);
        b->open = false;
    }
}

void cli_bus_close_keep(cli_bus_t *b)
{
    if (b->open) {
        j288_robot_close_keep(b->robot);
        b->open = false;
    }
}

bool cli_bus_gone(const cli_bus_t *b)
{
    j288_robot_bus_stats_t bs;
    return !b->open || j288_robot_bus_stats(b->robot, 0, &bs) != J288_OK || bs.gone;
}

int cli_bus_transfer(cli_bus_t *b, const j288_cmd_raw_t *cmd, j288_txn_t *txn)
{
    bool cleared = false;
    int rc;
    /* Marked before sending: even unconfirmed, the servo may have obeyed, so it is owed a
     * lock. */
    if (cmd->status != J288_MODE_LOCK && cmd->id <= J288_MAX_ID) {
        b->driven = (uint16_t)(b->driven | (1u << cmd->id));
    }
    rc = j288_robot_transfer(b->robot, 0, cmd, txn, &cleared);
    if (cleared) {
        char what[32];
        (void)snprintf(what, sizeof what, "servo %u", (unsigned)cmd->id);
        cli_report_watchdog(what);
    }
    return rc;
}

void cli_lock_cmd(uint8_t id, j288_cmd_raw_t *cmd)
{
    memset(cmd, 0, sizeof *cmd);
    cmd->id = id;
    cmd->status = J288_MODE_LOCK;
    cmd->watchdog = false;
}

/* Whether a lock not yet confirmed is sent once more (see LOCK_CONFIRM_US). */
static bool lock_keeps_trying(int attempts, uint32_t start_us)
{
    return attempts < LOCK_ATTEMPTS || j288_robot_now_us() - start_us < LOCK_CONFIRM_US;
}

int cli_bus_lock_driven(cli_bus_t *b)
{
    uint32_t start;
    int silent = 0;
    uint8_t id;
    j288_cmd_raw_t cmd;

    if (cli_bus_gone(b)) {
        return b->driven != 0u ? 1 : 0;
    }
    start = j288_robot_now_us();
    for (id = 0; id <= J288_MAX_ID; id++) {
        int attempt, rc = J288_ERR_TIMEOUT;
        if ((b->driven & (1u << id)) == 0u) {
            continue;
        }
        cli_lock_cmd(id, &cmd);
        for (attempt = 0; rc != J288_OK && lock_keeps_trying(attempt, start); attempt++) {
            rc = j288_robot_transfer(b->robot, 0, &cmd, NULL, NULL);
            if (rc == J288_ERR_OFFLINE) {
                return 1;
            }
        }
        if (rc == J288_OK) {
            b->driven = (uint16_t)(b->driven & ~(1u << id));
        } else {
            silent++;
        }
    }
    if (silent > 0) {
        /* Someone did not confirm: tell every servo at once (the runner's stop). */
        (void)j288_robot_stop(b->robot);
    }
    return silent;
}

void cli_report_txn_failure(cli_bus_t *b, uint8_t id, int rc)
{
    if (rc == J288_ERR_OFFLINE || cli_bus_gone(b)) {
        cli_error("%s", cli_bus_error(b));
    } else if (rc == J288_ERR_TIMEOUT) {
        cli_error("no reply from servo %u on %s (check id, power, wiring and --baud)", (unsigned)id,
                  b->dev);
    } else {
        cli_error("servo %u on %s: %s", (unsigned)id, b->dev, j288_strerror(rc));
    }
}

int cli_bus_sleep_until(cli_bus_t *b, uint32_t until_us)
{
    return j288_robot_idle(b->robot, until_us);
}

/* Parse loop shared by every bus command: common options are handled here, the command's
 * own keys are passed to fn. Returns -1 (exit code in *exit_code) to stop, 0 when done. */
int cli_parse_bus_args(int argc, char **argv, const cli_opt_t *opts, const char *help,
                          cli_bus_opts_t *o, cli_own_opt_fn fn, void *ctx, int *exit_code)
{
    cli_args_t a;
    const char *v;
    int key, rc;
    cli_args_init(&a, argc, argv);
    while ((key = cli_args_next(&a, opts, &v)) != CLI_ARG_END) {
        if (key == CLI_ARG_HELP) {
            fputs(help, stdout);
            *exit_code = CLI_EXIT_OK;
            return -1;
        }
        if (key == CLI_ARG_ERROR) {
            *exit_code = CLI_EXIT_USAGE;
            return -1;
        }
        rc = key == CLI_ARG_POSITIONAL ? 1 : cli_bus_common_opt(o, key, v);
        if (rc == 1) {
            rc = fn != NULL ? fn(ctx, key, v) : 1;
            if (rc == 1) {
                cli_error("unexpected argument '%s' (try --help)", v != NULL ? v : "");
                rc = -1;
            }
        }
        if (rc != 0) {
            *exit_code = CLI_EXIT_USAGE;
            return -1;
        }
    }
    return 0;
}
