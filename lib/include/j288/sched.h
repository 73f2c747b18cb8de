/*
 * j288/sched.h - the cycle scheduler: up to 15 servo slots on one bus.
 *
 * Each slot holds the latest command to send, the latest reply received and statistics.
 * A sweep sends every enabled slot its command once, in id order, one transaction after
 * another. Sweeps start from a control-loop tick (j288_sched_start_sweep) or run back to back
 * (config.continuous) from interrupts when the bus advances there.
 *
 * Events (j288_sched_config_t.on_event): a servo came online or went offline (after
 * offline_after consecutive failures), its fault bits or warning bits changed, it reported a
 * watchdog trip, or the trip cleared. Clearing a trip is j288_sched_clear_watchdog(): the
 * next command to that servo goes out with the watchdog bit 0, as the manual requires.
 *
 * Statistics: every completed transaction of a slot counts once, under its final result
 * (crc_errors: transactions that ended J288_ERR_CRC or J288_ERR_TRUNCATED, where the bus's
 * stats.crc_errors counts every bad frame; other_errors: line, port, tx timeout, offline,
 * aborted). consecutive_failures counts failures since the last good reply, except
 * J288_ERR_ABORTED (an emergency stop says nothing about the servo). Latencies are those of
 * good replies. A slot starts offline: its first good reply reports J288_EV_ONLINE; it goes
 * offline (J288_EV_OFFLINE, once) after offline_after consecutive failures. Fault and
 * warning events compare with the previous good reply (with 0 before the first one).
 * Watchdog events follow the reply's watchdog_tripped flag (tripped on a rising edge,
 * cleared on a falling edge).
 *
 * The scheduler owns the bus's completion callback while a sweep runs; do not submit to the
 * same bus yourself in between. Thread only unless the bus advances in its ISR, in which case
 * the same rules as bus.h apply (thread calls are wrapped in the port's lock/unlock).
 */
#ifndef J288_SCHED_H
#define J288_SCHED_H

#include <stdbool.h>
#include <stdint.h>

#include "j288/bus.h"
#include "j288/frame.h"
#include "j288/units.h"

