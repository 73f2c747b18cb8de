/*
 * dds_peer - a DDS peer of j288-dds for the tests and the benchmark, written apart from the
 * bridge: it shares only the IDL (the wire contract, checked byte for byte by golden.sh),
 * compiled as ROS 2 declares the types (-DJ288_DDS_AS_ROS2: unbounded sequences and strings;
 * dds_peer_xt also with XTypes type information), and computes unitree's crc its own way, as
 * unitree_sdk2 does (the message in a C struct's layout, crc32_core over its words in memory:
 * little-endian hosts only, which the tests run on).
 *
 * usage: dds_peer [--domain N] [--ns NS] [--hg] COMMAND ...
 *   --hg                      lowstate and lowcmd with unitree_hg's messages (35 motors)
 *   states [--timeout S]      the next rt/joint_states: 'name POS VEL EFF' lines
 *   diag [--timeout S]        the next rt/diagnostics: 'status NAME|LEVEL|MESSAGE' then
 *                             'NAME|KEY=VALUE' lines
 *   command [--for S | --count N] [--hz H] NAMES POS VEL EFF
 *                             rt/joint_command; each a comma list, '-' for an empty array;
 *                             values may be nan, inf; for S seconds, or exactly N messages
 *                             (one by default), at H per second (100); prints 'writer GUID'
 *                             (its writer's, as the bridge names it) once matched
 *   flood [--for S | --count N] [--hz H] [--names K]
 *                             rt/joint_command with K names (default 100000) of 11
 *                             characters: 1.6 MB samples, more names than any robot has;
 *                             at the end 'sent N in S s'
 *   endpoints [--timeout S]   the endpoints of other participants on rt/ topics, once at least
 *                             3 are seen (and 1 s more): 'pub|sub TOPIC TYPE USERDATA' lines
 *   lowstate [--timeout S]    the next rt/lowstate: 'motor I Q DQ TAU TEMP MODE' lines for the
 *                             motors, then 'crc ok' or 'crc bad'
 *   lowcmd [--for S | --count N] [--hz H] [--bad-crc] MOTOR MODE Q DQ TAU KP KD
 *                             rt/lowcmd for one motor (the others mode 0), crc set (or wrong)
 *   lowstate, lowcmd with --hg: unitree_hg's LowState_ (also 'mode_pr N' and temperatures
 *                             case,winding per motor) and LowCmd_
 *   listen [--for S] [--freeze]
 *                             read rt/joint_states for S seconds: 'samples N'; --freeze:
 *                             stop itself (SIGSTOP) after the first sample, a matched
 *                             reliable reader that neither takes nor acknowledges
 *   latency [--count N] [--hz H] NAME A B
 *                             commands for joint NAME alternating between positions A and B,
 *                             printing 'sent T_NS POS' for each (CLOCK_MONOTONIC at dds_write)
 * Exit 0 on success, 1 when nothing came within the timeout (default 10 s), 2 on bad usage.
 */
#include <math.h>
#include <signal.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <dds/dds.h>

#include "diagnostic_msgs.h"
#include "sensor_msgs.h"
#include "unitree_go.h"
#include "unitree_hg.h"

#define MAXN 80 /* more than J288_ROBOT_MAX_JOINTS: the bridge must refuse that too */

static dds_domainid_t domain;
static const char *ns;
static int hg; /* --hg: unitree_hg's messages */

static void topic_name(char *out, size_t cap, const char *name)
{
    snprintf(out, cap, "rt/%s%s%s", ns ? ns : "", ns ? "/" : "", name);
}

static dds_entity_t make_topic(dds_entity_t pp, const dds_topic_descriptor_t *d, const char *name)
{
    char t[200];
    topic_name(t, sizeof t, name);
    return dds_create_topic(pp, d, t, NULL, NULL);
}

static double mono_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* Wait up to timeout_s for a sample on a reliable reader; take it into sample. */
static int read_one(const dds_topic_descriptor_t *d, const char *name, double timeout_s, void *sample)
{
    dds_entity_t pp = dds_create_participant(domain, NULL, NULL);
    dds_entity_t tp = make_topic(pp, d, name);
    dds_qos_t *q = dds_create_qos();
    dds_entity_t r, ws;
    void *ptrs[1] = {sample};
    dds_sample_info_t si;
    double end = mono_s() + timeout_s;
    int got = 0;
    dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    r = dds_create_reader(pp, tp, q, NULL);
    dds_delete_qos(q);
    ws = dds_create_waitset(pp);
    dds_set_status_mask(r, DDS_DATA_AVAILABLE_STATUS);
    dds_waitset_attach(ws, r, r);
    while (!got && mono_s() < end) {
        dds_waitset_wait(ws, NULL, 0, DDS_MSECS(100));
        if (dds_take(r, ptrs, &si, 1, 1) > 0 && si.valid_data)
            got = 1;
    }
    /* the sample's strings and sequences were allocated by take: the caller prints and exits */
    (void)pp;
    return got ? 0 : 1;
}

