/* `j288 jog`: one terminal screen to step a joint with the arrow keys and tune its gains while
 * it holds, the values and a live plot updating as it moves. Built on the runner
 * (host/j288_robot.h): its cycles drive the joints (targets in the joint frame, the joint
 * layer's limits), its stop locks every bus; the screen is live.h's, the plot tplot.h's. */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli_bus.h"
#include "frameview.h"
#include "live.h"
#include "tplot.h"

static const char jog_help[] =
    "usage: j288 jog --config FILE [--joint NAME]\n"
    "       j288 jog --port DEV --id N\n"
    "                [--step RAD] [--speed RAD_S] [--kp NM_RAD] [--kd NMS_RAD] [--rate HZ]\n"
    "                [--csv FILE]\n"
    "\n"
    "Jog a joint and tune its gains on one terminal screen. The joint (--joint, else the\n"
    "config's first; with --port, servo --id at its output encoder angle wrapped to\n"
    "[-pi, pi)) holds where it is; the arrow keys step its target, other keys change its\n"
    "gains while it holds, and its angle, speed, torque, temperatures, voltage and faults\n"
    "update live with a plot of its angle and target below (braille characters: a UTF-8\n"
    "terminal, over SSH too). Joint frame, SI units.\n"
    "keys:\n"
    "  up / down        target + / - one step (a target beyond the joint's limits is refused\n"
    "                   and says so on screen; a joint with clamp: true is clamped)\n"
    "  left / right     step / 2, * 2\n"
    "  p / P            kp / 1.25, * 1.25 (from 0: 1)      d / D   kd / 1.25, * 1.25 (0: 0.05)\n"
    "  space            hold the joint where it is now / lock it (it goes limp)\n"
    "  tab              next joint of the config (held from where it is; the others keep\n"
    "                   what they had)\n"
    "  v                plot: angle and target, speed, torque\n"
    "  z                plot: one column a cycle from each step or gain change until the\n"
    "                   screen is full, then held (a step's response, spread out and kept\n"
    "                   in view), or 20 columns a second (the default: some 10 s a screen)\n"
    "  q                quit\n"
    "The target moves to a new value at --speed (or the joint's max_speed when lower), with\n"
    "that speed as feed-forward; the plot and --csv show that ramped target.\n"
    "When jog ends (q, Ctrl-C, SIGTERM, SIGHUP, SIGQUIT) it sends the broadcast lock on every\n"
    "bus: every servo goes limp (no holding torque), so support a joint that carries a load\n"
    "before you quit. If jog itself dies (killed, frozen), the servos' 1 s watchdog (on for\n"
    "every moving command) locks them. At the end it prints each joint's last gains, to copy\n"
    "into the robot config (kp:, kd:).\n"
    "A bus that vanishes locks its joints; jog stays, and reopens it when it reappears at the\n"
    "same path (its joints then at lock: space holds one where it is).\n"
    "  --joint NAME     the joint selected first (default the config's first)\n"
    "  --id N           (with --port, without --config) the servo, 0-14\n"
    "  --step RAD       target step, 0.0001-1 (default 0.05)\n"
    "  --speed RAD_S    ramp speed of the target, 0.01-100 (default 1)\n"
    "  --kp, --kd       starting gains (default the config's, else 20 and 2.5)\n"
    "  --rate HZ        bus cycles per second, 10-2000 (default 200)\n"
    "  --csv FILE       one row per cycle of the selected joint: j288 log's columns\n"
    "                   (pos_des_rad is the ramped target; `j288 plot` reads it), then\n"
    "                   joint, kp, kd, cycle\n"
    "Exit status: 0 quit with q; 1 the joint never answered or its angle stayed unknown, a\n"
    "device or config error, a bus lost (stopped answering or vanished) meanwhile, a servo's\n"
    "watchdog had tripped; 2 bad arguments (and on Windows: not available there);\n"
    "130/143/129/131 stopped by SIGINT/SIGTERM/SIGHUP/SIGQUIT after the locks.\n"
    "  --realtime[=PRIO], --cpu N  the loop under SCHED_FIFO (default 80) with memory locked,\n"
    "                   on CPU N (docs/realtime.md; as `j288 log --help` says)\n"
    "\n" CLI_BUS_COMMON_HELP;

