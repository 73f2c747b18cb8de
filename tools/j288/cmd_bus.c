/* The one-shot and drive bus commands: scan, status, stop, hold, move, torque. */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "cli_bus.h"
#include "frameview.h"
#include "json.h"

#define FAILS_BEFORE_GIVING_UP 25 /* consecutive failed refreshes of a driven servo */

/* Default gains, output side: gentle (a first try on real hardware should not snap), well
 * inside the wire range (kp 0..2128 N*m/rad, kd 0..21.28 N*m*s/rad on the output side);
 * kd gives a damping ratio near 0.7 on the simulator's rotor (2e-6 kg m^2). */
#define DEFAULT_RATE_HZ           200.0
#define DEFAULT_MOVE_SPEED_OUTPUT 1.0 /* rad/s */

/* The robot config of this run: one per process, too large for the stack. */
static cli_robot_t g_robot;

/* ---- scan ----------------------------------------------------------------------------------- */

static const char scan_help[] =
    "usage: j288 [--port DEV] scan [--ids LIST] [--json] [--config FILE]\n"
    "\n"
    "Address every id 0-14 (or those of --ids) once and list the servos that answer: mode,\n"
    "temperatures, voltage and faults. The protocol has no read-only query, so each id\n"
    "receives a lock command (watchdog bit 0): a servo that was moving stops.\n"
    "--json prints one array of objects with the keys of `j288 decode --json` (id, mode,\n"
    "case_temp_c, voltage_v, faults, ...) plus latency_us and possible_duplicate.\n"
    "  --ids LIST       the ids to address, e.g. 1,2,3 (default 0-14): each absent id costs\n"
    "                   a reply margin and its retries, so a scan with a long --margin-us\n"
    "                   stays short\n"
    "More bytes within 10 ms of a servo's reply (two servos answering one id) are reported as\n"
    "\"possible duplicate ids\" (JSON: possible_duplicate). The protocol has no command that\n"
    "sets a servo's id: give each servo its own id with the vendor's tool, one servo on the\n"
    "bus at a time (docs/troubleshooting.md).\n"
    "Exit status: 0 at least one servo answered; 1 silent bus or device error.\n"
    "\n" CLI_BUS_COMMON_HELP;

enum { OPT_SCAN_IDS = 0 };

static int parse_scan_opt(void *ctx, int key, const char *v)
{
    return key == OPT_SCAN_IDS ? cli_parse_id_list("--ids", v, J288_MAX_ID, ctx) : 1;
}

/* Bytes the bus took that were no reply of a transaction: late or extra replies, replies from
 * another id, corrupt frames. */
static uint32_t extra_bytes(const cli_bus_t *b)
{
    const j288_bus_stats_t *s = j288_robot_bus_wire_stats(b->robot, 0);
    return s == NULL ? 0u : s->stale_bytes + s->wrong_id + s->crc_errors;
}

/* How long scan listens after a good reply for a second one: a second servo on the id answers
 * the same command at once, so its bytes follow the first reply's at the wire's pace (two
 * replies at the same moment garble each other: a CRC error, noted as such). */
#define SCAN_SECOND_REPLY_US 10000u

/* After id's good reply, up to SCAN_SECOND_REPLY_US more (or the reply budget, when shorter):
 * any byte that comes then is a second answer. */
static bool answered_twice(cli_bus_t *b, uint32_t extra_before)
{
    const j288_bus_t *bus = j288_robot_bus_engine(b->robot, 0);
    uint32_t wait_us = bus != NULL ? j288_bus_reply_budget_us(bus) : 0u;
    if (wait_us > SCAN_SECOND_REPLY_US)
        wait_us = SCAN_SECOND_REPLY_US;
    (void)cli_bus_sleep_until(b, j288_robot_now_us() + wait_us);
    return extra_bytes(b) != extra_before;
}

int cli_cmd_scan(int argc, char **argv, const cli_global_t *g)
{
    static const cli_opt_t opts[] = {
        {"--ids", true, OPT_SCAN_IDS}, CLI_BUS_COMMON_OPTS, {NULL, false, 0}};
    uint32_t ids = 0; /* bit per id to address; none given: all */
    cli_bus_opts_t o;
    cli_bus_t b;
    j288_txn_t txn[J288_MAX_ID + 1u];
    int result[J288_MAX_ID + 1u];
    bool twice[J288_MAX_ID + 1u];
    j288_cmd_raw_t cmd;
    unsigned found = 0;
    int ec;
    uint8_t id;

    cli_bus_opts_init(&o, g);
    if (cli_parse_bus_args(argc, argv, opts, scan_help, &o, parse_scan_opt, &ids, &ec) != 0) {
        return ec;
    }
    if (ids == 0u) {
        ids = CLI_ALL_IDS;
    }
    if (cli_robot_load(&g_robot, o.config) != 0) {
        return CLI_EXIT_USAGE;
    }
    cli_robot_fill_bus(&g_robot, NULL, &o);
    cli_signals_install();
    if ((ec = cli_bus_open(&b, &o, 1)) != CLI_EXIT_OK) {
        return ec;
    }
    for (id = 0; id <= J288_MAX_ID; id++) {
        uint32_t extra = extra_bytes(&b);
        result[id] = J288_ERR_TIMEOUT; /* not addressed: not listed */
        twice[id] = false;
        if ((ids & (1ul << id)) == 0u) {
            continue;
        }
        cli_lock_cmd(id, &cmd);
        result[id] = cli_bus_transfer(&b, &cmd, &txn[id]);
        if (result[id] == J288_OK && txn[id].attempts == 1u) { /* (a re-send invites late replies) */
            twice[id] = answered_twice(&b, extra);
        }
        if (result[id] == J288_ERR_OFFLINE) {
            cli_report_txn_failure(&b, id, result[id]);
            cli_bus_close(&b);
            return CLI_EXIT_FAIL;
        }
        if (result[id] == J288_OK) {
            found++;
        }
        if (cli_stop_signal != 0) {
            cli_bus_close(&b);
            return cli_signal_exit_code();
        }
    }
    if (found == 0u) {
        cli_error("no servo answered on %s (%s tried): check power, wiring and --baud", b.dev,
                  ids == CLI_ALL_IDS ? "ids 0-14" : "the ids of --ids");
        cli_bus_close(&b);
        return CLI_EXIT_FAIL;
    }
    if (o.json) {
        cli_json_t j;
        cli_json_init(&j, stdout);
        cli_json_begin_array(&j, NULL);
        for (id = 0; id <= J288_MAX_ID; id++) {
            if (result[id] == J288_OK) {
                cli_json_begin_object(&j, NULL);
                cli_json_reply_members(&j, &txn[id].reply);
                cli_json_uint(&j, "latency_us", txn[id].latency_us);
                cli_json_bool(&j, "possible_duplicate", twice[id]);
                cli_json_end_object(&j);
            }
        }
        cli_json_end_array(&j);
        cli_json_newline(&j);
    } else {
        char list[512];
        printf("%-3s %-5s %9s %9s %8s  %s\n", "id", "mode", "case", "winding", "voltage", "faults");
        for (id = 0; id <= J288_MAX_ID; id++) {
            const j288_reply_raw_t *r = &txn[id].reply;
            if (result[id] != J288_OK) {
                continue;
            }
            printf("%-3u %-5s %7d C %7u C %6.1f V  %s%s%s\n", (unsigned)id, cli_mode_name(r->status),
                   (int)r->case_temp_c, (unsigned)r->winding_temp_c,
                   (double)r->voltage_raw * J288_SCALE_VOLTAGE,
                   cli_fault_list(r->faults, list, sizeof list),
                   r->watchdog_tripped ? " (watchdog had tripped)" : "",
                   twice[id] ? "  (possible duplicate ids)" : "");
        }
        printf("%u servo%s answered on %s\n", found, found == 1u ? "" : "s", b.dev);
    }
    for (id = 0; id <= J288_MAX_ID; id++) {
        if (result[id] != J288_OK && result[id] != J288_ERR_TIMEOUT) {
            fprintf(stderr, "note: id %u: %s (a servo may be there; the line is noisy, or two "
                            "servos answer to this id)\n",
                    (unsigned)id, j288_strerror(result[id]));
        }
        if (twice[id]) {
            fprintf(stderr, "note: id %u: more bytes came after its reply: possible duplicate "
                            "ids (two servos answering to %u). The protocol cannot set an id: "
                            "give each servo its own with the vendor's tool, one servo on the "
                            "bus at a time\n",
                    (unsigned)id, (unsigned)id);
        }
    }
    cli_bus_close(&b);
    return CLI_EXIT_OK;
}

