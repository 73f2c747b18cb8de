/* `j288 log`: run the cycle scheduler at a fixed rate, optionally drive a trajectory, and
 * write one CSV row per servo per cycle. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#ifdef __linux__
#include <sys/prctl.h>
#endif

#include "cli_bus.h"
#include "frameview.h"
#include "json.h"

static const char log_help[] =
    "usage: j288 [--port DEV] log --id N[,M..] --rate HZ --duration S [--csv FILE]\n"
    "                [--hold | --swing AMP [--period S]] [--kp NM_RAD] [--kd NMS_RAD]\n"
    "                [--side joint|rotor|output] [--config FILE] [--json]\n"
    "                [--realtime[=PRIO]] [--cpu N]\n"
    "\n"
    "Run the cycle scheduler: every 1/HZ seconds one sweep sends each listed servo its\n"
    "command and takes its reply. Without --hold or --swing each servo is sent lock\n"
    "(watchdog bit 0) and only observed.\n"
    "  --id LIST      servo ids 0-14, comma-separated (this or --joint is required)\n"
    "  --joint NAMES  joints of the --config file, comma-separated, instead of --id\n"
    "  --rate HZ      sweeps per second, 1..5000 (default 100)\n"
    "  --duration S   how long, seconds (default 1)\n"
    "  --csv FILE     one row per servo per cycle: time_s, id, ok (1 reply, 0 none),\n"
    "                 pos_rad, speed_rad_s, torque_nm (on --side), case_temp_c,\n"
    "                 winding_temp_c, voltage_v, faults, latency_us, pos_des_rad; a cycle\n"
    "                 without a reply leaves the measured columns empty, and so does a\n"
    "                 joint angle not known (pos_rad)\n"
    "  --hold         hold each servo where it starts (FOC, kp/kd)\n"
    "  --swing AMP    move each servo from where it starts through\n"
    "                 p0 + AMP (1 - cos(2 pi t / period)) / 2 and back, speed fed forward\n"
    "  --period S     period of the swing (default: --duration, one swing)\n"
    "  --kp, --kd     gains for --hold/--swing (default output side 20 N*m/rad, 2.5 N*m*s/rad)\n"
    "  --watchdog W   on (default when driving) or off\n"
    "  --side S       frame of AMP, gains and CSV: joint (default: the absolute joint angle,\n"
    "                 the output encoder's wrapped to [-pi, pi) or the --config joints'),\n"
    "                 rotor (raw), or output (rotor / N from where the rotor started)\n"
    "  --config FILE  the joints of the listed ids: zero, direction, limits (a swing\n"
    "                 leaving them is refused before it starts; a joint up to 0.05 rad\n"
    "                 beyond them holds or swings from the nearest limit), phase\n"
    "Prints the achieved rate, missed deadlines (sweeps that ended after the next tick was\n"
    "due: that tick starts late; ticks a whole period behind are skipped, never bunched),\n"
    "the loop's timing, bus statistics and, when driving, the tracking error. --csv is\n"
    "written from the loop (buffered, 64 KiB at a time): the tightest timing logs without\n"
    "it. Ctrl-C, SIGTERM, SIGHUP or SIGQUIT: every driven servo is sent lock before exiting\n"
    "(exit 130, 143, 129, 131).\n"
    "Exit status: 0 done; 1 a servo never answered, device error; 2 bad arguments.\n"
    "\n" CLI_BUS_RT_HELP "\n" CLI_BUS_COMMON_HELP;

enum {
    OPT_IDS = 0,
    OPT_RATE,
    OPT_DURATION,
    OPT_CSV,
    OPT_HOLD,
    OPT_SWING,
    OPT_PERIOD,
    OPT_KP,
    OPT_KD,
    OPT_SIDE,
    OPT_WATCHDOG,
    OPT_JOINTS
};

typedef enum { MOTION_NONE, MOTION_HOLD, MOTION_SWING } motion_t;

typedef struct {
    uint32_t ids;
    double rate_hz, duration_s, amp, period_s, kp, kd;
    bool have_kp, have_kd, have_period;
    const char *csv;
    const char *joints; /* --joint NAME[,NAME..] */
    motion_t motion;
    int side;
    bool watchdog;
} log_args_t;

enum { SIDE_ROTOR = 0, SIDE_OUTPUT = 1, SIDE_JOINT = 2 };
#define PROBE_SWEEPS_JOINT 40 /* the joints' starts take 8 replies each */

/* Per-servo running figures. */
typedef struct {
    int32_t p0;
    uint32_t replies, failures, seen_successes;
    double err_sq_sum, err_max;
    uint32_t err_n;
    double latency_sum;
    uint32_t latency_n, latency_max;
} servo_acc_t;

