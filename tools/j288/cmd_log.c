/* `j288 log`: run the cycle scheduler at a fixed rate, optionally drive a trajectory, and
 * write one CSV row per servo per cycle. */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <sys/prctl.h>

#include "cli_bus.h"
#include "frameview.h"
#include "json.h"

static const char log_help[] =
    "usage: j288 [--port DEV] log --id N[,M..] --rate HZ --duration S [--csv FILE]\n"
    "                [--hold | --swing AMP [--period S]] [--kp NM_RAD] [--kd NMS_RAD]\n"
    "                [--side output|rotor] [--json]\n"
    "\n"
    "Run the cycle scheduler: every 1/HZ seconds one sweep sends each listed servo its\n"
    "command and takes its reply. Without --hold or --swing each servo is sent lock\n"
    "(watchdog bit 0) and only observed.\n"
    "  --id LIST      servo ids 0-14, comma-separated (required)\n"
    "  --rate HZ      sweeps per second, 1..5000 (default 100)\n"
    "  --duration S   how long, seconds (default 1)\n"
    "  --csv FILE     one row per servo per cycle: time_s, id, ok (1 reply, 0 none),\n"
    "                 pos_rad, speed_rad_s, torque_nm (on --side), case_temp_c,\n"
    "                 winding_temp_c, voltage_v, faults, latency_us, pos_des_rad; a cycle\n"
    "                 without a reply leaves the measured columns empty\n"
    "  --hold         hold each servo where it starts (FOC, kp/kd)\n"
    "  --swing AMP    move each servo from where it starts through\n"
    "                 p0 + AMP (1 - cos(2 pi t / period)) / 2 and back, speed fed forward\n"
    "  --period S     period of the swing (default: --duration, one swing)\n"
    "  --kp, --kd     gains for --hold/--swing (default output side 20 N*m/rad, 2.5 N*m*s/rad)\n"
    "  --watchdog W   on (default when driving) or off\n"
    "  --side S       units of AMP, gains and CSV: output (default) or rotor\n"
    "Prints the achieved rate, missed deadlines (sweeps that ended after the next tick was\n"
    "due: that tick starts late; ticks a whole period behind are skipped, never bunched),\n"
    "bus statistics and, when driving, the tracking error. Ctrl-C or SIGTERM: every driven\n"
    "servo is sent lock before exiting (exit 130 / 143).\n"
    "Exit status: 0 done; 1 a servo never answered, device error; 2 bad arguments.\n"
    "\n" CLI_BUS_COMMON_HELP;

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
    OPT_WATCHDOG
};

typedef enum { MOTION_NONE, MOTION_HOLD, MOTION_SWING } motion_t;

typedef struct {
    uint32_t ids;
    double rate_hz, duration_s, amp, period_s, kp, kd;
    bool have_kp, have_kd, have_period;
    const char *csv;
    motion_t motion;
    int side;
    bool watchdog;
} log_args_t;

/* Per-servo running figures. */
typedef struct {
    int32_t p0;
    uint32_t replies, failures, seen_successes;
    double err_sq_sum, err_max;
    uint32_t err_n;
    double latency_sum;
    uint32_t latency_n, latency_max;
} servo_acc_t;

static int parse_positive(const char *opt, const char *v, double lo, double hi, double *out)
{
    if (cli_parse_real(opt, v, out) != 0) {
        return -1;
    }
    if (*out < lo || *out > hi) {
        cli_error("%s: %s is out of range %g..%g", opt, v, lo, hi);
        return -1;
    }
    return 0;
}

