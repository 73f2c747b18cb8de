/* Command and reply frames; see j288/frame.h for the contract. */
#include "j288/frame.h"

#include <string.h>

#include "frame_priv.h"

/* Byte offsets on the wire (spec tables). */
enum {
    CMD_MODE = 2, CMD_RES = 3, CMD_TAU = 4, CMD_SPEED = 6, CMD_POS = 8, CMD_KP = 12,
    CMD_KD = 14, CMD_CRC = 16, CMD_CRC_WORDS = 4,
    RPL_MODE = 2, RPL_TEMP = 3, RPL_SENSOR = 4, RPL_VOL = 5, RPL_TORQUE = 6, RPL_SPEED = 8,
    RPL_POS = 10, RPL_MERROR = 14, RPL_OUT = 18, RPL_RES = 20, RPL_CRC = 22,
    RPL_CRC_FIRST = 2, RPL_CRC_WORDS = 5
};

#define OUT_POS_MASK 0x1FFFu
#define EXFLAG_SHIFT 13u

/* mode byte: id in bits 0-3, status in bits 4-6, timeout in bit 7. */
static uint8_t mode_pack(uint8_t id, uint8_t status, bool timeout)
{
    return (uint8_t)((unsigned)id | ((unsigned)status << 4) | (timeout ? 0x80u : 0u));
}

static uint8_t mode_id(uint8_t mode) { return (uint8_t)(mode & 0x0Fu); }
static uint8_t mode_status(uint8_t mode) { return (uint8_t)((mode >> 4) & 0x07u); }
static bool mode_timeout(uint8_t mode) { return (mode & 0x80u) != 0u; }

/* Two's complement from the unsigned wire pattern, without implementation-defined casts
 * (flipping the sign bit and subtracting its weight; compilers emit one sign extension). */
static int16_t as_i16(uint16_t u)
{
    uint32_t flipped = (uint32_t)u ^ 0x8000u;
    int32_t v = (int32_t)flipped;
    return (int16_t)(v - 0x8000);
}

static int32_t as_i32(uint32_t u)
{
    if (u < 0x80000000u) {
        return (int32_t)u;
    }
    {
        uint32_t m = 0xFFFFFFFFu - u; /* 0 .. 0x7FFFFFFF: fits */
        return -(int32_t)m - 1;
    }
}

static uint16_t from_i16(int16_t v) { return (uint16_t)v; }
static uint32_t from_i32(int32_t v) { return (uint32_t)v; }

/* Two 16-bit fields as the little-endian word they make on the wire. */
static uint32_t pair16(int16_t lo, int16_t hi)
{
    return (uint32_t)from_i16(lo) | ((uint32_t)from_i16(hi) << 16);
}

#define CMD_HEAD16 J288_CMD_HEAD16
#define RPL_HEAD16 J288_REPLY_HEAD16

/* The frame as the four words it is made of (head, mode and reserved byte; tau and speed;
 * pos; kp and kd), then its CRC. Inlined in both its callers below. */
static J288_INLINE_HOT void cmd_pack(const j288_cmd_raw_t *cmd, uint8_t out[J288_CMD_LEN],
                                     const j288_crc_t *crc)
{
    uint32_t w[CMD_CRC_WORDS];
    w[0] = CMD_HEAD16 | ((uint32_t)mode_pack(cmd->id, cmd->status, cmd->watchdog) << 16);
    w[1] = pair16(cmd->tau, cmd->speed);
    w[2] = from_i32(cmd->pos);
    w[3] = pair16(cmd->kp, cmd->kd);
    j288_store_le32(&out[0], w[0]);
    j288_store_le32(&out[CMD_TAU], w[1]);
    j288_store_le32(&out[CMD_POS], w[2]);
    j288_store_le32(&out[CMD_KP], w[3]);
    /* The CRC from the words as computed: on cores without unaligned loads, reading them back
     * from out would cost four byte loads a word. */
    j288_store_le32(&out[CMD_CRC], j288_crc_frame_words(crc, out, w, CMD_CRC_WORDS));
}

void j288_cmd_pack(const j288_cmd_raw_t *cmd, uint8_t out[J288_CMD_LEN], const j288_crc_t *crc)
{
    cmd_pack(cmd, out, crc);
}