static int parse_log_opt(log_args_t *a, int key, const char *v)
{
    static const char *const sides[] = {"rotor", "output", "joint", NULL};
    static const char *const onoff[] = {"off", "on", NULL};
    int choice;
    switch (key) {
    case OPT_IDS:
        return cli_parse_id_list("--id", v, J288_MAX_ID, &a->ids);
    case OPT_RATE:
        return cli_parse_real_in("--rate", v, 1.0, 5000.0, &a->rate_hz);
    case OPT_DURATION:
        return cli_parse_real_in("--duration", v, 0.001, 86400.0, &a->duration_s);
    case OPT_CSV:
        a->csv = v;
        return 0;
    case OPT_HOLD:
        if (a->motion == MOTION_SWING) {
            cli_error("--hold and --swing exclude each other");
            return -1;
        }
        a->motion = MOTION_HOLD;
        return 0;
    case OPT_SWING:
        if (a->motion == MOTION_HOLD) {
            cli_error("--hold and --swing exclude each other");
            return -1;
        }
        a->motion = MOTION_SWING;
        return cli_parse_real("--swing", v, &a->amp);
    case OPT_PERIOD:
        a->have_period = true;
        return cli_parse_real_in("--period", v, 0.01, 86400.0, &a->period_s);
    case OPT_KP:
        a->have_kp = true;
        return cli_parse_real("--kp", v, &a->kp);
    case OPT_KD:
        a->have_kd = true;
        return cli_parse_real("--kd", v, &a->kd);
    case OPT_SIDE:
        for (choice = 0; sides[choice] != NULL; choice++) {
            if (strcmp(v, sides[choice]) == 0) {
                a->side = choice;
                return 0;
            }
        }
        cli_error("--side: '%s' is not joint, rotor or output", v);
        return -1;
    case OPT_JOINTS:
        a->joints = v;
        return 0;
    case OPT_WATCHDOG:
        if (cli_parse_choice("--watchdog", v, onoff, &choice) != 0) {
            return -1;
        }
        a->watchdog = choice == 1;
        return 0;
    default:
        return 1;
    }
}

static int parse_args(int argc, char **argv, log_args_t *a, cli_bus_opts_t *o, int *ec)
{
    static const cli_opt_t opts[] = {{"--id", true, OPT_IDS},
                                     {"--rate", true, OPT_RATE},
                                     {"--duration", true, OPT_DURATION},
                                     {"--csv", true, OPT_CSV},
                                     {"--hold", false, OPT_HOLD},
                                     {"--swing", true, OPT_SWING},
                                     {"--period", true, OPT_PERIOD},
                                     {"--kp", true, OPT_KP},
                                     {"--kd", true, OPT_KD},
                                     {"--side", true, OPT_SIDE},
                                     {"--watchdog", true, OPT_WATCHDOG},
                                     {"--joint", true, OPT_JOINTS},
                                     CLI_BUS_RT_OPTS,
                                     CLI_BUS_COMMON_OPTS,
                                     {NULL, false, 0}};
    cli_args_t args;
    const char *v;
    int key, rc;
    cli_args_init(&args, argc, argv);
    while ((key = cli_args_next(&args, opts, &v)) != CLI_ARG_END) {
        if (key == CLI_ARG_HELP) {
            fputs(log_help, stdout);
            *ec = CLI_EXIT_OK;
            return -1;
        }
        if (key == CLI_ARG_ERROR) {
            *ec = CLI_EXIT_USAGE;
            return -1;
        }
        if (key == CLI_ARG_POSITIONAL) {
            cli_error("unexpected argument '%s' (try --help)", v);
            *ec = CLI_EXIT_USAGE;
            return -1;
        }
        rc = cli_bus_common_opt(o, key, v);
        if (rc == 1) {
            rc = parse_log_opt(a, key, v);
        }
        if (rc != 0) {
            *ec = CLI_EXIT_USAGE;
            return -1;
        }
    }
    if (a->ids != 0u && a->joints != NULL) {
        cli_error("--id and --joint exclude each other");
        *ec = CLI_EXIT_USAGE;
        return -1;
    }
    if (a->ids == 0u && a->joints == NULL) {
        cli_error("--id is required (e.g. --id 1,2,3), or --joint NAMES with --config");
        *ec = CLI_EXIT_USAGE;
        return -1;
    }
    return 0;
}

/* The base command of a driven servo: FOC, gains, watchdog. */
static int base_command(const log_args_t *a, j288_cmd_raw_t *cmd)
{
    j288_side_t side = a->side == SIDE_ROTOR ? J288_SIDE_ROTOR : J288_SIDE_OUTPUT;
    double kp = a->have_kp ? a->kp : 20.0;
    double kd = a->have_kd ? a->kd : 2.5;
    int rc;
    memset(cmd, 0, sizeof *cmd);
    cmd->status = J288_MODE_FOC;
    cmd->watchdog = a->watchdog;
    rc = j288_kp_to_raw((j288_real_t)kp, a->have_kp ? side : J288_SIDE_OUTPUT, &cmd->kp);
    if (rc != J288_OK) {
        cli_error("--kp: %g: %s", kp, j288_strerror(rc));
        return -1;
    }
    rc = j288_kd_to_raw((j288_real_t)kd, a->have_kd ? side : J288_SIDE_OUTPUT, &cmd->kd);
    if (rc != J288_OK) {
        cli_error("--kd: %g: %s", kd, j288_strerror(rc));
        return -1;
    }
    return 0;
}

