/*
 * serial_loop.h - a bus loop over one desktop serial port, for the programs that exercise the
 * port below the host layer: the port tests (test/linux, test/windows), their benchmarks and
 * the soak (test/soak). Programs drive buses through host/j288_robot.h; the ports keep no
 * loop of their own.
 *
 * Thread only, one port; every wait is the port's own (j288_serial_port.wait): it sleeps
 * until bytes come or a deadline passes, never spins.
 */
#ifndef SERIAL_LOOP_H
#define SERIAL_LOOP_H

#include <stdint.h>

#include "j288/j288.h"
#include "j288_serial.h"

/* Return as soon as the bus (and the scheduler, when given) has nothing in progress. */
#define SERIAL_LOOP_UNTIL_IDLE 0x1u

/*
 * Drive bus, bound to sp, until until_us (a j288_serial_now_us() time, at most 35 minutes
 * ahead): poll the scheduler s (or, with s NULL, the bus), sleep in the port, repeat; while a
 * transaction is pending, wake at least every millisecond. Returns J288_OK at until_us (or,
 * with SERIAL_LOOP_UNTIL_IDLE, when idle), J288_ERR_TIMEOUT when UNTIL_IDLE was asked and
 * until_us came first, J288_ERR_OFFLINE when the device vanished (the bus and scheduler have
 * seen the line-gone event).
 */
int serial_loop_run(j288_serial_t *sp, j288_bus_t *bus, j288_sched_t *s, uint32_t until_us,
                    unsigned flags);

/* One scheduler sweep of s (on bus), start to end; timeout_us bounds the whole (0: 1 s).
 * J288_OK, j288_sched_start_sweep()'s error, or serial_loop_run()'s. */
int serial_loop_sweep(j288_serial_t *sp, j288_bus_t *bus, j288_sched_t *s, uint32_t timeout_us);

#endif /* SERIAL_LOOP_H */
