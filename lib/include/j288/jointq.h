/*
 * j288/jointq.h - the joint core: the one joint state machine of j288, in integers.
 *
 * What it does (docs/joint.md has the model): an absolute joint angle from the first replies
 * after power-up, its tracking, soft limits in every mode, events, and rotor-frame commands
 * from joint-frame targets, with a binding that keeps a scheduler's slots safe. The float API
 * of j288/joint.h is a facade over these functions: it converts configuration, targets and
 * state at its edge and runs this code, so a host, Python and a Cortex-M0 run the same state
 * machine and get the same commands, bit for bit. No floating-point operation, no soft-float
 * library: 32 x 32 -> 64-bit products (inline on Cortex-M0) and, at a start only, 32-bit
 * divisions. Always compiled (J288_CONFIG_SI=0 or 1); --gc-sections drops what is not called.
 *
 * Numbers. Angles are j288_q24_t: rad * 2^24 in an int64 (step 60 nrad, range +-2^39 rad,
 * 5.5e11 rad; a joint's angle is followed to 2.7e11 rad, a wheel at 30 rad/s for 285 years,
 * and a continuous joint's position targets are taken within +-2^38 rad). Speeds, torques
 * and gains are j288_q16_t: the SI value * 2^16 in an int32 (rad/s, N*m, N*m/rad, N*m*s/rad;
 * step 1.5e-5, range +-32768). J288_Q24() and J288_Q16() make constants of them. The gear
 * ratio is the exact fraction N = 5767 / 20 (20 output turns are exactly 5767 rotor turns);
 * constants with pi are the exact values rounded. pi itself is J288_JOINTQ_PI =
 * round(pi 2^24), 28 nrad above pi: a limit or tolerance of pi, configured here or converted
 * from the float API, is that value, and the default range [-pi, pi] is [-J288_JOINTQ_PI,
 * J288_JOINTQ_PI].
 *
 * The model. The rotor turns N times per output turn: r = N theta + c (theta the output angle,
 * c a phase fixed at assembly); a reply's rotor position is p = r - 2 pi k, k lost at every
 * power-up; the 13-bit output encoder (OutPos) gives theta modulo 2 pi in 0.77 mrad counts.
 * - Start: init_samples replies (default 8) are averaged into the output angle at an anchor
 *   rotor position (each contributes OutPos's count centre minus the rotor's motion since the
 *   first, so motion during the start does not matter; one that disagrees with the first by
 *   more than track_tol restarts the collection; fault bit 12 stops it).
 * - Turn choice: the angle is labelled q = direction (theta + 2 pi m - zero) with the m that
 *   puts q within pi of the middle of [pos_min, pos_max] (of 0 for a continuous joint). In Q24
 *   that is: q - middle is brought into [-(T - 1) / 2, (T - 1) / 2], T = J288_JOINTQ_TWO_PI,
 *   which is odd: no value is a tie (pi 2^24 is not an integer). A real angle of exactly pi
 *   rounds to J288_JOINTQ_PI, above pi, and is labelled -pi: [-pi, pi) as in the float API.
 * - Uncalibrated (no phase): q then follows the rotor, q = q0 + direction (p - p0) / N;
 *   absolute to within half a count (0.38 mrad), relative with the rotor's 0.66 urad.
 *   Calibrated (phase c from j288_cal_*, j288/joint.h): the rotor turn is chosen from the
 *   encoder and c, absolute with the rotor's resolution; eps (the phase residual) beyond
 *   cal_tol refuses the start (J288_JOINT_EV_CAL_MISMATCH).
 * - The angle is not bounded: the anchor moves by exactly 20 output turns (40 pi) whenever the
 *   rotor is 10 turns of output from it, so the angle stays within 2 Q24 steps of the exact
 *   value however far the joint turns (the wire's int32 rotor position is followed modulo
 *   2^32). A continuous joint (config.continuous) has no limits and turns for ever; its angle
 *   starts within pi of 0 (of zero, in the encoder's frame) and is never wrapped.
 * - Tracking: every reply compares the rotor-derived angle with the encoder; a difference
 *   (the residual, [-pi, pi]) beyond track_tol loses the angle (J288_JOINT_EV_ANGLE_LOST:
 *   unknown again, the start begins anew). With fault bit 12 the encoder is not used.
 *
 * Soft limits (not for a continuous joint), in every mode (docs/joint.md has the rule's why):
 * - Targets: a position outside [pos_min, pos_max] (checked only when kp > 0: with kp = 0 the
 *   position has no effect on the servo's law), or a speed or torque beyond max_speed /
 *   max_torque, is refused (J288_ERR_LIMIT_*) or, with clamp, saturated.
 * - A target "drives toward" the upper limit hi when its law, the servo's
 *   tau = T + kp (P - q) + kd (V - w), would push the joint on from rest at hi:
 *   T + kp (P - hi) + kd V > 0 (toward the lower limit lo: T + kp (P - lo) + kd V < 0). Targets
 *   that do not (a position inside the range with a feed-forward below its spring there,
 *   speed and torque 0, a speed or torque toward the range) are sent as they are, also to a
 *   joint beyond its range: so a joint found beyond a limit takes any target that brings it
 *   back (a position inside, a speed or a torque toward the range).
 * - The limit law of hi is a hold at hi, speed 0, no feed-forward, damping kd_L and stiffness
 *   kp_L = kd_L * J288_JOINTQ_LIMIT_RATE: tau_L = kd_L (2 (hi - q) - w), a speed toward hi of
 *   twice the remaining distance per second. kd_L is the largest of the target's kd, the
 *   joint's configured kd and J288_JOINTQ_LIMIT_KD (2 N*m*s/rad), at most 21 N*m*s/rad (the
 *   wire's range).
 * - A target that drives toward hi is sent while its law pushes less toward hi than the limit
 *   law, both taken at the latest reply's angle q and speed w; else the limit law is sent
 *   (J288_JOINT_LIMITED in *clamped). So the joint slows as it nears hi and comes to rest at
 *   it (short by static friction / kp_L), or is pulled back to it from beyond, without
 *   overshoot as long as J <= kd_L / (4 * J288_JOINTQ_LIMIT_RATE), J its inertia at the
 *   output: 0.25 kg m^2 with the least kd_L (the simulated J288's rotor is 0.17 at the
 *   output); a heavier joint needs a larger kd configured. The servo's torque is bounded by
 *   its own range; max_torque bounds the targets' feed-forward.
 * - A shaped command is only right for the state it was made at: j288_jointq_command() makes
 *   it for the latest reply, and the binding makes it again from the target on every reply
 *   for targets that can drive toward a limit (a speed or a torque). An application that
 *   calls j288_jointq_command() itself must do so once per reply, as its control loop does.
 * Holding near a limit (j288_jointq_target_init()): a joint beyond a limit by at most
 * J288_JOINTQ_HOLD_BEYOND (0.05 rad) is held at that limit, which pulls it in; farther
 * beyond, the hold target is where it is, which is refused (J288_ERR_LIMIT_POS; use a speed
 * or torque toward the range, or clamp). Lock: while the angle is unknown, only lock.
 *
 * Safety. While the angle is unknown every target is refused (J288_ERR_ANGLE_UNKNOWN, or
 * J288_ERR_CAL_MISMATCH after a failed calibrated start) and the binding keeps lock on the
 * joint's slot; when the angle is lost, the slot's next command becomes lock from inside the
 * scheduler's on_reply hook, before anything else is sent.
 *
 * Commands round the exact value of the Q16/Q24 target half away from zero: exactly for
 * torque and gains (rational factors); for speed and position (factors with pi) to within
 * 2^-15 LSB of the exact value, so only a value that close to a half may round either way.
 *
 * Objects are caller-allocated; nothing is allocated, no global state. Calling context: one
 * context per joint and binding (the thread that polls, or with advance_in_isr the bus's
 * interrupt); the functions take no lock. The conversions (j288_cmd_from_q*, j288_*_to_q)
 * are pure: ISR-safe, reentrant.
 */
