/* diag.c - rt/diagnostics: one DiagnosticStatus for the bridge, one per bus, one per joint
 * (its servo), each with key/value pairs. Strings live in a fixed pool owned here. */
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "bridge.h"

#define DIAG_MAX_STATUS (2u + J288_ROBOT_MAX_BUSES + J288_ROBOT_MAX_JOINTS) /* bridge, loop */
#define DIAG_MAX_VALUES 28u
#define DIAG_POOL (64u * 1024u)

enum { LEVEL_OK = 0, LEVEL_WARN = 1, LEVEL_ERROR = 2, LEVEL_STALE = 3 };

static struct {
    diagnostic_msgs_msg_dds__DiagnosticStatus_ status[DIAG_MAX_STATUS];
    diagnostic_msgs_msg_dds__KeyValue_ kv[DIAG_MAX_STATUS][DIAG_MAX_VALUES];
    char pool[DIAG_POOL];
    size_t used;
} d;

/* A formatted string in the pool ("" once the pool is full: a diagnostic is never worth a
 * crash). */
static char *str(const char *fmt, ...)
{
    va_list ap;
    char *s = d.pool + d.used;
    size_t room = DIAG_POOL - d.used;
    int n;
    if (room < 2u)
        return d.pool + DIAG_POOL - 1u;
    va_start(ap, fmt);
    n = vsnprintf(s, room, fmt, ap);
    va_end(ap);
    if (n < 0 || (size_t)n >= room) {
        s[0] = '\0';
        return s;
    }
    d.used += (size_t)n + 1u;
    return s;
}

static diagnostic_msgs_msg_dds__DiagnosticStatus_ *status(diagnostic_msgs_msg_dds__DiagnosticArray_ *m,
                                                          uint8_t level, char *name, char *hw)
{
    uint32_t i = m->status._length++;
    diagnostic_msgs_msg_dds__DiagnosticStatus_ *s = &d.status[i];
    memset(s, 0, sizeof *s);
    s->level = level;
    s->name = name;
    s->hardware_id = hw;
    s->message = str("");
    s->values._buffer = d.kv[i];
    return s;
}

static void kv(diagnostic_msgs_msg_dds__DiagnosticStatus_ *s, const char *key, char *value)
{
    diagnostic_msgs_msg_dds__KeyValue_ *p;
    if (s->values._length >= DIAG_MAX_VALUES)
        return;
    p = &s->values._buffer[s->values._length++];
    p->key = (char *)(uintptr_t)key;
    p->value = value;
    s->values._maximum = s->values._length;
}

/* A time of the runner's clock (j288_robot_now_us()) as UTC wall-clock time, ISO 8601 to the
 * millisecond ("2024-05-01T12:00:01.234Z"), and how long ago it was (s). */
static char *wall_time(uint32_t at_us, double *ago_s)
{
    struct timespec now;
    struct tm tm;
    time_t sec;
    double t;
    char day[32];
    *ago_s = (double)(uint32_t)(j288_robot_now_us() - at_us) * 1e-6;
    (void)clock_gettime(CLOCK_REALTIME, &now);
    t = (double)now.tv_sec + 1e-9 * (double)now.tv_nsec - *ago_s;
    sec = (time_t)t;
    if (gmtime_r(&sec, &tm) == NULL || strftime(day, sizeof day, "%Y-%m-%dT%H:%M:%S", &tm) == 0u)
        return str("?");
    return str("%s.%03dZ", day, (int)((t - (double)sec) * 1000.0));
}

/* The buses lost now (down or gone), named, with when ("" when none); *gone: how many are gone,
 * *n: how many lost. */
