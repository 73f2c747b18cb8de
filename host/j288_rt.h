/*
 * j288_rt.h - what a real-time control loop asks of the operating system, and how late its
 * cycles were: the host layer's one implementation, which the runner (j288_robot.h) applies
 * and feeds and every front end reports (docs/realtime.md says what each setting does and what
 * it cannot fix).
 *
 * Set-up (j288_rt_setup(), done by j288_robot_open() from j288_robot_options_t's rt):
 * - priority 1-99: the process's memory locked (mlockall(MCL_CURRENT | MCL_FUTURE): no page
 *   fault, no swap-in in the loop), J288_RT_STACK_PREFAULT bytes of stack touched now, and the
 *   calling thread put under SCHED_FIFO at that priority (it then preempts every ordinary
 *   process the moment its deadline comes). 0: none of it.
 * - cpu >= 0: the calling thread pinned to that CPU (its caches stay warm; with isolcpus= it
 *   has the CPU to itself). -1: left to the scheduler.
 * Without the rights (EPERM for SCHED_FIFO: RLIMIT_RTPRIO below the priority and no
 * CAP_SYS_NICE; ENOMEM/EPERM for mlockall: RLIMIT_MEMLOCK too small and no CAP_IPC_LOCK; a
 * cgroup without real-time runtime under CONFIG_RT_GROUP_SCHED) the setting is left out, the
 * rest is done, and st->notice says in one paragraph what was refused and how to allow it
 * (ulimit -r / -l, /etc/security/limits.d, CAP_SYS_NICE / CAP_IPC_LOCK): the loop runs on at
 * normal priority. A CPU this process may not run on is bad input: J288_ERR_BAD_ARG, nothing
 * changed. j288_rt_restore() puts back what set-up changed (scheduling, affinity, the lock).
 * On Windows (host/j288_rt_win32.c) the priority raises the thread to
 * THREAD_PRIORITY_TIME_CRITICAL and the cpu sets its affinity mask; no memory is locked; the
 * notice says so.
 *
 * Pacing (j288_rt_pace_begin() / j288_rt_pace_woke(), used by j288_robot_pace()): cycle k is
 * due at t0 + k * period, absolute deadlines on CLOCK_MONOTONIC from the schedule's first
 * cycle (t0), whatever each cycle took. The rule for a missed deadline: SKIP, never catch up.
 * - A loop that reaches its wait before the deadline sleeps until it; the wake-up's lateness
 *   (deadline to running again: the machine's share, what cyclictest measures) is recorded.
 * - A loop that reaches its wait after the deadline (its cycle, or the work between cycles,
 *   overran the period) has missed it (counted): the next cycle starts at once, and deadlines
 *   a whole period or more in the past are skipped (counted), never run back to back. The
 *   grid is kept: the rate holds exactly while overruns stay under a period, and a longer
 *   stall costs exactly the periods it covered.
 * Why skip: a robot's commands are set-points for now. Catching up would send a burst of
 * cycles computed from stale state, several sweeps queued on a half-duplex bus at once, and
 * after a long stall the loop would stay behind for as long as the stall lasted. Why keep the
 * grid rather than restart it from each late cycle (as the runner did before): each overrun
 * then lowered the rate for good (476 Hz of 500 at load 3), and a controller's fixed period
 * drifted with the machine's load.
 *
 * Statistics (j288_rt_timing_t, one per robot; j288_rt_report() summarises): wake-up lateness
 * and cycle duration as histograms (microseconds, log-linear: exact below 64 us, buckets
 * within 1/32 of their value above, to 2^32 us), the deadlines missed, the periods skipped, the
 * cycles cut at their bound (j288_robot_cycle()'s timeout). A cycle's duration runs from its
 * start (the wake-up, or at once after a miss) to the loop's next wait: the buses' sweep and
 * whatever the front end did in that period. Percentiles are nearest-rank, reported as their
 * bucket's upper bound (never above the maximum seen): at most 3.2 % high above 64 us.
 *
 * Nothing here allocates; the timing calls do no I/O. Thread only (the loop's thread), not
 * signal-safe. No mutable globals: everything lives in the caller's structs.
 */
#ifndef J288_RT_H
#define J288_RT_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define J288_RT_DEFAULT_PRIORITY 80     /* --realtime without =PRIO: above the threaded
                                           interrupts of PREEMPT_RT (50), below the kernel's
                                           own 99 */
