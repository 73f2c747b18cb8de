/*
 * j288/joint.h - the joint frame: an absolute joint angle from the first replies after
 * power-up, soft limits, and rotor-frame commands from joint-frame targets.
 *
 * The physics (docs/joint.md has the long form). The rotor turns N = J288_GEAR_RATIO times
 * per output turn: r = N * theta + c, with theta the output angle and c a rotor phase fixed
 * at assembly. The reply's rotor position is p = r - 2 pi k: the rotor encoder is absolute
 * over one turn only, so k (the turn count) is lost at every power-up, and p / N alone means
 * nothing after a power cycle. The 13-bit output encoder (OutPos) gives theta modulo 2 pi in
 * steps of 2 pi / 8192 (0.77 mrad) and survives power cycles. A joint combines the two:
 *
 * - Start (both modes): init_samples replies (default 8) are averaged into the output angle
 *   at an anchor rotor position (each reply contributes OutPos minus the rotor's motion since
 *   the first, so motion during the start does not matter). An OutPos count covers
 *   [n, n + 1) * 2 pi / 8192; the centre of the count is used. Replies that disagree with the
 *   first by more than track_tol restart the collection.
 * - Turn choice: the output angle is labelled theta_abs = theta_out + 2 pi m with the m that
 *   puts the joint angle q = direction * (theta_abs - zero) within pi of the middle of
 *   [pos_min, pos_max]: inside the range when the joint is, else nearest to it (and a limit
 *   event). A range across the encoder's wrap is thus labelled continuously.
 * - Uncalibrated (no phase): from then on q follows the rotor, q = q0 + direction * (p - p0) / N.
 *   Absolute to within half an OutPos count (0.38 mrad) plus the gear's backlash at the
 *   start; it never drifts, and has the rotor's resolution (0.66 urad) relative to the start.
 * - Calibrated (phase = c, fitted by j288_cal_*): the turn count k is the integer that makes
 *   p + 2 pi k closest to N * theta_abs + c, and theta = (p + 2 pi k - c) / N: absolute with the
 *   rotor's resolution, the same after every power cycle. The residual
 *   eps = N * theta_abs + c - (p + 2 pi k), in [-pi, pi] rotor rad, says whether c still holds:
 *   beyond cal_tol the start fails with J288_JOINT_EV_CAL_MISMATCH and the joint stays
 *   unknown (it retries with the next replies). c belongs with the turn labelling above: it
 *   stays valid when zero or the range change as long as the poses it was fitted at stay
 *   within pi of the range's middle; a label one turn off moves eps by 2 pi * 0.35 rad and is
 *   reported as a mismatch, not taken.
 * - Tracking: every reply compares the rotor-derived angle with the output encoder; the
 *   difference (the residual, wrapped to [-pi, pi]) beyond track_tol (a power cycle of the
 *   servo, a slipped gear, a wrong calibration) makes the angle unknown again
 *   (J288_JOINT_EV_ANGLE_LOST) and the start begins anew. So on every reply with a working
 *   encoder the angle agrees with it to within track_tol. Fault bit 12 (output encoder) means
 *   the encoder is not used: no start from it and no comparison; a joint already known keeps
 *   following the rotor.
 *
 * The joint frame: q = direction * (theta_abs - zero); speed = direction * rotor speed / N;
 * torque = direction * N * rotor torque; stiffness and damping = rotor gains * N^2. An all-zero
 * configuration (but the id) gives the output encoder angle wrapped to [-pi, pi), direction
 * +1, no speed or torque limit, targets outside [-pi, pi] refused.
 *
 * Safety. While the angle is unknown every target is refused (J288_ERR_ANGLE_UNKNOWN, or
 * J288_ERR_CAL_MISMATCH after a failed calibrated start) and the binding below keeps lock on
 * the joint's slot; when the angle is lost, the slot's next command becomes lock from inside
 * the scheduler's on_reply hook, before anything else is sent. The one command that drew the
 * first reply after a power cycle was made in the old frame: the servo may act on it for
 * one sweep before lock arrives. A target outside [pos_min, pos_max], or beyond max_speed or
 * max_torque, is refused with J288_ERR_LIMIT_POS / _SPEED / _TORQUE and nothing is produced,
 * unless the joint is configured to clamp: then it is saturated and the call reports which
 * fields it changed. Refusing is the default because a target outside the limits is a bug
 * in the controller that clamping would hide. Limits bound the targets; the servo's own
 * control law acts on the error between target and state, and the limit events report the
 * joint's measured angle leaving the range.
 *
 * Precision with float (J288_CONFIG_SI_FLOAT=1): positions are kept as an integer rotor
 * anchor plus a small joint-frame angle, so p / N is never formed from a large p; angles
 * within J288_JOINT_MAX_ANGLE keep about 1 urad in float. Angles in the configuration must lie
 * within J288_JOINT_MAX_ANGLE.
 *
 * Objects are caller-allocated; nothing is allocated, no global state. Calling context:
 * every function on a joint, a binding or a calibration is for one context at a time. With
 * a binding, that is the context that advances the bus: the thread that polls, or with
 * advance_in_isr the bus's interrupt (e.g. set targets from the scheduler's on_sweep). The
 * functions take no lock. Compiled only with J288_CONFIG_SI (but the event kinds, which the
 * fixed-point layer of j288/jointq.h shares).
 */
