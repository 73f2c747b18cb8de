/* The joint set-up commands: `j288 zero` (the zero at the current pose) and `j288 calibrate`
 * (the rotor phase c from a slow motion), each written back into the robot config. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cli_bus.h"
#include "json.h"

#define CAL_DEFAULT_RANGE   0.1   /* rad, joint frame: 130 OutPos counts */
#define CAL_DEFAULT_SPEED   0.05  /* rad/s: under half a count per reply at 200 Hz */
#define CAL_DEFAULT_RATE_HZ 200.0
#define CAL_LIMIT_MARGIN    0.01  /* rad kept from each limit */
#define FAILS_BEFORE_GIVING_UP 25
#define CAL_SETTLE_S        0.3   /* held at the start pose after the motion, before lock */

enum { OPT_ID = 0, OPT_JOINT, OPT_RANGE, OPT_SPEED, OPT_RATE, OPT_KP, OPT_KD };

typedef struct {
    long long id;
    const char *joint;
    double range, speed, rate_hz, kp, kd;
    bool have_kp, have_kd;
} joint_args_t;

static cli_robot_t g_robot;

static int parse_joint_opt(void *ctx, int key, const char *v)
{
    joint_args_t *a = ctx;
    switch (key) {
    case OPT_ID:
        return cli_parse_int("--id", v, 0, J288_MAX_ID, &a->id);
    case OPT_JOINT:
        a->joint = v;
        return 0;
    case OPT_RANGE:
        return cli_parse_real_in("--range", v, 0.02, 1.0, &a->range);
    case OPT_SPEED:
        return cli_parse_real_in("--speed", v, 0.001, 1.0, &a->speed);
    case OPT_RATE:
        return cli_parse_real_in("--rate", v, 50.0, 5000.0, &a->rate_hz);
    case OPT_KP:
        return cli_parse_gain(J288_QTY_KP, v, &a->have_kp, &a->kp);
    case OPT_KD:
        return cli_parse_gain(J288_QTY_KD, v, &a->have_kd, &a->kd);
    default:
        return 1;
    }
}

static void joint_args_init(joint_args_t *a)
{
    memset(a, 0, sizeof *a);
    a->id = -1;
    a->range = CAL_DEFAULT_RANGE;
    a->speed = CAL_DEFAULT_SPEED;
    a->rate_hz = CAL_DEFAULT_RATE_HZ;
}

/* Write one value back into the config when the joint came from it. Returns 0 written, 1 not
 * applicable (no file joint), -1 after an error line. */
static int write_back(const cli_joint_sel_t *sel, const j288_robot_config_update_t *upd)
{
    char err[J288_ROBOT_CONFIG_ERROR_MAX];
    if (sel->rj == NULL || g_robot.path == NULL) {
        return 1;
    }
    if (j288_robot_config_write_joint(g_robot.path, sel->rj->name, upd, err, sizeof err) != 0) {
        cli_error("%s", err);
        return -1;
    }
    return 0;
}

/* Before any motion: a value that could not be written back would be a motion for nothing
 * (a read-only config, a folder that cannot take the temporary file). 0, or -1 after an
 * error line. */
static int check_write_back(const cli_joint_sel_t *sel)
{
    char err[J288_ROBOT_CONFIG_ERROR_MAX];
    if (sel->rj == NULL || g_robot.path == NULL) {
        return 0;
    }
    if (j288_robot_config_check_writable(g_robot.path, err, sizeof err) != 0) {
        cli_error("%s; nothing was sent", err);
        return -1;
    }
    return 0;
}

/* ---- zero ----------------------------------------------------------------------------------- */

