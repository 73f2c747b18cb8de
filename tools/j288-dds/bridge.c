/* bridge.c - see bridge.h. A command becomes a plan (one entry per joint it names), every
 * entry is checked, then the plan is applied: all of it, or (atomic) none of it when any entry
 * was refused. */
#include "bridge.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "unitree_crc.h"

/* unitree_sdk2's "no position / no velocity control" markers (PosStopF, VelStopF). */
#define UNITREE_POS_STOP 2.146e9f
#define UNITREE_VEL_STOP 16000.0f

/* unitree_sdk2's motor modes in LowCmd_ (docs/dds.md has the table): 0 off, 1 servo (FOC,
 * Go2, B2W, H1's weaker motors, every unitree_hg robot), 0x0A servo (B2, H1's stronger
 * motors). */
#define UNITREE_MODE_OFF 0x00u
#define UNITREE_MODE_FOC 0x01u
#define UNITREE_MODE_SERVO 0x0Au

/* The names must fit the state sample's bounded strings (sensor_msgs.idl). */
typedef char bridge_name_fits[BRIDGE_NAME_LEN >= J288_ROBOT_CONFIG_NAME_MAX ? 1 : -1];

static const char *const cause_names[BRIDGE_NCAUSES] = {
    "array lengths differ",   "no joint or no values",  "unknown joint name",
    "joint named twice",      "NaN or infinite value",  "target outside the joint's limits",
    "joint angle not known yet", "bad crc",             "motor mode not 0, 1 or 0x0A",
    "robot stopped after a bus loss", "joint commanded by another writer",
    "the joint's bus is gone", "refused by the joint layer",
};

const char *bridge_cause_name(bridge_cause_t c)
{
    return (unsigned)c < BRIDGE_NCAUSES ? cause_names[c] : "?";
}

void bridge_init(bridge_t *b, j288_robot_t *robot, const j288_robot_config_t *cfg,
                 uint32_t timeout_us, bridge_timeout_policy_t policy, bool atomic)
{
    unsigned j;
    memset(b, 0, sizeof *b);
    b->robot = robot;
    b->cfg = cfg;
    b->timeout_us = timeout_us;
    b->policy = policy;
    b->atomic = atomic;
    for (j = 0; j < j288_robot_njoints(robot); j++)
        snprintf(b->names[j], sizeof b->names[j], "%s", j288_robot_joint_name(robot, j));
}

void bridge_refuse(bridge_t *b, bridge_cause_t c, const char *detail)
{
    if (b->refused[c]++ == 0u)
        fprintf(stderr, "j288-dds: command refused: %s: %s (further ones are counted in "
                        "diagnostics, not reported)\n", bridge_cause_name(c), detail);
}

static bridge_cause_t cause_of(int rc)
{
    switch (rc) {
    case J288_ERR_NOT_FINITE: return BRIDGE_CAUSE_NOT_FINITE;
    case J288_ERR_LIMIT_POS: case J288_ERR_LIMIT_SPEED: case J288_ERR_LIMIT_TORQUE:
    case J288_ERR_RANGE_POS: case J288_ERR_RANGE_SPEED: case J288_ERR_RANGE_TAU:
    case J288_ERR_RANGE_KP: case J288_ERR_RANGE_KD:
        return BRIDGE_CAUSE_LIMIT;
    case J288_ERR_ANGLE_UNKNOWN: return BRIDGE_CAUSE_UNKNOWN_ANGLE;
    case J288_ERR_OFFLINE: return BRIDGE_CAUSE_BUS_GONE;
    default: return BRIDGE_CAUSE_OTHER;
    }
}

/* ---- plans ---- */

typedef struct {
    unsigned joint;
    bool lock;               /* unitree mode 0: lock (a joint that was driven) */
    j288_robot_target_t t;   /* otherwise: the target */
} plan_entry_t;

typedef struct {
    plan_entry_t e[J288_ROBOT_MAX_JOINTS];
    bool refused[J288_ROBOT_MAX_JOINTS];
    unsigned n, nrefused;
} plan_t;

/* The joint's angle now, and its gains: the config's, else the runner's defaults (the ones
 * its hold uses too). */
static void current(const bridge_t *b, unsigned j, double *pos, double *kp, double *kd)
{
    const j288_robot_config_joint_t *cj = &b->cfg->joint[j];
    j288_robot_state_t st;
    (void)j288_robot_read(b->robot, j, &st);
    *pos = st.pos;
    *kp = cj->has_kp ? cj->kp : J288_ROBOT_DEFAULT_KP;
    *kd = cj->has_kd ? cj->kd : J288_ROBOT_DEFAULT_KD;
}

