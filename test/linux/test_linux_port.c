/*
 * The Linux port against the simulator over a real pseudo-terminal: open at 6 Mbps
 * (termios2 BOTHER), blocking transfers and scheduler sweeps through the real engine,
 * exclusive access, a vanished device, EINTR storms, injected faults.
 *
 * Each test starts its own j288-sim (fork/exec, --exit-after as a backstop) and tearDown
 * always kills and reaps it. The simulator binary: $J288_SIM, else the path compiled in.
 *
 * No test depends on the machine's speed (CI is a loaded 2-core machine; make test-valgrind
 * runs this under valgrind): exchanges that must succeed use a 250 ms reply margin, waits
 * are bounded polls, and the checks count events, never time taken.
 */
#define _GNU_SOURCE 1

#include "unity.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/time.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "j288/j288.h"
#include "j288_serial.h"
#include "serial_checks.h"
#include "serial_loop.h"
#include "sim_process.h"


static pid_t g_sim = -1;
static char g_pty[128];
static char g_log[64];
static j288_serial_t g_sp;
static j288_bus_t g_bus;

/* ---- the simulator ---------------------------------------------------------------------- */

/* Start j288-sim with extra arguments (NULL-terminated) and read its pty path. */
static void sim_start(const char *arg0, ...)
{
    const char *args[SIM_PROCESS_MAX_ARGS + 1];
    int n = 0;
    va_list ap;
    const char *a;

    args[n++] = "--quiet";
    args[n++] = "--exit-after";
    args[n++] = "30";
    args[n++] = "--log";
    args[n++] = g_log;
    va_start(ap, arg0);
    for (a = arg0; a != NULL && n < SIM_PROCESS_MAX_ARGS; a = va_arg(ap, const char *))
        args[n++] = a;
    va_end(ap);
    args[n] = NULL;
    sim_process_start(args, &g_sim, g_pty, sizeof g_pty);
}

/* Stop it (SIGTERM, then SIGKILL after 20 s) and reap it. Returns its exit status. */
static int sim_stop(void)
{
    int status = sim_process_stop(g_sim);
    g_sim = -1;
    return status;
}

static bool log_contains(const char *needle) { return sim_log_contains(g_log, needle); }

void setUp(void)
{
    g_sim = -1;
    g_pty[0] = '\0';
    (void)snprintf(g_log, sizeof g_log, "/tmp/j288-port-test-%ld.log", (long)getpid());
    memset(&g_sp, 0, sizeof g_sp);
    g_sp.os.fd = -1;
}

void tearDown(void)
{
    j288_serial_close(&g_sp);
    if (g_sim > 0)
        (void)kill(g_sim, SIGCONT); /* a test that failed with it frozen */
    (void)sim_stop();
    (void)unlink(g_log);
}

/* Open the simulator's pty with a reply margin of margin_us. */
static void open_sim_port_margin(uint32_t margin_us)
{
    j288_serial_options_t opt;
    memset(&opt, 0, sizeof opt);
    opt.margin_us = margin_us;
    TEST_ASSERT_EQUAL_INT_MESSAGE(J288_OK, j288_serial_open(&g_sp, g_pty, 0, &opt),
                                  j288_serial_error(&g_sp));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_serial_bus_init(&g_sp, &g_bus, NULL));
}

/* A short margin (a pty answers in microseconds), for tests that wait out timeouts and
 * expect no reply that could arrive in time. */
static void open_sim_port(void) { open_sim_port_margin(10000u); }

/* Exchanges that must succeed use a margin far beyond any scheduling hiccup of a loaded CI
 * machine (or valgrind): a failure there then means a real fault, not a slow simulator.
 * (1 s: beside stress-ng --cpu 2 a simulator went unscheduled for 0.3-1.6 s at times.) */
#define LOADED_MACHINE_MARGIN_US 1000000u
static void open_sim_port_loaded(void) { open_sim_port_margin(LOADED_MACHINE_MARGIN_US); }

static j288_cmd_raw_t lock_cmd(uint8_t id)
{
    j288_cmd_raw_t c;
    memset(&c, 0, sizeof c);
    c.id = id;
    c.status = J288_MODE_LOCK;
    c.watchdog = true;
    return c;
}

/* ---- tests ---------------------------------------------------------------------------------- */

