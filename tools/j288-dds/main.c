/*
 * j288-dds - the robot of a config file on DDS, as ROS 2 and unitree_sdk2 programs expect it
 * (docs/dds.md). One thread: take the commands that came in, run one cycle of the robot
 * runner, publish the state; diagnostics about once a second; sleep to the next period.
 * DDS's own threads receive in the background; nothing of theirs touches the robot.
 */
#include <errno.h>
#include <signal.h>
#include <sys/resource.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <dds/dds.h>

#include "bridge.h"

#define DIAG_PERIOD_US 1000000u
#define DEFAULT_RATE_HZ 500.0
#define TAKE_MAX 32

static const char usage[] =
    "usage: j288-dds --config ROBOT.yaml [options]\n"
    "The robot of ROBOT.yaml on DDS (Cyclone DDS), for ROS 2 and unitree_sdk2 programs.\n"
    "Publishes rt/[NS/]joint_states (sensor_msgs/JointState) every cycle and\n"
    "rt/[NS/]diagnostics (diagnostic_msgs/DiagnosticArray) about once a second; follows\n"
    "rt/[NS/]joint_command (sensor_msgs/JointState). See docs/dds.md.\n"
    "\n"
    "  --config FILE       the robot config (buses and joints)\n"
    "  --domain N          DDS domain id, 0-232 (default: $ROS_DOMAIN_ID, else 0)\n"
    "  --namespace NS      topics rt/NS/... (letters, digits, _ and /)\n"
    "  --rate HZ           cycles per second (default 500; 0: back to back)\n"
    "  --timeout MS        a command older than this is no longer followed (default 100)\n"
    "  --on-timeout hold|lock   then hold the joint where it is at its gains (default), or\n"
    "                      lock it\n"
    "  --unitree           unitree_sdk2 mode: rt/lowstate and rt/lowcmd (unitree_go LowState_,\n"
    "                      LowCmd_; motors in config order, crc checked and set) instead of\n"
    "                      joint_states and joint_command\n"
    "  --stop-on-bus-loss  a bus that stops answering or vanishes locks every bus, and\n"
    "                      commands are refused until restart\n"
    "  --realtime[=PRIO]   lock memory and run the loop under SCHED_FIFO at PRIO (1-99,\n"
    "                      default 80); without the rights a notice says how to get them\n"
    "                      (ulimit -r, limits.d, CAP_SYS_NICE) and the loop runs on\n"
    "  --cpu N             pin the loop to CPU N (docs/realtime.md)\n"
    "  --help, --version\n"
    "Gains: each joint's kp and kd from the config, else kp 20 N*m/rad, kd 2.5 N*m*s/rad.\n"
    "Pacing: cycle k is due at the first cycle's time + k/HZ; a cycle that overruns makes\n"
    "the next start at once (a missed deadline), periods wholly missed are skipped, never\n"
    "sent back to back. rt/diagnostics' \"j288-dds: loop\" status: deadlines missed,\n"
    "periods skipped, cycles cut at their bound, wake-up lateness and cycle duration\n"
    "(p50, p99, p99.9, max).\n"
    "SIGINT / SIGTERM: every bus locked (broadcast lock, watchdog bit 0), then exit 0.\n";

typedef struct {
    const char *config;
    long domain;
    const char *ns;
    double rate_hz;
    uint32_t timeout_us;
    bridge_timeout_policy_t policy;
    bool unitree;
    bool stop_on_bus_loss;
    int realtime; /* SCHED_FIFO priority, 0: none */
    int cpu;      /* -1: not pinned */
} options_t;

static volatile sig_atomic_t stop_signal;

static void on_signal(int sig)
{
    stop_signal = sig;
}

static int bad_usage(const char *what, const char *arg)
{
    fprintf(stderr, "j288-dds: %s%s%s\n%s", what, arg != NULL ? ": " : "", arg != NULL ? arg : "",
            "try j288-dds --help\n");
    return 2;
}

static bool number(const char *s, double lo, double hi, double *out)
{
    char *end;
    double v;
    if (s == NULL || *s == '\0')
        return false;
    errno = 0;
    v = strtod(s, &end);
    if (*end != '\0' || errno != 0 || !(v >= lo && v <= hi))
        return false;
    *out = v;
    return true;
}