static bool owned_by_other(const bridge_t *b, unsigned j, const bridge_writer_t *w, uint32_t now_us)
{
    const bridge_joint_t *bj = &b->joint[j];
    return bj->owned && bj->owner != w->id && (uint32_t)(now_us - bj->owner_us) <= b->timeout_us;
}

/* Check entry k; false (counted, the entry marked) when it is refused. */
static bool check_entry(bridge_t *b, plan_t *p, unsigned k, const bridge_writer_t *w, uint32_t now_us)
{
    const plan_entry_t *e = &p->e[k];
    const j288_robot_target_t *t = &e->t;
    const char *name = j288_robot_joint_name(b->robot, e->joint);
    char detail[200];
    int rc = J288_OK;
    bridge_cause_t cause = BRIDGE_CAUSE_OTHER;
    if (owned_by_other(b, e->joint, w, now_us)) {
        bridge_joint_t *bj = &b->joint[e->joint];
        bj->refused_other++;
        snprintf(bj->other_guid, sizeof bj->other_guid, "%s", w->guid);
        snprintf(detail, sizeof detail, "joint %s: writer %s; it is commanded by %s", name, w->guid,
                 bj->owner_guid);
        cause = BRIDGE_CAUSE_OWNED;
    } else if (e->lock) {
        return true;
    } else if (!isfinite(t->pos) || !isfinite(t->speed) || !isfinite(t->torque) ||
               !isfinite(t->kp) || !isfinite(t->kd)) {
        snprintf(detail, sizeof detail, "joint %s", name);
        cause = BRIDGE_CAUSE_NOT_FINITE;
    } else {
        rc = j288_robot_check_target(b->robot, e->joint, t);
        if (rc == J288_OK)
            return true;
        snprintf(detail, sizeof detail, "joint %s: pos %.4g speed %.4g torque %.4g: %s", name, t->pos,
                 t->speed, t->torque, j288_strerror(rc));
        cause = cause_of(rc);
    }
    p->refused[k] = true;
    p->nrefused++;
    bridge_refuse(b, cause, detail);
    return false;
}

static void take_ownership(bridge_t *b, unsigned j, const bridge_writer_t *w, uint32_t now_us)
{
    bridge_joint_t *bj = &b->joint[j];
    if (!bj->owned || bj->owner != w->id)
        snprintf(bj->owner_guid, sizeof bj->owner_guid, "%s", w->guid);
    bj->owned = true;
    bj->owner = w->id;
    bj->owner_us = now_us;
}

/* One checked entry into the runner. */
static void apply_entry(bridge_t *b, const plan_entry_t *e, const bridge_writer_t *w, uint32_t now_us)
{
    bridge_joint_t *bj = &b->joint[e->joint];
    int rc;
    if (e->lock) {
        if (bj->mode == JOINT_IDLE)
            return; /* never driven: at lock already, and nobody's */
        if (bj->mode != JOINT_LOCKED)
            (void)j288_robot_lock(b->robot, e->joint);
        bj->mode = JOINT_LOCKED;
        take_ownership(b, e->joint, w, now_us);
        return;
    }
    rc = j288_robot_set_target(b->robot, e->joint, &e->t);
    if (rc != J288_OK) { /* checked a moment ago: only a bus lost in between gets here */
        char detail[160];
        snprintf(detail, sizeof detail, "joint %s: %s", j288_robot_joint_name(b->robot, e->joint),
                 j288_strerror(rc));
        bridge_refuse(b, cause_of(rc), detail);
        return;
    }
    bj->mode = JOINT_FOLLOWING;
    bj->last_cmd_us = now_us;
    bj->accepted++;
    take_ownership(b, e->joint, w, now_us);
}

static void run_plan(bridge_t *b, plan_t *p, const bridge_writer_t *w, uint32_t now_us)
{
    unsigned k;
    for (k = 0; k < p->n; k++)
        (void)check_entry(b, p, k, w, now_us);
    if (p->nrefused != 0u && (b->atomic || p->nrefused == p->n)) {
        b->refused_whole++;
        return;
    }
    for (k = 0; k < p->n; k++)
        if (!p->refused[k])
            apply_entry(b, &p->e[k], w, now_us);
}

/* ---- ROS 2 commands ---- */

