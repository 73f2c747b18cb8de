/* `j288 --config robot.yaml log|status|hold|stop`: every bus and joint of a robot config from
 * one loop (host/j288_robot.h), when no --id or --joint picks one servo. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli_bus.h"
#include "j288_robot.h"
#include "json.h"

static const char robot_help[] =
    "usage: j288 --config FILE log|status|hold|stop [options]\n"
    "\n"
    "Without --id or --joint, these commands drive every bus and joint of the robot config\n"
    "FILE from one loop: each cycle sends every joint its command on every bus at once and\n"
    "ends when every bus that answers is done. Joint frame (the file's zero, direction and\n"
    "limits), SI units.\n"
    "  status         read every joint once its angle is known; one line per joint\n"
    "  log            cycles at --rate for --duration; --csv FILE writes one row per joint\n"
    "                 per cycle in the single-servo log's format, which `j288 plot` reads\n"
    "                 (time_s, id, ok, pos_rad, speed_rad_s, torque_nm, case_temp_c,\n"
    "                 winding_temp_c, voltage_v, faults, latency_us, pos_des_rad), then\n"
    "                 joint, bus, cycle; --hold holds every joint meanwhile\n"
    "  hold           hold every joint where it is (the file's kp, kd; where it gives none,\n"
    "                 kp 20 N*m/rad, kd 2.5 N*m*s/rad) for --duration, or until Ctrl-C\n"
    "  stop           broadcast lock (watchdog bit 0) on every bus (each on its own: a bus\n"
    "                 that cannot be opened is reported, the others are stopped)\n"
    "options:\n"
    "  --config FILE  the robot config (also accepted before the command)\n"
    "  --port DEV     the device when the file names no bus\n"
    "  --margin-us N  reply margin for buses whose entry gives none (default 20000)\n"
    "  --baud N, --echo, --retries N  for buses whose entry gives none (--baud: default\n"
    "                 $J288_BAUD, else 6000000); each also accepted before the command\n"
    "  --rate HZ      cycles per second (log, hold; default 500; 0: back to back)\n"
    "  --duration S   seconds (log: default 1; hold: default until Ctrl-C)\n"
    "  --csv FILE     (log) per-joint rows\n"
    "  --hold         (log) hold every joint while logging\n"
    "  --json         (status, log, hold, stop) machine-readable output\n"
    "  --stop-on-bus-loss  (log, hold) a bus that stops answering or vanishes stops every\n"
    "                 bus and ends the command: no half-held robot\n"
    "  --realtime[=PRIO]  (log, hold) memory locked, the loop under SCHED_FIFO at PRIO\n"
    "                 (1-99, default 80); refused without the rights: a notice says how to\n"
    "                 get them (ulimit -r, limits.d, CAP_SYS_NICE), and the loop runs on\n"
    "  --cpu N        (log, hold) pin the loop to CPU N\n"
    "Pacing (log, hold): cycle k is due at the first cycle's time + k/HZ; a cycle that\n"
    "overruns makes the next start at once (a missed deadline), periods wholly missed are\n"
    "skipped, never sent back to back. The summary's timing lines: deadlines missed,\n"
    "periods skipped, cycles cut at their bound, wake-up lateness and cycle duration (p50,\n"
    "p99, p99.9, max); docs/realtime.md.\n"
    "A bus that stops answering or vanishes is lost: the others go on without it (its joints\n"
    "go stale, reported at the end) and the command exits 1 when it ends. A vanished device\n"
    "is opened again when it reappears at the same path (a udev symlink): its joints restart\n"
    "at lock, their angles found again; hold (and log --hold) then holds each where it is.\n"
    "A servo found with its watchdog tripped is cleared and reported (exit 1).\n"
    "Ctrl-C, SIGTERM, SIGHUP or SIGQUIT sends the broadcast lock on every bus before exiting\n"
    "(130, 143, 129, 131). After the tool has gone every servo stays locked (no torque): hold\n"
    "ends with lock too (a robot left holding with no host would have nobody watching its\n"
    "buses and limits); one joint held on after exit: j288 hold --joint NAME --then hold.\n"
    "Exit status: 0 done; 1 a device or config error, a joint that never answered, or a bus\n"
    "lost during the command (whether or not --stop-on-bus-loss stopped the rest); 2 bad\n"
    "arguments.\n";

enum {
    OPT_CONFIG = 0,
    OPT_PORT,
    OPT_MARGIN,
    OPT_RATE,
    OPT_DURATION,
    OPT_CSV,
    OPT_HOLD,
    OPT_JSON,
    OPT_STOP_ON_LOSS,
    OPT_BAUD,
    OPT_ECHO,
    OPT_RETRIES,
    OPT_REALTIME,
    OPT_CPU
};
static const cli_opt_t robot_opts[] = {
    {"--config", true, OPT_CONFIG}, {"--port", true, OPT_PORT},   {"--margin-us", true, OPT_MARGIN},
    {"--rate", true, OPT_RATE},     {"--duration", true, OPT_DURATION}, {"--csv", true, OPT_CSV},
    {"--hold", false, OPT_HOLD},    {"--json", false, OPT_JSON},
    {"--stop-on-bus-loss", false, OPT_STOP_ON_LOSS}, {"--baud", true, OPT_BAUD},
    {"--echo", false, OPT_ECHO}, {"--retries", true, OPT_RETRIES},
    {"--realtime", CLI_VALUE_OPTIONAL, OPT_REALTIME}, {"--cpu", true, OPT_CPU}, {NULL, false, 0}};

typedef struct {
    const char *config, *port, *csv;
    uint32_t margin_us, baud;
    double rate_hz, duration_s;
    bool have_duration, hold, json, stop_on_loss, echo;
    int retries;
    int realtime, cpu; /* --realtime[=PRIO] (0: not asked), --cpu N (-1: not asked) */
} robot_args_t;