static void test_open_missing_device(void)
{
    TEST_ASSERT_EQUAL_INT(J288_ERR_OFFLINE, j288_serial_open(&g_sp, "/dev/j288-no-such", 0, NULL));
    TEST_ASSERT_NOT_NULL(strstr(j288_serial_error(&g_sp), "no such device"));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_serial_open(&g_sp, NULL, 0, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_serial_open(NULL, "/dev/null", 0, NULL));
}

/* The read-back check behind "the adapter cannot do N baud" (a pty takes any rate, so open()
 * cannot be made to fail it here): 3 % of the requested rate, boundary included. */
static void test_baud_read_back_tolerance(void)
{
    TEST_ASSERT_TRUE(j288_serial_baud_ok(6000000u, 6000000u));
    TEST_ASSERT_TRUE(j288_serial_baud_ok(6000000u, 6180000u));  /* +3 % exactly */
    TEST_ASSERT_FALSE(j288_serial_baud_ok(6000000u, 6180001u));
    TEST_ASSERT_TRUE(j288_serial_baud_ok(6000000u, 5820000u));  /* -3 % exactly */
    TEST_ASSERT_FALSE(j288_serial_baud_ok(6000000u, 5819999u));
    TEST_ASSERT_FALSE(j288_serial_baud_ok(6000000u, 3000000u)); /* a 3 Mbaud adapter */
    TEST_ASSERT_FALSE(j288_serial_baud_ok(6000000u, 0u));       /* driver reports nothing */
    TEST_ASSERT_FALSE(j288_serial_baud_ok(0u, 0u));
    TEST_ASSERT_FALSE(j288_serial_baud_ok(0u, 9600u));
    TEST_ASSERT_TRUE(j288_serial_baud_ok(100u, 103u));
    TEST_ASSERT_FALSE(j288_serial_baud_ok(100u, 104u));
    TEST_ASSERT_FALSE(j288_serial_baud_ok(100u, 96u));
    /* No 32-bit overflow near the top of the range. */
    TEST_ASSERT_TRUE(j288_serial_baud_ok(4000000000u, 4120000000u));
    TEST_ASSERT_FALSE(j288_serial_baud_ok(4000000000u, 4120000001u));
    TEST_ASSERT_FALSE(j288_serial_baud_ok(4000000000u, 4294967295u));
    TEST_ASSERT_FALSE(j288_serial_baud_ok(4294967295u, 1u));
}

static void test_open_not_a_tty(void)
{
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, j288_serial_open(&g_sp, "/dev/null", 0, NULL));
    TEST_ASSERT_NOT_NULL(strstr(j288_serial_error(&g_sp), "not a serial device"));
}

static void test_open_pty_at_6mbps(void)
{
    j288_bus_config_t cfg;
    sim_start(NULL);
    open_sim_port();
    TEST_ASSERT_EQUAL_UINT32(6000000u, j288_serial_baud(&g_sp));
    /* Pseudo-terminals refuse ASYNC_LOW_LATENCY: a notice, not an error. */
    TEST_ASSERT_NOT_NULL(strstr(j288_serial_notices(&g_sp), "low-latency"));
    TEST_ASSERT_FALSE(j288_serial_offline(&g_sp));
    j288_serial_bus_config(&g_sp, &cfg);
    TEST_ASSERT_EQUAL_UINT32(6000000u, cfg.baud);
    TEST_ASSERT_EQUAL_UINT32(10000u, cfg.margin_us);
    j288_serial_close(&g_sp);
    /* Another rate reads back as set. */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_serial_open(&g_sp, g_pty, 115200, NULL));
    TEST_ASSERT_EQUAL_UINT32(115200u, j288_serial_baud(&g_sp));
    j288_serial_bus_config(&g_sp, &cfg);
    TEST_ASSERT_EQUAL_UINT32(J288_SERIAL_DEFAULT_MARGIN_US, cfg.margin_us);
}

