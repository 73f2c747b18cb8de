/* Result code descriptions; see j288/error.h. */
#include "j288/error.h"

#include <stddef.h>

typedef struct {
    int code;
    const char *text;
} err_text_t;

const char *j288_strerror(int err)
{
    static const err_text_t err_texts[] = {
        {J288_OK, "ok"},
        {J288_ERR_NULL, "required pointer is NULL"},
        {J288_ERR_BAD_ID, "servo id out of range (0-14, 15 = broadcast)"},
        {J288_ERR_BAD_STATUS, "status must be lock (0) or FOC (1)"},
        {J288_ERR_NEG_GAIN, "gain must not be negative"},
        {J288_ERR_RANGE_TAU, "torque out of range (int16 on the wire)"},
        {J288_ERR_RANGE_SPEED, "speed out of range (int16 on the wire)"},
        {J288_ERR_RANGE_POS, "position out of range (int32 on the wire)"},
        {J288_ERR_RANGE_KP, "stiffness out of range (int16 on the wire)"},
        {J288_ERR_RANGE_KD, "damping out of range (int16 on the wire)"},
        {J288_ERR_NOT_FINITE, "value is not a number"},
        {J288_ERR_RANGE, "field out of range"},
        {J288_ERR_BAD_ARG, "invalid argument"},
        {J288_ERR_BAD_CONFIG, "invalid configuration"},
        {J288_ERR_PORT_OPS, "port lacks a required operation"},
        {J288_ERR_BAD_HEADER, "bad frame header"},
        {J288_ERR_CRC, "CRC mismatch"},
        {J288_ERR_TRUNCATED, "truncated frame"},
        {J288_ERR_BUSY, "bus busy"},
        {J288_ERR_TIMEOUT, "no reply before the deadline"},
        {J288_ERR_WRONG_ID, "reply from another servo id"},
        {J288_ERR_COLLISION, "bus collision (echo mismatch)"},
        {J288_ERR_LINE, "UART line error"},
        {J288_ERR_PORT, "port operation failed"},
        {J288_ERR_TX_TIMEOUT, "transmit never completed"},
        {J288_ERR_ABORTED, "aborted by emergency stop"},
        {J288_ERR_OVERFLOW, "receive overflow"},
        {J288_ERR_OFFLINE, "device gone"},
        {J288_ERR_ANGLE_UNKNOWN, "joint angle not known (starting, or lost)"},
        {J288_ERR_CAL_MISMATCH, "calibrated phase disagrees with the output encoder"},
        {J288_ERR_LIMIT_POS, "target position outside the joint's limits"},
        {J288_ERR_LIMIT_SPEED, "target speed beyond the joint's limit"},
        {J288_ERR_LIMIT_TORQUE, "target torque beyond the joint's limit"},
        {J288_ERR_CAL_DATA, "calibration data fail a quality check"},
    };
    size_t i;
    for (i = 0; i < (sizeof(err_texts) / sizeof(err_texts[0])); i++) {
        if (err_texts[i].code == err) {
            return err_texts[i].text;
        }
    }
    return "unknown error";
}
