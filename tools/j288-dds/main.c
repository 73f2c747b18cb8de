/*
 * j288-dds - the robot of a config file on DDS, as ROS 2 and unitree_sdk2 programs expect it
 * (docs/dds.md). One thread: take the commands that came in, run one cycle of the robot
 * runner, publish the state; diagnostics about once a second; sleep to the next period.
 * DDS's own threads receive in the background; nothing of theirs touches the robot (their log
 * lines pass through log_sink(), which only counts the samples DDS dropped).
 */
#include <errno.h>
#include <pthread.h>
#include <signal.h>
#include <sys/resource.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <dds/dds.h>

#include "bridge.h"
#include "service.h"
#include "typehash.h"

#define DIAG_PERIOD_US 1000000u
#define DEFAULT_RATE_HZ 500.0
#define TAKE_MAX 32
#define NS_MAX 245 /* ROS 2's RMW_NAMESPACE_MAX_LENGTH */
#define TOPIC_MAX (NS_MAX + 40)

typedef enum { MODE_ROS = 0, MODE_UNITREE_GO, MODE_UNITREE_HG } bridge_mode_t;

static const char usage[] =
    "usage: j288-dds --config ROBOT.yaml [options]\n"
    "The robot of ROBOT.yaml on DDS (Cyclone DDS), for ROS 2 and unitree_sdk2 programs.\n"
    "Publishes rt/[NS/]joint_states (sensor_msgs/JointState) every cycle and\n"
    "rt/[NS/]diagnostics (diagnostic_msgs/DiagnosticArray) about once a second; follows\n"
    "rt/[NS/]joint_command (sensor_msgs/JointState). See docs/dds.md.\n"
    "\n"
    "  --config FILE       the robot config (buses and joints)\n"
    "  --domain N          DDS domain id, 0-232 (default: $ROS_DOMAIN_ID, else 0)\n"
    "  --namespace NS      topics rt/NS/...: a ROS 2 namespace (/robot1, or robot1 taken as\n"
    "                      /robot1; letters, digits, _ and single inner /, no part starting\n"
    "                      with a digit; / alone: none)\n"
    "  --rate HZ           cycles per second (default 500; 0: back to back)\n"
    "  --timeout MS        a command older than this is no longer followed, and its writer\n"
    "                      no longer owns the joint (default 100)\n"
    "  --on-timeout hold|lock   then hold the joint where it is at its gains (default), or\n"
    "                      lock it\n"
    "  --per-joint         apply the joints of a command that are not refused (default: a\n"
    "                      command with any joint refused applies to none)\n"
    "  --unitree           unitree_sdk2 mode, unitree_go (Go2, B2, H1): rt/lowstate and\n"
    "                      rt/lowcmd (LowState_, LowCmd_; motors in config order, crc checked\n"
    "                      and set) instead of joint_states and joint_command\n"
    "  --unitree-hg        the same with unitree_hg's messages (G1, H1-2)\n"
    "  --stop-on-bus-loss  a bus that stops answering or vanishes locks every bus, and\n"
    "                      commands are refused until restart\n"
    "  --realtime[=PRIO]   lock memory and run the loop under SCHED_FIFO at PRIO (1-99,\n"
    "                      default 80); without the rights a notice says how to get them\n"
    "                      (ulimit -r, limits.d, CAP_SYS_NICE) and the loop runs on\n"
    "  --cpu N             pin the loop to CPU N (docs/realtime.md)\n"
    "  --exit-when-gone    exit 1 once every bus is gone, for a supervisor that restarts the\n"
    "                      bridge (default: stay up and reopen each device when it\n"
    "                      reappears at its path)\n"
    "  --help, --version\n"
    "Gains: each joint's kp and kd from the config, else kp 20 N*m/rad, kd 2.5 N*m*s/rad.\n"
    "Pacing: cycle k is due at the first cycle's time + k/HZ; a cycle that overruns makes\n"
    "the next start at once (a missed deadline), periods wholly missed are skipped, never\n"
    "sent back to back. rt/diagnostics' \"j288-dds: loop\" status: deadlines missed,\n"
    "periods skipped, cycles cut at their bound, wake-up lateness and cycle duration\n"
    "(p50, p99, p99.9, max).\n"
    "One commander per joint: the first writer whose command for a joint is applied owns it\n"
    "until it has been silent for the timeout; other writers' commands for it are refused.\n"
    "A joint not known or not fresh (its angle not found yet, no reply in the latest cycle,\n"
    "its bus lost) is published as NaN (position, velocity, effort); rt/diagnostics names\n"
    "each lost bus and when it was lost. A vanished device is reopened when it reappears at\n"
    "the same path (a udev symlink): its joints restart at lock until commanded again.\n"
    "SIGINT, SIGTERM, SIGHUP, SIGQUIT: every bus locked (broadcast lock, watchdog bit 0),\n"
    "then exit 0 (1 with --exit-when-gone once every bus was gone).\n"
    "Under systemd (NOTIFY_SOCKET): READY=1 once up, WATCHDOG=1 from the loop when\n"
    "WatchdogSec is set; a loop that stops cycling is killed and restarted by systemd, and\n"
    "its servos lock by their own 1 s watchdog meanwhile.\n";

