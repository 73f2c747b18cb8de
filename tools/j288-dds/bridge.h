/*
 * bridge.h - j288-dds's core: the robot's state into DDS samples, DDS commands into joint
 * targets, one commander per joint, the command timeout, and every refusal counted and
 * reported once per cause.
 *
 * The bridge is one more client of the robot runner (host/j288_robot.h): it owns a runner
 * opened from the robot config and uses only its public API. It holds no DDS entity itself:
 * main.c takes samples from DDS and hands them in with the writer that sent them, and
 * publishes what the bridge fills in. Everything here is called from the one thread that
 * drives the runner, between cycles.
 *
 * Commands (sensor_msgs/JointState on rt/joint_command): name selects joints; position,
 * velocity and effort are each empty or as long as name, and at least one is given. Per
 * joint: position given -> target at that angle with the joint's kp (and kd); else kp 0 and
 * the target angle is where the joint is; velocity given -> that speed with kd; effort given
 * -> feed-forward torque; neither position nor velocity -> kd 0 (pure torque). Gains are the
 * config's, or the runner's J288_ROBOT_DEFAULT_KP / _KD for a joint that gives none.
 * unitree mode (rt/lowcmd, unitree_go or unitree_hg LowCmd_): motor i is joint i; a motor's
 * mode 1 or 0x0A (unitree's servo modes) follows q, dq, tau, kp, kd; mode 0 locks a joint
 * that was driven.
 *
 * One commander per joint: the first writer whose command for a joint is applied owns it
 * until it has sent it nothing applied for the command timeout; meanwhile another writer's
 * commands for that joint are refused (cause "joint commanded by another writer"), counted
 * per joint, and that writer named (its GUID) in the joint's diagnostics.
 *
 * Refused (nothing sent for the joints concerned; counted; the first of each cause written on
 * stderr): a whole message whose arrays differ in length from name, that names no joint or
 * gives no values, or that names an unknown joint or one joint twice; per joint, a value that
 * is NaN or infinite, a target outside the joint's limits (position, speed, torque), a joint
 * whose angle is not known yet, a joint another writer owns. In unitree mode: a LowCmd_ with
 * a bad crc (whole message), a motor mode other than 0, 1 or 0x0A. Atomic (the default): a
 * message with any joint refused applies to none of its joints (counted as refused whole);
 * per joint (atomic false): the other joints of the message are applied.
 *
 * Timeout: a joint whose latest applied command is older than timeout_us (measured on this
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
#include "unitree_hg.h"

#define J288_DDS_DEFAULT_TIMEOUT_US 100000u /* 100 ms */
#define J288_DDS_UNITREE_MOTORS 20u         /* unitree_go LowCmd_/LowState_ motor slots */
#define J288_DDS_HG_MOTORS 35u              /* unitree_hg LowCmd_/LowState_ motor slots */
#define J288_DDS_MAX_SAMPLE_KIB 256u       /* the largest sample taken or sent (main.c) */
#define BRIDGE_GUID_LEN 48u                 /* "01.0f.xx....", 16 bytes as ROS 2 prints GIDs */
#define BRIDGE_NAME_LEN 32u                 /* a joint name in the state sample: as long as the
                                               IDL's bound (sensor_msgs.idl), with the NUL */

