/* j288_rt_linux.c - j288_rt.h's set-up, clock and sleep on Linux: mlockall, SCHED_FIFO, CPU
 * affinity (each refusal explained), clock_nanosleep(TIMER_ABSTIME). */
#define _GNU_SOURCE 1 /* CPU_SET, sched_setaffinity */

#include "j288_rt.h"

#include <errno.h>
#include <sched.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <sys/mman.h>
#include <time.h>

#include "j288/error.h"
#include "j288_rt_os.h"

/* ---- the real calls ------------------------------------------------------------------------ */

static int sys_lock_memory(void)
{
    return mlockall(MCL_CURRENT | MCL_FUTURE) == 0 ? 0 : errno;
}

static int sys_unlock_memory(void)
{
    return munlockall() == 0 ? 0 : errno;
}

static int sys_get_sched(int *policy, int *priority)
{
    struct sched_param sp;
    int p = sched_getscheduler(0);
    if (p < 0 || sched_getparam(0, &sp) != 0)
        return errno;
    *policy = p;
    *priority = sp.sched_priority;
    return 0;
}

/* pid 0: the calling thread (Linux schedules threads). */
static int sys_set_sched(int policy, int priority)
{
    struct sched_param sp;
    memset(&sp, 0, sizeof sp);
    sp.sched_priority = priority;
    return sched_setscheduler(0, policy, &sp) == 0 ? 0 : errno;
}

static int sys_get_cpus(unsigned char *mask)
{
    cpu_set_t set;
    unsigned i;
    CPU_ZERO(&set);
    if (sched_getaffinity(0, sizeof set, &set) != 0)
        return errno;
    memset(mask, 0, J288_RT_CPU_MASK_BYTES);
    for (i = 0; i < J288_RT_CPU_MASK_BYTES * 8u && i < (unsigned)CPU_SETSIZE; i++) {
        if (CPU_ISSET(i, &set))
            mask[i / 8u] = (unsigned char)(mask[i / 8u] | (1u << (i % 8u)));
    }
    return 0;
}

static int sys_set_cpus(const unsigned char *mask)
{
    cpu_set_t set;
    unsigned i;
    CPU_ZERO(&set);
    for (i = 0; i < J288_RT_CPU_MASK_BYTES * 8u && i < (unsigned)CPU_SETSIZE; i++) {
        if ((mask[i / 8u] & (1u << (i % 8u))) != 0u)
            CPU_SET(i, &set);
    }
    return sched_setaffinity(0, sizeof set, &set) == 0 ? 0 : errno;
}

static const j288_rt_sys_t real_sys = {sys_lock_memory, sys_unlock_memory, sys_get_sched,
                                        sys_set_sched,   sys_get_cpus,      sys_set_cpus};

/* ---- set-up ---------------------------------------------------------------------------------- */