#ifndef J288_JOINTQ_H
#define J288_JOINTQ_H

#include <stdbool.h>
#include <stdint.h>

#include "j288/config.h"
#include "j288/frame.h"
#include "j288/sched.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Events, reported by j288_jointq_take_reply() (and j288_joint_take_reply()) as bits
 * (1u << kind), in this order. */
typedef enum {
    J288_JOINT_EV_ENCODER_FAULT = 0, /* fault bit 12 set: the output encoder is not used */
    J288_JOINT_EV_ENCODER_OK,        /* fault bit 12 cleared */
    J288_JOINT_EV_ANGLE_UNKNOWN,     /* first reply since init/reset: the angle is not yet known */
    J288_JOINT_EV_ANGLE_LOST,        /* rotor and encoder disagree (value: the residual, rad):
                                        unknown again, lock, the start begins anew */
    J288_JOINT_EV_CAL_MISMATCH,      /* a calibrated start failed (value: eps, rotor rad);
                                        reported once until a start succeeds */
    J288_JOINT_EV_ANGLE_KNOWN,       /* the start is done (value: the joint angle) */
    J288_JOINT_EV_LIMIT_REACHED,     /* the angle went outside [pos_min, pos_max] (value: it) */
    J288_JOINT_EV_LIMIT_LEFT         /* back inside by J288_JOINTQ_LIMIT_HYST (value: it) */
} j288_joint_event_kind_t;

