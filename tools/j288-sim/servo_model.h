/*
 * servo_model.h - the simulated J288 bus: servos as the host sees them, without any I/O.
 *
 * Two levels:
 * - j288_sim_servo_t: one servo. Protocol state (mode, 1 s watchdog, latched faults) and
 *   physics: the hybrid law tau = tau_ff + kp (p_des - p) + kd (w_des - w) drives a rotor
 *   (inertia, viscous and Coulomb friction, an optional output load through the 288.35
 *   gear), with a two-node thermal model (winding, case) and a supply voltage. Integrated in
 *   fixed steps of at most J288_SIM_STEP_US up to whatever time the caller gives.
 *   Its joint: the continuous rotor angle is r = N * theta_gear + c, where N is the gear
 *   ratio (J288_GEAR_RATIO), theta_gear the gear side of the output stage and c the rotor
 *   phase fixed at assembly. The rotor encoder is single-turn: the position a reply reports
 *   is p = r - 2 pi k, with k chosen at power-up so that p starts in [0, 2 pi), and p
 *   counts turns from there. The output shaft angle theta (what the 13-bit output encoder
 *   measures, OutPos = floor(8192 * (theta mod 2 pi) / 2 pi)) equals theta_gear, or with
 *   backlash (params.backlash > 0) lies within half the play of it (see "Backlash" below).
 *   c goes with the labelling of theta's turns (theta + 2 pi gives another c); angles drawn
 *   from the seed are labelled in [-pi, pi), the frame the joint layer uses without
 *   configuration. A power cycle (j288_sim_servo_power_cycle) leaves theta, theta_gear and
 *   c where they are and loses the turn count: at power-up p restarts inside [0, 2 pi) (a
 *   new k). While off, the servo is deaf and silent and gives no torque; it comes back in
 *   lock with the watchdog off, as after the first power-up.
 * - j288_sim_bus_t: the wire. Bytes the host sent go through lib's command parser
 *   (J288_PARSE_COMMAND) and j288_cmd_decode(); addressed servos answer through the send
 *   callback, after the turnaround, with the configured faults injected (drop, corrupt,
 *   late, noise, duplicate id) from a seeded generator: the same bytes at the same times
 *   give the same output.
 *
 * Time is in microseconds since the simulation started (uint64_t, never wraps); the caller
 * ties it to a clock (the pty front end uses CLOCK_MONOTONIC). Single-threaded; no
 * allocation; objects are caller-allocated.
 *
 * Decisions where the manual is silent (documented for users of the simulator):
 * - A command with status other than 0 or 1 is obeyed as lock.
 * - While the watchdog is tripped the servo stays in lock and reports the trip; a command
 *   with the watchdog bit 0 clears it and is then obeyed as usual.
 * - The watchdog is fed by any good command addressed to the servo, broadcast included.
 * - A frame with a bad CRC sets the communication-checksum fault on the servo its id byte
 *   names (every servo for id 15); the bit is reported in the next reply, then cleared.
 * - Winding above 150 C or case above 100 C sets the matching fault and removes torque
 *   until the temperature falls 10 C below the limit. Supply below 10 V: under-voltage fault,
 *   above 30 V: over-voltage fault (both remove torque); below 11 V: low-supply warning.
 * - Injected fault bits are reported only; they do not change the physics.
 * - The wire faults (drop, corrupt, late, noise, duplicate-id replies) can be switched off
 *   and on again while running (j288_sim_bus_set_faults). Off means a clean line: every
 *   addressed servo answers once, intact, after the turnaround; the duplicate servos still
 *   obey commands (so they pick up where they were when switched on again) but stay silent.
 *   Injected fault bits (--fault) are servo state, not line faults: the switch keeps them.
 *   A reply draws the same random numbers with the faults on or off (a silent duplicate
 *   draws none), so a run stays reproducible for the same commands, timing and switching.
 *   Replies already handed to the send callback (e.g. a late one) are not recalled.
 * - Backlash: the output shaft is massless and moves only when the gear side pushes it (it
 *   stays inside [theta_gear - b/2, theta_gear + b/2], b the play) or when the load drives
 *   it: a load torque other than zero keeps it pressed against the side it pushes towards,
 *   so that the gear always carries the load. The load's inertia is always felt by the rotor.
 * - A power cycle keeps the temperatures and the injected fault bits (a broken encoder stays
 *   broken), clears the latched checksum fault, and does not change the random sequence of
 *   the bus (a servo that is off draws nothing: it does not answer).
 */
#ifndef J288_SIM_SERVO_MODEL_H
#define J288_SIM_SERVO_MODEL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "j288/frame.h"
#include "j288/parser.h"

#define J288_SIM_STEP_US         50u      /* integration step */
#define J288_SIM_WATCHDOG_US     1000000u /* the servo's communication watchdog */
#define J288_SIM_WIND_LIMIT_C    150.0
#define J288_SIM_CASE_LIMIT_C    100.0
#define J288_SIM_TEMP_HYST_C     10.0
#define J288_SIM_UNDER_VOLTAGE_V 10.0
#define J288_SIM_OVER_VOLTAGE_V  30.0
#define J288_SIM_LOW_SUPPLY_V    11.0