typedef struct {
    const j288_robot_t *robot;
    FILE *csv;
    uint32_t t0;
    unsigned joint_events, bus_events;
    bool held; /* every joint held where it was (pos_des: the hold pose) */
    double hold_pos[J288_ROBOT_MAX_JOINTS];
    bool rehold[J288_ROBOT_MAX_JOINTS]; /* back with its bus: hold once its angle is known */
} robot_run_t;


static const char *const robot_commands[] = {"log", "status", "hold", "stop", NULL};

bool cli_robot_takes(const char *command, int argc, char **argv, const cli_global_t *g)
{
    bool config = g->config != NULL, named = false;
    int i, k;
    for (k = 0; robot_commands[k] != NULL && strcmp(robot_commands[k], command) != 0; k++) {
    }
    if (robot_commands[k] == NULL)
        return false;
    for (i = 1; i < argc && strcmp(argv[i], "--") != 0; i++) {
        if (strcmp(argv[i], "--id") == 0 || strncmp(argv[i], "--id=", 5) == 0 ||
            strcmp(argv[i], "--joint") == 0 || strncmp(argv[i], "--joint=", 8) == 0)
            named = true;
        if (strcmp(argv[i], "--config") == 0 || strncmp(argv[i], "--config=", 9) == 0)
            config = true;
    }
    return config && !named;
}