static void test_transfer_blocking(void)
{
    j288_cmd_raw_t c = lock_cmd(2);
    j288_txn_t txn;
    int i;
    sim_start("--ids", "1,2,3", NULL);
    open_sim_port_loaded();
    for (i = 0; i < 20; i++) {
        memset(&txn, 0, sizeof txn);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_transfer_blocking(&g_bus, &c, &txn));
        TEST_ASSERT_EQUAL_UINT(2, txn.reply.id);
        TEST_ASSERT_EQUAL_UINT(J288_MODE_LOCK, txn.reply.status);
        TEST_ASSERT_EQUAL_UINT(48, txn.reply.voltage_raw);
    }
    /* An id nobody answers to times out, bounded by the budget. */
    c.id = 9;
    TEST_ASSERT_EQUAL_INT(J288_ERR_TIMEOUT, j288_bus_transfer_blocking(&g_bus, &c, &txn));
    /* Broadcast: no reply expected, success. */
    c.id = J288_BROADCAST_ID;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_transfer_blocking(&g_bus, &c, NULL));
    c.id = 1;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_transfer_blocking(&g_bus, &c, &txn));
    TEST_ASSERT_EQUAL_UINT(1, txn.reply.id);
    TEST_ASSERT_EQUAL_UINT32(23u * 20u, j288_serial_stats(&g_sp)->tx_bytes);
    TEST_ASSERT_EQUAL_UINT32(21u * 26u, j288_serial_stats(&g_sp)->rx_bytes);
    TEST_ASSERT_EQUAL_INT(0, sim_stop());
    TEST_ASSERT_TRUE(log_contains(" id=15 status=0 wd=1"));
    TEST_ASSERT_TRUE(log_contains(" id=9 status=0"));
}

static void test_scheduler_sweeps(void)
{
    j288_sched_t s;
    uint8_t id;
    int i;
    uint32_t next;
    sim_start("--ids", "1,2,3", NULL);
    open_sim_port_margin(LOADED_MACHINE_MARGIN_US);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_init(&s, &g_bus, NULL));
    for (id = 1; id <= 3; id++)
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_enable(&s, id, true));
    next = j288_serial_now_us();
    /* A sweep started by hand, finished by run(UNTIL_IDLE). */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_start_sweep(&s, next));
    TEST_ASSERT_EQUAL_INT(J288_OK,
                          serial_loop_run(&g_sp, &g_bus, &s, next + 2000000u, SERIAL_LOOP_UNTIL_IDLE));
    for (i = 0; i < 200; i++) {
        TEST_ASSERT_EQUAL_INT(J288_OK, serial_loop_sweep(&g_sp, &g_bus, &s, 0));
        next += 1000u; /* 1 kHz ticks */
        TEST_ASSERT_EQUAL_INT(J288_OK, serial_loop_run(&g_sp, &g_bus, &s, next, 0));
    }
    TEST_ASSERT_EQUAL_UINT32(201, j288_sched_sweeps(&s));
    for (id = 1; id <= 3; id++) {
        const j288_slot_t *sl = j288_sched_slot(&s, id);
        TEST_ASSERT_TRUE(sl->online);
        TEST_ASSERT_TRUE(sl->has_reply);
        TEST_ASSERT_EQUAL_UINT(id, sl->reply.id);
        /* With the long margin only a real fault fails a sweep; keep slack for a frozen host. */
        TEST_ASSERT_TRUE(sl->stats.successes >= 191u);
    }
}

static void test_port_in_use_names_the_holder(void)
{
    int fds[2];
    pid_t child;
    char msg[J288_SERIAL_MSG_LEN + 16];
    char want[64];
    ssize_t n;
    int status;
    sim_start(NULL);
    open_sim_port_loaded();
    TEST_ASSERT_EQUAL_INT(0, pipe(fds));
    child = fork();
    TEST_ASSERT_TRUE(child >= 0);
    if (child == 0) {
        j288_serial_t other;
        int rc = j288_serial_open(&other, g_pty, 0, NULL);
        char out[J288_SERIAL_MSG_LEN + 16];
        int len = snprintf(out, sizeof out, "%d %s", rc, j288_serial_error(&other));
        (void)!write(fds[1], out, (size_t)len);
        _exit(0);
    }
    (void)close(fds[1]);
    n = read(fds[0], msg, sizeof msg - 1u);
    (void)close(fds[0]);
    (void)waitpid(child, &status, 0);
    TEST_ASSERT_TRUE(n > 0);
    msg[n] = '\0';
    (void)snprintf(want, sizeof want, "%d ", J288_ERR_BUSY);
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, strncmp(msg, want, strlen(want)), msg);
    (void)snprintf(want, sizeof want, "in use by PID %ld", (long)getpid());
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(msg, want), msg);
    /* Our own port still works, and after close another program may open it. */
    {
        j288_cmd_raw_t c = lock_cmd(1);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_transfer_blocking(&g_bus, &c, NULL));
    }
    j288_serial_close(&g_sp);
    open_sim_port();
}

