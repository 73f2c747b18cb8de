/*
 * j288/frame.h - the 20-byte command and the 26-byte reply, as raw integers.
 *
 * Both directions exist: a host encodes commands and decodes replies, a device (the
 * simulator, tests) decodes commands and encodes replies. Fields are exactly the wire's
 * integers, rotor side; units.h converts to and from SI units.
 *
 * Encoders validate every field first: on any error they return a negative code and leave
 * the output buffer untouched. Decoders check the head and the CRC and never trust a field:
 * every value a byte can take is representable in the structs below, and the caller decides
 * what is acceptable. All functions are pure (no state): ISR-safe and reentrant. Buffers are
 * only used during the call.
 */
#ifndef J288_FRAME_H
#define J288_FRAME_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "j288/crc32.h"
#include "j288/error.h"

#ifdef __cplusplus
extern "C" {
#endif

#define J288_CMD_LEN 20u
#define J288_REPLY_LEN 26u
#define J288_CMD_HEAD0 0xFEu
#define J288_CMD_HEAD1 0xEEu
#define J288_REPLY_HEAD0 0xFCu
#define J288_REPLY_HEAD1 0xEEu

#define J288_MAX_ID 14u         /* servo addresses are 0..14 */
#define J288_BROADCAST_ID 15u   /* every servo obeys, none replies */
#define J288_MAX_SERVOS 15u

#define J288_MODE_LOCK 0u /* no torque */
#define J288_MODE_FOC 1u  /* closed loop: the servo runs the hybrid control law */

#define J288_OUT_POS_COUNTS 8192u /* output encoder counts per output turn (13 bits) */

/* Fault bits of j288_reply_raw_t.faults (MError). */
#define J288_FAULT_OVER_CURRENT (1ul << 0)
#define J288_FAULT_OVER_VOLTAGE_TRANSIENT (1ul << 1)
#define J288_FAULT_OVER_VOLTAGE (1ul << 2)
#define J288_FAULT_UNDER_VOLTAGE (1ul << 3)
#define J288_FAULT_CHIP_TEMP (1ul << 4)
#define J288_FAULT_MOSFET_TEMP (1ul << 5)
#define J288_FAULT_MOSFET_TEMP_ABNORMAL (1ul << 6)
#define J288_FAULT_CASE_TEMP (1ul << 7)
#define J288_FAULT_CASE_TEMP_ABNORMAL (1ul << 8)
#define J288_FAULT_WINDING_TEMP (1ul << 9)
#define J288_FAULT_ROTOR_ENCODER1 (1ul << 10)
#define J288_FAULT_ROTOR_ENCODER2 (1ul << 11)
#define J288_FAULT_OUTPUT_ENCODER (1ul << 12)
#define J288_FAULT_STORED_DATA (1ul << 13)
#define J288_FAULT_ABNORMAL_RESET (1ul << 14)
#define J288_FAULT_WAITING_UNLOCK (1ul << 15)
#define J288_FAULT_DRIVER_VERIFY (1ul << 16)
#define J288_FAULT_CALIBRATION (1ul << 17)
#define J288_FAULT_COMM_CHECKSUM (1ul << 18)
#define J288_FAULT_DRIVER_VERSION (1ul << 19)
#define J288_FAULT_FIRMWARE_MODEL (1ul << 20)
#define J288_FAULT_ENCODER_ANGLE (1ul << 21)
#define J288_FAULT_COUNT 22u
#define J288_FAULT_KNOWN_MASK ((1ul << J288_FAULT_COUNT) - 1ul)

/* Warning bits of j288_reply_raw_t.warnings (ExFlag, 3 bits). */
#define J288_WARN_LOW_SUPPLY (1u << 0)
#define J288_WARN_COUNT 3u

/* Host -> servo. */
typedef struct {
    uint8_t id;        /* 0-14, or 15 = broadcast */
    uint8_t status;    /* J288_MODE_LOCK or J288_MODE_FOC (3 bits on the wire) */
    bool watchdog;     /* true: enable the servo's 1 s communication watchdog */
    int16_t tau;       /* feed-forward rotor torque, 256000 LSB per N*m */
    int16_t speed;     /* rotor speed target, 2.56/(2 pi) LSB per rad/s */
    int32_t pos;       /* rotor position target, 32768/(2 pi) LSB per rad */
    int16_t kp;        /* rotor stiffness, 1280000 LSB per N*m/rad, >= 0 */
    int16_t kd;        /* rotor damping, 128000000 LSB per N*m*s/rad, >= 0 */
    uint8_t reserved;  /* byte 3; encoders send 0 whatever is here, decoders report it */
} j288_cmd_raw_t;

/* Servo -> host. */
typedef struct {
    uint8_t id;            /* 0-15 as received (a real servo never sends 15) */
    uint8_t status;        /* 0-7 as received */
    bool watchdog_tripped; /* the servo's watchdog has fired; cleared by a command with
                              the watchdog bit 0 */
    int8_t case_temp_c;    /* case temperature, deg C */
    uint8_t winding_temp_c;
    uint8_t voltage_raw;   /* 0.5 V per LSB */
    int16_t torque;        /* rotor torque, same scale as the command */
    int16_t speed;
    int32_t pos;
    uint32_t faults;       /* J288_FAULT_* bits; others are unknown faults */
    uint16_t out_pos;      /* output-shaft absolute encoder, 0-8191 */
    uint8_t warnings;      /* J288_WARN_* bits, 0-7 */
    uint16_t reserved;     /* bytes 20-21 */
} j288_reply_raw_t;

/*
 * Build a command frame. Errors (out untouched): J288_ERR_NULL, J288_ERR_BAD_ID (id > 15),
 * J288_ERR_BAD_STATUS (status > 1), J288_ERR_NEG_GAIN (kp or kd < 0). crc: NULL for the
 * default backend.
 */
int j288_cmd_encode(const j288_cmd_raw_t *cmd, uint8_t out[J288_CMD_LEN], const j288_crc_t *crc);

/* Device side: check head and CRC of a command frame and unpack it. Errors: J288_ERR_NULL,
 * J288_ERR_BAD_HEADER, J288_ERR_CRC (cmd untouched on error). Status and gains are reported
 * as received, even when an encoder would refuse them. */
int j288_cmd_decode(const uint8_t in[J288_CMD_LEN], j288_cmd_raw_t *cmd, const j288_crc_t *crc);

/* Device side: build a reply frame. Errors (out untouched): J288_ERR_NULL, J288_ERR_BAD_ID
 * (id > 14), J288_ERR_BAD_STATUS (status > 7), J288_ERR_RANGE (out_pos > 8191 or
 * warnings > 7). */
int j288_reply_encode(const j288_reply_raw_t *reply, uint8_t out[J288_REPLY_LEN],
                      const j288_crc_t *crc);

/* Host side: check head and CRC of a reply frame and unpack it. Errors: J288_ERR_NULL,
 * J288_ERR_BAD_HEADER, J288_ERR_CRC (reply untouched on error). */
int j288_reply_decode(const uint8_t in[J288_REPLY_LEN], j288_reply_raw_t *reply,
                      const j288_crc_t *crc);

/* Unpack without checking head or CRC: for frames the parser has already verified. */
void j288_reply_unpack(const uint8_t in[J288_REPLY_LEN], j288_reply_raw_t *reply);
void j288_cmd_unpack(const uint8_t in[J288_CMD_LEN], j288_cmd_raw_t *cmd);

/* CRC of a frame as it should be (command: bytes 0-15; reply: bytes 2-21), and the CRC
 * field it carries (its last four bytes). For tools that show both. j288_frame_crc_field()
 * reads nothing and returns 0 unless frame is non-NULL and len is J288_CMD_LEN or
 * J288_REPLY_LEN. */
uint32_t j288_cmd_crc_expected(const uint8_t in[J288_CMD_LEN], const j288_crc_t *crc);
uint32_t j288_reply_crc_expected(const uint8_t in[J288_REPLY_LEN], const j288_crc_t *crc);
uint32_t j288_frame_crc_field(const uint8_t *frame, size_t len);

/* Name of fault bit n (0-31): "over-current", ...; "unknown fault" for bits 22-31. Name of
 * warning bit n (0-2): "low-voltage supply abnormal", "unknown warning". Never NULL. */
const char *j288_fault_name(unsigned bit);
const char *j288_warning_name(unsigned bit);

/* Little-endian helpers, exposed because ports and tools need them too. */
static inline uint16_t j288_get_u16le(const uint8_t *p)
{
    return (uint16_t)((unsigned)p[0] | ((unsigned)p[1] << 8));
}
static inline uint32_t j288_get_u32le(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) |
           ((uint32_t)p[3] << 24);
}
static inline void j288_put_u16le(uint8_t *p, uint16_t v)
{
    p[0] = (uint8_t)(v & 0xFFu);
    p[1] = (uint8_t)(v >> 8);
}
static inline void j288_put_u32le(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)(v & 0xFFu);
    p[1] = (uint8_t)((v >> 8) & 0xFFu);
    p[2] = (uint8_t)((v >> 16) & 0xFFu);
    p[3] = (uint8_t)(v >> 24);
}

#ifdef __cplusplus
}
#endif

#endif /* J288_FRAME_H */