#ifndef J288_JOINT_H
#define J288_JOINT_H

#include <stdbool.h>
#include <stdint.h>

#include "j288/config.h"
#include "j288/frame.h"
#include "j288/sched.h"
#include "j288/units.h"

/* Events, reported by j288_joint_take_reply() (and j288_jointq_take_reply(), j288/jointq.h)
 * as bits (1u << kind), in this order. Outside J288_CONFIG_SI: the fixed-point layer has them
 * too. */
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
    J288_JOINT_EV_LIMIT_LEFT         /* back inside by J288_JOINT_LIMIT_HYST (value: it) */
} j288_joint_event_kind_t;

#define J288_JOINT_EV_BIT(kind) (1u << (unsigned)(kind))
#define J288_JOINT_EV_COUNT 8u
#define J288_JOINT_DEFAULT_INIT_SAMPLES 8u /* replies averaged at the start */

#if J288_CONFIG_SI

#ifdef __cplusplus
extern "C" {
#endif

#define J288_JOINT_DEFAULT_TRACK_TOL 0.010 /* rad of output: 13 OutPos counts */
#define J288_JOINT_DEFAULT_CAL_TOL 1.0     /* rad of rotor: 3.5 mrad of output */
#define J288_JOINT_LIMIT_HYST 0.001        /* rad: inside the range by this to leave a limit */
#define J288_JOINT_MAX_ANGLE 64.0          /* rad: bound of zero, pos_min, pos_max */

/* All-zero (but id) means the defaults described above. Checked by j288_joint_init(). */
typedef struct {
    uint8_t id;             /* servo id, 0-14 */
    int8_t direction;       /* +1 or -1 (0: +1): the joint's sense against the output's */
    bool clamp;             /* true: saturate targets at the limits instead of refusing */
    bool has_phase;         /* phase holds a calibrated c: the calibrated mode */
    uint8_t init_samples;   /* replies averaged at the start, 1-255; 0: 8 */
    j288_real_t zero;       /* rad, output-encoder frame: the output angle of joint angle 0 */
    j288_real_t pos_min;    /* rad, joint frame; pos_min = pos_max = 0: [-pi, pi] */
    j288_real_t pos_max;    /*   else pos_min < pos_max, both within J288_JOINT_MAX_ANGLE */
    j288_real_t max_speed;  /* rad/s, joint frame, >= 0; 0: only the wire's range */
    j288_real_t max_torque; /* N*m, joint frame, >= 0; 0: only the wire's range */
    j288_real_t kp;         /* default stiffness, N*m/rad, joint frame, >= 0 */
    j288_real_t kd;         /* default damping, N*m*s/rad, joint frame, >= 0 */
    j288_real_t phase;      /* c, rotor rad, |c| <= 2 pi (see above); used when has_phase */
    j288_real_t track_tol;  /* rad of output, >= 0; 0: J288_JOINT_DEFAULT_TRACK_TOL */
    j288_real_t cal_tol;    /* rad of rotor, 0 to pi; 0: J288_JOINT_DEFAULT_CAL_TOL */
} j288_joint_config_t;

/* A joint's view of its latest reply (j288_joint_state()). */
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

/* Joint-frame targets. j288_joint_target_init() fills a hold-here target. */
typedef struct {
    j288_real_t pos;    /* rad, joint frame, within [pos_min, pos_max] */
    j288_real_t speed;  /* rad/s, joint frame */
    j288_real_t torque; /* N*m, joint frame, feed-forward */
    j288_real_t kp;     /* N*m/rad, joint frame, >= 0 */
    j288_real_t kd;     /* N*m*s/rad, joint frame, >= 0 */
} j288_joint_target_t;

typedef struct {
    /* Private: read with j288_joint_state(). */
    j288_joint_config_t cfg;   /* defaults filled in, direction +-1 */
    j288_real_t dir;           /* cfg.direction as a real */
    j288_real_t centre;        /* middle of [pos_min, pos_max] */
    j288_real_t k_q;           /* joint rad per rotor LSB (direction included) */
    j288_real_t k_speed;       /* joint rad/s per rotor speed LSB (direction included) */
    j288_real_t k_torque;      /* joint N*m per rotor torque LSB (direction included) */
    int32_t ref_pos;           /* rotor LSB at the anchor */
    j288_real_t ref_q;         /* joint angle at the anchor */
    int32_t init_pos;          /* rotor LSB of the start's first sample */
    j288_real_t init_e0;       /* its output angle */
    j288_real_t init_sum;      /* sum of the later samples' differences to it */
    uint8_t init_n;            /* samples collected */
    bool seen;                 /* a reply came since init/reset */
    j288_joint_state_t st;
} j288_joint_t;

/* Check cfg and set the joint up (angle unknown). Errors (joint untouched): J288_ERR_NULL,
 * J288_ERR_BAD_ID (id > 14), J288_ERR_BAD_CONFIG (direction not -1/0/1, a value not finite
 * or outside its documented range, pos_min >= pos_max). */
int j288_joint_init(j288_joint_t *j, const j288_joint_config_t *cfg);

/* Forget the angle: the next replies start anew (e.g. the application knows the servo was
 * power-cycled). NULL is ignored. */
void j288_joint_reset(j288_joint_t *j);

/* Take one reply of this joint's servo: update the state, run the start, the tracking
 * check and the limit check, and OR the events (J288_JOINT_EV_BIT) into *events (may be
 * NULL; set to 0 first). Errors (joint untouched): J288_ERR_NULL, J288_ERR_WRONG_ID (the
 * reply is from another id). The reply is only read during the call (not kept); no field of
 * it is trusted beyond its type's range (OutPos is taken modulo 8192). */
int j288_joint_take_reply(j288_joint_t *j, const j288_reply_raw_t *reply, unsigned *events);

/* The state after the latest reply (all zero before one), or NULL for NULL. Valid as long as
 * the joint; changed by the next j288_joint_take_reply(). */
const j288_joint_state_t *j288_joint_state(const j288_joint_t *j);

/* A target that holds the joint where it is (the latest angle, 0 while unknown), at rest,
 * with the joint's default gains. NULL arguments are ignored. */
void j288_joint_target_init(const j288_joint_t *j, j288_joint_target_t *t);

/*
 * Target -> FOC command in the rotor frame (watchdog bit on). *clamped (may be NULL) gets
 * the J288_FIELD_* bits (units.h) of the fields saturated in clamp mode, 0 otherwise.
 * Errors (cmd untouched, nothing produced): J288_ERR_NULL; J288_ERR_ANGLE_UNKNOWN, or
 * J288_ERR_CAL_MISMATCH when the latest calibrated start failed; J288_ERR_NOT_FINITE (NaN);
 * J288_ERR_LIMIT_POS / _SPEED / _TORQUE (refuse mode); then as j288_cmd_from_si() on the
 * output side (J288_ERR_NEG_GAIN, J288_ERR_RANGE_*; clamp mode saturates those as
 * j288_cmd_from_si_clamped() does); J288_ERR_RANGE_POS also when the rotor target would
 * leave the int32 wire range (never clamped: that would be a different place).
 */
int j288_joint_command(const j288_joint_t *j, const j288_joint_target_t *t, j288_cmd_raw_t *cmd,
                       unsigned *clamped);

/* The lock command for this joint (no torque; watchdog bit on). Errors: J288_ERR_NULL. */
int j288_joint_lock_command(const j288_joint_t *j, j288_cmd_raw_t *cmd);

/* Zero at the current pose: the zero (output-encoder frame) that makes the latest angle
 * joint angle 0, for the configuration file; j288_joint_init() with it to use it. Errors:
 * J288_ERR_NULL, J288_ERR_ANGLE_UNKNOWN. */
int j288_joint_zero_here(const j288_joint_t *j, j288_real_t *zero);

/* ---- binding: the joints of one scheduler (one bus); a robot has one binding per bus. */

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
    j288_sched_t *sched;
    j288_joint_t *joint[J288_MAX_SERVOS];
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

/* Add joint j (initialised) under its id and set its slot's command to lock. Enabling the
 * slot is the application's (j288_sched_enable()). The binding keeps the pointer: j must
 * stay valid and in place as long as the binding is in use (there is no remove). Errors:
 * J288_ERR_NULL, J288_ERR_BAD_CONFIG (another joint has that id here). */
int j288_joint_bus_add(j288_joint_bus_t *jb, j288_joint_t *j);

/* The scheduler's reply hook (j288_reply_fn; user: the binding). Feeds the reply to the
 * joint with that id (none: nothing happens), keeps its slot at lock while the angle is
 * unknown (replacing any other command at once, so a loss is answered before the next
 * transaction), then reports the joint's events to on_event in J288_JOINT_EV_* order. */
void j288_joint_bus_on_reply(void *user, uint8_t id, const j288_slot_t *slot);

/* j288_joint_command() for joint j, then j288_sched_set_cmd() (its next transaction).
 * Errors: those of j288_joint_command(); J288_ERR_BAD_ARG when j is not bound here. */
int j288_joint_bus_set_target(j288_joint_bus_t *jb, const j288_joint_t *j,
                              const j288_joint_target_t *t, unsigned *clamped);

/* Put joint j's slot at lock (no torque). Errors: J288_ERR_NULL, J288_ERR_BAD_ARG. */
int j288_joint_bus_lock(j288_joint_bus_t *jb, const j288_joint_t *j);

/* ---- calibration: fit the rotor phase c from (OutPos, rotor position) pairs
 *
 * Stream the pairs of a slow motion over a small range (both directions, so that backlash
 * averages out) into j288_cal_add() or j288_cal_add_reply(); nothing is buffered. The fit is
 * the circular mean of p_i - N * theta_i over the pairs, with theta_i (count centres) continued
 * across the encoder's wrap and labelled as the joint labels its start (so the c it gives
 * belongs to that joint configuration's turn labelling). Residuals are unwrapped around the
 * running mean, which equals the circular mean while they stay well within pi of it, as a
 * usable fit's do (the quality check says when they do not). Expected accuracy: each pair's
 * residual carries up to +-0.11 rotor rad of OutPos quantization (half a count times N) and
 * N * backlash / 2; the mean over a motion that covers many counts evenly cancels the
 * quantization to about 0.22 rad / span_counts, so c comes within about 0.02 rotor rad
 * (70 urad of output) for a 16-count span without backlash. Backlash is averaged only as
 * evenly as the motion loads each side of the teeth. docs/joint.md has the measurements.
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
    j288_real_t zero;      /* the labelling: as the joint's */
    j288_real_t dir;
    j288_real_t centre;
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
