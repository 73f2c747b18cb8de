/* The robot config and the joint frame for the bus commands; see cli_bus.h. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "cli_bus.h"

int cli_robot_load(cli_robot_t *r, const char *path)
{
    char err[J288_ROBOT_CONFIG_ERROR_MAX];
    r->path = path;
    if (path == NULL) {
        return 0;
    }
    if (j288_robot_config_load(path, &r->cfg, err, sizeof err) != 0) {
        cli_error("%s", err);
        return -1;
    }
    return 0;
}

/* The file's joint with id: the only one, or the one on the bus whose port is o->port. */
static int joint_by_id(const cli_robot_t *r, uint8_t id, const cli_bus_opts_t *o,
                       const j288_robot_config_joint_t **found)
{
    const j288_robot_config_joint_t *match = NULL;
    unsigned n = 0;
    size_t i;
    for (i = 0; i < r->cfg.njoints; i++) {
        const j288_robot_config_joint_t *rj = &r->cfg.joint[i];
        if (rj->id != id) {
            continue;
        }
        if (o->port != NULL && rj->bus >= 0 && strcmp(r->cfg.bus[rj->bus].port, o->port) != 0) {
            continue;
        }
        match = rj;
        n++;
    }
    if (n > 1u) {
        cli_error("%s: id %u is used on %u buses: name the joint with --joint or the bus with "
                  "--port",
                  r->path, (unsigned)id, n);
        return -1;
    }
    *found = match;
    return 0;
}

/* The bus options the command line left open, from the joint's bus (or the file's only
 * bus). */
void cli_robot_fill_bus(const cli_robot_t *r, const j288_robot_config_joint_t *rj,
                        cli_bus_opts_t *o)
{
    const j288_robot_config_bus_t *bus = NULL;
    if (r->path == NULL) {
        return;
    }
    if (rj != NULL && rj->bus >= 0) {
        bus = &r->cfg.bus[rj->bus];
    } else if (r->cfg.nbuses == 1u) {
        bus = &r->cfg.bus[0];
    }
    if (bus == NULL) {
        return;
    }
    if (o->port == NULL) {
        o->port = bus->port;
    }
    if (o->baud == 0u && bus->has_baud) {
        o->baud = bus->baud;
    }
    if (o->margin_us == 0u && bus->has_margin_us) {
        o->margin_us = bus->margin_us;
    }
    if (!o->echo && bus->has_echo) {
        o->echo = bus->echo;
    }
}

int cli_joint_select(const cli_robot_t *r, const char *joint_name, long long id,
                     cli_bus_opts_t *o, cli_joint_sel_t *sel)
{
    j288_joint_t probe;
    int rc;
    memset(sel, 0, sizeof *sel);
    if (joint_name != NULL && id >= 0) {
        cli_error("--id and --joint exclude each other");
        return -1;
    }
    if (joint_name == NULL && id < 0) {
        cli_error("--id N or --joint NAME is required");
        return -1;
    }
    if (joint_name != NULL) {
        if (r->path == NULL) {
            cli_error("--joint %s needs --config FILE (the robot config naming it)", joint_name);
            return -1;
        }
        sel->rj = j288_robot_config_find_joint(&r->cfg, joint_name);
        if (sel->rj == NULL) {
            cli_error("%s: no joint named '%s'", r->path, joint_name);
            return -1;
        }
    } else if (r->path != NULL && joint_by_id(r, (uint8_t)id, o, &sel->rj) != 0) {
        return -1;
    }
    if (sel->rj != NULL) {
        sel->id = sel->rj->id;
        j288_robot_config_joint_config(sel->rj, &sel->jc);
        (void)snprintf(sel->name, sizeof sel->name, "joint %s", sel->rj->name);
    } else {
        sel->id = (uint8_t)id;
        sel->jc.id = sel->id; /* the all-zero configuration: the library's defaults */
        (void)snprintf(sel->name, sizeof sel->name, "servo %u", (unsigned)sel->id);
    }
    cli_robot_fill_bus(r, sel->rj, o);
    rc = j288_joint_init(&probe, &sel->jc);
    if (rc != J288_OK) {
        cli_error("%s:%u: %s: %s (zero and limits within +-%g rad, phase within 2 pi)",
                  r->path != NULL ? r->path : "-", sel->rj != NULL ? sel->rj->line : 0u, sel->name,
                  j288_strerror(rc), J288_JOINT_MAX_ANGLE);
        return -1;
    }
    sel->jc = *j288_joint_config(&probe); /* the library's defaults filled in */
    return 0;
}

void cli_joint_why_unknown(const j288_joint_t *j, const char *name, unsigned replies, char *buf,
                           size_t len)
{
    const j288_joint_state_t *st = j288_joint_state(j);
    if (st->encoder_fault) {
        (void)snprintf(buf, len, "%s: output encoder fault (fault bit 12): the joint angle is "
                       "unknown", name);
    } else if (st->cal_mismatch) {
        (void)snprintf(buf, len, "%s: %s: the rotor is %.3f rad away from where the phase puts "
                       "it (tolerance %.3f): the gear or the servo changed; run j288 calibrate, "
                       "or remove phase from the config to run uncalibrated",
                       name, j288_strerror(J288_ERR_CAL_MISMATCH), (double)st->cal_residual,
                       (double)j288_joint_config(j)->cal_tol);
    } else {
        (void)snprintf(buf, len, "%s: the joint angle is still unknown after %u replies (the "
                       "output encoder and the rotor disagree: the joint is moving fast, or the "
                       "encoder is noisy)", name, replies);
    }
}