static char *lost_buses(bridge_t *b, unsigned *n, unsigned *gone)
{
    char *s = str(""), *w;
    unsigned i;
    double ago;
    *n = *gone = 0;
    for (i = 0; i < j288_robot_nbuses(b->robot); i++) {
        j288_robot_bus_stats_t bs;
        if (j288_robot_bus_stats(b->robot, i, &bs) != J288_OK || bs.up)
            continue;
        w = wall_time(bs.lost_at_us, &ago);
        s = str("%s%sbus %s %s at %s", s, (*n)++ > 0u ? "; " : "", j288_robot_bus_name(b->robot, i),
                bs.gone ? "vanished" : "stopped answering", w);
        *gone += bs.gone ? 1u : 0u;
    }
    return s;
}

static void bridge_status(bridge_t *b, diagnostic_msgs_msg_dds__DiagnosticArray_ *m)
{
    unsigned c, timed_out = 0, j, nlost, ngone;
    uint32_t total = 0, refused;
    diagnostic_msgs_msg_dds__DiagnosticStatus_ *s;
    char *lost = lost_buses(b, &nlost, &ngone);
    for (c = 0; c < BRIDGE_NCAUSES; c++)
        total += b->refused[c];
    total += b->dropped;
    refused = total - b->refused_reported; /* a warning while refusals go on, not forever */
    b->refused_reported = total;
    for (j = 0; j < j288_robot_njoints(b->robot); j++)
        timed_out += b->joint[j].mode == JOINT_TIMED_OUT;
    s = status(m, (b->stopped || nlost != 0u) ? LEVEL_ERROR
                  : (timed_out != 0u || refused != 0u) ? LEVEL_WARN : LEVEL_OK,
               str("j288-dds: bridge"), str("j288-dds"));
    s->message = b->stopped ? str("stopped: %s", b->stop_reason)
                 : ngone == j288_robot_nbuses(b->robot)
                     ? str("every bus is gone (%s): waiting for the devices to reappear", lost)
                 : nlost != 0u ? str("%s: its joints publish NaN", lost)
                 : timed_out != 0u ? str("%u joint(s) timed out", timed_out)
                 : refused != 0u ? str("%lu command(s) refused or dropped since the last report",
                                       (unsigned long)refused)
                                : str("ok");
    kv(s, "buses_lost", str("%u", nlost));
    if (nlost != 0u)
        kv(s, "lost", lost);
    kv(s, "messages", str("%lu", (unsigned long)b->messages));
    kv(s, "timeout_ms", str("%lu", (unsigned long)(b->timeout_us / 1000u)));
    kv(s, "refused", str("%lu", (unsigned long)(total - b->dropped)));
    kv(s, "refused_whole_messages", str("%lu", (unsigned long)b->refused_whole));
    kv(s, "atomic", str("%s", b->atomic ? "true" : "false"));
    kv(s, "timeout_policy", str("%s", b->policy == TIMEOUT_HOLD ? "hold" : "lock"));
    kv(s, "dropped_by_dds", str("%lu", (unsigned long)b->dropped));
    if (b->dropped != 0u)
        kv(s, "dropped_from", str("%s", b->dropped_guid));
    for (c = 0; c < BRIDGE_NCAUSES; c++)
        if (b->refused[c] != 0u)
            kv(s, bridge_cause_name((bridge_cause_t)c), str("%lu", (unsigned long)b->refused[c]));
}

