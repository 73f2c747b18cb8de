/*
 * j288/joint.h - the joint frame in SI units: a float facade over the joint core.
 *
 * What a joint does is j288/jointq.h's, which has the model and the rules: the start from the
 * first replies after power-up (uncalibrated to half an OutPos count, calibrated with the
 * rotor's resolution), the turn choice, the tracking check, soft limits in every mode (the
 * limit law), continuous joints, the events, the binding and its lock rules. The functions
 * here convert at their edge and run the core: j288_joint_take_reply() runs
 * j288_jointq_take_reply() and converts the state; j288_joint_command() converts the target
 * and runs j288_jointq_command(). So a host, Python and a microcontroller run one state
 * machine: for the same configuration, replies and targets (converted as below) the commands
 * are the same, bit for bit, and the state is the core's, converted.
 *
 * The conversions (j288_real_t: double, or float with J288_CONFIG_SI_FLOAT=1):
 * - real -> core: x * 2^24 (angles) or x * 2^16 (speeds, torques, gains) rounded to the
 *   nearest integer, halves away from zero. Targets: NaN is refused here
 *   (J288_ERR_NOT_FINITE, before any other check but NULL); infinities and values beyond the
 *   core's range saturate at its extreme, which the core then refuses or clamps as any
 *   value beyond a limit. Configuration: NaN and infinities are J288_ERR_BAD_CONFIG; a
 *   speed, torque or gain beyond 32768 saturates there (beyond the wire's range anyway).
 *   So a limit or tolerance of J288_PI is J288_JOINTQ_PI, 28 nrad above pi, and a target
 *   within 30 nrad (half a Q24 step) of a limit is judged as its rounding. A float's pi
 *   (and 2 pi) lies above pi by 87 nrad, 1.5 steps: as a tolerance (or phase) it is beyond
 *   the bound and refused; the default range is [-pi, pi] as j288_real_t holds pi, so that
 *   a target of pi is inside it with float too.
 * - core -> real: exact in double for angles below 2^29 rad (a wheel at 30 rad/s for 200
 *   days; beyond, double rounds to 53 bits); in float, angles keep 24 significant bits: 60
 *   nrad below 1 rad, 0.5 urad at 8 rad, 8 urad at 128 rad, 0.25 rad at 2.6e6 rad (a wheel
 *   at 30 rad/s for a day). A continuous joint's angle stays exact in the core however far it
 *   turns; with float, read it with j288_jointq_state() (j288_joint_core()) and give
 *   positions as j288_q24_t, or steer it by speed.
 *
 * Objects are caller-allocated; nothing is allocated, no global state. Calling context: every
 * function on a joint, a binding or a calibration is for one context at a time. With a
 * binding, that is the context that advances the bus: the thread that polls, or with
 * advance_in_isr the bus's interrupt (e.g. set targets from the scheduler's on_sweep). The
 * functions take no lock. Compiled only with J288_CONFIG_SI.
 */
#ifndef J288_JOINT_H
#define J288_JOINT_H

#include <stdbool.h>
#include <stdint.h>

#include "j288/config.h"
#include "j288/frame.h"
#include "j288/jointq.h"
#include "j288/sched.h"
#include "j288/units.h"

#if J288_CONFIG_SI

