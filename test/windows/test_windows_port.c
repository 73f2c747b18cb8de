/*
 * The Windows port against j288-sim through Wine's COM mapping (scripts/windows-test.sh
 * starts the simulators, points the prefix's dosdevices/comN at their pseudo-terminals and
 * runs this under wine):
 *
 *   test_windows_port.exe CLEAN SILENT ECHO VANISH TXLOG
 *     CLEAN   servos 1, 2, 3                    SILENT  servo 1 that never answers (--drop 1)
 *     ECHO    servo 1 behind an echoing line    VANISH  servo 1, stopped once it hears us
 *     TXLOG   a file: every command frame the byte-exact test sent, one hex line each (the
 *             script compares it with the simulator's log of what it received)
 *
 * Correctness and timeouts only (no timing thresholds: Wine's serial layer is not
 * Windows'). Exchanges that must succeed use a 250 ms margin; the byte-exact test retries an
 * exchange that is late even so (a starved Wine) and accounts for every reply byte. The rate
 * is 4,000,000: Wine leaves a pseudo-terminal at 38400 for anything faster (and says
 * success), which the port's read-back refuses (test_6mbps_refused_when_not_applied).
 */
#include "unity.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "j288/j288.h"
#include "j288_serial.h"
#include "serial_checks.h"
#include "serial_loop.h"

#define WINE_MAX_BAUD            4000000u
#define LOADED_MACHINE_MARGIN_US 250000u
#define EXACT_TRANSACTIONS       2000

static const char *g_clean, *g_silent, *g_echo, *g_vanish, *g_txlog;
static j288_serial_t g_sp;
static j288_bus_t g_bus;

void setUp(void)
{
    memset(&g_sp, 0, sizeof g_sp);
    g_sp.os.h = INVALID_HANDLE_VALUE;
}

void tearDown(void)
{
    j288_serial_close(&g_sp);
}

static void open_port(const char *com, uint32_t margin_us, bool echo)
{
    j288_serial_options_t o;
    int rc;
    memset(&o, 0, sizeof o);
    o.margin_us = margin_us;
    o.echo = echo;
    rc = j288_serial_open(&g_sp, com, WINE_MAX_BAUD, &o);
    TEST_ASSERT_EQUAL_INT_MESSAGE(J288_OK, rc, j288_serial_error(&g_sp));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_serial_bus_init(&g_sp, &g_bus, NULL));
}

static j288_cmd_raw_t lock_cmd(uint8_t id)
{
    j288_cmd_raw_t c;
    memset(&c, 0, sizeof c);
    c.id = id;
    c.status = J288_MODE_LOCK;
    c.watchdog = true;
    return c;
}

/* ---- pure helpers --------------------------------------------------------------------------- */

static void test_device_path(void)
{
    char out[16];
    TEST_ASSERT_TRUE(j288_windows_device_path("COM5", out, sizeof out));
    TEST_ASSERT_EQUAL_STRING("\\\\.\\COM5", out);
    TEST_ASSERT_TRUE(j288_windows_device_path("COM12", out, sizeof out));
    TEST_ASSERT_EQUAL_STRING("\\\\.\\COM12", out);
    TEST_ASSERT_TRUE(j288_windows_device_path("\\\\.\\COM7", out, sizeof out));
    TEST_ASSERT_EQUAL_STRING("\\\\.\\COM7", out);
    TEST_ASSERT_FALSE(j288_windows_device_path("COM123456789012", out, sizeof out));
    TEST_ASSERT_TRUE(j288_windows_same_device("COM5", "\\\\.\\com5"));
    TEST_ASSERT_TRUE(j288_windows_same_device("com12", "COM12"));
    TEST_ASSERT_FALSE(j288_windows_same_device("COM1", "COM12"));
    TEST_ASSERT_FALSE(j288_windows_same_device("COM1", NULL));
}

static void test_baud_read_back_tolerance(void)
{
    TEST_ASSERT_TRUE(j288_serial_baud_ok(6000000u, 6180000u)); /* +3 % exactly */
    TEST_ASSERT_FALSE(j288_serial_baud_ok(6000000u, 6180001u));
    TEST_ASSERT_TRUE(j288_serial_baud_ok(6000000u, 5820000u));
    TEST_ASSERT_FALSE(j288_serial_baud_ok(6000000u, 38400u)); /* Wine above 4 Mbps */
    TEST_ASSERT_FALSE(j288_serial_baud_ok(6000000u, 0u));
    TEST_ASSERT_FALSE(j288_serial_baud_ok(0u, 0u));
    TEST_ASSERT_FALSE(j288_serial_baud_ok(4294967295u, 1u));
}

