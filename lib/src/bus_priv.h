/*
 * bus_priv.h - what bus.c gives the other modules of lib/ (not installed, not API): the bus's
 * thread-side lock, and a transaction begun on a frame kept elsewhere (the scheduler's slot
 * frames), queued or started as the bus's state says. The scheduler asks the bus through
 * these; it reads none of j288_bus_t's fields.
 */
#ifndef J288_BUS_PRIV_H
#define J288_BUS_PRIV_H

#include <stdbool.h>
#include <stdint.h>

#include "hints.h"
#include "j288/bus.h"

/* The bus's thread-side lock (bus.h: with advance_in_isr, thread calls are wrapped in the
 * port's lock/unlock; from inside an advance the lock is already held or not needed). */
static inline bool j288_bus_needs_lock(const j288_bus_t *bus)
{
    return bus->cfg.advance_in_isr && !bus->in_advance && (bus->port->lock != NULL);
}

/* The port's lock (unlock) when locked: j288_bus_needs_lock() as the caller found it once,
 * for a section in which nothing changes the answer. */
static J288_INLINE_HOT void j288_bus_port_lock(const j288_bus_t *bus, bool locked)
{
    if (locked) {
        bus->port->lock(bus->port_ctx);
    }
}

static J288_INLINE_HOT void j288_bus_port_unlock(const j288_bus_t *bus, bool locked)
{
    if (locked) {
        bus->port->unlock(bus->port_ctx);
    }
}

static inline void j288_bus_lock(const j288_bus_t *bus)
{
    if (j288_bus_needs_lock(bus)) {
        bus->port->lock(bus->port_ctx);
    }
}

static inline void j288_bus_unlock(const j288_bus_t *bus)
{
    if (j288_bus_needs_lock(bus)) {
        bus->port->unlock(bus->port_ctx);
    }
}

/* j288_bus_t.flags: what waits for the machine, one bit each, written only by the context
 * that advances it (never by the event calls). */
#define J288_BUSF_QUEUED 0x01u        /* an accepted submit waits for the guard to end */
#define J288_BUSF_RETRY 0x02u         /* the failed attempt is re-sent when the guard ends */
#define J288_BUSF_ESTOP_PENDING 0x04u /* a stop was requested and is not on the wire yet */
#define J288_BUSF_ESTOP_ACTIVE 0x08u  /* the frame in flight (or to be re-sent) is the stop */
#define J288_BUSF_ESTOP_REARM 0x10u   /* an estop was requested while the stop was active */
/* Any of these refuses a submit. */
#define J288_BUSF_REFUSE                                                                       \
    (J288_BUSF_QUEUED | J288_BUSF_RETRY | J288_BUSF_ESTOP_PENDING | J288_BUSF_ESTOP_ACTIVE)

/* Whether the bus accepts a new transaction now (j288_bus_submit()'s J288_ERR_BUSY test:
 * idle or in the guard, nothing queued, no retry or estop pending). Call it, and
 * j288_bus_accept_frame() after it, under one j288_bus_lock(). */
static inline bool j288_bus_accepts(const j288_bus_t *bus)
{
    uint8_t st = bus->state;
    return ((bus->flags & J288_BUSF_REFUSE) == 0u) &&
           ((st == (uint8_t)J288_BUS_IDLE) || (st == (uint8_t)J288_BUS_GUARD));
}

/* A new transaction record, in the slot the previous callback is not looking at. Only what a
 * callback may read is set here (no clearing of the whole record), and only what the end of
 * the transaction does not set (result, start and latency: start_attempt() and finish()); the
 * reply is cleared by finish() when none is taken. */
static J288_INLINE_HOT void j288_bus_begin_txn(j288_bus_t *bus, uint8_t id,
                                               j288_bus_done_fn done, void *user)
{
    j288_txn_t *t;
    unsigned i;

    bus->cur ^= 1u;
    t = &bus->txn[bus->cur];
    t->id = id;
    t->attempts = 0u;
    /* Element by element: a few stores, where some targets' compilers (RV32) would call
     * memset for these 16 bytes. */
    for (i = 0u; i < (J288_CONFIG_MAX_RETRIES + 1u); i++) {
        t->attempt_result[i] = J288_OK;
    }
    bus->tx_id = id;
    bus->done = done;
    bus->done_user = user;
}

/* j288_bus_accept_frame() from inside an advance (a completion callback), where it only
 * queues: the guard's timer, or the next poll, starts the transmit. */
static J288_INLINE_HOT void j288_bus_queue_frame(j288_bus_t *bus, const uint8_t *frame,
                                                 uint8_t id, j288_bus_done_fn done, void *user)
{
    bus->tx_frame = frame;
    j288_bus_begin_txn(bus, id, done, user);
    bus->stats.transactions++;
    bus->flags = (uint8_t)(bus->flags | J288_BUSF_QUEUED);
}

/* The transaction of frame (J288_CMD_LEN bytes, addressed to id, CRC in place) begins, once
 * j288_bus_accepts() said yes under the same lock; the frame is sent from where it is, for
 * every attempt and the echo check, and must stay untouched until the completion call. */
void j288_bus_accept_frame(j288_bus_t *bus, const uint8_t *frame, uint8_t id, uint32_t now_us,
                           j288_bus_done_fn done, void *user);

/* The transaction of a frame kept by the caller (the scheduler's slot frames) begins, once
 * j288_bus_accepts() said yes under the same lock: queued from inside an advance (a
 * completion callback), else started now. The bus decides which from its own state. */
static J288_INLINE_HOT void j288_bus_take_frame(j288_bus_t *bus, const uint8_t *frame, uint8_t id,
                                                uint32_t now_us, j288_bus_done_fn done,
                                                void *user)
{
    if (bus->in_advance) {
        j288_bus_queue_frame(bus, frame, id, done, user);
    } else {
        j288_bus_accept_frame(bus, frame, id, now_us, done, user);
    }
}

/* The CRC engine the bus builds and checks its frames with (for j288_cmd_pack()). */
static inline const j288_crc_t *j288_bus_crc(const j288_bus_t *bus)
{
    return &bus->crc;
}

#endif /* J288_BUS_PRIV_H */