/* Swing setpoint (rotor raw) and speed feed-forward at time t. */
static void swing_setpoint(const log_args_t *a, int32_t p0, double t, int32_t *pos, int16_t *speed)
{
    double n = a->side == 0 ? 1.0 : J288_GEAR_RATIO;
    double w = 2.0 * J288_PI / a->period_s;
    double amp_rotor_rad = a->amp * n;
    double p = (double)p0 + amp_rotor_rad * J288_SCALE_POS * 0.5 * (1.0 - cos(w * t));
    double v = amp_rotor_rad * 0.5 * w * sin(w * t) * J288_SCALE_SPEED;
    if (p > 2147483647.0) {
        p = 2147483647.0;
    } else if (p < -2147483648.0) {
        p = -2147483648.0;
    }
    if (v > 32767.0) {
        v = 32767.0;
    } else if (v < -32768.0) {
        v = -32768.0;
    }
    *pos = (int32_t)lround(p);
    *speed = (int16_t)lround(v);
}

static void csv_header(FILE *f)
{
    fputs("time_s,id,ok,pos_rad,speed_rad_s,torque_nm,case_temp_c,winding_temp_c,voltage_v,"
          "faults,latency_us,pos_des_rad\n",
          f);
}

static void csv_row_joint(FILE *f, double t, uint8_t id, const j288_slot_t *sl,
                          const j288_joint_t *j, double pos_des)
{
    const j288_reply_raw_t *r = &sl->reply;
    const j288_joint_state_t *st = j288_joint_state(j);
    char pos[32] = "";
    if (st->known) {
        snprintf(pos, sizeof pos, "%.7g", (double)st->pos);
    }
    fprintf(f, "%.6f,%u,1,%s,%.7g,%.7g,%d,%u,%.1f,%lu,%lu,%.7g\n", t, (unsigned)id, pos,
            (double)st->speed, (double)st->torque, (int)r->case_temp_c,
            (unsigned)r->winding_temp_c, (double)r->voltage_raw * J288_SCALE_VOLTAGE,
            (unsigned long)r->faults, (unsigned long)sl->stats.last_latency_us, pos_des);
}

static void csv_row(FILE *f, double t, uint8_t id, const j288_slot_t *sl, bool fresh,
                    j288_side_t side, double pos_des)
{
    const j288_reply_raw_t *r = &sl->reply;
    if (fresh) {
        fprintf(f, "%.6f,%u,1,%.7g,%.7g,%.7g,%d,%u,%.1f,%lu,%lu,%.7g\n", t, (unsigned)id,
                (double)j288_pos_from_raw(r->pos, side),
                (double)j288_speed_from_raw(r->speed, side),
                (double)j288_torque_from_raw(r->torque, side), (int)r->case_temp_c,
                (unsigned)r->winding_temp_c, (double)r->voltage_raw * J288_SCALE_VOLTAGE,
                (unsigned long)r->faults, (unsigned long)sl->stats.last_latency_us, pos_des);
    } else {
        fprintf(f, "%.6f,%u,0,,,,,,,,,%.7g\n", t, (unsigned)id, pos_des);
    }
}

#define PROBE_SWEEPS 5

static bool all_answered(const j288_sched_t *s, uint32_t ids)
{
    uint8_t id;
    for (id = 0; id <= J288_MAX_ID; id++) {
        if ((ids & (1u << id)) != 0u && !j288_sched_slot(s, id)->has_reply) {
            return false;
        }
    }
    return true;
}

/* One sweep of the listed slots, to its end: a cycle of the host layer's runner (its loop,
 * its watchdog policy; a stop signal stops the bus there). */
static int sweep(cli_bus_t *b, uint32_t timeout_us)
{
    j288_robot_cycle_t info;
    int rc = j288_robot_cycle(b->robot, timeout_us, &info);
    if (info.watchdog != 0u) {
        cli_report_watchdog(info.watchdog == 1u ? "a servo" : "servos");
    }
    return rc == J288_ERR_TIMEOUT ? J288_OK : rc;
}


typedef struct {
    uint32_t cycles, missed, skipped, rows;
    double elapsed_s;
} run_stats_t;

