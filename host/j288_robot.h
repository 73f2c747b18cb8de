/*
 * j288_robot.h - the host layer: several buses from one loop, the joints of a robot config,
 * one thread, one wait over every bus's device (j288_serial_wait_any()). Every host front end
 * (the j288 tool's bus commands, the Python package, a DDS bridge) drives servos through it:
 * one loop, one stop path, one watchdog policy.
 *
 * Watchdog policy (the servo's 1 s communication watchdog; the manual: a servo whose watchdog
 * tripped stays locked and ignores commands until one comes with the watchdog bit 0):
 * - moving (FOC) commands go out with the watchdog bit 1: a host that stops talking for 1 s
 *   leaves its servos locked;
 * - every lock goes out with the bit 0 (the start-up reads that find a joint's angle, a
 *   joint's lock, j288_robot_exchange()/j288_robot_transfer() locks such as scan and status,
 *   the stop's broadcast lock and the slots it leaves at lock): a locked servo needs no
 *   watchdog, and the bit 0 clears a trip an earlier session left, so a stopped bus takes the
 *   next session's commands;
 * - a reply reporting a trip, or a servo answering in lock mode to FOC commands (twice in a
 *   row in cycles, once for j288_robot_transfer()), is cleared by the runner (the next command
 *   to it goes out with the bit 0) and reported: a J288_ROBOT_EV_WATCHDOG event, the cycle's
 *   `watchdog` count, the servo reply's watchdog_cleared. Never a silent success.
 *
 * A cycle starts a scheduler sweep on every bus at once and completes whichever bus answers
 * first; it ends when every bus that answers has finished its sweep, and calls on_cycle once,
 * with how many joints got fresh state in it. Between cycles the application sets joint
 * targets (joint frame, SI units) for the next one, from on_cycle or after j288_robot_cycle().
 *
 * Buses that fail do not stop the others:
 * - a bus whose sweeps get no reply at all down_after times in a row is "down"
 *   (J288_ROBOT_EV_BUS_DOWN): cycles stop waiting for it; it keeps being swept in the
 *   background, and the first reply brings it back (J288_ROBOT_EV_BUS_UP). Its joints are not
 *   fresh meanwhile, so those cycles are incomplete. Until it is down, cycles wait for its
 *   sweeps (every servo's reply budget and retries): the whole robot slows for those
 *   down_after cycles (measured: 3 servos, 20 ms margin, about 120 ms a cycle for 3 cycles).
 *   A small margin_us on each bus and a small down_after keep that short.
 * - a bus whose device vanishes (adapter unplugged, simulator gone) is reported once
 *   (J288_ROBOT_EV_BUS_GONE, with the port's message in j288_robot_error()), its device
 *   closed at once (a USB adapter that re-enumerates gets its old name back only once nobody
 *   holds the old node) and its joints' angles forgotten: they read not known, not online,
 *   not fresh. Cycles go on without it; only a cycle that finds every bus gone fails
 *   (J288_ERR_OFFLINE).
 * A lost bus is never silent: besides the events, j288_robot_cycle_t.lost counts the buses
 * lost (down or gone) since the previous cycle, j288_robot_stats_t.bus_losses all of them,
 * and j288_robot_bus_stats_t says which bus and when (lost_at_us). A joint whose servo went
 * offline (the scheduler's offline_after failures) or whose bus is down or gone reads
 * known = false (its pos 0), whatever the joint layer last knew.
 *
 * Reconnection (unless no_reopen): a gone bus's device is opened again at the same path (a
 * udev symlink such as /dev/serial/by-id/..., or j288-sim's --link) when it reappears. The
 * attempts are rate-limited: at most one every J288_ROBOT_REOPEN_US per gone bus, made only
 * at the start of a cycle and in j288_robot_run()'s waits between cycles (never in a stop, a
 * transfer, an exchange or j288_robot_idle(), whose callers hold a command made for the old
 * session). An attempt is one non-blocking open (O_NONBLOCK; nothing waits for the device):
 * a path that is not there fails in microseconds; a device that is there costs its driver's
 * open and the line set-up, once (a USB adapter: a few control transfers, milliseconds).
 * The bus comes back restarted from scratch: its bus engine and scheduler initialised anew
 * (their counters restart), the slots that were enabled enabled again, every one at lock
 * (watchdog bit 0), and its joints' angles found again from their first replies (the start
 * of joint.h: no jump is commanded, whatever the servo's angle now is). Their targets are not
 * restored: the joints stay at lock until the application sets targets again (after
 * J288_ROBOT_EV_BUS_BACK, cycle info's back, once their angles are known). Reported as
 * J288_ROBOT_EV_BUS_BACK, j288_robot_cycle_t.back, the bus stats' reopens and back_at_us.
 * Whatever device is found at the path is taken: name an adapter by a stable path
 * (/dev/serial/by-id/...), as a kernel name (/dev/ttyUSB0) may come back as another adapter.
 * A bus named by a pseudo-terminal itself (/dev/pts/N) is never reopened: its number goes to
 * the next program that asks for a terminal (a link to it, as j288-sim's --link, is removed
 * and placed anew by whoever serves the pty).
 * Nothing waits without a bound: every transaction ends by its reply deadline (the bus's
 * margin_us), and a cycle by its timeout.
 *
 * Safe stop: j288_robot_stop() sends the broadcast lock on every bus still there (after the
 * transaction in flight) and waits, bounded, until the stop frames are out; every joint's
 * slot is left at lock, so a later cycle does not resume motion. j288_robot_run() and
 * j288_robot_cycle() do it themselves when the stop flag (j288_robot_set_stop_flag(), e.g.
 * set by a SIGINT handler installed without SA_RESTART) becomes non-zero, then return
 * J288_ERR_ABORTED. j288_robot_close() stops first if any target was sent since the last stop.
 *
 * Pacing and real time (host/j288_rt.h, docs/realtime.md): j288_robot_pace() waits for the
 * next cycle by absolute deadlines (a missed one skipped, never caught up) and
 * j288_robot_run() paces with it; the options realtime, pin_cpu and cpu put the opening
 * thread under SCHED_FIFO with memory locked, on one CPU; j288_robot_timing() reports the
 * loop's wake-up lateness, cycle durations, misses, skips and cut cycles. A cycle allocates
 * nothing and does no I/O but the ports' (non-blocking) reads and writes.
 *
 * Joints: each joint of the config becomes a j288_joint_t (lib/joint.h) bound to its bus's
 * scheduler, in the config's order (joint index 0 .. njoints-1); a joint whose config gives no
 * kp (kd) gets J288_ROBOT_DEFAULT_KP (_KD). A joint's angle is unknown
 * until its first replies (joint.h); until then targets are refused (J288_ERR_ANGLE_UNKNOWN)
 * and the joint is held at lock.
 *
 * Bad input (J288_ERR_BAD_CONFIG with a message in j288_robot_error()): no bus, a bus
 * named twice, two buses on the same device, a joint on a bus that does not exist, an id
 * used twice on one bus, a joint the joint layer refuses. A device that cannot be opened:
 * j288_serial_open()'s code and message. Nothing stays open after a failed open.
 *
 * Objects are caller-allocated (j288_robot_sizeof() for foreign callers), hold no heap memory
 * and must not move while open. One thread owns a robot; nothing here is ISR- or
 * signal-safe but the stop flag. on_event and on_cycle run on that thread from inside the
 * runner's loop (a cycle, a transfer, a stop): they may read and set targets (read, set_target,
 * set_targets, hold, lock), never call cycle, run, stop, transfer, exchange, idle or close,
 * which would re-enter the loop (docs/architecture.md has the table for every layer).
 * Results are the library's codes (j288/error.h).
 */