#define JOG_ACQUIRE_CYCLES 200u /* the most cycles the start waits for the joint's angle */
#define JOG_GAIN_FACTOR 1.25
#define JOG_KP_FROM_0 1.0
#define JOG_KD_FROM_0 0.05
#define JOG_STEP_MIN 0.0001
#define JOG_STEP_MAX 1.0
#define JOG_MSG_LEN 240u

enum { OPT_JOINT = 0, OPT_ID, OPT_STEP, OPT_SPEED, OPT_KP, OPT_KD, OPT_RATE, OPT_CSV };

typedef struct {
    const char *joint;
    long long id; /* -1: none */
    double step, speed, kp, kd, rate_hz;
    bool have_kp, have_kd;
    const char *csv;
} jog_args_t;

/* What jog does with each joint of the runner. */
typedef struct {
    bool held;       /* driven toward target */
    bool driven;     /* held at some time: its gains are printed at the end */
    double target;   /* rad, joint frame: where the keys put it */
    double setpoint; /* the ramped target commanded now */
    double kp, kd;
} jog_joint_t;

typedef struct {
    j288_robot_t *r;
    const jog_args_t *a;
    unsigned sel;     /* the selected joint */
    double step;
    unsigned view;    /* plot: 0 angle and target, 1 speed, 2 torque */
    bool fine;        /* plot: every cycle a column from the latest step on (z), else 20
                         columns a second */
    unsigned plot_cols; /* dot columns the plot showed last (fine: it stops when full) */
    jog_joint_t j[J288_ROBOT_MAX_JOINTS];
    bool live;        /* the screen runs: cycles are plotted and logged */
    cli_tplot_t tp;   /* the selected joint: angle, target, speed, torque */
    FILE *csv;
    uint32_t t0_us;
    char msg[JOG_MSG_LEN]; /* the latest message, on screen */
    unsigned trips;   /* watchdog trips the runner cleared */
    char trip_what[J288_ROBOT_CONFIG_NAME_MAX + 8];
} jog_t;

static int parse_jog_opt(void *ctx, int key, const char *v)
{
    jog_args_t *a = ctx;
    switch (key) {
    case OPT_JOINT:
        a->joint = v;
        return 0;
    case OPT_ID:
        return cli_parse_int("--id", v, 0, J288_MAX_ID, &a->id);
    case OPT_STEP:
        return cli_parse_real_in("--step", v, JOG_STEP_MIN, JOG_STEP_MAX, &a->step);
    case OPT_SPEED:
        return cli_parse_real_in("--speed", v, 0.01, 100.0, &a->speed);
    case OPT_KP:
        return cli_parse_gain(J288_QTY_KP, v, &a->have_kp, &a->kp);
    case OPT_KD:
        return cli_parse_gain(J288_QTY_KD, v, &a->have_kd, &a->kd);
    case OPT_RATE:
        return cli_parse_real_in("--rate", v, 10.0, 2000.0, &a->rate_hz);
    case OPT_CSV:
        a->csv = v;
        return 0;
    default:
        return 1;
    }
}

/* The message line on screen. */
static void say(jog_t *g, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 2, 3)))
#endif
    ;

static void say(jog_t *g, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    (void)vsnprintf(g->msg, sizeof g->msg, fmt, ap);
    va_end(ap);
}

/* The joint's limits, [-pi, pi] when its config gives none. */
static void limits_of(const j288_robot_t *r, unsigned j, double *lo, double *hi, bool *clamp)
{
    j288_joint_config_t jc;
    (void)j288_robot_joint_config(r, j, &jc);
    *lo = (double)jc.pos_min;
    *hi = (double)jc.pos_max;
    if (*lo == 0.0 && *hi == 0.0) {
        *lo = -J288_PI;
        *hi = J288_PI;
    }
    *clamp = jc.clamp;
}