/* ---- status --------------------------------------------------------------------------------- */

static const char status_help[] =
    "usage: j288 [--port DEV] status (--id N | --joint NAME --config FILE) [--json]\n"
    "\n"
    "Read one servo's reply and decode it as `j288 decode` does (same JSON keys), plus the\n"
    "joint frame: the absolute joint angle from the output encoder and the rotor (JSON:\n"
    "joint_pos in rad, joint_known, joint_calibrated, joint_speed, joint_torque,\n"
    "encoder_fault, cal_mismatch, beyond_limit). Without --config the joint angle is the\n"
    "output encoder angle wrapped to [-pi, pi); with it, the joint's zero, direction, limits\n"
    "and phase apply. Finding the angle takes a few replies (8 by default). The protocol has\n"
    "no read-only query: the servo receives lock commands (watchdog bit 0).\n"
    "Exit status: 0 the servo answered (joint_known says whether the angle is known; a\n"
    "note on stderr says why not); 1 no reply or device error; 2 bad arguments.\n"
    "\n" CLI_BUS_COMMON_HELP;

enum {
    OPT_ID = 0,
    OPT_JOINT,
    OPT_KP,
    OPT_KD,
    OPT_POS,
    OPT_SPEED,
    OPT_TAU,
    OPT_SIDE,
    OPT_RATE,
    OPT_DURATION,
    OPT_WATCHDOG,
    OPT_KEEP,
    OPT_ARRIVE,
    OPT_RANGE,
    OPT_THEN
};

typedef struct {
    long long id;
    const char *joint;
} id_ctx_t;

static int parse_id_opt(void *ctx, int key, const char *v)
{
    id_ctx_t *c = ctx;
    if (key == OPT_ID) {
        return cli_parse_int("--id", v, 0, J288_MAX_ID, &c->id);
    }
    if (key == OPT_JOINT) {
        c->joint = v;
        return 0;
    }
    return 1;
}


/* --config and --id / --joint into a joint's configuration (o filled from the file). */
static int select_joint(cli_bus_opts_t *o, const char *joint_name, long long id,
                        cli_joint_sel_t *sel)
{
    if (cli_robot_load(&g_robot, o->config) != 0 ||
        cli_joint_select(&g_robot, joint_name, id, o, sel) != 0) {
        return -1;
    }
    return 0;
}

static void status_text(const cli_bus_t *b, const cli_joint_sel_t *sel, const j288_joint_t *j,
                        const j288_txn_t *txn)
{
    const j288_joint_state_t *st = j288_joint_state(j);
    char title[200];
    snprintf(title, sizeof title, "servo %u on %s: reply after %lu us", (unsigned)sel->id, b->dev,
             (unsigned long)txn->latency_us);
    cli_show_reply(stdout, &txn->reply, title);
    if (st->known) {
        printf("  %s: pos %.6f rad (%s), speed %.5g rad/s, torque %.5g N*m%s\n", sel->name,
               (double)st->pos, st->calibrated ? "calibrated" : "from the output encoder",
               (double)st->speed, (double)st->torque,
               st->beyond_limit ? "; outside its limits" : "");
    } else {
        printf("  %s: angle unknown\n", sel->name);
    }
}

int cli_cmd_status(int argc, char **argv, const cli_global_t *g)
{
    static const cli_opt_t opts[] = {
        {"--id", true, OPT_ID}, {"--joint", true, OPT_JOINT}, CLI_BUS_COMMON_OPTS, {NULL, false, 0}};
    cli_bus_opts_t o;
    cli_bus_t b;
    id_ctx_t c = {-1, NULL};
    cli_joint_sel_t sel;
    const j288_joint_t *joint = NULL;
    j288_txn_t txn;
    unsigned replies = 0;
    int ec;

    cli_bus_opts_init(&o, g);
    if (cli_parse_bus_args(argc, argv, opts, status_help, &o, parse_id_opt, &c, &ec) != 0) {
        return ec;
    }
    if (select_joint(&o, c.joint, c.id, &sel) != 0) {
        return CLI_EXIT_USAGE;
    }
    cli_signals_install();
    if ((ec = cli_bus_open(&b, &o, 2)) != CLI_EXIT_OK) {
        return ec;
    }
    ec = cli_joint_start(&b, &sel.jc, sel.name, &joint, &txn, &replies, false);
    if (replies == 0u || (ec != CLI_EXIT_OK && ec != CLI_EXIT_FAIL)) {
        cli_bus_close(&b);
        return ec != CLI_EXIT_OK ? ec : CLI_EXIT_FAIL;
    }
    if (ec != CLI_EXIT_OK) {
        char why[400];
        cli_joint_why_unknown(joint, sel.name, replies, why, sizeof why);
        fprintf(stderr, "note: %s\n", why);
    }
    if (o.json) {
        cli_json_t j;
        cli_json_init(&j, stdout);
        cli_json_begin_object(&j, NULL);
        cli_json_reply_members(&j, &txn.reply);
        cli_json_uint(&j, "latency_us", txn.latency_us);
        if (sel.rj != NULL) {
            cli_json_str(&j, "joint", sel.rj->name);
        }
        cli_json_joint_members(&j, joint);
        cli_json_end_object(&j);
        cli_json_newline(&j);
    } else {
        status_text(&b, &sel, joint, &txn);
    }
    cli_bus_close(&b);
    return CLI_EXIT_OK;
}

/* ---- stop ----------------------------------------------------------------------------------- */

static const char stop_help[] =
    "usage: j288 [--port DEV] stop [--id N | --joint NAME --config FILE]\n"
    "\n"
    "Lock (no torque) servo N, confirmed by its reply; without --id or --joint, broadcast\n"
    "lock to every servo on the bus (id 15: nobody replies). The lock goes out with the\n"
    "watchdog bit 0.\n"
    "Exit status: 0 sent (and confirmed with --id); 1 no reply or device error.\n"
    "\n" CLI_BUS_COMMON_HELP;