#ifndef J288_ROBOT_H
#define J288_ROBOT_H

#include <signal.h>
#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "j288/j288.h"
#include "j288_serial.h"
#include "j288_robot_config.h"
#include "j288_rt.h"

#if !J288_CONFIG_SI
#error "the multi-bus runner needs the SI-unit API (J288_CONFIG_SI=1): it drives joints"
#endif

#ifdef __cplusplus
extern "C" {
#endif

#define J288_ROBOT_MAX_BUSES 8u
#define J288_ROBOT_MAX_JOINTS 64u
#define J288_ROBOT_DEFAULT_DOWN_AFTER 3u         /* empty sweeps before a bus is down */
#define J288_ROBOT_DEFAULT_CYCLE_TIMEOUT_US 1000000u
#define J288_ROBOT_STOP_TIMEOUT_US 200000u       /* bound on flushing the stop frames, beyond
                                                    the buses' own reply budgets */
#define J288_ROBOT_MSG_LEN 512u
/* The gains of a joint whose config gives none (j288_robot_hold(), j288_robot_set_targets()
 * without gains, the j288 tool's hold and move): gentle, well inside the wire range, a
 * damping ratio near 0.7 on the simulator's rotor. Joint frame. */
#define J288_ROBOT_DEFAULT_KP 20.0  /* N*m/rad */
#define J288_ROBOT_DEFAULT_KD 2.5   /* N*m*s/rad */

typedef enum {
    J288_ROBOT_EV_SERVO = 0, /* a scheduler event on a joint's servo: servo_ev */
    J288_ROBOT_EV_JOINT,     /* a joint-layer event: joint_kind, value */
    J288_ROBOT_EV_BUS_DOWN,  /* no reply in down_after sweeps: cycles go on without it */
    J288_ROBOT_EV_BUS_UP,    /* a down bus answers again */
    J288_ROBOT_EV_BUS_GONE,  /* its device vanished: left out from now on */
    J288_ROBOT_EV_WATCHDOG,  /* a servo's watchdog had tripped (value 1: the reply said so;
                                2: it answered FOC commands in lock mode); cleared by the
                                runner: see the watchdog policy at the top */
    J288_ROBOT_EV_BUS_BACK   /* a gone bus's device was opened again: restarted from
                                scratch, its joints at lock (reconnection, at the top) */
} j288_robot_event_kind_t;

typedef struct {
    j288_robot_event_kind_t kind;
    unsigned bus;        /* bus index */
    int joint;           /* joint index, or -1 (bus events, a servo that is no joint) */
    uint8_t id;          /* servo id (SERVO, JOINT) */
    j288_event_t servo_ev;                /* SERVO: the scheduler's event */
    j288_joint_event_kind_t joint_kind;   /* JOINT */
    double value;                         /* JOINT: see joint.h */
} j288_robot_event_t;

/* What on_cycle is told. */
typedef struct {
    uint32_t cycle;       /* cycles completed, this one included */
    uint32_t start_us;    /* j288_robot_now_us() clock */
    uint32_t duration_us;
    unsigned fresh;       /* joints with a new reply in this cycle */
    unsigned joints;      /* joints in all */
    bool complete;        /* fresh == joints */
    unsigned watchdog;    /* servos found tripped in this cycle (and cleared) */
    unsigned lost;        /* buses lost (went down or vanished) since the previous cycle */
    unsigned back;        /* buses back (answering again, or reopened) since then */
} j288_robot_cycle_t;

typedef struct j288_robot j288_robot_t;
typedef void (*j288_robot_event_fn)(void *user, const j288_robot_event_t *ev);
typedef void (*j288_robot_cycle_fn)(void *user, j288_robot_t *r, const j288_robot_cycle_t *c);

/* All-zero means defaults. */
typedef struct {
    const char *port;      /* the device when the config has no buses (NULL: then an error) */
    uint32_t baud;         /* for buses that give none; 0: 6000000 */
    uint32_t margin_us;    /* reply margin for buses that give none; 0: 20 ms (USB) */
    uint8_t down_after;    /* 0: J288_ROBOT_DEFAULT_DOWN_AFTER */
    bool no_low_latency;   /* as j288_serial_options_t */
    j288_robot_event_fn on_event; /* may be NULL */
    j288_robot_cycle_fn on_cycle; /* may be NULL; called at the end of every cycle */
    void *user;
    bool stop_on_bus_loss; /* a bus that goes down or vanishes stops every bus: the cycle
                              (and run) returns J288_ERR_OFFLINE after j288_robot_stop(), for
                              robots where half the joints holding is worse than all locked */
    bool echo;             /* for buses that give none: the adapter hears its own transmit */
    uint8_t retries;       /* re-sends of a failed transaction (0-3; bus.h's retries) */
    /* Real time (j288_rt.h), for the thread that opens the robot (the one that runs its loop)
     * from j288_robot_open() until j288_robot_close(), which undoes it: */
    uint8_t realtime;      /* 1-99: memory locked, stack pre-faulted, SCHED_FIFO at this
                              priority (refused without the rights: j288_robot_rt_notice()
                              says why and how to allow it, and the robot runs on); 0: none */
    bool pin_cpu;          /* pin that thread to cpu (one it may run on, else the open fails
                              with J288_ERR_BAD_ARG) */
    uint16_t cpu;
    bool no_reopen;        /* a vanished bus is given up for good (no reconnection) */
} j288_robot_options_t;

/* Least time between two attempts to reopen a gone bus's device (reconnection, at the top). */
#define J288_ROBOT_REOPEN_US 200000u

typedef struct {
    uint32_t sweeps;          /* sweeps completed */
    uint32_t empty_sweeps;    /* of them, with no good reply */
    uint32_t down_events;     /* times it went down */
    uint32_t last_sweep_us;   /* duration of the latest sweep */
    uint32_t worst_sweep_us;
    bool up;                  /* cycles wait for it */
    bool gone;                /* its device vanished (and is not back) */
    uint32_t gone_events;     /* times its device vanished */
    uint32_t up_events;       /* times it answered again after being down */
    uint32_t reopens;         /* times it was opened again (J288_ROBOT_EV_BUS_BACK) */
    uint32_t reopen_attempts; /* opens tried while it was gone */
    uint32_t lost_at_us;      /* j288_robot_now_us() when it was last lost (went down or
                                 vanished); valid once down_events + gone_events > 0 */
    uint32_t back_at_us;      /* ... when it last came back (up again, or reopened) */
} j288_robot_bus_stats_t;

typedef struct {
    uint32_t fresh_cycles;    /* cycles in which this joint got a reply */
    uint32_t stale_cycles;    /* cycles in which it did not */
    j288_slot_stats_t servo;  /* the scheduler's statistics of its slot */
} j288_robot_joint_stats_t;

typedef struct {
    uint32_t cycles;
    uint32_t complete_cycles;
    uint32_t last_cycle_us;
    uint32_t worst_cycle_us;
    uint32_t bus_losses;      /* buses lost (down or gone events), every bus, since open */
    uint32_t bus_returns;     /* buses back (up again, or reopened) */
} j288_robot_stats_t;

/* A joint's state (j288_robot_read()): joint frame, SI units. */
typedef struct {
    bool known;        /* pos is the absolute joint angle (joint.h) and the joint is not lost
                          (its servo online, its bus up and not gone) */
    bool online;       /* its servo answers (and its bus is not gone) */
    bool fresh;        /* a reply came in the latest cycle */
    double pos;        /* rad (0 while unknown) */
    double speed;      /* rad/s */
    double torque;     /* N*m */
    uint32_t faults;   /* the servo's fault bits (J288_FAULT_*) */
    uint8_t warnings;
    double case_temp_c;
    double winding_temp_c;
    double voltage_v;
} j288_robot_state_t;

/* A joint target (joint frame, SI units); see j288_joint_target_t. */
typedef struct {
    double pos, speed, torque, kp, kd;
} j288_robot_target_t;

/* One servo's reply, output side (j288_robot_exchange()). */
typedef struct {
    uint8_t id;
    uint8_t mode;       /* J288_MODE_LOCK or J288_MODE_FOC */
    bool watchdog_tripped;
    double pos;         /* rad, output side, from the rotor's multi-turn count */
    double speed;       /* rad/s, output side */
    double torque;      /* N*m, output side */
    double out_pos;     /* rad, output encoder, [0, 2 pi) */
    double case_temp_c;
    double winding_temp_c;
    double voltage_v;
    uint32_t faults;
    uint8_t warnings;
    uint32_t latency_us;
    bool watchdog_cleared; /* the servo had tripped its watchdog: the command was sent again
                              with the bit 0 (clearing it), and this is that reply */
    /* The joint frame of servo-level use (j288_robot_exchange_joint()): the library's joint
     * with the all-zero configuration, the absolute output angle wrapped to [-pi, pi), as
     * `j288 status --id N` without --config (its joint_pos), or the configuration
     * j288_robot_servo_joint_setup() gave it. Fed by every exchange. */
    bool joint_known;   /* joint_pos is valid (after the start's replies) */
    double joint_pos;   /* rad */
    double joint_speed; /* rad/s */
    double joint_torque; /* N*m */
} j288_robot_servo_t;

typedef struct {
    j288_serial_t serial;
    char port[J288_ROBOT_CONFIG_PORT_MAX]; /* the device, for reopening it */
    uint32_t baud;                         /* asked at open */
    j288_serial_options_t sopt;            /* the port's options at open */
    uint32_t reopen_at_us;                 /* gone: the next reopen attempt */
    j288_bus_t bus;
    j288_sched_t sched;
    j288_joint_bus_t jb;
    j288_robot_t *robot;
    unsigned index;
    char name[J288_ROBOT_CONFIG_NAME_MAX];
    int joint_of[J288_MAX_SERVOS]; /* joint index per id, or -1 */
    bool open;
    bool swept_ok;       /* the sweep in progress had a good reply */
    uint8_t lock_under_foc[J288_MAX_SERVOS]; /* replies in lock mode to FOC commands in a row */
    j288_joint_t servo_joint[J288_MAX_SERVOS]; /* servo level's joint frame (exchanges) */
    bool txn_done;       /* j288_robot_transfer()'s submit has ended (its result in txn) */
    j288_txn_t txn;
    uint16_t servo_joint_on;                   /* bit id: servo_joint[id] initialised */
    uint8_t empty_run;   /* consecutive sweeps without a reply */
    uint32_t sweep_start_us;
    j288_robot_bus_stats_t stats;
} j288_robot_bus_t;

struct j288_robot {
    /* Private: use the functions below. */
    j288_robot_options_t opt;
    unsigned nbuses;
    unsigned njoints;
    j288_robot_bus_t bus[J288_ROBOT_MAX_BUSES];
    j288_joint_t joint[J288_ROBOT_MAX_JOINTS];
    unsigned joint_bus[J288_ROBOT_MAX_JOINTS];
    char joint_name[J288_ROBOT_MAX_JOINTS][J288_ROBOT_CONFIG_NAME_MAX];
    uint32_t fresh_at[J288_ROBOT_MAX_JOINTS]; /* cycle number + 1 of the latest reply */
    j288_robot_joint_stats_t jstats[J288_ROBOT_MAX_JOINTS];
    uint32_t cycle;      /* the cycle in progress (cycles completed + 1) */
    bool driven;         /* a target went out since the last stop */
    bool bus_lost;       /* stop_on_bus_loss: a bus went down or vanished */
    unsigned lost_bus;   /* which one (the first) */
    unsigned wd_cleared; /* watchdog trips cleared in the cycle in progress */
    unsigned lost_pending; /* buses lost since the previous cycle's end */
    unsigned back_pending; /* buses back since then */
    const volatile sig_atomic_t *stop_flag;
    j288_robot_stats_t stats;
    char err[J288_ROBOT_MSG_LEN];
    j288_rt_status_t rt;      /* what the real-time set-up did (j288_rt.h) */
    j288_rt_pacer_t pacer;    /* j288_robot_pace()'s schedule */
    j288_rt_timing_t timing;  /* the loop's timing statistics */
};

/* sizeof(j288_robot_t), for callers that allocate it themselves (ctypes). */
size_t j288_robot_sizeof(void);

/* The library's version (J288_VERSION_STRING). */
const char *j288_robot_version(void);

/* The runner's clock: monotonic microseconds, wrapping at 2^32 (the buses' clock,
 * j288_serial_now_us()): what every *_us time the runner takes or reports is counted in.
 * Any thread. */
uint32_t j288_robot_now_us(void);

/* Set up the calling thread's real time (opt->realtime, pin_cpu), then open every bus of cfg
 * (buses in cfg order; a config without buses: opt->port) and set up its joints (every
 * joint's slot enabled, at lock). Errors: J288_ERR_NULL, J288_ERR_BAD_CONFIG (see the top),
 * J288_ERR_BAD_ARG (realtime above 99, a cpu this process may not run on: nothing opened),
 * j288_serial_open()'s codes; the message in j288_robot_error(). r need not be initialised
 * before; after a failure (the real-time set-up undone) j288_robot_error() stays valid and
 * close is harmless. */
int j288_robot_open(j288_robot_t *r, const j288_robot_config_t *cfg,
                    const j288_robot_options_t *opt);

/* The same from a robot config file (j288_robot_config_load(): its message on failure). */
int j288_robot_open_file(j288_robot_t *r, const char *path, const j288_robot_options_t *opt);

/* One bus on device port and no joints: servo-level use (j288_robot_exchange()). */
int j288_robot_open_port(j288_robot_t *r, const char *port, const j288_robot_options_t *opt);

/* Stop (if any target went out since the last stop) and close every bus; the real-time
 * set-up undone. Safe on a closed or failed robot, and twice. */
void j288_robot_close(j288_robot_t *r);

/* Close without that stop: the servos keep their last command (with the watchdog bit 1 they
 * lock themselves 1 s later). For a front end's explicit "leave it running" (j288 --keep), or
 * after it confirmed every lock itself. */
void j288_robot_close_keep(j288_robot_t *r);

/* Let cycles return J288_ERR_ABORTED (after j288_robot_stop()) once *flag is non-zero. */
void j288_robot_set_stop_flag(j288_robot_t *r, const volatile sig_atomic_t *flag);

/*
 * One cycle: reopen a gone bus whose attempt is due (reconnection, at the top), start a sweep
 * on every bus (a down bus's sweep only if its previous one ended), drive them all from one
 * loop until every bus that is up has finished, then call on_cycle.
 * timeout_us bounds the cycle (0: 1 s; at most 2^31 - 1 us, about 35 min: more is taken as
 * that). Returns J288_OK when every joint got fresh state, J288_ERR_TIMEOUT when some did not
 * (*info says how many; a cycle at its bound first takes the replies that have arrived, as a
 * host woken late would otherwise lose them, then leaves the remaining sweeps running into
 * the next cycle), J288_ERR_OFFLINE when every bus is gone (with stop_on_bus_loss: when one
 * went down or vanished; every bus is then stopped), J288_ERR_ABORTED after a stop on the
 * stop flag, J288_ERR_NULL. info may be NULL. A cycle that finds every bus gone sleeps until
 * the next reopen attempt is due (at most its bound; not with no_reopen), makes it, and runs
 * if a bus came back, else returns J288_ERR_OFFLINE without calling on_cycle: a loop of
 * cycles over a robot whose every device is unplugged waits, it does not spin.
 */
int j288_robot_cycle(j288_robot_t *r, uint32_t timeout_us, j288_robot_cycle_t *info);

/*
 * Cycles until ncycles are done (0: no limit) or duration_us has passed (0: no limit), one
 * every period_us (0: back to back), paced by j288_robot_pace(): absolute deadlines, a missed
 * one skipped, never caught up (j288_rt.h). A run that follows another at the same period goes
 * on with its schedule (a caller running in slices keeps one even rate), and ends before a
 * cycle due at or after duration_us, which the next run then takes up. Returns J288_OK, or
 * J288_ERR_ABORTED (stop flag: every bus stopped), J288_ERR_OFFLINE (with stop_on_bus_loss one
 * bus lost: every bus stopped; with no_reopen every bus gone), J288_ERR_NULL. Incomplete cycles
 * do not end the run, nor (with reconnection) cycles that find every bus gone: the run waits
 * for a device to come back until its end (each such cycle counts toward ncycles);
 * j288_robot_stats() and the events say what was lost.
 */
int j288_robot_run(j288_robot_t *r, uint32_t period_us, uint32_t ncycles, uint32_t duration_us);

/*
 * The loop's wait between cycles, by absolute deadlines: ends the cycle in progress (its
 * duration into the timing statistics) and returns when the next is due, cycle k of a
 * schedule at its first cycle's time + k * period_us, serving every bus meanwhile (sweeps
 * running on in the background, a vanished device); with nothing in flight it sleeps in
 * clock_nanosleep(TIMER_ABSTIME) as cyclictest does. The first call, or the first after the
 * period changes or j288_robot_pace_restart(), starts a schedule and returns at once; so does
 * period_us 0 (back to back: durations only). A deadline already past when it is called is
 * missed: it returns at once, and whole periods behind are skipped, never run back to back
 * (the rule, and why, in j288_rt.h). Returns J288_OK, J288_ERR_ABORTED (the stop flag: nothing
 * is sent, the caller stops), J288_ERR_OFFLINE (every bus gone with no_reopen; with
 * reconnection the next cycle waits for a device instead), J288_ERR_NULL. No allocation, no
 * I/O but the ports' own; a gone bus's reopen attempt that falls due is made.
 */
int j288_robot_pace(j288_robot_t *r, uint32_t period_us);
/* The next j288_robot_pace() starts a new schedule (e.g. after a pause in the loop, whose
 * deadlines would otherwise count as missed). Statistics are kept. */
void j288_robot_pace_restart(j288_robot_t *r);

/* Broadcast lock on every bus still there, every joint's slot at lock; returns once the stop
 * frames are out: after the transaction in flight on each bus (its reply budget) and any
 * re-sends, at most (J288_ESTOP_ATTEMPTS + 2) reply budgets + J288_ROBOT_STOP_TIMEOUT_US.
 * J288_OK, J288_ERR_OFFLINE (some bus is gone: nothing could be sent there),
 * J288_ERR_TIMEOUT, J288_ERR_NULL. */
int j288_robot_stop(j288_robot_t *r);

/* ---- joints (index 0 .. njoints - 1, in the config's order) */

unsigned j288_robot_njoints(const j288_robot_t *r);
unsigned j288_robot_nbuses(const j288_robot_t *r);
/* The joint called name, or -1. */
int j288_robot_find_joint(const j288_robot_t *r, const char *name);
/* Names ("" for a bad index); the bus index and servo id of a joint (-1 for a bad index). */
const char *j288_robot_joint_name(const j288_robot_t *r, unsigned joint);
const char *j288_robot_bus_name(const j288_robot_t *r, unsigned bus);
int j288_robot_joint_bus(const j288_robot_t *r, unsigned joint);
int j288_robot_joint_id(const j288_robot_t *r, unsigned joint);

/* The joint's configuration as the joint layer took it (limits, gains with the defaults
 * filled in, ...). Errors: J288_ERR_NULL, J288_ERR_BAD_ARG. */
int j288_robot_joint_config(const j288_robot_t *r, unsigned joint, j288_joint_config_t *out);

/* The joint's state after the latest cycle. Errors: J288_ERR_NULL, J288_ERR_BAD_ARG. */
int j288_robot_read(const j288_robot_t *r, unsigned joint, j288_robot_state_t *st);

/* Every joint at once, into arrays of n (>= njoints) entries; any array may be NULL. Unknown
 * angles read 0 (known[] says which). Errors: J288_ERR_NULL, J288_ERR_BAD_ARG (n too small). */
int j288_robot_read_all(const j288_robot_t *r, size_t n, double *pos, double *speed,
                        double *torque, uint8_t *known);

/* The joint's next command from a target (joint.h's checks and limits). Errors: those of
 * j288_joint_command(), J288_ERR_BAD_ARG (bad index), J288_ERR_OFFLINE (its bus is gone). */
int j288_robot_set_target(j288_robot_t *r, unsigned joint, const j288_robot_target_t *t);

/* Whether j288_robot_set_target() would take this target now (the same checks), changing
 * nothing: a caller that applies several targets all or none checks each first. Returns
 * J288_OK or the code j288_robot_set_target() would return. */
int j288_robot_check_target(const j288_robot_t *r, unsigned joint, const j288_robot_target_t *t);

/* Every joint at once from arrays of n (>= njoints) entries; speed, torque, kp, kd may be
 * NULL (0, 0, and each joint's configured gains, J288_ROBOT_DEFAULT_KP/_KD where none). All
 * targets are checked before any is set: on an error nothing changes and *bad (may be NULL)
 * gets the failing joint's index. */
int j288_robot_set_targets(j288_robot_t *r, size_t n, const double *pos, const double *speed,
                           const double *torque, const double *kp, const double *kd,
                           unsigned *bad);

/* How far beyond its soft limits a joint may be for j288_robot_hold() to hold it at the
 * nearest limit (rad, joint frame): a joint zeroed against a hard stop reads a hair outside
 * its range, and must still be holdable; the first command pulls it in by at most this. The
 * joint layer's rule (j288_joint_target_init(), J288_JOINT_HOLD_BEYOND). */
#define J288_ROBOT_HOLD_BEYOND_MAX J288_JOINT_HOLD_BEYOND

/* Hold the joint where it is (its configured gains, else J288_ROBOT_DEFAULT_KP/_KD), or put
 * it at lock (watchdog bit 0). A joint beyond its limits by at most J288_ROBOT_HOLD_BEYOND_MAX
 * is held at the nearest limit. Errors:
 * J288_ERR_NULL, J288_ERR_BAD_ARG; hold: J288_ERR_ANGLE_UNKNOWN, J288_ERR_LIMIT_POS (farther
 * beyond its limits: nothing changes). */
int j288_robot_hold(j288_robot_t *r, unsigned joint);
int j288_robot_lock(j288_robot_t *r, unsigned joint);

/* ---- statistics */
int j288_robot_stats(const j288_robot_t *r, j288_robot_stats_t *out);
/* The loop's timing (j288_rt.h): wake-up lateness and cycle duration percentiles, deadlines
 * missed, periods skipped (j288_robot_pace()), cycles cut at their bound (j288_robot_cycle()),
 * and what the real-time set-up put in effect. Errors: J288_ERR_NULL. */
int j288_robot_timing(const j288_robot_t *r, j288_rt_report_t *out);
/* Start the timing statistics afresh (e.g. after a front end's start-up cycles). */
void j288_robot_timing_reset(j288_robot_t *r);
/* What the real-time set-up refused, and how to allow it (j288_rt.h): "" when nothing was
 * asked or all was done; lines each ending in '\n'. Never NULL. */
const char *j288_robot_rt_notice(const j288_robot_t *r);
int j288_robot_bus_stats(const j288_robot_t *r, unsigned bus, j288_robot_bus_stats_t *out);
/* The bus engine's own counters (bus.h), or NULL for a bad index. */
const j288_bus_stats_t *j288_robot_bus_wire_stats(const j288_robot_t *r, unsigned bus);
int j288_robot_joint_stats(const j288_robot_t *r, unsigned joint, j288_robot_joint_stats_t *out);

/* ---- servo level, outside cycles */

/* One transaction with servo id (0-14) on a bus: foc NULL sends lock (watchdog bit 0), else
 * an FOC command from an output-side SI target (j288_cmd_from_si()'s checks; watchdog bit 1),
 * as j288_robot_transfer() (its watchdog policy, out->watchdog_cleared). out (may be NULL)
 * gets the reply. Not while a cycle's sweep runs on that bus. Errors:
 * J288_ERR_NULL, J288_ERR_BAD_ARG (bus), J288_ERR_BUSY, the encoder's and the bus's results
 * (J288_ERR_TIMEOUT: no servo answered, ...), J288_ERR_OFFLINE. */
int j288_robot_exchange(j288_robot_t *r, unsigned bus, uint8_t id, const j288_robot_target_t *foc,
                        j288_robot_servo_t *out);

/* The same in the joint frame (see j288_robot_servo_t's joint_* members): foc NULL sends lock,
 * else an FOC command from a joint-frame target (the joint layer's checks: J288_ERR_LIMIT_POS
 * beyond [-pi, pi], ...). A servo whose angle is not known yet is first sent locks (watchdog
 * bit 0) until it is, bounded: the start-up reads (j288_robot_acquire_joint(); out gets their
 * latest reply when one came). Errors: those of j288_robot_exchange(), J288_ERR_ANGLE_UNKNOWN /
 * J288_ERR_CAL_MISMATCH (the angle could not be found: encoder fault), J288_ERR_ABORTED (the
 * stop flag), the joint layer's. */
#define J288_ROBOT_ACQUIRE_TRIES 40u
int j288_robot_exchange_joint(j288_robot_t *r, unsigned bus, uint8_t id,
                              const j288_robot_target_t *foc, j288_robot_servo_t *out);

/* The servo-level joint of servo jc->id on a bus (the joint frame of
 * j288_robot_exchange_joint(), fed by every j288_robot_transfer() reply from that servo)
 * takes the configuration jc instead of the all-zero one: a front end driving one configured
 * joint outside cycles (the j288 tool's move, hold, zero, calibrate). Its angle is found anew
 * (j288_robot_acquire_joint()); a reopened bus keeps the configuration. Errors: J288_ERR_NULL,
 * J288_ERR_BAD_ARG (bus), j288_joint_init()'s (nothing changes). */
int j288_robot_servo_joint_setup(j288_robot_t *r, unsigned bus, const j288_joint_config_t *jc);

/* That joint, to read (j288_joint_state(), j288_joint_config(): the defaults filled in) and to
 * make commands from (j288_joint_command(), j288_joint_zero_here()); the runner feeds it. NULL
 * for a bad bus or id. Valid until close. */
const j288_joint_t *j288_robot_servo_joint(j288_robot_t *r, unsigned bus, uint8_t id);

/* The start-up reads of that joint: locks (watchdog bit 0) until its angle is known, bounded:
 * J288_ROBOT_ACQUIRE_TRIES exchanges, or 4 per start sample (init_samples) when more; ended
 * early by a failed first exchange (no such servo), 5 failures in a row, the stop flag, or an
 * encoder fault or calibration mismatch still there after two starts' worth of replies (they
 * do not come right by asking again). *last (may be NULL) gets the latest good exchange,
 * *replies (may be NULL) how many replies came. J288_OK (known); the last exchange's error
 * (J288_ERR_TIMEOUT, J288_ERR_OFFLINE, ...); J288_ERR_ABORTED (stop flag);
 * J288_ERR_CAL_MISMATCH or J288_ERR_ANGLE_UNKNOWN (the replies came, the angle was not found:
 * j288_joint_state() says why); J288_ERR_NULL, J288_ERR_BAD_ARG, J288_ERR_BAD_ID. */
int j288_robot_acquire_joint(j288_robot_t *r, unsigned bus, uint8_t id, j288_txn_t *last,
                             unsigned *replies);

/* One transaction of a raw command on a bus, outside cycles, through the runner's loop (the
 * same waits, vanished-device handling and watchdog policy as cycles): a lock goes out with
 * the watchdog bit 0 whatever cmd says; an FOC command whose reply reports a trip, or comes
 * in lock mode, is sent once more with the bit 0 (clearing the trip) and *wd_cleared (may be
 * NULL) is set, with a J288_ROBOT_EV_WATCHDOG event; txn (may be NULL) gets the final
 * transaction. A command other than lock marks the robot driven (close then stops). Not
 * while a cycle's sweep runs on that bus. Errors: J288_ERR_NULL, J288_ERR_BAD_ARG (bus),
 * J288_ERR_BAD_ID (broadcast: use j288_robot_stop()), J288_ERR_BUSY, the bus's results
 * (J288_ERR_TIMEOUT: no reply, ...), J288_ERR_OFFLINE. */
int j288_robot_transfer(j288_robot_t *r, unsigned bus, const j288_cmd_raw_t *cmd,
                        j288_txn_t *txn, bool *wd_cleared);

/* Serve every bus (background sweeps, the port's events) without starting anything until
 * until_us (a j288_robot_now_us() time, at most 35 minutes ahead): a front end's pause
 * between commands. J288_OK, J288_ERR_ABORTED (the stop flag: nothing is sent, the caller
 * stops), J288_ERR_OFFLINE (every bus is gone), J288_ERR_NULL. */
int j288_robot_idle(j288_robot_t *r, uint32_t until_us);

/* The port's notices from open (low latency refused, latency timer advice: zero or more
 * lines, each ending in '\n'), "" when none or for a bad index. Never NULL. */
const char *j288_robot_notices(const j288_robot_t *r, unsigned bus);

/* A bus's scheduler, for a front end without joints (j288 log --id): it may enable slots and
 * set their commands (j288_sched_enable(), j288_sched_set_cmd(), j288_sched_slot()) for
 * j288_robot_cycle() to sweep, under the same watchdog policy; it must not start sweeps, poll
 * or stop it itself. And the bus engine, for its counters and reply budget (j288_bus_stats(),
 * j288_bus_parser_stats(), j288_bus_reply_budget_us()); never submit to it. NULL for a bad
 * index. */
j288_sched_t *j288_robot_bus_sched(j288_robot_t *r, unsigned bus);
const j288_bus_t *j288_robot_bus_engine(const j288_robot_t *r, unsigned bus);

/* The latest error, one line ("" if none). Never NULL. */
const char *j288_robot_error(const j288_robot_t *r);

#ifdef __cplusplus
}
#endif

#endif /* J288_ROBOT_H */