int cli_joint_start(cli_bus_t *b, const j288_joint_config_t *jc, const char *name,
                    const j288_joint_t **j, j288_txn_t *last, unsigned *replies,
                    bool report_unknown)
{
    int rc = j288_robot_servo_joint_setup(b->robot, 0, jc);
    *replies = 0;
    *j = j288_robot_servo_joint(b->robot, 0, jc->id);
    if (rc != J288_OK || *j == NULL) {
        cli_error("%s: %s", name, j288_strerror(rc != J288_OK ? rc : J288_ERR_BAD_ARG));
        return CLI_EXIT_FAIL;
    }
    rc = j288_robot_acquire_joint(b->robot, 0, jc->id, last, replies);
    if (rc == J288_OK) {
        return CLI_EXIT_OK;
    }
    if (cli_stop_signal != 0) {
        return cli_signal_exit_code();
    }
    if (*replies == 0u || rc == J288_ERR_OFFLINE ||
        (report_unknown && rc != J288_ERR_ANGLE_UNKNOWN && rc != J288_ERR_CAL_MISMATCH)) {
        cli_report_txn_failure(b, jc->id, rc);
    } else if (report_unknown) {
        char why[400];
        cli_joint_why_unknown(*j, name, *replies, why, sizeof why);
        cli_error("%s", why);
    }
    return CLI_EXIT_FAIL;
}

/* The joint's range (the defaults filled in: cli_joint_select()); a continuous joint has
 * none. */
static void joint_range(const j288_joint_config_t *jc, double *lo, double *hi)
{
    *lo = jc->continuous ? -HUGE_VAL : (double)jc->pos_min;
    *hi = jc->continuous ? HUGE_VAL : (double)jc->pos_max;
}

double cli_joint_nearest_inside(const j288_joint_config_t *jc, double q)
{
    double lo, hi;
    joint_range(jc, &lo, &hi);
    return q < lo ? lo : (q > hi ? hi : q);
}

bool cli_joint_pos_allowed(const j288_joint_config_t *jc, double pos)
{
    double lo, hi;
    joint_range(jc, &lo, &hi);
    return jc->clamp || (pos >= lo && pos <= hi);
}

int cli_joint_start_inside(const j288_joint_config_t *jc, const char *name, double q,
                           double *q_start)
{
    double lo, hi, out;
    joint_range(jc, &lo, &hi);
    out = q < lo ? lo - q : (q > hi ? q - hi : 0.0);
    if (jc->clamp || out == 0.0) {
        *q_start = q;
        return 0;
    }
    if (out > CLI_JOINT_START_OUTSIDE_MAX) {
        cli_error("%s: at %g rad, %g rad outside its limits [%g, %g] (more than %g): move it "
                  "inside by hand or with --side output; servo locked",
                  name, q, out, lo, hi, CLI_JOINT_START_OUTSIDE_MAX);
        return -1;
    }
    *q_start = q < lo ? lo : hi;
    return 0;
}

void cli_joint_target_error(const j288_joint_config_t *jc, const char *name, const char *what,
                            double value, int rc)
{
    double lo, hi;
    joint_range(jc, &lo, &hi);
    if (rc == J288_ERR_LIMIT_POS) {
        cli_error("%s: %s %g: %s [%g, %g]; nothing sent", name, what, value, j288_strerror(rc),
                  lo, hi);
    } else if (rc == J288_ERR_LIMIT_SPEED) {
        cli_error("%s: %s %g: %s (%g rad/s); nothing sent", name, what, value,
                  j288_strerror(rc), (double)jc->max_speed);
    } else if (rc == J288_ERR_LIMIT_TORQUE) {
        cli_error("%s: %s %g: %s (%g N*m); nothing sent", name, what, value, j288_strerror(rc),
                  (double)jc->max_torque);
    } else {
        cli_error("%s: %s %g: %s", name, what, value, j288_strerror(rc));
    }
}

void cli_joint_gains(const j288_robot_config_joint_t *rj, bool have_kp, double kp, bool have_kd,
                     double kd, double *out_kp, double *out_kd)
{
    *out_kp = have_kp ? kp : (rj != NULL && rj->has_kp ? rj->kp : J288_ROBOT_DEFAULT_KP);
    *out_kd = have_kd ? kd : (rj != NULL && rj->has_kd ? rj->kd : J288_ROBOT_DEFAULT_KD);
}

void cli_json_joint_members(cli_json_t *jw, const j288_joint_t *j)
{
    const j288_joint_state_t *st = j288_joint_state(j);
    cli_json_bool(jw, "joint_known", st->known);
    cli_json_bool(jw, "joint_calibrated", st->calibrated);
    if (st->known) {
        cli_json_real(jw, "joint_pos", (double)st->pos);
    }
    cli_json_real(jw, "joint_speed", (double)st->speed);
    cli_json_real(jw, "joint_torque", (double)st->torque);
    cli_json_real(jw, "joint_encoder", (double)st->encoder);
    cli_json_bool(jw, "encoder_fault", st->encoder_fault);
    cli_json_bool(jw, "cal_mismatch", st->cal_mismatch);
    if (st->cal_mismatch) {
        cli_json_real(jw, "cal_residual", (double)st->cal_residual);
    }
    cli_json_bool(jw, "beyond_limit", st->beyond_limit);
}
