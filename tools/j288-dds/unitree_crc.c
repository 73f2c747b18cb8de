/* unitree_crc.c - see unitree_crc.h. A small cursor writes each member at its C alignment. */
#include "unitree_crc.h"

#include <string.h>

#include "j288/crc32.h"

typedef struct {
    uint8_t *buf;
    size_t pos;
} packer_t;

static void align(packer_t *p, size_t a)
{
    while (p->pos % a != 0u)
        p->buf[p->pos++] = 0u;
}

static void put_u8(packer_t *p, uint8_t v)
{
    p->buf[p->pos++] = v;
}

static void put_u16(packer_t *p, uint16_t v)
{
    align(p, 2u);
    p->buf[p->pos++] = (uint8_t)(v & 0xFFu);
    p->buf[p->pos++] = (uint8_t)(v >> 8);
}

static void put_u32(packer_t *p, uint32_t v)
{
    unsigned k;
    align(p, 4u);
    for (k = 0; k < 4u; k++)
        p->buf[p->pos++] = (uint8_t)((v >> (8u * k)) & 0xFFu);
}

static void put_f32(packer_t *p, float f)
{
    uint32_t v;
    memcpy(&v, &f, sizeof v);
    put_u32(p, v);
}

static void put_f32s(packer_t *p, const float *f, size_t n)
{
    size_t k;
    for (k = 0; k < n; k++)
        put_f32(p, f[k]);
}

static void put_u16s(packer_t *p, const uint16_t *v, size_t n)
{
    size_t k;
    for (k = 0; k < n; k++)
        put_u16(p, v[k]);
}

static void put_i16s(packer_t *p, const int16_t *v, size_t n)
{
    size_t k;
    for (k = 0; k < n; k++)
        put_u16(p, (uint16_t)v[k]);
}

static void put_u32s(packer_t *p, const uint32_t *v, size_t n)
{
    size_t k;
    for (k = 0; k < n; k++)
        put_u32(p, v[k]);
}

static void put_bytes(packer_t *p, const uint8_t *b, size_t n)
{
    memcpy(p->buf + p->pos, b, n);
    p->pos += n;
}

/* The shared head: head[2], level_flag, frame_reserve, sn[2], version[2], bandwidth. */
static void put_head(packer_t *p, const uint8_t head[2], uint8_t level, uint8_t frame_reserve,
                     const uint32_t sn[2], const uint32_t version[2], uint16_t bandwidth)
{
    put_bytes(p, head, 2u);
    put_u8(p, level);
    put_u8(p, frame_reserve);
    put_u32(p, sn[0]);
    put_u32(p, sn[1]);
    put_u32(p, version[0]);
    put_u32(p, version[1]);
    put_u16(p, bandwidth);
}

void j288_dds_pack_lowcmd(const unitree_go_msg_dds__LowCmd_ *m, uint8_t out[J288_DDS_LOWCMD_PACKED])
{
    packer_t p = {out, 0u};
    unsigned i, k;
    put_head(&p, m->head, m->level_flag, m->frame_reserve, m->sn, m->version, m->bandwidth);
    for (i = 0; i < 20u; i++) {
        const unitree_go_msg_dds__MotorCmd_ *c = &m->motor_cmd[i];
        align(&p, 4u); /* the struct's alignment */
        put_u8(&p, c->mode);
        put_f32(&p, c->q);
        put_f32(&p, c->dq);
        put_f32(&p, c->tau);
        put_f32(&p, c->kp);
        put_f32(&p, c->kd);
        for (k = 0; k < 3u; k++)
            put_u32(&p, c->reserve[k]);
    }
    put_u8(&p, m->bms_cmd.off); /* BmsCmd: 4 bytes, alignment 1 */
    put_bytes(&p, m->bms_cmd.reserve, 3u);
    put_bytes(&p, m->wireless_remote, 40u);
    put_bytes(&p, m->led, 12u);
    put_bytes(&p, m->fan, 2u);
    put_u8(&p, m->gpio);
    put_u32(&p, m->reserve);
    put_u32(&p, 0u); /* crc */
    align(&p, 4u);
}