int cli_cmd_stop(int argc, char **argv, const cli_global_t *g)
{
    static const cli_opt_t opts[] = {
        {"--id", true, OPT_ID}, {"--joint", true, OPT_JOINT}, CLI_BUS_COMMON_OPTS, {NULL, false, 0}};
    cli_bus_opts_t o;
    cli_bus_t b;
    id_ctx_t c = {-1, NULL};
    j288_cmd_raw_t cmd;
    j288_txn_t txn;
    int ec, rc;

    cli_bus_opts_init(&o, g);
    if (cli_parse_bus_args(argc, argv, opts, stop_help, &o, parse_id_opt, &c, &ec) != 0) {
        return ec;
    }
    if (cli_robot_load(&g_robot, o.config) != 0) {
        return CLI_EXIT_USAGE;
    }
    if (c.joint != NULL || (c.id >= 0 && o.config != NULL)) {
        cli_joint_sel_t sel;
        if (cli_joint_select(&g_robot, c.joint, c.id, &o, &sel) != 0) {
            return CLI_EXIT_USAGE;
        }
        c.id = sel.id;
    } else {
        cli_robot_fill_bus(&g_robot, NULL, &o);
    }
    if ((ec = cli_bus_open(&b, &o, 2)) != CLI_EXIT_OK) {
        return ec;
    }
    cli_lock_cmd(c.id < 0 ? (uint8_t)J288_BROADCAST_ID : (uint8_t)c.id, &cmd);
    /* All: the runner's stop, the one every front end uses (broadcast lock, watchdog bit 0). */
    rc = c.id < 0 ? j288_robot_stop(b.robot) : cli_bus_transfer(&b, &cmd, &txn);
    if (rc != J288_OK) {
        cli_report_txn_failure(&b, cmd.id, rc);
        cli_bus_close(&b);
        return CLI_EXIT_FAIL;
    }
    if (o.json) {
        printf("{\"stopped\": %s, \"confirmed\": %s}\n", c.id < 0 ? "\"all\"" : "\"one\"",
               c.id < 0 ? "false" : "true");
    } else if (c.id < 0) {
        printf("lock broadcast to every servo on %s\n", b.dev);
    } else {
        printf("servo %u locked (mode %s)\n", (unsigned)c.id, cli_mode_name(txn.reply.status));
    }
    cli_bus_close(&b);
    return CLI_EXIT_OK;
}

/* ---- hold, move, torque: a refresh loop --------------------------------------------------------
 */

typedef enum { DRIVE_HOLD, DRIVE_MOVE, DRIVE_TORQUE } drive_kind_t;
/* How a drive that ends normally (--duration, --arrive, the move done) leaves the servo: a
 * signal or a failure always locks. */
typedef enum { THEN_LOCK = 0, THEN_HOLD = 1, THEN_KEEP } drive_then_t;
enum { SIDE_ROTOR = 0, SIDE_OUTPUT = 1, SIDE_JOINT = 2 };

typedef struct {
    drive_kind_t kind;
    long long id;
    const char *joint_name;
    int side; /* SIDE_*: joint (default), or the raw rotor frame, or rotor / N */
    bool have_kp, have_kd, have_pos, have_speed, have_tau;
    double kp, kd, pos, speed, tau;
    double rate_hz;
    double duration_s; /* < 0: until a signal */
    bool watchdog;
    bool keep;
    bool have_then;
    drive_then_t then; /* move: THEN_HOLD by default; hold, torque: THEN_LOCK */
    double arrive; /* move --arrive: the tolerance in rad (on the move's side); < 0: none */
    /* The joint (side joint): the runner's, once started (cli_joint_start()) */
    cli_joint_sel_t sel;
    const j288_joint_t *j;
} drive_args_t;

static int parse_drive_opt(void *ctx, int key, const char *v)
{
    static const char *const sides[] = {"rotor", "output", "joint", NULL};
    static const char *const onoff[] = {"off", "on", NULL};
    drive_args_t *d = ctx;
    int choice;
    switch (key) {
    case OPT_ID:
        return cli_parse_int("--id", v, 0, J288_MAX_ID, &d->id);
    case OPT_JOINT:
        d->joint_name = v;
        return 0;
    case OPT_KP:
        d->have_kp = true;
        return cli_parse_real("--kp", v, &d->kp);
    case OPT_KD:
        d->have_kd = true;
        return cli_parse_real("--kd", v, &d->kd);
    case OPT_POS:
        d->have_pos = true;
        return cli_parse_real("--pos", v, &d->pos);
    case OPT_SPEED:
        d->have_speed = true;
        if (cli_parse_real("--speed", v, &d->speed) != 0) {
            return -1;
        }
        /* A ramp speed, not a velocity: the direction comes from --pos. */
        if (d->speed <= 0.0) {
            cli_error("--speed: %s is not above 0 (the ramp speed; --pos sets the direction)", v);
            return -1;
        }
        return 0;
    case OPT_TAU:
        d->have_tau = true;
        return cli_parse_real("--tau", v, &d->tau);
    case OPT_SIDE:
        for (choice = 0; sides[choice] != NULL; choice++) {
            if (strcmp(v, sides[choice]) == 0) {
                d->side = choice;
                return 0;
            }
        }
        cli_error("--side: '%s' is not joint, rotor or output", v);
        return -1;
    case OPT_RATE:
        if (cli_parse_real("--rate", v, &d->rate_hz) != 0) {
            return -1;
        }
        if (d->rate_hz < 1.0 || d->rate_hz > 5000.0) {
            cli_error("--rate: %s is out of range 1..5000 Hz", v);
            return -1;
        }
        return 0;
    case OPT_DURATION:
        if (cli_parse_real("--duration", v, &d->duration_s) != 0) {
            return -1;
        }
        if (d->duration_s < 0.0 || d->duration_s > 86400.0) {
            cli_error("--duration: %s is out of range 0..86400 s", v);
            return -1;
        }
        return 0;
    case OPT_WATCHDOG:
        if (cli_parse_choice("--watchdog", v, onoff, &choice) != 0) {
            return -1;
        }
        d->watchdog = choice == 1;
        return 0;
    case OPT_KEEP:
        d->keep = true;
        return 0;
    case OPT_THEN: {
        static const char *const ends[] = {"lock", "hold", NULL};
        if (cli_parse_choice("--then", v, ends, &choice) != 0) {
            return -1;
        }
        d->have_then = true;
        d->then = choice == 1 ? THEN_HOLD : THEN_LOCK;
        return 0;
    }
    case OPT_ARRIVE:
        if (cli_parse_real("--arrive", v, &d->arrive) != 0) {
            return -1;
        }
        if (!(d->arrive > 0.0 && d->arrive <= 1.0)) {
            cli_error("--arrive: %s is out of range (0, 1] rad", v);
            return -1;
        }
        return 0;
    default:
        return 1;
    }
}

/* Gains and fields, validated and converted once. */
typedef struct {
    j288_cmd_raw_t base;   /* id, FOC, watchdog, gains, tau */
    int32_t start_pos;     /* rotor raw, from the first reply */
    int32_t target_pos;    /* rotor raw */
    double ramp_lsb_per_s; /* move: setpoint speed in position LSB per second */
    int16_t ramp_speed_raw;
    double ramp_time_s;
    /* side joint: joint-frame values */
    double q0;             /* the joint angle at the start */
    double jkp, jkd;       /* gains */
    double jspeed;         /* move: ramp speed, rad/s */
} drive_plan_t;