/* Everything one run of `log` works with. */
typedef struct {
    log_args_t a;
    cli_bus_opts_t o;
    j288_side_t side;       /* of --swing, the gains and the CSV */
    j288_cmd_raw_t base;    /* a driven servo's command: FOC, gains, watchdog */
    cli_bus_t b;
    j288_sched_t *s;        /* the runner's scheduler of the bus */
    FILE *csv;              /* NULL without --csv, and once closed */
    servo_acc_t acc[J288_MAX_ID + 1u];
    double pos_des[J288_MAX_ID + 1u];
    cli_robot_t robot;                 /* --config */
    cli_joint_sel_t sel[J288_MAX_ID + 1u];
    j288_joint_t joint[J288_MAX_ID + 1u]; /* side joint */
    double q0[J288_MAX_ID + 1u];       /* joint angle at the start */
    uint16_t lost;                     /* ids whose joint angle was lost: locked */
    uint32_t t0;            /* when the cycles began */
    uint32_t sweep_timeout_us;
    run_stats_t rs;
} log_run_t;

typedef enum { LOG_DONE, LOG_INTERRUPTED, LOG_FAILED } log_end_t;

static bool listed(const log_run_t *r, uint8_t id)
{
    return (r->a.ids & (1u << id)) != 0u;
}

static double mean_latency(const servo_acc_t *x)
{
    return x->latency_n != 0u ? x->latency_sum / x->latency_n : 0.0;
}

static void print_summary_json(const log_run_t *r, double achieved)
{
    const j288_bus_stats_t *bs = j288_bus_stats(j288_robot_bus_engine(r->b.robot, 0));
    cli_json_t j;
    uint8_t id;
    cli_json_init(&j, stdout);
    cli_json_begin_object(&j, NULL);
    cli_json_uint(&j, "cycles", r->rs.cycles);
    cli_json_real(&j, "elapsed_s", r->rs.elapsed_s);
    cli_json_real(&j, "rate_hz", r->a.rate_hz);
    cli_json_real(&j, "achieved_hz", achieved);
    cli_json_uint(&j, "missed_deadlines", r->rs.missed);
    cli_json_uint(&j, "skipped_ticks", r->rs.skipped);
    cli_json_uint(&j, "csv_rows", r->rs.rows);
    cli_json_begin_object(&j, "bus");
    cli_json_uint(&j, "transactions", bs->transactions);
    cli_json_uint(&j, "ok", bs->ok);
    cli_json_uint(&j, "timeouts", bs->timeouts);
    cli_json_uint(&j, "crc_errors", bs->crc_errors);
    cli_json_uint(&j, "wrong_id", bs->wrong_id);
    cli_json_uint(&j, "collisions", bs->collisions);
    cli_json_uint(&j, "line_errors", bs->line_errors);
    cli_json_uint(&j, "stale_bytes", bs->stale_bytes);
    cli_json_uint(&j, "garbage_bytes", j288_bus_parser_stats(j288_robot_bus_engine(r->b.robot, 0))->garbage_bytes);
    cli_json_end_object(&j);
    cli_json_begin_array(&j, "servos");
    for (id = 0; id <= J288_MAX_ID; id++) {
        const servo_acc_t *x = &r->acc[id];
        if (!listed(r, id)) {
            continue;
        }
        cli_json_begin_object(&j, NULL);
        cli_json_int(&j, "id", id);
        cli_json_uint(&j, "replies", x->replies);
        cli_json_uint(&j, "failures", x->failures);
        cli_json_real(&j, "latency_mean_us", mean_latency(x));
        cli_json_uint(&j, "latency_max_us", x->latency_max);
        if (r->a.motion != MOTION_NONE && x->err_n != 0u) {
            cli_json_real(&j, "tracking_rms_rad", sqrt(x->err_sq_sum / x->err_n));
            cli_json_real(&j, "tracking_max_rad", x->err_max);
        }
        cli_json_end_object(&j);
    }
    cli_json_end_array(&j);
    cli_json_str(&j, "side", r->a.side == SIDE_ROTOR ? "rotor" : (r->a.side == SIDE_OUTPUT ? "output" : "joint"));
    cli_json_timing(&j, r->b.robot);
    cli_json_end_object(&j);
    cli_json_newline(&j);
}

