/*
 * The real-time module (host/j288_rt.h) on its own: the histogram and its percentiles, the
 * pacing rule on a made-up clock (deadlines kept, a miss started at once, whole periods
 * skipped, never a burst), the report and its text, and the set-up through its seam: the
 * refusals (EPERM, ENOMEM) explained with the fix and the loop going on, a CPU outside the
 * allowed set refused before anything changes, and j288_rt_restore() undoing exactly what was
 * done. No check depends on the machine's speed.
 */
#define _GNU_SOURCE 1

#include "unity.h"

#include <errno.h>
#include <grp.h>
#include <sched.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "j288/error.h"
#include "j288_rt.h"

void setUp(void) {}
void tearDown(void) {}

/* ---- the histogram ---------------------------------------------------------------------------- */

static j288_rt_hist_t g_h;

static void test_small_values_are_exact(void)
{
    uint32_t v;
    memset(&g_h, 0, sizeof g_h);
    for (v = 0; v < 64u; v++)
        j288_rt_hist_add(&g_h, v);
    TEST_ASSERT_EQUAL_UINT32(64, g_h.n);
    TEST_ASSERT_EQUAL_UINT32(63, g_h.max);
    TEST_ASSERT_EQUAL_UINT32(31, j288_rt_hist_quantile(&g_h, 500000u)); /* rank 32: value 31 */
    TEST_ASSERT_EQUAL_UINT32(63, j288_rt_hist_quantile(&g_h, 990000u)); /* rank 64 (63.36 up) */
    TEST_ASSERT_EQUAL_UINT32(0, j288_rt_hist_quantile(&g_h, 1u));
}

static void test_large_values_within_a_thirty_second(void)
{
    static const uint32_t values[] = {64u, 100u, 1000u, 1999u, 65535u, 1000000u, 4000000000u};
    unsigned i;
    for (i = 0; i < sizeof values / sizeof values[0]; i++) {
        uint32_t got;
        memset(&g_h, 0, sizeof g_h);
        j288_rt_hist_add(&g_h, values[i]);
        j288_rt_hist_add(&g_h, UINT32_MAX); /* max far above: the bucket's top shows */
        got = j288_rt_hist_quantile(&g_h, 500000u);
        TEST_ASSERT_TRUE_MESSAGE(got >= values[i], "a quantile below its value");
        TEST_ASSERT_TRUE_MESSAGE((uint64_t)got * 32u <= (uint64_t)values[i] * 33u,
                                 "a bucket wider than 1/32 of its value");
    }
}

static void test_quantiles_are_capped_by_the_max_and_ordered(void)
{
    uint32_t i;
    memset(&g_h, 0, sizeof g_h);
    for (i = 0; i < 1000u; i++)
        j288_rt_hist_add(&g_h, 100u);
    j288_rt_hist_add(&g_h, 5000u);
    /* 100 lies in the bucket 100-101: its top, under the max */
    TEST_ASSERT_EQUAL_UINT32(101, j288_rt_hist_quantile(&g_h, 500000u));
    TEST_ASSERT_EQUAL_UINT32(5000, j288_rt_hist_quantile(&g_h, 1000000u));
    TEST_ASSERT_TRUE(j288_rt_hist_quantile(&g_h, 999000u) <= 5000u);
    memset(&g_h, 0, sizeof g_h);
    TEST_ASSERT_EQUAL_UINT32(0, j288_rt_hist_quantile(&g_h, 990000u));
}

/* ---- pacing ------------------------------------------------------------------------------------ */

static j288_rt_timing_t g_t;
static j288_rt_pacer_t g_p;

#define MS 1000000ull /* ns */

static void pacing_reset(void)
{
    memset(&g_t, 0, sizeof g_t);
    memset(&g_p, 0, sizeof g_p);
}