static j288_side_t side_of(const drive_args_t *d)
{
    return d->side == SIDE_ROTOR ? J288_SIDE_ROTOR : J288_SIDE_OUTPUT;
}

static int si_error(const char *opt, double v, int rc)
{
    if (rc == J288_ERR_NEG_GAIN) {
        cli_error("%s: %g is negative; gains must be >= 0", opt, v);
    } else {
        cli_error("%s: %g is out of range for the wire (%s)", opt, v, j288_strerror(rc));
    }
    return -1;
}

/* Joint side: gains from the command line, else the config, else the defaults; targets
 * checked against the joint's limits before anything is sent. */
static int plan_joint(const drive_args_t *d, drive_plan_t *p)
{
    const j288_joint_config_t *jc = &d->sel.jc;
    j288_cmd_raw_t probe;
    int rc;
    cli_joint_gains(d->sel.rj, d->have_kp, d->kp, d->have_kd, d->kd, &p->jkp, &p->jkd);
    p->jspeed = d->have_speed ? d->speed : DEFAULT_MOVE_SPEED_OUTPUT;
    if (d->kind == DRIVE_TORQUE) {
        p->jkp = 0.0;
        p->jkd = 0.0;
    }
    if ((rc = j288_kp_to_raw((j288_real_t)p->jkp, J288_SIDE_OUTPUT, &probe.kp)) != J288_OK) {
        return si_error("--kp", p->jkp, rc);
    }
    if ((rc = j288_kd_to_raw((j288_real_t)p->jkd, J288_SIDE_OUTPUT, &probe.kd)) != J288_OK) {
        return si_error("--kd", p->jkd, rc);
    }
    if (d->kind == DRIVE_MOVE && !cli_joint_pos_allowed(jc, d->pos)) {
        cli_joint_target_error(jc, d->sel.name, "--pos", d->pos, J288_ERR_LIMIT_POS);
        return -1;
    }
    if (d->kind == DRIVE_MOVE) {
        int16_t speed; /* the ramp's feed-forward: within the wire's range, checked now */
        if ((rc = j288_speed_to_raw((j288_real_t)p->jspeed, J288_SIDE_OUTPUT, &speed)) != J288_OK) {
            return si_error("--speed", p->jspeed, rc);
        }
    }
    if (d->kind == DRIVE_MOVE && jc->max_speed > 0 && !jc->clamp && p->jspeed > (double)jc->max_speed) {
        cli_joint_target_error(jc, d->sel.name, "--speed", p->jspeed, J288_ERR_LIMIT_SPEED);
        return -1;
    }
    if (d->kind == DRIVE_TORQUE) {
        int16_t tau;
        if (jc->max_torque > 0 && !jc->clamp && fabs(d->tau) > (double)jc->max_torque) {
            cli_joint_target_error(jc, d->sel.name, "--tau", d->tau, J288_ERR_LIMIT_TORQUE);
            return -1;
        }
        if ((rc = j288_torque_to_raw((j288_real_t)d->tau, J288_SIDE_OUTPUT, &tau)) != J288_OK) {
            return si_error("--tau", d->tau, rc);
        }
    }
    return 0;
}

/* Everything that can be checked before touching the bus. */
static int plan_fields(const drive_args_t *d, drive_plan_t *p)
{
    j288_side_t side = side_of(d);
    int rc;
    memset(p, 0, sizeof *p);
    p->base.id = (uint8_t)d->id;
    p->base.status = J288_MODE_FOC;
    p->base.watchdog = d->watchdog;
    if (d->side == SIDE_JOINT && d->kind == DRIVE_TORQUE && d->keep && !d->sel.jc.continuous) {
        /* The limit law runs in the host: a torque left in force after exit would carry the
         * joint through its limits (for up to 1 s with the watchdog on, for good without). */
        cli_error("%s: --keep: a torque left in force after exit has nothing to stop it at the "
                  "joint's limits [%g, %g]; nothing sent",
                  d->sel.name, (double)d->sel.jc.pos_min, (double)d->sel.jc.pos_max);
        return -1;
    }
    if (d->side == SIDE_JOINT) {
        return plan_joint(d, p);
    }
    if (d->sel.rj != NULL && d->sel.rj->has_limits) {
        /* The rotor and output frames count from power-up: a target there cannot be held to
         * the joint's limits, so a joint that has limits is driven in its own frame (a torque
         * too: the joint frame stops it at its limits). */
        cli_error("%s: --side %s would bypass its limits [%g, %g]; drive it in the joint frame "
                  "(the default); nothing sent",
                  d->sel.name, d->side == SIDE_ROTOR ? "rotor" : "output",
                  (double)d->sel.jc.pos_min, (double)d->sel.jc.pos_max);
        return -1;
    }
    if (d->kind != DRIVE_TORQUE) {
        double kp = d->have_kp ? d->kp : J288_ROBOT_DEFAULT_KP; /* output side */
        double kd = d->have_kd ? d->kd : J288_ROBOT_DEFAULT_KD;
        j288_side_t gain_side = d->have_kp ? side : J288_SIDE_OUTPUT;
        rc = j288_kp_to_raw((j288_real_t)kp, gain_side, &p->base.kp);
        if (rc != J288_OK) {
            return si_error("--kp", kp, rc);
        }
        gain_side = d->have_kd ? side : J288_SIDE_OUTPUT;
        rc = j288_kd_to_raw((j288_real_t)kd, gain_side, &p->base.kd);
        if (rc != J288_OK) {
            return si_error("--kd", kd, rc);
        }
    }
    if (d->kind == DRIVE_TORQUE) {
        rc = j288_torque_to_raw((j288_real_t)d->tau, side, &p->base.tau);
        if (rc != J288_OK) {
            return si_error("--tau", d->tau, rc);
        }
    }
    if (d->kind == DRIVE_MOVE) {
        double v = d->have_speed
                       ? d->speed
                       : (side == J288_SIDE_OUTPUT ? DEFAULT_MOVE_SPEED_OUTPUT
                                                   : DEFAULT_MOVE_SPEED_OUTPUT * J288_GEAR_RATIO);
        rc = j288_pos_to_raw((j288_real_t)d->pos, side, &p->target_pos);
        if (rc != J288_OK) {
            return si_error("--pos", d->pos, rc);
        }
        rc = j288_speed_to_raw((j288_real_t)v, side, &p->ramp_speed_raw);
        if (rc != J288_OK) {
            return si_error("--speed", v, rc);
        }
        p->ramp_lsb_per_s = v * J288_SCALE_POS * (side == J288_SIDE_OUTPUT ? J288_GEAR_RATIO : 1.0);
    }
    return 0;
}

/* The command at time t since the start (rotor and output sides). */
static void drive_setpoint(const drive_args_t *d, const drive_plan_t *p, double t,
                           j288_cmd_raw_t *cmd)
{
    *cmd = p->base;
    if (d->kind == DRIVE_HOLD) {
        cmd->pos = p->start_pos;
    } else if (d->kind == DRIVE_MOVE) {
        double dist = (double)p->target_pos - (double)p->start_pos;
        double travelled = p->ramp_lsb_per_s * t;
        if (travelled >= fabs(dist)) {
            cmd->pos = p->target_pos;
            cmd->speed = 0;
        } else {
            double sp = (double)p->start_pos + (dist < 0.0 ? -travelled : travelled);
            cmd->pos = (int32_t)lround(sp);
            cmd->speed = (int16_t)(dist < 0.0 ? -p->ramp_speed_raw : p->ramp_speed_raw);
        }
    }
}

