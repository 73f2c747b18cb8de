/* j288_rt.c - the loop's timing statistics and the pacing rule (see j288_rt.h); the OS
 * set-up, the clock and the sleep are in j288_rt_linux.c and j288_rt_win32.c. */
#include "j288_rt.h"

#include <stdio.h>
#include <string.h>

#include "j288/error.h"
#include "j288_rt_os.h"

/* ---- set-up: the arguments here, the rest in the OS's file ---------------------------------- */

void j288_rt_options_init(j288_rt_options_t *o)
{
    o->priority = 0;
    o->cpu = -1;
}

int j288_rt_setup_with(const j288_rt_options_t *o, const j288_rt_sys_t *sys, j288_rt_status_t *st)
{
    if (st == NULL)
        return J288_ERR_NULL;
    memset(st, 0, sizeof *st);
    st->cpu = -1;
    if (o == NULL)
        return J288_ERR_NULL;
    if (o->priority < 0 || o->priority > 99) {
        (void)snprintf(st->notice, sizeof st->notice,
                       "real time: priority %d is not 1-99 (0: none)\n", o->priority);
        return J288_ERR_BAD_ARG;
    }
    return j288_rt_os_setup(o, sys, st);
}

int j288_rt_setup(const j288_rt_options_t *o, j288_rt_status_t *st)
{
    return j288_rt_setup_with(o, NULL, st);
}

/* Bucket of a value: exact below J288_RT_HIST_EXACT; above, the power of two it lies in and
 * its top J288_RT_HIST_SUB_BITS bits after the leading one. */
static unsigned bucket_of(uint32_t v)
{
    unsigned e = 0;
    uint32_t x = v;
    if (v < J288_RT_HIST_EXACT)
        return (unsigned)v;
    while (x > 1u) {
        x >>= 1;
        e++;
    }
    /* e >= SUB_BITS + 1 here */
    return J288_RT_HIST_EXACT + (e - J288_RT_HIST_SUB_BITS - 1u) * (1u << J288_RT_HIST_SUB_BITS) +
           ((unsigned)(v >> (e - J288_RT_HIST_SUB_BITS)) & ((1u << J288_RT_HIST_SUB_BITS) - 1u));
}

/* The largest value that falls in bucket i. */
static uint32_t bucket_top(unsigned i)
{
    unsigned k, e, sub;
    uint64_t low;
    if (i < J288_RT_HIST_EXACT)
        return (uint32_t)i;
    k = i - J288_RT_HIST_EXACT;
    e = k / (1u << J288_RT_HIST_SUB_BITS) + J288_RT_HIST_SUB_BITS + 1u;
    sub = k % (1u << J288_RT_HIST_SUB_BITS);
    low = (uint64_t)((1u << J288_RT_HIST_SUB_BITS) + sub) << (e - J288_RT_HIST_SUB_BITS);
    return (uint32_t)(low + ((uint64_t)1u << (e - J288_RT_HIST_SUB_BITS)) - 1u);
}

void j288_rt_hist_add(j288_rt_hist_t *h, uint32_t value)
{
    unsigned i = bucket_of(value);
    if (h->n == UINT32_MAX)
        return; /* full: the percentiles stand as they are */
    h->n++;
    h->count[i]++;
    if (value > h->max)
        h->max = value;
}

uint32_t j288_rt_hist_quantile(const j288_rt_hist_t *h, uint32_t q_ppm)
{
    uint64_t rank, seen = 0;
    unsigned i;
    if (h->n == 0u)
        return 0;
    if (q_ppm > 1000000u)
        q_ppm = 1000000u;
    /* nearest rank: the smallest value with at least q * n values at or below it */
    rank = ((uint64_t)h->n * q_ppm + 999999u) / 1000000u;
    if (rank == 0u)
        rank = 1;
    for (i = 0; i < J288_RT_HIST_BUCKETS; i++) {
        seen += h->count[i];
        if (seen >= rank) {
            uint32_t top = bucket_top(i);
            return top < h->max ? top : h->max;
        }
    }
    return h->max;
}

void j288_rt_timing_reset(j288_rt_timing_t *t)
{
    uint32_t period = t->period_us;
    memset(t, 0, sizeof *t);
    t->period_us = period;
}

static void summarise(const j288_rt_hist_t *h, j288_rt_summary_t *s)
{
    s->count = h->n;
    s->p50_us = j288_rt_hist_quantile(h, 500000u);
    s->p99_us = j288_rt_hist_quantile(h, 990000u);
    s->p999_us = j288_rt_hist_quantile(h, 999000u);
    s->max_us = h->max;
}