static void bus_status(bridge_t *b, unsigned bus, diagnostic_msgs_msg_dds__DiagnosticArray_ *m)
{
    j288_robot_bus_stats_t bs;
    const char *name = j288_robot_bus_name(b->robot, bus);
    diagnostic_msgs_msg_dds__DiagnosticStatus_ *s;
    char *lost_at = str("never"), *back_at = str("never");
    double lost_ago = 0.0, back_ago = 0.0;
    (void)j288_robot_bus_stats(b->robot, bus, &bs);
    if (bs.down_events + bs.gone_events != 0u)
        lost_at = wall_time(bs.lost_at_us, &lost_ago);
    if (bs.up_events + bs.reopens != 0u)
        back_at = wall_time(bs.back_at_us, &back_ago);
    s = status(m, bs.gone ? LEVEL_ERROR : bs.up ? LEVEL_OK : LEVEL_ERROR,
               str("j288-dds: bus %s", name), str("bus:%s", name));
    s->message = bs.gone ? str("gone: its device vanished at %s (%.1f s ago); reopened when it "
                               "reappears at its path", lost_at, lost_ago)
                 : !bs.up ? str("down: no reply since %s (%.1f s ago)", lost_at, lost_ago)
                          : str("up");
    kv(s, "sweeps", str("%lu", (unsigned long)bs.sweeps));
    kv(s, "empty_sweeps", str("%lu", (unsigned long)bs.empty_sweeps));
    kv(s, "down_events", str("%lu", (unsigned long)bs.down_events));
    kv(s, "gone_events", str("%lu", (unsigned long)bs.gone_events));
    kv(s, "lost_at", lost_at);
    if (bs.down_events + bs.gone_events != 0u)
        kv(s, "lost_s_ago", str("%.1f", lost_ago));
    kv(s, "back_at", back_at);
    kv(s, "reopens", str("%lu", (unsigned long)bs.reopens));
    kv(s, "reopen_attempts", str("%lu", (unsigned long)bs.reopen_attempts));
    kv(s, "last_sweep_us", str("%lu", (unsigned long)bs.last_sweep_us));
    kv(s, "worst_sweep_us", str("%lu", (unsigned long)bs.worst_sweep_us));
}

/* The loop's timing (host/j288_rt.h): a warning while deadlines are being missed. */
static void loop_status(bridge_t *b, diagnostic_msgs_msg_dds__DiagnosticArray_ *m)
{
    static uint32_t missed_reported; /* at the previous diagnostics */
    j288_rt_report_t t;
    uint32_t missed;
    diagnostic_msgs_msg_dds__DiagnosticStatus_ *s;
    (void)j288_robot_timing(b->robot, &t);
    missed = t.missed - missed_reported;
    missed_reported = t.missed;
    s = status(m, missed != 0u ? LEVEL_WARN : LEVEL_OK, str("j288-dds: loop"), str("j288-dds"));
    s->message = missed != 0u ? str("%lu deadline(s) missed since the last report",
                                    (unsigned long)missed)
                              : str("ok");
    kv(s, "cycles", str("%lu", (unsigned long)t.cycles));
    kv(s, "period_us", str("%lu", (unsigned long)t.period_us));
    kv(s, "missed_deadlines", str("%lu", (unsigned long)t.missed));
    kv(s, "skipped_periods", str("%lu", (unsigned long)t.skipped));
    kv(s, "cut_cycles", str("%lu", (unsigned long)t.cut));
    kv(s, "lateness_count", str("%lu", (unsigned long)t.lateness.count));
    kv(s, "lateness_p50_us", str("%lu", (unsigned long)t.lateness.p50_us));
    kv(s, "lateness_p99_us", str("%lu", (unsigned long)t.lateness.p99_us));
    kv(s, "lateness_p99_9_us", str("%lu", (unsigned long)t.lateness.p999_us));
    kv(s, "lateness_max_us", str("%lu", (unsigned long)t.lateness.max_us));
    kv(s, "duration_p50_us", str("%lu", (unsigned long)t.duration.p50_us));
    kv(s, "duration_p99_us", str("%lu", (unsigned long)t.duration.p99_us));
    kv(s, "duration_p99_9_us", str("%lu", (unsigned long)t.duration.p999_us));
    kv(s, "duration_max_us", str("%lu", (unsigned long)t.duration.max_us));
    kv(s, "priority", str("%ld", (long)t.priority));
    kv(s, "cpu", str("%ld", (long)t.cpu));
    kv(s, "memory_locked", str("%s", t.memory_locked != 0u ? "true" : "false"));
}

static const char *mode_name(bridge_joint_mode_t mo)
{
    switch (mo) {
    case JOINT_FOLLOWING: return "following";
    case JOINT_TIMED_OUT: return "timed out";
    case JOINT_LOCKED: return "locked by command";
    default: return "idle (lock)";
    }
}