#define J288_JOINT_EV_BIT(kind) (1u << (unsigned)(kind))
#define J288_JOINT_EV_COUNT 8u
#define J288_JOINT_DEFAULT_INIT_SAMPLES 8u /* replies averaged at the start */

/* In *clamped of a command, beside the J288_FIELD_* bits (units.h): the limit law was sent
 * instead of the target (see "Soft limits" above). */
#define J288_JOINT_LIMITED 0x20u

typedef int64_t j288_q24_t; /* rad * 2^24 */
typedef int32_t j288_q16_t; /* SI value * 2^16 */

/* Constants from real literals, rounded half away from zero (constant expressions: the
 * compiler folds them; never use them on variables in an FPU-less build). Defined for every
 * x: beyond the type's range (J288_Q24: |x| >= 2^39 rad; J288_Q16: |x| >= 32768) and for NaN
 * they saturate at the type's extreme, a value every function taking it refuses or clamps. */
#define J288_Q24(x)                                                                           \
    ((j288_q24_t)(!((x) < 549755813888.0)                                                     \
                      ? INT64_MAX                                                             \
                      : (!((x) > -549755813888.0)                                             \
                             ? INT64_MIN                                                      \
                             : (int64_t)(((x) * 16777216.0) + (((x) < 0) ? -0.5 : 0.5)))))
#define J288_Q16(x)                                                                           \
    ((j288_q16_t)(!((x) < 32768.0)                                                            \
                      ? INT32_MAX                                                             \
                      : (!((x) > -32768.0)                                                    \
                             ? INT32_MIN                                                      \
                             : (int32_t)(((x) * 65536.0) + (((x) < 0) ? -0.5 : 0.5)))))

#define J288_JOINTQ_PI 52707179                /* round(pi 2^24): pi in Q24, 28 nrad above */
#define J288_JOINTQ_TWO_PI 105414357           /* round(2 pi 2^24), odd */
#define J288_JOINTQ_MAX_ANGLE 1073741824       /* 64 rad: bound of zero, pos_min, pos_max */
#define J288_JOINTQ_DEFAULT_TRACK_TOL 167772   /* 0.010 rad of output: 13 OutPos counts */
#define J288_JOINTQ_DEFAULT_CAL_TOL 16777216   /* 1.0 rad of rotor: 3.5 mrad of output */
#define J288_JOINTQ_LIMIT_HYST 16777           /* 0.001 rad: inside by this to leave a limit */
#define J288_JOINTQ_HOLD_BEYOND 838861         /* 0.05 rad: beyond by at most this, hold at
                                                  the limit (j288_jointq_target_init()) */
#define J288_JOINTQ_LIMIT_RATE 2               /* 1/s: the limit law's kp_L / kd_L */
#define J288_JOINTQ_LIMIT_KD 131072            /* 2 N*m*s/rad: the limit law's least kd_L */

/* A joint's configuration. All-zero (but id) means: the output encoder angle wrapped to
 * [-pi, pi), direction +1, limits [-pi, pi], no speed or torque limit but the wire's, targets
 * refused beyond the limits. Checked by j288_jointq_init(). */