static const char zero_help[] =
    "usage: j288 [--port DEV] zero (--joint NAME --config FILE | --id N [--config FILE])\n"
    "                 [--json]\n"
    "\n"
    "Make the joint's current pose joint angle 0: find the absolute angle (the servo is sent\n"
    "lock commands: it goes limp), compute the zero (rad, in the output encoder's frame)\n"
    "and write it as the joint's zero: in FILE, keeping comments and every other value.\n"
    "Without a joint from FILE it prints the value to put in the config. With a calibrated\n"
    "phase the zero has the rotor's resolution; uncalibrated, the output encoder's half\n"
    "count (0.38 mrad). Hold the joint still at the pose while it runs.\n"
    "Exit status: 0 done; 1 no reply, the angle unknown (encoder fault, calibration\n"
    "mismatch) or the file could not be written; 2 bad arguments.\n"
    "\n" CLI_BUS_COMMON_HELP;

int cli_cmd_zero(int argc, char **argv, const cli_global_t *g)
{
    static const cli_opt_t opts[] = {
        {"--id", true, OPT_ID}, {"--joint", true, OPT_JOINT}, CLI_BUS_COMMON_OPTS, {NULL, false, 0}};
    const j288_joint_t *joint = NULL;
    joint_args_t a;
    cli_bus_opts_t o;
    cli_bus_t b;
    cli_joint_sel_t sel;
    j288_txn_t txn;
    j288_robot_config_update_t upd;
    j288_real_t zero = 0;
    unsigned replies;
    bool calibrated = false;
    int ec, wrote;

    joint_args_init(&a);
    cli_bus_opts_init(&o, g);
    if (cli_parse_bus_args(argc, argv, opts, zero_help, &o, parse_joint_opt, &a, &ec) != 0) {
        return ec;
    }
    if (cli_robot_load(&g_robot, o.config) != 0 ||
        cli_joint_select(&g_robot, a.joint, a.id, &o, &sel) != 0) {
        return CLI_EXIT_USAGE;
    }
    if (check_write_back(&sel) != 0) {
        return CLI_EXIT_FAIL;
    }
    cli_signals_install();
    if ((ec = cli_bus_open(&b, &o, 2)) != CLI_EXIT_OK) {
        return ec;
    }
    ec = cli_joint_start(&b, &sel.jc, sel.name, &joint, &txn, &replies, true);
    if (ec == CLI_EXIT_OK) {
        (void)j288_joint_zero_here(joint, &zero);
        calibrated = j288_joint_state(joint)->calibrated;
    }
    cli_bus_close(&b);
    if (ec != CLI_EXIT_OK) {
        return ec;
    }
    memset(&upd, 0, sizeof upd);
    upd.set_zero = true;
    upd.zero = (double)zero;
    if ((wrote = write_back(&sel, &upd)) < 0) {
        return CLI_EXIT_FAIL;
    }
    if (o.json) {
        cli_json_t j;
        cli_json_init(&j, stdout);
        cli_json_begin_object(&j, NULL);
        cli_json_int(&j, "id", sel.id);
        if (sel.rj != NULL) {
            cli_json_str(&j, "joint", sel.rj->name);
            cli_json_real(&j, "previous_zero", sel.rj->zero);
        }
        cli_json_real(&j, "zero", (double)zero);
        cli_json_bool(&j, "calibrated", calibrated);
        cli_json_bool(&j, "written", wrote == 0);
        cli_json_end_object(&j);
        cli_json_newline(&j);
    } else if (wrote == 0) {
        printf("%s: zero %.9f rad (was %.9f), written to %s\n", sel.name, (double)zero,
               sel.rj->zero, g_robot.path);
    } else {
        printf("%s: zero %.9f rad (put 'zero: %.9f' in the joint's entry of the robot "
               "config)\n",
               sel.name, (double)zero, (double)zero);
    }
    return CLI_EXIT_OK;
}

/* ---- calibrate ------------------------------------------------------------------------------ */