void j288_rt_report(const j288_rt_timing_t *t, const j288_rt_status_t *st, j288_rt_report_t *out)
{
    memset(out, 0, sizeof *out);
    out->cycles = t->duration.n;
    out->period_us = t->period_us;
    out->missed = t->missed;
    out->skipped = t->skipped;
    out->cut = t->cut;
    summarise(&t->lateness, &out->lateness);
    summarise(&t->duration, &out->duration);
    out->cpu = -1;
    if (st != NULL) { /* what is in effect (an all-zero status: nothing) */
        out->priority = st->sched_changed ? st->priority : 0;
        out->cpu = st->affinity_changed ? st->cpu : -1;
        out->memory_locked = st->memory_locked ? 1u : 0u;
    }
}

char *j288_rt_format(const j288_rt_report_t *rep, char *buf, size_t len)
{
    char rate[32] = "back to back", what[64];
    size_t n;
    int k;
    if (len == 0u)
        return buf;
    if (rep->period_us != 0u)
        (void)snprintf(rate, sizeof rate, "at %.6g Hz", 1e6 / (double)rep->period_us);
    if (rep->priority > 0)
        k = snprintf(what, sizeof what, "SCHED_FIFO %d", (int)rep->priority);
    else
        k = snprintf(what, sizeof what, "normal priority");
    if (k > 0 && (size_t)k < sizeof what && rep->cpu >= 0)
        (void)snprintf(what + k, sizeof what - (size_t)k, ", CPU %d", (int)rep->cpu);
    if (rep->memory_locked != 0u) {
        n = strlen(what);
        (void)snprintf(what + n, sizeof what - n, ", memory locked");
    }
    k = snprintf(buf, len,
                 "timing: %lu cycles %s (%s): %lu deadlines missed, %lu periods skipped, "
                 "%lu cycles cut at their bound\n",
                 (unsigned long)rep->cycles, rate, what, (unsigned long)rep->missed,
                 (unsigned long)rep->skipped, (unsigned long)rep->cut);
    n = (k < 0) ? 0u : ((size_t)k < len ? (size_t)k : len - 1u);
    k = snprintf(buf + n, len - n,
                 "timing: wake-up lateness p50 %lu us, p99 %lu us, p99.9 %lu us, max %lu us "
                 "(%lu wake-ups)\n",
                 (unsigned long)rep->lateness.p50_us, (unsigned long)rep->lateness.p99_us,
                 (unsigned long)rep->lateness.p999_us, (unsigned long)rep->lateness.max_us,
                 (unsigned long)rep->lateness.count);
    n += (k < 0) ? 0u : ((size_t)k < len - n ? (size_t)k : len - n - 1u);
    (void)snprintf(buf + n, len - n,
                   "timing: cycle duration p50 %lu us, p99 %lu us, p99.9 %lu us, max %lu us\n",
                   (unsigned long)rep->duration.p50_us, (unsigned long)rep->duration.p99_us,
                   (unsigned long)rep->duration.p999_us, (unsigned long)rep->duration.max_us);
    return buf;
}

/* ---- pacing ---------------------------------------------------------------------------------- */

static uint32_t to_us(uint64_t ns)
{
    uint64_t us = ns / 1000u;
    return us > UINT32_MAX ? UINT32_MAX : (uint32_t)us;
}

void j288_rt_pace_restart(j288_rt_pacer_t *p)
{
    p->started = false;
}

bool j288_rt_pace_next_due(const j288_rt_pacer_t *p, uint64_t period_ns, uint64_t *due_ns)
{
    if (!p->started || period_ns == 0u || period_ns != p->period_ns)
        return false;
    *due_ns = p->due_ns + period_ns;
    return true;
}

bool j288_rt_pace_begin(j288_rt_pacer_t *p, j288_rt_timing_t *t, uint64_t period_ns,
                        uint64_t now_ns, uint64_t *until_ns)
{
    uint64_t due;
    if (p->started)
        j288_rt_hist_add(&t->duration, to_us(now_ns - p->start_ns));
    t->period_us = to_us(period_ns);
    if (!j288_rt_pace_next_due(p, period_ns, &due)) {
        /* the schedule's first cycle (or back to back): due now */
        p->started = true;
        p->period_ns = period_ns;
        p->due_ns = now_ns;
        return false;
    }
    if (now_ns < due) {
        p->due_ns = due;
        *until_ns = due;
        return true;
    }
    /* Missed: start at once; whole periods behind are dropped, not run back to back. */
    {
        uint64_t behind = (now_ns - due) / period_ns; /* whole periods past the deadline */
        uint64_t skipped = (uint64_t)t->skipped + behind;
        if (t->missed != UINT32_MAX)
            t->missed++;
        t->skipped = skipped > UINT32_MAX ? UINT32_MAX : (uint32_t)skipped;
        p->due_ns = due + behind * period_ns;
    }
    return false;
}

void j288_rt_pace_woke(j288_rt_pacer_t *p, j288_rt_timing_t *t, uint64_t now_ns, bool slept)
{
    if (slept)
        j288_rt_hist_add(&t->lateness, now_ns > p->due_ns ? to_us(now_ns - p->due_ns) : 0u);
    p->start_ns = now_ns;
}
