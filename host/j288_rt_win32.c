/* j288_rt_win32.c - j288_rt.h's set-up, clock and sleep on Windows: a stand-in. Windows has
 * no SCHED_FIFO for an ordinary program and no mlockall: a priority raises the calling thread
 * to THREAD_PRIORITY_TIME_CRITICAL (highest in its process's class; above most programs' threads,
 * not above the system's), a cpu sets the thread's affinity mask, and nothing is locked in
 * memory. The notice says so. The sleep is Sleep() in whole milliseconds (the port asks for
 * 1 ms timer steps with timeBeginPeriod). */
#include "j288_rt.h"

#include <stdio.h>
#include <string.h>
#include <windows.h>

#include "j288/error.h"
#include "j288_rt_os.h"

int j288_rt_os_setup(const j288_rt_options_t *o, const j288_rt_sys_t *sys, j288_rt_status_t *st)
{
    DWORD_PTR proc_mask = 0, sys_mask = 0;
    HANDLE self = GetCurrentThread();
    (void)sys; /* the seam is Linux's */
    if (o->cpu >= 0) {
        (void)GetProcessAffinityMask(GetCurrentProcess(), &proc_mask, &sys_mask);
        if (o->cpu >= (int)(8u * sizeof(DWORD_PTR)) ||
            (proc_mask & ((DWORD_PTR)1 << (unsigned)o->cpu)) == 0u) {
            (void)snprintf(st->notice, sizeof st->notice,
                           "real time: CPU %d is not one this process may run on (mask 0x%llx)\n",
                           o->cpu, (unsigned long long)proc_mask);
            return J288_ERR_BAD_ARG;
        }
        st->saved_win_affinity = (uint64_t)SetThreadAffinityMask(self, (DWORD_PTR)1 << (unsigned)o->cpu);
        if (st->saved_win_affinity != 0u) {
            st->affinity_changed = true;
            st->cpu = o->cpu;
        }
    }
    if (o->priority > 0) {
        st->saved_win_priority = GetThreadPriority(self);
        if (SetThreadPriority(self, THREAD_PRIORITY_TIME_CRITICAL)) {
            st->sched_changed = true;
            st->priority = o->priority;
        }
        (void)snprintf(st->notice, sizeof st->notice,
                       "real time: on Windows the priority raises the loop's thread to "
                       "THREAD_PRIORITY_TIME_CRITICAL;\n"
                       "  no memory is locked and there is no SCHED_FIFO (docs/realtime.md)\n");
    }
    return J288_OK;
}

void j288_rt_restore(j288_rt_status_t *st)
{
    HANDLE self = GetCurrentThread();
    if (st == NULL)
        return;
    if (st->sched_changed)
        (void)SetThreadPriority(self, st->saved_win_priority);
    if (st->affinity_changed)
        (void)SetThreadAffinityMask(self, (DWORD_PTR)st->saved_win_affinity);
    st->sched_changed = false;
    st->affinity_changed = false;
    st->priority = 0;
    st->cpu = -1;
}

uint64_t j288_rt_now_ns(void)
{
    LARGE_INTEGER f, c;
    uint64_t freq, count;
    (void)QueryPerformanceFrequency(&f);
    (void)QueryPerformanceCounter(&c);
    freq = (uint64_t)f.QuadPart;
    count = (uint64_t)c.QuadPart;
    /* split so that count * 1e9 cannot overflow 64 bits */
    return (count / freq) * 1000000000u + (count % freq) * 1000000000u / freq;
}

bool j288_rt_sleep_until(uint64_t t_ns)
{
    uint64_t now = j288_rt_now_ns();
    if (t_ns > now) {
        uint64_t ms = (t_ns - now) / 1000000u;
        Sleep(ms > 0u ? (DWORD)(ms > 10000u ? 10000u : ms) : 0u);
    }
    return true;
}