static void print_summary_text(const log_run_t *r, double achieved)
{
    const j288_bus_stats_t *bs = j288_bus_stats(j288_robot_bus_engine(r->b.robot, 0));
    const j288_parser_stats_t *ps = j288_bus_parser_stats(j288_robot_bus_engine(r->b.robot, 0));
    uint8_t id;
    printf("log: %lu cycles in %.3f s: achieved %.1f Hz (asked %.1f Hz), %lu missed "
           "deadlines, %lu ticks skipped\n",
           (unsigned long)r->rs.cycles, r->rs.elapsed_s, achieved, r->a.rate_hz,
           (unsigned long)r->rs.missed, (unsigned long)r->rs.skipped);
    cli_print_timing(stdout, r->b.robot);
    printf("bus: %lu transactions, %lu ok, %lu timeouts, %lu CRC errors, %lu wrong id, "
           "%lu collisions, %lu line errors, %lu stale bytes, %lu garbage bytes\n",
           (unsigned long)bs->transactions, (unsigned long)bs->ok, (unsigned long)bs->timeouts,
           (unsigned long)bs->crc_errors, (unsigned long)bs->wrong_id,
           (unsigned long)bs->collisions, (unsigned long)bs->line_errors,
           (unsigned long)bs->stale_bytes, (unsigned long)ps->garbage_bytes);
    for (id = 0; id <= J288_MAX_ID; id++) {
        const servo_acc_t *x = &r->acc[id];
        if (!listed(r, id)) {
            continue;
        }
        printf("servo %u: %lu replies, %lu failed, latency mean %.0f us, worst %lu us",
               (unsigned)id, (unsigned long)x->replies, (unsigned long)x->failures,
               mean_latency(x), (unsigned long)x->latency_max);
        if (r->a.motion != MOTION_NONE && x->err_n != 0u) {
            printf("; tracking error rms %.4g rad, max %.4g rad (%s side)",
                   sqrt(x->err_sq_sum / x->err_n), x->err_max,
                   r->a.side == SIDE_ROTOR ? "rotor" : (r->a.side == SIDE_OUTPUT ? "output" : "joint"));
        }
        printf("\n");
    }
    if (r->a.csv != NULL) {
        printf("csv: %s (%lu rows)\n", r->a.csv, (unsigned long)r->rs.rows);
    }
}

/* --joint NAMES: the ids of those joints of the file (one bus: the port of the first). */
static int joints_to_ids(log_run_t *r)
{
    char name[J288_ROBOT_CONFIG_NAME_MAX];
    const char *p = r->a.joints;
    if (p == NULL) {
        return 0;
    }
    for (;;) {
        const char *comma = strchr(p, ',');
        size_t n = comma != NULL ? (size_t)(comma - p) : strlen(p);
        cli_joint_sel_t sel;
        if (n == 0u || n >= sizeof name) {
            cli_error("--joint: '%s' is not a comma-separated list of joint names", r->a.joints);
            return -1;
        }
        memcpy(name, p, n);
        name[n] = '\0';
        if (cli_joint_select(&r->robot, name, -1, &r->o, &sel) != 0) {
            return -1;
        }
        if (sel.rj->bus >= 0 && strcmp(r->robot.cfg.bus[sel.rj->bus].port, r->o.port) != 0) {
            cli_error("--joint: %s is on bus %s, not on %s (one bus per log)", name,
                      r->robot.cfg.bus[sel.rj->bus].name, r->o.port);
            return -1;
        }
        if ((r->a.ids & (1u << sel.id)) != 0u) {
            cli_error("--joint: %s and another listed joint share id %u", name, (unsigned)sel.id);
            return -1;
        }
        r->a.ids |= 1u << sel.id;
        if (comma == NULL) {
            return 0;
        }
        p = comma + 1;
    }
}

/* --config and the listed ids: each servo's joint (the file's, or the library's defaults). */
static int log_select_joints(log_run_t *r)
{
    uint8_t id;
    if (cli_robot_load(&r->robot, r->o.config) != 0 || joints_to_ids(r) != 0) {
        return -1;
    }
    for (id = 0; id <= J288_MAX_ID; id++) {
        if (listed(r, id) && (cli_joint_select(&r->robot, NULL, id, &r->o, &r->sel[id]) != 0 ||
                              j288_joint_init(&r->joint[id], &r->sel[id].jc) != J288_OK)) {
            return -1;
        }
    }
    return 0;
}

/* Parse and check everything that needs no bus. Returns 0, or -1 with *ec the exit status
 * (CLI_EXIT_OK after --help). */
static int log_prepare(log_run_t *r, int argc, char **argv, const cli_global_t *g, int *ec)
{
    log_args_t *a = &r->a;
    a->rate_hz = 100.0;
    a->duration_s = 1.0;
    a->side = SIDE_JOINT;
    a->watchdog = true;
    cli_bus_opts_init(&r->o, g);
    if (parse_args(argc, argv, a, &r->o, ec) != 0) {
        return -1;
    }
    if (!a->have_period) {
        a->period_s = a->duration_s;
    }
    r->side = a->side == SIDE_ROTOR ? J288_SIDE_ROTOR : J288_SIDE_OUTPUT;
    *ec = CLI_EXIT_USAGE;
    if (log_select_joints(r) != 0) {
        return -1;
    }
    if (a->motion != MOTION_NONE && base_command(a, &r->base) != 0) {
        return -1;
    }
    if (a->motion == MOTION_SWING) {
        int32_t probe;
        if (j288_pos_to_raw((j288_real_t)a->amp, r->side, &probe) != J288_OK) {
            cli_error("--swing: %g rad is out of range", a->amp);
            return -1;
        }
    }
    return 0;
}