/* The structure of a command: every name a joint, once; the arrays as long as name. Fills
 * idx[] with joint indices; false (and counted) when the whole message is refused. The name
 * sequence is bounded by the IDL (J288_ROBOT_MAX_JOINTS): DDS drops a longer one. */
static bool check_command(bridge_t *b, const sensor_msgs_msg_dds__JointState_ *m, int *idx)
{
    uint32_t n = m->name._length, i, k;
    char detail[160];
    if (n == 0u || (m->position._length == 0u && m->velocity._length == 0u &&
                    m->effort._length == 0u)) {
        bridge_refuse(b, BRIDGE_CAUSE_EMPTY, n == 0u ? "no name" : "no position, velocity or effort");
        return false;
    }
    if ((m->position._length != 0u && m->position._length != n) ||
        (m->velocity._length != 0u && m->velocity._length != n) ||
        (m->effort._length != 0u && m->effort._length != n)) {
        snprintf(detail, sizeof detail, "%u names, %u positions, %u velocities, %u efforts",
                 (unsigned)n, (unsigned)m->position._length, (unsigned)m->velocity._length,
                 (unsigned)m->effort._length);
        bridge_refuse(b, BRIDGE_CAUSE_LENGTHS, detail);
        return false;
    }
    for (i = 0; i < n; i++) {
        const char *name = m->name._buffer[i];
        int j;
        if (i >= J288_ROBOT_MAX_JOINTS) /* the IDL's bound: unreachable; kept so idx[] cannot
                                           overflow */
            return false;
        j = j288_robot_find_joint(b->robot, name);
        if (j < 0) {
            snprintf(detail, sizeof detail, "'%.64s'", name);
            bridge_refuse(b, BRIDGE_CAUSE_UNKNOWN, detail);
            return false;
        }
        for (k = 0; k < i; k++) {
            if (idx[k] == j) {
                snprintf(detail, sizeof detail, "'%.64s'", name);
                bridge_refuse(b, BRIDGE_CAUSE_DUPLICATE, detail);
                return false;
            }
        }
        idx[i] = j;
    }
    return true;
}

void bridge_take_command(bridge_t *b, const sensor_msgs_msg_dds__JointState_ *m,
                         const bridge_writer_t *w, uint32_t now_us)
{
    static plan_t p;
    int idx[J288_ROBOT_MAX_JOINTS];
    uint32_t i;
    b->messages++;
    if (b->stopped) {
        bridge_refuse(b, BRIDGE_CAUSE_STOPPED, b->stop_reason);
        b->refused_whole++;
        return;
    }
    if (!check_command(b, m, idx)) {
        b->refused_whole++;
        return;
    }
    memset(&p, 0, sizeof p);
    for (i = 0; i < m->name._length; i++) {
        plan_entry_t *e = &p.e[p.n++];
        bool has_pos = m->position._length != 0u, has_vel = m->velocity._length != 0u;
        double kp, kd;
        e->joint = (unsigned)idx[i];
        current(b, e->joint, &e->t.pos, &kp, &kd);
        e->t.kp = has_pos ? kp : 0.0;
        e->t.kd = (has_pos || has_vel) ? kd : 0.0;
        if (has_pos)
            e->t.pos = m->position._buffer[i];
        e->t.speed = has_vel ? m->velocity._buffer[i] : 0.0;
        e->t.torque = m->effort._length != 0u ? m->effort._buffer[i] : 0.0;
    }
    run_plan(b, &p, w, now_us);
}

/* ---- unitree ---- */

/* A motor slot of either LowCmd_, as the plan needs it. */
typedef struct {
    uint8_t mode;
    float q, dq, tau, kp, kd;
} motor_cmd_t;

/* Motor j's command into the plan; false (counted) for an unknown mode. */
static bool plan_motor(bridge_t *b, plan_t *p, unsigned j, const motor_cmd_t *c)
{
    plan_entry_t *e = &p->e[p->n];
    double kp, kd;
    char detail[80];
    if (c->mode != UNITREE_MODE_OFF && c->mode != UNITREE_MODE_FOC && c->mode != UNITREE_MODE_SERVO) {
        snprintf(detail, sizeof detail, "motor %u mode %u", j, (unsigned)c->mode);
        bridge_refuse(b, BRIDGE_CAUSE_BAD_MODE, detail);
        return false;
    }
    p->n++;
    e->joint = j;
    e->lock = c->mode == UNITREE_MODE_OFF;
    if (e->lock)
        return true;
    current(b, j, &e->t.pos, &kp, &kd);
    e->t.kp = c->kp;
    e->t.kd = c->kd;
    if (fabsf(c->q) >= UNITREE_POS_STOP)
        e->t.kp = 0.0; /* no position control: stay where it is */
    else
        e->t.pos = c->q;
    e->t.speed = fabsf(c->dq) >= UNITREE_VEL_STOP ? 0.0 : c->dq;
    e->t.torque = c->tau;
    return true;
}