/* The joint-frame target at time t since the start (side joint). */
static void joint_setpoint(const drive_args_t *d, const drive_plan_t *p, double t,
                           j288_joint_target_t *tg)
{
    const j288_joint_state_t *st = j288_joint_state(d->j);
    memset(tg, 0, sizeof *tg);
    tg->kp = (j288_real_t)p->jkp;
    tg->kd = (j288_real_t)p->jkd;
    tg->pos = (j288_real_t)p->q0;
    if (d->kind == DRIVE_MOVE) {
        double dist = d->pos - p->q0;
        double travelled = p->jspeed * t;
        if (travelled >= fabs(dist)) {
            tg->pos = (j288_real_t)d->pos;
        } else {
            tg->pos = (j288_real_t)(p->q0 + (dist < 0.0 ? -travelled : travelled));
            tg->speed = (j288_real_t)(dist < 0.0 ? -p->jspeed : p->jspeed);
        }
    } else if (d->kind == DRIVE_TORQUE) {
        /* No stiffness: the position only has to pass the limit check. */
        double q = (double)st->pos;
        tg->pos = (j288_real_t)cli_joint_nearest_inside(j288_joint_config(d->j), q);
        tg->torque = (j288_real_t)d->tau;
    }
}

typedef struct {
    uint32_t sent, ok, failed, overruns;
    const j288_robot_t *robot; /* for the loop's timing */
    j288_reply_raw_t last;
    bool have_last;
    j288_cmd_raw_t last_cmd;
    double last_target; /* side joint: the latest target position */
    bool reached;       /* move: the ramp got to --pos */
    bool arrived;       /* move --arrive: reached, and the servo within the tolerance */
    bool holding;       /* --then hold: the last hold went out (watchdog bit 0), confirmed */
    double hold_pos;    /* where, rad on the drive's side */
    bool progress;      /* a progress line is on the terminal */
    double shown_s;     /* when it was last redrawn */
} drive_result_t;

#define PROGRESS_EVERY_S 0.2

/* On a terminal (stderr), one line redrawn in place: how long, where the servo is, the
 * target. Quiet when stderr is not a terminal (scripts, logs). */
static void drive_progress(const drive_args_t *d, drive_result_t *r, double t)
{
    static const char *const verb[] = {"hold", "move", "torque"};
    if (!isatty(STDERR_FILENO) || t - r->shown_s < PROGRESS_EVERY_S || !r->have_last) {
        return;
    }
    r->shown_s = t;
    r->progress = true;
    if (d->side == SIDE_JOINT) {
        const j288_joint_state_t *st = j288_joint_state(d->j);
        fprintf(stderr, "\r%s %s: %6.1f s  pos %9.4f rad  target %9.4f rad  torque %7.3f N*m ",
                verb[d->kind], d->sel.name, t, (double)st->pos, r->last_target,
                (double)st->torque);
    } else {
        fprintf(stderr, "\r%s servo %lld: %6.1f s  %lu replies  %lu failed ", verb[d->kind],
                d->id, t, (unsigned long)r->ok, (unsigned long)r->failed);
    }
    fflush(stderr);
}

/* End the progress line before anything else is printed. */
static void drive_progress_end(drive_result_t *r)
{
    if (r->progress) {
        fputc('\n', stderr);
        r->progress = false;
    }
}

static void drive_report_json(const drive_args_t *d, const drive_result_t *r, const char *how)
{
    j288_side_t side = side_of(d);
    cli_json_t j;
    cli_json_init(&j, stdout);
    cli_json_begin_object(&j, NULL);
    cli_json_str(&j, "ended", how);
    cli_json_int(&j, "id", d->id);
    if (d->sel.rj != NULL) {
        cli_json_str(&j, "joint", d->sel.rj->name);
    }
    cli_json_uint(&j, "commands", r->sent);
    cli_json_uint(&j, "replies", r->ok);
    cli_json_uint(&j, "failures", r->failed);
    cli_json_uint(&j, "overruns", r->overruns);
    cli_json_timing(&j, r->robot);
    cli_json_bool(&j, "locked", !r->holding && (d->then != THEN_KEEP || cli_stop_signal != 0));
    cli_json_bool(&j, "holding", r->holding);
    if (r->holding) {
        cli_json_real(&j, "hold_pos", r->hold_pos);
    }
    if (d->side == SIDE_JOINT) {
        cli_json_str(&j, "side", "joint");
        cli_json_real(&j, "target_pos", r->last_target);
        cli_json_joint_members(&j, d->j);
    } else {
        cli_json_str(&j, "side", side == J288_SIDE_ROTOR ? "rotor" : "output");
        cli_json_real(&j, "target_pos", (double)j288_pos_from_raw(r->last_cmd.pos, side));
    }
    if (r->have_last) {
        cli_json_begin_object(&j, "last_reply");
        cli_json_reply_members(&j, &r->last);
        cli_json_end_object(&j);
    }
    cli_json_end_object(&j);
    cli_json_newline(&j);
}

/* What the servo does now that the command has ended, for the summary line. */
static const char *drive_end_text(const drive_args_t *d, const drive_result_t *r, char *buf,
                                  size_t len)
{
    if (r->holding) {
        (void)snprintf(buf, len,
                       "holding at %.6g rad with the watchdog off: the servo keeps holding after "
                       "exit (`j288 stop --id %lld` releases it)",
                       r->hold_pos, d->id);
        return buf;
    }
    return (d->then == THEN_KEEP && cli_stop_signal == 0) ? "last command left in force (--keep)"
                                                          : "servo locked";
}

static void drive_report(const drive_args_t *d, const drive_result_t *r, const char *how,
                         bool json)
{
    j288_side_t side = side_of(d);
    char list[512], end[200];
    if (json) {
        drive_report_json(d, r, how);
        return;
    }
    if (r->have_last && d->side == SIDE_JOINT) {
        const j288_joint_state_t *st = j288_joint_state(d->j);
        printf("%s: pos %.6g rad, speed %.5g rad/s, torque %.5g N*m (joint frame); target "
               "%.6g rad; faults %s\n",
               d->sel.name, (double)st->pos, (double)st->speed, (double)st->torque,
               r->last_target, cli_fault_list(r->last.faults, list, sizeof list));
    } else if (r->have_last) {
        printf("servo %lld: pos %.5g rad, speed %.5g rad/s, torque %.5g N*m (%s side); "
               "target %.5g rad; faults %s\n",
               d->id, (double)j288_pos_from_raw(r->last.pos, side),
               (double)j288_speed_from_raw(r->last.speed, side),
               (double)j288_torque_from_raw(r->last.torque, side),
               side == J288_SIDE_ROTOR ? "rotor" : "output",
               (double)j288_pos_from_raw(r->last_cmd.pos, side),
               cli_fault_list(r->last.faults, list, sizeof list));
    }
    printf("%s: %lu commands, %lu replies, %lu failed, %lu late cycles; %s\n", how,
           (unsigned long)r->sent, (unsigned long)r->ok, (unsigned long)r->failed,
           (unsigned long)r->overruns,
           drive_end_text(d, r, end, sizeof end));
    cli_print_timing(stdout, r->robot);
}