typedef struct {
    uint8_t id;            /* servo id, 0-14 */
    int8_t direction;      /* +1 or -1 (0: +1): the joint's sense against the output's */
    bool clamp;            /* true: saturate targets at the limits instead of refusing */
    bool has_phase;        /* phase holds a calibrated c: the calibrated mode */
    bool continuous;       /* no position limits, the angle unbounded (a wheel); pos_min and
                              pos_max must be 0 */
    uint8_t init_samples;  /* replies averaged at the start, 1-255; 0: 8 */
    j288_q24_t zero;       /* rad, output-encoder frame: the output angle of joint angle 0,
                              within +-J288_JOINTQ_MAX_ANGLE */
    j288_q24_t pos_min;    /* rad, joint frame; pos_min = pos_max = 0: [-pi, pi] */
    j288_q24_t pos_max;    /*   else pos_min < pos_max, both within +-J288_JOINTQ_MAX_ANGLE */
    j288_q16_t max_speed;  /* rad/s, joint frame, >= 0; 0: only the wire's range */
    j288_q16_t max_torque; /* N*m, joint frame, >= 0; 0: only the wire's range */
    j288_q16_t kp;         /* default stiffness (hold), N*m/rad, joint frame, >= 0 */
    j288_q16_t kd;         /* default damping (hold, and the limit law's), N*m*s/rad, >= 0 */
    j288_q24_t phase;      /* c, rotor rad, |c| <= 2 pi; used when has_phase */
    j288_q24_t track_tol;  /* rad of output, 0 to pi; 0: J288_JOINTQ_DEFAULT_TRACK_TOL */
    j288_q24_t cal_tol;    /* rad of rotor, 0 to pi; 0: J288_JOINTQ_DEFAULT_CAL_TOL */
} j288_jointq_config_t;

/* A joint's view of its latest reply (j288_jointq_state()). */
typedef struct {
    bool known;              /* pos is the absolute joint angle */
    bool calibrated;         /* known through the phase, with the rotor's resolution */
    bool cal_mismatch;       /* the latest calibrated start failed: see cal_residual */
    bool encoder_fault;      /* fault bit 12 in the latest reply: OutPos is not used */
    bool beyond_limit;       /* pos outside [pos_min, pos_max] (until back inside by 1 mrad) */
    j288_q24_t pos;          /* rad, joint frame; valid when known (0 before) */
    j288_q16_t speed;        /* rad/s, joint frame (from the rotor: always valid) */
    j288_q16_t torque;       /* N*m, joint frame (always valid) */
    j288_q24_t encoder;      /* rad, OutPos's count centre in [0, 2 pi) */
    j288_q24_t residual;     /* rad of output: rotor-derived minus encoder angle, in [-pi, pi];
                                0 while unknown or with an encoder fault; at a loss, the
                                residual that caused it */
    j288_q24_t cal_residual; /* rotor rad: eps of the latest calibrated start (0 before) */
} j288_jointq_state_t;

/* Joint-frame targets; the servo's law on them: tau = torque + kp (pos - q) + kd (speed - w). */
typedef struct {
    j288_q24_t pos;    /* rad, joint frame (used and checked only when kp > 0) */
    j288_q16_t speed;  /* rad/s, joint frame */
    j288_q16_t torque; /* N*m, joint frame, feed-forward */
    j288_q16_t kp;     /* N*m/rad, joint frame, >= 0 */
    j288_q16_t kd;     /* N*m*s/rad, joint frame, >= 0 */
} j288_jointq_target_t;

typedef struct {
    /* Private: read with j288_jointq_state() and j288_jointq_config(). */
    j288_jointq_config_t cfg;  /* defaults filled in, direction +-1 */
    j288_q24_t centre;         /* middle of [pos_min, pos_max]; 0 for a continuous joint */
    j288_q24_t start_q;        /* joint angle at the start's anchor */
    j288_q24_t ref_q;          /* joint angle at the anchor: start_q + 40 pi turns (direction) */
    int32_t ref_theta;         /* output angle at the anchor, wrapped: the tracking's base */
    int32_t ref_pos;           /* rotor LSB at the anchor */
    int32_t turns;             /* 20-output-turn steps of the anchor since the start */
    int32_t last_pos;          /* rotor LSB of the latest reply */
    int32_t init_pos;          /* rotor LSB of the start's first sample */
    int32_t init_e0;           /* its output angle (Q24) */
    int64_t init_sum;          /* sum of the later samples' differences to it */
    uint8_t init_n;            /* samples collected */
    bool seen;                 /* a reply came since init/reset */
    bool live;                 /* the binding remakes live_target's command on every reply */
    j288_jointq_target_t live_target;
    j288_cmd_raw_t live_cmd;   /* the command the binding made of it last */
    j288_jointq_state_t st;
} j288_jointq_t;

/* Check cfg and set the joint up (angle unknown). Errors (joint untouched): J288_ERR_NULL,
 * J288_ERR_BAD_ID (id > 14), J288_ERR_BAD_CONFIG (direction not -1/0/1, a value outside its
 * documented range, pos_min >= pos_max, limits on a continuous joint). */
int j288_jointq_init(j288_jointq_t *j, const j288_jointq_config_t *cfg);