static int parse_robot_args(int argc, char **argv, const cli_global_t *g, robot_args_t *a,
                            int *exit_code)
{
    cli_args_t p;
    const char *v;
    double n;
    int key;
    memset(a, 0, sizeof *a);
    a->config = g->config;
    a->port = g->port;
    a->margin_us = g->margin_us;
    a->baud = g->baud;
    a->echo = g->echo;
    a->retries = g->has_retries ? (int)g->retries : -1;
    a->rate_hz = 500.0;
    a->duration_s = 1.0;
    a->cpu = -1;
    cli_args_init(&p, argc, argv);
    while ((key = cli_args_next(&p, robot_opts, &v)) != CLI_ARG_END) {
        int rc = 0;
        switch (key) {
        case CLI_ARG_HELP:
            fputs(robot_help, stdout);
            *exit_code = CLI_EXIT_OK;
            return -1;
        case CLI_ARG_ERROR:
            *exit_code = CLI_EXIT_USAGE;
            return -1;
        case CLI_ARG_POSITIONAL:
            cli_error("unexpected argument '%s'", v);
            rc = -1;
            break;
        case OPT_CONFIG:
            a->config = v;
            break;
        case OPT_PORT:
            a->port = v;
            break;
        case OPT_MARGIN:
            rc = cli_parse_qty(J288_QTY_MARGIN_US, "--margin-us", v, &n);
            a->margin_us = (uint32_t)n;
            break;
        case OPT_BAUD:
            rc = cli_parse_qty(J288_QTY_BAUD, "--baud", v, &n);
            a->baud = (uint32_t)n;
            break;
        case OPT_ECHO:
            a->echo = true;
            break;
        case OPT_RETRIES:
            rc = cli_parse_qty(J288_QTY_RETRIES, "--retries", v, &n);
            a->retries = (int)n;
            break;
        case OPT_RATE:
            rc = cli_parse_real_in("--rate", v, 0.0, 100000.0, &a->rate_hz);
            break;
        case OPT_DURATION:
            rc = cli_parse_real_in("--duration", v, 0.001, 86400.0, &a->duration_s);
            a->have_duration = true;
            break;
        case OPT_CSV:
            a->csv = v;
            break;
        case OPT_HOLD:
            a->hold = true;
            break;
        case OPT_STOP_ON_LOSS:
            a->stop_on_loss = true;
            break;
        case OPT_REALTIME:
        case OPT_CPU: {
            long long k = J288_RT_DEFAULT_PRIORITY;
            if (key == OPT_CPU)
                rc = cli_parse_int("--cpu", v, 0, 1023, &k);
            else if (v != NULL)
                rc = cli_parse_int("--realtime", v, 1, 99, &k);
            if (key == OPT_CPU)
                a->cpu = (int)k;
            else
                a->realtime = (int)k;
            break;
        }
        default: /* OPT_JSON */
            a->json = true;
            break;
        }
        if (rc != 0) {
            *exit_code = CLI_EXIT_USAGE;
            return -1;
        }
    }
    if (a->config == NULL) {
        cli_error("--config FILE is needed without --id or --joint");
        *exit_code = CLI_EXIT_USAGE;
        return -1;
    }
    return 0;
}

static void on_event(void *user, const j288_robot_event_t *ev)
{
    robot_run_t *run = user;
    if (ev->kind == J288_ROBOT_EV_BUS_DOWN || ev->kind == J288_ROBOT_EV_BUS_UP ||
        ev->kind == J288_ROBOT_EV_BUS_GONE || ev->kind == J288_ROBOT_EV_BUS_BACK) {
        static const char *const what[] = {
            "", "", "stopped answering", "answers again", "is gone", "",
            "is back (its device reopened): its joints restart at lock"};
        unsigned j;
        run->bus_events++;
        fprintf(stderr, "j288: bus '%s' %s\n", j288_robot_bus_name(run->robot, ev->bus),
                what[ev->kind]);
        for (j = 0; ev->kind == J288_ROBOT_EV_BUS_BACK && j < j288_robot_njoints(run->robot); j++)
            run->rehold[j] = run->held && j288_robot_joint_bus(run->robot, j) == (int)ev->bus;
    } else if (ev->kind == J288_ROBOT_EV_JOINT) {
        run->joint_events++;
    } else if (ev->kind == J288_ROBOT_EV_WATCHDOG) {
        char what[J288_ROBOT_CONFIG_NAME_MAX + 16];
        (void)snprintf(what, sizeof what, "joint %s",
                       ev->joint >= 0 ? j288_robot_joint_name(run->robot, (unsigned)ev->joint)
                                      : "?");
        cli_report_watchdog(what);
    }
}

/* A bus back from the dead: each of its joints is held where it is found (no jump), once
 * its angle is known again; a joint found beyond its limits stays at lock. */
static void rehold(robot_run_t *run, j288_robot_t *r)
{
    unsigned j;
    for (j = 0; j < j288_robot_njoints(r); j++) {
        j288_robot_state_t st;
        int rc;
        if (!run->rehold[j] || j288_robot_read(r, j, &st) != J288_OK || !st.known)
            continue;
        run->rehold[j] = false;
        rc = j288_robot_hold(r, j);
        if (rc == J288_OK) {
            (void)j288_robot_read(r, j, &st);
            run->hold_pos[j] = st.pos;
            fprintf(stderr, "j288: joint '%s' found again at %.4f rad: held there\n",
                    j288_robot_joint_name(r, j), st.pos);
        } else {
            cli_error("joint %s: found again at %.4f rad, not held (%s): left at lock",
                      j288_robot_joint_name(r, j), st.pos, j288_strerror(rc));
        }
    }
}