/* Append a formatted line to st->notice (cut short when full). */
static void note(j288_rt_status_t *st, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void note(j288_rt_status_t *st, const char *fmt, ...)
{
    size_t n = strlen(st->notice);
    va_list ap;
    if (n + 1u >= sizeof st->notice)
        return;
    va_start(ap, fmt);
    (void)vsnprintf(st->notice + n, sizeof st->notice - n, fmt, ap);
    va_end(ap);
}

static bool mask_has(const unsigned char *mask, int cpu)
{
    return cpu >= 0 && (unsigned)cpu < J288_RT_CPU_MASK_BYTES * 8u &&
           (mask[(unsigned)cpu / 8u] & (1u << ((unsigned)cpu % 8u))) != 0u;
}

/* "0-3,6" */
static void mask_text(const unsigned char *mask, char *buf, size_t len)
{
    int i = 0, top = (int)(J288_RT_CPU_MASK_BYTES * 8u);
    size_t n = 0;
    buf[0] = '\0';
    while (i < top && n + 1u < len) {
        int first;
        if (!mask_has(mask, i)) {
            i++;
            continue;
        }
        first = i;
        while (i + 1 < top && mask_has(mask, i + 1))
            i++;
        n += (size_t)snprintf(buf + n, len - n, first == i ? "%s%d" : "%s%d-%d",
                              n != 0u ? "," : "", first, i);
        i++;
    }
}

/* Memory first: a page fault in the loop costs as much as a late wake-up. */
static void lock_memory(const j288_rt_sys_t *sys, j288_rt_status_t *st)
{
    int e = sys->lock_memory();
    if (e == 0) {
        st->memory_locked = true;
        return;
    }
    st->refused = true;
    note(st, "real time: memory not locked (%s): a page fault can still stall the loop.\n"
             "  Allow it: `ulimit -l unlimited` before starting it (raising the hard limit needs "
             "root),\n"
             "  or `USER - memlock unlimited` in /etc/security/limits.d/j288.conf, or the "
             "capability CAP_IPC_LOCK\n"
             "  (systemd: LimitMEMLOCK=infinity). docs/realtime.md\n",
         strerror(e));
}

/* Touch the stack the loop will use, so that it is mapped (and locked) before it runs. */
static void prefault_stack(void)
{
    volatile unsigned char stack[J288_RT_STACK_PREFAULT];
    size_t i;
    for (i = 0; i < sizeof stack; i += 1024u)
        stack[i] = 0;
}

static void set_fifo(const j288_rt_sys_t *sys, int priority, j288_rt_status_t *st)
{
    int policy = SCHED_OTHER, old = 0, e;
    if (sys->get_sched(&policy, &old) != 0) {
        policy = SCHED_OTHER;
        old = 0;
    }
    e = sys->set_sched(SCHED_FIFO, priority);
    if (e == 0) {
        st->priority = priority;
        st->sched_changed = true;
        st->saved_policy = policy;
        st->saved_priority = old;
        return;
    }
    st->refused = true;
    note(st, "real time: SCHED_FIFO priority %d refused (%s): the loop runs at normal "
             "priority.\n"
             "  Allow it: `ulimit -r %d` before starting it (raising the hard limit needs root),\n"
             "  or `USER - rtprio %d` in /etc/security/limits.d/j288.conf, or the capability "
             "CAP_SYS_NICE\n"
             "  (setcap cap_sys_nice+ep PROGRAM; systemd: LimitRTPRIO=%d); in a container or a "
             "cgroup, it\n"
             "  needs real-time runtime (cpu.rt_runtime_us). docs/realtime.md\n",
         priority, strerror(e), priority, priority, priority);
}

int j288_rt_os_setup(const j288_rt_options_t *o, const j288_rt_sys_t *sys, j288_rt_status_t *st)
{
    unsigned char allowed[J288_RT_CPU_MASK_BYTES];
    if (sys == NULL)
        sys = &real_sys;
    st->sys = sys;
    if (o->cpu >= 0) {
        char list[256];
        if (sys->get_cpus(allowed) != 0 || !mask_has(allowed, o->cpu)) {
            if (sys->get_cpus(allowed) != 0)
                memset(allowed, 0, sizeof allowed);
            mask_text(allowed, list, sizeof list);
            note(st, "real time: CPU %d is not one this process may run on (allowed: %s)\n",
                 o->cpu, list[0] != '\0' ? list : "unknown");
            return J288_ERR_BAD_ARG;
        }
    }
    if (o->priority > 0) {
        lock_memory(sys, st);
        prefault_stack();
    }
    if (o->cpu >= 0) {
        unsigned char one[J288_RT_CPU_MASK_BYTES];
        int e;
        memset(one, 0, sizeof one);
        one[(unsigned)o->cpu / 8u] = (unsigned char)(1u << ((unsigned)o->cpu % 8u));
        e = sys->set_cpus(one);
        if (e == 0) {
            memcpy(st->saved_cpus, allowed, sizeof allowed);
            st->affinity_changed = true;
            st->cpu = o->cpu;
        } else {
            st->refused = true;
            note(st, "real time: not pinned to CPU %d (%s)\n", o->cpu, strerror(e));
        }
    }
    if (o->priority > 0)
        set_fifo(sys, o->priority, st);
    return J288_OK;
}

void j288_rt_restore(j288_rt_status_t *st)
{
    const j288_rt_sys_t *sys;
    if (st == NULL)
        return;
    sys = st->sys != NULL ? st->sys : &real_sys;
    if (st->sched_changed)
        (void)sys->set_sched(st->saved_policy, st->saved_priority);
    if (st->affinity_changed)
        (void)sys->set_cpus(st->saved_cpus);
    if (st->memory_locked)
        (void)sys->unlock_memory();
    st->sched_changed = false;
    st->affinity_changed = false;
    st->memory_locked = false;
    st->priority = 0;
    st->cpu = -1;
}

/* ---- the clock and the sleep ----------------------------------------------------------------- */

uint64_t j288_rt_now_ns(void)
{
    struct timespec ts;
    (void)clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint64_t)ts.tv_sec * 1000000000u + (uint64_t)ts.tv_nsec;
}

bool j288_rt_sleep_until(uint64_t t_ns)
{
    struct timespec ts;
    ts.tv_sec = (time_t)(t_ns / 1000000000u);
    ts.tv_nsec = (long)(t_ns % 1000000000u);
    return clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, NULL) == 0;
}
