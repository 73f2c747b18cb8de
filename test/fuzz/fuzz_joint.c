/*
 * Fuzz target: the joint core (j288/jointq.h) and its float facade (j288/joint.h) side by
 * side, fed arbitrary configurations, replies (any rotor count, OutPos, speed, torque, fault
 * bit 12), targets (any Q value) and resets.
 *
 * Input: byte 0 = config flags (bits 0-1 direction -1/0/+1, 2 clamp, 3 continuous, 4 has_phase,
 * 5-7 init_samples 0-7), then zero, pos_min, pos_max, phase as int16 (rad / 256), max_speed,
 * max_torque, kp, kd as uint16 (Q16 / 16); then operations until the input runs dry: an
 * op byte (low 2 bits: 0-1 reply, 2 target, 3 reset or zero_here) and its fields (reply: int32
 * pos, uint16 out_pos, int16 speed, int16 torque, the op's bit 2 fault 12; target: int32 pos
 * and a shift 0-31 (pos * 2^shift, Q24; shift bit 6: near INT64_MAX, bit 7 too: INT64_MIN),
 * int32 speed, torque, kp, kd).
 *
 * Invariants:
 * - core and facade agree on everything: init result, events, errors, clamp masks, command
 *   frames (bit for bit), and the facade's state is the core's converted (exactly: double);
 * - while known with a working encoder, |residual| <= track_tol (else the angle was lost);
 * - a command made is FOC, the joint's id, watchdog on; a refused one leaves cmd untouched;
 * - a continuous joint never reports a limit event and is never beyond a limit.
 */
#include "fuzz_common.h"

#include "j288/joint.h"
#include "j288/jointq.h"

#include <string.h>

#if J288_CONFIG_SI && !J288_CONFIG_SI_FLOAT

static double rad(j288_q24_t q)
{
    return (double)q / 16777216.0;
}

static double si16(j288_q16_t q)
{
    return (double)q / 65536.0;
}

static int16_t s16(fuzz_in_t *in)
{
    return (int16_t)fuzz_s16(fuzz_u16(in));
}

static int32_t s32(fuzz_in_t *in)
{
    return (int32_t)fuzz_s32(fuzz_u32(in));
}

static void configure(fuzz_in_t *in, j288_jointq_config_t *q, j288_joint_config_t *f)
{
    uint8_t flags = fuzz_u8(in);
    memset(q, 0, sizeof *q);
    q->direction = (int8_t)((int)(flags & 3u) - 1);
    q->clamp = (flags & 4u) != 0u;
    q->continuous = (flags & 8u) != 0u;
    q->has_phase = (flags & 16u) != 0u;
    q->init_samples = (uint8_t)(flags >> 5);
    q->id = 3u;
    q->zero = (j288_q24_t)s16(in) * 65536;
    q->pos_min = (j288_q24_t)s16(in) * 65536;
    q->pos_max = (j288_q24_t)s16(in) * 65536;
    q->phase = (j288_q24_t)s16(in) * 65536;
    q->max_speed = (j288_q16_t)fuzz_u16(in) * 16;
    q->max_torque = (j288_q16_t)fuzz_u16(in) * 16;
    q->kp = (j288_q16_t)fuzz_u16(in) * 16;
    q->kd = (j288_q16_t)fuzz_u16(in) * 16;
    memset(f, 0, sizeof *f);
    f->id = q->id;
    f->direction = q->direction;
    f->clamp = q->clamp;
    f->continuous = q->continuous;
    f->has_phase = q->has_phase;
    f->init_samples = q->init_samples;
    f->zero = rad(q->zero);
    f->pos_min = rad(q->pos_min);
    f->pos_max = rad(q->pos_max);
    f->phase = rad(q->phase);
    f->max_speed = si16(q->max_speed);
    f->max_torque = si16(q->max_torque);
    f->kp = si16(q->kp);
    f->kd = si16(q->kd);
}

static int same_cmd(const j288_cmd_raw_t *a, const j288_cmd_raw_t *b)
{
    return (a->id == b->id) && (a->status == b->status) && (a->watchdog == b->watchdog) &&
           (a->tau == b->tau) && (a->speed == b->speed) && (a->pos == b->pos) &&
           (a->kp == b->kp) && (a->kd == b->kd);
}

static void check_state(const j288_jointq_t *q, const j288_joint_t *f)
{
    const j288_jointq_state_t *a = j288_jointq_state(q);
    const j288_joint_state_t *b = j288_joint_state(f);
    FUZZ_CHECK(memcmp(a, &f->core.st, sizeof *a) == 0);
    FUZZ_CHECK(a->known == b->known && a->calibrated == b->calibrated &&
               a->beyond_limit == b->beyond_limit && a->cal_mismatch == b->cal_mismatch &&
               a->encoder_fault == b->encoder_fault);
    FUZZ_CHECK(rad(a->pos) == b->pos && rad(a->residual) == b->residual &&
               rad(a->encoder) == b->encoder && rad(a->cal_residual) == b->cal_residual);
    FUZZ_CHECK(si16(a->speed) == b->speed && si16(a->torque) == b->torque);
    if (a->known && !a->encoder_fault) {
        FUZZ_CHECK(a->residual <= q->cfg.track_tol && -a->residual <= q->cfg.track_tol);
    }
    if (q->cfg.continuous) {
        FUZZ_CHECK(!a->beyond_limit);
    }
}