static void on_cycle(void *user, j288_robot_t *r, const j288_robot_cycle_t *c)
{
    robot_run_t *run = user;
    unsigned j;
    rehold(run, r);
    if (run->csv == NULL)
        return;
    for (j = 0; j < j288_robot_njoints(r); j++) {
        j288_robot_state_t st;
        j288_robot_joint_stats_t js;
        char pos[32] = "", des[32] = "";
        const char *bus = j288_robot_bus_name(r, (unsigned)j288_robot_joint_bus(r, j));
        double t = (double)(c->start_us - run->t0) * 1e-6;
        (void)j288_robot_read(r, j, &st);
        (void)j288_robot_joint_stats(r, j, &js);
        if (st.known)
            (void)snprintf(pos, sizeof pos, "%.7g", st.pos);
        if (run->held)
            (void)snprintf(des, sizeof des, "%.7g", run->hold_pos[j]);
        /* j288 log's columns (cmd_log.c), then the joint's name, bus and cycle. */
        if (st.fresh)
            fprintf(run->csv, "%.6f,%d,1,%s,%.7g,%.7g,%.0f,%.0f,%.1f,%lu,%lu,%s,%s,%s,%u\n", t,
                    j288_robot_joint_id(r, j), pos, st.speed, st.torque, st.case_temp_c,
                    st.winding_temp_c, st.voltage_v, (unsigned long)st.faults,
                    (unsigned long)js.servo.last_latency_us,
                    des, j288_robot_joint_name(r, j), bus,
                    (unsigned)c->cycle);
        else
            fprintf(run->csv, "%.6f,%d,0,,,,,,,,,,%s,%s,%u\n", t, j288_robot_joint_id(r, j),
                    j288_robot_joint_name(r, j), bus, (unsigned)c->cycle);
    }
}

/* Cycle until every joint's angle is known (or 200 cycles). Returns the number unknown. */
static unsigned acquire(j288_robot_t *r)
{
    unsigned tries, j, unknown = 0;
    for (tries = 0; tries < 200; tries++) {
        int rc = j288_robot_cycle(r, 0, NULL);
        if (rc == J288_ERR_ABORTED || rc == J288_ERR_OFFLINE)
            break;
        unknown = 0;
        for (j = 0; j < j288_robot_njoints(r); j++) {
            j288_robot_state_t st;
            (void)j288_robot_read(r, j, &st);
            unknown += st.known ? 0u : 1u;
        }
        if (unknown == 0u)
            return 0;
    }
    return (unknown == 0u) ? j288_robot_njoints(r) : unknown;
}

static void print_status(j288_robot_t *r, bool json)
{
    unsigned j;
    cli_json_t jw;
    if (json) {
        cli_json_init(&jw, stdout);
        cli_json_begin_array(&jw, NULL);
    } else {
        printf("%-16s %-10s %3s  %-7s %12s %12s %10s %7s %8s  %s\n", "joint", "bus", "id", "state",
               "pos_rad", "speed_rad_s", "torque_nm", "case_C", "voltage", "faults");
    }
    for (j = 0; j < j288_robot_njoints(r); j++) {
        j288_robot_state_t st;
        const char *bus = j288_robot_bus_name(r, (unsigned)j288_robot_joint_bus(r, j));
        (void)j288_robot_read(r, j, &st);
        if (json) {
            cli_json_begin_object(&jw, NULL);
            cli_json_str(&jw, "joint", j288_robot_joint_name(r, j));
            cli_json_str(&jw, "bus", bus);
            cli_json_int(&jw, "id", j288_robot_joint_id(r, j));
            cli_json_bool(&jw, "online", st.online);
            cli_json_bool(&jw, "known", st.known);
            if (st.known)
                cli_json_real(&jw, "pos", st.pos);
            cli_json_real(&jw, "speed", st.speed);
            cli_json_real(&jw, "torque", st.torque);
            cli_json_real(&jw, "case_temp_c", st.case_temp_c);
            cli_json_real(&jw, "voltage_v", st.voltage_v);
            cli_json_uint(&jw, "faults", st.faults);
            cli_json_end_object(&jw);
        } else if (!st.online) {
            printf("%-16s %-10s %3d  %-7s\n", j288_robot_joint_name(r, j), bus,
                   j288_robot_joint_id(r, j), "silent");
        } else {
            printf("%-16s %-10s %3d  %-7s %12.6f %12.6f %10.4f %7.1f %7.1fV  0x%x\n",
                   j288_robot_joint_name(r, j), bus, j288_robot_joint_id(r, j),
                   st.known ? "known" : "unknown", st.pos, st.speed, st.torque, st.case_temp_c,
                   st.voltage_v, (unsigned)st.faults);
        }
    }
    if (json) {
        cli_json_end_array(&jw);
        cli_json_newline(&jw);
    }
}

