/* service.c - see service.h. */
#include "service.h"

#include <stdio.h>

#ifndef J288_DDS_SYSTEMD
#define J288_DDS_SYSTEMD 0
#endif

#if J288_DDS_SYSTEMD
#include <systemd/sd-daemon.h>

static uint64_t watchdog_us, last_ping_us;

bool service_available(void)
{
    return true;
}

uint64_t service_start(void)
{
    uint64_t us = 0;
    /* > 0 only when WATCHDOG_USEC is set and WATCHDOG_PID (if set) is this process */
    if (sd_watchdog_enabled(0, &us) > 0)
        watchdog_us = us;
    return watchdog_us;
}

void service_ready(const char *status)
{
    (void)sd_notifyf(0, "READY=1\nSTATUS=%s", status);
}

void service_tick(uint64_t now_us, void (*status)(void *ctx, char *buf, unsigned cap), void *ctx)
{
    char buf[200];
    if (watchdog_us == 0u)
        return;
    if (last_ping_us == 0u) /* the first cycle: READY=1 was the sign of life until now */
        last_ping_us = now_us;
    if (now_us - last_ping_us < watchdog_us / 2u)
        return;
    last_ping_us = now_us;
    status(ctx, buf, (unsigned)sizeof buf);
    (void)sd_notifyf(0, "WATCHDOG=1\nSTATUS=%s", buf);
}

void service_stopping(const char *why)
{
    (void)sd_notifyf(0, "STOPPING=1\nSTATUS=%s", why);
}
#else
bool service_available(void)
{
    return false;
}

uint64_t service_start(void)
{
    return 0;
}

void service_ready(const char *status)
{
    (void)status;
}

void service_tick(uint64_t now_us, void (*status)(void *ctx, char *buf, unsigned cap), void *ctx)
{
    (void)now_us;
    (void)status;
    (void)ctx;
}

void service_stopping(const char *why)
{
    (void)why;
}
#endif