/* The ramp speed of joint j: --speed, or its max_speed when lower. */
static double ramp_speed(const jog_t *g, unsigned j)
{
    j288_joint_config_t jc;
    (void)j288_robot_joint_config(g->r, j, &jc);
    return (jc.max_speed > 0 && (double)jc.max_speed < g->a->speed) ? (double)jc.max_speed
                                                                    : g->a->speed;
}

/* Hold joint j where it is (the nearest limit when it is beyond one by at most
 * J288_ROBOT_HOLD_BEYOND_MAX, as the runner's hold). False, with the reason on screen, if not. */
static bool hold_here(jog_t *g, unsigned j)
{
    j288_robot_state_t st;
    double lo, hi, q;
    bool clamp;
    (void)j288_robot_read(g->r, j, &st);
    if (!st.online) {
        say(g, "%s does not answer: nothing held", j288_robot_joint_name(g->r, j));
        return false;
    }
    if (!st.known) {
        say(g, "%s: angle not known yet: nothing held", j288_robot_joint_name(g->r, j));
        return false;
    }
    limits_of(g->r, j, &lo, &hi, &clamp);
    q = st.pos < lo ? lo : (st.pos > hi ? hi : st.pos);
    if (fabs(q - st.pos) > J288_ROBOT_HOLD_BEYOND_MAX) { /* (clamping or not: no jump at the start) */
        say(g, "%s is at %.4f rad, beyond its limits [%.4f, %.4f] by more than %g rad: "
               "nothing held; move it inside by hand",
            j288_robot_joint_name(g->r, j), st.pos, lo, hi, J288_ROBOT_HOLD_BEYOND_MAX);
        return false;
    }
    g->j[j].target = q;
    g->j[j].setpoint = q;
    g->j[j].held = true;
    g->j[j].driven = true;
    return true;
}

static void lock_joint(jog_t *g, unsigned j)
{
    g->j[j].held = false;
    (void)j288_robot_lock(g->r, j);
}

/* The plot starts again: 20 columns a second (a screen spans some 10 s), or with fine one column
 * a cycle from now until the screen is full, where it stays (a step's response spread out and
 * kept in view, as an oscilloscope's single trigger): every step and gain change starts it. */
static void restart_plot(jog_t *g)
{
    cli_tplot_init(&g->tp, 4, g->fine ? 1u : (unsigned)(g->a->rate_hz / 20.0 + 0.5));
}

/* Select joint j: the plot starts again, and the joint is held unless it already is. */
static void select_joint(jog_t *g, unsigned j)
{
    g->sel = j;
    restart_plot(g);
    if (!g->j[j].held && hold_here(g, j))
        say(g, "%s holds at %.4f rad", j288_robot_joint_name(g->r, j), g->j[j].target);
}

/* ---- the cycle ------------------------------------------------------------------------------- */

static void record(jog_t *g, const j288_robot_cycle_t *c)
{
    j288_robot_state_t st;
    j288_robot_joint_stats_t js;
    const jog_joint_t *jj = &g->j[g->sel];
    double v[CLI_TPLOT_MAX_SERIES];
    unsigned k;
    (void)j288_robot_read(g->r, g->sel, &st);
    for (k = 0; k < CLI_TPLOT_MAX_SERIES; k++)
        v[k] = NAN;
    if (st.fresh && st.known) {
        v[0] = st.pos;
        v[2] = st.speed;
        v[3] = st.torque;
    }
    if (jj->held)
        v[1] = jj->setpoint;
    if (!g->fine || g->plot_cols == 0u || g->tp.ncols < g->plot_cols)
        cli_tplot_add(&g->tp, v);
    if (g->csv == NULL)
        return;
    (void)j288_robot_joint_stats(g->r, g->sel, &js);
    fprintf(g->csv, "%.6f,%d,", (double)(c->start_us - g->t0_us) * 1e-6,
            j288_robot_joint_id(g->r, g->sel));
    if (st.fresh && st.known)
        fprintf(g->csv, "1,%.17g,%.17g,%.17g,%.0f,%.0f,%.1f,%lu,%lu,", st.pos, st.speed,
                st.torque, st.case_temp_c, st.winding_temp_c, st.voltage_v,
                (unsigned long)st.faults, (unsigned long)js.servo.last_latency_us);
    else
        fputs("0,,,,,,,,,", g->csv);
    if (jj->held)
        fprintf(g->csv, "%.17g", jj->setpoint);
    fprintf(g->csv, ",%s,%.6g,%.6g,%lu\n", j288_robot_joint_name(g->r, g->sel), jj->kp, jj->kd,
            (unsigned long)c->cycle);
}