/* The motors of a LowCmd_ whose crc was checked (ok: crc right). False when nothing of it is
 * to be applied. */
static bool unitree_plan(bridge_t *b, plan_t *p, const motor_cmd_t *mc, unsigned nslots, bool crc_ok,
                         uint32_t got_crc, uint32_t want_crc)
{
    unsigned n = j288_robot_njoints(b->robot), j, bad_modes = 0;
    char detail[80];
    b->messages++;
    memset(p, 0, sizeof *p);
    if (b->stopped) {
        bridge_refuse(b, BRIDGE_CAUSE_STOPPED, b->stop_reason);
        b->refused_whole++;
        return false;
    }
    if (!crc_ok) {
        snprintf(detail, sizeof detail, "crc 0x%08lx, expected 0x%08lx", (unsigned long)got_crc,
                 (unsigned long)want_crc);
        bridge_refuse(b, BRIDGE_CAUSE_BAD_CRC, detail);
        b->refused_whole++;
        return false;
    }
    for (j = 0; j < n && j < nslots; j++)
        bad_modes += plan_motor(b, p, j, &mc[j]) ? 0u : 1u;
    if (bad_modes != 0u && b->atomic) {
        b->refused_whole++;
        return false;
    }
    return true;
}

/* The n motor slots of a LowCmd_ m (unitree_go's or unitree_hg's) into mc[]. */
#define MOTOR_CMDS(mc, m, n)                                                            \
    do {                                                                                \
        unsigned k_;                                                                    \
        for (k_ = 0; k_ < (n); k_++) {                                                  \
            motor_cmd_t t_ = {(m)->motor_cmd[k_].mode, (m)->motor_cmd[k_].q,            \
                              (m)->motor_cmd[k_].dq,   (m)->motor_cmd[k_].tau,          \
                              (m)->motor_cmd[k_].kp,   (m)->motor_cmd[k_].kd};          \
            (mc)[k_] = t_;                                                              \
        }                                                                               \
    } while (0)

void bridge_take_lowcmd(bridge_t *b, const unitree_go_msg_dds__LowCmd_ *m,
                        const bridge_writer_t *w, uint32_t now_us)
{
    static plan_t p;
    motor_cmd_t mc[J288_DDS_UNITREE_MOTORS];
    uint32_t want = j288_dds_lowcmd_crc(m);
    MOTOR_CMDS(mc, m, J288_DDS_UNITREE_MOTORS);
    if (unitree_plan(b, &p, mc, J288_DDS_UNITREE_MOTORS, want == m->crc, m->crc, want))
        run_plan(b, &p, w, now_us);
}

void bridge_take_hg_lowcmd(bridge_t *b, const unitree_hg_msg_dds__LowCmd_ *m,
                           const bridge_writer_t *w, uint32_t now_us)
{
    static plan_t p;
    motor_cmd_t mc[J288_DDS_HG_MOTORS];
    uint32_t want = j288_dds_hg_lowcmd_crc(m);
    MOTOR_CMDS(mc, m, J288_DDS_HG_MOTORS);
    if (unitree_plan(b, &p, mc, J288_DDS_HG_MOTORS, want == m->crc, m->crc, want)) {
        unsigned refused_whole = b->refused_whole;
        run_plan(b, &p, w, now_us);
        if (b->refused_whole == refused_whole)
            b->hg_mode_pr = m->mode_pr;
    }
}

/* ---- after each cycle, events ---- */

