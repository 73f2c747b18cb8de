/* The cycle scheduler: slots, sweeps, statistics and events; see j288/sched.h. */
#include "j288/sched.h"

#include <string.h>

#include "bus_priv.h"
#include "frame_priv.h"

#define ALL_SLOTS ((uint16_t)(((uint32_t)1u << J288_MAX_SERVOS) - 1u))

int j288_sched_init(j288_sched_t *s, j288_bus_t *bus, const j288_sched_config_t *cfg)
{
    uint8_t i;

    if ((s == NULL) || (bus == NULL)) {
        return J288_ERR_NULL;
    }
    (void)memset(s, 0, sizeof *s);
    s->bus = bus;
    if (cfg != NULL) {
        s->cfg = *cfg;
    }
    if (s->cfg.offline_after == 0u) {
        s->cfg.offline_after = (uint8_t)J288_DEFAULT_OFFLINE_AFTER;
    }
    for (i = 0u; i < J288_MAX_SERVOS; i++) {
        j288_cmd_lock(&s->slot[i].cmd, i, true);
        s->slot[i].last_result = J288_OK;
    }
    s->frame_stale = ALL_SLOTS;
    return J288_OK;
}

int j288_sched_enable(j288_sched_t *s, uint8_t id, bool enabled)
{
    if (s == NULL) {
        return J288_ERR_NULL;
    }
    if (id > J288_MAX_ID) {
        return J288_ERR_BAD_ID;
    }
    s->slot[id].enabled = enabled;
    return J288_OK;
}

int j288_sched_set_cmd(j288_sched_t *s, const j288_cmd_raw_t *cmd)
{
    bool locked;
    int err;

    if ((s == NULL) || (cmd == NULL)) {
        return J288_ERR_NULL;
    }
    /* The encoder's checks, so that a slot never holds a command the bus would refuse
     * mid-sweep; 15 (broadcast) is not a slot. */
    if (cmd->id > J288_MAX_ID) {
        return J288_ERR_BAD_ID;
    }
    err = j288_cmd_check(cmd);
    if (err != J288_OK) {
        return err;
    }
    locked = j288_bus_needs_lock(s->bus); /* once: nothing in between changes it */
    j288_bus_port_lock(s->bus, locked);
    s->slot[cmd->id].cmd = *cmd;
    s->frame_stale |= (uint16_t)((uint32_t)1u << cmd->id);
    j288_bus_port_unlock(s->bus, locked);
    return J288_OK;
}

#if J288_CONFIG_SI
int j288_sched_set_cmd_si(j288_sched_t *s, const j288_cmd_si_t *cmd, j288_side_t side)
{
    j288_cmd_raw_t raw;
    int err;

    if ((s == NULL) || (cmd == NULL)) {
        return J288_ERR_NULL;
    }
    err = j288_cmd_from_si(cmd, side, &raw);
    if (err != J288_OK) {
        return err;
    }
    return j288_sched_set_cmd(s, &raw);
}
#endif

/* ---- events and statistics */

static void emit(const j288_sched_t *s, j288_event_kind_t kind, uint8_t id, uint32_t old_bits,
                 uint32_t new_bits)
{
    j288_event_t ev;
    if (s->cfg.on_event == NULL) {
        return;
    }
    ev.kind = kind;
    ev.id = id;
    ev.old_bits = old_bits;
    ev.new_bits = new_bits;
    s->cfg.on_event(s->cfg.user, &ev);
}

/* A good reply's events against the previous one (old_*), in the order sched.h lists them;
 * out of line: most replies change nothing. */
J288_NOINLINE static void report_reply(j288_sched_t *s, j288_slot_t *slot, uint8_t id,
                                       uint32_t old_faults, uint8_t old_warn, bool old_trip)
{
    const j288_reply_raw_t *r = &slot->reply;

    slot->has_reply = true; /* (a slot without a reply yet is offline: it comes here) */
    if (!slot->online) {
        slot->online = true;
        emit(s, J288_EV_ONLINE, id, 0u, 0u);
    }
    if (r->faults != old_faults) {
        emit(s, J288_EV_FAULTS_CHANGED, id, old_faults, r->faults);
    }
    if (r->warnings != old_warn) {
        emit(s, J288_EV_WARNINGS_CHANGED, id, old_warn, r->warnings);
    }
    if (r->watchdog_tripped && !old_trip) {
        emit(s, J288_EV_WATCHDOG_TRIPPED, id, 0u, 1u);
    } else if (!r->watchdog_tripped && old_trip) {
        emit(s, J288_EV_WATCHDOG_CLEARED, id, 1u, 0u);
    }
}