int j288_cmd_encode(const j288_cmd_raw_t *cmd, uint8_t out[J288_CMD_LEN], const j288_crc_t *crc)
{
    int err;

    if ((cmd == NULL) || (out == NULL)) {
        return J288_ERR_NULL;
    }
    err = j288_cmd_check(cmd);
    if (err != J288_OK) {
        return err;
    }
    cmd_pack(cmd, out, crc); /* every check done: out is written only now */
    return J288_OK;
}

void j288_cmd_unpack(const uint8_t in[J288_CMD_LEN], j288_cmd_raw_t *cmd)
{
    uint8_t mode = in[CMD_MODE];
    cmd->id = mode_id(mode);
    cmd->status = mode_status(mode);
    cmd->watchdog = mode_timeout(mode);
    cmd->reserved = in[CMD_RES];
    cmd->tau = as_i16(j288_get_u16le(&in[CMD_TAU]));
    cmd->speed = as_i16(j288_get_u16le(&in[CMD_SPEED]));
    cmd->pos = as_i32(j288_get_u32le(&in[CMD_POS]));
    cmd->kp = as_i16(j288_get_u16le(&in[CMD_KP]));
    cmd->kd = as_i16(j288_get_u16le(&in[CMD_KD]));
}

uint32_t j288_cmd_crc_expected(const uint8_t in[J288_CMD_LEN], const j288_crc_t *crc)
{
    return j288_crc_frame(crc, in, CMD_CRC_WORDS);
}

uint32_t j288_frame_crc_field(const uint8_t *frame, size_t len)
{
    /* Public: a bad length must not read before the buffer. */
    if ((frame == NULL) || ((len != J288_CMD_LEN) && (len != J288_REPLY_LEN))) {
        return 0u;
    }
    return j288_get_u32le(&frame[len - 4u]);
}

int j288_cmd_decode(const uint8_t in[J288_CMD_LEN], j288_cmd_raw_t *cmd, const j288_crc_t *crc)
{
    if ((in == NULL) || (cmd == NULL)) {
        return J288_ERR_NULL;
    }
    if (j288_get_u16le(in) != CMD_HEAD16) {
        return J288_ERR_BAD_HEADER;
    }
    if (j288_cmd_crc_expected(in, crc) != j288_get_u32le(&in[CMD_CRC])) {
        return J288_ERR_CRC;
    }
    j288_cmd_unpack(in, cmd);
    return J288_OK;
}

int j288_reply_encode(const j288_reply_raw_t *reply, uint8_t out[J288_REPLY_LEN],
                      const j288_crc_t *crc)
{
    uint8_t f[J288_REPLY_LEN];

    if ((reply == NULL) || (out == NULL)) {
        return J288_ERR_NULL;
    }
    if (reply->id > J288_MAX_ID) {
        return J288_ERR_BAD_ID;
    }
    if (reply->status > 7u) {
        return J288_ERR_BAD_STATUS;
    }
    if ((reply->out_pos > OUT_POS_MASK) || (reply->warnings > 7u)) {
        return J288_ERR_RANGE;
    }
    f[0] = J288_REPLY_HEAD0;
    f[1] = J288_REPLY_HEAD1;
    f[RPL_MODE] = mode_pack(reply->id, reply->status, reply->watchdog_tripped);
    f[RPL_TEMP] = (uint8_t)reply->case_temp_c;
    f[RPL_SENSOR] = reply->winding_temp_c;
    f[RPL_VOL] = reply->voltage_raw;
    j288_put_u16le(&f[RPL_TORQUE], from_i16(reply->torque));
    j288_put_u16le(&f[RPL_SPEED], from_i16(reply->speed));
    j288_put_u32le(&f[RPL_POS], from_i32(reply->pos));
    j288_put_u32le(&f[RPL_MERROR], reply->faults);
    j288_put_u16le(&f[RPL_OUT],
                   (uint16_t)(reply->out_pos | ((unsigned)reply->warnings << EXFLAG_SHIFT)));
    j288_put_u16le(&f[RPL_RES], reply->reserved);
    j288_put_u32le(&f[RPL_CRC], j288_crc_frame(crc, &f[RPL_CRC_FIRST], RPL_CRC_WORDS));
    (void)memcpy(out, f, sizeof f);
    return J288_OK;
}

/* The sign of a byte, as as_i16() does it for 16 bits. */
static int8_t as_i8(uint8_t u)
{
    return (int8_t)((u < 0x80u) ? (int)u : (int)u - 256);
}