/* The summary of a run: rate, complete cycles, each bus and each joint that missed cycles. */
static void print_summary(j288_robot_t *r, double seconds, uint32_t cycles, uint32_t complete,
                          FILE *f)
{
    j288_robot_stats_t rs;
    unsigned b, j;
    (void)j288_robot_stats(r, &rs);
    fprintf(f, "robot: %u cycles in %.3f s: %.1f cycles/s, %u complete, worst cycle %u us\n",
            (unsigned)cycles, seconds, seconds > 0 ? (double)cycles / seconds : 0.0,
            (unsigned)complete, (unsigned)rs.worst_cycle_us);
    cli_print_timing(f, r);
    for (b = 0; b < j288_robot_nbuses(r); b++) {
        j288_robot_bus_stats_t bs;
        const j288_bus_stats_t *ws = j288_robot_bus_wire_stats(r, b);
        (void)j288_robot_bus_stats(r, b, &bs);
        fprintf(f, "bus %s: %u sweeps (%u without a reply), %u ok, %u failed, %u timeouts%s%s\n",
                j288_robot_bus_name(r, b), (unsigned)bs.sweeps, (unsigned)bs.empty_sweeps,
                (unsigned)ws->ok, (unsigned)ws->failed, (unsigned)ws->timeouts,
                bs.gone ? ", gone" : "", (!bs.gone && !bs.up) ? ", not answering" : "");
    }
    for (j = 0; j < j288_robot_njoints(r); j++) {
        j288_robot_joint_stats_t js;
        (void)j288_robot_joint_stats(r, j, &js);
        if (js.stale_cycles != 0u)
            fprintf(f, "joint %s: fresh in %u cycles, stale in %u\n", j288_robot_joint_name(r, j),
                    (unsigned)js.fresh_cycles, (unsigned)js.stale_cycles);
    }
}

static int hold_all(j288_robot_t *r, robot_run_t *run)
{
    unsigned j;
    for (j = 0; j < j288_robot_njoints(r); j++) {
        j288_robot_state_t st;
        int rc = j288_robot_hold(r, j);
        (void)j288_robot_read(r, j, &st);
        if (rc == J288_ERR_LIMIT_POS) {
            j288_joint_config_t jc;
            (void)j288_robot_joint_config(r, j, &jc);
            cli_error("joint %s: at %g rad, beyond its limits [%g, %g] by more than %g rad: "
                      "nothing held; move it inside by hand",
                      j288_robot_joint_name(r, j), st.pos, (double)jc.pos_min,
                      (double)jc.pos_max, J288_ROBOT_HOLD_BEYOND_MAX);
            return CLI_EXIT_USAGE;
        }
        if (rc != J288_OK) {
            cli_error("joint %s: %s", j288_robot_joint_name(r, j), j288_strerror(rc));
            return CLI_EXIT_FAIL;
        }
        (void)j288_robot_read(r, j, &st);
        run->hold_pos[j] = st.pos;
    }
    run->held = true;
    return CLI_EXIT_OK;
}

/* stop: every bus on its own, so that a bus that cannot be opened does not keep the
 * broadcast lock from the others. */