static void test_vanished_device_between_transfers(void)
{
    j288_cmd_raw_t c = lock_cmd(1);
    sim_start(NULL);
    open_sim_port_loaded();
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_transfer_blocking(&g_bus, &c, NULL));
    TEST_ASSERT_EQUAL_INT(0, sim_stop()); /* closes the pty master */
    TEST_ASSERT_EQUAL_INT(J288_ERR_OFFLINE, j288_bus_transfer_blocking(&g_bus, &c, NULL));
    TEST_ASSERT_TRUE(j288_serial_offline(&g_sp));
    TEST_ASSERT_NOT_NULL(strstr(j288_serial_error(&g_sp), "vanished"));
    /* The bus heard it as a line-gone event. */
    TEST_ASSERT_TRUE(j288_bus_stats(&g_bus)->line_errors >= 1u);
    /* Stays offline, at once, without spinning. */
    TEST_ASSERT_EQUAL_INT(J288_ERR_OFFLINE, j288_bus_transfer_blocking(&g_bus, &c, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_OFFLINE,
                          serial_loop_run(&g_sp, &g_bus, NULL, j288_serial_now_us() + 1000000u, 0));
}

static void test_vanished_device_while_running(void)
{
    j288_cmd_raw_t c = lock_cmd(1);
    int rc = J288_OK, loops = 0;
    uint32_t waits_before;
    sim_start(NULL);
    open_sim_port_loaded();
    /* The simulator is told to leave after 20 transactions, in the middle of the loop (by
     * count, not by a clock: a slow machine must not run fewer than it needs). */
    while (rc == J288_OK && loops < 100000) {
        if (loops == 20)
            (void)kill(g_sim, SIGTERM); /* reaped in tearDown */
        rc = j288_bus_submit(&g_bus, &c, j288_serial_now_us(), NULL, NULL);
        TEST_ASSERT_EQUAL_INT(J288_OK, rc);
        rc = serial_loop_run(&g_sp, &g_bus, NULL, j288_serial_now_us() + 5000000u, SERIAL_LOOP_UNTIL_IDLE);
        if (rc == J288_OK) /* and sleep a little between transactions, like a control loop */
            rc = serial_loop_run(&g_sp, &g_bus, NULL, j288_serial_now_us() + 2000u, 0);
        loops++;
    }
    TEST_ASSERT_EQUAL_INT(J288_ERR_OFFLINE, rc);
    TEST_ASSERT_TRUE(loops > 20);
    TEST_ASSERT_NOT_NULL(strstr(j288_serial_error(&g_sp), "vanished"));
    /* A long run returns at once and does not loop on the dead descriptor. */
    waits_before = j288_serial_stats(&g_sp)->waits;
    TEST_ASSERT_EQUAL_INT(J288_ERR_OFFLINE,
                          serial_loop_run(&g_sp, &g_bus, NULL, j288_serial_now_us() + 5000000u, 0));
    TEST_ASSERT_TRUE(j288_serial_stats(&g_sp)->waits - waits_before <= 1u);
    /* The bus is not stuck: the next transaction ends at once, offline. */
    TEST_ASSERT_EQUAL_INT(J288_ERR_OFFLINE, j288_bus_transfer_blocking(&g_bus, &c, NULL));
}

static volatile sig_atomic_t g_alarms;

static void on_alarm(int sig)
{
    (void)sig;
    g_alarms++;
}

/* Alarms every 150 us, without SA_RESTART, for at least 300 transfers and until the storm
 * has interrupted the port's system calls at least MIN_EINTR times and delivered
 * MIN_ALARMS alarms (bounded by MAX_STORM_TRANSFERS): counted, not timed, so a fast machine
 * cannot finish before the storm hits. */
#define MIN_ALARMS 200u
#define MIN_EINTR 20u
#define MAX_STORM_TRANSFERS 50000