typedef struct {
    const char *config;
    long domain;
    double rate_hz;
    uint32_t timeout_us;
    bridge_timeout_policy_t policy;
    bridge_mode_t mode;
    bool per_joint;
    bool stop_on_bus_loss;
    bool exit_when_gone;
    char ns[NS_MAX + 1]; /* without the leading /; "" for none */
    int realtime; /* SCHED_FIFO priority, 0: none */
    int cpu;      /* -1: not pinned */
} options_t;

static volatile sig_atomic_t stop_signal;

static void on_signal(int sig)
{
    stop_signal = sig;
}

static const char *signal_name(int sig)
{
    return sig == SIGINT ? "SIGINT" : sig == SIGHUP ? "SIGHUP" : sig == SIGQUIT ? "SIGQUIT" : "SIGTERM";
}

/* SIGHUP (a closed terminal or SSH session) and SIGQUIT stop the bridge as SIGTERM does: their
 * default actions would end it with the servos running their last command until their own
 * watchdog. One the bridge was started ignoring (nohup) stays ignored. */
static void install_signals(void)
{
    struct sigaction sa, old;
    static const int unless_ignored[] = {SIGHUP, SIGQUIT};
    unsigned i;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal; /* no SA_RESTART: a blocked ppoll() or sleep returns */
    sigemptyset(&sa.sa_mask);
    (void)sigaction(SIGINT, &sa, NULL);
    (void)sigaction(SIGTERM, &sa, NULL);
    for (i = 0; i < sizeof unless_ignored / sizeof unless_ignored[0]; i++) {
        if (sigaction(unless_ignored[i], NULL, &old) == 0 && old.sa_handler == SIG_IGN)
            continue;
        (void)sigaction(unless_ignored[i], &sa, NULL);
    }
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

/* ROS 2's rules for a node namespace (rcl makes a relative one absolute, rmw validates it):
 * into out without the leading /, "" for the root. NULL when it is valid, else why not. */
static const char *ros_namespace(const char *ns, char out[NS_MAX + 1])
{
    const char *p = ns[0] == '/' ? ns + 1 : ns;
    size_t n = strlen(p);
    if (n == 0u) {
        out[0] = '\0';
        return NULL;
    }
    if (n + 1u > NS_MAX)
        return "longer than 245 characters";
    if (p[n - 1u] == '/')
        return "ends with /";
    for (; *p != '\0'; p++) {
        bool start = p == (ns[0] == '/' ? ns + 1 : ns) || p[-1] == '/';
        if (!((*p >= 'a' && *p <= 'z') || (*p >= 'A' && *p <= 'Z') || (*p >= '0' && *p <= '9') ||
              *p == '_' || *p == '/'))
            return "characters other than letters, digits, _ and /";
        if (*p == '/' && start)
            return "repeated /";
        if (start && *p >= '0' && *p <= '9')
            return "a part starts with a digit";
    }
    memcpy(out, ns[0] == '/' ? ns + 1 : ns, n + 1u);
    return NULL;
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
        } else if (strcmp(a, "--unitree") == 0 || strcmp(a, "--unitree-hg") == 0) {
            o->mode = strcmp(a, "--unitree") == 0 ? MODE_UNITREE_GO : MODE_UNITREE_HG;
            takes = false;
        } else if (strcmp(a, "--per-joint") == 0) {
            o->per_joint = true;
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
        } else if (strcmp(a, "--exit-when-gone") == 0) {
            o->exit_when_gone = true;
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
            const char *why = ros_namespace(val, o->ns);
            if (why != NULL) {
                fprintf(stderr, "j288-dds: --namespace %s: not a ROS 2 namespace: %s\n", val, why);
                return bad_usage("--namespace takes a ROS 2 namespace such as /robot1", NULL);
            }
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
               ev->kind == J288_ROBOT_EV_BUS_UP || ev->kind == J288_ROBOT_EV_BUS_BACK;
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
            bridge_bus_lost(b, k, "vanished (device gone)", true);
            break;
        case J288_ROBOT_EV_BUS_DOWN:
            bridge_bus_lost(b, k, "stopped answering", false);
            break;
        case J288_ROBOT_EV_BUS_BACK:
            bridge_bus_back(b, k);
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
    dds_entity_t domain, participant, state_w, diag_w, cmd_r;
    bridge_mode_t mode;
} dds_io_t;


/* The domain, with Cyclone's Internal/MaxSampleSize at J288_DDS_MAX_SAMPLE_KIB: above the
 * bridge's largest own sample, diagnostics of 64 joints (under 100 KiB: 73 statuses of at most
 * 28 values, strings from a 64 KiB pool, diag.c), far below a sample that would keep the
 * receive thread busy reassembling it. Cyclone drops a larger one at its first fragment.
 * Configured by this setting first, then by $CYCLONEDDS_URI as usual
 * (Cyclone reads a list of sources in order, the later overriding the earlier: a user's own
 * MaxSampleSize wins). */
static dds_entity_t create_domain(dds_domainid_t id)
{
    const char *user = getenv("CYCLONEDDS_URI");
    size_t cap = 200u + (user != NULL ? strlen(user) : 0u);
    char *cfg = malloc(cap);
    dds_entity_t d;
    if (cfg == NULL)
        return DDS_RETCODE_OUT_OF_RESOURCES;
    snprintf(cfg, cap, "<CycloneDDS><Domain id=\"any\"><Internal><MaxSampleSize>%ukB</MaxSampleSize>"
             "</Internal></Domain></CycloneDDS>%s%s", J288_DDS_MAX_SAMPLE_KIB, user != NULL ? "," : "",
             user != NULL ? user : "");
    d = dds_create_domain(id, cfg);
    free(cfg);
    return d;
}

static dds_entity_t topic(dds_entity_t pp, const dds_topic_descriptor_t *desc, const char *ns,
                          const char *name)
{
    char full[TOPIC_MAX];
    snprintf(full, sizeof full, "rt/%s%s%s", ns, *ns != '\0' ? "/" : "", name);
    return dds_create_topic(pp, desc, full, NULL, NULL);
}

/* A copy of q with the USER_DATA ROS 2 gives an endpoint of type t: "typehash=RIHS01_...;". */
static dds_qos_t *with_typehash(const dds_qos_t *q, j288_dds_type_t t)
{
    dds_qos_t *c = dds_create_qos();
    char hash[J288_DDS_TYPEHASH_LEN], ud[J288_DDS_TYPEHASH_LEN + 16];
    int n;
    (void)dds_copy_qos(c, q);
    j288_dds_typehash(t, hash);
    n = snprintf(ud, sizeof ud, "typehash=%s;", hash);
    dds_qset_userdata(c, ud, (size_t)n);
    return c;
}

static dds_entity_t writer(dds_entity_t pp, dds_entity_t tp, const dds_qos_t *q, j288_dds_type_t t)
{
    dds_qos_t *c = with_typehash(q, t);
    dds_entity_t w = dds_create_writer(pp, tp, c, NULL);
    dds_delete_qos(c);
    return w;
}

static dds_entity_t reader(dds_entity_t pp, dds_entity_t tp, const dds_qos_t *q, j288_dds_type_t t)
{
    dds_qos_t *c = with_typehash(q, t);
    dds_entity_t r = dds_create_reader(pp, tp, c, NULL);
    dds_delete_qos(c);
    return r;
}

/* Reliable keep-last-1 writers (they match reliable and best-effort readers alike, so ROS 2's
 * default and sensor-data subscribers both see the state); a best-effort reader keeping the
 * latest 32 commands (it matches every writer; commands are periodic, the newest counts).
 * The writers never block the loop: keep-last 1 already replaces an unacknowledged sample
 * (a frozen reliable reader measured no slower, docs/dds.md), and a max blocking time of 0
 * makes it a guarantee: a write that would wait fails at once and the next cycle's sample
 * takes its place. Every endpoint carries ROS 2's typehash USER_DATA, the participant ROS 2's
 * "enclave=/;" (what rmw_cyclonedds gives a node's). */
static int dds_open(dds_io_t *io, const options_t *o)
{
    static const char enclave[] = "enclave=/;";
    dds_qos_t *wq = dds_create_qos(), *rq = dds_create_qos(), *pq = dds_create_qos();
    dds_entity_t st, dg, cm;
    j288_dds_type_t st_t, cm_t;
    int rc = 0;
    dds_qset_reliability(wq, DDS_RELIABILITY_RELIABLE, 0);
    dds_qset_history(wq, DDS_HISTORY_KEEP_LAST, 1);
    dds_qset_reliability(rq, DDS_RELIABILITY_BEST_EFFORT, 0);
    dds_qset_history(rq, DDS_HISTORY_KEEP_LAST, TAKE_MAX);
    dds_qset_userdata(pq, enclave, sizeof enclave - 1u);
    io->mode = o->mode;
    io->domain = create_domain((dds_domainid_t)o->domain);
    io->participant = io->domain < 0 ? io->domain
                                     : dds_create_participant((dds_domainid_t)o->domain, pq, NULL);
    if (io->participant < 0) {
        fprintf(stderr, "j288-dds: DDS %s on domain %ld: %s\n",
                io->domain < 0 ? "domain (CYCLONEDDS_URI?)" : "participant", o->domain,
                dds_strretcode(io->participant));
        rc = -1;
        goto out;
    }
    if (o->mode == MODE_UNITREE_GO) {
        st = topic(io->participant, &unitree_go_msg_dds__LowState__desc, o->ns, "lowstate");
        cm = topic(io->participant, &unitree_go_msg_dds__LowCmd__desc, o->ns, "lowcmd");
        st_t = J288_DDS_TYPE_GO_LOWSTATE;
        cm_t = J288_DDS_TYPE_GO_LOWCMD;
    } else if (o->mode == MODE_UNITREE_HG) {
        st = topic(io->participant, &unitree_hg_msg_dds__LowState__desc, o->ns, "lowstate");
        cm = topic(io->participant, &unitree_hg_msg_dds__LowCmd__desc, o->ns, "lowcmd");
        st_t = J288_DDS_TYPE_HG_LOWSTATE;
        cm_t = J288_DDS_TYPE_HG_LOWCMD;
    } else {
        st = topic(io->participant, &sensor_msgs_msg_dds__JointState__desc, o->ns, "joint_states");
        cm = topic(io->participant, &sensor_msgs_msg_dds__JointState__desc, o->ns, "joint_command");
        st_t = cm_t = J288_DDS_TYPE_JOINT_STATE;
    }
    dg = topic(io->participant, &diagnostic_msgs_msg_dds__DiagnosticArray__desc, o->ns, "diagnostics");
    io->state_w = writer(io->participant, st, wq, st_t);
    io->diag_w = writer(io->participant, dg, wq, J288_DDS_TYPE_DIAGNOSTIC_ARRAY);
    io->cmd_r = reader(io->participant, cm, rq, cm_t);
    if (st < 0 || cm < 0 || dg < 0 || io->state_w < 0 || io->diag_w < 0 || io->cmd_r < 0) {
        fprintf(stderr, "j288-dds: DDS topics, writers or reader could not be made\n");
        rc = -1;
    }
out:
    dds_delete_qos(wq);
    dds_delete_qos(rq);
    dds_delete_qos(pq);
    return rc;
}

/* A GUID as ROS 2 prints a GID: 16 bytes in hex, dot separated. */
static void guid_text(const uint8_t v[16], char out[BRIDGE_GUID_LEN])
{
    unsigned k;
    for (k = 0; k < 16u; k++)
        snprintf(out + 3u * k, 4u, "%02x%s", v[k], k < 15u ? "." : "");
}

/* The GUIDs of the writers seen lately, by Cyclone's instance handle (a writer's GUID is
 * looked up once, while it is matched). */
#define WRITERS_KEPT 16u
static struct {
    uint64_t handle[WRITERS_KEPT];
    char guid[WRITERS_KEPT][BRIDGE_GUID_LEN];
    unsigned next;
} writers;

static const char *writer_guid(dds_entity_t rd, dds_instance_handle_t ih)
{
    dds_builtintopic_endpoint_t *ep;
    unsigned k;
    for (k = 0; k < WRITERS_KEPT; k++)
        if (writers.handle[k] == ih && ih != 0u)
            return writers.guid[k];
    k = writers.next;
    writers.next = (writers.next + 1u) % WRITERS_KEPT;
    writers.handle[k] = ih;
    ep = dds_get_matched_publication_data(rd, ih);
    if (ep != NULL) {
        guid_text(ep->key.v, writers.guid[k]);
        dds_builtintopic_free_endpoint(ep);
    } else {
        snprintf(writers.guid[k], sizeof writers.guid[k], "unknown (no longer matched)");
    }
    return writers.guid[k];
}

/* Every command waiting, oldest first. */
static void take_commands(bridge_t *b, const dds_io_t *io)
{
    void *samples[TAKE_MAX] = {NULL};
    dds_sample_info_t info[TAKE_MAX];
    dds_return_t n = dds_take(io->cmd_r, samples, info, TAKE_MAX, TAKE_MAX);
    uint32_t now = j288_robot_now_us();
    dds_return_t i;
    for (i = 0; i < n; i++) {
        bridge_writer_t w;
        if (!info[i].valid_data)
            continue;
        w.id = info[i].publication_handle;
        w.guid = writer_guid(io->cmd_r, info[i].publication_handle);
        if (io->mode == MODE_UNITREE_GO)
            bridge_take_lowcmd(b, samples[i], &w, now);
        else if (io->mode == MODE_UNITREE_HG)
            bridge_take_hg_lowcmd(b, samples[i], &w, now);
        else
            bridge_take_command(b, samples[i], &w, now);
    }
    if (n > 0)
        (void)dds_return_loan(io->cmd_r, samples, n);
}

/* ---- Cyclone's log: the samples it drops ---- */

/* Cyclone logs (a warning, from its receive thread) each sample it drops: larger than the
 * MaxSampleSize the bridge sets (dds_open), or outside the bounds of its types (sensor_msgs.idl).
 * The sink counts those and keeps the writer's GUID for the loop to pick up; every other line
 * goes to stderr as Cyclone's own sink writes it. */
static struct {
    pthread_mutex_t lock;
    uint32_t count;
    char guid[BRIDGE_GUID_LEN];
} drops = {PTHREAD_MUTEX_INITIALIZER, 0u, ""};

/* The writer's GUID in a line about a sample Cyclone dropped (its PGUIDFMT, four words in
 * hex), or NULL when the line is about something else: "dropping oversize (N > MAX) sample S
 * from remote writer G ..." (larger than MaxSampleSize, at its first fragment) or
 * "data(application, ...): G #S: deserialization ... failed" (outside the types' bounds). */
static const char *dropped_writer(const char *msg)
{
    const char *g;
    if (strstr(msg, "dropping oversize (") != NULL && (g = strstr(msg, "from remote writer ")) != NULL)
        return g + strlen("from remote writer ");
    if (strstr(msg, ": deserialization ") != NULL && (g = strstr(msg, "): ")) != NULL)
        return g + 3;
    return NULL;
}

static void log_sink(void *arg, const dds_log_data_t *d)
{
    unsigned w[4];
    const char *g = dropped_writer(d->message);
    (void)arg;
    if (g != NULL && sscanf(g, "%x:%x:%x:%x", &w[0], &w[1], &w[2], &w[3]) == 4) {
        uint8_t v[16];
        unsigned k;
        for (k = 0; k < 16u; k++)
            v[k] = (uint8_t)(w[k / 4u] >> (24u - 8u * (k % 4u)));
        (void)pthread_mutex_lock(&drops.lock);
        drops.count++;
        guid_text(v, drops.guid);
        (void)pthread_mutex_unlock(&drops.lock);
        return;
    }
    (void)fwrite(d->message - d->hdrsize, 1, d->hdrsize + d->size + 1u, stderr); /* and its \n */
}

/* The drops since the last call, to the bridge. */
static void collect_drops(bridge_t *b)
{
    uint32_t n;
    char guid[BRIDGE_GUID_LEN];
    (void)pthread_mutex_lock(&drops.lock);
    n = drops.count;
    drops.count = 0;
    memcpy(guid, drops.guid, sizeof guid);
    (void)pthread_mutex_unlock(&drops.lock);
    bridge_dropped(b, n, guid);
}

/* CLOCK_MONOTONIC in seconds (the runner's microsecond clock wraps after 71 minutes). */
static double mono_s(void)
{
    struct timespec ts;
    (void)clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void publish_state(bridge_t *b, const dds_io_t *io, double start_s)
{
    uint32_t tick_ms = (uint32_t)(uint64_t)((mono_s() - start_s) * 1000.0);
    if (io->mode == MODE_UNITREE_GO) {
        static unitree_go_msg_dds__LowState_ ls;
        bridge_fill_lowstate(b, &ls, tick_ms);
        (void)dds_write(io->state_w, &ls);
    } else if (io->mode == MODE_UNITREE_HG) {
        static unitree_hg_msg_dds__LowState_ hs;
        bridge_fill_hg_lowstate(b, &hs, tick_ms);
        (void)dds_write(io->state_w, &hs);
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

/* The STATUS= line systemd shows (systemctl status): the cycle rate since the previous one. */
typedef struct {
    const j288_robot_t *robot;
    const bridge_t *bridge;
    uint32_t cycles;
    double at_s;
} status_ctx_t;

static void service_status(void *ctx, char *buf, unsigned cap)
{
    status_ctx_t *c = ctx;
    j288_robot_stats_t rs;
    double now = mono_s(), dt = now - c->at_s;
    unsigned k;
    uint32_t refused = 0;
    (void)j288_robot_stats(c->robot, &rs);
    for (k = 0; k < BRIDGE_NCAUSES; k++)
        refused += c->bridge->refused[k];
    snprintf(buf, cap, "%.0f cycles/s, %lu cycles, %u joints on %u buses, %lu commands, %lu refused",
             dt > 0 ? (double)(rs.cycles - c->cycles) / dt : 0.0, (unsigned long)rs.cycles,
             j288_robot_njoints(c->robot), j288_robot_nbuses(c->robot),
             (unsigned long)c->bridge->messages, (unsigned long)refused);
    c->cycles = rs.cycles;
    c->at_s = now;
}

static int run(const options_t *o)
{
    static const char *const mode_topics[] = {"rt/joint_states + rt/joint_command",
                                              "rt/lowstate + rt/lowcmd (unitree_go)",
                                              "rt/lowstate + rt/lowcmd (unitree_hg)"};
    static j288_robot_config_t cfg;
    static j288_robot_t robot;
    static bridge_t b;
    static pending_t pending;
    char err[J288_ROBOT_CONFIG_ERROR_MAX], line[NS_MAX + 256u]; /* the longest namespace fits */
    j288_robot_options_t ro;
    dds_io_t io;
    status_ctx_t sc;
    uint32_t period_us = o->rate_hz > 0 ? (uint32_t)(1e6 / o->rate_hz + 0.5) : 0u;
    unsigned slots = o->mode == MODE_UNITREE_GO ? J288_DDS_UNITREE_MOTORS : J288_DDS_HG_MOTORS;
    uint32_t last_diag;
    double start_s;
    int rc, status = 0;

    (void)service_start();
    if (j288_robot_config_load(o->config, &cfg, err, sizeof err) != 0) {
        fprintf(stderr, "j288-dds: %s\n", err);
        return 1;
    }
    if (o->mode != MODE_ROS && cfg.njoints > slots) {
        fprintf(stderr, "j288-dds: %s: %u joints, LowCmd_ has %u motors\n",
                o->mode == MODE_UNITREE_GO ? "--unitree" : "--unitree-hg", (unsigned)cfg.njoints,
                slots);
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
    dds_set_log_sink(log_sink, NULL);
    if (dds_open(&io, o) != 0) {
        j288_robot_close(&robot);
        if (io.domain > 0)
            (void)dds_delete(io.domain);
        return 1;
    }
    bridge_init(&b, &robot, &cfg, o->timeout_us, o->policy, !o->per_joint);
    snprintf(line, sizeof line, "%u joints on %u buses, domain %ld, %s%s%s, %s, %s",
             j288_robot_njoints(&robot), j288_robot_nbuses(&robot), o->domain, mode_topics[o->mode],
             o->ns[0] != '\0' ? " in namespace /" : "", o->ns, o->rate_hz > 0 ? "paced" : "back to back",
             o->per_joint ? "commands per joint" : "commands all or nothing");
    fprintf(stderr, "j288-dds: %s\n", line);
    start_s = mono_s();
    sc.robot = &robot;
    sc.bridge = &b;
    sc.cycles = 0;
    sc.at_s = start_s;
    last_diag = j288_robot_now_us();
    publish_diagnostics(&b, &io);
    service_ready(line);
    j288_robot_timing_reset(&robot);
    (void)j288_robot_pace(&robot, period_us); /* the schedule starts with the first cycle */
    while (stop_signal == 0) {
        take_commands(&b, &io);
        collect_drops(&b);
        bridge_check_timeouts(&b, j288_robot_now_us());
        /* (with every bus gone the cycle waits for the next reopen attempt, 0.2 s at most) */
        rc = j288_robot_cycle(&robot, 0, NULL);
        handle_events(&b, &pending);
        if (rc == J288_ERR_ABORTED)
            break;
        if (rc == J288_ERR_OFFLINE && o->exit_when_gone && every_bus_gone(&robot)) {
            fprintf(stderr, "j288-dds: every bus is gone (--exit-when-gone): %s\n",
                    j288_robot_error(&robot));
            status = 1;
            break;
        }
        bridge_every_bus_gone(&b, every_bus_gone(&robot));
        if (rc == J288_ERR_OFFLINE && o->stop_on_bus_loss) /* the runner locked every bus */
            bridge_stopped(&b, j288_robot_error(&robot));
        publish_state(&b, &io, start_s);
        if ((uint32_t)(j288_robot_now_us() - last_diag) >= DIAG_PERIOD_US) {
            last_diag = j288_robot_now_us();
            publish_diagnostics(&b, &io);
        }
        service_tick((uint64_t)(mono_s() * 1e6), service_status, &sc);
        /* absolute deadlines, j288_rt.h (every bus gone: the next cycle waits for one) */
        if (j288_robot_pace(&robot, period_us) == J288_ERR_ABORTED)
            break;
    }
    if (stop_signal != 0) {
        char why[64];
        snprintf(why, sizeof why, "%s: locking every bus", signal_name(stop_signal));
        service_stopping(why);
        rc = j288_robot_stop(&robot); /* again after an abort: harmless, and the cycle may not
                                         have seen the flag */
        fprintf(stderr, "j288-dds: %s: every bus locked (%s)\n", signal_name(stop_signal),
                rc == J288_OK ? "broadcast lock sent"
                : every_bus_gone(&robot) ? "every bus is gone: nothing to send"
                                         : j288_strerror(rc));
        publish_diagnostics(&b, &io);
    } else {
        service_stopping("every bus is gone");
    }
    print_summary(&robot, start_s);
    j288_robot_close(&robot);
    (void)dds_delete(io.domain);
    dds_set_log_sink(NULL, NULL);
    return status;
}

int main(int argc, char **argv)
{
    options_t o;
    bool done = false;
    int rc = parse(argc, argv, &o, &done);
    if (rc != 0 || done)
        return rc;
    install_signals();
    return run(&o);
}
