/*
 * bridge.h - j288-dds's core: the robot's state into DDS samples, DDS commands into joint
 * targets, the command timeout, and every refusal counted and reported once per cause.
 *
 * The bridge is one more client of the robot runner (host/j288_robot.h): it owns a runner
 * opened from the robot config and uses only its public API. It holds no DDS entity itself:
 * main.c takes samples from DDS and hands them in, and publishes what the bridge fills in.
 * Everything here is called from the one thread that drives the runner, between cycles.
 *
 * Commands (sensor_msgs/JointState on rt/joint_command): name selects joints; position,
 * velocity and effort are each empty or as long as name, and at least one is given. Per
 * joint: position given -> target at that angle with the joint's kp (and kd); else kp 0 and
 * the target angle is where the joint is; velocity given -> that speed with kd; effort given
 * -> feed-forward torque; neither position nor velocity -> kd 0 (pure torque). Gains are the
 * config's, or the runner's J288_ROBOT_DEFAULT_KP / _KD for a joint that gives none.
 *
 * Refused (nothing sent for the joints concerned; counted; the first of each cause written on
 * stderr): a whole message whose arrays differ in length from name, that names no joint or
 * gives no values, or that names an unknown joint or one joint twice; per joint, a value that
 * is NaN or infinite, a target outside the joint's limits (position, speed, torque), a joint
 * whose angle is not known yet. In unitree mode: a LowCmd_ with a bad crc (whole message), a
 * motor mode other than 0 (lock) or 1 (FOC).
 *
 * Timeout: a joint whose latest accepted command is older than timeout_us (measured on this
 * machine from when the bridge took it, not from the sender's stamp) is held where it is at
 * its gains (policy hold) or locked (policy lock); said on stderr once per episode and shown
 * in diagnostics until a new command comes.
 */
#ifndef J288_DDS_BRIDGE_H
#define J288_DDS_BRIDGE_H

#include <stdbool.h>
#include <stdint.h>

#include "diagnostic_msgs.h"
#include "j288_robot.h"
#include "sensor_msgs.h"
#include "unitree_go.h"

#define J288_DDS_DEFAULT_TIMEOUT_US 100000u /* 100 ms */
#define J288_DDS_UNITREE_MOTORS 20u         /* LowCmd_/LowState_ motor slots */

typedef enum {
    BRIDGE_CAUSE_LENGTHS = 0, /* position/velocity/effort length differs from name's */
    BRIDGE_CAUSE_EMPTY,       /* no name, or no values */
    BRIDGE_CAUSE_UNKNOWN,     /* a name that is no joint of the config */
    BRIDGE_CAUSE_DUPLICATE,   /* a joint named twice in one message */
    BRIDGE_CAUSE_NOT_FINITE,  /* NaN or infinity */
    BRIDGE_CAUSE_LIMIT,       /* outside the joint's limits (position, speed, torque) */
    BRIDGE_CAUSE_UNKNOWN_ANGLE, /* the joint's angle is not known yet */
    BRIDGE_CAUSE_BAD_CRC,     /* unitree mode: LowCmd_ crc mismatch */
    BRIDGE_CAUSE_BAD_MODE,    /* unitree mode: motor mode other than 0 or 1 */
    BRIDGE_CAUSE_STOPPED,     /* a command while the robot is stopped (a bus lost) */
    BRIDGE_CAUSE_OTHER,       /* any other refusal of the joint layer */
    BRIDGE_NCAUSES
} bridge_cause_t;

typedef enum {
    JOINT_IDLE = 0,   /* never commanded: at lock */
    JOINT_FOLLOWING,  /* following its latest command */
    JOINT_TIMED_OUT,  /* no command within the timeout: held or locked */
    JOINT_LOCKED      /* locked by a command (unitree mode 0) */
} bridge_joint_mode_t;

typedef enum { TIMEOUT_HOLD = 0, TIMEOUT_LOCK } bridge_timeout_policy_t;

typedef struct {
    bridge_joint_mode_t mode;
    uint32_t last_cmd_us;  /* j288_robot_now_us() when its latest command was accepted */
    uint32_t accepted;     /* commands accepted for this joint */
    uint32_t timeouts;
    uint32_t watchdog;     /* servo watchdog trips the runner found and cleared */
} bridge_joint_t;

typedef struct {
    j288_robot_t *robot;
    const j288_robot_config_t *cfg;
    uint32_t timeout_us;
    bridge_timeout_policy_t policy;
    bool stopped;               /* every bus locked after a bus loss: commands refused */
    char stop_reason[128];
    bridge_joint_t joint[J288_ROBOT_MAX_JOINTS];
    uint32_t refused[BRIDGE_NCAUSES];
    uint32_t messages;          /* command messages taken */
    uint32_t refused_reported;  /* refusals counted at the previous diagnostics */
    uint32_t bus_lost[J288_ROBOT_MAX_BUSES];
    /* what the samples point at (names are the runner's own strings) */
    char *names[J288_ROBOT_MAX_JOINTS];
    double pos[J288_ROBOT_MAX_JOINTS], vel[J288_ROBOT_MAX_JOINTS], eff[J288_ROBOT_MAX_JOINTS];
} bridge_t;

/* Ready a bridge over an open robot (its joints in cfg's order). */
void bridge_init(bridge_t *b, j288_robot_t *robot, const j288_robot_config_t *cfg,
                 uint32_t timeout_us, bridge_timeout_policy_t policy);

/* The name of a cause, for messages and diagnostics. */
const char *bridge_cause_name(bridge_cause_t c);

/* Count a refusal; the first of each cause goes to stderr with detail. */
void bridge_refuse(bridge_t *b, bridge_cause_t c, const char *detail);

/* One rt/joint_command sample taken at now_us. */
void bridge_take_command(bridge_t *b, const sensor_msgs_msg_dds__JointState_ *m, uint32_t now_us);

/* One rt/lowcmd sample taken at now_us (unitree mode). */
void bridge_take_lowcmd(bridge_t *b, const unitree_go_msg_dds__LowCmd_ *m, uint32_t now_us);

/* After each cycle: the timeout policy for joints whose command is too old. */
void bridge_check_timeouts(bridge_t *b, uint32_t now_us);

/* A bus went down or vanished (a runner event): reported and counted. */
void bridge_bus_lost(bridge_t *b, unsigned bus, const char *what);

/* The runner stopped every bus on a bus loss (its stop_on_bus_loss): commands are refused
 * from then on, no joint is driven again (no timeout hold either); why says which bus. */
void bridge_stopped(bridge_t *b, const char *why);

/* A servo's watchdog had tripped (a runner event, cleared by the runner): reported. */
void bridge_watchdog(bridge_t *b, unsigned joint);

/* The robot's state after the latest cycle into a JointState sample (stamp: CLOCK_REALTIME).
 * The sample points into b: valid until the next call. */
void bridge_fill_joint_state(bridge_t *b, sensor_msgs_msg_dds__JointState_ *m);

/* The same as a LowState_ (motors in config order, crc set; see docs/dds.md for the fields). */
void bridge_fill_lowstate(bridge_t *b, unitree_go_msg_dds__LowState_ *m, uint32_t tick_ms);

/* The diagnostics (diag.c): per bus, per joint, and the bridge itself. The sample points into
 * storage the function owns: valid until the next call. */
void bridge_fill_diagnostics(bridge_t *b, diagnostic_msgs_msg_dds__DiagnosticArray_ *m);

/* CLOCK_REALTIME as a ROS 2 stamp. */
void bridge_stamp_now(builtin_interfaces_msg_dds__Time_ *t);

#endif