typedef enum {
    BRIDGE_CAUSE_LENGTHS = 0, /* position/velocity/effort length differs from name's */
    BRIDGE_CAUSE_EMPTY,       /* no name, or no values */
    BRIDGE_CAUSE_UNKNOWN,     /* a name that is no joint of the config */
    BRIDGE_CAUSE_DUPLICATE,   /* a joint named twice in one message */
    BRIDGE_CAUSE_NOT_FINITE,  /* NaN or infinity */
    BRIDGE_CAUSE_LIMIT,       /* outside the joint's limits (position, speed, torque) */
    BRIDGE_CAUSE_UNKNOWN_ANGLE, /* the joint's angle is not known yet */
    BRIDGE_CAUSE_BAD_CRC,     /* unitree mode: LowCmd_ crc mismatch */
    BRIDGE_CAUSE_BAD_MODE,    /* unitree mode: motor mode other than 0, 1 or 0x0A */
    BRIDGE_CAUSE_STOPPED,     /* a command while the robot is stopped (a bus lost) */
    BRIDGE_CAUSE_OWNED,       /* the joint is commanded by another writer */
    BRIDGE_CAUSE_BUS_GONE,    /* the joint's bus is gone (until its device is reopened) */
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

/* The writer a command came from: id identifies it while it is matched (Cyclone's instance
 * handle of the writer), guid is what diagnostics show. */
typedef struct {
    uint64_t id;
    const char *guid;
} bridge_writer_t;

typedef struct {
    bridge_joint_mode_t mode;
    uint32_t last_cmd_us;  /* j288_robot_now_us() when its latest command was accepted */
    uint32_t accepted;     /* commands accepted for this joint */
    uint32_t timeouts;
    uint32_t watchdog;     /* servo watchdog trips the runner found and cleared */
    bool owned;            /* owner below is the joint's commander, until owner_us is older
                              than the timeout */
    uint64_t owner;
    uint32_t owner_us;     /* when the owner's latest command for it was applied */
    char owner_guid[BRIDGE_GUID_LEN];
    uint32_t refused_other;             /* commands of other writers refused meanwhile */
    char other_guid[BRIDGE_GUID_LEN];   /* the latest of them */
} bridge_joint_t;

typedef struct {
    j288_robot_t *robot;
    const j288_robot_config_t *cfg;
    uint32_t timeout_us;
    bridge_timeout_policy_t policy;
    bool atomic;                /* a message applies to all its joints or to none */
    bool stopped;               /* every bus locked after a bus loss: commands refused */
    char stop_reason[128];
    bridge_joint_t joint[J288_ROBOT_MAX_JOINTS];
    uint32_t refused[BRIDGE_NCAUSES];
    uint32_t messages;          /* command messages taken */
    uint32_t refused_whole;     /* messages of which nothing was applied (atomic, or a
                                   message-level cause) */
    uint32_t refused_reported;  /* refusals counted at the previous diagnostics */
    uint32_t dropped;           /* command samples DDS dropped before the bridge saw them */
    char dropped_guid[BRIDGE_GUID_LEN]; /* the writer of the latest of them */
    uint8_t hg_mode_pr;         /* unitree_hg: the latest applied LowCmd_'s mode_pr */
    uint32_t bus_lost[J288_ROBOT_MAX_BUSES];
    bool all_gone;              /* every bus is gone (said once an episode) */
    /* what the samples point at */
    char names[J288_ROBOT_MAX_JOINTS][BRIDGE_NAME_LEN];
    double pos[J288_ROBOT_MAX_JOINTS], vel[J288_ROBOT_MAX_JOINTS], eff[J288_ROBOT_MAX_JOINTS];
} bridge_t;

/* Ready a bridge over an open robot (its joints in cfg's order). */
void bridge_init(bridge_t *b, j288_robot_t *robot, const j288_robot_config_t *cfg,
                 uint32_t timeout_us, bridge_timeout_policy_t policy, bool atomic);

/* The name of a cause, for messages and diagnostics. */
const char *bridge_cause_name(bridge_cause_t c);

/* Count a refusal; the first of each cause goes to stderr with detail. */
void bridge_refuse(bridge_t *b, bridge_cause_t c, const char *detail);

/* One rt/joint_command sample from writer w, taken at now_us. */
void bridge_take_command(bridge_t *b, const sensor_msgs_msg_dds__JointState_ *m,
                         const bridge_writer_t *w, uint32_t now_us);

/* One rt/lowcmd sample (unitree_go, unitree_hg) from writer w, taken at now_us. */
void bridge_take_lowcmd(bridge_t *b, const unitree_go_msg_dds__LowCmd_ *m,
                        const bridge_writer_t *w, uint32_t now_us);
void bridge_take_hg_lowcmd(bridge_t *b, const unitree_hg_msg_dds__LowCmd_ *m,
                           const bridge_writer_t *w, uint32_t now_us);

/* n command samples DDS dropped before they reached the bridge (larger than
 * J288_DDS_MAX_SAMPLE_KIB, or beyond its types' bounds), the latest from the writer guid:
 * counted, the first said on stderr. */
void bridge_dropped(bridge_t *b, uint32_t n, const char *guid);

/* After each cycle: the timeout policy for joints whose command is too old. */
void bridge_check_timeouts(bridge_t *b, uint32_t now_us);

/* A bus went down or vanished (a runner event): reported and counted; when it vanished
 * (gone true) its joints are no longer followed (their commands are refused until it is
 * back, no timeout acts on them). */
void bridge_bus_lost(bridge_t *b, unsigned bus, const char *what, bool gone);

/* A vanished bus's device was reopened (J288_ROBOT_EV_BUS_BACK): reported; its joints restart
 * at lock, nobody's, until a command comes once their angles are known again. */
void bridge_bus_back(bridge_t *b, unsigned bus);

/* After each cycle: whether every bus is gone now; said once on stderr at the start and at
 * the end of each such episode. */
void bridge_every_bus_gone(bridge_t *b, bool gone);

/* The runner stopped every bus on a bus loss (its stop_on_bus_loss): commands are refused
 * from then on, no joint is driven again (no timeout hold either); why says which bus. */
void bridge_stopped(bridge_t *b, const char *why);

/* A servo's watchdog had tripped (a runner event, cleared by the runner): reported. */
void bridge_watchdog(bridge_t *b, unsigned joint);

/* The robot's state after the latest cycle into a JointState sample (stamp: CLOCK_REALTIME):
 * position, velocity and effort NaN for a joint that is not known or not fresh (its angle not
 * found yet, no reply in the latest cycle, its bus lost). The sample points into b: valid
 * until the next call. The LowState_ below carry NaN in q, dq and tau_est alike. */
void bridge_fill_joint_state(bridge_t *b, sensor_msgs_msg_dds__JointState_ *m);

/* The same as a LowState_ (motors in config order, crc set; see docs/dds.md for the fields). */
void bridge_fill_lowstate(bridge_t *b, unitree_go_msg_dds__LowState_ *m, uint32_t tick_ms);
void bridge_fill_hg_lowstate(bridge_t *b, unitree_hg_msg_dds__LowState_ *m, uint32_t tick_ms);

/* The diagnostics (diag.c): per bus, per joint, and the bridge itself. The sample points into
 * storage the function owns: valid until the next call. */
void bridge_fill_diagnostics(bridge_t *b, diagnostic_msgs_msg_dds__DiagnosticArray_ *m);

/* CLOCK_REALTIME as a ROS 2 stamp. */
void bridge_stamp_now(builtin_interfaces_msg_dds__Time_ *t);

#endif