#define J288_RT_STACK_PREFAULT (256u * 1024u) /* bytes of stack touched at set-up */
#define J288_RT_NOTICE_LEN 640u
#define J288_RT_CPU_MASK_BYTES 128u /* 1024 CPUs, as glibc's cpu_set_t */

/* ---- set-up ------------------------------------------------------------------------------ */

/* What to ask for (j288_rt_options_init(): nothing). */
typedef struct {
    int priority; /* 1-99: SCHED_FIFO at it, memory locked, stack pre-faulted; 0: none */
    int cpu;      /* >= 0: pin the calling thread to it; -1: no pinning */
} j288_rt_options_t;

/* The OS calls set-up makes, replaceable for tests (a seam: a unit test gives ones that fail
 * with EPERM). Each returns 0 or an errno value. A CPU mask is J288_RT_CPU_MASK_BYTES bytes,
 * bit i of byte i / 8 for CPU i. NULL in j288_rt_setup_with(): the real ones. Linux only. */
typedef struct {
    int (*lock_memory)(void);   /* mlockall(MCL_CURRENT | MCL_FUTURE) */
    int (*unlock_memory)(void); /* munlockall() */
    int (*get_sched)(int *policy, int *priority);
    int (*set_sched)(int policy, int priority); /* the calling thread */
    int (*get_cpus)(unsigned char *mask);       /* the CPUs the calling thread may run on */
    int (*set_cpus)(const unsigned char *mask);
} j288_rt_sys_t;

/* What set-up did (and what j288_rt_restore() needs to undo it). */
typedef struct {
    int priority;        /* the SCHED_FIFO priority in effect, 0 when none */
    int cpu;             /* the CPU pinned to, -1 when none */
    bool memory_locked;  /* mlockall succeeded */
    bool refused;        /* something asked for was refused (notice says what) */
    char notice[J288_RT_NOTICE_LEN]; /* "" or lines each ending in '\n' */
    /* Private: what to restore, and with which calls. */
    const j288_rt_sys_t *sys;
    int saved_policy;
    int saved_priority;
    bool sched_changed;
    bool affinity_changed;
    unsigned char saved_cpus[J288_RT_CPU_MASK_BYTES];
    int saved_win_priority;
    uint64_t saved_win_affinity;
} j288_rt_status_t;

void j288_rt_options_init(j288_rt_options_t *o); /* priority 0, cpu -1 */

/* Apply o to the calling thread (see the top). Returns J288_OK (also when something was
 * refused: st->refused, st->notice), J288_ERR_BAD_ARG (priority outside 0-99, or a CPU this
 * process may not run on: st->notice says which are allowed; nothing changed), J288_ERR_NULL.
 * st is fully written. */
int j288_rt_setup(const j288_rt_options_t *o, j288_rt_status_t *st);
int j288_rt_setup_with(const j288_rt_options_t *o, const j288_rt_sys_t *sys, j288_rt_status_t *st);

/* Undo what st records (scheduling, affinity, the memory lock); st then says nothing is in
 * effect. Safe on an all-zero st and twice. */
void j288_rt_restore(j288_rt_status_t *st);

/* ---- the clock and the sleep -------------------------------------------------------------- */

/* CLOCK_MONOTONIC in nanoseconds (Windows: QueryPerformanceCounter). */
uint64_t j288_rt_now_ns(void);

/* Sleep until the monotonic time t_ns (clock_nanosleep(TIMER_ABSTIME): no drift from the
 * time it takes to get here). Returns early, false, when a signal interrupted it. Windows:
 * Sleep() for the whole milliseconds left (the port's timeBeginPeriod(1) gives 1 ms steps),
 * then returns; the caller loops until the time has come. */
bool j288_rt_sleep_until(uint64_t t_ns);

/* ---- statistics --------------------------------------------------------------------------- */

#define J288_RT_HIST_SUB_BITS 5u
#define J288_RT_HIST_EXACT (2u << J288_RT_HIST_SUB_BITS) /* values below: one bucket each */
#define J288_RT_HIST_BUCKETS (J288_RT_HIST_EXACT + (32u - J288_RT_HIST_SUB_BITS - 1u) * \
                              (1u << J288_RT_HIST_SUB_BITS))