static bool good_namespace(const char *ns)
{
    const char *p;
    if (*ns == '\0' || *ns == '/' || ns[strlen(ns) - 1] == '/' || strlen(ns) > 100u)
        return false;
    for (p = ns; *p != '\0'; p++) {
        bool ok = (*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') || (*p >= '0' && *p <= '9') ||
                  *p == '_' || (*p == '/' && p[1] != '/');
        if (!ok)
            return false;
    }
    return true;
}

/* 0: go on; otherwise the exit status (help and version: 0 after printing, with *done). */
static int parse(int argc, char **argv, options_t *o, bool *done)
{
    int i;
    const char *env = getenv("ROS_DOMAIN_ID");
    double v;
    memset(o, 0, sizeof *o);
    o->rate_hz = DEFAULT_RATE_HZ;
    o->timeout_us = J288_DDS_DEFAULT_TIMEOUT_US;
    o->cpu = -1;
    if (env != NULL && *env != '\0') {
        if (!number(env, 0, 232, &v))
            return bad_usage("ROS_DOMAIN_ID is not a domain id 0-232", env);
        o->domain = (long)v;
    }
    for (i = 1; i < argc; i++) {
        const char *a = argv[i], *val = (i + 1 < argc) ? argv[i + 1] : NULL;
        bool takes = true;
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            fputs(usage, stdout);
            *done = true;
            return 0;
        } else if (strcmp(a, "--version") == 0) {
            printf("j288-dds %s\n", j288_robot_version());
            *done = true;
            return 0;
        } else if (strcmp(a, "--unitree") == 0) {
            o->unitree = true;
            takes = false;
        } else if (strcmp(a, "--stop-on-bus-loss") == 0) {
            o->stop_on_bus_loss = true;
            takes = false;
        } else if (strcmp(a, "--realtime") == 0 || strncmp(a, "--realtime=", 11) == 0) {
            o->realtime = J288_RT_DEFAULT_PRIORITY;
            if (a[10] == '=' && (!number(a + 11, 1, 99, &v) || v != (double)(int)v))
                return bad_usage("--realtime takes a priority 1-99", a + 11);
            if (a[10] == '=')
                o->realtime = (int)v;
            takes = false;
        } else if (val == NULL) {
            return bad_usage(strncmp(a, "--", 2) == 0 ? "missing value" : "unknown argument", a);
        } else if (strcmp(a, "--config") == 0) {
            o->config = val;
        } else if (strcmp(a, "--domain") == 0) {
            if (!number(val, 0, 232, &v) || v != (double)(long)v)
                return bad_usage("--domain takes a domain id 0-232", val);
            o->domain = (long)v;
        } else if (strcmp(a, "--namespace") == 0) {
            if (!good_namespace(val))
                return bad_usage("--namespace takes letters, digits, _ and single inner /", val);
            o->ns = val;
        } else if (strcmp(a, "--rate") == 0) {
            if (!number(val, 0, 10000, &v) || (v > 0 && v < 0.1))
                return bad_usage("--rate takes 0 (back to back) or 0.1-10000 Hz", val);
            o->rate_hz = v;
        } else if (strcmp(a, "--cpu") == 0) {
            if (!number(val, 0, 1023, &v) || v != (double)(int)v)
                return bad_usage("--cpu takes a CPU number 0-1023", val);
            o->cpu = (int)v;
        } else if (strcmp(a, "--timeout") == 0) {
            if (!number(val, 1, 60000, &v))
                return bad_usage("--timeout takes 1-60000 ms", val);
            o->timeout_us = (uint32_t)(v * 1000.0);
        } else if (strcmp(a, "--on-timeout") == 0) {
            if (strcmp(val, "hold") == 0)
                o->policy = TIMEOUT_HOLD;
            else if (strcmp(val, "lock") == 0)
                o->policy = TIMEOUT_LOCK;
            else
                return bad_usage("--on-timeout takes hold or lock", val);
        } else {
            return bad_usage("unknown option", a);
        }
        if (takes)
            i++;
    }
    if (o->config == NULL)
        return bad_usage("--config FILE is needed", NULL);
    return 0;
}

/* ---- runner events: recorded during a cycle, handled after it ---- */

typedef struct {
    unsigned n;
    struct {
        unsigned index; /* bus, or joint (watchdog) */
        j288_robot_event_kind_t kind;
    } ev[2u * J288_ROBOT_MAX_BUSES + J288_ROBOT_MAX_JOINTS];
} pending_t;