static void test_pacing_keeps_absolute_deadlines(void)
{
    uint64_t until = 0;
    pacing_reset();
    /* the schedule's first cycle: at once, due at 100 ms */
    TEST_ASSERT_FALSE(j288_rt_pace_begin(&g_p, &g_t, MS, 100 * MS, &until));
    j288_rt_pace_woke(&g_p, &g_t, 100 * MS, false);
    /* a cycle of 0.3 ms: sleep to 101 ms; woken 20 us late */
    TEST_ASSERT_TRUE(j288_rt_pace_begin(&g_p, &g_t, MS, 100 * MS + 300000u, &until));
    TEST_ASSERT_EQUAL_UINT64(101 * MS, until);
    j288_rt_pace_woke(&g_p, &g_t, 101 * MS + 20000u, true);
    /* the next deadline does not move with that lateness: 102 ms */
    TEST_ASSERT_TRUE(j288_rt_pace_begin(&g_p, &g_t, MS, 101 * MS + 500000u, &until));
    TEST_ASSERT_EQUAL_UINT64(102 * MS, until);
    j288_rt_pace_woke(&g_p, &g_t, 102 * MS, true);
    TEST_ASSERT_EQUAL_UINT32(2, g_t.lateness.n);
    TEST_ASSERT_EQUAL_UINT32(20, g_t.lateness.max);
    TEST_ASSERT_EQUAL_UINT32(2, g_t.duration.n);
    TEST_ASSERT_EQUAL_UINT32(480, g_t.duration.max); /* 101.02 -> 101.5 ms */
    TEST_ASSERT_EQUAL_UINT32(0, g_t.missed);
    TEST_ASSERT_EQUAL_UINT32(1000, g_t.period_us);
}

static void test_a_missed_deadline_starts_at_once_and_skips_whole_periods(void)
{
    uint64_t until = 0;
    pacing_reset();
    (void)j288_rt_pace_begin(&g_p, &g_t, MS, 0, &until);
    j288_rt_pace_woke(&g_p, &g_t, 0, false);
    /* the cycle ran to 1.4 ms: deadline 1 ms missed, the next cycle starts at once */
    TEST_ASSERT_FALSE(j288_rt_pace_begin(&g_p, &g_t, MS, 1400000u, &until));
    j288_rt_pace_woke(&g_p, &g_t, 1400000u, false);
    TEST_ASSERT_EQUAL_UINT32(1, g_t.missed);
    TEST_ASSERT_EQUAL_UINT32(0, g_t.skipped);
    /* the grid holds: the next is due at 2 ms */
    TEST_ASSERT_TRUE(j288_rt_pace_begin(&g_p, &g_t, MS, 1500000u, &until));
    TEST_ASSERT_EQUAL_UINT64(2 * MS, until);
    j288_rt_pace_woke(&g_p, &g_t, 2 * MS, true);
    /* a stall to 5.2 ms: due 3 ms missed, 3 and 4 ms periods skipped, due 5 ms now; no burst */
    TEST_ASSERT_FALSE(j288_rt_pace_begin(&g_p, &g_t, MS, 5200000u, &until));
    j288_rt_pace_woke(&g_p, &g_t, 5200000u, false);
    TEST_ASSERT_EQUAL_UINT32(2, g_t.missed);
    TEST_ASSERT_EQUAL_UINT32(2, g_t.skipped);
    TEST_ASSERT_TRUE(j288_rt_pace_begin(&g_p, &g_t, MS, 5300000u, &until));
    TEST_ASSERT_EQUAL_UINT64(6 * MS, until);
    /* a miss is not a wake-up: lateness counts the sleeps only */
    TEST_ASSERT_EQUAL_UINT32(1, g_t.lateness.n);
    TEST_ASSERT_EQUAL_UINT32(g_t.duration.n, g_t.lateness.n + g_t.missed + 1u);
}

static void test_a_new_period_or_a_restart_starts_a_new_schedule(void)
{
    uint64_t until = 0, due = 0;
    pacing_reset();
    (void)j288_rt_pace_begin(&g_p, &g_t, MS, 0, &until);
    j288_rt_pace_woke(&g_p, &g_t, 0, false);
    TEST_ASSERT_TRUE(j288_rt_pace_next_due(&g_p, MS, &due));
    TEST_ASSERT_EQUAL_UINT64(MS, due);
    TEST_ASSERT_FALSE(j288_rt_pace_next_due(&g_p, 2 * MS, &due));
    /* a pause of a second, then the same period after a restart: no miss counted */
    j288_rt_pace_restart(&g_p);
    TEST_ASSERT_FALSE(j288_rt_pace_begin(&g_p, &g_t, MS, 1000 * MS, &until));
    j288_rt_pace_woke(&g_p, &g_t, 1000 * MS, false);
    TEST_ASSERT_EQUAL_UINT32(0, g_t.missed);
    /* another period: a new schedule from now */
    TEST_ASSERT_FALSE(j288_rt_pace_begin(&g_p, &g_t, 2 * MS, 1000 * MS + 100u, &until));
    j288_rt_pace_woke(&g_p, &g_t, 1000 * MS + 100u, false);
    TEST_ASSERT_TRUE(j288_rt_pace_begin(&g_p, &g_t, 2 * MS, 1000 * MS + 200u, &until));
    TEST_ASSERT_EQUAL_UINT64(1002 * MS + 100u, until);
    /* back to back: never a sleep, never a miss, durations only */
    TEST_ASSERT_FALSE(j288_rt_pace_begin(&g_p, &g_t, 0, 1003 * MS, &until));
    TEST_ASSERT_FALSE(j288_rt_pace_begin(&g_p, &g_t, 0, 1004 * MS, &until));
    TEST_ASSERT_EQUAL_UINT32(0, g_t.missed);
    TEST_ASSERT_EQUAL_UINT32(0, g_t.period_us);
}