/* Every held joint one ramp step on toward its target, then its command for the next cycle. */
static void drive(jog_t *g)
{
    unsigned j;
    for (j = 0; j < j288_robot_njoints(g->r); j++) {
        jog_joint_t *jj = &g->j[j];
        j288_robot_target_t t;
        double max_step = ramp_speed(g, j) / g->a->rate_hz, d;
        int rc;
        if (!jj->held)
            continue;
        d = jj->target - jj->setpoint;
        memset(&t, 0, sizeof t);
        if (fabs(d) <= max_step) {
            jj->setpoint = jj->target;
        } else {
            jj->setpoint += d > 0.0 ? max_step : -max_step;
            t.speed = d > 0.0 ? ramp_speed(g, j) : -ramp_speed(g, j);
        }
        t.pos = jj->setpoint;
        t.kp = jj->kp;
        t.kd = jj->kd;
        rc = j288_robot_set_target(g->r, j, &t);
        if (rc == J288_ERR_OFFLINE) { /* its bus is gone: keep the bus's news on screen */
            lock_joint(g, j);
            say(g, "bus '%s' is gone: %s locked",
                j288_robot_bus_name(g->r, (unsigned)j288_robot_joint_bus(g->r, j)),
                j288_robot_joint_name(g->r, j));
        } else if (rc != J288_OK) {
            lock_joint(g, j);
            say(g, "%s locked: %s", j288_robot_joint_name(g->r, j), j288_strerror(rc));
        }
    }
}

static void on_cycle(void *user, j288_robot_t *r, const j288_robot_cycle_t *c)
{
    jog_t *g = user;
    (void)r;
    if (g->live)
        record(g, c);
    drive(g);
}

static void on_event(void *user, const j288_robot_event_t *ev)
{
    jog_t *g = user;
    if (ev->kind == J288_ROBOT_EV_WATCHDOG) {
        g->trips++;
        (void)snprintf(g->trip_what, sizeof g->trip_what, "joint %s",
                       ev->joint >= 0 ? j288_robot_joint_name(g->r, (unsigned)ev->joint) : "?");
        say(g, "%s had tripped its watchdog: cleared", g->trip_what);
    } else if (ev->kind == J288_ROBOT_EV_BUS_DOWN || ev->kind == J288_ROBOT_EV_BUS_UP ||
               ev->kind == J288_ROBOT_EV_BUS_GONE || ev->kind == J288_ROBOT_EV_BUS_BACK) {
        unsigned j;
        say(g, "bus '%s' %s", j288_robot_bus_name(g->r, ev->bus),
            ev->kind == J288_ROBOT_EV_BUS_DOWN   ? "stopped answering"
            : ev->kind == J288_ROBOT_EV_BUS_UP   ? "answers again"
            : ev->kind == J288_ROBOT_EV_BUS_GONE ? "is gone"
                                                 : "is back: its joints at lock (space holds)");
        /* Its joints restart at lock (the runner's reconnection): nothing of theirs is held. */
        for (j = 0; ev->kind == J288_ROBOT_EV_BUS_BACK && j < j288_robot_njoints(g->r); j++)
            if (j288_robot_joint_bus(g->r, j) == (int)ev->bus)
                g->j[j].held = false;
    }
}

/* ---- the keys -------------------------------------------------------------------------------- */