typedef struct {
    uint32_t n;   /* values recorded (saturates at UINT32_MAX) */
    uint32_t max; /* the largest */
    uint32_t count[J288_RT_HIST_BUCKETS];
} j288_rt_hist_t;

typedef struct {
    j288_rt_hist_t lateness; /* us, one per wake-up at a deadline */
    j288_rt_hist_t duration; /* us, one per cycle ended by the loop's next wait */
    uint32_t missed;         /* deadlines already past when the loop came to wait */
    uint32_t skipped;        /* whole periods dropped after such a miss */
    uint32_t cut;            /* cycles ended by their bound (the runner's cycle timeout) */
    uint32_t period_us;      /* of the latest paced wait (0: back to back) */
} j288_rt_timing_t;

void j288_rt_hist_add(j288_rt_hist_t *h, uint32_t value);
/* The nearest-rank q-quantile (0 < q <= 1; in parts per million, e.g. 999000 for p99.9) as
 * its bucket's upper bound, at most h->max; 0 when nothing was recorded. */
uint32_t j288_rt_hist_quantile(const j288_rt_hist_t *h, uint32_t q_ppm);

void j288_rt_timing_reset(j288_rt_timing_t *t);

/* One histogram summarised. */
typedef struct {
    uint32_t count;
    uint32_t p50_us;
    uint32_t p99_us;
    uint32_t p999_us; /* p99.9 */
    uint32_t max_us;
} j288_rt_summary_t;

/* What every front end reports (Python mirrors it: python/j288/_native.py, size checked). */
typedef struct {
    uint32_t cycles;      /* cycles ended by a paced wait (duration.count) */
    uint32_t period_us;   /* the pacing period (0: back to back, or never paced) */
    uint32_t missed;
    uint32_t skipped;
    uint32_t cut;
    j288_rt_summary_t lateness;
    j288_rt_summary_t duration;
    int32_t priority;     /* SCHED_FIFO priority in effect, 0: normal scheduling */
    int32_t cpu;          /* pinned CPU, -1: none */
    uint32_t memory_locked; /* 1: mlockall in effect */
} j288_rt_report_t;

/* Summarise t (and what st says is in effect; st may be NULL). */
void j288_rt_report(const j288_rt_timing_t *t, const j288_rt_status_t *st, j288_rt_report_t *out);

/* The report as three lines, each starting "timing: " and ending in '\n' (truncated to len,
 * always terminated): cycles, period, misses, skips, cuts and what is in effect; wake-up
 * lateness; cycle duration. Returns buf. */
char *j288_rt_format(const j288_rt_report_t *rep, char *buf, size_t len);

/* ---- pacing (the rule at the top) ---------------------------------------------------------- */

typedef struct {
    uint64_t period_ns;
    uint64_t due_ns;       /* the deadline of the cycle in progress */
    uint64_t start_ns;     /* when the cycle in progress began */
    bool started;
} j288_rt_pacer_t;

/* Start a new schedule at the next j288_rt_pace_begin() (the one after that is due a period
 * later). */
void j288_rt_pace_restart(j288_rt_pacer_t *p);

/* The loop comes to wait at now_ns after a cycle, for a period of period_ns (0: back to
 * back). Ends the cycle in progress (its duration into t) and applies the rule: returns true
 * with *until_ns the deadline to sleep to, or false when the next cycle starts at once (the
 * schedule's first cycle, back to back, or a missed deadline: counted, with the skipped
 * periods). A new period restarts the schedule. */
bool j288_rt_pace_begin(j288_rt_pacer_t *p, j288_rt_timing_t *t, uint64_t period_ns,
                        uint64_t now_ns, uint64_t *until_ns);

/* The loop runs again at now_ns: after a sleep to the deadline (slept: its lateness into t)
 * or at once. The next cycle starts now. */
void j288_rt_pace_woke(j288_rt_pacer_t *p, j288_rt_timing_t *t, uint64_t now_ns, bool slept);

/* The deadline of the next cycle if the schedule goes on at period_ns, or false when the next
 * j288_rt_pace_begin() would start a new one. */
bool j288_rt_pace_next_due(const j288_rt_pacer_t *p, uint64_t period_ns, uint64_t *due_ns);

#ifdef __cplusplus
}
#endif

#endif /* J288_RT_H */