static void test_report_and_its_text(void)
{
    j288_rt_status_t st;
    j288_rt_report_t rep;
    char text[512];
    uint32_t i;
    pacing_reset();
    for (i = 0; i < 1000u; i++) {
        j288_rt_hist_add(&g_t.lateness, i < 999u ? 50u : 3000u);
        j288_rt_hist_add(&g_t.duration, 400u);
    }
    g_t.missed = 3;
    g_t.skipped = 2;
    g_t.cut = 1;
    g_t.period_us = 2000;
    memset(&st, 0, sizeof st);
    st.priority = 80;
    st.sched_changed = true;
    st.cpu = 1;
    st.affinity_changed = true;
    st.memory_locked = true;
    j288_rt_report(&g_t, &st, &rep);
    TEST_ASSERT_EQUAL_UINT32(1000, rep.cycles);
    TEST_ASSERT_EQUAL_UINT32(50, rep.lateness.p50_us);
    TEST_ASSERT_EQUAL_UINT32(50, rep.lateness.p999_us); /* 999 of 1000 at 50 */
    TEST_ASSERT_EQUAL_UINT32(3000, rep.lateness.max_us);
    TEST_ASSERT_EQUAL_INT32(80, rep.priority);
    TEST_ASSERT_EQUAL_INT32(1, rep.cpu);
    TEST_ASSERT_EQUAL_UINT32(1, rep.memory_locked);
    j288_rt_format(&rep, text, sizeof text);
    TEST_ASSERT_NOT_NULL(strstr(text, "timing: 1000 cycles at 500 Hz (SCHED_FIFO 80, CPU 1, "
                                      "memory locked): 3 deadlines missed, 2 periods skipped, 1 "
                                      "cycles cut at their bound\n"));
    TEST_ASSERT_NOT_NULL(strstr(text, "wake-up lateness p50 50 us, p99 50 us, p99.9 50 us, "
                                      "max 3000 us (1000 wake-ups)\n"));
    TEST_ASSERT_NOT_NULL(strstr(text, "cycle duration p50 400 us"));
    j288_rt_report(&g_t, NULL, &rep);
    TEST_ASSERT_EQUAL_INT32(-1, rep.cpu);
    j288_rt_format(&rep, text, 40); /* cut short, still a string */
    TEST_ASSERT_EQUAL_UINT64(39, strlen(text));
}

/* ---- set-up through the seam ------------------------------------------------------------------- */

static struct {
    int lock_rc, sched_rc, cpus_rc;
    int locks, unlocks, sched_calls, cpu_sets;
    int policy, priority;            /* as set last */
    unsigned char allowed[J288_RT_CPU_MASK_BYTES];
    unsigned char cpus[J288_RT_CPU_MASK_BYTES]; /* as set last */
} g_sys;

static int fake_lock(void)
{
    g_sys.locks++;
    return g_sys.lock_rc;
}
static int fake_unlock(void)
{
    g_sys.unlocks++;
    return 0;
}
static int fake_get_sched(int *policy, int *priority)
{
    *policy = SCHED_OTHER;
    *priority = 0;
    return 0;
}
static int fake_set_sched(int policy, int priority)
{
    g_sys.sched_calls++;
    if (g_sys.sched_rc != 0 && policy == SCHED_FIFO)
        return g_sys.sched_rc;
    g_sys.policy = policy;
    g_sys.priority = priority;
    return 0;
}
static int fake_get_cpus(unsigned char *mask)
{
    memcpy(mask, g_sys.allowed, J288_RT_CPU_MASK_BYTES);
    return 0;
}
static int fake_set_cpus(const unsigned char *mask)
{
    g_sys.cpu_sets++;
    if (g_sys.cpus_rc != 0)
        return g_sys.cpus_rc;
    memcpy(g_sys.cpus, mask, J288_RT_CPU_MASK_BYTES);
    return 0;
}
static const j288_rt_sys_t fake = {fake_lock,      fake_unlock,   fake_get_sched,
                                   fake_set_sched, fake_get_cpus, fake_set_cpus};