static int stop_each_bus(const robot_args_t *a, const j288_robot_options_t *o)
{
    static j288_robot_config_t cfg, one_bus;
    static j288_robot_t one;
    char err[J288_ROBOT_CONFIG_ERROR_MAX];
    size_t i, n, failed = 0;
    if (j288_robot_config_load(a->config, &cfg, err, sizeof err) != 0) {
        cli_error("%s", err);
        return CLI_EXIT_FAIL;
    }
    n = (cfg.nbuses == 0u) ? 1u : cfg.nbuses;
    for (i = 0; i < n; i++) {
        j288_robot_options_t bo = *o;
        int rc;
        bo.on_event = NULL;
        bo.on_cycle = NULL;
        /* The bus's own entry, without joints: the runner's messages name it as the file does. */
        memset(&one_bus, 0, sizeof one_bus);
        if (cfg.nbuses != 0u) {
            one_bus.nbuses = 1;
            one_bus.bus[0] = cfg.bus[i];
        } else if (o->port == NULL) {
            cli_error("the config names no bus and no --port was given");
            return CLI_EXIT_USAGE;
        }
        rc = j288_robot_open(&one, &one_bus, &bo);
        if (rc == J288_OK)
            rc = j288_robot_stop(&one);
        if (rc != J288_OK) {
            cli_error("%s", j288_robot_error(&one));
            failed++;
        }
        j288_robot_close(&one);
    }
    if (a->json)
        printf("{\"stopped\": \"all\", \"buses\": %zu, \"sent\": %zu}\n", n, n - failed);
    else
        printf("broadcast lock sent on %zu of %zu buses\n", n - failed, n);
    return failed == 0u ? CLI_EXIT_OK : CLI_EXIT_FAIL;
}

/* Every bus's notices (low latency refused, latency timer advice), once, on stderr. */
static void print_notices(const j288_robot_t *r)
{
    char all[2048] = "";
    unsigned b;
    for (b = 0; b < j288_robot_nbuses(r); b++)
        (void)strncat(all, j288_robot_notices(r, b), sizeof all - strlen(all) - 1u);
    cli_print_notices(all);
}

static FILE *g_csv_open; /* closed by finish() when a command ends before its run */

static int finish(j288_robot_t *r, int code)
{
    if (g_csv_open != NULL) {
        (void)fclose(g_csv_open);
        g_csv_open = NULL;
    }
    if (cli_stop_signal != 0) {
        (void)j288_robot_stop(r);
        code = cli_signal_exit_code();
    } else if (code == CLI_EXIT_OK && cli_report_lost_buses(r) != 0u) {
        code = CLI_EXIT_FAIL;
    }
    j288_robot_close(r);
    return code;
}