static const char calibrate_help[] =
    "usage: j288 [--port DEV] calibrate (--joint NAME --config FILE | --id N [--config FILE])\n"
    "                 [--range RAD] [--speed RAD_S] [--rate HZ] [--kp NM_RAD] [--kd NMS_RAD]\n"
    "                 [--json]\n"
    "\n"
    "Fit the joint's rotor phase c (r = N theta + c) and write it as the joint's phase: in\n"
    "FILE (comments and every other value kept); without a joint from FILE, print it. The\n"
    "joint moves: from where it is, slowly over --range (default 0.1 rad) up and down and\n"
    "back, kept inside its limits by 0.01 rad (a joint starting closer to a limit, or up to\n"
    "0.05 rad beyond it, starts from there); every reply's (output encoder, rotor) pair goes\n"
    "into the fit. The joint must be free to move over that range.\n"
    "  --range RAD      width of the motion, 0.02..1 (default 0.1)\n"
    "  --speed RAD_S    speed of the motion, 0.001..1 (default 0.05)\n"
    "  --rate HZ        command refresh rate, 50..5000 (default 200)\n"
    "  --kp, --kd       gains of the motion (default the config's, else 20 and 2.5)\n"
    "The report: pairs used, span in output encoder counts, residual rms and maximum\n"
    "(rotor rad), the fitted gear ratio. A fit failing a quality check (too few pairs, too\n"
    "small a span, residuals beyond the tolerance, a ratio off N) writes nothing. A phase\n"
    "already in the file is ignored during the motion (the joint runs uncalibrated), and the\n"
    "new one is checked by a calibrated start at the end.\n"
    "Ctrl-C, SIGTERM, SIGHUP or SIGQUIT: the servo is sent lock, nothing written (exit 130,\n"
    "143, 129, 131).\n"
    "Exit status: 0 written (or printed); 1 no reply, angle unknown or lost, a failed fit,\n"
    "the file could not be written; 2 bad arguments or no room inside the limits.\n"
    "\n" CLI_BUS_COMMON_HELP;

typedef struct {
    double q0, lo, hi;   /* the path: q0 -> hi -> lo -> q0 */
    double kp, kd, speed;
} cal_path_t;

/* The window of the motion inside the limits, by CAL_LIMIT_MARGIN or, for a joint starting
 * closer (at a hard stop, say), from its start pose (the nearest limit when it is just beyond:
 * cli_joint_start_inside). 0, or -1 after an error line. */
static int cal_window(const joint_args_t *a, const j288_joint_t *j, double q, cal_path_t *p,
                      const char *name)
{
    const j288_joint_config_t *cfg = j288_joint_config(j); /* the defaults filled in */
    double lmin = cfg->continuous ? -HUGE_VAL : (double)cfg->pos_min;
    double lmax = cfg->continuous ? HUGE_VAL : (double)cfg->pos_max, q0;
    if (cli_joint_start_inside(cfg, name, q, &q0) != 0) {
        return -1;
    }
    lmin = fmin(lmin + CAL_LIMIT_MARGIN, q0);
    lmax = fmax(lmax - CAL_LIMIT_MARGIN, q0);
    p->q0 = q0;
    p->lo = q0 - a->range / 2.0;
    p->hi = q0 + a->range / 2.0;
    if (p->lo < lmin) {
        p->hi += lmin - p->lo;
        p->lo = lmin;
    }
    if (p->hi > lmax) {
        p->lo -= p->hi - lmax;
        p->hi = lmax;
    }
    if (p->lo < lmin) {
        cli_error("%s: no room for a %g rad motion inside the limits [%g, %g] (give a smaller "
                  "--range)",
                  name, a->range, (double)cfg->pos_min, (double)cfg->pos_max);
        return -1;
    }
    return 0;
}