static j288_rt_status_t g_st;

static void sys_reset(void)
{
    memset(&g_sys, 0, sizeof g_sys);
    g_sys.allowed[0] = 0x13; /* CPUs 0, 1, 4 */
    memset(&g_st, 0, sizeof g_st);
}

static void test_setup_does_all_and_restore_undoes_it(void)
{
    j288_rt_options_t o = {80, 4};
    sys_reset();
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_rt_setup_with(&o, &fake, &g_st));
    TEST_ASSERT_FALSE(g_st.refused);
    TEST_ASSERT_EQUAL_STRING("", g_st.notice);
    TEST_ASSERT_EQUAL_INT(80, g_st.priority);
    TEST_ASSERT_EQUAL_INT(4, g_st.cpu);
    TEST_ASSERT_TRUE(g_st.memory_locked);
    TEST_ASSERT_EQUAL_INT(SCHED_FIFO, g_sys.policy);
    TEST_ASSERT_EQUAL_INT(80, g_sys.priority);
    TEST_ASSERT_EQUAL_HEX8(0x10, g_sys.cpus[0]);
    j288_rt_restore(&g_st);
    TEST_ASSERT_EQUAL_INT(SCHED_OTHER, g_sys.policy);
    TEST_ASSERT_EQUAL_HEX8(0x13, g_sys.cpus[0]);
    TEST_ASSERT_EQUAL_INT(1, g_sys.unlocks);
    TEST_ASSERT_EQUAL_INT(0, g_st.priority);
    TEST_ASSERT_EQUAL_INT(-1, g_st.cpu);
    j288_rt_restore(&g_st); /* twice: nothing more */
    TEST_ASSERT_EQUAL_INT(1, g_sys.unlocks);
}

static void test_eperm_is_explained_and_the_loop_runs_on(void)
{
    j288_rt_options_t o = {80, -1};
    sys_reset();
    g_sys.sched_rc = EPERM;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_rt_setup_with(&o, &fake, &g_st));
    TEST_ASSERT_TRUE(g_st.refused);
    TEST_ASSERT_EQUAL_INT(0, g_st.priority);
    TEST_ASSERT_TRUE(g_st.memory_locked); /* the rest is done */
    TEST_ASSERT_NOT_NULL(strstr(g_st.notice, "SCHED_FIFO priority 80 refused (Operation not "
                                             "permitted): the loop runs at normal priority"));
    TEST_ASSERT_NOT_NULL(strstr(g_st.notice, "ulimit -r 80"));
    TEST_ASSERT_NOT_NULL(strstr(g_st.notice, "/etc/security/limits.d"));
    TEST_ASSERT_NOT_NULL(strstr(g_st.notice, "CAP_SYS_NICE"));
    j288_rt_restore(&g_st);
    TEST_ASSERT_EQUAL_INT(0, g_sys.policy); /* never changed, so never "restored" */
}

static void test_memory_refused_is_explained(void)
{
    j288_rt_options_t o = {50, -1};
    sys_reset();
    g_sys.lock_rc = ENOMEM;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_rt_setup_with(&o, &fake, &g_st));
    TEST_ASSERT_TRUE(g_st.refused);
    TEST_ASSERT_FALSE(g_st.memory_locked);
    TEST_ASSERT_EQUAL_INT(50, g_st.priority);
    TEST_ASSERT_NOT_NULL(strstr(g_st.notice, "memory not locked (Cannot allocate memory)"));
    TEST_ASSERT_NOT_NULL(strstr(g_st.notice, "ulimit -l unlimited"));
    TEST_ASSERT_NOT_NULL(strstr(g_st.notice, "memlock"));
    TEST_ASSERT_NOT_NULL(strstr(g_st.notice, "CAP_IPC_LOCK"));
    j288_rt_restore(&g_st);
    TEST_ASSERT_EQUAL_INT(0, g_sys.unlocks);
}

static void test_a_cpu_not_allowed_is_refused_before_anything_changes(void)
{
    j288_rt_options_t o = {80, 2};
    sys_reset();
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_ARG, j288_rt_setup_with(&o, &fake, &g_st));
    TEST_ASSERT_EQUAL_STRING("real time: CPU 2 is not one this process may run on (allowed: "
                             "0-1,4)\n",
                             g_st.notice);
    TEST_ASSERT_EQUAL_INT(0, g_sys.locks + g_sys.sched_calls + g_sys.cpu_sets);
    o.cpu = 1000000;
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_ARG, j288_rt_setup_with(&o, &fake, &g_st));
    o.cpu = -1;
    o.priority = 100;
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_ARG, j288_rt_setup_with(&o, &fake, &g_st));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_rt_setup_with(NULL, &fake, &g_st));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_rt_setup_with(&o, &fake, NULL));
}