typedef enum {
    DRIVE_END_DONE,   /* --duration reached, or the move arrived (--arrive) */
    DRIVE_END_SIGNAL, /* SIGINT or SIGTERM */
    DRIVE_END_GONE,   /* the device went away: nothing can be sent any more */
    DRIVE_END_SILENT, /* the servo stopped answering: lock already sent */
    DRIVE_END_JOINT   /* the joint angle was lost or a target refused: lock already sent */
} drive_end_t;

/* The options each command requires. */
static int drive_check(drive_args_t *d)
{
    if (d->kind == DRIVE_MOVE && !d->have_pos) {
        cli_error("--pos is required");
        return -1;
    }
    if (d->kind == DRIVE_TORQUE && !d->have_tau) {
        cli_error("--tau is required");
        return -1;
    }
    if (d->keep && d->have_then) {
        cli_error("--keep and --then exclude each other");
        return -1;
    }
    /* A torque left in force once the tool has gone has nothing to stop it at the joint's
     * limits (they live in the host), and a position hold would be a command torque never
     * sent: a torque ends locked. */
    if (d->kind == DRIVE_TORQUE && d->then == THEN_HOLD) {
        cli_error("--then hold: torque ends with lock (a torque left running after exit has "
                  "no limits to stop it; hold the joint with `j288 hold --then hold`)");
        return -1;
    }
    if (d->keep) {
        d->then = THEN_KEEP;
    }
    return 0;
}

/* Where is the servo now? (Locks: the protocol has no read-only query.) */
static int drive_start(cli_bus_t *b, drive_args_t *d, drive_plan_t *p, drive_result_t *res)
{
    j288_cmd_raw_t cmd;
    j288_txn_t txn;
    unsigned replies = 0;
    int rc;
    if (d->side == SIDE_JOINT) {
        rc = cli_joint_start(b, &d->sel.jc, d->sel.name, &d->j, &txn, &replies, true);
        if (rc != CLI_EXIT_OK) {
            return rc;
        }
        p->q0 = (double)j288_joint_state(d->j)->pos;
        /* Just beyond a limit (a zero at a hard stop, a load): start from the limit, so the
         * joint can be brought back; the lib refuses any target outside. */
        if (d->kind != DRIVE_TORQUE && cli_joint_start_inside(&d->sel.jc, d->sel.name, p->q0, &p->q0) != 0) {
            return CLI_EXIT_USAGE;
        }
        res->last_target = p->q0;
    } else {
        cli_lock_cmd((uint8_t)d->id, &cmd);
        rc = cli_bus_transfer(b, &cmd, &txn);
        if (rc != J288_OK) {
            cli_report_txn_failure(b, (uint8_t)d->id, rc);
            return CLI_EXIT_FAIL;
        }
    }
    p->start_pos = txn.reply.pos;
    res->last = txn.reply;
    res->have_last = true;
    return CLI_EXIT_OK;
}

/* Side joint: the command at time t from the joint layer. Returns 0, or -1 after an error
 * line (refused: nothing is sent). */
static int joint_command_at(drive_args_t *d, const drive_plan_t *p, double t,
                            drive_result_t *res, j288_cmd_raw_t *cmd)
{
    j288_joint_target_t tg;
    int rc;
    joint_setpoint(d, p, t, &tg);
    rc = j288_joint_command(d->j, &tg, cmd, NULL);
    if (rc != J288_OK) {
        drive_progress_end(res);
        cli_joint_target_error(&d->sel.jc, d->sel.name, "target", (double)tg.pos, rc);
        return -1;
    }
    cmd->watchdog = d->watchdog;
    res->last_target = (double)tg.pos;
    return 0;
}

/* --arrive: the servo within TOL rad of --pos and slower than TOL rad/s (settled, so that
 * the lock that follows does not leave it coasting), from the latest reply, on the move's
 * side. */
static bool drive_settled(const drive_args_t *d, const drive_plan_t *p, const drive_result_t *r)
{
    double err, speed;
    if (d->side == SIDE_JOINT) {
        const j288_joint_state_t *st = j288_joint_state(d->j);
        err = (double)st->pos - d->pos;
        speed = (double)st->speed;
    } else {
        err = (double)j288_pos_from_raw(r->last.pos, side_of(d)) -
              (double)j288_pos_from_raw(p->target_pos, side_of(d));
        speed = (double)j288_speed_from_raw(r->last.speed, side_of(d));
    }
    return fabs(err) <= d->arrive && fabs(speed) <= d->arrive;
}

/* One refresh: the command at time t, sent and counted. Returns the transfer's result, or
 * J288_ERR_ANGLE_UNKNOWN when the joint refused the target or lost its angle (reported). */
static int drive_step(cli_bus_t *b, drive_args_t *d, const drive_plan_t *p, double t,
                      drive_result_t *res)
{
    j288_cmd_raw_t cmd;
    j288_txn_t txn;
    int rc;
    if (d->side == SIDE_JOINT) {
        if (joint_command_at(d, p, t, res, &cmd) != 0) {
            return J288_ERR_ANGLE_UNKNOWN;
        }
        res->reached = res->last_target == d->pos;
    } else {
        drive_setpoint(d, p, t, &cmd);
        res->reached = cmd.pos == p->target_pos;
    }
    res->last_cmd = cmd;
    res->sent++;
    rc = cli_bus_transfer(b, &cmd, &txn);
    if (rc == J288_OK) {
        res->ok++;
        res->last = txn.reply;
        /* (the runner fed the reply to the joint: known before, unknown now is a lost angle) */
        if (d->side == SIDE_JOINT) {
            if (!j288_joint_state(d->j)->known) {
                drive_progress_end(res);
                cli_error("%s: the joint angle was lost (rotor and output encoder differ by %.4f "
                          "rad: a power cycle or a slipped gear); lock sent",
                          d->sel.name, (double)j288_joint_state(d->j)->residual);
                return J288_ERR_ANGLE_UNKNOWN;
            }
        }
        res->arrived = d->arrive > 0.0 && res->reached && drive_settled(d, p, res);
    } else if (rc != J288_ERR_OFFLINE) {
        res->failed++;
    }
    return rc;
}

/* Refresh the command at --rate until --duration or a stop signal; a late cycle never
 * bursts to catch up. Gives up when the device goes away or after FAILS_BEFORE_GIVING_UP
 * failures in a row (then sending lock). */