static int cmd_states(double timeout_s)
{
    static sensor_msgs_msg_dds__JointState_ m;
    uint32_t i;
    if (read_one(&sensor_msgs_msg_dds__JointState__desc, "joint_states", timeout_s, &m) != 0)
        return 1;
    printf("stamp %d.%09u\n", m.header.stamp.sec, m.header.stamp.nanosec);
    for (i = 0; i < m.name._length; i++)
        printf("%s %.6f %.6f %.6f\n", m.name._buffer[i],
               i < m.position._length ? m.position._buffer[i] : NAN,
               i < m.velocity._length ? m.velocity._buffer[i] : NAN,
               i < m.effort._length ? m.effort._buffer[i] : NAN);
    return 0;
}

static int cmd_listen(double seconds, int freeze)
{
    dds_entity_t pp = dds_create_participant(domain, NULL, NULL);
    dds_entity_t tp = make_topic(pp, &sensor_msgs_msg_dds__JointState__desc, "joint_states");
    dds_qos_t *q = dds_create_qos();
    dds_entity_t r;
    void *ptrs[16] = {NULL};
    dds_sample_info_t si[16];
    double end = mono_s() + seconds;
    long n = 0;
    dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    dds_qset_history(q, DDS_HISTORY_KEEP_LAST, 16);
    r = dds_create_reader(pp, tp, q, NULL);
    dds_delete_qos(q);
    while (mono_s() < end) {
        int k = dds_take(r, ptrs, si, 16, 16);
        if (k > 0) {
            n += k;
            dds_return_loan(r, ptrs, k);
            if (freeze)
                raise(SIGSTOP); /* the test resumes (or kills) it */
        } else {
            dds_sleepfor(DDS_USECS(500));
        }
    }
    printf("samples %ld\n", n);
    return 0;
}

static int cmd_diag(double timeout_s)
{
    static diagnostic_msgs_msg_dds__DiagnosticArray_ m;
    uint32_t i, k;
    if (read_one(&diagnostic_msgs_msg_dds__DiagnosticArray__desc, "diagnostics", timeout_s, &m) != 0)
        return 1;
    for (i = 0; i < m.status._length; i++) {
        const diagnostic_msgs_msg_dds__DiagnosticStatus_ *s = &m.status._buffer[i];
        printf("status %s|%u|%s\n", s->name, (unsigned)s->level, s->message);
        for (k = 0; k < s->values._length; k++)
            printf("%s|%s=%s\n", s->name, s->values._buffer[k].key, s->values._buffer[k].value);
    }
    return 0;
}

/* ---- unitree's way: the message as a C struct, crc32_core over its words ---- */

typedef struct {
    uint8_t mode;
    float q, dq, tau, kp, kd;
    uint32_t reserve[3];
} raw_motor_cmd;

typedef struct {
    uint8_t head[2], level_flag, frame_reserve;
    uint32_t sn[2], version[2];
    uint16_t bandwidth;
    raw_motor_cmd motor[20];
    uint8_t bms_off, bms_reserve[3];
    uint8_t wireless_remote[40], led[12], fan[2], gpio;
    uint32_t reserve, crc;
} raw_low_cmd;

typedef struct {
    uint8_t mode;
    float q, dq, ddq, tau_est, q_raw, dq_raw, ddq_raw;
    uint8_t temperature;
    uint32_t lost, reserve[2];
} raw_motor_state;

typedef struct {
    uint8_t head[2], level_flag, frame_reserve;
    uint32_t sn[2], version[2];
    uint16_t bandwidth;
    float quaternion[4], gyroscope[3], accelerometer[3], rpy[3];
    uint8_t imu_temperature;
    raw_motor_state motor[20];
    uint8_t version_high, version_low, status, soc;
    int32_t current;
    uint16_t cycle;
    uint8_t bq_ntc[2], mcu_ntc[2];
    uint16_t cell_vol[15];
    int16_t foot_force[4], foot_force_est[4];
    uint32_t tick;
    uint8_t wireless_remote[40], bit_flag;
    float adc_reel;
    uint8_t temperature_ntc1, temperature_ntc2;
    float power_v, power_a;
    uint16_t fan_frequency[4];
    uint32_t reserve, crc;
} raw_low_state;

/* unitree_hg's (the humanoids') */
typedef struct {
    uint8_t mode;
    float q, dq, tau, kp, kd;
    uint32_t reserve;
} raw_hg_motor_cmd;

typedef struct {
    uint8_t mode_pr, mode_machine;
    raw_hg_motor_cmd motor[35];
    uint32_t reserve[4], crc;
} raw_hg_low_cmd;

