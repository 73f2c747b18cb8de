/* bridge.c - see bridge.h. */
#include "bridge.h"

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "unitree_crc.h"

/* unitree_sdk2's "no position / no velocity control" markers (PosStopF, VelStopF). */
#define UNITREE_POS_STOP 2.146e9f
#define UNITREE_VEL_STOP 16000.0f

static const char *const cause_names[BRIDGE_NCAUSES] = {
    "array lengths differ",   "no joint or no values",  "unknown joint name",
    "joint named twice",      "NaN or infinite value",  "target outside the joint's limits",
    "joint angle not known yet", "bad crc",             "motor mode not 0 or 1",
    "robot stopped after a bus loss", "refused by the joint layer",
};

const char *bridge_cause_name(bridge_cause_t c)
{
    return (unsigned)c < BRIDGE_NCAUSES ? cause_names[c] : "?";
}

void bridge_init(bridge_t *b, j288_robot_t *robot, const j288_robot_config_t *cfg,
                 uint32_t timeout_us, bridge_timeout_policy_t policy)
{
    unsigned j;
    memset(b, 0, sizeof *b);
    b->robot = robot;
    b->cfg = cfg;
    b->timeout_us = timeout_us;
    b->policy = policy;
    for (j = 0; j < j288_robot_njoints(robot); j++)
        b->names[j] = (char *)(uintptr_t)j288_robot_joint_name(robot, j); /* DDS wants char * */
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
    default: return BRIDGE_CAUSE_OTHER;
    }
}

/* Set one joint's target, or count why not. */
static void drive(bridge_t *b, unsigned j, const j288_robot_target_t *t, uint32_t now_us)
{
    char detail[160];
    int rc;
    if (!isfinite(t->pos) || !isfinite(t->speed) || !isfinite(t->torque) || !isfinite(t->kp) ||
        !isfinite(t->kd)) {
        snprintf(detail, sizeof detail, "joint %s", j288_robot_joint_name(b->robot, j));
        bridge_refuse(b, BRIDGE_CAUSE_NOT_FINITE, detail);
        return;
    }
    rc = j288_robot_set_target(b->robot, j, t);
    if (rc != J288_OK) {
        snprintf(detail, sizeof detail, "joint %s: pos %.4g speed %.4g torque %.4g: %s",
                 j288_robot_joint_name(b->robot, j), t->pos, t->speed, t->torque,
                 j288_strerror(rc));
        bridge_refuse(b, cause_of(rc), detail);
        return;
    }
    b->joint[j].mode = JOINT_FOLLOWING;
    b->joint[j].last_cmd_us = now_us;
    b->joint[j].accepted++;
}

/* The structure of a command: every name a joint, once; the arrays as long as name. Fills
 * idx[] with joint indices; false (and counted) when the whole message is refused. */
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
    if (n > J288_ROBOT_MAX_JOINTS) {
        bridge_refuse(b, BRIDGE_CAUSE_DUPLICATE, "more names than the robot has joints");
        return false;
    }
    for (i = 0; i < n; i++) {
        const char *name = m->name._buffer[i] != NULL ? m->name._buffer[i] : "";
        idx[i] = j288_robot_find_joint(b->robot, name);
        if (idx[i] < 0) {
            snprintf(detail, sizeof detail, "'%.64s'", name);
            bridge_refuse(b, BRIDGE_CAUSE_UNKNOWN, detail);
            return false;
        }
        for (k = 0; k < i; k++) {
            if (idx[k] == idx[i]) {
                snprintf(detail, sizeof detail, "'%.64s'", name);
                bridge_refuse(b, BRIDGE_CAUSE_DUPLICATE, detail);
                return false;
            }
        }
    }
    return true;
}

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

void bridge_take_command(bridge_t *b, const sensor_msgs_msg_dds__JointState_ *m, uint32_t now_us)
{
    int idx[J288_ROBOT_MAX_JOINTS];
    uint32_t i;
    b->messages++;
    if (b->stopped) {
        bridge_refuse(b, BRIDGE_CAUSE_STOPPED, b->stop_reason);
        return;
    }
    if (!check_command(b, m, idx))
        return;
    for (i = 0; i < m->name._length; i++) {
        unsigned j = (unsigned)idx[i];
        bool has_pos = m->position._length != 0u, has_vel = m->velocity._length != 0u;
        j288_robot_target_t t;
        double kp, kd;
        current(b, j, &t.pos, &kp, &kd);
        t.kp = has_pos ? kp : 0.0;
        t.kd = (has_pos || has_vel) ? kd : 0.0;
        if (has_pos)
            t.pos = m->position._buffer[i];
        t.speed = has_vel ? m->velocity._buffer[i] : 0.0;
        t.torque = m->effort._length != 0u ? m->effort._buffer[i] : 0.0;
        drive(b, j, &t, now_us);
    }
}