/* The target at distance s travelled along q0 -> hi -> lo -> q0. Returns false past the end. */
static bool cal_target_at(const cal_path_t *p, double s, j288_joint_target_t *t)
{
    double up = p->hi - p->q0, down = p->hi - p->lo, back = p->q0 - p->lo;
    memset(t, 0, sizeof *t);
    t->kp = (j288_real_t)p->kp;
    t->kd = (j288_real_t)p->kd;
    if (s < up) {
        t->pos = (j288_real_t)(p->q0 + s);
        t->speed = (j288_real_t)p->speed;
    } else if (s < up + down) {
        t->pos = (j288_real_t)(p->hi - (s - up));
        t->speed = (j288_real_t)-p->speed;
    } else if (s < up + down + back) {
        t->pos = (j288_real_t)(p->lo + (s - up - down));
        t->speed = (j288_real_t)p->speed;
    } else {
        t->pos = (j288_real_t)p->q0;
        return false;
    }
    return true;
}

/* The motion, every reply into the fit. CLI_EXIT_OK, or an exit status after an error line
 * (the servo then locked by the caller). */
static int cal_move(cli_bus_t *b, const j288_joint_t *j, j288_cal_t *cal, const cal_path_t *p,
                    const joint_args_t *a, const char *name)
{
    uint32_t period_us = (uint32_t)lround(1e6 / a->rate_hz);
    uint32_t t0 = j288_robot_now_us(), next = t0;
    int fails = 0;
    double end_s = -1.0; /* when the path ended */
    for (;;) {
        j288_joint_target_t t;
        j288_cmd_raw_t cmd;
        j288_txn_t txn;
        double el = (double)(uint32_t)(j288_robot_now_us() - t0) / 1e6;
        int rc;
        if (cli_stop_signal != 0) {
            return cli_signal_exit_code();
        }
        /* After the path, hold the start pose a moment: a joint locked while moving coasts. */
        if (!cal_target_at(p, el * p->speed, &t) && end_s < 0.0) {
            end_s = el;
        }
        if (end_s >= 0.0 && el - end_s >= CAL_SETTLE_S) {
            break;
        }
        rc = j288_joint_command(j, &t, &cmd, NULL);
        if (rc != J288_OK) {
            cli_joint_target_error(j288_joint_config(j), name, "calibration motion to",
                                   (double)t.pos, rc);
            return CLI_EXIT_FAIL;
        }
        rc = cli_bus_transfer(b, &cmd, &txn);
        if (rc == J288_ERR_OFFLINE) {
            cli_report_txn_failure(b, j288_joint_config(j)->id, rc);
            return CLI_EXIT_FAIL;
        }
        fails = rc == J288_OK ? 0 : fails + 1;
        if (fails >= FAILS_BEFORE_GIVING_UP) {
            cli_error("%s stopped answering (%d commands in a row failed)", name, fails);
            return CLI_EXIT_FAIL;
        }
        if (rc == J288_OK) { /* (the runner fed the reply to j: known before, now lost) */
            if (!j288_joint_state(j)->known) {
                cli_error("%s: the joint angle was lost during the motion (residual %.4f rad)",
                          name, (double)j288_joint_state(j)->residual);
                return CLI_EXIT_FAIL;
            }
            if (end_s < 0.0) {
                (void)j288_cal_add_reply(cal, &txn.reply);
            }
        }
        next += period_us;
        if ((int32_t)(next - j288_robot_now_us()) < 0) {
            next = j288_robot_now_us();
        }
        if (cli_bus_sleep_until(b, next) == J288_ERR_OFFLINE) {
            cli_report_txn_failure(b, j288_joint_config(j)->id, J288_ERR_OFFLINE);
            return CLI_EXIT_FAIL;
        }
    }
    return CLI_EXIT_OK;
}