static int parse_log_opt(log_args_t *a, int key, const char *v)
{
    static const char *const sides[] = {"rotor", "output", NULL};
    static const char *const onoff[] = {"off", "on", NULL};
    int choice;
    switch (key) {
    case OPT_IDS:
        return cli_parse_id_list("--id", v, J288_MAX_ID, &a->ids);
    case OPT_RATE:
        return parse_positive("--rate", v, 1.0, 5000.0, &a->rate_hz);
    case OPT_DURATION:
        return parse_positive("--duration", v, 0.001, 86400.0, &a->duration_s);
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
        return parse_positive("--period", v, 0.01, 86400.0, &a->period_s);
    case OPT_KP:
        a->have_kp = true;
        return cli_parse_real("--kp", v, &a->kp);
    case OPT_KD:
        a->have_kd = true;
        return cli_parse_real("--kd", v, &a->kd);
    case OPT_SIDE:
        return cli_parse_choice("--side", v, sides, &a->side);
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
    if (a->ids == 0u) {
        cli_error("--id is required (e.g. --id 1,2,3)");
        *ec = CLI_EXIT_USAGE;
        return -1;
    }
    return 0;
}

/* The base command of a driven servo: FOC, gains, watchdog. */
static int base_command(const log_args_t *a, j288_cmd_raw_t *cmd)
{
    j288_side_t side = a->side == 0 ? J288_SIDE_ROTOR : J288_SIDE_OUTPUT;
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

/* Run one sweep to its end, even after a stop signal when ignore_stop is set. */
static int sweep(cli_bus_t *b, j288_sched_t *s, uint32_t timeout_us, bool ignore_stop)
{
    uint32_t now = j288_linux_now_us();
    int rc = j288_sched_start_sweep(s, now);
    if (rc != J288_OK) {
        return rc;
    }
    return j288_linux_run(&b->lp, s, now + timeout_us,
                          J288_LINUX_RUN_UNTIL_IDLE |
                              (ignore_stop ? J288_LINUX_RUN_IGNORE_STOP : 0u));
}

typedef struct {
    uint32_t cycles, missed, skipped, rows;
    double elapsed_s;
} run_stats_t;

static void print_summary(const log_args_t *a, cli_bus_t *b, const j288_sched_t *s,
                          const servo_acc_t *acc, const run_stats_t *rs, bool json)
{
    const j288_bus_stats_t *bs = j288_bus_stats(&b->bus);
    const j288_parser_stats_t *ps = j288_bus_parser_stats(&b->bus);
    const char *side_name = a->side == 0 ? "rotor" : "output";
    double achieved = rs->elapsed_s > 0.0 ? (double)rs->cycles / rs->elapsed_s : 0.0;
    uint8_t id;
    (void)s;
    if (json) {
        cli_json_t j;
        cli_json_init(&j, stdout);
        cli_json_begin_object(&j, NULL);
        cli_json_uint(&j, "cycles", rs->cycles);
        cli_json_real(&j, "elapsed_s", rs->elapsed_s);
        cli_json_real(&j, "rate_hz", a->rate_hz);
        cli_json_real(&j, "achieved_hz", achieved);
        cli_json_uint(&j, "missed_deadlines", rs->missed);
        cli_json_uint(&j, "skipped_ticks", rs->skipped);
        cli_json_uint(&j, "csv_rows", rs->rows);
        cli_json_begin_object(&j, "bus");
        cli_json_uint(&j, "transactions", bs->transactions);
        cli_json_uint(&j, "ok", bs->ok);
        cli_json_uint(&j, "timeouts", bs->timeouts);
        cli_json_uint(&j, "crc_errors", bs->crc_errors);
        cli_json_uint(&j, "wrong_id", bs->wrong_id);
        cli_json_uint(&j, "collisions", bs->collisions);
        cli_json_uint(&j, "line_errors", bs->line_errors);
        cli_json_uint(&j, "stale_bytes", bs->stale_bytes);
        cli_json_uint(&j, "garbage_bytes", ps->garbage_bytes);
        cli_json_end_object(&j);
        cli_json_begin_array(&j, "servos");
        for (id = 0; id <= J288_MAX_ID; id++) {
            const servo_acc_t *x = &acc[id];
            if ((a->ids & (1u << id)) == 0u) {
                continue;
            }
            cli_json_begin_object(&j, NULL);
            cli_json_int(&j, "id", id);
            cli_json_uint(&j, "replies", x->replies);
            cli_json_uint(&j, "failures", x->failures);
            cli_json_real(&j, "latency_mean_us",
                          x->latency_n != 0u ? x->latency_sum / x->latency_n : 0.0);
            cli_json_uint(&j, "latency_max_us", x->latency_max);
            if (a->motion != MOTION_NONE && x->err_n != 0u) {
                cli_json_real(&j, "tracking_rms_rad", sqrt(x->err_sq_sum / x->err_n));
                cli_json_real(&j, "tracking_max_rad", x->err_max);
            }
            cli_json_end_object(&j);
        }
        cli_json_end_array(&j);
        cli_json_str(&j, "side", side_name);
        cli_json_end_object(&j);
        cli_json_newline(&j);
        return;
    }
    printf("log: %lu cycles in %.3f s: achieved %.1f Hz (asked %.1f Hz), %lu missed "
           "deadlines, %lu ticks skipped\n",
           (unsigned long)rs->cycles, rs->elapsed_s, achieved, a->rate_hz,
           (unsigned long)rs->missed, (unsigned long)rs->skipped);
    printf("bus: %lu transactions, %lu ok, %lu timeouts, %lu CRC errors, %lu wrong id, "
           "%lu collisions, %lu line errors, %lu stale bytes, %lu garbage bytes\n",
           (unsigned long)bs->transactions, (unsigned long)bs->ok, (unsigned long)bs->timeouts,
           (unsigned long)bs->crc_errors, (unsigned long)bs->wrong_id,
           (unsigned long)bs->collisions, (unsigned long)bs->line_errors,
           (unsigned long)bs->stale_bytes, (unsigned long)ps->garbage_bytes);
    for (id = 0; id <= J288_MAX_ID; id++) {
        const servo_acc_t *x = &acc[id];
        if ((a->ids & (1u << id)) == 0u) {
            continue;
        }
        printf("servo %u: %lu replies, %lu failed, latency mean %.0f us, worst %lu us",
               (unsigned)id, (unsigned long)x->replies, (unsigned long)x->failures,
               x->latency_n != 0u ? x->latency_sum / x->latency_n : 0.0,
               (unsigned long)x->latency_max);
        if (a->motion != MOTION_NONE && x->err_n != 0u) {
            printf("; tracking error rms %.4g rad, max %.4g rad (%s side)",
                   sqrt(x->err_sq_sum / x->err_n), x->err_max, side_name);
        }
        printf("\n");
    }
    if (a->csv != NULL) {
        printf("csv: %s (%lu rows)\n", a->csv, (unsigned long)rs->rows);
    }
}

int cli_cmd_log(int argc, char **argv, const cli_global_t *g)
{
    static cli_bus_t b;
    static j288_sched_t s;
    servo_acc_t acc[J288_MAX_ID + 1u];
    double pos_des[J288_MAX_ID + 1u];
    log_args_t a;
    cli_bus_opts_t o;
    run_stats_t rs;
    j288_cmd_raw_t base, cmd;
    j288_side_t side;
    FILE *csv = NULL;
    uint32_t t0, next, period_us, sweep_timeout_us;
    int ec, rc;
    uint8_t id;
    bool interrupted = false, failed = false;

    memset(&a, 0, sizeof a);
    a.rate_hz = 100.0;
    a.duration_s = 1.0;
    a.side = 1;
    a.watchdog = true;
    cli_bus_opts_init(&o, g);
    if (parse_args(argc, argv, &a, &o, &ec) != 0) {
        return ec;
    }
    if (!a.have_period) {
        a.period_s = a.duration_s;
    }
    side = a.side == 0 ? J288_SIDE_ROTOR : J288_SIDE_OUTPUT;
    if (a.motion != MOTION_NONE && base_command(&a, &base) != 0) {
        return CLI_EXIT_USAGE;
    }
    if (a.motion == MOTION_SWING) {
        int32_t probe;
        if (j288_pos_to_raw((j288_real_t)a.amp, side, &probe) != J288_OK) {
            cli_error("--swing: %g rad is out of range", a.amp);
            return CLI_EXIT_USAGE;
        }
    }
    cli_signals_install();
    /* Best effort: wake from the tick sleeps within a microsecond rather than the default
     * 50 us timer slack. */
    (void)prctl(PR_SET_TIMERSLACK, 1ul, 0ul, 0ul, 0ul);
    if ((ec = cli_bus_open(&b, &o, 0)) != CLI_EXIT_OK) {
        return ec;
    }
    if (a.csv != NULL) {
        csv = fopen(a.csv, "w");
        if (csv == NULL) {
            cli_error("cannot write %s: %s", a.csv, strerror(errno));
            cli_bus_close(&b);
            return CLI_EXIT_FAIL;
        }
        setvbuf(csv, NULL, _IOFBF, 1u << 16);
        csv_header(csv);
    }
    j288_sched_init(&s, &b.bus, NULL);
    memset(acc, 0, sizeof acc);
    for (id = 0; id <= J288_MAX_ID; id++) {
        if ((a.ids & (1u << id)) != 0u) {
            cli_lock_cmd(id, &cmd);
            j288_sched_set_cmd(&s, &cmd);
            j288_sched_enable(&s, id, true);
        }
        pos_des[id] = NAN;
    }
    /* The budget of one sweep: every servo's full reply window, plus slack. */
    sweep_timeout_us = 15u * (j288_bus_reply_budget_us(&b.bus) * 2u + 1000u) + 100000u;

    /* First sweeps: who is there and where they start; a few tries so that one dropped
     * reply does not fail the whole log. */
    for (rc = 0; rc < PROBE_SWEEPS && !all_answered(&s, a.ids); rc++) {
        int r = sweep(&b, &s, sweep_timeout_us, false);
        if (r == J288_ERR_OFFLINE || r == J288_ERR_ABORTED) {
            if (r == J288_ERR_OFFLINE) {
                cli_error("%s", j288_linux_error(&b.lp));
            }
            if (csv != NULL) {
                fclose(csv);
            }
            cli_bus_close(&b);
            return r == J288_ERR_ABORTED ? cli_signal_exit_code() : CLI_EXIT_FAIL;
        }
    }
    for (id = 0; id <= J288_MAX_ID; id++) {
        const j288_slot_t *sl = j288_sched_slot(&s, id);
        if ((a.ids & (1u << id)) == 0u) {
            continue;
        }
        if (!sl->has_reply) {
            cli_error("no reply from servo %u on %s (check id, power, wiring and --baud)",
                      (unsigned)id, b.dev);
            if (csv != NULL) {
                fclose(csv);
            }
            cli_bus_close(&b);
            return CLI_EXIT_FAIL;
        }
        acc[id].p0 = sl->reply.pos;
        acc[id].seen_successes = sl->stats.successes;
        if (a.motion != MOTION_NONE) {
            b.driven = (uint16_t)(b.driven | (1u << id));
        }
    }

    memset(&rs, 0, sizeof rs);
    period_us = (uint32_t)lround(1e6 / a.rate_hz);
    t0 = j288_linux_now_us();
    next = t0;
    for (;;) {
        uint32_t now = j288_linux_now_us();
        double t = (double)(uint32_t)(now - t0) / 1e6;
        if (t >= a.duration_s) {
            break;
        }
        /* This cycle's commands. */
        for (id = 0; id <= J288_MAX_ID; id++) {
            if ((a.ids & (1u << id)) == 0u) {
                continue;
            }
            if (a.motion == MOTION_NONE) {
                continue; /* the lock set at the start stays */
            }
            cmd = base;
            cmd.id = id;
            if (a.motion == MOTION_HOLD) {
                cmd.pos = acc[id].p0;
            } else {
                swing_setpoint(&a, acc[id].p0, t, &cmd.pos, &cmd.speed);
            }
            pos_des[id] = (double)j288_pos_from_raw(cmd.pos, side);
            j288_sched_set_cmd(&s, &cmd);
        }
        rc = sweep(&b, &s, sweep_timeout_us, false);
        if (rc == J288_ERR_ABORTED) {
            interrupted = true;
            break;
        }
        if (rc == J288_ERR_OFFLINE) {
            cli_error("%s", j288_linux_error(&b.lp));
            failed = true;
            break;
        }
        rs.cycles++;
        for (id = 0; id <= J288_MAX_ID; id++) {
            const j288_slot_t *sl = j288_sched_slot(&s, id);
            servo_acc_t *x = &acc[id];
            bool fresh;
            if ((a.ids & (1u << id)) == 0u) {
                continue;
            }
            fresh = sl->stats.successes != x->seen_successes;
            x->seen_successes = sl->stats.successes;
            if (fresh) {
                uint32_t lat = sl->stats.last_latency_us;
                x->replies++;
                x->latency_sum += (double)lat;
                x->latency_n++;
                if (lat > x->latency_max) {
                    x->latency_max = lat;
                }
                if (a.motion != MOTION_NONE) {
                    double e = fabs(pos_des[id] - (double)j288_pos_from_raw(sl->reply.pos, side));
                    x->err_sq_sum += e * e;
                    x->err_n++;
                    if (e > x->err_max) {
                        x->err_max = e;
                    }
                }
            } else {
                x->failures++;
            }
            if (csv != NULL) {
                double rt = fresh ? (double)(uint32_t)(sl->reply_us - t0) / 1e6 : t;
                csv_row(csv, rt, id, sl, fresh, side, pos_des[id]);
                rs.rows++;
            }
        }
        next += period_us;
        now = j288_linux_now_us();
        if ((int32_t)(next - now) < 0) {
            /* The sweep ran past the next tick: that tick starts late, at once. Ticks a
             * whole period or more behind are skipped rather than sent in a burst. */
            rs.missed++;
            while ((int32_t)(next + period_us - now) <= 0) {
                next += period_us;
                rs.skipped++;
            }
        }
        rc = cli_bus_sleep_until(&b, next);
        if (rc == J288_ERR_ABORTED) {
            interrupted = true;
            break;
        }
        if (rc == J288_ERR_OFFLINE) {
            cli_error("%s", j288_linux_error(&b.lp));
            failed = true;
            break;
        }
    }
    rs.elapsed_s = (double)(uint32_t)(j288_linux_now_us() - t0) / 1e6;
    if (!failed) {
        /* Let a sweep cut short by the signal finish, then lock every driven servo. */
        (void)j288_linux_run(&b.lp, &s, j288_linux_now_us() + sweep_timeout_us,
                             J288_LINUX_RUN_UNTIL_IDLE | J288_LINUX_RUN_IGNORE_STOP);
        if (cli_bus_lock_driven(&b) != 0) {
            cli_error("a servo did not confirm the lock (a broadcast lock was sent)");
            failed = true;
        }
    }
    if (csv != NULL && fclose(csv) != 0) {
        cli_error("writing %s failed", a.csv);
        failed = true;
    }
    if (!failed) {
        print_summary(&a, &b, &s, acc, &rs, o.json);
    }
    cli_bus_close(&b);
    if (interrupted) {
        return cli_signal_exit_code();
    }
    return failed ? CLI_EXIT_FAIL : CLI_EXIT_OK;
}