void bridge_check_timeouts(bridge_t *b, uint32_t now_us)
{
    unsigned j;
    for (j = 0; j < j288_robot_njoints(b->robot); j++) {
        bridge_joint_t *bj = &b->joint[j];
        int rc = J288_OK;
        if (bj->owned && (uint32_t)(now_us - bj->owner_us) > b->timeout_us)
            bj->owned = false; /* silent for the timeout: anyone may command it now */
        if (bj->mode != JOINT_FOLLOWING || (uint32_t)(now_us - bj->last_cmd_us) <= b->timeout_us)
            continue;
        if (b->policy == TIMEOUT_HOLD)
            rc = j288_robot_hold(b->robot, j);
        if (b->policy == TIMEOUT_LOCK || rc != J288_OK)
            (void)j288_robot_lock(b->robot, j);
        bj->mode = JOINT_TIMED_OUT;
        bj->timeouts++;
        fprintf(stderr, "j288-dds: joint %s: no command for %u ms: %s\n",
                j288_robot_joint_name(b->robot, j), (unsigned)(b->timeout_us / 1000u),
                (b->policy == TIMEOUT_HOLD && rc == J288_OK) ? "holding where it is" : "locked");
    }
}

void bridge_dropped(bridge_t *b, uint32_t n, const char *guid)
{
    if (n == 0u)
        return;
    if (b->dropped == 0u)
        fprintf(stderr, "j288-dds: command samples dropped by DDS before the bridge saw them "
                        "(larger than %u KiB, or than the bridge's types allow: more than %u "
                        "joints, a name longer than %u bytes), from writer %s (further ones are "
                        "counted in diagnostics, not reported)\n",
                (unsigned)J288_DDS_MAX_SAMPLE_KIB, (unsigned)J288_ROBOT_MAX_JOINTS,
                (unsigned)(BRIDGE_NAME_LEN - 1u), guid);
    b->dropped += n;
    snprintf(b->dropped_guid, sizeof b->dropped_guid, "%s", guid);
}

/* Every joint on bus: at lock and nobody's (the runner has it at lock: gone, or back anew). */
static void release_joints(bridge_t *b, unsigned bus)
{
    unsigned j;
    for (j = 0; j < j288_robot_njoints(b->robot); j++) {
        if (j288_robot_joint_bus(b->robot, j) == (int)bus) {
            b->joint[j].mode = JOINT_IDLE;
            b->joint[j].owned = false;
        }
    }
}

void bridge_bus_lost(bridge_t *b, unsigned bus, const char *what, bool gone)
{
    if (bus < J288_ROBOT_MAX_BUSES)
        b->bus_lost[bus]++;
    fprintf(stderr, "j288-dds: bus '%s' %s%s\n", j288_robot_bus_name(b->robot, bus), what,
            gone ? ": its joints publish NaN until it is back; reopened when it reappears" : "");
    if (gone)
        release_joints(b, bus);
}

void bridge_bus_back(bridge_t *b, unsigned bus)
{
    fprintf(stderr, "j288-dds: bus '%s' is back (its device reopened): its joints restart at "
                    "lock until commanded\n", j288_robot_bus_name(b->robot, bus));
    release_joints(b, bus);
}

void bridge_every_bus_gone(bridge_t *b, bool gone)
{
    if (gone == b->all_gone)
        return;
    b->all_gone = gone;
    fprintf(stderr, "j288-dds: %s\n", gone ? "every bus is gone: the bridge stays up, publishing "
                                              "NaN, and reopens each device when it reappears"
                                            : "a bus is back: the robot runs again");
}

void bridge_stopped(bridge_t *b, const char *why)
{
    unsigned j;
    if (b->stopped)
        return;
    b->stopped = true;
    snprintf(b->stop_reason, sizeof b->stop_reason, "%s", why);
    for (j = 0; j < J288_ROBOT_MAX_JOINTS; j++) { /* at lock now: no timeout may hold them again */
        b->joint[j].mode = JOINT_IDLE;
        b->joint[j].owned = false;
    }
    fprintf(stderr, "j288-dds: --stop-on-bus-loss: %s; commands refused until restart\n", why);
}

void bridge_watchdog(bridge_t *b, unsigned joint)
{
    if (joint >= J288_ROBOT_MAX_JOINTS)
        return;
    b->joint[joint].watchdog++;
    fprintf(stderr, "j288-dds: joint %s: the servo's watchdog had tripped (cleared)\n",
            j288_robot_joint_name(b->robot, joint));
}

/* ---- state ---- */

void bridge_stamp_now(builtin_interfaces_msg_dds__Time_ *t)
{
    struct timespec ts;
    (void)clock_gettime(CLOCK_REALTIME, &ts);
    t->sec = (int32_t)ts.tv_sec;
    t->nanosec = (uint32_t)ts.tv_nsec;
}