typedef struct {
    uint8_t mode;
    float q, dq, ddq, tau_est;
    int16_t temperature[2];
    float vol;
    uint32_t sensor[2], motorstate, reserve[4];
} raw_hg_motor_state;

typedef struct {
    uint32_t version[2];
    uint8_t mode_pr, mode_machine;
    uint32_t tick;
    float quaternion[4], gyroscope[3], accelerometer[3], rpy[3];
    int16_t imu_temperature;
    raw_hg_motor_state motor[35];
    uint8_t wireless_remote[40];
    uint32_t reserve[4], crc;
} raw_hg_low_state;

/* unitree's sizes (C99 has no static assert: a negative array size fails the build) */
typedef char raw_low_cmd_is_812[sizeof(raw_low_cmd) == 812u ? 1 : -1];
typedef char raw_low_state_is_1180[sizeof(raw_low_state) == 1180u ? 1 : -1];
typedef char raw_hg_low_cmd_is_1004[sizeof(raw_hg_low_cmd) == 1004u ? 1 : -1];
typedef char raw_hg_low_state_is_2092[sizeof(raw_hg_low_state) == 2092u ? 1 : -1];

static uint32_t crc32_core(const uint32_t *ptr, uint32_t len)
{
    uint32_t crc = 0xFFFFFFFFu, i, bit;
    for (i = 0; i < len; i++) {
        uint32_t data = ptr[i], xbit = 1u << 31;
        for (bit = 0; bit < 32u; bit++) {
            crc = (crc & 0x80000000u) ? (crc << 1) ^ 0x04C11DB7u : crc << 1;
            if (data & xbit)
                crc ^= 0x04C11DB7u;
            xbit >>= 1;
        }
    }
    return crc;
}

/* The message's bytes where unitree's C struct has them, padding zero. (Member stores into a
 * struct may leave its padding bytes unspecified, and an optimising compiler does: so the
 * struct gives the layout through offsetof, and the bytes go into a zeroed image.) */
#define PUT(img, base, type, member, src) \
    memcpy((img) + (base) + offsetof(type, member), &(src), sizeof(src))

/* The members both messages start with. */
#define PUT_HEAD(img, type, m)                               \
    do {                                                     \
        PUT(img, 0, type, head, (m)->head);                  \
        PUT(img, 0, type, level_flag, (m)->level_flag);      \
        PUT(img, 0, type, frame_reserve, (m)->frame_reserve); \
        PUT(img, 0, type, sn, (m)->sn);                      \
        PUT(img, 0, type, version, (m)->version);            \
        PUT(img, 0, type, bandwidth, (m)->bandwidth);        \
    } while (0)

static uint32_t image_crc(const unsigned char *img, size_t size)
{
    uint32_t words[600];
    memcpy(words, img, size); /* little-endian host: the words as unitree reads them */
    return crc32_core(words, (uint32_t)(size / 4u - 1u));
}

static uint32_t lowcmd_crc(const unitree_go_msg_dds__LowCmd_ *m)
{
    unsigned char img[sizeof(raw_low_cmd)];
    unsigned i;
    memset(img, 0, sizeof img);
    PUT_HEAD(img, raw_low_cmd, m);
    for (i = 0; i < 20; i++) {
        size_t base = offsetof(raw_low_cmd, motor) + i * sizeof(raw_motor_cmd);
        const unitree_go_msg_dds__MotorCmd_ *c = &m->motor_cmd[i];
        PUT(img, base, raw_motor_cmd, mode, c->mode);
        PUT(img, base, raw_motor_cmd, q, c->q);
        PUT(img, base, raw_motor_cmd, dq, c->dq);
        PUT(img, base, raw_motor_cmd, tau, c->tau);
        PUT(img, base, raw_motor_cmd, kp, c->kp);
        PUT(img, base, raw_motor_cmd, kd, c->kd);
        PUT(img, base, raw_motor_cmd, reserve, c->reserve);
    }
    PUT(img, 0, raw_low_cmd, bms_off, m->bms_cmd.off);
    PUT(img, 0, raw_low_cmd, bms_reserve, m->bms_cmd.reserve);
    PUT(img, 0, raw_low_cmd, wireless_remote, m->wireless_remote);
    PUT(img, 0, raw_low_cmd, led, m->led);
    PUT(img, 0, raw_low_cmd, fan, m->fan);
    PUT(img, 0, raw_low_cmd, gpio, m->gpio);
    PUT(img, 0, raw_low_cmd, reserve, m->reserve);
    return image_crc(img, sizeof img);
}

