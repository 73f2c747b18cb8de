/*
 * j288/jointq.h - the joint layer in fixed point, for cores without an FPU (Cortex-M0/M0+,
 * RV32IMAC): the model, the start, the tracking, the limits, the events and the binding of
 * j288/joint.h, in integers only. No floating-point operation, no soft-float library: 32 x 32
 * -> 64-bit products (inline on Cortex-M0) and, at a start only, 32-bit divisions (the C
 * library's helper where the core has no divide). Compiled with J288_CONFIG_JOINT_FIXED
 * (config.h, default 1), independently of J288_CONFIG_SI: an FPU-less build sets
 * J288_CONFIG_SI=0 and has no floating point at all.
 *
 * Numbers. Angles are j288_q24_t: rad * 2^24 in an int32 (step 60 nrad, range +-128 rad).
 * Speeds, torques and gains are j288_q16_t: the SI value * 2^16 in an int32 (rad/s, N*m,
 * N*m/rad, N*m*s/rad; step 1.5e-5). J288_Q24() and J288_Q16() make constants of them. The
 * gear ratio is the exact fraction N = 5767 / 20; constants that involve pi are rounded to
 * at least 2^-28 relative.
 *
 * The contract is j288/joint.h's, function for function (j288_jointq_* for j288_joint_*),
 * with these differences (docs/joint.md, "Fixed point"):
 * - Resolution: the state's angles to within 1 urad of the float layer's in double (the Q24
 *   roundings and the rounded 2 pi of the wraps; 74 nrad measured), speed and torque to
 *   within 1 Q16 step; the rotor's 0.66 urad and the output encoder's 0.77 mrad are coarser.
 * - Range: the joint angle is kept within +-J288_JOINTQ_MAX_POS (120 rad, 19 output turns);
 *   beyond, the state's angle saturates there (a joint that far beyond its +-64 rad
 *   configuration then fails the tracking check and is lost, unless its encoder has a fault).
 * - Commands round the exact value of the Q16/Q24 target half away from zero, as the float
 *   path does: exactly for torque and gains (rational factors); for speed and position (their
 *   factors contain pi) to within 2^-15 LSB of the exact value, i.e. a value that close to a
 *   half may round either way.
 * - No NaN: J288_ERR_NOT_FINITE is never returned. The calibration fit (j288_cal_*) stays in
 *   floating point, on a host: the phase it gives is configured here as J288_Q24(c).
 *
 * Objects are caller-allocated; nothing is allocated, no global state; calling context as
 * j288/joint.h (one context per joint and binding; the functions take no lock). The
 * conversions (j288_cmd_from_q*, j288_*_to_q) are pure: ISR-safe, reentrant.
 */
#ifndef J288_JOINTQ_H
#define J288_JOINTQ_H

#include <stdbool.h>
#include <stdint.h>

#include "j288/config.h"
#include "j288/frame.h"
#include "j288/joint.h"
#include "j288/sched.h"

#if J288_CONFIG_JOINT_FIXED