static void on_event(void *user, const j288_robot_event_t *ev)
{
    pending_t *p = user;
    bool bus = ev->kind == J288_ROBOT_EV_BUS_DOWN || ev->kind == J288_ROBOT_EV_BUS_GONE ||
               ev->kind == J288_ROBOT_EV_BUS_UP;
    if (!bus && !(ev->kind == J288_ROBOT_EV_WATCHDOG && ev->joint >= 0))
        return;
    if (p->n < sizeof p->ev / sizeof p->ev[0]) {
        p->ev[p->n].index = bus ? ev->bus : (unsigned)ev->joint;
        p->ev[p->n].kind = ev->kind;
        p->n++;
    }
}

static void handle_events(bridge_t *b, pending_t *p)
{
    unsigned i;
    for (i = 0; i < p->n; i++) {
        unsigned k = p->ev[i].index;
        switch (p->ev[i].kind) {
        case J288_ROBOT_EV_BUS_UP:
            fprintf(stderr, "j288-dds: bus '%s' answers again\n", j288_robot_bus_name(b->robot, k));
            break;
        case J288_ROBOT_EV_BUS_GONE:
            bridge_bus_lost(b, k, "vanished (device gone)");
            break;
        case J288_ROBOT_EV_BUS_DOWN:
            bridge_bus_lost(b, k, "stopped answering");
            break;
        default:
            bridge_watchdog(b, k);
            break;
        }
    }
    p->n = 0;
}

/* Whether every bus's device is gone (nothing left to run). */
static bool every_bus_gone(const j288_robot_t *r)
{
    unsigned i;
    for (i = 0; i < j288_robot_nbuses(r); i++) {
        j288_robot_bus_stats_t bs;
        if (j288_robot_bus_stats(r, i, &bs) == J288_OK && !bs.gone)
            return false;
    }
    return true;
}

/* ---- DDS entities ---- */

typedef struct {
    dds_entity_t participant, state_w, diag_w, cmd_r;
} dds_io_t;

static dds_entity_t topic(dds_entity_t pp, const dds_topic_descriptor_t *desc, const char *ns,
                          const char *name)
{
    char full[160];
    snprintf(full, sizeof full, "rt/%s%s%s", ns != NULL ? ns : "", ns != NULL ? "/" : "", name);
    return dds_create_topic(pp, desc, full, NULL, NULL);
}

/* Reliable keep-last-1 writers (they match reliable and best-effort readers alike, so ROS 2's
 * default and sensor-data subscribers both see the state); a best-effort reader keeping the
 * latest 32 commands (it matches every writer; commands are periodic, the newest counts).
 * The writers never block the loop: keep-last 1 already replaces an unacknowledged sample
 * (a frozen reliable reader measured no slower, docs/dds.md), and a max blocking time of 0
 * makes it a guarantee: a write that would wait fails at once and the next cycle's sample
 * takes its place. */
static int dds_open(dds_io_t *io, const options_t *o)
{
    dds_qos_t *wq = dds_create_qos(), *rq = dds_create_qos();
    dds_entity_t st, dg, cm;
    int rc = 0;
    dds_qset_reliability(wq, DDS_RELIABILITY_RELIABLE, 0);
    dds_qset_history(wq, DDS_HISTORY_KEEP_LAST, 1);
    dds_qset_reliability(rq, DDS_RELIABILITY_BEST_EFFORT, 0);
    dds_qset_history(rq, DDS_HISTORY_KEEP_LAST, TAKE_MAX);
    io->participant = dds_create_participant((dds_domainid_t)o->domain, NULL, NULL);
    if (io->participant < 0) {
        fprintf(stderr, "j288-dds: DDS participant on domain %ld: %s\n", o->domain,
                dds_strretcode(io->participant));
        rc = -1;
        goto out;
    }
    if (o->unitree) {
        st = topic(io->participant, &unitree_go_msg_dds__LowState__desc, o->ns, "lowstate");
        cm = topic(io->participant, &unitree_go_msg_dds__LowCmd__desc, o->ns, "lowcmd");
    } else {
        st = topic(io->participant, &sensor_msgs_msg_dds__JointState__desc, o->ns, "joint_states");
        cm = topic(io->participant, &sensor_msgs_msg_dds__JointState__desc, o->ns, "joint_command");
    }
    dg = topic(io->participant, &diagnostic_msgs_msg_dds__DiagnosticArray__desc, o->ns, "diagnostics");
    io->state_w = dds_create_writer(io->participant, st, wq, NULL);
    io->diag_w = dds_create_writer(io->participant, dg, wq, NULL);
    io->cmd_r = dds_create_reader(io->participant, cm, rq, NULL);
    if (st < 0 || cm < 0 || dg < 0 || io->state_w < 0 || io->diag_w < 0 || io->cmd_r < 0) {
        fprintf(stderr, "j288-dds: DDS topics, writers or reader could not be made\n");
        rc = -1;
    }
out:
    dds_delete_qos(wq);
    dds_delete_qos(rq);
    return rc;
}