/* Physical parameters, rotor side unless named otherwise. */
typedef struct {
    double inertia;      /* rotor inertia, kg m^2 */
    double viscous;      /* viscous friction, N m s/rad */
    double coulomb;      /* Coulomb (dry) friction, N m */
    double tau_max;      /* motor torque limit, N m */
    double load_inertia; /* extra inertia on the output shaft, kg m^2 */
    double load_torque;  /* constant torque on the output shaft, N m (e.g. a weight) */
    double voltage;      /* supply, V */
    double ambient_c;    /* ambient temperature, deg C */
    double loss_per_nm2; /* copper loss per torque squared, W/(N m)^2 */
    double backlash;     /* play between the gear and the output shaft, output rad (0: none) */
} j288_sim_params_t;

/* Sensible defaults: a small rotor, 24 V, 25 C. */
void j288_sim_params_default(j288_sim_params_t *prm);

typedef struct {
    uint8_t id;
    j288_sim_params_t prm;
    /* physics */
    double p;     /* rotor angle since power-up, rad (multi-turn; what replies report) */
    double w;     /* rotor speed, rad/s */
    double tau;   /* motor torque applied in the last step, N m */
    double c;     /* rotor phase: r = N * theta_gear + c */
    long k;       /* turns lost at the last power-up: r = p + 2 pi k */
    double theta; /* output shaft angle, rad (multi-turn), what the output encoder measures */
    double t_wind, t_case;
    /* power */
    bool powered;          /* false while a power cycle keeps it off */
    uint64_t power_on_us;  /* when it comes back (while !powered) */
    uint32_t power_cycles; /* since the simulation started */
    /* protocol */
    j288_cmd_raw_t cmd; /* the last command obeyed */
    uint8_t mode;       /* J288_MODE_LOCK or J288_MODE_FOC, as reported */
    bool wd_enabled;
    bool wd_tripped;
    uint64_t last_cmd_us;
    uint64_t now_us;          /* model time */
    uint32_t faults_latched;  /* reported once, then cleared (checksum) */
    uint32_t faults_active;   /* conditions (temperature, voltage) */
    uint32_t faults_injected; /* --fault */
    uint32_t watchdog_trips;
} j288_sim_servo_t;

/* Power up servo id at time 0: lock, watchdog off, rotor phase c, output shaft at
 * out_angle (rad, multi-turn; it labels the turns c goes with). The gear side starts at the
 * shaft, or, with backlash and a load torque, half the play away from it (the load presses
 * the shaft against one side); p is then r modulo 2 pi. prm NULL: defaults. */
void j288_sim_servo_init(j288_sim_servo_t *s, uint8_t id, const j288_sim_params_t *prm, double c,
                         double out_angle);

/* Integrate up to now_us (no-op if now_us is not later). Trips the watchdog at the exact
 * time it starves, and powers the servo up at the exact time a power cycle ends. */
void j288_sim_servo_advance(j288_sim_servo_t *s, uint64_t now_us);

/* A good command for this servo (or broadcast) arrived at now_us. Returns false when the
 * servo is off (power cycle) and did not hear it; it must then not answer. */
bool j288_sim_servo_command(j288_sim_servo_t *s, const j288_cmd_raw_t *cmd, uint64_t now_us);

/* A frame naming this servo failed its CRC (ignored while it is off). */
void j288_sim_servo_bad_crc(j288_sim_servo_t *s);

/* The reply the servo sends now (clears report-once faults). */
void j288_sim_servo_reply(j288_sim_servo_t *s, j288_reply_raw_t *r);

/* Switch the servo off at now_us (after advancing to it) for off_us microseconds (0: it is
 * back at once), then on again: theta, theta_gear and c kept, p restarts inside [0, 2 pi),
 * lock, watchdog off. A cycle while already off restarts the off time. */
void j288_sim_servo_power_cycle(j288_sim_servo_t *s, uint64_t now_us, uint32_t off_us);

/* Output shaft angle, rad (multi-turn), and the 13-bit OutPos the encoder reports. */
double j288_sim_servo_out_angle(const j288_sim_servo_t *s);
uint16_t j288_sim_servo_out_pos(const j288_sim_servo_t *s);

/* The simulated truth, for tests that compare what the host computes with it. */
typedef struct {
    double theta;      /* output shaft angle, rad (multi-turn) */
    double theta_gear; /* gear side of the output stage, rad: r = N * theta_gear + c */
    double c;          /* rotor phase, rad */
    double r;          /* continuous rotor angle, rad */
    double p;          /* rotor position a reply reports, rad: p = r - 2 pi k */
    long k;            /* turns lost at the last power-up */
    uint16_t out_pos;  /* the output encoder's count */
    bool powered;      /* false during a power cycle's off time */
    uint32_t power_cycles;
} j288_sim_truth_t;

void j288_sim_servo_truth(const j288_sim_servo_t *s, j288_sim_truth_t *t);

/* ---- the bus ---------------------------------------------------------------------------- */