static void test_clock_is_monotonic(void)
{
    uint32_t a = j288_serial_now_us(), b;
    Sleep(20);
    b = j288_serial_now_us();
    TEST_ASSERT_TRUE((int32_t)(b - a) >= 15000); /* Sleep(20) sleeps at least ~20 ms */
}

/* ---- open ------------------------------------------------------------------------------------ */

static void test_open_errors(void)
{
    char long_name[sizeof g_sp.dev + 1u];
    TEST_ASSERT_EQUAL_INT(J288_ERR_OFFLINE, j288_serial_open(&g_sp, "COM199", 0, NULL));
    TEST_ASSERT_NOT_NULL(strstr(j288_serial_error(&g_sp), "no such port"));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_serial_open(&g_sp, NULL, 0, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_serial_open(NULL, "COM1", 0, NULL));
    memset(long_name, 'C', sizeof long_name - 1u);
    long_name[sizeof long_name - 1u] = '\0';
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, j288_serial_open(&g_sp, long_name, 0, NULL));
    TEST_ASSERT_NOT_NULL(strstr(j288_serial_error(&g_sp), "too long"));
    /* A file is no serial port. */
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG,
                          j288_serial_open(&g_sp, "C:\\windows\\win.ini", 0, NULL));
    TEST_ASSERT_NOT_NULL(strstr(j288_serial_error(&g_sp), "not a serial port"));
    TEST_ASSERT_EQUAL_UINT32(0u, j288_serial_baud(&g_sp));
    j288_serial_close(&g_sp); /* harmless after a failure, and twice */
    j288_serial_close(&g_sp);
}

/* Under Wine a pty keeps 38400 for any rate above 4 Mbps while SetCommState says success: the
 * read-back turns that into a clear error instead of a bus that silently runs at 38400. */
static void test_6mbps_refused_when_not_applied(void)
{
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, j288_serial_open(&g_sp, g_clean, 0, NULL));
    TEST_ASSERT_NOT_NULL(strstr(j288_serial_error(&g_sp), "cannot do 6000000 baud"));
    open_port(g_clean, 0, false);
    TEST_ASSERT_EQUAL_UINT32(WINE_MAX_BAUD, j288_serial_baud(&g_sp));
    TEST_ASSERT_EQUAL_STRING(g_clean, j288_serial_device(&g_sp));
}

/* ---- transactions ------------------------------------------------------------------------- */

/* A late exchange: under Wine on a loaded machine the test thread (or wineserver, through
 * which every read and write goes) can be kept off the CPU for longer than any margin: then
 * the write alone outlasts the reply deadline, and the bus declares a timeout while the reply
 * waits, intact, in the driver's queue (seen in a CI-like run: 373 ms in start_tx, no wait,
 * every byte so far received). Such an exchange is retried, at most this many times, and
 * counted; the bytes of its late reply must all be accounted for (read, or dropped as stale
 * before the next transmit), so that "late" can never hide "lost". */
#define LATE_RETRIES_MAX 4

/* The port's operations, with the duration of the last start_tx (the overlapped write) kept
 * for the diagnostics of a late exchange. */
static j288_port_t g_timed_port;
static uint32_t g_last_tx_call_us;

static int timed_start_tx(void *ctx, const uint8_t *data, size_t len)
{
    uint32_t t0 = j288_serial_now_us();
    int rc = j288_serial_port.start_tx(ctx, data, len);
    g_last_tx_call_us = j288_serial_now_us() - t0;
    return rc;
}

static void time_the_writes(void)
{
    j288_bus_config_t cfg;
    g_timed_port = j288_serial_port;
    g_timed_port.start_tx = timed_start_tx;
    j288_serial_bus_config(&g_sp, &cfg);
    g_sp.bus = &g_bus; /* (as j288_serial_bus_init() sets it) */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_init(&g_bus, &g_timed_port, &g_sp, &cfg));
}