static void test_eintr_storm(void)
{
    struct sigaction sa, old;
    struct itimerval it, off;
    j288_cmd_raw_t c = lock_cmd(1);
    int i, ok = 0;
    sim_start(NULL);
    open_sim_port_margin(LOADED_MACHINE_MARGIN_US);
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_alarm;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = 0; /* no SA_RESTART: every blocking call sees EINTR */
    TEST_ASSERT_EQUAL_INT(0, sigaction(SIGALRM, &sa, &old));
    memset(&it, 0, sizeof it);
    it.it_interval.tv_usec = 150;
    it.it_value.tv_usec = 150;
    memset(&off, 0, sizeof off);
    g_alarms = 0;
    TEST_ASSERT_EQUAL_INT(0, setitimer(ITIMER_REAL, &it, NULL));
    for (i = 0; i < MAX_STORM_TRANSFERS &&
                (i < 300 || (uint32_t)g_alarms < MIN_ALARMS ||
                 j288_serial_stats(&g_sp)->eintr < MIN_EINTR);
         i++)
        if (j288_bus_transfer_blocking(&g_bus, &c, NULL) == J288_OK)
            ok++;
    (void)setitimer(ITIMER_REAL, &off, NULL);
    /* The counting handler stays: an alarm still in flight must not kill the runner. */
    (void)old;
    TEST_ASSERT_TRUE((uint32_t)g_alarms >= MIN_ALARMS);
    TEST_ASSERT_TRUE(j288_serial_stats(&g_sp)->eintr >= MIN_EINTR);
    /* With the 250 ms margin an interrupted transfer has no excuse to fail; a little slack
     * for a machine frozen for a quarter of a second. */
    TEST_ASSERT_TRUE(i >= 300);
    TEST_ASSERT_TRUE(ok >= i - 5);
}

static void test_injected_faults_give_bus_errors(void)
{
    j288_cmd_raw_t c = lock_cmd(1);
    int i, ok = 0, timeouts = 0, other = 0;
    sim_start("--drop", "0.3", "--seed", "7", NULL);
    open_sim_port_margin(50000u); /* a dropped reply costs the margin: 50 ms, yet no stall */
    for (i = 0; i < 40; i++) {
        int rc = j288_bus_transfer_blocking(&g_bus, &c, NULL);
        if (rc == J288_OK)
            ok++;
        else if (rc == J288_ERR_TIMEOUT)
            timeouts++;
        else
            other++;
    }
    TEST_ASSERT_TRUE(ok > 10 && timeouts > 3);
    TEST_ASSERT_EQUAL_INT(0, other);
    j288_serial_close(&g_sp);
    (void)sim_stop();

    sim_start("--corrupt", "1", NULL);
    open_sim_port_loaded(); /* read before the deadline, or it would be a time-out */
    TEST_ASSERT_EQUAL_INT(J288_ERR_CRC, j288_bus_transfer_blocking(&g_bus, &c, NULL));
    j288_serial_close(&g_sp);
    (void)sim_stop();

    sim_start("--noise", "1", NULL);
    open_sim_port_loaded();
    for (i = 0; i < 10; i++)
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_transfer_blocking(&g_bus, &c, NULL));
}

/* Whether process pid is stopped (state T in /proc/pid/stat). */
static bool process_stopped(pid_t pid)
{
    char path[64], line[256];
    const char *state;
    FILE *f;
    bool stopped = false;
    (void)snprintf(path, sizeof path, "/proc/%ld/stat", (long)pid);
    f = fopen(path, "r");
    if (f == NULL)
        return false;
    if (fgets(line, sizeof line, f) != NULL) {
        state = strrchr(line, ')'); /* the command name may hold spaces */
        stopped = (state != NULL) && (state[1] == ' ') && (state[2] == 'T');
    }
    (void)fclose(f);
    return stopped;
}

/* SIGSTOP to the simulator, returning once it is stopped (bounded: 30 s): from then on it
 * cannot answer, however long this host is held up. */
static void freeze_sim(void)
{
    const struct timespec ms = {0, 1000000L};
    int i;
    TEST_ASSERT_EQUAL_INT(0, kill(g_sim, SIGSTOP));
    for (i = 0; i < 30000 && !process_stopped(g_sim); i++)
        (void)nanosleep(&ms, NULL);
    TEST_ASSERT_TRUE_MESSAGE(process_stopped(g_sim), "the simulator did not stop");
}