typedef struct {
    uint32_t turnaround_us; /* delay before a reply */
    double drop;            /* probability a reply is not sent */
    double corrupt;         /* probability one byte of a reply is changed */
    double late;            /* probability a reply is delayed by late_us */
    uint32_t late_us;       /* 0: 50 ms */
    double noise;           /* probability of 1-8 noise bytes ahead of a reply */
    uint16_t dup_ids;       /* bit n: a second servo also answers to id n */
    uint64_t seed;
    uint32_t idle_flush_us; /* a gap this long drops a partial command; 0: 5 ms */
    uint32_t power_off_us;  /* how long a power-cycled servo stays off (0: back at once) */
} j288_sim_bus_config_t;

typedef struct {
    uint64_t bytes;
    uint64_t commands; /* good frames */
    uint64_t broadcasts;
    uint64_t bad_crc;
    uint64_t for_others; /* good frames for ids not on this bus */
    uint64_t replies;    /* replies sent (duplicates included) */
    uint64_t dropped;
    uint64_t corrupted;
    uint64_t late;
    uint64_t noise;
    uint64_t duplicates;
    uint64_t watchdog_trips;
    uint64_t power_cycles; /* servo power cycles (each servo counts; duplicates too) */
} j288_sim_stats_t;

/* Bytes to put on the wire at at_us (>= the time of the command that caused them). */
typedef void (*j288_sim_send_fn)(void *user, uint64_t at_us, const uint8_t *data, size_t len);
/* Every complete command frame seen, good (cmd non-NULL) or with a bad CRC (cmd NULL). */
typedef void (*j288_sim_log_fn)(void *user, uint64_t now_us, const uint8_t frame[J288_CMD_LEN],
                                const j288_cmd_raw_t *cmd);

typedef struct {
    j288_parser_t parser;
    j288_sim_bus_config_t cfg;
    j288_sim_servo_t servo[J288_MAX_SERVOS];
    j288_sim_servo_t dup[J288_MAX_SERVOS];
    uint16_t present; /* bit n: servo n is on the bus */
    uint64_t rng;
    uint8_t window[J288_CMD_LEN]; /* the last 20 bytes fed, oldest first */
    uint64_t last_byte_us;
    uint64_t now_us;
    bool faults_off; /* j288_sim_bus_set_faults(b, false): a clean line */
    j288_sim_stats_t stats;
    j288_sim_send_fn send;
    j288_sim_log_fn log;
    void *user;
} j288_sim_bus_t;

/* Set up a bus with the servos whose bits are set in ids (bit n = id n, 0-14). Each servo's
 * rotor phase c (in [0, 2 pi)) and start output angle (in [-pi, pi)) come from the seed,
 * drawn for every id present or not, so a servo's draw does not depend on the others.
 * cfg, prm may be NULL. send may be NULL (replies are counted, not sent), log may be NULL.
 * Returns 0, or -1 for ids == 0 or ids with bit 15. */
int j288_sim_bus_init(j288_sim_bus_t *b, uint16_t ids, const j288_sim_bus_config_t *cfg,
                      const j288_sim_params_t *prm, j288_sim_send_fn send, j288_sim_log_fn log,
                      void *user);

/* Give servo id (not its duplicate) rotor phase c and start output angle theta instead of
 * the drawn ones: it is powered up afresh with them. Call before any traffic. -1 for an id
 * not on the bus. */
int j288_sim_bus_set_joint(j288_sim_bus_t *b, uint8_t id, double c, double theta);

/* Power-cycle the servos whose bits are set in ids (their duplicates too) at now_us, off for
 * cfg.power_off_us. Returns the number of servos cycled, or -1 (nothing done) when ids names
 * a servo that is not on the bus. */
int j288_sim_bus_power_cycle(j288_sim_bus_t *b, uint16_t ids, uint64_t now_us);

/* Inject fault bits (reported in every reply until changed). -1 for an id not on the bus. */
int j288_sim_bus_inject_faults(j288_sim_bus_t *b, uint8_t id, uint32_t bits);

/* Wire faults on (as configured; the state after init) or off (a clean line) from the next
 * command on. Injected fault bits are kept either way; see the decisions above. */
void j288_sim_bus_set_faults(j288_sim_bus_t *b, bool on);

/* Bytes from the host, received at now_us. */
void j288_sim_bus_feed(j288_sim_bus_t *b, const uint8_t *data, size_t len, uint64_t now_us);

/* Advance every servo to now_us (call now and then, e.g. every 10 ms, when idle). */
void j288_sim_bus_advance(j288_sim_bus_t *b, uint64_t now_us);

/* The simulator itself did not run from from_us to to_us (a starved process woke late):
 * what the host sent meanwhile waits unread, so no servo's watchdog counts that stretch as
 * the host's silence (each one's silence clock is held for it). Call before the servos
 * advance past from_us. */
void j288_sim_bus_excuse_stall(j288_sim_bus_t *b, uint64_t from_us, uint64_t to_us);

/* Servo id's state, or NULL when it is not on the bus. */
j288_sim_servo_t *j288_sim_bus_servo(j288_sim_bus_t *b, uint8_t id);

#endif /* J288_SIM_SERVO_MODEL_H */