static void take_reply(j288_sched_t *s, j288_slot_t *slot, const j288_txn_t *txn)
{
    const j288_reply_raw_t *r = &txn->reply;
    /* Before the first reply slot->reply is all zero (init), the "previous" sched.h names. */
    uint32_t old_faults = slot->reply.faults;
    uint8_t old_warn = slot->reply.warnings;
    bool old_trip = slot->reply.watchdog_tripped;
    uint32_t latency = txn->latency_us;

    slot->stats.successes++;
    slot->stats.consecutive_failures = 0u;
    slot->stats.last_latency_us = latency;
    if (latency > slot->stats.worst_latency_us) {
        slot->stats.worst_latency_us = latency;
    }
    slot->reply = *r;
    slot->reply_us = txn->start_us + latency;
    if (s->wd_clear_in_flight) {
        slot->clear_watchdog = false; /* the servo heard it: once is enough */
    }
    if (!slot->online || (r->faults != old_faults) || (r->warnings != old_warn) ||
        (r->watchdog_tripped != old_trip)) {
        report_reply(s, slot, txn->id, old_faults, old_warn, old_trip);
    }
}

static void take_failure(j288_sched_t *s, j288_slot_t *slot, uint8_t id, int result)
{
    j288_slot_stats_t *st = &slot->stats;

    switch (result) {
    case J288_ERR_TIMEOUT:
        st->timeouts++;
        break;
    case J288_ERR_CRC:
    case J288_ERR_TRUNCATED:
        st->crc_errors++;
        break;
    case J288_ERR_WRONG_ID:
        st->wrong_id++;
        break;
    case J288_ERR_COLLISION:
        st->collisions++;
        break;
    default:
        st->other_errors++;
        break;
    }
    if (result == J288_ERR_ABORTED) {
        return; /* an emergency stop says nothing about the servo */
    }
    st->consecutive_failures++;
    if (slot->online && (st->consecutive_failures >= s->cfg.offline_after)) {
        slot->online = false;
        emit(s, J288_EV_OFFLINE, id, 0u, 0u);
    }
}

/* ---- sweeps */

static void sched_done(void *user, const j288_txn_t *txn);

static void end_sweep(j288_sched_t *s, uint32_t now)
{
    s->sweeping = false;
    s->sweeps++;
    if (s->cfg.on_sweep != NULL) {
        s->cfg.on_sweep(s->cfg.user, s->sweeps, now);
    }
}

/* Submit slot id's command. The frame encoded for it is reused while the command stays the
 * same (its checks were made by set_cmd, its CRC once); a watchdog clear goes out as a
 * one-off frame. frame[id] is the bus's frame until the completion: only this function
 * writes it, and only once the bus has accepted a new transaction (until then frame[id] may
 * still be on the wire, in a transaction an estop is ending), under the lock that set_cmd
 * takes (its stale mark is not lost). */
static int submit_slot(j288_sched_t *s, uint8_t id, uint32_t now, bool locked)
{
    const j288_slot_t *slot = &s->slot[id];
    j288_bus_t *bus = s->bus;
    uint16_t bit = (uint16_t)((uint32_t)1u << id);
    int rc;

    if (slot->clear_watchdog) {
        j288_cmd_raw_t cleared = slot->cmd;
        cleared.watchdog = false;
        return j288_bus_submit(bus, &cleared, now, sched_done, s);
    }
    j288_bus_port_lock(bus, locked);
    rc = J288_ERR_BUSY;
    if (j288_bus_accepts(bus)) {
        if ((s->frame_stale & bit) != 0u) {
            /* Checked fields (set_cmd, init and estop make only such commands), its id the
             * slot's */
            j288_cmd_pack(&slot->cmd, s->frame[id], j288_bus_crc(bus));
            s->frame_stale &= (uint16_t)~bit;
        }
        j288_bus_take_frame(bus, s->frame[id], id, now, sched_done, s);
        rc = J288_OK;
    }
    j288_bus_port_unlock(bus, locked);
    return rc;
}

/* Submit the next enabled slot of this sweep; end the sweep (and start the next one when
 * continuous) when none is left. Returns J288_ERR_BUSY if the bus refused the submit. locked:
 * j288_bus_needs_lock() as the caller found it, the same before and after the submit (false
 * in a completion callback, which runs with the lock held or not needed: bus_priv.h). */