/* Forget the angle: the next replies start anew (e.g. the application knows the servo was
 * power-cycled). NULL is ignored. */
void j288_jointq_reset(j288_jointq_t *j);

/* The configuration in use: as given, with the defaults filled in (pos_min = pos_max = 0
 * become -+J288_JOINTQ_PI, direction 0 becomes 1 ...). NULL for NULL. Valid as long as j. */
const j288_jointq_config_t *j288_jointq_config(const j288_jointq_t *j);

/* Take one reply of this joint's servo: update the state, run the start, the tracking check
 * and the limit check, and set *events (may be NULL) to the events' bits (J288_JOINT_EV_BIT).
 * Errors (joint and *events untouched): J288_ERR_NULL, J288_ERR_WRONG_ID (the reply is from
 * another id). The reply is only read during the call; no field of it is trusted beyond its
 * type's range (OutPos is taken modulo 8192). */
int j288_jointq_take_reply(j288_jointq_t *j, const j288_reply_raw_t *reply, unsigned *events);

/* The state after the latest reply (all zero before one), or NULL for NULL. Valid as long as
 * the joint; changed by the next j288_jointq_take_reply(). */
const j288_jointq_state_t *j288_jointq_state(const j288_jointq_t *j);

/* A target that holds the joint at rest with its default gains: where it is, or at the
 * nearest limit when it is beyond one by at most J288_JOINTQ_HOLD_BEYOND (see "Holding near a
 * limit"); 0 while the angle is unknown. NULL arguments are ignored. */
void j288_jointq_target_init(const j288_jointq_t *j, j288_jointq_target_t *t);

/*
 * Target -> FOC command in the rotor frame (watchdog bit on), shaped at the limits for the
 * latest reply (see "Soft limits"). *clamped (may be NULL) gets the J288_FIELD_* bits
 * (units.h) of the fields saturated in clamp mode, and J288_JOINT_LIMITED when the limit law
 * was sent; 0 otherwise. With kp = 0 the command's position is the rotor's latest (it has no
 * effect on the law). Errors (cmd and *clamped untouched): J288_ERR_NULL;
 * J288_ERR_ANGLE_UNKNOWN, or J288_ERR_CAL_MISMATCH after a failed calibrated start;
 * J288_ERR_LIMIT_POS / _SPEED / _TORQUE (refuse mode); then as j288_cmd_from_q() in field order
 * (J288_ERR_RANGE_TAU, _SPEED, J288_ERR_NEG_GAIN or J288_ERR_RANGE_KP, then KD; clamp mode
 * saturates those); J288_ERR_RANGE_POS when the rotor target would leave the int32 wire range
 * (never clamped: that would be a different place), which a position within 190 rad of the
 * joint's angle never does unless the rotor count itself is near the end of int32.
 */
int j288_jointq_command(const j288_jointq_t *j, const j288_jointq_target_t *t,
                        j288_cmd_raw_t *cmd, unsigned *clamped);

/* The lock command for this joint (no torque; watchdog bit on). Errors: J288_ERR_NULL. */
int j288_jointq_lock_command(const j288_jointq_t *j, j288_cmd_raw_t *cmd);

/* Zero at the current pose: the zero (output-encoder frame) that makes the latest angle joint
 * angle 0, for the configuration; j288_jointq_init() with it to use it. Errors (*zero
 * untouched): J288_ERR_NULL, J288_ERR_ANGLE_UNKNOWN, J288_ERR_RANGE when that zero is beyond
 * +-J288_JOINTQ_MAX_ANGLE (64 rad, included: what j288_jointq_init() takes). */
int j288_jointq_zero_here(const j288_jointq_t *j, j288_q24_t *zero);

/* ---- conversions, output side (the joint frame before direction and anchor) */

/* An output-side command in fixed point (as j288_cmd_si_t with J288_SIDE_OUTPUT). */
typedef struct {
    uint8_t id; /* as j288_cmd_raw_t, copied unchecked */
    uint8_t status;
    bool watchdog;
    j288_q16_t tau;   /* N*m */
    j288_q16_t speed; /* rad/s */
    j288_q24_t pos;   /* rad */
    j288_q16_t kp;    /* N*m/rad, >= 0 */
    j288_q16_t kd;    /* N*m*s/rad, >= 0 */
} j288_cmd_q_t;

