/*
 * j288/error.h - the library's result codes.
 *
 * Every function that can fail returns int: J288_OK (0) on success, one of the negative codes
 * below on failure. Bus-level results (timeout, CRC, wrong id, ...) are library results; the
 * servo's own fault and warning bits travel in the decoded reply (frame.h), never here.
 */
#ifndef J288_ERROR_H
#define J288_ERROR_H

#ifdef __cplusplus
extern "C" {
#endif

enum {
    J288_OK = 0,

    /* Caller errors: nothing was written or sent. */
    J288_ERR_NULL = -1,        /* a required pointer argument was NULL */
    J288_ERR_BAD_ID = -2,      /* id outside 0-14 (15 = broadcast where allowed) */
    J288_ERR_BAD_STATUS = -3,  /* status (mode) other than lock (0) or FOC (1) */
    J288_ERR_NEG_GAIN = -4,    /* k_pos or k_spd below zero */
    J288_ERR_RANGE_TAU = -5,   /* torque outside the int16 wire range */
    J288_ERR_RANGE_SPEED = -6, /* speed outside the int16 wire range */
    J288_ERR_RANGE_POS = -7,   /* position outside the int32 wire range */
    J288_ERR_RANGE_KP = -8,    /* stiffness outside the int16 wire range */
    J288_ERR_RANGE_KD = -9,    /* damping outside the int16 wire range */
    J288_ERR_NOT_FINITE = -10, /* an SI value was NaN */
    J288_ERR_RANGE = -11,      /* another field outside its range (device-side encoders) */
    J288_ERR_BAD_ARG = -12,    /* an argument outside its documented set (side, length...) */
    J288_ERR_BAD_CONFIG = -13, /* a configuration field outside its range */
    J288_ERR_PORT_OPS = -14,   /* the port lacks a required operation */

    /* Frame errors: bytes that are not a valid frame. */
    J288_ERR_BAD_HEADER = -20, /* first two bytes are not the expected head */
    J288_ERR_CRC = -21,        /* CRC mismatch */
    J288_ERR_TRUNCATED = -22,  /* a frame still incomplete at the deadline (or a flush) */

    /* Bus results. */
    J288_ERR_BUSY = -30,       /* a transaction is already in progress */
    J288_ERR_TIMEOUT = -31,    /* no valid reply before the deadline */
    J288_ERR_WRONG_ID = -32,   /* a valid reply came from another servo id */
    J288_ERR_COLLISION = -33,  /* the echo of our command differed: someone else talked */
    J288_ERR_LINE = -34,       /* the UART reported a framing/noise/overrun error */
    J288_ERR_PORT = -35,       /* a port operation failed (start_tx returned an error) */
    J288_ERR_TX_TIMEOUT = -36, /* transmit-complete never came */
    J288_ERR_ABORTED = -37,    /* dropped by an emergency stop or an abort */
    J288_ERR_OVERFLOW = -38,   /* received bytes arrived faster than they were consumed */
    J288_ERR_OFFLINE = -39,    /* device gone (unplugged adapter, closed simulator) */

    /* Joint layer (joint.h): nothing was produced. */
    J288_ERR_ANGLE_UNKNOWN = -50, /* the joint's absolute angle is not known (yet, or any more) */
    J288_ERR_CAL_MISMATCH = -51,  /* the calibrated phase disagrees with the output encoder */
    J288_ERR_LIMIT_POS = -52,     /* target position outside the joint's soft limits */
    J288_ERR_LIMIT_SPEED = -53,   /* target speed beyond the joint's limit */
    J288_ERR_LIMIT_TORQUE = -54,  /* target torque beyond the joint's limit */
    J288_ERR_CAL_DATA = -55       /* calibration data fail a quality check */
};

/* A short English description of a result code; never NULL, "unknown error" for a code
 * outside the list. ISR-safe; the string is static. */
const char *j288_strerror(int err);

#ifdef __cplusplus
}
#endif

#endif /* J288_ERROR_H */
