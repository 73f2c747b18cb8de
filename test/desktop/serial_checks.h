/*
 * serial_checks.h - checks of the desktop serial core that every OS's port test runs the same
 * way (test/linux/test_linux_port.c, test/windows/test_windows_port.c), against its own
 * simulator. Unity assertions: call from inside a test.
 */
#ifndef SERIAL_CHECKS_H
#define SERIAL_CHECKS_H

#include "j288/j288.h"
#include "j288_serial.h"

/*
 * A host that wakes past the reply deadline (a loaded machine) with the reply already waiting
 * in the OS: servo 1 (answering on the device sp has open, bus bound to it) is sent a lock and
 * the host "sleeps" until the whole reply is queued and the deadline has passed (each bounded:
 * 30 s); then one j288_serial_service() and a poll. The reply must be taken, on the first
 * attempt, with no timeout and no stale byte: the core hands waiting bytes to the bus before it
 * judges a due deadline (before 4dff84e the deadline came first: a timeout, a retry, and the
 * reply that came in time counted as stale bytes).
 */
void serial_check_late_host_takes_waiting_reply(j288_serial_t *sp, j288_bus_t *bus);

#endif /* SERIAL_CHECKS_H */