static uint32_t lowstate_crc(const unitree_go_msg_dds__LowState_ *m)
{
    unsigned char img[sizeof(raw_low_state)];
    unsigned i;
    memset(img, 0, sizeof img);
    PUT_HEAD(img, raw_low_state, m);
    PUT(img, 0, raw_low_state, quaternion, m->imu_state.quaternion);
    PUT(img, 0, raw_low_state, gyroscope, m->imu_state.gyroscope);
    PUT(img, 0, raw_low_state, accelerometer, m->imu_state.accelerometer);
    PUT(img, 0, raw_low_state, rpy, m->imu_state.rpy);
    PUT(img, 0, raw_low_state, imu_temperature, m->imu_state.temperature);
    for (i = 0; i < 20; i++) {
        size_t base = offsetof(raw_low_state, motor) + i * sizeof(raw_motor_state);
        const unitree_go_msg_dds__MotorState_ *s = &m->motor_state[i];
        PUT(img, base, raw_motor_state, mode, s->mode);
        PUT(img, base, raw_motor_state, q, s->q);
        PUT(img, base, raw_motor_state, dq, s->dq);
        PUT(img, base, raw_motor_state, ddq, s->ddq);
        PUT(img, base, raw_motor_state, tau_est, s->tau_est);
        PUT(img, base, raw_motor_state, q_raw, s->q_raw);
        PUT(img, base, raw_motor_state, dq_raw, s->dq_raw);
        PUT(img, base, raw_motor_state, ddq_raw, s->ddq_raw);
        PUT(img, base, raw_motor_state, temperature, s->temperature);
        PUT(img, base, raw_motor_state, lost, s->lost);
        PUT(img, base, raw_motor_state, reserve, s->reserve);
    }
    PUT(img, 0, raw_low_state, version_high, m->bms_state.version_high);
    PUT(img, 0, raw_low_state, version_low, m->bms_state.version_low);
    PUT(img, 0, raw_low_state, status, m->bms_state.status);
    PUT(img, 0, raw_low_state, soc, m->bms_state.soc);
    PUT(img, 0, raw_low_state, current, m->bms_state.current);
    PUT(img, 0, raw_low_state, cycle, m->bms_state.cycle);
    PUT(img, 0, raw_low_state, bq_ntc, m->bms_state.bq_ntc);
    PUT(img, 0, raw_low_state, mcu_ntc, m->bms_state.mcu_ntc);
    PUT(img, 0, raw_low_state, cell_vol, m->bms_state.cell_vol);
    PUT(img, 0, raw_low_state, foot_force, m->foot_force);
    PUT(img, 0, raw_low_state, foot_force_est, m->foot_force_est);
    PUT(img, 0, raw_low_state, tick, m->tick);
    PUT(img, 0, raw_low_state, wireless_remote, m->wireless_remote);
    PUT(img, 0, raw_low_state, bit_flag, m->bit_flag);
    PUT(img, 0, raw_low_state, adc_reel, m->adc_reel);
    PUT(img, 0, raw_low_state, temperature_ntc1, m->temperature_ntc1);
    PUT(img, 0, raw_low_state, temperature_ntc2, m->temperature_ntc2);
    PUT(img, 0, raw_low_state, power_v, m->power_v);
    PUT(img, 0, raw_low_state, power_a, m->power_a);
    PUT(img, 0, raw_low_state, fan_frequency, m->fan_frequency);
    PUT(img, 0, raw_low_state, reserve, m->reserve);
    return image_crc(img, sizeof img);
}

static uint32_t hg_lowcmd_crc(const unitree_hg_msg_dds__LowCmd_ *m)
{
    unsigned char img[sizeof(raw_hg_low_cmd)];
    unsigned i;
    memset(img, 0, sizeof img);
    PUT(img, 0, raw_hg_low_cmd, mode_pr, m->mode_pr);
    PUT(img, 0, raw_hg_low_cmd, mode_machine, m->mode_machine);
    for (i = 0; i < 35; i++) {
        size_t base = offsetof(raw_hg_low_cmd, motor) + i * sizeof(raw_hg_motor_cmd);
        const unitree_hg_msg_dds__MotorCmd_ *c = &m->motor_cmd[i];
        PUT(img, base, raw_hg_motor_cmd, mode, c->mode);
        PUT(img, base, raw_hg_motor_cmd, q, c->q);
        PUT(img, base, raw_hg_motor_cmd, dq, c->dq);
        PUT(img, base, raw_hg_motor_cmd, tau, c->tau);
        PUT(img, base, raw_hg_motor_cmd, kp, c->kp);
        PUT(img, base, raw_hg_motor_cmd, kd, c->kd);
        PUT(img, base, raw_hg_motor_cmd, reserve, c->reserve);
    }
    PUT(img, 0, raw_hg_low_cmd, reserve, m->reserve);
    return image_crc(img, sizeof img);
}

