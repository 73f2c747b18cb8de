/*
 * dds_golden - what Cyclone DDS puts on the wire for fixed samples, printed as hex: a
 * sensor_msgs JointState_ (the bridge's bounded type), a unitree_go LowCmd_ (its crc set by
 * tools/j288-dds's unitree_crc.c) and a std_msgs Header_ (its body ends off a 4-byte
 * boundary: the encapsulation's padding count); the crc of a unitree_go LowState_ and of a
 * unitree_hg LowCmd_ and LowState_; and the ROS 2 type hash of every type the bridge puts on
 * DDS (tools/j288-dds/typehash.c), as 'typehash NAME HASH' lines. test/dds/golden.sh compares the lines with test/dds/golden.py, which
 * computes the same bytes from the XCDR1 rules and unitree's crc32_core independently, and
 * with test/dds/typehash.py, which computes the hashes from the IDL.
 * Each sample goes through a writer and a reader of one participant (local delivery), and
 * the reader's serialized sample (dds_takecdr) is printed whole: encapsulation header and
 * body. The samples here and in golden.py must stay the same (they say so in both).
 * Run inside a private network namespace or with a loopback-only CYCLONEDDS_URI.
 * usage: dds_golden [DOMAIN]; exit 0 when both samples were printed.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <dds/dds.h>
#include <dds/ddsi/ddsi_serdata.h>

#include "sensor_msgs.h"
#include "std_msgs.h"
#include "typehash.h"
#include "unitree_crc.h"
#include "unitree_go.h"
#include "unitree_hg.h"

static int print_cdr(dds_entity_t pp, const dds_topic_descriptor_t *desc, const char *name,
                     const void *sample)
{
    dds_entity_t tp = dds_create_topic(pp, desc, name, NULL, NULL);
    dds_qos_t *q = dds_create_qos();
    dds_entity_t w, r;
    struct ddsi_serdata *sd = NULL;
    dds_sample_info_t si;
    unsigned char buf[4096];
    uint32_t size, i;
    int tries, n = 0;
    dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
    dds_qset_history(q, DDS_HISTORY_KEEP_ALL, 0);
    w = dds_create_writer(pp, tp, q, NULL);
    r = dds_create_reader(pp, tp, q, NULL);
    dds_delete_qos(q);
    if (tp < 0 || w < 0 || r < 0 || dds_write(w, sample) < 0) {
        fprintf(stderr, "dds_golden: %s: could not write\n", name);
        return -1;
    }
    for (tries = 0; tries < 500 && n <= 0; tries++) { /* local delivery: at once, in practice */
        n = dds_takecdr(r, &sd, 1, &si, DDS_ANY_STATE);
        if (n <= 0)
            dds_sleepfor(DDS_MSECS(10));
    }
    if (n <= 0) {
        fprintf(stderr, "dds_golden: %s: nothing read back\n", name);
        return -1;
    }
    size = ddsi_serdata_size(sd);
    if (size > sizeof buf) {
        ddsi_serdata_unref(sd);
        return -1;
    }
    ddsi_serdata_to_ser(sd, 0, size, buf);
    ddsi_serdata_unref(sd);
    printf("%s ", name);
    for (i = 0; i < size; i++)
        printf("%02x", buf[i]);
    printf("\n");
    return 0;
}

/* The JointState sample (the same in golden.py). */
static void joint_state(sensor_msgs_msg_dds__JointState_ *m)
{
    static char names[2][32] = {"hip", "knee"};
    static double pos[] = {0.5, -1.25}, eff[] = {2.0, 0.0};
    memset(m, 0, sizeof *m);
    m->header.stamp.sec = 1700000000;
    m->header.stamp.nanosec = 123456789u;
    strcpy(m->header.frame_id, "base");
    m->name._buffer = names;
    m->name._length = m->name._maximum = 2;
    m->position._buffer = pos;
    m->position._length = m->position._maximum = 2;
    m->effort._buffer = eff;
    m->effort._length = m->effort._maximum = 2;
    /* velocity: empty */
}