/* Signals, the bus, the CSV file, and the scheduler with every listed servo sent lock.
 * Returns CLI_EXIT_OK, or the exit status with nothing left open. */
static int log_open(log_run_t *r)
{
    j288_cmd_raw_t cmd;
    uint8_t id;
    int ec;
    cli_signals_install();
    /* Best effort: wake from the tick sleeps within a microsecond rather than the default
     * 50 us timer slack. */
#ifdef __linux__
    (void)prctl(PR_SET_TIMERSLACK, 1ul, 0ul, 0ul, 0ul);
#endif
    if ((ec = cli_bus_open(&r->b, &r->o, 0)) != CLI_EXIT_OK) {
        return ec;
    }
    if (r->a.csv != NULL) {
        r->csv = fopen(r->a.csv, "w");
        if (r->csv == NULL) {
            cli_error("cannot write %s: %s", r->a.csv, strerror(errno));
            cli_bus_close(&r->b);
            return CLI_EXIT_FAIL;
        }
        setvbuf(r->csv, NULL, _IOFBF, 1u << 16);
        csv_header(r->csv);
    }
    r->s = j288_robot_bus_sched(r->b.robot, 0);
    for (id = 0; id <= J288_MAX_ID; id++) {
        if (listed(r, id)) {
            cli_lock_cmd(id, &cmd);
            j288_sched_set_cmd(r->s, &cmd);
            j288_sched_enable(r->s, id, true);
        }
        r->pos_des[id] = NAN;
    }
    /* The budget of one sweep: every servo's full reply window, plus slack. */
    r->sweep_timeout_us = 15u * (j288_bus_reply_budget_us(j288_robot_bus_engine(r->b.robot, 0)) * 2u + 1000u) + 100000u;
    return CLI_EXIT_OK;
}

/* Whether every listed joint knows its angle, or cannot (encoder fault), on the joint side. */
static bool all_known(const log_run_t *r)
{
    uint8_t id;
    if (r->a.side != SIDE_JOINT) {
        return true;
    }
    for (id = 0; id <= J288_MAX_ID; id++) {
        const j288_joint_state_t *st = j288_joint_state(&r->joint[id]);
        if (listed(r, id) && !st->known && !st->encoder_fault) {
            return false;
        }
    }
    return true;
}

/* The probe's fresh replies into the joints (seen: each slot's success count so far). */
static void probe_feed_joints(log_run_t *r, uint32_t *seen)
{
    uint8_t id;
    for (id = 0; id <= J288_MAX_ID; id++) {
        const j288_slot_t *sl = j288_sched_slot(r->s, id);
        if (listed(r, id) && sl->stats.successes != seen[id]) {
            seen[id] = sl->stats.successes;
            (void)j288_joint_take_reply(&r->joint[id], &sl->reply, NULL);
        }
    }
}

/* First sweeps: who is there and where each starts; a few tries so that one dropped reply
 * does not fail the whole log. Returns CLI_EXIT_OK, or the exit status when a servo never
 * answered, the device went away or a stop signal came. */
static int log_probe(log_run_t *r)
{
    uint8_t id;
    int i;
    uint32_t seen[J288_MAX_ID + 1u] = {0};
    int sweeps = r->a.side == SIDE_JOINT ? PROBE_SWEEPS_JOINT : PROBE_SWEEPS;
    for (i = 0; i < sweeps && !(all_answered(r->s, r->a.ids) && all_known(r)); i++) {
        int rc = sweep(&r->b, r->sweep_timeout_us);
        probe_feed_joints(r, seen);
        if (rc == J288_ERR_ABORTED) {
            return cli_signal_exit_code();
        }
        if (rc == J288_ERR_OFFLINE) {
            cli_error("%s", cli_bus_error(&r->b));
            return CLI_EXIT_FAIL;
        }
    }
    for (id = 0; id <= J288_MAX_ID; id++) {
        const j288_slot_t *sl = j288_sched_slot(r->s, id);
        if (!listed(r, id)) {
            continue;
        }
        if (!sl->has_reply) {
            cli_error("no reply from servo %u on %s (check id, power, wiring and --baud)",
                      (unsigned)id, r->b.dev);
            return CLI_EXIT_FAIL;
        }
        r->acc[id].p0 = sl->reply.pos;
        if (r->a.side == SIDE_JOINT && r->a.motion != MOTION_NONE) {
            const j288_joint_state_t *st = j288_joint_state(&r->joint[id]);
            if (!st->known) {
                char why[400];
                cli_joint_why_unknown(&r->joint[id], r->sel[id].name, 0u, why, sizeof why);
                cli_error("%s", why);
                return CLI_EXIT_FAIL;
            }
            /* Just beyond a limit: hold or swing from the limit (every target outside is
             * refused); farther out, refused here. */
            if (cli_joint_start_inside(&r->sel[id].jc, r->sel[id].name, (double)st->pos, &r->q0[id]) != 0) {
                return CLI_EXIT_USAGE;
            }
            if (r->a.motion == MOTION_SWING &&
                !cli_joint_pos_allowed(&r->sel[id].jc, r->q0[id] + r->a.amp)) {
                cli_joint_target_error(&r->sel[id].jc, r->sel[id].name, "--swing to",
                                       r->q0[id] + r->a.amp, J288_ERR_LIMIT_POS);
                return CLI_EXIT_USAGE;
            }
        }
        r->acc[id].seen_successes = sl->stats.successes;
        if (r->a.motion != MOTION_NONE) {
            r->b.driven = (uint16_t)(r->b.driven | (1u << id));
        }
    }
    return CLI_EXIT_OK;
}