#ifdef __cplusplus
extern "C" {
#endif

#define J288_DEFAULT_OFFLINE_AFTER 3u

typedef struct {
    uint32_t transactions;
    uint32_t successes;
    uint32_t timeouts;
    uint32_t crc_errors;       /* transactions ended CRC or TRUNCATED (not frames) */
    uint32_t wrong_id;
    uint32_t collisions;
    uint32_t other_errors;     /* line, port, tx timeout, aborted */
    uint32_t consecutive_failures;
    uint32_t last_latency_us;
    uint32_t worst_latency_us;
} j288_slot_stats_t;

typedef enum {
    J288_EV_ONLINE = 0,
    J288_EV_OFFLINE,
    J288_EV_FAULTS_CHANGED,   /* old_bits/new_bits: MError */
    J288_EV_WARNINGS_CHANGED, /* old_bits/new_bits: ExFlag */
    J288_EV_WATCHDOG_TRIPPED,
    J288_EV_WATCHDOG_CLEARED
} j288_event_kind_t;

typedef struct {
    j288_event_kind_t kind;
    uint8_t id;
    uint32_t old_bits;
    uint32_t new_bits;
} j288_event_t;

typedef struct {
    bool enabled;
    bool online;
    bool has_reply;            /* reply holds a real reply */
    bool clear_watchdog;       /* the next command goes out with the watchdog bit 0 */
    j288_cmd_raw_t cmd;        /* the latest command to send */
    j288_reply_raw_t reply;    /* the latest good reply */
    uint32_t reply_us;         /* when it was taken */
    int last_result;
    j288_slot_stats_t stats;
} j288_slot_t;

typedef void (*j288_event_fn)(void *user, const j288_event_t *ev);
typedef void (*j288_sweep_fn)(void *user, uint32_t sweep, uint32_t now_us);
/* Every good reply, once it is stored in slot id (slot->reply, reply_us, statistics) and its
 * events have been reported, before the scheduler submits anything else. Layers above the
 * scheduler (the joint layer) turn the reply into their state here, and may replace the
 * slot's next command with j288_sched_set_cmd() (e.g. a safe lock when the reply says the
 * angle can no longer be trusted). */
typedef void (*j288_reply_fn)(void *user, uint8_t id, const j288_slot_t *slot);

/* All-zero means defaults. */
typedef struct {
    uint8_t offline_after;  /* consecutive failures before OFFLINE; 0: 3 */
    bool continuous;        /* start the next sweep as soon as one ends */
    j288_event_fn on_event; /* may be NULL; called from the advancing context */
    j288_sweep_fn on_sweep; /* may be NULL; called when a sweep ends */
    j288_reply_fn on_reply; /* may be NULL; called for every good reply (see above) */
    void *user;
} j288_sched_config_t;

typedef struct {
    /* Private. */
    j288_bus_t *bus;
    j288_sched_config_t cfg;
    j288_slot_t slot[J288_MAX_SERVOS];
    uint8_t cursor;        /* next slot to visit in this sweep */
    uint8_t sent;          /* transactions submitted in this sweep */
    bool sweeping;
    bool stopped;          /* after an estop, until the next start */
    bool wd_clear_in_flight; /* the command in flight has its watchdog bit cleared */
    uint16_t frame_stale;  /* bit id: frame[id] no longer matches slot[id].cmd */
    uint32_t sweeps;
    uint8_t frame[J288_MAX_SERVOS][J288_CMD_LEN]; /* each slot's command, encoded when sent */
} j288_sched_t;

/* Bind a scheduler to a bus (already initialised). cfg may be NULL. Slots start disabled,
 * with a lock command, watchdog on. Errors: J288_ERR_NULL. Thread only. */
int j288_sched_init(j288_sched_t *s, j288_bus_t *bus, const j288_sched_config_t *cfg);

/* Enable or disable slot id (0-14). Errors: J288_ERR_NULL, J288_ERR_BAD_ID. */
int j288_sched_enable(j288_sched_t *s, uint8_t id, bool enabled);

/* Replace slot cmd->id's command (validated as j288_cmd_encode() would; nothing changes on
 * error). Takes effect from the slot's next transaction. Errors: J288_ERR_NULL,
 * J288_ERR_BAD_ID (15 is not a slot), J288_ERR_BAD_STATUS, J288_ERR_NEG_GAIN. */
int j288_sched_set_cmd(j288_sched_t *s, const j288_cmd_raw_t *cmd);
#if J288_CONFIG_SI
/* The same from SI units (j288_cmd_from_si() errors as well). */
int j288_sched_set_cmd_si(j288_sched_t *s, const j288_cmd_si_t *cmd, j288_side_t side);
#endif

/* Begin a sweep over the enabled slots. Errors: J288_ERR_NULL, J288_ERR_BUSY (a sweep is
 * running, or the bus refused the first submit: a transaction in flight or queued, or an
 * estop pending). A sweep with no enabled slot ends at once (on_sweep is called, and a
 * continuous scheduler does not restart an empty sweep). Starting during the 2 us guard
 * after the previous transaction is fine (the first command waits for the guard). If the
 * bus refuses a submit in the middle of a sweep (an estop made directly on the bus), the
 * sweep ends there without counting; that slot's last_result says why. */
int j288_sched_start_sweep(j288_sched_t *s, uint32_t now_us);

/* Advance bus and scheduler (calls j288_bus_poll()). Thread only, or the owning ISR. */
void j288_sched_poll(j288_sched_t *s, uint32_t now_us);

/* True while a sweep is in progress. */
bool j288_sched_busy(const j288_sched_t *s);

/* Ask that servo id's watchdog trip be cleared: its next command goes out with the
 * watchdog bit 0 (once), after which the slot's own watchdog setting applies again. "Once"
 * means until a transaction carrying it succeeds: if the servo did not answer, the next
 * sweep sends the bit 0 again. The slot must be enabled for anything to be sent.
 * Errors: J288_ERR_NULL, J288_ERR_BAD_ID. */
int j288_sched_clear_watchdog(j288_sched_t *s, uint8_t id);

/* Emergency stop: end the sweep, drop queued work and broadcast lock (j288_bus_estop()).
 * Every slot's command becomes lock (all fields 0, each slot's watchdog bit kept) so that a
 * later sweep does not resume motion; no further slot is sent in this sweep, and the
 * transaction in flight ends J288_ERR_ABORTED. Sweeps resume only with
 * j288_sched_start_sweep(). Errors: J288_ERR_NULL. */
int j288_sched_estop(j288_sched_t *s, uint32_t now_us);

/* Slot id's state, or NULL for a bad id. Valid until the next poll. */
const j288_slot_t *j288_sched_slot(const j288_sched_t *s, uint8_t id);

/* Completed sweeps. */
uint32_t j288_sched_sweeps(const j288_sched_t *s);

#ifdef __cplusplus
}
#endif

#endif /* J288_SCHED_H */