static void step_target(jog_t *g, double sign)
{
    jog_joint_t *jj = &g->j[g->sel];
    double lo, hi, want;
    bool clamp;
    if (!jj->held && !hold_here(g, g->sel))
        return;
    limits_of(g->r, g->sel, &lo, &hi, &clamp);
    want = jj->target + sign * g->step;
    if (want > hi || want < lo) {
        if (!clamp) {
            say(g, "refused: %.4f rad is beyond the %s limit %.4f rad; target kept at %.4f", want,
                want > hi ? "upper" : "lower", want > hi ? hi : lo, jj->target);
            return;
        }
        say(g, "clamped: %.4f rad to the %s limit %.4f rad", want, want > hi ? "upper" : "lower",
            want > hi ? hi : lo);
        want = want > hi ? hi : lo;
    } else {
        say(g, "target %.4f rad", want);
    }
    jj->target = want;
    if (g->fine)
        restart_plot(g);
}

static void change_gain(jog_t *g, j288_quantity_t q, bool up)
{
    jog_joint_t *jj = &g->j[g->sel];
    double *gain = q == J288_QTY_KP ? &jj->kp : &jj->kd;
    double from_0 = q == J288_QTY_KP ? JOG_KP_FROM_0 : JOG_KD_FROM_0;
    double want = up ? (*gain > 0.0 ? *gain * JOG_GAIN_FACTOR : from_0) : *gain / JOG_GAIN_FACTOR;
    const char *name = q == J288_QTY_KP ? "kp" : "kd";
    if (!jj->held && !hold_here(g, g->sel))
        return;
    if (!up && want < from_0 / 100.0)
        want = 0.0;
    if (!j288_range_has(q, want)) {
        say(g, "refused: %s %.6g is beyond the wire's %g %s; kept at %.6g", name, want,
            j288_range(q)->hi, j288_range(q)->unit, *gain);
        return;
    }
    *gain = want;
    say(g, "%s %.6g %s", name, want, j288_range(q)->unit);
    if (g->fine)
        restart_plot(g);
}

/* One key; false for q. */
static bool key(jog_t *g, int k)
{
    switch (k) {
    case CLI_KEY_UP:
        step_target(g, 1.0);
        break;
    case CLI_KEY_DOWN:
        step_target(g, -1.0);
        break;
    case CLI_KEY_LEFT:
        g->step = g->step / 2.0 < JOG_STEP_MIN ? JOG_STEP_MIN : g->step / 2.0;
        say(g, "step %.4f rad", g->step);
        break;
    case CLI_KEY_RIGHT:
        g->step = g->step * 2.0 > JOG_STEP_MAX ? JOG_STEP_MAX : g->step * 2.0;
        say(g, "step %.4f rad", g->step);
        break;
    case 'p':
    case 'P':
        change_gain(g, J288_QTY_KP, k == 'P');
        break;
    case 'd':
    case 'D':
        change_gain(g, J288_QTY_KD, k == 'D');
        break;
    case ' ':
        if (g->j[g->sel].held) {
            lock_joint(g, g->sel);
            say(g, "%s locked (limp)", j288_robot_joint_name(g->r, g->sel));
        } else if (hold_here(g, g->sel)) {
            say(g, "%s holds at %.4f rad", j288_robot_joint_name(g->r, g->sel),
                g->j[g->sel].target);
        }
        break;
    case '\t':
        select_joint(g, (g->sel + 1u) % j288_robot_njoints(g->r));
        break;
    case 'v':
        g->view = (g->view + 1u) % 3u;
        break;
    case 'z':
        g->fine = !g->fine;
        restart_plot(g);
        say(g, "plot: %s", g->fine ? "one column a cycle from each step or gain change, then held"
                                   : "20 columns a second");
        break;
    case 'q':
    case 'Q':
        return false;
    default:
        break;
    }
    return true;
}

/* ---- the screen ------------------------------------------------------------------------------ */