/* Every command waiting, oldest first. */
static void take_commands(bridge_t *b, const dds_io_t *io, bool unitree)
{
    void *samples[TAKE_MAX] = {NULL};
    dds_sample_info_t info[TAKE_MAX];
    dds_return_t n = dds_take(io->cmd_r, samples, info, TAKE_MAX, TAKE_MAX);
    uint32_t now = j288_robot_now_us();
    dds_return_t i;
    for (i = 0; i < n; i++) {
        if (!info[i].valid_data)
            continue;
        if (unitree)
            bridge_take_lowcmd(b, samples[i], now);
        else
            bridge_take_command(b, samples[i], now);
    }
    if (n > 0)
        (void)dds_return_loan(io->cmd_r, samples, n);
}

/* CLOCK_MONOTONIC in seconds (the runner's microsecond clock wraps after 71 minutes). */
static double mono_s(void)
{
    struct timespec ts;
    (void)clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void publish_state(bridge_t *b, const dds_io_t *io, bool unitree, double start_s)
{
    if (unitree) {
        static unitree_go_msg_dds__LowState_ ls;
        bridge_fill_lowstate(b, &ls, (uint32_t)(uint64_t)((mono_s() - start_s) * 1000.0));
        (void)dds_write(io->state_w, &ls);
    } else {
        sensor_msgs_msg_dds__JointState_ js;
        bridge_fill_joint_state(b, &js);
        (void)dds_write(io->state_w, &js);
    }
}

static void publish_diagnostics(bridge_t *b, const dds_io_t *io)
{
    diagnostic_msgs_msg_dds__DiagnosticArray_ da;
    bridge_fill_diagnostics(b, &da);
    (void)dds_write(io->diag_w, &da);
}

/* One line at exit: cycles, their rate, and the process's CPU time (DDS's threads included). */
static void print_summary(const j288_robot_t *r, double start_s)
{
    j288_robot_stats_t rs;
    struct rusage ru;
    double secs = mono_s() - start_s, cpu;
    (void)j288_robot_stats(r, &rs);
    (void)getrusage(RUSAGE_SELF, &ru);
    cpu = (double)ru.ru_utime.tv_sec + (double)ru.ru_stime.tv_sec +
          1e-6 * (double)(ru.ru_utime.tv_usec + ru.ru_stime.tv_usec);
    fprintf(stderr, "j288-dds: %lu cycles (%lu complete) in %.2f s, %.0f cycles/s, cpu %.3f s\n",
            (unsigned long)rs.cycles, (unsigned long)rs.complete_cycles, secs,
            secs > 0 ? (double)rs.cycles / secs : 0.0, cpu);
    {
        j288_rt_report_t rep;
        char text[640];
        (void)j288_robot_timing(r, &rep);
        fputs(j288_rt_format(&rep, text, sizeof text), stderr);
    }
}

static int run(const options_t *o)
{
    static j288_robot_config_t cfg;
    static j288_robot_t robot;
    static bridge_t b;
    static pending_t pending;
    char err[J288_ROBOT_CONFIG_ERROR_MAX];
    j288_robot_options_t ro;
    dds_io_t io;
    uint32_t period_us = o->rate_hz > 0 ? (uint32_t)(1e6 / o->rate_hz + 0.5) : 0u;
    uint32_t last_diag;
    double start_s;
    int rc, status = 0;

    if (j288_robot_config_load(o->config, &cfg, err, sizeof err) != 0) {
        fprintf(stderr, "j288-dds: %s\n", err);
        return 1;
    }
    if (o->unitree && cfg.njoints > J288_DDS_UNITREE_MOTORS) {
        fprintf(stderr, "j288-dds: --unitree: %u joints, LowCmd_ has %u motors\n",
                (unsigned)cfg.njoints, J288_DDS_UNITREE_MOTORS);
        return 1;
    }
    memset(&ro, 0, sizeof ro);
    ro.on_event = on_event;
    ro.user = &pending;
    ro.stop_on_bus_loss = o->stop_on_bus_loss; /* the runner stops every bus itself */
    ro.realtime = (uint8_t)o->realtime;
    ro.pin_cpu = o->cpu >= 0;
    ro.cpu = (uint16_t)(o->cpu >= 0 ? o->cpu : 0);
    rc = j288_robot_open(&robot, &cfg, &ro);
    if (rc != J288_OK) {
        fprintf(stderr, "j288-dds: %s\n", j288_robot_error(&robot));
        j288_robot_close(&robot);
        return rc == J288_ERR_BAD_ARG ? 2 : 1;
    }
    fputs(j288_robot_rt_notice(&robot), stderr);
    j288_robot_set_stop_flag(&robot, &stop_signal);
    if (dds_open(&io, o) != 0) {
        j288_robot_close(&robot);
        if (io.participant > 0)
            (void)dds_delete(io.participant);
        return 1;
    }
    bridge_init(&b, &robot, &cfg, o->timeout_us, o->policy);
    fprintf(stderr, "j288-dds: %u joints on %u buses, domain %ld, %s%s%s, %s\n",
            j288_robot_njoints(&robot), j288_robot_nbuses(&robot), o->domain,
            o->unitree ? "rt/lowstate + rt/lowcmd" : "rt/joint_states + rt/joint_command",
            o->ns != NULL ? " in namespace " : "", o->ns != NULL ? o->ns : "",
            o->rate_hz > 0 ? "paced" : "back to back");
    start_s = mono_s();
    last_diag = j288_robot_now_us();
    publish_diagnostics(&b, &io);
    j288_robot_timing_reset(&robot);
    (void)j288_robot_pace(&robot, period_us); /* the schedule starts with the first cycle */
    while (stop_signal == 0) {
        take_commands(&b, &io, o->unitree);
        bridge_check_timeouts(&b, j288_robot_now_us());
        rc = j288_robot_cycle(&robot, 0, NULL);
        handle_events(&b, &pending);
        if (rc == J288_ERR_ABORTED)
            break;
        if (rc == J288_ERR_OFFLINE && every_bus_gone(&robot)) {
            fprintf(stderr, "j288-dds: every bus is gone: %s\n", j288_robot_error(&robot));
            status = 1;
            break;
        }
        if (rc == J288_ERR_OFFLINE) /* stop on bus loss: the runner locked every bus */
            bridge_stopped(&b, j288_robot_error(&robot));
        publish_state(&b, &io, o->unitree, start_s);
        if ((uint32_t)(j288_robot_now_us() - last_diag) >= DIAG_PERIOD_US) {
            last_diag = j288_robot_now_us();
            publish_diagnostics(&b, &io);
        }
        rc = j288_robot_pace(&robot, period_us); /* absolute deadlines, j288_rt.h */
        if (rc == J288_ERR_OFFLINE) {
            fprintf(stderr, "j288-dds: every bus is gone: %s\n", j288_robot_error(&robot));
            status = 1;
            break;
        }
    }
    if (stop_signal != 0) {
        rc = j288_robot_stop(&robot); /* again after an abort: harmless, and the cycle may not
                                         have seen the flag */
        fprintf(stderr, "j288-dds: %s: every bus locked (%s)\n",
                stop_signal == SIGINT ? "SIGINT" : "SIGTERM",
                rc == J288_OK ? "broadcast lock sent" : j288_strerror(rc));
        publish_diagnostics(&b, &io);
    }
    print_summary(&robot, start_s);
    j288_robot_close(&robot);
    (void)dds_delete(io.participant);
    return status;
}

int main(int argc, char **argv)
{
    options_t o;
    bool done = false;
    struct sigaction sa;
    int rc = parse(argc, argv, &o, &done);
    if (rc != 0 || done)
        return rc;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal; /* no SA_RESTART: a blocked ppoll() or sleep returns */
    sigemptyset(&sa.sa_mask);
    (void)sigaction(SIGINT, &sa, NULL);
    (void)sigaction(SIGTERM, &sa, NULL);
    return run(&o);
}