/* Word i of w is the reply's bytes 4i+2 .. 4i+5 (little-endian): mode, case temperature,
 * winding temperature, voltage; torque, speed; position; faults; output position and
 * warnings, reserved. */
void j288_reply_unpack_words(const uint32_t w[5], j288_reply_raw_t *reply)
{
    uint8_t mode = (uint8_t)(w[0] & 0xFFu);
    uint16_t out = (uint16_t)(w[4] & 0xFFFFu);
    reply->id = mode_id(mode);
    reply->status = mode_status(mode);
    reply->watchdog_tripped = mode_timeout(mode);
    reply->case_temp_c = as_i8((uint8_t)((w[0] >> 8) & 0xFFu));
    reply->winding_temp_c = (uint8_t)((w[0] >> 16) & 0xFFu);
    reply->voltage_raw = (uint8_t)(w[0] >> 24);
    reply->torque = as_i16((uint16_t)(w[1] & 0xFFFFu));
    reply->speed = as_i16((uint16_t)(w[1] >> 16));
    reply->pos = as_i32(w[2]);
    reply->faults = w[3];
    reply->out_pos = (uint16_t)(out & OUT_POS_MASK);
    reply->warnings = (uint8_t)(out >> EXFLAG_SHIFT);
    reply->reserved = (uint16_t)(w[4] >> 16);
}

void j288_reply_unpack(const uint8_t in[J288_REPLY_LEN], j288_reply_raw_t *reply)
{
    uint8_t mode = in[RPL_MODE];
    uint16_t out = j288_get_u16le(&in[RPL_OUT]);
    reply->id = mode_id(mode);
    reply->status = mode_status(mode);
    reply->watchdog_tripped = mode_timeout(mode);
    reply->case_temp_c = as_i8(in[RPL_TEMP]);
    reply->winding_temp_c = in[RPL_SENSOR];
    reply->voltage_raw = in[RPL_VOL];
    reply->torque = as_i16(j288_get_u16le(&in[RPL_TORQUE]));
    reply->speed = as_i16(j288_get_u16le(&in[RPL_SPEED]));
    reply->pos = as_i32(j288_get_u32le(&in[RPL_POS]));
    reply->faults = j288_get_u32le(&in[RPL_MERROR]);
    reply->out_pos = (uint16_t)(out & OUT_POS_MASK);
    reply->warnings = (uint8_t)(out >> EXFLAG_SHIFT);
    reply->reserved = j288_get_u16le(&in[RPL_RES]);
}

uint32_t j288_reply_crc_expected(const uint8_t in[J288_REPLY_LEN], const j288_crc_t *crc)
{
    return j288_crc_frame(crc, &in[RPL_CRC_FIRST], RPL_CRC_WORDS);
}

int j288_reply_decode(const uint8_t in[J288_REPLY_LEN], j288_reply_raw_t *reply,
                      const j288_crc_t *crc)
{
    if ((in == NULL) || (reply == NULL)) {
        return J288_ERR_NULL;
    }
    if (j288_get_u16le(in) != RPL_HEAD16) {
        return J288_ERR_BAD_HEADER;
    }
    if (j288_reply_crc_expected(in, crc) != j288_get_u32le(&in[RPL_CRC])) {
        return J288_ERR_CRC;
    }
    j288_reply_unpack(in, reply);
    return J288_OK;
}

const char *j288_fault_name(unsigned bit)
{
    static const char *const fault_names[J288_FAULT_COUNT] = {
        "over-current",
        "transient over-voltage",
        "sustained over-voltage",
        "under-voltage",
        "chip over-temperature",
        "MOSFET over/under-temperature",
        "MOSFET temperature abnormal",
        "case over/under-temperature",
        "case temperature abnormal",
        "winding over-temperature",
        "rotor encoder 1 error",
        "rotor encoder 2 error",
        "output encoder error",
        "stored data error",
        "abnormal reset",
        "waiting for unlock",
        "driver verification error",
        "calibration mode",
        "communication checksum error",
        "driver version too low",
        "firmware model error",
        "encoder angle abnormal",
    };
    return (bit < J288_FAULT_COUNT) ? fault_names[bit] : "unknown fault";
}

const char *j288_warning_name(unsigned bit)
{
    return (bit == 0u) ? "low-voltage supply abnormal" : "unknown warning";
}