static void print_joint_rows(FILE *f, const jog_t *g)
{
    unsigned j;
    fprintf(f, "  %-12s %-6s %8s %8s %8s %7s %7s %7s %5s %5s %5s  %s\n", "joint", "state",
            "target", "angle", "speed", "torque", "kp", "kd", "case", "wind", "volt", "faults");
    fprintf(f, "  %-12s %-6s %8s %8s %8s %7s %7s %7s %5s %5s %5s\n", "", "", "rad", "rad",
            "rad/s", "N*m", "N*m/rad", "N*m*s", "C", "C", "V");
    for (j = 0; j < j288_robot_njoints(g->r); j++) {
        const jog_joint_t *jj = &g->j[j];
        j288_robot_state_t st;
        j288_robot_joint_stats_t js;
        char target[16] = "-", faults[256];
        const char *state;
        (void)j288_robot_read(g->r, j, &st);
        (void)j288_robot_joint_stats(g->r, j, &js);
        state = js.servo.successes == 0u ? "silent" : (!st.known ? "?" : (jj->held ? "hold" : "lock"));
        if (jj->held)
            (void)snprintf(target, sizeof target, "%.4f", jj->target);
        fprintf(f, "%c %-12.12s %-6s %8s", j == g->sel ? '>' : ' ', j288_robot_joint_name(g->r, j),
                state, target);
        if (js.servo.successes == 0u) {
            fputs("\n", f);
            continue;
        }
        fprintf(f, " %8.4f %8.3f %7.3f %7.4g %7.4g %5.1f %5.1f %5.1f  %s\n", st.pos, st.speed,
                st.torque, jj->kp, jj->kd, st.case_temp_c, st.winding_temp_c, st.voltage_v,
                cli_fault_list(st.faults, faults, sizeof faults));
    }
}

static void draw(jog_t *g, const char *source)
{
    static const char *const views[] = {"angle (green) and target (yellow), rad",
                                        "speed, rad/s", "torque, N*m"};
    static const uint32_t masks[] = {0x3u, 0x4u, 0x8u};
    static const double min_span[] = {0.01, 0.1, 0.01};
    cli_live_frame_t fr;
    j288_robot_stats_t rs;
    unsigned cols, rows, used;
    double lo, hi;
    bool clamp;
    cli_live_size(&cols, &rows);
    if (!cli_live_frame_begin(&fr))
        return;
    (void)j288_robot_stats(g->r, &rs);
    limits_of(g->r, g->sel, &lo, &hi, &clamp);
    fprintf(fr.f, "j288 jog  %s  cycle %lu  q or Ctrl-C: lock every servo and quit\n\n", source,
            (unsigned long)rs.cycles);
    print_joint_rows(fr.f, g);
    fprintf(fr.f, "\nstep %.4f rad   ramp %.2f rad/s   limits [%.4f, %.4f] rad%s\n", g->step,
            ramp_speed(g, g->sel), lo, hi, clamp ? " (clamp)" : "");
    fputs("up/down: target +/- step   left/right: step /2 *2   p/P: kp -/+   d/D: kd -/+\n"
          "space: hold/lock   tab: next joint   v: plot view   z: zoom   q: quit (servos go limp)\n",
          fr.f);
    fprintf(fr.f, "%s\n", g->msg);
    fprintf(fr.f, "plot: %s of %s   %lu samples, %u a column\n", views[g->view],
            j288_robot_joint_name(g->r, g->sel), (unsigned long)g->tp.samples, g->tp.per_column);
    used = 10u + j288_robot_njoints(g->r);
    g->plot_cols = cols > 20u ? 2u * (cols - 11u) : 0u;
    if (rows > used + 2u && cols > 20u)
        cli_live_plot(fr.f, &g->tp, masks[g->view], cols,
                      rows - used - 2u > 24u ? 24u : rows - used - 2u, min_span[g->view],
                      (double)(2u * (cols - 11u) * g->tp.per_column) / g->a->rate_hz, true);
    cli_live_frame_show(&fr, cols, rows);
}

/* ---- the command ----------------------------------------------------------------------------- */

/* Cycles until the selected joint's angle is known (or it stayed silent for 5 cycles). */
static int acquire(jog_t *g)
{
    unsigned k;
    for (k = 0; k < JOG_ACQUIRE_CYCLES; k++) {
        j288_robot_state_t st;
        j288_robot_joint_stats_t js;
        int rc = j288_robot_cycle(g->r, 0, NULL);
        if (rc == J288_ERR_ABORTED || rc == J288_ERR_OFFLINE)
            return rc;
        (void)j288_robot_read(g->r, g->sel, &st);
        (void)j288_robot_joint_stats(g->r, g->sel, &js);
        if (st.known || (k >= 5u && js.servo.successes == 0u))
            return J288_OK;
    }
    return J288_OK;
}