int cli_cmd_robot(int argc, char **argv, const cli_global_t *g)
{
    static j288_robot_t robot; /* large: not on the stack */
    const char *cmd = argv[0];
    robot_args_t a;
    robot_run_t run;
    FILE *csv = NULL;
    j288_robot_options_t o;
    uint32_t period_us, t_end;
    int exit_code = CLI_EXIT_OK, rc;

    if (parse_robot_args(argc, argv, g, &a, &exit_code) != 0)
        return exit_code;
    memset(&run, 0, sizeof run);
    run.robot = &robot;
    memset(&o, 0, sizeof o);
    o.port = a.port != NULL ? a.port : getenv("J288_PORT");
    o.margin_us = a.margin_us;
    o.echo = a.echo;
    o.retries = (uint8_t)(a.retries > 0 ? a.retries : 0);
    if (cli_bus_baud(a.baud, &o.baud) != 0)
        return CLI_EXIT_USAGE;
    o.on_event = on_event;
    o.on_cycle = on_cycle;
    o.user = &run;
    o.stop_on_bus_loss = a.stop_on_loss;
    if (strcmp(cmd, "log") == 0 || strcmp(cmd, "hold") == 0) {
        o.realtime = (uint8_t)a.realtime;
        o.pin_cpu = a.cpu >= 0;
        o.cpu = (uint16_t)(a.cpu >= 0 ? a.cpu : 0);
    }
    if (a.csv != NULL && strcmp(cmd, "log") == 0) {
        csv = fopen(a.csv, "w");
        if (csv == NULL) {
            cli_error("%s: cannot write", a.csv);
            return CLI_EXIT_FAIL;
        }
        fputs("time_s,id,ok,pos_rad,speed_rad_s,torque_nm,case_temp_c,winding_temp_c,voltage_v,"
              "faults,latency_us,pos_des_rad,joint,bus,cycle\n",
              csv);
        g_csv_open = csv;
    }
    cli_signals_install();
    if (strcmp(cmd, "stop") == 0)
        return stop_each_bus(&a, &o);
    rc = j288_robot_open_file(&robot, a.config, &o);
    if (rc != J288_OK) {
        cli_error("%s", j288_robot_error(&robot));
        if (csv != NULL)
            fclose(csv);
        return rc == J288_ERR_BAD_ARG ? CLI_EXIT_USAGE : CLI_EXIT_FAIL;
    }
    j288_robot_set_stop_flag(&robot, &cli_stop_signal);
    print_notices(&robot);
    cli_print_rt_notice(&robot);

    {
        unsigned unknown = acquire(&robot);
        if (cli_stop_signal != 0)
            return finish(&robot, CLI_EXIT_OK);
        if (strcmp(cmd, "status") == 0) {
            print_status(&robot, a.json);
            return finish(&robot, unknown == 0u ? CLI_EXIT_OK : CLI_EXIT_FAIL);
        }
        if (unknown != 0u && (a.hold || strcmp(cmd, "hold") == 0)) {
            print_status(&robot, false);
            cli_error("%u joints have no known angle: nothing to hold", unknown);
            return finish(&robot, CLI_EXIT_FAIL);
        }
    }
    if (a.hold || strcmp(cmd, "hold") == 0) {
        int held = hold_all(&robot, &run);
        if (held != CLI_EXIT_OK)
            return finish(&robot, held);
    }

    /* log and hold: cycles at the rate; the statistics restart here (the start's cycles). */
    period_us = (a.rate_hz > 0.0) ? (uint32_t)(1e6 / a.rate_hz + 0.5) : 0u;
    if (period_us == 0u && a.rate_hz > 0.0)
        period_us = 1u;
    {
        j288_robot_stats_t before, after;
        uint32_t t0 = j288_robot_now_us(), dur_us;
        bool forever = strcmp(cmd, "hold") == 0 && !a.have_duration;
        (void)j288_robot_stats(&robot, &before);
        j288_robot_timing_reset(&robot);
        run.t0 = t0;
        run.csv = csv; /* from the first cycle after the start */
        g_csv_open = NULL;
        dur_us = (uint32_t)(a.duration_s * 1e6);
        t_end = t0 + dur_us;
        do {
            /* Runs of at most 10 min keep the 32-bit clock's comparisons valid. */
            uint32_t left = forever ? 600000000u : t_end - j288_robot_now_us();
            if (!forever && (int32_t)left <= 0)
                break;
            rc = j288_robot_run(&robot, period_us, 0, left > 600000000u ? 600000000u : left);
        } while (rc == J288_OK && (forever || (int32_t)(t_end - j288_robot_now_us()) > 0));
        (void)j288_robot_stats(&robot, &after);
        run.csv = NULL;
        if (csv != NULL && fclose(csv) != 0)
            cli_error("%s: write failed", a.csv);
        if (rc == J288_ERR_OFFLINE)
            cli_error("%s", j288_robot_error(&robot));
        if (rc != J288_ERR_ABORTED || cli_stop_signal != 0) {
            double secs = (double)(j288_robot_now_us() - t0) * 1e-6;
            if (a.json) {
                cli_json_t jw;
                cli_json_init(&jw, stdout);
                cli_json_begin_object(&jw, NULL);
                cli_json_uint(&jw, "cycles", after.cycles - before.cycles);
                cli_json_uint(&jw, "complete_cycles", after.complete_cycles - before.complete_cycles);
                cli_json_real(&jw, "seconds", secs);
                cli_json_real(&jw, "cycles_per_s", (double)(after.cycles - before.cycles) / secs);
                cli_json_uint(&jw, "joints", j288_robot_njoints(&robot));
                cli_json_uint(&jw, "buses", j288_robot_nbuses(&robot));
                cli_json_timing(&jw, &robot);
                cli_json_end_object(&jw);
                cli_json_newline(&jw);
            } else {
                print_summary(&robot, secs, after.cycles - before.cycles,
                              after.complete_cycles - before.complete_cycles, stdout);
            }
        }
        if (strcmp(cmd, "hold") == 0 || a.hold)
            (void)j288_robot_stop(&robot);
        return finish(&robot, rc == J288_OK || rc == J288_ERR_ABORTED ? CLI_EXIT_OK : CLI_EXIT_FAIL);
    }
}