static void reply(fuzz_in_t *in, uint8_t op, j288_jointq_t *q, j288_joint_t *f)
{
    j288_reply_raw_t r;
    unsigned ea = 0u, eb = 0u;
    memset(&r, 0, sizeof r);
    r.id = 3u;
    r.pos = s32(in);
    r.out_pos = fuzz_u16(in);
    r.speed = s16(in);
    r.torque = s16(in);
    r.faults = ((op & 4u) != 0u) ? J288_FAULT_OUTPUT_ENCODER : 0u;
    FUZZ_CHECK(j288_jointq_take_reply(q, &r, &ea) == J288_OK);
    FUZZ_CHECK(j288_joint_take_reply(f, &r, &eb) == J288_OK);
    FUZZ_CHECK(ea == eb);
    if (q->cfg.continuous) {
        FUZZ_CHECK((ea & (J288_JOINT_EV_BIT(J288_JOINT_EV_LIMIT_REACHED) |
                          J288_JOINT_EV_BIT(J288_JOINT_EV_LIMIT_LEFT))) == 0u);
    }
    check_state(q, f);
}

static void target(fuzz_in_t *in, j288_jointq_t *q, j288_joint_t *f)
{
    j288_jointq_target_t tq;
    j288_joint_target_t tf;
    j288_cmd_raw_t a, b, before;
    unsigned ma = 77u, mb = 77u;
    int ra, rb;
    {
        int32_t p = s32(in);
        uint8_t shift = fuzz_u8(in);
        /* bit 6: an extreme (near int64's ends, where differences overflow) */
        tq.pos = ((shift & 0x40u) != 0u) ? (((shift & 0x80u) != 0u) ? (INT64_MIN + (p & 0xFFFF))
                                                                    : (INT64_MAX - (p & 0xFFFF)))
                                         : (j288_q24_t)p * ((j288_q24_t)1 << (shift & 31u));
    }
    tq.speed = s32(in);
    tq.torque = s32(in);
    tq.kp = s32(in);
    tq.kd = s32(in);
    tf.pos = rad(tq.pos);
    tf.speed = si16(tq.speed);
    tf.torque = si16(tq.torque);
    tf.kp = si16(tq.kp);
    tf.kd = si16(tq.kd);
    memset(&before, 0x5A, sizeof before);
    before.watchdog = false; /* (a bool's bytes must be one) */
    a = before;
    b = before;
    ra = j288_jointq_command(q, &tq, &a, &ma);
    rb = j288_joint_command(f, &tf, &b, &mb);
    /* The facade saturates a real from 16384 - 2^-16 (Q16 +-(2^30 - 1)) on, where the core
     * takes it as it is: both are beyond every range, but the error, or whether the limit law
     * takes over, may then differ (a CI run found Q16 speed -(2^30 - 1) admitted here). */
    if ((tq.pos > -(1LL << 53)) && (tq.pos < (1LL << 53)) &&
        (tq.speed > -1073741823 && tq.speed < 1073741823) &&
        (tq.torque > -1073741823 && tq.torque < 1073741823) &&
        (tq.kp > -1073741823 && tq.kp < 1073741823) &&
        (tq.kd > -1073741823 && tq.kd < 1073741823)) {
        FUZZ_CHECK(ra == rb);
        FUZZ_CHECK(ma == mb);
        FUZZ_CHECK(same_cmd(&a, &b));
    }
    if (ra == J288_OK) {
        FUZZ_CHECK(a.status == J288_MODE_FOC && a.id == 3u && a.watchdog);
    } else {
        FUZZ_CHECK(same_cmd(&a, &before) && ma == 77u);
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static j288_jointq_t q;
    static j288_joint_t f;
    j288_jointq_config_t qc;
    j288_joint_config_t fc;
    fuzz_in_t in;
    int ra, rb;

    in.p = data;
    in.n = size;
    configure(&in, &qc, &fc);
    ra = j288_jointq_init(&q, &qc);
    rb = j288_joint_init(&f, &fc);
    FUZZ_CHECK(ra == rb);
    if (ra != J288_OK) {
        return 0;
    }
    while (in.n > 0u) {
        uint8_t op = fuzz_u8(&in);
        switch (op & 3u) {
        case 0u:
        case 1u:
            reply(&in, op, &q, &f);
            break;
        case 2u:
            target(&in, &q, &f);
            break;
        default:
            if ((op & 4u) != 0u) {
                j288_jointq_reset(&q);
                j288_joint_reset(&f);
                check_state(&q, &f);
            } else {
                j288_q24_t zq = 0;
                j288_real_t zf = 0.0;
                ra = j288_jointq_zero_here(&q, &zq);
                rb = j288_joint_zero_here(&f, &zf);
                FUZZ_CHECK(ra == rb && rad(zq) == zf);
            }
            break;
        }
    }
    return 0;
}

#else
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    (void)data;
    (void)size;
    return 0;
}
#endif