static uint32_t hg_lowstate_crc(const unitree_hg_msg_dds__LowState_ *m)
{
    unsigned char img[sizeof(raw_hg_low_state)];
    unsigned i;
    memset(img, 0, sizeof img);
    PUT(img, 0, raw_hg_low_state, version, m->version);
    PUT(img, 0, raw_hg_low_state, mode_pr, m->mode_pr);
    PUT(img, 0, raw_hg_low_state, mode_machine, m->mode_machine);
    PUT(img, 0, raw_hg_low_state, tick, m->tick);
    PUT(img, 0, raw_hg_low_state, quaternion, m->imu_state.quaternion);
    PUT(img, 0, raw_hg_low_state, gyroscope, m->imu_state.gyroscope);
    PUT(img, 0, raw_hg_low_state, accelerometer, m->imu_state.accelerometer);
    PUT(img, 0, raw_hg_low_state, rpy, m->imu_state.rpy);
    PUT(img, 0, raw_hg_low_state, imu_temperature, m->imu_state.temperature);
    for (i = 0; i < 35; i++) {
        size_t base = offsetof(raw_hg_low_state, motor) + i * sizeof(raw_hg_motor_state);
        const unitree_hg_msg_dds__MotorState_ *s = &m->motor_state[i];
        PUT(img, base, raw_hg_motor_state, mode, s->mode);
        PUT(img, base, raw_hg_motor_state, q, s->q);
        PUT(img, base, raw_hg_motor_state, dq, s->dq);
        PUT(img, base, raw_hg_motor_state, ddq, s->ddq);
        PUT(img, base, raw_hg_motor_state, tau_est, s->tau_est);
        PUT(img, base, raw_hg_motor_state, temperature, s->temperature);
        PUT(img, base, raw_hg_motor_state, vol, s->vol);
        PUT(img, base, raw_hg_motor_state, sensor, s->sensor);
        PUT(img, base, raw_hg_motor_state, motorstate, s->motorstate);
        PUT(img, base, raw_hg_motor_state, reserve, s->reserve);
    }
    PUT(img, 0, raw_hg_low_state, wireless_remote, m->wireless_remote);
    PUT(img, 0, raw_hg_low_state, reserve, m->reserve);
    return image_crc(img, sizeof img);
}

static int cmd_hg_lowstate(double timeout_s)
{
    static unitree_hg_msg_dds__LowState_ m;
    unsigned i;
    if (read_one(&unitree_hg_msg_dds__LowState__desc, "lowstate", timeout_s, &m) != 0)
        return 1;
    for (i = 0; i < 35; i++)
        printf("motor %u %.6f %.6f %.6f %d,%d %u %.2f %u\n", i, (double)m.motor_state[i].q,
               (double)m.motor_state[i].dq, (double)m.motor_state[i].tau_est,
               m.motor_state[i].temperature[0], m.motor_state[i].temperature[1],
               (unsigned)m.motor_state[i].mode, (double)m.motor_state[i].vol,
               (unsigned)m.motor_state[i].motorstate);
    printf("mode_pr %u\ncrc %s %08lx %08lx\n", (unsigned)m.mode_pr,
           hg_lowstate_crc(&m) == m.crc ? "ok" : "bad", (unsigned long)m.crc,
           (unsigned long)hg_lowstate_crc(&m));
    return 0;
}

static int cmd_lowstate(double timeout_s)
{
    static unitree_go_msg_dds__LowState_ m;
    unsigned i;
    if (read_one(&unitree_go_msg_dds__LowState__desc, "lowstate", timeout_s, &m) != 0)
        return 1;
    for (i = 0; i < 20; i++)
        printf("motor %u %.6f %.6f %.6f %u %u\n", i, (double)m.motor_state[i].q,
               (double)m.motor_state[i].dq, (double)m.motor_state[i].tau_est,
               (unsigned)m.motor_state[i].temperature, (unsigned)m.motor_state[i].mode);
    printf("power_v %.2f\ncrc %s %08lx %08lx\n", (double)m.power_v, lowstate_crc(&m) == m.crc ? "ok" : "bad", (unsigned long)m.crc, (unsigned long)lowstate_crc(&m));
    return 0;
}

/* ---- writing ---- */

/* A sample from the bridge's state writer on a reader in pp, within timeout_s. The bridge
 * sends state only to readers it has discovered, so a sample means it has taken this
 * participant's endpoint announcements, the writer's (made first) with them: its best-effort
 * command reader drops what a writer it does not know yet sends (a loaded machine lost some of
 * a test's counted commands that way). False when none came: the caller goes on regardless. */