/* What tells a late reply from a lost one when an exchange fails. */
static void print_exchange_stats(int i, int rc, uint32_t took_us)
{
    const j288_serial_stats_t *ps = j288_serial_stats(&g_sp);
    const j288_bus_stats_t *bs = j288_bus_stats(&g_bus);
    printf("exchange %d: rc %d after %lu us (its write call %lu us); port: tx %lu rx %lu "
           "flushed %lu reads %lu empty %lu waits %lu; bus: ok %lu timeouts %lu crc %lu "
           "wrong_id %lu stale %lu\n",
           i, rc, (unsigned long)took_us, (unsigned long)g_last_tx_call_us,
           (unsigned long)ps->tx_bytes, (unsigned long)ps->rx_bytes,
           (unsigned long)ps->flushed_bytes, (unsigned long)ps->reads,
           (unsigned long)ps->empty_reads, (unsigned long)ps->waits, (unsigned long)bs->ok,
           (unsigned long)bs->timeouts, (unsigned long)bs->crc_errors, (unsigned long)bs->wrong_id,
           (unsigned long)bs->stale_bytes);
}

/* Every byte the simulator sent back (bytes_each per frame sent: a reply, and our echo on an
 * echoing line), read or dropped as stale: waits (bounded) for the late reply of a last
 * retried exchange, then checks that none is missing or extra. */
static void assert_every_byte_back_accounted(uint32_t frames, uint32_t bytes_each)
{
    const j288_serial_stats_t *ps = j288_serial_stats(&g_sp);
    int round;
    for (round = 0; round < 400 && ps->rx_bytes + ps->flushed_bytes < frames * bytes_each;
         round++)
        TEST_ASSERT_EQUAL_INT(J288_OK,
                              serial_loop_run(&g_sp, &g_bus, NULL, j288_serial_now_us() + 10000u, 0));
    TEST_ASSERT_EQUAL_UINT32(frames * bytes_each, ps->rx_bytes + ps->flushed_bytes);
}

static void assert_every_reply_byte_accounted(uint32_t replies)
{
    assert_every_byte_back_accounted(replies, J288_REPLY_LEN);
}

/* Many transactions with changing contents: every one answered by its servo (a late one
 * after retries, see LATE_RETRIES_MAX), every byte counted; every frame sent goes to TXLOG for
 * the script's byte-by-byte comparison with what the simulator received. */
static void test_transactions_byte_exact(void)
{
    FILE *log = fopen(g_txlog, "w");
    j288_txn_t txn;
    int i, rc, attempt;
    uint32_t sent = 0, late = 0, t0;
    size_t k;
    TEST_ASSERT_NOT_NULL(log);
    open_port(g_clean, LOADED_MACHINE_MARGIN_US, false);
    time_the_writes();
    for (i = 0; i < EXACT_TRANSACTIONS; i++) {
        j288_cmd_raw_t c = lock_cmd((uint8_t)(1 + i % 3));
        uint8_t frame[J288_CMD_LEN];
        c.status = J288_MODE_FOC;
        c.pos = (int32_t)(i * 7919) - 500000;
        c.kp = (uint16_t)(i & 0x7fff);
        c.kd = (uint16_t)(0x7fff - (i & 0x7fff));
        c.watchdog = false;
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_cmd_encode(&c, frame, NULL));
        rc = J288_ERR_TIMEOUT;
        for (attempt = 0; attempt <= LATE_RETRIES_MAX && rc == J288_ERR_TIMEOUT; attempt++) {
            for (k = 0; k < sizeof frame; k++)
                fprintf(log, "%02x", frame[k]);
            fputc('\n', log);
            sent++;
            memset(&txn, 0, sizeof txn);
            t0 = j288_serial_now_us();
            rc = j288_bus_transfer_blocking(&g_bus, &c, &txn);
            if (rc != J288_OK)
                print_exchange_stats(i, rc, j288_serial_now_us() - t0);
            if (rc == J288_ERR_TIMEOUT)
                late++;
        }
        TEST_ASSERT_EQUAL_INT(J288_OK, rc);
        TEST_ASSERT_EQUAL_UINT(c.id, txn.reply.id);
        TEST_ASSERT_EQUAL_UINT(J288_MODE_FOC, txn.reply.status);
    }
    fclose(log);
    if (late > 0u)
        printf("%lu late exchanges retried (a loaded machine)\n", (unsigned long)late);
    TEST_ASSERT_EQUAL_UINT32(sent, (uint32_t)EXACT_TRANSACTIONS + late);
    TEST_ASSERT_EQUAL_UINT32(late, j288_bus_stats(&g_bus)->timeouts);
    TEST_ASSERT_EQUAL_UINT32((uint32_t)EXACT_TRANSACTIONS, j288_bus_stats(&g_bus)->ok);
    TEST_ASSERT_EQUAL_UINT32(sent * J288_CMD_LEN, j288_serial_stats(&g_sp)->tx_bytes);
    assert_every_reply_byte_accounted(sent);
    /* Without a late exchange, every reply byte reached the bus and none was dropped. */
    if (late == 0u)
        TEST_ASSERT_EQUAL_UINT32(0u, j288_serial_stats(&g_sp)->flushed_bytes);
    /* A late reply may land in the next exchange's window (a good frame from another id): so
     * many at most, and never a corrupt or partial frame. */
    TEST_ASSERT_TRUE(j288_bus_stats(&g_bus)->wrong_id <= late);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_stats(&g_bus)->crc_errors);
}

