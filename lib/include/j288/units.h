/*
 * j288/units.h - SI units on the rotor side or on the output side.
 *
 * All wire quantities are rotor-side. The output shaft is the rotor through a reduction of
 * N = J288_GEAR_RATIO (288.35): output angle = rotor angle / N, output speed = rotor speed / N,
 * output torque = rotor torque * N, output stiffness and damping = rotor gains * N^2 (because
 * tau_out = N * tau_rotor and theta_rotor = N * theta_out).
 *
 * SI -> raw rounds to nearest (halves away from zero). A value outside the field's integer
 * range is an error naming the field (J288_ERR_RANGE_TAU ... _KD), never a silent wrap; NaN is
 * J288_ERR_NOT_FINITE; a negative gain is J288_ERR_NEG_GAIN. On any error the output is
 * untouched. The _clamped variant saturates instead and reports, as J288_FIELD_* bits, which
 * fields it changed; NaN is still refused there.
 *
 * Compiled only with J288_CONFIG_SI (config.h). All functions are pure: ISR-safe, reentrant.
 */
#ifndef J288_UNITS_H
#define J288_UNITS_H

#include "j288/config.h"
#include "j288/frame.h"

/* Bits reported by j288_cmd_from_si_clamped() (and the fixed-point j288/jointq.h, which has
 * them without J288_CONFIG_SI). */
#define J288_FIELD_TAU 0x01u
#define J288_FIELD_SPEED 0x02u
#define J288_FIELD_POS 0x04u
#define J288_FIELD_KP 0x08u
#define J288_FIELD_KD 0x10u

#if J288_CONFIG_SI

#ifdef __cplusplus
extern "C" {
#endif

#if J288_CONFIG_SI_FLOAT
typedef float j288_real_t;
#else
typedef double j288_real_t;
#endif

#define J288_GEAR_RATIO 288.35
#define J288_PI 3.14159265358979323846

/* LSB per SI unit, rotor side. The speed factor follows the manual (2.56 / 2 pi); a sister
 * product prints 256 / 2 pi, so it lives in this one place. */
#define J288_SCALE_TORQUE 256000.0                     /* per N*m       */
#define J288_SCALE_SPEED (2.56 / (2.0 * J288_PI))      /* per rad/s     */
#define J288_SCALE_POS (32768.0 / (2.0 * J288_PI))     /* per rad       */
#define J288_SCALE_KP 1280000.0                        /* per N*m/rad   */
#define J288_SCALE_KD 128000000.0                      /* per N*m*s/rad */
#define J288_SCALE_VOLTAGE 0.5                         /* V per LSB     */

typedef enum { J288_SIDE_ROTOR = 0, J288_SIDE_OUTPUT = 1 } j288_side_t;

typedef struct {
    uint8_t id;       /* as j288_cmd_raw_t */
    uint8_t status;   /* as j288_cmd_raw_t */
    bool watchdog;
    j288_real_t tau;  /* N*m    (feed-forward torque) */
    j288_real_t speed;/* rad/s  */
    j288_real_t pos;  /* rad    */
    j288_real_t kp;   /* N*m/rad, >= 0 */
    j288_real_t kd;   /* N*m*s/rad, >= 0 */
} j288_cmd_si_t;

typedef struct {
    uint8_t id;
    uint8_t status;
    bool watchdog_tripped;
    j288_real_t case_temp_c;
    j288_real_t winding_temp_c;
    j288_real_t voltage_v;
    j288_real_t torque;     /* N*m   on the chosen side */
    j288_real_t speed;      /* rad/s on the chosen side */
    j288_real_t pos;        /* rad   on the chosen side (the rotor's multi-turn count) */
    j288_real_t out_pos;    /* rad, output encoder, [0, 2 pi), absolute over one turn */
    uint32_t faults;
    uint8_t warnings;
} j288_reply_si_t;

/* SI -> raw command. Errors: J288_ERR_NULL, J288_ERR_BAD_ARG (side), J288_ERR_NOT_FINITE,
 * J288_ERR_NEG_GAIN, J288_ERR_RANGE_TAU/_SPEED/_POS/_KP/_KD. id and status are copied
 * unchecked; j288_cmd_encode() checks them. */
int j288_cmd_from_si(const j288_cmd_si_t *si, j288_side_t side, j288_cmd_raw_t *raw);

/* As j288_cmd_from_si(), but a value outside its range (or a negative gain) is saturated to
 * the nearest representable value and its J288_FIELD_* bit set in *clamped (0 when nothing
 * was clamped; clamped may be NULL). Still fails on NaN, NULL or a bad side. */
int j288_cmd_from_si_clamped(const j288_cmd_si_t *si, j288_side_t side, j288_cmd_raw_t *raw,
                             unsigned *clamped);

/* SI straight to a frame: j288_cmd_from_si() then j288_cmd_encode(). */
int j288_cmd_encode_si(const j288_cmd_si_t *si, j288_side_t side, uint8_t out[J288_CMD_LEN],
                       const j288_crc_t *crc);

/* Raw -> SI (exact but for the division). Errors: J288_ERR_NULL, J288_ERR_BAD_ARG. */
int j288_reply_to_si(const j288_reply_raw_t *raw, j288_side_t side, j288_reply_si_t *si);
int j288_cmd_to_si(const j288_cmd_raw_t *raw, j288_side_t side, j288_cmd_si_t *si);

/* Single quantities, for tools and control code. *_to_raw return the rounded value through
 * *raw and J288_OK, or a J288_ERR_RANGE_* / J288_ERR_NOT_FINITE / J288_ERR_NEG_GAIN code. */
int j288_torque_to_raw(j288_real_t nm, j288_side_t side, int16_t *raw);
int j288_speed_to_raw(j288_real_t rad_s, j288_side_t side, int16_t *raw);
int j288_pos_to_raw(j288_real_t rad, j288_side_t side, int32_t *raw);
int j288_kp_to_raw(j288_real_t nm_per_rad, j288_side_t side, int16_t *raw);
int j288_kd_to_raw(j288_real_t nms_per_rad, j288_side_t side, int16_t *raw);
/* *_from_raw cannot fail: a side other than J288_SIDE_OUTPUT or J288_SIDE_ROTOR is taken as
 * the rotor side (the wire's own units). */
j288_real_t j288_torque_from_raw(int32_t raw, j288_side_t side);
j288_real_t j288_speed_from_raw(int32_t raw, j288_side_t side);
j288_real_t j288_pos_from_raw(int32_t raw, j288_side_t side);
j288_real_t j288_kp_from_raw(int32_t raw, j288_side_t side);
j288_real_t j288_kd_from_raw(int32_t raw, j288_side_t side);
j288_real_t j288_out_pos_to_rad(uint16_t out_pos);

#ifdef __cplusplus
}
#endif

#endif /* J288_CONFIG_SI */
#endif /* J288_UNITS_H */