static void test_nothing_asked_nothing_done(void)
{
    j288_rt_options_t o;
    sys_reset();
    j288_rt_options_init(&o);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_rt_setup_with(&o, &fake, &g_st));
    TEST_ASSERT_EQUAL_INT(0, g_sys.locks + g_sys.sched_calls + g_sys.cpu_sets);
    TEST_ASSERT_EQUAL_INT(-1, g_st.cpu);
}

/* ASan intercepts mlockall() and returns 0 without locking anything (its shadow memory could
 * not be locked), so under it the memory check below cannot fail: it is skipped there. */
#if defined(__SANITIZE_ADDRESS__)
#define MLOCK_IS_REAL 0
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define MLOCK_IS_REAL 0
#endif
#endif
#ifndef MLOCK_IS_REAL
#define MLOCK_IS_REAL 1
#endif

/* The real refusal: a child process without the rights (root drops to nobody, which ends
 * its capabilities; everyone lowers RLIMIT_RTPRIO and RLIMIT_MEMLOCK to 0) asks for priority
 * 80: the kernel says EPERM, set-up says how to allow it and returns J288_OK, and the child
 * runs on under its old scheduling. Its exit status names the first check that failed. */
static int refused_child(void)
{
    struct rlimit none = {0, 0};
    j288_rt_options_t o = {80, -1};
    static j288_rt_status_t st;
    if (geteuid() == 0 && (setgroups(0, NULL) != 0 || setgid(65534) != 0 || setuid(65534) != 0))
        return 10;
    if (setrlimit(RLIMIT_RTPRIO, &none) != 0 || setrlimit(RLIMIT_MEMLOCK, &none) != 0)
        return 11;
    if (j288_rt_setup(&o, &st) != J288_OK)
        return 12;
    if (!st.refused || st.priority != 0 || sched_getscheduler(0) != SCHED_OTHER)
        return 13;
    if (strstr(st.notice, "SCHED_FIFO priority 80 refused (Operation not permitted)") == NULL ||
        strstr(st.notice, "ulimit -r 80") == NULL || strstr(st.notice, "CAP_SYS_NICE") == NULL)
        return 14;
    if (!MLOCK_IS_REAL)
        return 0;
    if (st.memory_locked || strstr(st.notice, "memory not locked") == NULL)
        return 15;
    return 0;
}

static void test_refused_for_real_without_the_rights(void)
{
    int status = -1;
    pid_t pid = fork();
    TEST_ASSERT_TRUE(pid >= 0);
    if (pid == 0)
        _exit(refused_child());
    TEST_ASSERT_EQUAL_INT(pid, waitpid(pid, &status, 0));
    TEST_ASSERT_TRUE(WIFEXITED(status));
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, WEXITSTATUS(status), "the child's check that failed: "
                                                          "10 drop root, 11 limits, 12 result, "
                                                          "13 refused, 14 notice, 15 memory");
}

/* The real clock and sleep: the sleep returns at or after its deadline (an order, not a
 * duration). */
static void test_sleep_until_an_absolute_time(void)
{
    uint64_t t = j288_rt_now_ns() + 2000000u;
    while (!j288_rt_sleep_until(t)) {
    }
    TEST_ASSERT_TRUE(j288_rt_now_ns() >= t);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_small_values_are_exact);
    RUN_TEST(test_large_values_within_a_thirty_second);
    RUN_TEST(test_quantiles_are_capped_by_the_max_and_ordered);
    RUN_TEST(test_pacing_keeps_absolute_deadlines);
    RUN_TEST(test_a_missed_deadline_starts_at_once_and_skips_whole_periods);
    RUN_TEST(test_a_new_period_or_a_restart_starts_a_new_schedule);
    RUN_TEST(test_report_and_its_text);
    RUN_TEST(test_setup_does_all_and_restore_undoes_it);
    RUN_TEST(test_eperm_is_explained_and_the_loop_runs_on);
    RUN_TEST(test_memory_refused_is_explained);
    RUN_TEST(test_a_cpu_not_allowed_is_refused_before_anything_changes);
    RUN_TEST(test_nothing_asked_nothing_done);
    RUN_TEST(test_refused_for_real_without_the_rights);
    RUN_TEST(test_sleep_until_an_absolute_time);
    return UNITY_END();
}