/* A reply after its deadline on purpose (a margin and turnaround of 1 us, shorter than a Wine
 * round trip; bounded retries should one come in time): the exchange times out, and the late
 * reply's bytes still all show up, none lost or corrupt; the bus then goes on as usual. What
 * the byte-exact test relies on when a loaded machine makes an exchange late. */
static void test_late_reply_accounted(void)
{
    j288_bus_config_t cfg;
    j288_cmd_raw_t c = lock_cmd(2);
    j288_txn_t txn;
    uint32_t sent = 0;
    int rc = J288_OK;
    open_port(g_clean, LOADED_MACHINE_MARGIN_US, false);
    j288_serial_bus_config(&g_sp, &cfg);
    cfg.margin_us = 1u;
    cfg.turnaround_us = 1u;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_serial_bus_init(&g_sp, &g_bus, &cfg));
    while (rc == J288_OK && sent < 100u) {
        rc = j288_bus_transfer_blocking(&g_bus, &c, &txn);
        sent++;
    }
    TEST_ASSERT_EQUAL_INT(J288_ERR_TIMEOUT, rc);
    assert_every_reply_byte_accounted(sent);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_stats(&g_bus)->crc_errors);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_serial_bus_init(&g_sp, &g_bus, NULL));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_transfer_blocking(&g_bus, &c, &txn));
    TEST_ASSERT_EQUAL_UINT(2u, txn.reply.id);
    assert_every_reply_byte_accounted(sent + 1u);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_stats(&g_bus)->crc_errors);
}

static void test_scheduler_sweeps(void)
{
    j288_sched_t s;
    uint8_t id;
    int i;
    open_port(g_clean, LOADED_MACHINE_MARGIN_US, false);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_init(&s, &g_bus, NULL));
    for (id = 1; id <= 3; id++)
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_enable(&s, id, true));
    for (i = 0; i < 200; i++)
        TEST_ASSERT_EQUAL_INT(J288_OK, serial_loop_sweep(&g_sp, &g_bus, &s, 2000000u));
    TEST_ASSERT_EQUAL_UINT32(200, j288_sched_sweeps(&s));
    for (id = 1; id <= 3; id++) {
        const j288_slot_t *sl = j288_sched_slot(&s, id);
        TEST_ASSERT_TRUE(sl->online);
        TEST_ASSERT_EQUAL_UINT(id, sl->reply.id);
        TEST_ASSERT_TRUE(sl->stats.successes >= 190u);
    }
}

/* No reply: each transaction ends at its deadline with J288_ERR_TIMEOUT (the read in flight
 * meanwhile ends on its own timeout, ERROR_TIMEOUT under Wine), and nothing hangs. */