/* The LowCmd sample (the same in golden.py). */
static void low_cmd(unitree_go_msg_dds__LowCmd_ *m)
{
    unsigned i;
    memset(m, 0, sizeof *m);
    m->head[0] = 0xFE;
    m->head[1] = 0xEF;
    m->level_flag = 0xFF;
    m->sn[0] = 1;
    m->sn[1] = 2;
    m->version[0] = 3;
    m->version[1] = 4;
    m->bandwidth = 0x1234;
    for (i = 0; i < 20u; i++) {
        unitree_go_msg_dds__MotorCmd_ *c = &m->motor_cmd[i];
        c->mode = i < 3u ? 1u : 0u;
        c->q = 0.25f * (float)i;
        c->dq = -0.5f * (float)i;
        c->tau = 1.0f;
        c->kp = 20.0f;
        c->kd = 0.75f;
        c->reserve[0] = i;
    }
    m->bms_cmd.off = 0xA5;
    m->bms_cmd.reserve[0] = 1;
    m->bms_cmd.reserve[1] = 2;
    m->bms_cmd.reserve[2] = 3;
    for (i = 0; i < 40u; i++)
        m->wireless_remote[i] = (uint8_t)i;
    for (i = 0; i < 12u; i++)
        m->led[i] = (uint8_t)(0x10u + i);
    m->fan[0] = 7;
    m->fan[1] = 8;
    m->gpio = 9;
    m->reserve = 0xDEADBEEFu;
    m->crc = j288_dds_lowcmd_crc(m);
}

/* The LowState sample for the crc alone (the same in golden.py). */
static void low_state(unitree_go_msg_dds__LowState_ *m)
{
    static const float imu[13] = {1.0f, 0, 0, 0, 0.5f, -0.5f, 0.25f, 0, 0, 9.75f, 0.125f, -0.125f, 3.0f};
    unsigned i;
    memset(m, 0, sizeof *m);
    m->head[0] = 0xFE;
    m->head[1] = 0xEF;
    m->level_flag = 0xFF;
    m->sn[0] = 5;
    m->sn[1] = 6;
    m->version[0] = 7;
    m->version[1] = 8;
    m->bandwidth = 0x4321;
    memcpy(m->imu_state.quaternion, imu, 4 * sizeof(float));
    memcpy(m->imu_state.gyroscope, imu + 4, 3 * sizeof(float));
    memcpy(m->imu_state.accelerometer, imu + 7, 3 * sizeof(float));
    memcpy(m->imu_state.rpy, imu + 10, 3 * sizeof(float));
    m->imu_state.temperature = 249; /* -7 as unitree_ros2's int8 reads it */
    for (i = 0; i < 20u; i++) {
        unitree_go_msg_dds__MotorState_ *s = &m->motor_state[i];
        s->mode = (uint8_t)(i % 2u);
        s->q = 0.5f * (float)i;
        s->dq = -0.25f * (float)i;
        s->tau_est = 1.5f;
        s->temperature = (uint8_t)(30 + i);
        s->lost = 3u * i;
    }
    m->bms_state.version_high = 1;
    m->bms_state.version_low = 2;
    m->bms_state.status = 3;
    m->bms_state.soc = 80;
    m->bms_state.current = -1500;
    m->bms_state.cycle = 42;
    m->bms_state.bq_ntc[0] = 253;
    m->bms_state.bq_ntc[1] = 4;
    m->bms_state.mcu_ntc[0] = 5;
    m->bms_state.mcu_ntc[1] = 250;
    for (i = 0; i < 15u; i++)
        m->bms_state.cell_vol[i] = (uint16_t)(3700u + i);
    m->foot_force[0] = 10;
    m->foot_force[1] = -20;
    m->foot_force[2] = 30;
    m->foot_force[3] = -40;
    for (i = 0; i < 4u; i++)
        m->foot_force_est[i] = (int16_t)(i + 1u);
    m->tick = 123456;
    for (i = 0; i < 40u; i++)
        m->wireless_remote[i] = (uint8_t)i;
    m->bit_flag = 0x5A;
    m->adc_reel = 0.75f;
    m->temperature_ntc1 = 33;
    m->temperature_ntc2 = 34;
    m->power_v = 24.5f;
    m->power_a = -1.25f;
    for (i = 0; i < 4u; i++)
        m->fan_frequency[i] = (uint16_t)(100u * (i + 1u));
    m->reserve = 0xCAFEF00Du;
}