void bridge_take_lowcmd(bridge_t *b, const unitree_go_msg_dds__LowCmd_ *m, uint32_t now_us)
{
    unsigned n = j288_robot_njoints(b->robot), j;
    uint32_t want = j288_dds_lowcmd_crc(m);
    char detail[160];
    b->messages++;
    if (b->stopped) {
        bridge_refuse(b, BRIDGE_CAUSE_STOPPED, b->stop_reason);
        return;
    }
    if (want != m->crc) {
        snprintf(detail, sizeof detail, "crc 0x%08lx, expected 0x%08lx", (unsigned long)m->crc,
                 (unsigned long)want);
        bridge_refuse(b, BRIDGE_CAUSE_BAD_CRC, detail);
        return;
    }
    for (j = 0; j < n && j < J288_DDS_UNITREE_MOTORS; j++) {
        const unitree_go_msg_dds__MotorCmd_ *c = &m->motor_cmd[j];
        j288_robot_target_t t;
        double kp, kd;
        if (c->mode == 0u) {
            if (b->joint[j].mode != JOINT_IDLE && b->joint[j].mode != JOINT_LOCKED)
                (void)j288_robot_lock(b->robot, j);
            if (b->joint[j].mode != JOINT_IDLE)
                b->joint[j].mode = JOINT_LOCKED;
            continue;
        }
        if (c->mode != 1u) {
            snprintf(detail, sizeof detail, "motor %u mode %u", j, (unsigned)c->mode);
            bridge_refuse(b, BRIDGE_CAUSE_BAD_MODE, detail);
            continue;
        }
        current(b, j, &t.pos, &kp, &kd);
        t.kp = c->kp;
        t.kd = c->kd;
        if (fabsf(c->q) >= UNITREE_POS_STOP) {
            t.kp = 0.0; /* no position control: stay where it is */
        } else {
            t.pos = c->q;
        }
        t.speed = fabsf(c->dq) >= UNITREE_VEL_STOP ? 0.0 : c->dq;
        t.torque = c->tau;
        drive(b, j, &t, now_us);
    }
}

void bridge_check_timeouts(bridge_t *b, uint32_t now_us)
{
    unsigned j;
    for (j = 0; j < j288_robot_njoints(b->robot); j++) {
        bridge_joint_t *bj = &b->joint[j];
        int rc = J288_OK;
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

void bridge_bus_lost(bridge_t *b, unsigned bus, const char *what)
{
    if (bus < J288_ROBOT_MAX_BUSES)
        b->bus_lost[bus]++;
    fprintf(stderr, "j288-dds: bus '%s' %s\n", j288_robot_bus_name(b->robot, bus), what);
}

void bridge_stopped(bridge_t *b, const char *why)
{
    unsigned j;
    if (b->stopped)
        return;
    b->stopped = true;
    snprintf(b->stop_reason, sizeof b->stop_reason, "%s", why);
    for (j = 0; j < J288_ROBOT_MAX_JOINTS; j++) /* at lock now: no timeout may hold them again */
        b->joint[j].mode = JOINT_IDLE;
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

void bridge_stamp_now(builtin_interfaces_msg_dds__Time_ *t)
{
    struct timespec ts;
    (void)clock_gettime(CLOCK_REALTIME, &ts);
    t->sec = (int32_t)ts.tv_sec;
    t->nanosec = (uint32_t)ts.tv_nsec;
}

void bridge_fill_joint_state(bridge_t *b, sensor_msgs_msg_dds__JointState_ *m)
{
    unsigned n = j288_robot_njoints(b->robot), j;
    for (j = 0; j < n; j++) {
        j288_robot_state_t st;
        (void)j288_robot_read(b->robot, j, &st);
        b->pos[j] = st.known ? st.pos : NAN; /* ROS: NaN where a value is unknown */
        b->vel[j] = st.speed;
        b->eff[j] = st.torque;
    }
    memset(m, 0, sizeof *m);
    bridge_stamp_now(&m->header.stamp);
    m->header.frame_id = (char *)(uintptr_t)"";
    m->name._buffer = b->names;
    m->position._buffer = b->pos;
    m->velocity._buffer = b->vel;
    m->effort._buffer = b->eff;
    m->name._length = m->name._maximum = m->position._length = m->position._maximum = n;
    m->velocity._length = m->velocity._maximum = m->effort._length = m->effort._maximum = n;
}

static int8_t temp_i8(double c)
{
    return (int8_t)(c > 127.0 ? 127 : c < -128.0 ? -128 : lround(c));
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
        j288_robot_joint_stats_t js;
        (void)j288_robot_read(b->robot, j, &st);
        (void)j288_robot_joint_stats(b->robot, j, &js);
        s->mode = (b->joint[j].mode == JOINT_FOLLOWING) ? 1u : 0u;
        s->q = (float)st.pos;
        s->dq = (float)st.speed;
        s->tau_est = (float)st.torque;
        s->temperature = temp_i8(st.winding_temp_c);
        s->lost = js.stale_cycles;
        if (st.online) {
            volts += st.voltage_v;
            online++;
        }
    }
    m->power_v = online != 0u ? (float)(volts / online) : 0.0f;
    m->crc = j288_dds_lowstate_crc(m);
}