static void test_timeouts(void)
{
    j288_cmd_raw_t c = lock_cmd(1);
    j288_txn_t txn;
    int i;
    open_port(g_silent, 5000u, false);
    for (i = 0; i < 5; i++)
        TEST_ASSERT_EQUAL_INT(J288_ERR_TIMEOUT, j288_bus_transfer_blocking(&g_bus, &c, &txn));
    TEST_ASSERT_EQUAL_UINT32(5u, j288_bus_stats(&g_bus)->timeouts);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_serial_stats(&g_sp)->rx_bytes);
    /* An idle port: run() returns at its time, again and again, with the read in flight
     * (Windows ends it empty every J288_WINDOWS_READ_SLICE_MS; Wine 8 keeps it pending until
     * a byte comes: both are fine). */
    for (i = 0; i < 3; i++)
        TEST_ASSERT_EQUAL_INT(J288_OK,
                              serial_loop_run(&g_sp, &g_bus, NULL, j288_serial_now_us() + 250000u, 0));
    TEST_ASSERT_FALSE(j288_serial_offline(&g_sp));
    /* An id nobody answers on the clean bus: the same (the long margin: the exchange after it
     * must succeed on a loaded machine too). */
    j288_serial_close(&g_sp);
    open_port(g_clean, LOADED_MACHINE_MARGIN_US, false);
    c.id = 9;
    TEST_ASSERT_EQUAL_INT(J288_ERR_TIMEOUT, j288_bus_transfer_blocking(&g_bus, &c, &txn));
    c.id = 2;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_transfer_blocking(&g_bus, &c, &txn));
}

/* On a loaded machine the echo too can come back after the deadline, which the bus reports
 * as a collision ("our own frame never came back whole") when the exchange has lasted the
 * whole margin: such a late exchange is retried and counted, like a late reply in the
 * byte-exact test. A differing echo ends the exchange when it comes, within the margin, and
 * fails the test. */
static void test_echoing_adapter(void)
{
    j288_cmd_raw_t c = lock_cmd(1);
    j288_txn_t txn;
    int i, rc, attempt;
    uint32_t sent = 0, late = 0;
    open_port(g_echo, LOADED_MACHINE_MARGIN_US, true);
    time_the_writes();
    for (i = 0; i < 50; i++) {
        rc = J288_ERR_TIMEOUT;
        for (attempt = 0; attempt <= LATE_RETRIES_MAX && rc != J288_OK; attempt++) {
            memset(&txn, 0, sizeof txn);
            rc = j288_bus_transfer_blocking(&g_bus, &c, &txn);
            sent++;
            if (rc != J288_OK)
                print_exchange_stats(i, rc, txn.latency_us);
            if (!(rc == J288_ERR_TIMEOUT ||
                  (rc == J288_ERR_COLLISION && txn.latency_us >= LOADED_MACHINE_MARGIN_US)))
                break;
            late++;
        }
        TEST_ASSERT_EQUAL_INT(J288_OK, rc);
        TEST_ASSERT_EQUAL_UINT(1, txn.reply.id);
    }
    TEST_ASSERT_EQUAL_UINT32(late, j288_bus_stats(&g_bus)->collisions +
                                       j288_bus_stats(&g_bus)->timeouts);
    assert_every_byte_back_accounted(sent, J288_CMD_LEN + J288_REPLY_LEN);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_stats(&g_bus)->crc_errors);
}

/* Two ports, one j288_serial_wait_any() (WaitForMultipleObjects over their read events):
 * the way a host waits for several buses. Both transactions complete, woken by their replies. */