static void thaw_sim(void)
{
    TEST_ASSERT_EQUAL_INT(0, kill(g_sim, SIGCONT));
}

/* The bytes the bus and the port have discarded as stale, once there are want of them or
 * 30 s have passed. */
static uint32_t wait_discarded(uint32_t want)
{
    uint32_t discarded = 0;
    int i;
    for (i = 0; i < 300 && discarded < want; i++) {
        (void)serial_loop_run(&g_sp, &g_bus, NULL, j288_serial_now_us() + 100000u, 0);
        discarded = j288_bus_stats(&g_bus)->stale_bytes + j288_serial_stats(&g_sp)->flushed_bytes;
    }
    return discarded;
}

static void test_late_replies_never_credited(void)
{
    j288_cmd_raw_t c = lock_cmd(1);
    uint32_t i;
    /* Every reply comes late: the simulator is stopped while a transfer waits (so no reply
     * can come before its deadline, however long this host is held up: a reply merely 300 ms
     * late is found in time by a host frozen that long before it reads, and then rightly
     * taken), and once resumed answers 300 ms after reading the command. Each must count as
     * stale (by the bus, or by the port before a transmit), never as a reply. */
    sim_start("--late", "1", "--late-us", "300000", NULL);
    open_sim_port();
    for (i = 1; i <= 6; i++) {
        freeze_sim();
        TEST_ASSERT_EQUAL_INT(J288_ERR_TIMEOUT, j288_bus_transfer_blocking(&g_bus, &c, NULL));
        thaw_sim();
        TEST_ASSERT_EQUAL_UINT32(i * J288_REPLY_LEN, wait_discarded(i * J288_REPLY_LEN));
    }
    TEST_ASSERT_EQUAL_UINT32(0, j288_bus_stats(&g_bus)->ok);
    /* One more transfer: the stale bytes do not answer it either. */
    freeze_sim();
    TEST_ASSERT_EQUAL_INT(J288_ERR_TIMEOUT, j288_bus_transfer_blocking(&g_bus, &c, NULL));
    thaw_sim();
    TEST_ASSERT_EQUAL_UINT32(0, j288_bus_stats(&g_bus)->ok);
}

/* The core's late-host rule on Linux (serial_checks.h). */
static void test_reply_waiting_when_the_host_wakes_late(void)
{
    sim_start("--ids", "1", NULL);
    open_sim_port();
    serial_check_late_host_takes_waiting_reply(&g_sp, &g_bus);
}

static void test_echoing_adapter(void)
{
    j288_serial_options_t opt;
    j288_cmd_raw_t c = lock_cmd(1);
    j288_txn_t txn;
    int i;
    sim_start("--echo", NULL);
    memset(&opt, 0, sizeof opt);
    opt.margin_us = LOADED_MACHINE_MARGIN_US;
    opt.echo = true;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_serial_open(&g_sp, g_pty, 0, &opt));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_serial_bus_init(&g_sp, &g_bus, NULL));
    TEST_ASSERT_TRUE(g_bus.cfg.echo);
    for (i = 0; i < 10; i++) {
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_transfer_blocking(&g_bus, &c, &txn));
        TEST_ASSERT_EQUAL_UINT(1, txn.reply.id);
    }
    TEST_ASSERT_EQUAL_UINT32(10u * (20u + 26u), j288_serial_stats(&g_sp)->rx_bytes);
    TEST_ASSERT_EQUAL_UINT32(0, j288_bus_stats(&g_bus)->collisions);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_open_missing_device);
    RUN_TEST(test_open_not_a_tty);
    RUN_TEST(test_baud_read_back_tolerance);
    RUN_TEST(test_open_pty_at_6mbps);
    RUN_TEST(test_transfer_blocking);
    RUN_TEST(test_scheduler_sweeps);
    RUN_TEST(test_port_in_use_names_the_holder);
    RUN_TEST(test_vanished_device_between_transfers);
    RUN_TEST(test_vanished_device_while_running);
    RUN_TEST(test_eintr_storm);
    RUN_TEST(test_injected_faults_give_bus_errors);
    RUN_TEST(test_late_replies_never_credited);
    RUN_TEST(test_echoing_adapter);
    RUN_TEST(test_reply_waiting_when_the_host_wakes_late);
    return UNITY_END();
}