/* The unitree_hg samples for the crc alone (the same in golden.py). */
static void hg_low_cmd(unitree_hg_msg_dds__LowCmd_ *m)
{
    unsigned i;
    memset(m, 0, sizeof *m);
    m->mode_pr = 1;
    m->mode_machine = 6;
    for (i = 0; i < 35u; i++) {
        unitree_hg_msg_dds__MotorCmd_ *c = &m->motor_cmd[i];
        c->mode = i % 3u == 0u ? 1u : 0u;
        c->q = 0.125f * (float)i;
        c->dq = -0.25f * (float)i;
        c->tau = 0.5f;
        c->kp = 40.0f;
        c->kd = 1.5f;
        c->reserve = 100u + i;
    }
    for (i = 0; i < 4u; i++)
        m->reserve[i] = 0x01010101u * (i + 1u);
}

static void hg_low_state(unitree_hg_msg_dds__LowState_ *m)
{
    static const float imu[13] = {1.0f, 0, 0, 0, 0.5f, -0.5f, 0.25f, 0, 0, 9.75f, 0.125f, -0.125f, 3.0f};
    unsigned i;
    memset(m, 0, sizeof *m);
    m->version[0] = 1;
    m->version[1] = 2;
    m->mode_pr = 0;
    m->mode_machine = 5;
    m->tick = 987654;
    memcpy(m->imu_state.quaternion, imu, 4 * sizeof(float));
    memcpy(m->imu_state.gyroscope, imu + 4, 3 * sizeof(float));
    memcpy(m->imu_state.accelerometer, imu + 7, 3 * sizeof(float));
    memcpy(m->imu_state.rpy, imu + 10, 3 * sizeof(float));
    m->imu_state.temperature = -7;
    for (i = 0; i < 35u; i++) {
        unitree_hg_msg_dds__MotorState_ *s = &m->motor_state[i];
        s->mode = (uint8_t)(i % 2u);
        s->q = 0.5f * (float)i;
        s->dq = -0.25f * (float)i;
        s->ddq = 0.0625f;
        s->tau_est = 1.5f;
        s->temperature[0] = (int16_t)(30 + (int)i);
        s->temperature[1] = (int16_t)(-5 - (int)i);
        s->vol = 24.25f;
        s->sensor[0] = i;
        s->sensor[1] = 7u * i;
        s->motorstate = i == 3u ? 0x20u : 0u;
        s->reserve[3] = 0xFFFFFFFFu - i;
    }
    for (i = 0; i < 40u; i++)
        m->wireless_remote[i] = (uint8_t)(200u + i);
    m->reserve[0] = 0xCAFEF00Du;
}

int main(int argc, char **argv)
{
    dds_domainid_t domain = argc > 1 ? (dds_domainid_t)atoi(argv[1]) : 0;
    dds_entity_t pp = dds_create_participant(domain, NULL, NULL);
    static sensor_msgs_msg_dds__JointState_ js;
    static unitree_go_msg_dds__LowCmd_ lc;
    static unitree_go_msg_dds__LowState_ ls;
    static unitree_hg_msg_dds__LowCmd_ hc;
    static unitree_hg_msg_dds__LowState_ hs;
    static std_msgs_msg_dds__Header_ hd = {{-2, 7u}, "ab"}; /* the same in golden.py */
    char hash[J288_DDS_TYPEHASH_LEN];
    int rc = 0, t;
    if (pp < 0) {
        fprintf(stderr, "dds_golden: participant: %s\n", dds_strretcode(pp));
        return 1;
    }
    joint_state(&js);
    low_cmd(&lc);
    printf("lowcmd_crc %08lx\n", (unsigned long)lc.crc);
    low_state(&ls);
    printf("lowstate_crc %08lx\n", (unsigned long)j288_dds_lowstate_crc(&ls));
    hg_low_cmd(&hc);
    printf("hg_lowcmd_crc %08lx\n", (unsigned long)j288_dds_hg_lowcmd_crc(&hc));
    hg_low_state(&hs);
    printf("hg_lowstate_crc %08lx\n", (unsigned long)j288_dds_hg_lowstate_crc(&hs));
    for (t = 0; t < (int)J288_DDS_NTYPES; t++) {
        j288_dds_typehash((j288_dds_type_t)t, hash);
        printf("typehash %s %s\n", j288_dds_type_name((j288_dds_type_t)t), hash);
    }
    if (print_cdr(pp, &sensor_msgs_msg_dds__JointState__desc, "joint_state", &js) != 0 ||
        print_cdr(pp, &unitree_go_msg_dds__LowCmd__desc, "lowcmd", &lc) != 0 ||
        print_cdr(pp, &std_msgs_msg_dds__Header__desc, "header", &hd) != 0)
        rc = 1;
    (void)dds_delete(pp);
    return rc;
}