static void joint_status(bridge_t *b, unsigned j, diagnostic_msgs_msg_dds__DiagnosticArray_ *m)
{
    j288_robot_state_t st;
    j288_robot_joint_stats_t js;
    const char *name = j288_robot_joint_name(b->robot, j);
    const char *bus = j288_robot_bus_name(b->robot, (unsigned)j288_robot_joint_bus(b->robot, j));
    uint8_t level;
    diagnostic_msgs_msg_dds__DiagnosticStatus_ *s;
    (void)j288_robot_read(b->robot, j, &st);
    (void)j288_robot_joint_stats(b->robot, j, &js);
    level = !st.online ? LEVEL_STALE
            : st.faults != 0u ? LEVEL_ERROR
            : (st.warnings != 0u || b->joint[j].mode == JOINT_TIMED_OUT) ? LEVEL_WARN
                                                                        : LEVEL_OK;
    s = status(m, level, str("j288-dds: joint %s", name),
               str("bus:%s id:%d", bus, j288_robot_joint_id(b->robot, j)));
    s->message = str("%s, %s%s", st.online ? "online" : "offline", mode_name(b->joint[j].mode),
                     st.faults != 0u ? ", faults" : "");
    kv(s, "online", str("%s", st.online ? "true" : "false"));
    kv(s, "command", str("%s", mode_name(b->joint[j].mode)));
    kv(s, "commands_accepted", str("%lu", (unsigned long)b->joint[j].accepted));
    kv(s, "owner", str("%s", b->joint[j].owned ? b->joint[j].owner_guid : "none"));
    kv(s, "refused_other_writer", str("%lu", (unsigned long)b->joint[j].refused_other));
    if (b->joint[j].refused_other != 0u)
        kv(s, "other_writer", str("%s", b->joint[j].other_guid));
    kv(s, "timeouts", str("%lu", (unsigned long)b->joint[j].timeouts));
    kv(s, "watchdog_trips", str("%lu", (unsigned long)b->joint[j].watchdog));
    kv(s, "faults", str("0x%06lx", (unsigned long)st.faults));
    kv(s, "warnings", str("0x%02x", (unsigned)st.warnings));
    kv(s, "case_temp_c", str("%.1f", st.case_temp_c));
    kv(s, "winding_temp_c", str("%.1f", st.winding_temp_c));
    kv(s, "voltage_v", str("%.2f", st.voltage_v));
    kv(s, "angle_known", str("%s", st.known ? "true" : "false"));
    kv(s, "fresh_cycles", str("%lu", (unsigned long)js.fresh_cycles));
    kv(s, "stale_cycles", str("%lu", (unsigned long)js.stale_cycles));
    kv(s, "transactions", str("%lu", (unsigned long)js.servo.transactions));
    kv(s, "timeouts_wire", str("%lu", (unsigned long)js.servo.timeouts));
    kv(s, "crc_errors", str("%lu", (unsigned long)js.servo.crc_errors));
    kv(s, "wrong_id", str("%lu", (unsigned long)js.servo.wrong_id));
    kv(s, "other_errors", str("%lu", (unsigned long)js.servo.other_errors));
    kv(s, "latency_us", str("%lu", (unsigned long)js.servo.last_latency_us));
    kv(s, "worst_latency_us", str("%lu", (unsigned long)js.servo.worst_latency_us));
}

void bridge_fill_diagnostics(bridge_t *b, diagnostic_msgs_msg_dds__DiagnosticArray_ *m)
{
    unsigned i;
    d.used = 0;
    memset(m, 0, sizeof *m);
    bridge_stamp_now(&m->header.stamp); /* frame_id: empty */
    m->status._buffer = d.status;
    bridge_status(b, m);
    loop_status(b, m);
    for (i = 0; i < j288_robot_nbuses(b->robot); i++)
        bus_status(b, i, m);
    for (i = 0; i < j288_robot_njoints(b->robot); i++)
        joint_status(b, i, m);
    m->status._maximum = m->status._length;
}
