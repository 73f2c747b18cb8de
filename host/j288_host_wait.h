/*
 * j288_host_wait.h - the host layer's one OS-specific call: sleep until one of several ports
 * has input, or a timeout passes.
 *
 * The runner (j288_robot.c) drives every bus from one thread: it polls each bus, then sleeps
 * here over all of their devices at once, then lets each port that has input service itself
 * (j288_linux_service()). Everything else in the runner is plain C over the port's accessors,
 * so another OS needs only its own port and this one function (Windows:
 * host/j288_host_wait_win32.c, one WaitForMultipleObjects over the ports' read events). On
 * Windows j288_linux_t names the Windows port (j288_host_port.h).
 *
 * Thread only; not signal-safe. A signal ends the sleep early (the caller looks at its flags).
 */
#ifndef J288_HOST_WAIT_H
#define J288_HOST_WAIT_H

#include <stdbool.h>
#include <stdint.h>

#include "j288_host_port.h"

/* Sleep until one of ports[0..n-1] (open, not gone) has bytes to read or a hang-up to report,
 * or timeout_us has passed, or a signal came. ready[i] is set for each port with something to
 * service, cleared for the others. Returns how many are ready (0: timeout or signal). n may be
 * 0 (a plain bounded sleep). At most J288_HOST_WAIT_MAX ports. */
#define J288_HOST_WAIT_MAX 16u
unsigned j288_host_wait(j288_linux_t *const ports[], unsigned n, uint32_t timeout_us,
                        bool ready[]);

#endif /* J288_HOST_WAIT_H */