#ifdef __cplusplus
extern "C" {
#endif

#define J288_JOINT_DEFAULT_TRACK_TOL 0.010 /* rad of output: 13 OutPos counts */
#define J288_JOINT_DEFAULT_CAL_TOL 1.0     /* rad of rotor: 3.5 mrad of output */
#define J288_JOINT_LIMIT_HYST 0.001        /* rad: inside the range by this to leave a limit */
#define J288_JOINT_MAX_ANGLE 64.0          /* rad: bound of zero, pos_min, pos_max */
#define J288_JOINT_HOLD_BEYOND 0.05        /* rad: J288_JOINTQ_HOLD_BEYOND */

/* As j288_jointq_config_t, in SI units; all-zero (but id) means the same defaults.
 * Checked by j288_joint_init(). */
typedef struct {
    uint8_t id;             /* servo id, 0-14 */
    int8_t direction;       /* +1 or -1 (0: +1): the joint's sense against the output's */
    bool clamp;             /* true: saturate targets at the limits instead of refusing */
    bool has_phase;         /* phase holds a calibrated c: the calibrated mode */
    bool continuous;        /* no position limits, the angle unbounded (a wheel); pos_min and
                               pos_max must be 0 */
    uint8_t init_samples;   /* replies averaged at the start, 1-255; 0: 8 */
    j288_real_t zero;       /* rad, output-encoder frame: the output angle of joint angle 0 */
    j288_real_t pos_min;    /* rad, joint frame; pos_min = pos_max = 0: [-pi, pi] */
    j288_real_t pos_max;    /*   else pos_min < pos_max, both within J288_JOINT_MAX_ANGLE */
    j288_real_t max_speed;  /* rad/s, joint frame, >= 0; 0: only the wire's range */
    j288_real_t max_torque; /* N*m, joint frame, >= 0; 0: only the wire's range */
    j288_real_t kp;         /* default stiffness (hold), N*m/rad, joint frame, >= 0 */
    j288_real_t kd;         /* default damping (hold, the limit law), N*m*s/rad, >= 0 */
    j288_real_t phase;      /* c, rotor rad, |c| <= 2 pi; used when has_phase */
    j288_real_t track_tol;  /* rad of output, 0 to pi; 0: J288_JOINT_DEFAULT_TRACK_TOL */
    j288_real_t cal_tol;    /* rad of rotor, 0 to pi; 0: J288_JOINT_DEFAULT_CAL_TOL */
} j288_joint_config_t;

/* As j288_jointq_state_t, in SI units (converted from the core's after every reply). */
typedef struct {
    bool known;            /* pos is the absolute joint angle */
    bool calibrated;       /* known through the phase, with the rotor's resolution */
    bool cal_mismatch;     /* the latest calibrated start failed: see cal_residual */
    bool encoder_fault;    /* fault bit 12 in the latest reply: OutPos is not used */
    bool beyond_limit;     /* pos outside [pos_min, pos_max] (until back inside by 1 mrad) */
    j288_real_t pos;       /* rad, joint frame; valid when known */
    j288_real_t speed;     /* rad/s, joint frame (from the rotor: always valid) */
    j288_real_t torque;    /* N*m, joint frame (always valid) */
    j288_real_t encoder;   /* rad, OutPos as an output angle in [0, 2 pi): its count's centre */
    j288_real_t residual;  /* rad of output: rotor-derived minus encoder angle, in [-pi, pi];
                              0 while unknown or with an encoder fault; at a loss, the
                              residual that caused it */
    j288_real_t cal_residual; /* rotor rad: eps of the latest calibrated start (0 before) */
} j288_joint_state_t;

/* As j288_jointq_target_t; j288_joint_target_init() fills a hold target. */
typedef struct {
    j288_real_t pos;    /* rad, joint frame (used and checked only when kp > 0) */
    j288_real_t speed;  /* rad/s, joint frame */
    j288_real_t torque; /* N*m, joint frame, feed-forward */
    j288_real_t kp;     /* N*m/rad, joint frame, >= 0 */
    j288_real_t kd;     /* N*m*s/rad, joint frame, >= 0 */
} j288_joint_target_t;

typedef struct {
    /* Private: read with j288_joint_state(), j288_joint_config() and j288_joint_core(). */
    j288_jointq_t core;      /* the joint */
    j288_joint_config_t cfg; /* as given, defaults filled in */
    j288_joint_state_t st;   /* the core's state, converted */
} j288_joint_t;

/* Convert cfg and set the joint up (angle unknown). Errors (joint untouched): J288_ERR_NULL,
 * J288_ERR_BAD_ID (id > 14), J288_ERR_BAD_CONFIG (direction not -1/0/1, a value not finite
 * or outside its documented range, pos_min >= pos_max, limits on a continuous joint). */
int j288_joint_init(j288_joint_t *j, const j288_joint_config_t *cfg);

/* As j288_jointq_reset(). */
void j288_joint_reset(j288_joint_t *j);

/* The configuration as given, with the defaults filled in (pos_min = pos_max = 0 become
 * -+J288_PI, direction 0 becomes 1, tolerances 0 their defaults ...); the core uses these
 * values rounded to Q24 / Q16. NULL for NULL. Valid as long as j. */
const j288_joint_config_t *j288_joint_config(const j288_joint_t *j);

/* The joint core inside j, for its integer API (j288_jointq_state() ...: a continuous
 * joint's exact angle). NULL for NULL. */
const j288_jointq_t *j288_joint_core(const j288_joint_t *j);

/* As j288_jointq_take_reply(), and the state converted. */
int j288_joint_take_reply(j288_joint_t *j, const j288_reply_raw_t *reply, unsigned *events);

/* The state after the latest reply (all zero before one), or NULL for NULL. Valid as long as
 * the joint; changed by the next j288_joint_take_reply() (or the binding's hook). */
const j288_joint_state_t *j288_joint_state(const j288_joint_t *j);

/* As j288_jointq_target_init(): hold at rest with the default gains, where the joint is or
 * at the nearest limit when it is beyond one by at most J288_JOINT_HOLD_BEYOND. */
void j288_joint_target_init(const j288_joint_t *j, j288_joint_target_t *t);

/* As j288_jointq_command() for the target converted: J288_ERR_NULL, J288_ERR_NOT_FINITE (a
 * NaN anywhere in the target), then j288_jointq_command()'s errors in its order. *clamped as
 * there (J288_FIELD_* bits, J288_JOINT_LIMITED). */
int j288_joint_command(const j288_joint_t *j, const j288_joint_target_t *t, j288_cmd_raw_t *cmd,
                       unsigned *clamped);

/* The lock command for this joint (no torque; watchdog bit on). Errors: J288_ERR_NULL. */
int j288_joint_lock_command(const j288_joint_t *j, j288_cmd_raw_t *cmd);

/* As j288_jointq_zero_here(), in rad: J288_ERR_NULL, J288_ERR_ANGLE_UNKNOWN, J288_ERR_RANGE
 * (the zero beyond +-J288_JOINT_MAX_ANGLE). */
int j288_joint_zero_here(const j288_joint_t *j, j288_real_t *zero);

/* ---- binding: as j288_jointq_bus_t (j288/jointq.h), for these joints. */

typedef struct {
    j288_joint_event_kind_t kind;
    uint8_t id;
    const j288_joint_t *joint;
    j288_real_t value; /* see the kinds */
} j288_joint_event_t;

/* Called from the context that advances the bus (inside the scheduler's on_reply: in an
 * interrupt with advance_in_isr, so keep it short). ev is valid during the call only. */
typedef void (*j288_joint_event_fn)(void *user, const j288_joint_event_t *ev);

typedef struct {
    /* Private. */
    j288_jointq_bus_t core;
    j288_joint_t *joint[J288_MAX_SERVOS]; /* the facade joints whose cores are bound */
    j288_joint_event_fn on_event;
    void *user;
} j288_joint_bus_t;

/*
 * Bind joints to a scheduler. Register the binding as the scheduler's reply hook: in the
 * j288_sched_config_t given to j288_sched_init(), on_reply = j288_joint_bus_on_reply and
 * user = the binding (the scheduler's other callbacks then get the binding as user too; or
 * call j288_joint_bus_on_reply(binding, id, slot) from your own on_reply). on_event may be
 * NULL. Errors: J288_ERR_NULL. The binding must not move while the scheduler uses it.
 */
int j288_joint_bus_init(j288_joint_bus_t *jb, j288_sched_t *sched, j288_joint_event_fn on_event,
                        void *user);

/* As j288_jointq_bus_add(): joint j under its id, its slot at lock. Errors: J288_ERR_NULL,
 * J288_ERR_BAD_CONFIG (another joint has that id here). */
int j288_joint_bus_add(j288_joint_bus_t *jb, j288_joint_t *j);

/* The scheduler's reply hook: as j288_jointq_bus_on_reply() (the reply taken, the lock while
 * unknown, a kept target's command made again, the events in J288_JOINT_EV_* order), with
 * the joint's state converted before the events are reported. */
void j288_joint_bus_on_reply(void *user, uint8_t id, const j288_slot_t *slot);

/* As j288_jointq_bus_set_target() for the target converted: j288_joint_command()'s errors,
 * J288_ERR_BAD_ARG when j is not bound here. */
int j288_joint_bus_set_target(j288_joint_bus_t *jb, const j288_joint_t *j,
                              const j288_joint_target_t *t, unsigned *clamped);

/* Put joint j's slot at lock (no torque), and forget its target. Errors: J288_ERR_NULL,
 * J288_ERR_BAD_ARG. */
int j288_joint_bus_lock(j288_joint_bus_t *jb, const j288_joint_t *j);

/* ---- calibration: fit the rotor phase c from (OutPos, rotor position) pairs (joint_cal.c)
 *
 * Stream the pairs of a slow motion over a small range (both directions, so that backlash
 * averages out) into j288_cal_add() or j288_cal_add_reply(); nothing is buffered. The fit is
 * the circular mean of p_i - N * theta_i over the pairs, with theta_i (count centres) continued
 * across the encoder's wrap and labelled by the core's turn choice (so the c it gives belongs
 * to that joint configuration's turn labelling). Residuals are unwrapped around the running
 * mean, which equals the circular mean while they stay well within pi of it, as a usable
 * fit's do (the quality check says when they do not). Expected accuracy: each pair's
 * residual carries up to +-0.11 rotor rad of OutPos quantization (half a count times N) and
 * N * backlash / 2; the mean over a motion that covers many counts evenly cancels the
 * quantization to about 0.22 rad / span_counts, so c comes within about 0.02 rotor rad
 * (70 urad of output) for a 16-count span without backlash. Backlash is averaged only as
 * evenly as the motion loads each side of the teeth. docs/joint.md has the measurements. The
 * fit runs in j288_real_t (on a host, as `j288 calibrate` does); a firmware configures the
 * phase it gives as J288_Q24(c).
 */

#define J288_CAL_MIN_SAMPLES 100u  /* fewer pairs: J288_CAL_FEW_SAMPLES */
#define J288_CAL_MIN_SPAN 16u      /* OutPos counts (12 mrad); less: J288_CAL_SMALL_SPAN */
#define J288_CAL_MAX_RATIO_ERROR 0.02 /* |fitted ratio / N - 1| beyond: J288_CAL_RATIO */

/* Bits of j288_cal_report_t.problems. */
#define J288_CAL_FEW_SAMPLES 0x01u /* fewer than J288_CAL_MIN_SAMPLES pairs */
#define J288_CAL_SMALL_SPAN 0x02u  /* the motion covered fewer than J288_CAL_MIN_SPAN counts */
#define J288_CAL_NOISY 0x04u       /* a residual beyond cal_tol: starts would be refused */
#define J288_CAL_RATIO 0x08u       /* rotor and encoder motion do not agree on N */

typedef struct {
    j288_real_t phase;     /* c, rotor rad, in [-pi, pi] */
    uint32_t samples;      /* pairs used */
    uint32_t rejected;     /* replies skipped (output encoder fault) */
    uint32_t span_counts;  /* OutPos counts between the extreme poses */
    j288_real_t rms;       /* rotor rad: residuals about c */
    j288_real_t max_abs;   /* rotor rad: the largest of them */
    j288_real_t ratio;     /* fitted rotor rad per output rad (N if all is well; 0: no motion) */
    unsigned problems;     /* J288_CAL_* bits; 0: good */
} j288_cal_report_t;

typedef struct {
    /* Private. */
    j288_jointq_config_t label; /* the joint's configuration (core units): its turn choice */
    j288_q24_t centre;
    j288_real_t cal_tol;
    uint32_t n;
    uint32_t rejected;
    int32_t first_pos;     /* rotor LSB of the first pair */
    j288_real_t first_v;   /* its residual p - N * theta, wrapped */
    uint16_t prev_count;
    int32_t cont;          /* OutPos counts since the first pair, continued across the wrap */
    int32_t cont_min;
    int32_t cont_max;
    j288_real_t mean;      /* residuals: running mean, sum of squares about it, extremes */
    j288_real_t m2;
    j288_real_t vmin;
    j288_real_t vmax;
    j288_real_t mx;        /* motion (output rad x, rotor rad y): means, co-moment, variance */
    j288_real_t my;
    j288_real_t cxy;
    j288_real_t m2y;
} j288_cal_t;

/* Start a fit for the joint configuration cfg (its zero, direction and range label the
 * turns; its cal_tol judges the residuals; NULL: the all-zero configuration). Errors:
 * J288_ERR_NULL (cal), those of j288_joint_init(). */
int j288_cal_init(j288_cal_t *cal, const j288_joint_config_t *cfg);

/* One pair: OutPos count (0-8191) and rotor position (LSB) from the same reply. Consecutive
 * pairs must be less than half an output turn apart. Errors (nothing taken): J288_ERR_NULL,
 * J288_ERR_RANGE (out_pos > 8191; or 2^32 - 1 pairs, or a motion of 65536 turns, taken
 * already: bounds no real motion reaches, kept so that no input can overflow). */
int j288_cal_add(j288_cal_t *cal, uint16_t out_pos, int32_t rotor_pos);

/* The pair of a reply; a reply with fault bit 12 is counted as rejected and skipped. Errors:
 * J288_ERR_NULL. */
int j288_cal_add_reply(j288_cal_t *cal, const j288_reply_raw_t *reply);

/* The fit so far (the accumulator is unchanged). J288_OK: a good fit. J288_ERR_CAL_DATA: a
 * quality check failed (report->problems says which; the other fields are filled as far as
 * the data allow). J288_ERR_NULL. */
int j288_cal_result(const j288_cal_t *cal, j288_cal_report_t *report);

#ifdef __cplusplus
}
#endif

#endif /* J288_CONFIG_SI */
#endif /* J288_JOINT_H */