/* Output side -> raw command, rounding half away from zero (see the top of this file).
 * Errors, first failing field in frame order, raw untouched: J288_ERR_NULL,
 * J288_ERR_RANGE_TAU, _SPEED, _POS (|pos| >= 256 rad, 2^32 in Q24; the wire itself reaches
 * 1428 rad of output), J288_ERR_NEG_GAIN, J288_ERR_RANGE_KP, _KD. */
int j288_cmd_from_q(const j288_cmd_q_t *q, j288_cmd_raw_t *raw);

/* As j288_cmd_from_q(), saturating instead (J288_FIELD_* bits into *clamped, may be NULL;
 * a position beyond 256 rad becomes the wire's int32 extreme): fails only on NULL. */
int j288_cmd_from_q_clamped(const j288_cmd_q_t *q, j288_cmd_raw_t *raw, unsigned *clamped);

/* A reply's output-side speed and torque (within 1 Q16 step of the exact value; torque
 * exactly rounded) and OutPos's count centre (within 1 Q24 step). Pure. */
j288_q16_t j288_speed_to_q(int16_t raw);
j288_q16_t j288_torque_to_q(int16_t raw);
j288_q24_t j288_out_pos_to_q(uint16_t out_pos);

/* ---- binding: the joints of one scheduler (one bus); a robot has one binding per bus. */

typedef struct {
    j288_joint_event_kind_t kind;
    uint8_t id;
    const j288_jointq_t *joint;
    j288_q24_t value; /* rad (rotor rad for CAL_MISMATCH), see the kinds */
} j288_jointq_event_t;

/* Called from the context that advances the bus (inside the scheduler's on_reply: in an
 * interrupt with advance_in_isr, so keep it short). ev is valid during the call only. */
typedef void (*j288_jointq_event_fn)(void *user, const j288_jointq_event_t *ev);

typedef struct {
    /* Private. */
    j288_sched_t *sched;
    j288_jointq_t *joint[J288_MAX_SERVOS];
    j288_jointq_event_fn on_event;
    void *user;
} j288_jointq_bus_t;

/*
 * Bind joints to a scheduler. Register the binding as the scheduler's reply hook: in the
 * j288_sched_config_t given to j288_sched_init(), on_reply = j288_jointq_bus_on_reply and
 * user = the binding (or call j288_jointq_bus_on_reply(binding, id, slot) from your own
 * on_reply). on_event may be NULL. Errors: J288_ERR_NULL. The binding must not move while the
 * scheduler uses it.
 */
int j288_jointq_bus_init(j288_jointq_bus_t *jb, j288_sched_t *sched,
                         j288_jointq_event_fn on_event, void *user);

/* Add joint j (initialised) under its id and set its slot's command to lock. Enabling the
 * slot is the application's (j288_sched_enable()). The binding keeps the pointer: j must stay
 * valid and in place as long as the binding is in use (there is no remove). Errors:
 * J288_ERR_NULL, J288_ERR_BAD_CONFIG (another joint has that id here). */
int j288_jointq_bus_add(j288_jointq_bus_t *jb, j288_jointq_t *j);

/* The scheduler's reply hook (j288_reply_fn; user: the binding). Feeds the reply to the
 * joint with that id (none: nothing happens); keeps its slot at lock while the angle is
 * unknown (replacing any other command at once, so a loss is answered before the next
 * transaction); remakes the command of a target set with j288_jointq_bus_set_target() that
 * can drive toward a limit (a speed or a torque), as long as the slot still holds the
 * command it made last (a lock, an emergency stop or any command put in the slot otherwise
 * ends that; a target that fails at the new state puts lock in the slot); then reports the
 * joint's events to on_event in J288_JOINT_EV_* order. */
void j288_jointq_bus_on_reply(void *user, uint8_t id, const j288_slot_t *slot);

/* j288_jointq_command() for joint j, then j288_sched_set_cmd() (its next transaction); a
 * target that drives toward a limit is kept and its command made again on every reply.
 * Errors: those of j288_jointq_command() (the slot and the kept target unchanged);
 * J288_ERR_BAD_ARG when j is not bound here. */
int j288_jointq_bus_set_target(j288_jointq_bus_t *jb, const j288_jointq_t *j,
                               const j288_jointq_target_t *t, unsigned *clamped);

/* Put joint j's slot at lock (no torque), and forget its target. Errors: J288_ERR_NULL,
 * J288_ERR_BAD_ARG. */
int j288_jointq_bus_lock(j288_jointq_bus_t *jb, const j288_jointq_t *j);

#ifdef __cplusplus
}
#endif

#endif /* J288_JOINTQ_H */