static int bridge_knows_us(dds_entity_t pp, const dds_topic_descriptor_t *cmd, double timeout_s)
{
    dds_entity_t tp = cmd == &unitree_go_msg_dds__LowCmd__desc
                          ? make_topic(pp, &unitree_go_msg_dds__LowState__desc, "lowstate")
                      : cmd == &unitree_hg_msg_dds__LowCmd__desc
                          ? make_topic(pp, &unitree_hg_msg_dds__LowState__desc, "lowstate")
                          : make_topic(pp, &sensor_msgs_msg_dds__JointState__desc, "joint_states");
    dds_entity_t r = dds_create_reader(pp, tp, NULL, NULL);
    void *ptrs[1] = {NULL};
    dds_sample_info_t si;
    double end = mono_s() + timeout_s;
    int got = 0;
    while (!got && mono_s() < end) {
        int k = dds_take(r, ptrs, &si, 1, 1);
        if (k > 0) {
            got = 1;
            dds_return_loan(r, ptrs, k);
        } else {
            dds_sleepfor(DDS_MSECS(1));
        }
    }
    dds_delete(r);
    return got;
}

static dds_entity_t writer_for(const dds_topic_descriptor_t *d, const char *name)
{
    dds_entity_t pp = dds_create_participant(domain, NULL, NULL);
    dds_entity_t tp = make_topic(pp, d, name);
    dds_qos_t *q = dds_create_qos();
    dds_entity_t w;
    dds_publication_matched_status_t st;
    double end = mono_s() + 10.0;
    dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    w = dds_create_writer(pp, tp, q, NULL);
    dds_delete_qos(q);
    do { /* until the bridge's reader is there, then until the bridge knows this writer */
        dds_get_publication_matched_status(w, &st);
        if (st.current_count > 0) {
            dds_guid_t g;
            unsigned k;
            (void)bridge_knows_us(pp, d, 5.0);
            if (dds_get_guid(w, &g) == DDS_RETCODE_OK) { /* as the bridge prints it */
                printf("writer ");
                for (k = 0; k < 16; k++)
                    printf("%02x%s", g.v[k], k < 15 ? "." : "\n");
            }
            return w;
        }
        dds_sleepfor(DDS_MSECS(20));
    } while (mono_s() < end);
    fprintf(stderr, "dds_peer: no reader matched %s\n", name);
    return -1;
}

/* Publish write() at hz: count times when count > 0, else for seconds (once when 0). Returns
 * how many were written. */
static int pace(int count, double seconds, double hz, void (*write)(void *ctx), void *ctx)
{
    double end = mono_s() + seconds, next = mono_s();
    int sent = 0;
    do {
        write(ctx);
        sent++;
        next += 1.0 / hz;
        while (mono_s() < next)
            dds_sleepfor(DDS_USECS(200));
    } while (count > 0 ? sent < count : mono_s() < end);
    return sent;
}

/* "a,b,c" -> values; "-" -> none. */
static uint32_t parse_list(char *s, double *out)
{
    uint32_t n = 0;
    char *tok;
    if (strcmp(s, "-") == 0)
        return 0;
    for (tok = strtok(s, ","); tok != NULL && n < MAXN; tok = strtok(NULL, ","))
        out[n++] = strtod(tok, NULL);
    return n;
}

typedef struct {
    dds_entity_t w;
    const void *m;
} sample_ctx;

static void write_sample(void *p)
{
    sample_ctx *c = p;
    dds_write(c->w, c->m);
}

/* m on topic name (type d) as pace() says, once a reader matched; prints 'sent N in S s' with
 * print_sent. 1 when no reader matched. */
static int publish(const dds_topic_descriptor_t *d, const char *name, const void *m, int count,
                   double seconds, double hz, int print_sent)
{
    sample_ctx c;
    double t0;
    int n;
    c.m = m;
    c.w = writer_for(d, name);
    if (c.w < 0)
        return 1;
    t0 = mono_s();
    n = pace(count, seconds, hz, write_sample, &c);
    if (print_sent)
        printf("sent %d in %.2f s\n", n, mono_s() - t0);
    dds_wait_for_acks(c.w, DDS_SECS(2));
    return 0;
}

static int cmd_command(int count, double seconds, double hz, char **argv)
{
    static char *names[MAXN];
    static double pos[MAXN], vel[MAXN], eff[MAXN];
    static sensor_msgs_msg_dds__JointState_ m;
    uint32_t n = 0;
    char *tok;
    for (tok = strtok(argv[0], ","); tok != NULL && n < MAXN; tok = strtok(NULL, ","))
        names[n++] = tok;
    m.header.frame_id = (char *)"";
    m.name._buffer = names;
    m.name._length = m.name._maximum = n;
    m.position._buffer = pos;
    m.position._length = m.position._maximum = parse_list(argv[1], pos);
    m.velocity._buffer = vel;
    m.velocity._length = m.velocity._maximum = parse_list(argv[2], vel);
    m.effort._buffer = eff;
    m.effort._length = m.effort._maximum = parse_list(argv[3], eff);
    return publish(&sensor_msgs_msg_dds__JointState__desc, "joint_command", &m, count, seconds, hz, 0);
}