/* Side joint: the joint's target at time t through the joint layer; a joint that lost its
 * angle (or is refused) is locked for the rest of the run. */
static void joint_cycle_command(log_run_t *r, uint8_t id, double t)
{
    j288_joint_target_t tg;
    j288_cmd_raw_t cmd;
    double w = 2.0 * J288_PI / r->a.period_s;
    int rc;
    memset(&tg, 0, sizeof tg);
    {
        double kp, kd;
        cli_joint_gains(r->sel[id].rj, r->a.have_kp, r->a.kp, r->a.have_kd, r->a.kd, &kp, &kd);
        tg.kp = (j288_real_t)kp;
        tg.kd = (j288_real_t)kd;
    }
    tg.pos = (j288_real_t)r->q0[id];
    if (r->a.motion == MOTION_SWING) {
        tg.pos = (j288_real_t)(r->q0[id] + r->a.amp * 0.5 * (1.0 - cos(w * t)));
        tg.speed = (j288_real_t)(r->a.amp * 0.5 * w * sin(w * t));
    }
    if ((r->lost & (1u << id)) == 0u) {
        rc = j288_joint_command(&r->joint[id], &tg, &cmd, NULL);
        if (rc == J288_OK) {
            cmd.watchdog = r->a.watchdog;
            r->pos_des[id] = (double)tg.pos;
            j288_sched_set_cmd(r->s, &cmd);
            return;
        }
        cli_joint_target_error(&r->sel[id].jc, r->sel[id].name, "target", (double)tg.pos, rc);
        r->lost = (uint16_t)(r->lost | (1u << id));
    }
    cli_lock_cmd(id, &cmd);
    r->pos_des[id] = NAN;
    j288_sched_set_cmd(r->s, &cmd);
}

/* This cycle's commands: hold where each servo started, or the swing at time t. Observed
 * servos keep the lock set at the start. */
static void set_cycle_commands(log_run_t *r, double t)
{
    j288_cmd_raw_t cmd;
    uint8_t id;
    if (r->a.motion == MOTION_NONE) {
        return;
    }
    for (id = 0; id <= J288_MAX_ID; id++) {
        if (!listed(r, id)) {
            continue;
        }
        cmd = r->base;
        cmd.id = id;
        if (r->a.side == SIDE_JOINT) {
            joint_cycle_command(r, id, t);
            continue;
        }
        if (r->a.motion == MOTION_HOLD) {
            cmd.pos = r->acc[id].p0;
        } else {
            swing_setpoint(&r->a, r->acc[id].p0, t, &cmd.pos, &cmd.speed);
        }
        r->pos_des[id] = (double)j288_pos_from_raw(cmd.pos, r->side);
        j288_sched_set_cmd(r->s, &cmd);
    }
}

/* A reply taken in this cycle: latency and, when driving, the tracking error. */
static void account_reply(log_run_t *r, uint8_t id, const j288_slot_t *sl)
{
    servo_acc_t *x = &r->acc[id];
    uint32_t lat = sl->stats.last_latency_us;
    x->replies++;
    x->latency_sum += (double)lat;
    x->latency_n++;
    if (lat > x->latency_max) {
        x->latency_max = lat;
    }
    if (r->a.side == SIDE_JOINT) {
        const j288_joint_state_t *st = j288_joint_state(&r->joint[id]);
        if (r->a.motion != MOTION_NONE && st->known && !isnan(r->pos_des[id])) {
            double e = fabs(r->pos_des[id] - (double)st->pos);
            x->err_sq_sum += e * e;
            x->err_n++;
            if (e > x->err_max) {
                x->err_max = e;
            }
        }
    } else if (r->a.motion != MOTION_NONE) {
        double e = fabs(r->pos_des[id] - (double)j288_pos_from_raw(sl->reply.pos, r->side));
        x->err_sq_sum += e * e;
        x->err_n++;
        if (e > x->err_max) {
            x->err_max = e;
        }
    }
}