static void test_two_ports_one_wait(void)
{
    j288_serial_t other;
    j288_bus_t other_bus;
    j288_serial_options_t o;
    j288_cmd_raw_t c = lock_cmd(1);
    uint32_t t0;
    int rounds = 0;
    memset(&o, 0, sizeof o);
    o.echo = true;
    o.margin_us = LOADED_MACHINE_MARGIN_US;
    open_port(g_clean, LOADED_MACHINE_MARGIN_US, false);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_serial_open(&other, g_echo, WINE_MAX_BAUD, &o));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_serial_bus_init(&other, &other_bus, NULL));
    t0 = j288_serial_now_us();
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_submit(&g_bus, &c, t0, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_submit(&other_bus, &c, t0, NULL, NULL));
    j288_serial_t *ports[2];
    bool ready[2];
    unsigned woken = 0;
    ports[0] = &g_sp;
    ports[1] = &other;
    while (!(j288_bus_is_idle(&g_bus) && j288_bus_is_idle(&other_bus)) && rounds < 10000) {
        unsigned k, got = j288_serial_wait_any(ports, 2, 1000u, ready);
        for (k = 0; k < 2; k++) {
            if (ready[k]) {
                TEST_ASSERT_EQUAL_INT(J288_OK, j288_serial_service(ports[k]));
                woken++;
            }
        }
        TEST_ASSERT_TRUE(got <= 2u);
        /* (the bus's poll sees its reply deadline itself) */
        j288_bus_poll(&g_bus, j288_serial_now_us());
        j288_bus_poll(&other_bus, j288_serial_now_us());
        rounds++;
    }
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&g_bus)->ok);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&other_bus)->ok);
    TEST_ASSERT_TRUE(woken >= 2u); /* both replies woke the wait */
    /* A closed port is never ready, and the wait is then a bounded sleep. */
    j288_serial_close(&other);
    TEST_ASSERT_EQUAL_UINT(0u, j288_serial_wait_any(&ports[1], 1, 1000u, ready));
    TEST_ASSERT_FALSE(ready[0]);
    TEST_ASSERT_EQUAL_UINT(0u, j288_serial_wait_any(ports, 0, 1000u, ready));
}

/* The core's late-host rule under Windows (serial_checks.h): bytes that came while no read
 * was in flight are read at once, not by a read that Wine completes after the deadline. */
static void test_reply_waiting_when_the_host_wakes_late(void)
{
    open_port(g_clean, 20000u, false);
    serial_check_late_host_takes_waiting_reply(&g_sp, &g_bus);
}

/* The simulator goes away: the port says the device vanished, once, and then fails fast. */
static void test_vanished_device(void)
{
    j288_serial_t *ports[1];
    bool ready[1];
    j288_cmd_raw_t c = lock_cmd(1);
    j288_txn_t txn;
    int rc = J288_OK;
    int i;
    open_port(g_vanish, LOADED_MACHINE_MARGIN_US, false);
    /* The script stops the simulator once it has logged our first frame; bounded. */
    for (i = 0; i < 200000 && rc != J288_ERR_OFFLINE; i++)
        rc = j288_bus_transfer_blocking(&g_bus, &c, &txn);
    TEST_ASSERT_EQUAL_INT(J288_ERR_OFFLINE, rc);
    TEST_ASSERT_TRUE(j288_serial_offline(&g_sp));
    TEST_ASSERT_NOT_NULL(strstr(j288_serial_error(&g_sp), "vanished"));
    TEST_ASSERT_EQUAL_INT(J288_ERR_OFFLINE, j288_bus_transfer_blocking(&g_bus, &c, &txn));
    TEST_ASSERT_EQUAL_INT(J288_ERR_OFFLINE, j288_serial_port.wait(&g_sp, j288_serial_now_us()));
    /* A gone port is never ready (its read is not restarted). */
    ports[0] = &g_sp;
    TEST_ASSERT_EQUAL_UINT(0u, j288_serial_wait_any(ports, 1, 1000u, ready));
    TEST_ASSERT_FALSE(ready[0]);
}

int main(int argc, char **argv)
{
    if (argc != 6) {
        fprintf(stderr, "usage: %s CLEAN SILENT ECHO VANISH TXLOG (COM names, a file)\n", argv[0]);
        return 2;
    }
    g_clean = argv[1];
    g_silent = argv[2];
    g_echo = argv[3];
    g_vanish = argv[4];
    g_txlog = argv[5];
    UNITY_BEGIN();
    RUN_TEST(test_device_path);
    RUN_TEST(test_baud_read_back_tolerance);
    RUN_TEST(test_clock_is_monotonic);
    RUN_TEST(test_open_errors);
    RUN_TEST(test_6mbps_refused_when_not_applied);
    RUN_TEST(test_transactions_byte_exact);
    RUN_TEST(test_late_reply_accounted);
    RUN_TEST(test_scheduler_sweeps);
    RUN_TEST(test_timeouts);
    RUN_TEST(test_echoing_adapter);
    RUN_TEST(test_two_ports_one_wait);
    RUN_TEST(test_reply_waiting_when_the_host_wakes_late);
    RUN_TEST(test_vanished_device);
    return UNITY_END();
}