/* A joint's state, or NaN (ROS's mark of a value not known) for each value that is not the
 * joint's now: not known, or not fresh (frozen data is worse than none to a controller). */
static void state_or_nan(const bridge_t *b, unsigned j, j288_robot_state_t *st)
{
    (void)j288_robot_read(b->robot, j, st);
    if (!st->known || !st->fresh) {
        st->pos = NAN;
        st->speed = NAN;
        st->torque = NAN;
    }
}

void bridge_fill_joint_state(bridge_t *b, sensor_msgs_msg_dds__JointState_ *m)
{
    unsigned n = j288_robot_njoints(b->robot), j;
    for (j = 0; j < n; j++) {
        j288_robot_state_t st;
        state_or_nan(b, j, &st);
        b->pos[j] = st.pos;
        b->vel[j] = st.speed;
        b->eff[j] = st.torque;
    }
    memset(m, 0, sizeof *m);
    bridge_stamp_now(&m->header.stamp);
    m->name._buffer = b->names;
    m->position._buffer = b->pos;
    m->velocity._buffer = b->vel;
    m->effort._buffer = b->eff;
    m->name._length = m->name._maximum = m->position._length = m->position._maximum = n;
    m->velocity._length = m->velocity._maximum = m->effort._length = m->effort._maximum = n;
}

/* unitree_sdk2's uint8: below 0 deg C reads 0, not 200-something (docs/dds.md). */
static uint8_t temp_u8(double c)
{
    return (uint8_t)(c > 255.0 ? 255 : c < 0.0 ? 0 : lround(c));
}

static int16_t temp_i16(double c)
{
    return (int16_t)(c > 32767.0 ? 32767 : c < -32768.0 ? -32768 : lround(c));
}

/* What both LowState_ carry of one joint: its state (NaN as in joint_states), mode (1 while it
 * follows commands) and the cycles its servo gave no reply. */
static void motor_state(bridge_t *b, unsigned j, j288_robot_state_t *st, uint8_t *mode, uint32_t *lost)
{
    j288_robot_joint_stats_t js;
    state_or_nan(b, j, st);
    (void)j288_robot_joint_stats(b->robot, j, &js);
    *mode = (b->joint[j].mode == JOINT_FOLLOWING) ? 1u : 0u;
    *lost = js.stale_cycles;
}

void bridge_fill_lowstate(bridge_t *b, unitree_go_msg_dds__LowState_ *m, uint32_t tick_ms)
{
    unsigned n = j288_robot_njoints(b->robot), j, online = 0;
    double volts = 0.0;
    memset(m, 0, sizeof *m);
    m->head[0] = 0xFEu;
    m->head[1] = 0xEFu;
    m->level_flag = 0xFFu; /* low level */
    m->tick = tick_ms;
    for (j = 0; j < n && j < J288_DDS_UNITREE_MOTORS; j++) {
        unitree_go_msg_dds__MotorState_ *s = &m->motor_state[j];
        j288_robot_state_t st;
        motor_state(b, j, &st, &s->mode, &s->lost);
        s->q = (float)st.pos;
        s->dq = (float)st.speed;
        s->tau_est = (float)st.torque;
        s->temperature = temp_u8(st.winding_temp_c);
        if (st.online) {
            volts += st.voltage_v;
            online++;
        }
    }
    m->power_v = online != 0u ? (float)(volts / online) : 0.0f;
    m->crc = j288_dds_lowstate_crc(m);
}

void bridge_fill_hg_lowstate(bridge_t *b, unitree_hg_msg_dds__LowState_ *m, uint32_t tick_ms)
{
    unsigned n = j288_robot_njoints(b->robot), j;
    memset(m, 0, sizeof *m);
    m->mode_pr = b->hg_mode_pr;
    m->tick = tick_ms;
    for (j = 0; j < n && j < J288_DDS_HG_MOTORS; j++) {
        unitree_hg_msg_dds__MotorState_ *s = &m->motor_state[j];
        j288_robot_state_t st;
        uint32_t lost;
        motor_state(b, j, &st, &s->mode, &lost);
        s->q = (float)st.pos;
        s->dq = (float)st.speed;
        s->tau_est = (float)st.torque;
        s->temperature[0] = temp_i16(st.case_temp_c);
        s->temperature[1] = temp_i16(st.winding_temp_c);
        s->vol = st.online ? (float)st.voltage_v : 0.0f;
        s->motorstate = st.faults;
    }
    m->crc = j288_dds_hg_lowstate_crc(m);
}
