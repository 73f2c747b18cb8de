/*
 * service.h - j288-dds as a systemd service (debian/j288-dds@.service, docs/dds.md "Running on
 * a robot"), through libsystemd's sd_notify(): READY=1 once the robot and DDS are up,
 * WATCHDOG=1 from the loop at half the period systemd asks for (WatchdogSec=, given in
 * WATCHDOG_USEC), so that a loop that stops cycling stops the pings and systemd restarts the
 * bridge; a STATUS= line with each ping; STOPPING=1 at exit. Outside systemd (no
 * NOTIFY_SOCKET) nothing is sent. Built without libsystemd (J288_DDS_SYSTEMD 0: mk/dds.mk says
 * so), every call does nothing and service_available() is false.
 * Called from the loop's thread only.
 */
#ifndef J288_DDS_SERVICE_H
#define J288_DDS_SERVICE_H

#include <stdbool.h>
#include <stdint.h>

/* Whether this build can talk to systemd. */
bool service_available(void);

/* The watchdog period systemd gave this process (us), 0 when none. Read once, before
 * anything else here. */
uint64_t service_start(void);

/* The service is up: READY=1 and the status line. */
void service_ready(const char *status);

/* Once a cycle, with the monotonic time (us): when half the watchdog period has passed since
 * the previous ping, WATCHDOG=1 and the status line status() writes into buf. */
void service_tick(uint64_t now_us, void (*status)(void *ctx, char *buf, unsigned cap), void *ctx);

/* The bridge is stopping: STOPPING=1 and the reason. */
void service_stopping(const char *why);

#endif
