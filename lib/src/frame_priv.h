/*
 * frame_priv.h - what frame.c gives the other modules of lib/ (not installed, not API): a
 * whole frame's CRC check, the reply unpacked from words already read, and the command checks,
 * packer and lock command (one copy for the encoder, the bus, the scheduler and the joints).
 */
#ifndef J288_FRAME_PRIV_H
#define J288_FRAME_PRIV_H

#include <stdbool.h>
#include <stdint.h>
#include <string.h>

#include "crc32_priv.h"
#include "hints.h"
#include "j288/frame.h"

/* The head's two bytes as one little-endian halfword, for a single compare. */
#define J288_CMD_HEAD16 (J288_CMD_HEAD0 | ((uint32_t)J288_CMD_HEAD1 << 8u))
#define J288_REPLY_HEAD16 (J288_REPLY_HEAD0 | ((uint32_t)J288_REPLY_HEAD1 << 8u))

/* A whole reply's CRC (bytes 2-21) against its field (bytes 22-25), with constant offsets so
 * that the default table backends unroll to straight-line code. The head is not checked. */
static J288_INLINE_HOT bool j288_reply_crc_ok(const j288_crc_t *crc, const uint8_t *f)
{
    return j288_crc_frame_hot(crc, &f[2], 5u) == j288_get_u32le(&f[22]);
}

/* The same for a whole command (bytes 0-15, field 16-19). */
static J288_INLINE_HOT bool j288_cmd_crc_ok(const j288_crc_t *crc, const uint8_t *f)
{
    return j288_crc_frame_hot(crc, f, 4u) == j288_get_u32le(&f[16]);
}

/* j288_reply_unpack() from the reply's words 1-5 as values (word i: bytes 4i+2 .. 4i+5,
 * little-endian), e.g. read aligned from the parser's buffer. */
void j288_reply_unpack_words(const uint32_t w[5], j288_reply_raw_t *reply);

/* The encoder's checks, in its order: J288_ERR_BAD_ID (id > 15), J288_ERR_BAD_STATUS,
 * J288_ERR_NEG_GAIN, else J288_OK. */
static inline int j288_cmd_check(const j288_cmd_raw_t *cmd)
{
    if (cmd->id > J288_BROADCAST_ID) {
        return J288_ERR_BAD_ID;
    }
    if (cmd->status > J288_MODE_FOC) {
        return J288_ERR_BAD_STATUS;
    }
    if ((cmd->kp < 0) || (cmd->kd < 0)) {
        return J288_ERR_NEG_GAIN;
    }
    return J288_OK;
}

/* j288_cmd_encode() without its checks, for a command that passed them (the scheduler's
 * slots: j288_sched_set_cmd() checks, init and estop make lock commands). */
void j288_cmd_pack(const j288_cmd_raw_t *cmd, uint8_t out[J288_CMD_LEN], const j288_crc_t *crc);

/* Lock (no torque), every other field 0: the scheduler's initial and post-estop command, and
 * with id 15 and the watchdog on, the emergency stop frame. */
static inline void j288_cmd_lock(j288_cmd_raw_t *c, uint8_t id, bool watchdog)
{
    (void)memset(c, 0, sizeof *c);
    c->id = id;
    c->status = J288_MODE_LOCK;
    c->watchdog = watchdog;
}

#endif /* J288_FRAME_PRIV_H */