static drive_end_t drive_loop_run(cli_bus_t *b, drive_args_t *d, const drive_plan_t *p,
                              drive_result_t *res)
{
    uint32_t period_us = (uint32_t)lround(1e6 / d->rate_hz);
    uint32_t t0 = j288_robot_now_us();
    int fails = 0, rc;
    res->robot = b->robot;
    j288_robot_timing_reset(b->robot); /* the start's reads are not the loop's */
    (void)j288_robot_pace(b->robot, period_us); /* the schedule starts with the first step */
    for (;;) {
        j288_rt_report_t rep;
        double t = (double)(uint32_t)(j288_robot_now_us() - t0) / 1e6;
        if (cli_stop_signal != 0) {
            return DRIVE_END_SIGNAL;
        }
        if (d->duration_s >= 0.0 && t >= d->duration_s) {
            return DRIVE_END_DONE;
        }
        rc = drive_step(b, d, p, t, res);
        drive_progress(d, res, t);
        if (res->arrived) {
            return DRIVE_END_DONE;
        }
        if (rc == J288_ERR_OFFLINE) {
            drive_progress_end(res);
            cli_report_txn_failure(b, (uint8_t)d->id, rc);
            return DRIVE_END_GONE;
        }
        if (rc == J288_ERR_ANGLE_UNKNOWN) {
            (void)cli_bus_lock_driven(b);
            return DRIVE_END_JOINT;
        }
        fails = rc == J288_OK ? 0 : fails + 1;
        if (fails >= FAILS_BEFORE_GIVING_UP) {
            (void)cli_bus_lock_driven(b);
            drive_progress_end(res);
            cli_error("servo %lld stopped answering (%d commands in a row failed, last: %s); "
                      "lock sent",
                      d->id, fails, j288_strerror(rc));
            return DRIVE_END_SILENT;
        }
        rc = j288_robot_pace(b->robot, period_us);
        (void)j288_robot_timing(b->robot, &rep);
        res->overruns = rep.missed;
        if (rc == J288_ERR_OFFLINE) {
            drive_progress_end(res);
            cli_report_txn_failure(b, (uint8_t)d->id, J288_ERR_OFFLINE);
            return DRIVE_END_GONE;
        }
    }
}

/* The loop, its progress line ended before whatever comes next is printed. */
static drive_end_t drive_loop(cli_bus_t *b, drive_args_t *d, const drive_plan_t *p,
                              drive_result_t *res)
{
    drive_end_t end = drive_loop_run(b, d, p, res);
    drive_progress_end(res);
    return end;
}

/* The hold a drive ends with (--then hold): the last target it sent (--pos once the move got
 * there), speed 0, its gains, with the watchdog bit 0 so that the servo keeps it after the tool
 * has gone. Sent until confirmed (as a lock is); false when it was not (then the caller locks). */
#define HOLD_CONFIRM_ATTEMPTS 5
static bool drive_hold_after(cli_bus_t *b, drive_args_t *d, const drive_plan_t *p,
                             drive_result_t *res)
{
    j288_cmd_raw_t cmd = res->last_cmd;
    int attempt, rc = J288_ERR_TIMEOUT;
    if (res->sent == 0u) { /* --duration 0: nothing went out yet */
        drive_setpoint(d, p, 0.0, &cmd);
    }
    if (d->side == SIDE_JOINT) {
        j288_joint_target_t tg;
        memset(&tg, 0, sizeof tg);
        tg.pos = (j288_real_t)res->last_target;
        tg.kp = (j288_real_t)p->jkp;
        tg.kd = (j288_real_t)p->jkd;
        if (j288_joint_command(d->j, &tg, &cmd, NULL) != J288_OK) {
            return false;
        }
        res->hold_pos = res->last_target;
    } else {
        cmd.speed = 0;
        res->hold_pos = (double)j288_pos_from_raw(cmd.pos, side_of(d));
    }
    cmd.watchdog = false;
    for (attempt = 0; attempt < HOLD_CONFIRM_ATTEMPTS && rc != J288_OK; attempt++) {
        if (cli_stop_signal != 0) {
            return false;
        }
        rc = cli_bus_transfer(b, &cmd, NULL);
        if (rc == J288_ERR_OFFLINE) {
            return false;
        }
    }
    res->holding = rc == J288_OK;
    return res->holding;
}

/* After the loop: lock the servo, or (--then hold) leave it holding, or (--keep) leave its
 * last command; report. A signal locks whatever --then says. Returns the exit status. */
static int drive_finish(cli_bus_t *b, drive_args_t *d, const drive_plan_t *p,
                        drive_result_t *res, drive_end_t end, bool json)
{
    const char *left;
    if (end == DRIVE_END_GONE || end == DRIVE_END_SILENT || end == DRIVE_END_JOINT) {
        return CLI_EXIT_FAIL;
    }
    if (cli_stop_signal == 0 && d->then == THEN_HOLD && !drive_hold_after(b, d, p, res) &&
        cli_stop_signal == 0) {
        (void)cli_bus_lock_driven(b);
        cli_error("servo %lld did not confirm the hold at the end; lock sent", d->id);
        return CLI_EXIT_FAIL;
    }
    if (cli_stop_signal != 0 || d->then == THEN_LOCK) {
        res->holding = false;
        if (cli_bus_lock_driven(b) != 0) {
            cli_error("servo %lld did not confirm the lock (a broadcast lock was sent)", d->id);
            return cli_stop_signal != 0 ? cli_signal_exit_code() : CLI_EXIT_FAIL;
        }
    }
    left = res->holding ? "holding at the last target"
                        : (d->then == THEN_KEEP ? "last target left in force" : "servo locked");
    if (d->kind == DRIVE_MOVE && end == DRIVE_END_DONE &&
        !(d->arrive > 0.0 ? res->arrived : res->reached)) {
        /* --duration ended the move before --pos (or before the servo got there, with
         * --arrive): say so, and fail (a script must know). */
        drive_report(d, res, "cut short by --duration", json);
        cli_error("the move ended after --duration %g s before %s --pos %g (%s)", d->duration_s,
                  res->reached ? "the servo settled within --arrive of" : "reaching", d->pos,
                  left);
        return CLI_EXIT_FAIL;
    }
    drive_report(d, res, end == DRIVE_END_SIGNAL ? "stopped by signal" : "done", json);
    return cli_stop_signal != 0 ? cli_signal_exit_code() : CLI_EXIT_OK;
}

/* --config, --id / --joint: the servo and, on the joint side, its joint. */
static int drive_select(drive_args_t *d, cli_bus_opts_t *o)
{
    if (cli_robot_load(&g_robot, o->config) != 0 ||
        cli_joint_select(&g_robot, d->joint_name, d->id, o, &d->sel) != 0) {
        return -1;
    }
    d->id = d->sel.id;
    return 0;
}

static int run_drive(drive_args_t *d, cli_bus_opts_t *o)
{
    cli_bus_t b;
    drive_plan_t plan;
    drive_result_t res;
    int ec;

    if (drive_check(d) != 0 || drive_select(d, o) != 0 || plan_fields(d, &plan) != 0) {
        return CLI_EXIT_USAGE;
    }
    cli_signals_install();
    if ((ec = cli_bus_open(&b, o, 1)) != CLI_EXIT_OK) {
        return ec;
    }
    memset(&res, 0, sizeof res);
    if ((ec = drive_start(&b, d, &plan, &res)) == CLI_EXIT_OK) {
        ec = drive_finish(&b, d, &plan, &res, drive_loop(&b, d, &plan, &res), o->json);
    }
    if ((d->then == THEN_KEEP || res.holding) && cli_stop_signal == 0) {
        cli_bus_close_keep(&b); /* --keep, --then hold: the last command stays in force */
    } else {
        cli_bus_close(&b);
    }
    return ec;
}