static const char *problem_list(unsigned problems, char *buf, size_t len)
{
    static const struct {
        unsigned bit;
        const char *text;
    } names[] = {{J288_CAL_FEW_SAMPLES, "too few pairs"},
                 {J288_CAL_SMALL_SPAN, "too small a span"},
                 {J288_CAL_NOISY, "residuals beyond the tolerance"},
                 {J288_CAL_RATIO, "the gear ratio does not match"}};
    size_t i, used = 0;
    buf[0] = '\0';
    for (i = 0; i < sizeof names / sizeof names[0]; i++) {
        if ((problems & names[i].bit) != 0u && used < len) {
            int n = snprintf(buf + used, len - used, "%s%s", used != 0u ? ", " : "",
                             names[i].text);
            used += n > 0 ? (size_t)n : 0u;
        }
    }
    return buf;
}

/* After a fit: a calibrated start with the new phase, from the pose the joint is at. The
 * start's eps in *eps. Returns CLI_EXIT_OK when the start succeeded. */
static int cal_check(cli_bus_t *b, const j288_joint_config_t *jc_uncal, double phase,
                     const char *name, double *eps)
{
    const j288_joint_t *jt = NULL;
    j288_joint_config_t jc = *jc_uncal;
    j288_txn_t txn;
    unsigned replies;
    int ec;
    jc.has_phase = true;
    jc.phase = (j288_real_t)phase;
    ec = cli_joint_start(b, &jc, name, &jt, &txn, &replies, true);
    *eps = jt != NULL ? (double)j288_joint_state(jt)->cal_residual : 0.0;
    return ec;
}

static void cal_report(const cli_joint_sel_t *sel, const j288_cal_report_t *r, double eps,
                       int wrote, bool json)
{
    char list[200];
    if (json) {
        cli_json_t j;
        cli_json_init(&j, stdout);
        cli_json_begin_object(&j, NULL);
        cli_json_int(&j, "id", sel->id);
        if (sel->rj != NULL) {
            cli_json_str(&j, "joint", sel->rj->name);
        }
        cli_json_real(&j, "phase", (double)r->phase);
        cli_json_uint(&j, "samples", r->samples);
        cli_json_uint(&j, "rejected", r->rejected);
        cli_json_uint(&j, "span_counts", r->span_counts);
        cli_json_real(&j, "rms", (double)r->rms);
        cli_json_real(&j, "max_abs", (double)r->max_abs);
        cli_json_real(&j, "ratio", (double)r->ratio);
        cli_json_real(&j, "check_residual", eps);
        cli_json_bool(&j, "written", wrote == 0);
        cli_json_end_object(&j);
        cli_json_newline(&j);
        return;
    }
    printf("%s: phase %.6f rotor rad from %lu pairs over %lu counts; residual rms %.4f, max "
           "%.4f rotor rad; gear ratio %.3f; check: calibrated start %.4f rotor rad off%s\n",
           sel->name, (double)r->phase, (unsigned long)r->samples, (unsigned long)r->span_counts,
           (double)r->rms, (double)r->max_abs, (double)r->ratio, eps,
           r->problems != 0u ? problem_list(r->problems, list, sizeof list) : "");
    if (wrote == 0) {
        printf("written to %s\n", g_robot.path);
    } else {
        printf("put 'phase: %.9f' in the joint's entry of the robot config\n", (double)r->phase);
    }
}

/* The motion, the fit and its check on an open bus. The report in *r, the check's eps in
 * *eps. */
