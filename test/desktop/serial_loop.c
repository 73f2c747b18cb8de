/* serial_loop.c - a bus loop over one desktop serial port (see serial_loop.h). */
#include "serial_loop.h"

/* While a transaction is pending, wake at least this often to let the bus check its reply
 * deadline even if the engine arms no timer. */
#define PENDING_SLICE_US 1000u

static void poll_once(j288_bus_t *bus, j288_sched_t *s, uint32_t now)
{
    if (s != NULL)
        j288_sched_poll(s, now);
    else
        j288_bus_poll(bus, now);
}

int serial_loop_run(j288_serial_t *sp, j288_bus_t *bus, j288_sched_t *s, uint32_t until_us,
                    unsigned flags)
{
    bool until_idle = (flags & SERIAL_LOOP_UNTIL_IDLE) != 0u;
    for (;;) {
        uint32_t now = j288_serial_now_us();
        int32_t left = (int32_t)(until_us - now);
        bool pending;
        poll_once(bus, s, now);
        if (j288_serial_offline(sp))
            return J288_ERR_OFFLINE;
        pending = j288_sched_busy(s) || !j288_bus_is_idle(bus);
        if (until_idle && !pending)
            return J288_OK;
        if (left <= 0)
            return until_idle ? J288_ERR_TIMEOUT : J288_OK;
        if (pending && left > (int32_t)PENDING_SLICE_US)
            left = (int32_t)PENDING_SLICE_US;
        if (j288_serial_port.wait(sp, now + (uint32_t)left) == J288_ERR_OFFLINE) {
            /* Let the bus and scheduler see the line-gone event before returning. */
            poll_once(bus, s, j288_serial_now_us());
            return J288_ERR_OFFLINE;
        }
    }
}

int serial_loop_sweep(j288_serial_t *sp, j288_bus_t *bus, j288_sched_t *s, uint32_t timeout_us)
{
    uint32_t now;
    int rc;
    if (j288_serial_offline(sp))
        return J288_ERR_OFFLINE;
    now = j288_serial_now_us();
    rc = j288_sched_start_sweep(s, now);
    if (rc != J288_OK)
        return rc;
    return serial_loop_run(sp, bus, s, now + (timeout_us != 0u ? timeout_us : 1000000u),
                           SERIAL_LOOP_UNTIL_IDLE);
}