/* One motor's command (unitree_go's or unitree_hg's MotorCmd_) from MOTOR MODE Q DQ TAU KP KD. */
#define SET_MOTOR(mc, argv)                        \
    do {                                           \
        (mc)->mode = (uint8_t)atoi((argv)[1]);     \
        (mc)->q = strtof((argv)[2], NULL);         \
        (mc)->dq = strtof((argv)[3], NULL);        \
        (mc)->tau = strtof((argv)[4], NULL);       \
        (mc)->kp = strtof((argv)[5], NULL);        \
        (mc)->kd = strtof((argv)[6], NULL);        \
    } while (0)

static int cmd_lowcmd(int count, double seconds, double hz, int bad_crc, char **argv)
{
    static unitree_go_msg_dds__LowCmd_ m;
    int motor = atoi(argv[0]);
    if (motor < 0 || motor >= 20)
        return 2;
    m.head[0] = 0xFE;
    m.head[1] = 0xEF;
    m.level_flag = 0xFF;
    SET_MOTOR(&m.motor_cmd[motor], argv);
    m.crc = lowcmd_crc(&m) ^ (bad_crc ? 1u : 0u);
    return publish(&unitree_go_msg_dds__LowCmd__desc, "lowcmd", &m, count, seconds, hz, 0);
}

static int cmd_hg_lowcmd(int count, double seconds, double hz, int bad_crc, char **argv)
{
    static unitree_hg_msg_dds__LowCmd_ m;
    int motor = atoi(argv[0]);
    if (motor < 0 || motor >= 35)
        return 2;
    m.mode_pr = (uint8_t)(getenv("DDS_PEER_MODE_PR") ? atoi(getenv("DDS_PEER_MODE_PR")) : 0);
    SET_MOTOR(&m.motor_cmd[motor], argv);
    m.crc = hg_lowcmd_crc(&m) ^ (bad_crc ? 1u : 0u);
    return publish(&unitree_hg_msg_dds__LowCmd__desc, "lowcmd", &m, count, seconds, hz, 0);
}

/* JointState commands with k names: far more than the bridge's types allow. */
static int cmd_flood(int count, double seconds, double hz, long k)
{
    static sensor_msgs_msg_dds__JointState_ m;
    static char text[16];
    long i;
    char **names = malloc((size_t)k * sizeof *names);
    char *pool = malloc((size_t)k * 12u);
    if (names == NULL || pool == NULL || k <= 0)
        return 2;
    for (i = 0; i < k; i++) {
        names[i] = pool + 12 * i;
        snprintf(names[i], 12, "flood%06ld", i % 1000000);
    }
    m.header.frame_id = text;
    m.name._buffer = names;
    m.name._length = m.name._maximum = (uint32_t)k;
    return publish(&sensor_msgs_msg_dds__JointState__desc, "joint_command", &m, count, seconds, hz, 1);
}

/* The endpoints other participants have on rt/ topics, with their USER_DATA. */
static int cmd_endpoints(double timeout_s)
{
    dds_entity_t pp = dds_create_participant(domain, NULL, NULL);
    dds_entity_t rd[2];
    const char *kind[2] = {"pub", "sub"};
    dds_guid_t self;
    double end = mono_s() + timeout_s, seen_at = 0;
    char lines[64][400];
    int n = 0, k;
    rd[0] = dds_create_reader(pp, DDS_BUILTIN_TOPIC_DCPSPUBLICATION, NULL, NULL);
    rd[1] = dds_create_reader(pp, DDS_BUILTIN_TOPIC_DCPSSUBSCRIPTION, NULL, NULL);
    dds_get_guid(pp, &self);
    while (mono_s() < end && (n < 3 || mono_s() < seen_at + 1.0)) {
        for (k = 0; k < 2; k++) {
            void *ptrs[1] = {NULL};
            dds_sample_info_t si;
            while (dds_take(rd[k], ptrs, &si, 1, 1) > 0) {
                dds_builtintopic_endpoint_t *ep = ptrs[0];
                void *ud = NULL;
                size_t sz = 0;
                if (si.valid_data && memcmp(ep->participant_key.v, self.v, 12) != 0 &&
                    strncmp(ep->topic_name, "rt/", 3) == 0 && n < 64) {
                    dds_qget_userdata(ep->qos, &ud, &sz);
                    snprintf(lines[n++], sizeof lines[0], "%s %s %s %.*s", kind[k], ep->topic_name,
                             ep->type_name, (int)sz, ud != NULL ? (const char *)ud : "");
                    dds_free(ud);
                    seen_at = mono_s();
                }
                dds_return_loan(rd[k], ptrs, 1);
            }
        }
        dds_sleepfor(DDS_MSECS(20));
    }
    for (k = 0; k < n; k++)
        printf("%s\n", lines[k]);
    return n >= 3 ? 0 : 1;
}