static int next_slot(j288_sched_t *s, uint32_t now, bool locked)
{
    for (;;) {
        while (s->cursor < J288_MAX_SERVOS) {
            uint8_t id = s->cursor++;
            j288_slot_t *slot = &s->slot[id];
            int rc;
            if (!slot->enabled) {
                continue;
            }
            s->wd_clear_in_flight = slot->clear_watchdog;
            s->sent++;
            rc = submit_slot(s, id, now, locked);
            if (rc == J288_OK) {
                return J288_OK; /* sched_done continues the sweep */
            }
            s->sent--;
            slot->last_result = rc;
            s->sweeping = false; /* busy (an estop) or refused: the sweep stops here */
            return rc;
        }
        {
            /* (not stopped: a running sweep never is, see sched_done) */
            bool again = s->cfg.continuous && (s->sent != 0u);
            end_sweep(s, now);
            if (!again || s->sweeping || s->stopped) {
                return J288_OK; /* (on_sweep may have started or stopped a sweep itself) */
            }
        }
        s->sweeping = true;
        s->cursor = 0u;
        s->sent = 0u;
    }
}

static void sched_done(void *user, const j288_txn_t *txn)
{
    j288_sched_t *s = (j288_sched_t *)user;
    j288_slot_t *slot;

    if (txn->id > J288_MAX_ID) { /* GCOVR_EXCL_BR_LINE: only slots 0-14 are submitted */
        return;                  /* GCOVR_EXCL_LINE: (a guard for the slot index) */
    }
    slot = &s->slot[txn->id];
    slot->stats.transactions++;
    slot->last_result = txn->result;
    if (txn->result == J288_OK) {
        take_reply(s, slot, txn);
        if (s->cfg.on_reply != NULL) {
            s->cfg.on_reply(s->cfg.user, txn->id, slot);
        }
    } else {
        take_failure(s, slot, txn->id, txn->result);
    }
    s->wd_clear_in_flight = false;
    /* j288_sched_estop() clears sweeping as it sets stopped, and only a start sets sweeping
     * again (clearing stopped): a sweeping scheduler is never stopped. */
    if (s->sweeping) {
        (void)next_slot(s, txn->start_us + txn->latency_us, false);
    }
}

int j288_sched_start_sweep(j288_sched_t *s, uint32_t now_us)
{
    int rc;

    if (s == NULL) {
        return J288_ERR_NULL;
    }
    if (s->sweeping) {
        return J288_ERR_BUSY;
    }
    /* All sched state is set before the submit: the ISR may complete it at once. */
    s->stopped = false;
    s->cursor = 0u;
    s->sent = 0u;
    s->sweeping = true;
    rc = next_slot(s, now_us, j288_bus_needs_lock(s->bus));
    return rc;
}

void j288_sched_poll(j288_sched_t *s, uint32_t now_us)
{
    if (s != NULL) {
        j288_bus_poll(s->bus, now_us);
    }
}

bool j288_sched_busy(const j288_sched_t *s)
{
    return (s != NULL) && s->sweeping;
}

int j288_sched_clear_watchdog(j288_sched_t *s, uint8_t id)
{
    if (s == NULL) {
        return J288_ERR_NULL;
    }
    if (id > J288_MAX_ID) {
        return J288_ERR_BAD_ID;
    }
    j288_bus_lock(s->bus);
    s->slot[id].clear_watchdog = true;
    j288_bus_unlock(s->bus);
    return J288_OK;
}

int j288_sched_estop(j288_sched_t *s, uint32_t now_us)
{
    uint8_t i;

    if (s == NULL) {
        return J288_ERR_NULL;
    }
    j288_bus_lock(s->bus);
    s->sweeping = false;
    s->stopped = true;
    for (i = 0u; i < J288_MAX_SERVOS; i++) {
        j288_cmd_lock(&s->slot[i].cmd, i, s->slot[i].cmd.watchdog);
    }
    s->frame_stale = ALL_SLOTS;
    j288_bus_unlock(s->bus);
    return j288_bus_estop(s->bus, now_us);
}

const j288_slot_t *j288_sched_slot(const j288_sched_t *s, uint8_t id)
{
    if ((s == NULL) || (id > J288_MAX_ID)) {
        return NULL;
    }
    return &s->slot[id];
}

uint32_t j288_sched_sweeps(const j288_sched_t *s)
{
    return (s == NULL) ? 0u : s->sweeps;
}