void j288_dds_pack_lowstate(const unitree_go_msg_dds__LowState_ *m,
                            uint8_t out[J288_DDS_LOWSTATE_PACKED])
{
    packer_t p = {out, 0u};
    const unitree_go_msg_dds__IMUState_ *imu = &m->imu_state;
    const unitree_go_msg_dds__BmsState_ *bms = &m->bms_state;
    unsigned i;
    put_head(&p, m->head, m->level_flag, m->frame_reserve, m->sn, m->version, m->bandwidth);
    align(&p, 4u);
    put_f32s(&p, imu->quaternion, 4u);
    put_f32s(&p, imu->gyroscope, 3u);
    put_f32s(&p, imu->accelerometer, 3u);
    put_f32s(&p, imu->rpy, 3u);
    put_u8(&p, imu->temperature);
    for (i = 0; i < 20u; i++) {
        const unitree_go_msg_dds__MotorState_ *s = &m->motor_state[i];
        align(&p, 4u);
        put_u8(&p, s->mode);
        put_f32(&p, s->q);
        put_f32(&p, s->dq);
        put_f32(&p, s->ddq);
        put_f32(&p, s->tau_est);
        put_f32(&p, s->q_raw);
        put_f32(&p, s->dq_raw);
        put_f32(&p, s->ddq_raw);
        put_u8(&p, s->temperature);
        put_u32(&p, s->lost);
        put_u32(&p, s->reserve[0]);
        put_u32(&p, s->reserve[1]);
    }
    align(&p, 4u); /* BmsState holds an int32 */
    put_u8(&p, bms->version_high);
    put_u8(&p, bms->version_low);
    put_u8(&p, bms->status);
    put_u8(&p, bms->soc);
    put_u32(&p, (uint32_t)bms->current);
    put_u16(&p, bms->cycle);
    put_u8(&p, bms->bq_ntc[0]);
    put_u8(&p, bms->bq_ntc[1]);
    put_u8(&p, bms->mcu_ntc[0]);
    put_u8(&p, bms->mcu_ntc[1]);
    put_u16s(&p, bms->cell_vol, 15u);
    align(&p, 4u); /* end of BmsState (size 44) */
    put_i16s(&p, m->foot_force, 4u);
    put_i16s(&p, m->foot_force_est, 4u);
    put_u32(&p, m->tick);
    put_bytes(&p, m->wireless_remote, 40u);
    put_u8(&p, m->bit_flag);
    put_f32(&p, m->adc_reel);
    put_u8(&p, m->temperature_ntc1);
    put_u8(&p, m->temperature_ntc2);
    put_f32(&p, m->power_v);
    put_f32(&p, m->power_a);
    put_u16s(&p, m->fan_frequency, 4u);
    put_u32(&p, m->reserve);
    put_u32(&p, 0u); /* crc */
    align(&p, 4u);
}

uint32_t j288_dds_lowcmd_crc(const unitree_go_msg_dds__LowCmd_ *m)
{
    uint8_t buf[J288_DDS_LOWCMD_PACKED];
    j288_dds_pack_lowcmd(m, buf);
    return j288_crc32(buf, J288_DDS_LOWCMD_PACKED / 4u - 1u);
}

uint32_t j288_dds_lowstate_crc(const unitree_go_msg_dds__LowState_ *m)
{
    uint8_t buf[J288_DDS_LOWSTATE_PACKED];
    j288_dds_pack_lowstate(m, buf);
    return j288_crc32(buf, J288_DDS_LOWSTATE_PACKED / 4u - 1u);
}

void j288_dds_pack_hg_lowcmd(const unitree_hg_msg_dds__LowCmd_ *m,
                             uint8_t out[J288_DDS_HG_LOWCMD_PACKED])
{
    packer_t p = {out, 0u};
    unsigned i;
    put_u8(&p, m->mode_pr);
    put_u8(&p, m->mode_machine);
    for (i = 0; i < 35u; i++) {
        const unitree_hg_msg_dds__MotorCmd_ *c = &m->motor_cmd[i];
        align(&p, 4u); /* the struct's alignment */
        put_u8(&p, c->mode);
        put_f32(&p, c->q);
        put_f32(&p, c->dq);
        put_f32(&p, c->tau);
        put_f32(&p, c->kp);
        put_f32(&p, c->kd);
        put_u32(&p, c->reserve);
    }
    put_u32s(&p, m->reserve, 4u);
    put_u32(&p, 0u); /* crc */
}

void j288_dds_pack_hg_lowstate(const unitree_hg_msg_dds__LowState_ *m,
                               uint8_t out[J288_DDS_HG_LOWSTATE_PACKED])
{
    packer_t p = {out, 0u};
    const unitree_hg_msg_dds__IMUState_ *imu = &m->imu_state;
    unsigned i;
    put_u32s(&p, m->version, 2u);
    put_u8(&p, m->mode_pr);
    put_u8(&p, m->mode_machine);
    put_u32(&p, m->tick);
    put_f32s(&p, imu->quaternion, 4u);
    put_f32s(&p, imu->gyroscope, 3u);
    put_f32s(&p, imu->accelerometer, 3u);
    put_f32s(&p, imu->rpy, 3u);
    put_i16s(&p, &imu->temperature, 1u);
    for (i = 0; i < 35u; i++) {
        const unitree_hg_msg_dds__MotorState_ *s = &m->motor_state[i];
        align(&p, 4u);
        put_u8(&p, s->mode);
        put_f32(&p, s->q);
        put_f32(&p, s->dq);
        put_f32(&p, s->ddq);
        put_f32(&p, s->tau_est);
        put_i16s(&p, s->temperature, 2u);
        put_f32(&p, s->vol);
        put_u32s(&p, s->sensor, 2u);
        put_u32(&p, s->motorstate);
        put_u32s(&p, s->reserve, 4u);
    }
    put_bytes(&p, m->wireless_remote, 40u);
    put_u32s(&p, m->reserve, 4u);
    put_u32(&p, 0u); /* crc */
}

uint32_t j288_dds_hg_lowcmd_crc(const unitree_hg_msg_dds__LowCmd_ *m)
{
    uint8_t buf[J288_DDS_HG_LOWCMD_PACKED];
    j288_dds_pack_hg_lowcmd(m, buf);
    return j288_crc32(buf, J288_DDS_HG_LOWCMD_PACKED / 4u - 1u);
}

uint32_t j288_dds_hg_lowstate_crc(const unitree_hg_msg_dds__LowState_ *m)
{
    uint8_t buf[J288_DDS_HG_LOWSTATE_PACKED];
    j288_dds_pack_hg_lowstate(m, buf);
    return j288_crc32(buf, J288_DDS_HG_LOWSTATE_PACKED / 4u - 1u);
}