static int cmd_latency(int count, double hz, char **argv)
{
    static char *names[1];
    static double pos[1];
    static sensor_msgs_msg_dds__JointState_ m;
    dds_entity_t w;
    double a = strtod(argv[1], NULL), b = strtod(argv[2], NULL);
    int i;
    names[0] = argv[0];
    m.header.frame_id = (char *)"";
    m.name._buffer = names;
    m.name._length = m.name._maximum = 1;
    m.position._buffer = pos;
    m.position._length = m.position._maximum = 1;
    w = writer_for(&sensor_msgs_msg_dds__JointState__desc, "joint_command");
    if (w < 0)
        return 1;
    for (i = 0; i < count; i++) {
        struct timespec ts;
        double next = mono_s() + 1.0 / hz;
        pos[0] = (i % 2) ? b : a;
        clock_gettime(CLOCK_MONOTONIC, &ts);
        dds_write(w, &m);
        printf("sent %lld %.6f\n", (long long)ts.tv_sec * 1000000000LL + ts.tv_nsec, pos[0]);
        while (mono_s() < next)
            dds_sleepfor(DDS_USECS(100));
    }
    dds_wait_for_acks(w, DDS_SECS(2));
    return 0;
}

int main(int argc, char **argv)
{
    double timeout_s = 10.0, seconds = 0.0, hz = 100.0;
    int i = 1, bad_crc = 0, freeze = 0, count = 0; /* latency: 100 when not given */
    long names = 100000;
    const char *cmd;
    const char *env = getenv("DDS_DOMAIN");
    if (env != NULL)
        domain = (dds_domainid_t)atoi(env);
    for (; i < argc && strncmp(argv[i], "--", 2) == 0; i += 2) {
        if (i + 1 >= argc && strcmp(argv[i], "--hg") != 0)
            return 2;
        if (strcmp(argv[i], "--domain") == 0)
            domain = (dds_domainid_t)atoi(argv[i + 1]);
        else if (strcmp(argv[i], "--ns") == 0)
            ns = argv[i + 1];
        else if (strcmp(argv[i], "--hg") == 0) {
            hg = 1;
            i--; /* takes no value */
        } else
            return 2;
    }
    if (i >= argc)
        return 2;
    cmd = argv[i++];
    for (; i < argc && strncmp(argv[i], "--", 2) == 0; i++) {
        if (strcmp(argv[i], "--bad-crc") == 0) {
            bad_crc = 1;
            continue;
        }
        if (strcmp(argv[i], "--freeze") == 0) {
            freeze = 1;
            continue;
        }
        if (i + 1 >= argc)
            return 2;
        if (strcmp(argv[i], "--timeout") == 0)
            timeout_s = atof(argv[i + 1]);
        else if (strcmp(argv[i], "--for") == 0)
            seconds = atof(argv[i + 1]);
        else if (strcmp(argv[i], "--hz") == 0)
            hz = atof(argv[i + 1]);
        else if (strcmp(argv[i], "--count") == 0)
            count = atoi(argv[i + 1]);
        else if (strcmp(argv[i], "--names") == 0)
            names = atol(argv[i + 1]);
        else
            return 2;
        i++;
    }
    setvbuf(stdout, NULL, _IOLBF, 0);
    if (strcmp(cmd, "states") == 0)
        return cmd_states(timeout_s);
    if (strcmp(cmd, "listen") == 0)
        return cmd_listen(seconds, freeze);
    if (strcmp(cmd, "diag") == 0)
        return cmd_diag(timeout_s);
    if (strcmp(cmd, "lowstate") == 0)
        return hg ? cmd_hg_lowstate(timeout_s) : cmd_lowstate(timeout_s);
    if (strcmp(cmd, "endpoints") == 0)
        return cmd_endpoints(timeout_s);
    if (strcmp(cmd, "flood") == 0 && argc == i)
        return cmd_flood(count, seconds, hz, names);
    if (strcmp(cmd, "command") == 0 && argc - i == 4)
        return cmd_command(count, seconds, hz, argv + i);
    if (strcmp(cmd, "lowcmd") == 0 && argc - i == 7)
        return hg ? cmd_hg_lowcmd(count, seconds, hz, bad_crc, argv + i)
                  : cmd_lowcmd(count, seconds, hz, bad_crc, argv + i);
    if (strcmp(cmd, "latency") == 0 && argc - i == 3)
        return cmd_latency(count > 0 ? count : 100, hz, argv + i);
    fprintf(stderr, "dds_peer: bad usage (see the top of test/dds/dds_peer.c)\n");
    return 2;
}