/* Each listed servo after a cycle's sweep at time t: a reply or a failure, and a CSV row. */
static void account_cycle(log_run_t *r, double t)
{
    uint8_t id;
    for (id = 0; id <= J288_MAX_ID; id++) {
        const j288_slot_t *sl = j288_sched_slot(r->s, id);
        servo_acc_t *x = &r->acc[id];
        bool fresh;
        if (!listed(r, id)) {
            continue;
        }
        fresh = sl->stats.successes != x->seen_successes;
        x->seen_successes = sl->stats.successes;
        if (fresh) {
            if (r->a.side == SIDE_JOINT) {
                (void)j288_joint_take_reply(&r->joint[id], &sl->reply, NULL);
            }
            account_reply(r, id, sl);
        } else {
            x->failures++;
        }
        if (r->csv != NULL) {
            double rt = fresh ? (double)(uint32_t)(sl->reply_us - r->t0) / 1e6 : t;
            if (fresh && r->a.side == SIDE_JOINT) {
                csv_row_joint(r->csv, rt, id, sl, &r->joint[id], r->pos_des[id]);
            } else {
                csv_row(r->csv, rt, id, sl, fresh, r->side, r->pos_des[id]);
            }
            r->rs.rows++;
        }
    }
}

/* Sleep until the next tick: the runner's pacing (absolute deadlines; a sweep that ran past
 * the tick makes it start late, at once; ticks a whole period behind are skipped, never
 * bunched). */
static int wait_tick(log_run_t *r, uint32_t period_us)
{
    j288_rt_report_t rep;
    int rc = j288_robot_pace(r->b.robot, period_us);
    (void)j288_robot_timing(r->b.robot, &rep);
    r->rs.missed = rep.missed;
    r->rs.skipped = rep.skipped;
    return rc;
}

/* Whether a sweep's or a sleep's result ends the run: a stop signal or a vanished device. */
static bool run_ends(const log_run_t *r, int rc, log_end_t *end)
{
    if (rc == J288_ERR_ABORTED) {
        *end = LOG_INTERRUPTED;
        return true;
    }
    if (rc == J288_ERR_OFFLINE) {
        cli_error("%s", cli_bus_error(&r->b));
        *end = LOG_FAILED;
        return true;
    }
    return false;
}

/* One sweep per tick for --duration: commands, sweep, replies, CSV rows. */
static log_end_t log_cycles(log_run_t *r)
{
    uint32_t period_us = (uint32_t)lround(1e6 / r->a.rate_hz);
    log_end_t end = LOG_DONE;
    r->t0 = j288_robot_now_us();
    j288_robot_timing_reset(r->b.robot); /* the probe's sweeps are not the log's */
    (void)j288_robot_pace(r->b.robot, period_us); /* the schedule starts with the first tick */
    for (;;) {
        double t = (double)(uint32_t)(j288_robot_now_us() - r->t0) / 1e6;
        if (t >= r->a.duration_s) {
            break;
        }
        set_cycle_commands(r, t);
        if (run_ends(r, sweep(&r->b, r->sweep_timeout_us), &end)) {
            break;
        }
        r->rs.cycles++;
        account_cycle(r, t);
        if (run_ends(r, wait_tick(r, period_us), &end)) {
            break;
        }
    }
    r->rs.elapsed_s = (double)(uint32_t)(j288_robot_now_us() - r->t0) / 1e6;
    return end;
}

/* After the cycles: let a sweep cut short by a signal finish, lock every driven servo, close
 * the CSV file, print the summary. Returns the exit status. */
static int log_finish(log_run_t *r, log_end_t end)
{
    bool failed = end == LOG_FAILED;
    if (!failed) {
        if (cli_bus_lock_driven(&r->b) != 0) {
            cli_error("a servo did not confirm the lock (a broadcast lock was sent)");
            failed = true;
        }
    }
    if (r->csv != NULL) {
        int rc = fclose(r->csv);
        r->csv = NULL;
        if (rc != 0) {
            cli_error("writing %s failed", r->a.csv);
            failed = true;
        }
    }
    if (!failed) {
        double achieved = r->rs.elapsed_s > 0.0 ? (double)r->rs.cycles / r->rs.elapsed_s : 0.0;
        if (r->o.json) {
            print_summary_json(r, achieved);
        } else {
            print_summary_text(r, achieved);
        }
    }
    if (end == LOG_INTERRUPTED) {
        return cli_signal_exit_code();
    }
    return failed || r->lost != 0u ? CLI_EXIT_FAIL : CLI_EXIT_OK;
}

int cli_cmd_log(int argc, char **argv, const cli_global_t *g)
{
    static log_run_t r;
    int ec;
    memset(&r, 0, sizeof r);
    if (log_prepare(&r, argc, argv, g, &ec) != 0 || (ec = log_open(&r)) != CLI_EXIT_OK) {
        return ec;
    }
    ec = log_probe(&r);
    if (ec == CLI_EXIT_OK) {
        ec = log_finish(&r, log_cycles(&r));
    }
    if (r.csv != NULL) {
        (void)fclose(r.csv);
    }
    cli_bus_close(&r.b);
    return ec;
}
