/* serial_checks.c - checks every OS's port test runs (see serial_checks.h). */
#ifndef _WIN32
#define _GNU_SOURCE 1 /* nanosleep, FIONREAD */
#endif

#include "serial_checks.h"

#include <string.h>

#include "unity.h"

#ifdef _WIN32
static void sleep_1ms(void)
{
    Sleep(1);
}

/* A whole reply in the driver's queue (no read is in flight before the port first waits). */
static bool reply_queued(const j288_serial_t *sp)
{
    COMSTAT st;
    DWORD errs;
    memset(&st, 0, sizeof st);
    return ClearCommError(sp->os.h, &errs, &st) && st.cbInQue >= J288_REPLY_LEN;
}
#else
#include <sys/ioctl.h>
#include <time.h>

static void sleep_1ms(void)
{
    const struct timespec ms = {0, 1000000L};
    (void)nanosleep(&ms, NULL);
}

static bool reply_queued(const j288_serial_t *sp)
{
    int n = 0;
    return ioctl(sp->os.fd, FIONREAD, &n) == 0 && n >= (int)J288_REPLY_LEN;
}
#endif

static j288_txn_t g_done_txn;
static bool g_done;

static void on_done(void *user, const j288_txn_t *txn)
{
    (void)user;
    g_done_txn = *txn;
    g_done = true;
}

void serial_check_late_host_takes_waiting_reply(j288_serial_t *sp, j288_bus_t *bus)
{
    j288_cmd_raw_t c;
    uint32_t at;
    int i;
    memset(&c, 0, sizeof c);
    c.id = 1;
    c.status = J288_MODE_LOCK;
    c.watchdog = true;
    g_done = false;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_submit(bus, &c, j288_serial_now_us(), on_done, NULL));
    for (i = 0; i < 30000 && !reply_queued(sp); i++)
        sleep_1ms();
    TEST_ASSERT_TRUE_MESSAGE(reply_queued(sp), "no reply from the simulator");
    TEST_ASSERT_TRUE(j288_serial_next_deadline(sp, &at));
    for (i = 0; i < 30000 && (int32_t)(j288_serial_now_us() - at) <= 0; i++)
        sleep_1ms();
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_serial_service(sp));
    j288_bus_poll(bus, j288_serial_now_us());
    TEST_ASSERT_TRUE(g_done);
    TEST_ASSERT_EQUAL_INT(J288_OK, g_done_txn.result);
    TEST_ASSERT_EQUAL_UINT(1, g_done_txn.attempts);
    TEST_ASSERT_EQUAL_UINT(1, g_done_txn.reply.id);
    TEST_ASSERT_EQUAL_UINT32(0, j288_bus_stats(bus)->timeouts);
    TEST_ASSERT_EQUAL_UINT32(0, j288_bus_stats(bus)->stale_bytes);
}