static int run_screen(jog_t *g, const char *source)
{
    uint32_t period_us = (uint32_t)(1e6 / g->a->rate_hz + 0.5);
    bool go = true;
    int rc;
    (void)cli_live_raw();
    fputs("\033[H\033[2J", stdout);
    do {
        int k;
        rc = j288_robot_run(g->r, period_us, 0, 50000u);
        while (go && (k = cli_live_key()) != CLI_KEY_NONE)
            go = key(g, k);
        if (g->csv != NULL)
            (void)fflush(g->csv);
        draw(g, source);
    } while (rc == J288_OK && go);
    cli_live_restore();
    return rc;
}

/* The gains each driven joint ended with, for the config file. */
static void print_gains(const jog_t *g)
{
    unsigned j;
    for (j = 0; j < j288_robot_njoints(g->r); j++)
        if (g->j[j].driven)
            printf("%s: kp: %.6g  kd: %.6g\n", j288_robot_joint_name(g->r, j), g->j[j].kp,
                   g->j[j].kd);
}

/* Open the runner on the config file, or on --port with servo --id as joint "idN". */
static int open_robot(j288_robot_t *r, const cli_bus_opts_t *o, const jog_args_t *a,
                      j288_robot_options_t *ro)
{
    static j288_robot_config_t cfg;
    if (o->config != NULL)
        return j288_robot_open_file(r, o->config, ro);
    cli_live_bus_config(o->port, (uint32_t)(1ul << a->id), &cfg);
    return j288_robot_open(r, &cfg, ro);
}