#ifdef __cplusplus
extern "C" {
#endif

typedef int32_t j288_q24_t; /* rad * 2^24 */
typedef int32_t j288_q16_t; /* SI value * 2^16 */

/* Constants from real literals, rounded half away from zero (constant expressions: the
 * compiler folds them; never use them on variables in an FPU-less build). */
#define J288_Q24(x) ((j288_q24_t)(((x) * 16777216.0) + (((x) < 0) ? -0.5 : 0.5)))
#define J288_Q16(x) ((j288_q16_t)(((x) * 65536.0) + (((x) < 0) ? -0.5 : 0.5)))

#define J288_JOINTQ_PI 52707179                /* pi in Q24 */
#define J288_JOINTQ_TWO_PI 105414357           /* 2 pi in Q24 */
#define J288_JOINTQ_MAX_ANGLE 1073741824       /* 64 rad: bound of zero, pos_min, pos_max */
#define J288_JOINTQ_MAX_POS 2013265920         /* 120 rad: the state's angle saturates here */
#define J288_JOINTQ_DEFAULT_TRACK_TOL 167772   /* 0.010 rad of output */
#define J288_JOINTQ_DEFAULT_CAL_TOL 16777216   /* 1.0 rad of rotor */
#define J288_JOINTQ_LIMIT_HYST 16777           /* 0.001 rad */

/* As j288_joint_config_t; all-zero (but id) means the same defaults. */
typedef struct {
    uint8_t id;            /* servo id, 0-14 */
    int8_t direction;      /* +1 or -1 (0: +1) */
    bool clamp;            /* true: saturate targets at the limits instead of refusing */
    bool has_phase;        /* phase holds a calibrated c */
    uint8_t init_samples;  /* replies averaged at the start, 1-255; 0: 8 */
    j288_q24_t zero;       /* rad, output-encoder frame, within +-J288_JOINTQ_MAX_ANGLE */
    j288_q24_t pos_min;    /* rad, joint frame; pos_min = pos_max = 0: [-pi, pi] */
    j288_q24_t pos_max;    /*   else pos_min < pos_max, both within +-MAX_ANGLE */
    j288_q16_t max_speed;  /* rad/s, joint frame, >= 0; 0: only the wire's range */
    j288_q16_t max_torque; /* N*m, joint frame, >= 0; 0: only the wire's range */
    j288_q16_t kp;         /* default stiffness, N*m/rad, >= 0 */
    j288_q16_t kd;         /* default damping, N*m*s/rad, >= 0 */
    j288_q24_t phase;      /* c, rotor rad, |c| <= 2 pi; used when has_phase */
    j288_q24_t track_tol;  /* rad of output, 0 to pi; 0: J288_JOINTQ_DEFAULT_TRACK_TOL */
    j288_q24_t cal_tol;    /* rad of rotor, 0 to pi; 0: J288_JOINTQ_DEFAULT_CAL_TOL */
} j288_jointq_config_t;

/* As j288_joint_state_t. */
typedef struct {
    bool known;
    bool calibrated;
    bool cal_mismatch;
    bool encoder_fault;
    bool beyond_limit;
    j288_q24_t pos;          /* rad, joint frame; valid when known */
    j288_q16_t speed;        /* rad/s, joint frame */
    j288_q16_t torque;       /* N*m, joint frame */
    j288_q24_t encoder;      /* rad, OutPos's count centre in [0, 2 pi) */
    j288_q24_t residual;     /* rad of output, in [-pi, pi] */
    j288_q24_t cal_residual; /* rotor rad */
} j288_jointq_state_t;

/* As j288_joint_target_t. */
typedef struct {
    j288_q24_t pos;    /* rad, joint frame */
    j288_q16_t speed;  /* rad/s */
    j288_q16_t torque; /* N*m, feed-forward */
    j288_q16_t kp;     /* N*m/rad, >= 0 */
    j288_q16_t kd;     /* N*m*s/rad, >= 0 */
} j288_jointq_target_t;

typedef struct {
    /* Private: read with j288_jointq_state(). */
    j288_jointq_config_t cfg; /* defaults filled in, direction +-1 */
    j288_q24_t centre;        /* middle of [pos_min, pos_max] */
    int32_t ref_pos;          /* rotor LSB at the anchor */
    j288_q24_t ref_q;         /* joint angle at the anchor */
    int32_t init_pos;         /* rotor LSB of the start's first sample */
    j288_q24_t init_e0;       /* its output angle */
    int64_t init_sum;         /* sum of the later samples' differences to it */
    uint8_t init_n;           /* samples collected */
    bool seen;                /* a reply came since init/reset */
    j288_jointq_state_t st;
} j288_jointq_t;

/* As j288_joint_init(): J288_ERR_NULL, J288_ERR_BAD_ID, J288_ERR_BAD_CONFIG. */
int j288_jointq_init(j288_jointq_t *j, const j288_jointq_config_t *cfg);

/* As j288_joint_reset(). */
void j288_jointq_reset(j288_jointq_t *j);

/* As j288_joint_take_reply(): J288_ERR_NULL, J288_ERR_WRONG_ID; events as J288_JOINT_EV_BIT. */
int j288_jointq_take_reply(j288_jointq_t *j, const j288_reply_raw_t *reply, unsigned *events);

/* As j288_joint_state(). */
const j288_jointq_state_t *j288_jointq_state(const j288_jointq_t *j);

/* As j288_joint_target_init(). */
void j288_jointq_target_init(const j288_jointq_t *j, j288_jointq_target_t *t);

/* As j288_joint_command(), without NaN: J288_ERR_NULL; J288_ERR_ANGLE_UNKNOWN or
 * J288_ERR_CAL_MISMATCH; J288_ERR_LIMIT_POS / _SPEED / _TORQUE (refuse mode); then as
 * j288_cmd_from_q() in field order (J288_ERR_RANGE_TAU, _SPEED, J288_ERR_NEG_GAIN or
 * J288_ERR_RANGE_KP, then KD; clamp mode saturates those); J288_ERR_RANGE_POS when the rotor
 * target would leave the int32 wire range (never clamped). cmd untouched on an error. */
int j288_jointq_command(const j288_jointq_t *j, const j288_jointq_target_t *t,
                        j288_cmd_raw_t *cmd, unsigned *clamped);

/* As j288_joint_lock_command(). */
int j288_jointq_lock_command(const j288_jointq_t *j, j288_cmd_raw_t *cmd);

/* As j288_joint_zero_here(); also J288_ERR_RANGE when the zero falls outside +-128 rad. */
int j288_jointq_zero_here(const j288_jointq_t *j, j288_q24_t *zero);

/* ---- conversions, output side (the joint frame before direction and anchor) */

/* An output-side command in fixed point: as j288_cmd_si_t with J288_SIDE_OUTPUT. */
typedef struct {
    uint8_t id;        /* as j288_cmd_raw_t, copied unchecked */
    uint8_t status;
    bool watchdog;
    j288_q16_t tau;    /* N*m */
    j288_q16_t speed;  /* rad/s */
    j288_q24_t pos;    /* rad */
    j288_q16_t kp;     /* N*m/rad, >= 0 */
    j288_q16_t kd;     /* N*m*s/rad, >= 0 */
} j288_cmd_q_t;

/* Output side -> raw command, rounding half away from zero (see the top of this file).
 * Errors, first failing field in frame order, raw untouched: J288_ERR_NULL,
 * J288_ERR_RANGE_TAU, _SPEED, J288_ERR_NEG_GAIN, J288_ERR_RANGE_KP, _KD (a Q24 position,
 * +-128 rad, is always within the wire's int32). */
int j288_cmd_from_q(const j288_cmd_q_t *q, j288_cmd_raw_t *raw);

/* As j288_cmd_from_q(), saturating instead (J288_FIELD_* bits into *clamped, may be NULL):
 * fails only on NULL. */
int j288_cmd_from_q_clamped(const j288_cmd_q_t *q, j288_cmd_raw_t *raw, unsigned *clamped);

/* A reply's output-side speed and torque (within 1 Q16 step of the exact value; torque
 * exactly rounded) and OutPos's count centre (within 1 Q24 step). Pure. */
j288_q16_t j288_speed_to_q(int16_t raw);
j288_q16_t j288_torque_to_q(int16_t raw);
j288_q24_t j288_out_pos_to_q(uint16_t out_pos);

/* ---- binding: as j288_joint_bus_t */

typedef struct {
    j288_joint_event_kind_t kind;
    uint8_t id;
    const j288_jointq_t *joint;
    j288_q24_t value; /* rad (rotor rad for CAL_MISMATCH), as j288_joint_event_t */
} j288_jointq_event_t;

typedef void (*j288_jointq_event_fn)(void *user, const j288_jointq_event_t *ev);

typedef struct {
    /* Private. */
    j288_sched_t *sched;
    j288_jointq_t *joint[J288_MAX_SERVOS];
    j288_jointq_event_fn on_event;
    void *user;
} j288_jointq_bus_t;

/* As j288_joint_bus_init() ... j288_joint_bus_lock(), errors and promises included. */
int j288_jointq_bus_init(j288_jointq_bus_t *jb, j288_sched_t *sched,
                         j288_jointq_event_fn on_event, void *user);
int j288_jointq_bus_add(j288_jointq_bus_t *jb, j288_jointq_t *j);
void j288_jointq_bus_on_reply(void *user, uint8_t id, const j288_slot_t *slot);
int j288_jointq_bus_set_target(j288_jointq_bus_t *jb, const j288_jointq_t *j,
                               const j288_jointq_target_t *t, unsigned *clamped);
int j288_jointq_bus_lock(j288_jointq_bus_t *jb, const j288_jointq_t *j);

#ifdef __cplusplus
}
#endif

#endif /* J288_CONFIG_JOINT_FIXED */
#endif /* J288_JOINTQ_H */