static int cal_run(cli_bus_t *b, const joint_args_t *a, const cli_joint_sel_t *sel,
                   const j288_joint_config_t *jc, j288_cal_report_t *r, double *eps)
{
    static j288_cal_t cal;
    const j288_joint_t *joint = NULL;
    char list[200];
    cal_path_t path;
    j288_txn_t txn;
    unsigned replies;
    int ec, rc;
    (void)j288_cal_init(&cal, jc);
    if ((ec = cli_joint_start(b, jc, sel->name, &joint, &txn, &replies, true)) != CLI_EXIT_OK) {
        return ec;
    }
    if (cal_window(a, joint, (double)j288_joint_state(joint)->pos, &path, sel->name) != 0) {
        return CLI_EXIT_USAGE;
    }
    path.speed = a->speed;
    cli_joint_gains(sel->rj, a->have_kp, a->kp, a->have_kd, a->kd, &path.kp, &path.kd);
    ec = cal_move(b, joint, &cal, &path, a, sel->name);
    if (cli_bus_lock_driven(b) != 0 && ec == CLI_EXIT_OK) {
        cli_error("%s did not confirm the lock (a broadcast lock was sent)", sel->name);
        ec = CLI_EXIT_FAIL;
    }
    if (ec != CLI_EXIT_OK) {
        return ec;
    }
    rc = j288_cal_result(&cal, r);
    if (rc != J288_OK) {
        cli_error("%s: %s: %s (%lu pairs, %lu counts, residual rms %.3f rotor rad, ratio %.2f); "
                  "nothing written",
                  sel->name, j288_strerror(rc), problem_list(r->problems, list, sizeof list),
                  (unsigned long)r->samples, (unsigned long)r->span_counts, (double)r->rms,
                  (double)r->ratio);
        return CLI_EXIT_FAIL;
    }
    if (cal_check(b, jc, (double)r->phase, sel->name, eps) != CLI_EXIT_OK) {
        return CLI_EXIT_FAIL;
    }
    return CLI_EXIT_OK;
}

int cli_cmd_calibrate(int argc, char **argv, const cli_global_t *g)
{
    static const cli_opt_t opts[] = {{"--id", true, OPT_ID},       {"--joint", true, OPT_JOINT},
                                     {"--range", true, OPT_RANGE}, {"--speed", true, OPT_SPEED},
                                     {"--rate", true, OPT_RATE},   {"--kp", true, OPT_KP},
                                     {"--kd", true, OPT_KD},       CLI_BUS_COMMON_OPTS,
                                     {NULL, false, 0}};
    joint_args_t a;
    cli_bus_opts_t o;
    cli_bus_t b;
    cli_joint_sel_t sel;
    j288_joint_config_t jc;
    j288_cal_report_t r;
    j288_robot_config_update_t upd;
    double eps = 0.0;
    int ec, wrote;

    joint_args_init(&a);
    cli_bus_opts_init(&o, g);
    if (cli_parse_bus_args(argc, argv, opts, calibrate_help, &o, parse_joint_opt, &a, &ec) != 0) {
        return ec;
    }
    if (cli_robot_load(&g_robot, o.config) != 0 ||
        cli_joint_select(&g_robot, a.joint, a.id, &o, &sel) != 0) {
        return CLI_EXIT_USAGE;
    }
    if (check_write_back(&sel) != 0) {
        return CLI_EXIT_FAIL;
    }
    /* The motion runs uncalibrated: an old phase that no longer fits must not stop it. The
     * fit labels the turns as this configuration does, which is what the phase goes with. */
    jc = sel.jc;
    jc.has_phase = false;
    jc.phase = 0;
    cli_signals_install();
    if ((ec = cli_bus_open(&b, &o, 1)) != CLI_EXIT_OK) {
        return ec;
    }
    memset(&r, 0, sizeof r);
    ec = cal_run(&b, &a, &sel, &jc, &r, &eps);
    cli_bus_close(&b);
    if (cli_stop_signal != 0) {
        cli_error("%s: calibration interrupted (servo locked); nothing written%s%s", sel.name,
                  o.config != NULL ? " to " : "", o.config != NULL ? o.config : "");
        return cli_signal_exit_code();
    }
    if (ec != CLI_EXIT_OK) {
        return ec;
    }
    memset(&upd, 0, sizeof upd);
    upd.set_phase = true;
    upd.phase = (double)r.phase;
    if ((wrote = write_back(&sel, &upd)) < 0) {
        return CLI_EXIT_FAIL;
    }
    cal_report(&sel, &r, eps, wrote, o.json);
    return CLI_EXIT_OK;
}