int cli_cmd_jog(int argc, char **argv, const cli_global_t *gl)
{
    static const cli_opt_t opts[] = {
        {"--joint", true, OPT_JOINT}, {"--id", true, OPT_ID},   {"--step", true, OPT_STEP},
        {"--speed", true, OPT_SPEED}, {"--kp", true, OPT_KP},   {"--kd", true, OPT_KD},
        {"--rate", true, OPT_RATE},   {"--csv", true, OPT_CSV}, CLI_BUS_RT_OPTS, CLI_BUS_COMMON_OPTS,
        {NULL, false, 0}};
    static j288_robot_t robot; /* large: not on the stack */
    static jog_t g;
    jog_args_t a;
    cli_bus_opts_t o;
    j288_robot_options_t ro;
    int ec, rc, sel = 0;
    unsigned k;

    memset(&a, 0, sizeof a);
    a.id = -1;
    a.step = 0.05;
    a.speed = 1.0;
    a.rate_hz = 200.0;
    cli_bus_opts_init(&o, gl);
    if (cli_parse_bus_args(argc, argv, opts, jog_help, &o, parse_jog_opt, &a, &ec) != 0)
        return ec;
    if (o.port == NULL && getenv("J288_PORT") != NULL && getenv("J288_PORT")[0] != '\0')
        o.port = getenv("J288_PORT");
    if (o.json) {
        cli_error("--json: jog draws a screen (`j288 status --json` prints a result)");
        return CLI_EXIT_USAGE;
    }
    if (o.config == NULL && (o.port == NULL || a.id < 0)) {
        cli_error("give --config FILE [--joint NAME], or --port DEV (or $J288_PORT) and --id N");
        return CLI_EXIT_USAGE;
    }
    if (o.config != NULL && a.id >= 0) {
        cli_error("--id: with --config, name the joint (--joint NAME)");
        return CLI_EXIT_USAGE;
    }
    if (o.config == NULL && a.joint != NULL) {
        cli_error("--joint needs --config FILE");
        return CLI_EXIT_USAGE;
    }
    if (!isatty(STDIN_FILENO) || !isatty(STDOUT_FILENO)) {
        cli_error("needs a terminal (keys in, a screen out); `j288 hold` or `move` drive a "
                  "servo from a script");
        return CLI_EXIT_USAGE;
    }
    memset(&g, 0, sizeof g);
    g.r = &robot;
    g.a = &a;
    g.step = a.step;
    memset(&ro, 0, sizeof ro);
    ro.port = o.port;
    if (cli_bus_baud(o.baud, &ro.baud) != 0)
        return CLI_EXIT_USAGE;
    ro.margin_us = o.margin_us;
    ro.echo = o.echo;
    ro.retries = (uint8_t)(o.retries > 0 ? o.retries : 0);
    ro.on_cycle = on_cycle;
    ro.on_event = on_event;
    ro.user = &g;
    cli_bus_rt_options(&o, &ro);
    if (a.csv != NULL) {
        g.csv = fopen(a.csv, "w");
        if (g.csv == NULL) {
            cli_error("%s: cannot write", a.csv);
            return CLI_EXIT_FAIL;
        }
        fputs("time_s,id,ok,pos_rad,speed_rad_s,torque_nm,case_temp_c,winding_temp_c,voltage_v,"
              "faults,latency_us,pos_des_rad,joint,kp,kd,cycle\n",
              g.csv);
    }
    cli_signals_install();
    rc = open_robot(&robot, &o, &a, &ro);
    if (rc == J288_OK && a.joint != NULL && (sel = j288_robot_find_joint(&robot, a.joint)) < 0) {
        cli_error("--joint: no joint '%s' in %s", a.joint, o.config);
        rc = J288_ERR_BAD_ARG;
    } else if (rc != J288_OK) {
        cli_error("%s", j288_robot_error(&robot));
    } else if (j288_robot_njoints(&robot) == 0u) {
        cli_error("%s has no joints", o.config);
        rc = J288_ERR_BAD_ARG;
    }
    if (rc != J288_OK) {
        j288_robot_close(&robot);
        if (g.csv != NULL)
            (void)fclose(g.csv);
        return rc == J288_ERR_BAD_ARG ? CLI_EXIT_USAGE : CLI_EXIT_FAIL;
    }
    j288_robot_set_stop_flag(&robot, &cli_stop_signal);
    cli_print_rt_notice(&robot); /* (before the screen: what --realtime could not get) */
    for (k = 0; k < j288_robot_njoints(&robot); k++) { /* --kp, --kd, else the config's */
        j288_joint_config_t jc;
        (void)j288_robot_joint_config(&robot, k, &jc);
        g.j[k].kp = a.have_kp ? a.kp : (double)jc.kp;
        g.j[k].kd = a.have_kd ? a.kd : (double)jc.kd;
    }
    g.sel = (unsigned)sel;
    g.t0_us = j288_robot_now_us();
    rc = acquire(&g);
    if (rc == J288_OK) {
        select_joint(&g, g.sel);
        if (!g.j[g.sel].held) {
            cli_error("%s", g.msg);
            rc = J288_ERR_ANGLE_UNKNOWN;
        }
    }
    g.live = true;
    if (rc == J288_OK)
        rc = run_screen(&g, o.config != NULL ? o.config : o.port);
    /* Every servo limp: the broadcast lock on every bus (done already after a signal). */
    if (rc != J288_ERR_ABORTED)
        (void)j288_robot_stop(&robot);
    if (g.csv != NULL && fclose(g.csv) != 0)
        cli_error("%s: write failed", a.csv);
    if (rc == J288_ERR_OFFLINE)
        cli_error("%s", j288_robot_error(&robot));
    if (g.trips != 0u)
        cli_report_watchdog(g.trip_what);
    if (rc == J288_OK || rc == J288_ERR_ABORTED)
        print_gains(&g);
    if (cli_stop_signal == 0 && rc == J288_OK && cli_report_lost_buses(&robot) != 0u)
        rc = J288_ERR_OFFLINE;
    j288_robot_close(&robot);
    if (cli_stop_signal != 0)
        return cli_signal_exit_code();
    return rc == J288_OK ? CLI_EXIT_OK : CLI_EXIT_FAIL;
}