#define DRIVE_COMMON_HELP                                                                          \
    "  --rate HZ        command refresh rate, default 200\n"                                       \
    "  --duration S     stop after S seconds; default: run until Ctrl-C or SIGTERM\n"              \
    "  --watchdog W     on (default): the servo locks itself if commands stop for 1 s\n"           \
    "  --keep           leave the last command in force at the end (the watchdog on: the\n"       \
    "                   servo locks itself 1 s later); excludes --then\n"                         \
    "  --side S         joint (default): the absolute joint frame (output encoder angle\n"         \
    "                   wrapped to [-pi, pi), or the --config joint's zero, direction,\n"          \
    "                   limits and gains); rotor: the raw rotor frame; output: rotor / N,\n"       \
    "                   counted from wherever the rotor started at power-up (no limits)\n"         \
    "  --id N           the servo; or --joint NAME with --config FILE\n"                           \
    "On the joint side a torque toward a limit becomes a hold at the limit before the joint\n"   \
    "gets there (the limit law, docs/joint.md); --id alone has the limits [-pi, pi]: a servo\n"  \
    "that turns on takes --side output, or a --config joint with continuous: true. A --config\n" \
    "joint that has limits is driven on the joint side only.\n"                                   \
    "A target outside the joint's limits is refused before anything is sent (exit 2),\n"          \
    "unless the joint is configured to clamp. A joint found up to 0.05 rad beyond its\n"          \
    "limits starts from the nearest one (it is pulled in); farther out it is refused (exit 2).\n" \
    "The joint angle is watched: if it is lost (power cycle, slipped gear) the servo is\n"       \
    "locked and the command fails.\n"                                                             \
    "Ctrl-C, SIGTERM, SIGHUP or SIGQUIT (an abort), or a failure: lock, whatever --then says\n"  \
    "(exit 130, 143, 129, 131).\n"                                                                \
    "Exit status: 0 done; 1 no reply, servo stopped answering, joint angle unknown or lost,\n"     \
    "or device error; 2 bad arguments or a target outside the limits.\n"                         \
    "\n" CLI_BUS_RT_HELP

#define DRIVE_OPTS                                                                                 \
    {"--id", true, OPT_ID}, {"--joint", true, OPT_JOINT}, {"--side", true, OPT_SIDE},              \
        {"--rate", true, OPT_RATE}, {"--duration", true, OPT_DURATION},                            \
        {"--watchdog", true, OPT_WATCHDOG}, {"--keep", false, OPT_KEEP},                          \
        {"--then", true, OPT_THEN}, CLI_BUS_RT_OPTS,                                               \
        CLI_BUS_COMMON_OPTS

static void drive_args_init(drive_args_t *d, drive_kind_t kind)
{
    memset(d, 0, sizeof *d);
    d->kind = kind;
    d->id = -1;
    d->side = SIDE_JOINT;
    d->rate_hz = DEFAULT_RATE_HZ;
    d->duration_s = -1.0;
    d->watchdog = true;
    d->arrive = -1.0;
    d->then = kind == DRIVE_MOVE ? THEN_HOLD : THEN_LOCK;
}

static const char hold_help[] =
    "usage: j288 [--port DEV] hold (--id N | --joint NAME --config FILE) [--kp NM_RAD]\n"
    "                 [--kd NMS_RAD] [options]\n"
    "\n"
    "Hold servo N at the position it is at now (FOC, stiffness kp, damping kd), refreshing\n"
    "the command at --rate. Default gains (joint or output side): the config's kp and kd,\n"
    "else kp 20 N*m/rad, kd 2.5 N*m*s/rad.\n"
    "  --then lock|hold at the end of --duration: lock (the default: no torque, the servo\n"
    "                   limp after exit), or hold: one last hold at the same position with\n"
    "                   the servo's watchdog off, which the servo keeps after j288 exits\n"
    "                   (under a load too) until `j288 stop` or another command\n"
    DRIVE_COMMON_HELP "\n" CLI_BUS_COMMON_HELP;

int cli_cmd_hold(int argc, char **argv, const cli_global_t *g)
{
    static const cli_opt_t opts[] = {
        {"--kp", true, OPT_KP}, {"--kd", true, OPT_KD}, DRIVE_OPTS, {NULL, false, 0}};
    static drive_args_t d;
    cli_bus_opts_t o;
    int ec;
    drive_args_init(&d, DRIVE_HOLD);
    cli_bus_opts_init(&o, g);
    if (cli_parse_bus_args(argc, argv, opts, hold_help, &o, parse_drive_opt, &d, &ec) != 0) {
        return ec;
    }
    return run_drive(&d, &o);
}

static const char move_help[] =
    "usage: j288 [--port DEV] move (--id N | --joint NAME --config FILE) --pos RAD\n"
    "                 [--speed RAD_S] [--kp NM_RAD] [--kd NMS_RAD] [--side joint|rotor|output]\n"
    "                 [options]\n"
    "\n"
    "Move servo N from where it is to --pos along a ramp at --speed (default 1 rad/s on the\n"
    "joint or output side), then hold there. On the joint side (the default) --pos is the\n"
    "absolute joint angle: the move ends at joint angle RAD whatever the rotor did since\n"
    "power-up. Default gains: the config's kp and kd, else kp 20 N*m/rad, kd 2.5 N*m*s/rad.\n"
    "  --arrive TOL     end (done, exit 0) as soon as the ramp is at --pos and the servo\n"
    "                   has settled there: within TOL rad, slower than TOL rad/s (on the\n"
    "                   move's side; 0 < TOL <= 1); --duration then bounds the wait: not\n"
    "                   there by then, the move is cut short (exit 1)\n"
    "  --then hold|lock the end: hold (default) holds the target reached with the watchdog\n"
    "                   off, after exit too, until `j288 stop`; lock: no torque (loads fall)\n"
    DRIVE_COMMON_HELP "\n" CLI_BUS_COMMON_HELP;

int cli_cmd_move(int argc, char **argv, const cli_global_t *g)
{
    static const cli_opt_t opts[] = {{"--pos", true, OPT_POS},
                                     {"--speed", true, OPT_SPEED},
                                     {"--kp", true, OPT_KP},
                                     {"--kd", true, OPT_KD},
                                     {"--arrive", true, OPT_ARRIVE},
                                     DRIVE_OPTS,
                                     {NULL, false, 0}};
    static drive_args_t d;
    cli_bus_opts_t o;
    int ec;
    drive_args_init(&d, DRIVE_MOVE);
    cli_bus_opts_init(&o, g);
    if (cli_parse_bus_args(argc, argv, opts, move_help, &o, parse_drive_opt, &d, &ec) != 0) {
        return ec;
    }
    return run_drive(&d, &o);
}

static const char torque_help[] =
    "usage: j288 [--port DEV] torque (--id N | --joint NAME --config FILE) --tau NM\n"
    "                 [--side joint|rotor|output] [options]\n"
    "\n"
    "Apply a constant feed-forward torque (FOC, kp = kd = 0) to servo N; on the joint side\n"
    "in the joint's direction, refused beyond its max_torque. It ends with lock (--then\n"
    "lock only: a torque left running after exit has no limits to stop it; for the same\n"
    "reason --keep is refused on the joint side but for a continuous joint).\n"
    DRIVE_COMMON_HELP
    "\n" CLI_BUS_COMMON_HELP;

int cli_cmd_torque(int argc, char **argv, const cli_global_t *g)
{
    static const cli_opt_t opts[] = {{"--tau", true, OPT_TAU}, DRIVE_OPTS, {NULL, false, 0}};
    static drive_args_t d;
    cli_bus_opts_t o;
    int ec;
    drive_args_init(&d, DRIVE_TORQUE);
    cli_bus_opts_init(&o, g);
    if (cli_parse_bus_args(argc, argv, opts, torque_help, &o, parse_drive_opt, &d, &ec) != 0) {
        return ec;
    }
    return run_drive(&d, &o);
}
