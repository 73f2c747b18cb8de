/*
 * Bus timing model: back-to-back sweeps of the scheduler over the fake port's virtual clock
 * (bytes timed at 6 Mbps 8N1, a configurable servo turnaround), compared with the pure wire
 * time of a transaction (46 bytes = 76.67 us). The host costs no virtual time here: what is
 * measured is the protocol and the engine's own gaps (turnaround, guard, whole-microsecond
 * deadlines), i.e. the best an MCU advancing the bus from its interrupts can reach.
 *
 *   bus_timing [--turnaround "0 10 20 50"] [--rx-latency NS] [--guard US]
 *       prints a markdown table.
 *   bus_timing --count N [--poll]
 *       runs N transactions over 15 servos (for callgrind: the library is entered only
 *       through fake_port_deliver, bench_poll and bench_start).
 */
#include "fake_port.h"
#include "j288/j288.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define WARMUP            5u
#define MEASURE           200u
#define WIRE_NS_PER_SERVO 76667.0 /* 46 bytes x 10 bits at 6 Mbps */

static fake_port_t fp;
static j288_bus_t bus;
static j288_sched_t sch;

typedef struct {
    uint32_t t0, t1;
    bool done;
} meter_t;

static void on_sweep(void *user, uint32_t sweep, uint32_t now_us)
{
    meter_t *m = (meter_t *)user;
    if (sweep == WARMUP) {
        m->t0 = now_us;
    }
    if (sweep == WARMUP + MEASURE) {
        m->t1 = now_us;
        m->done = true;
    }
}

/* Entry points kept out of line so that callgrind can count from them. */
void bench_poll(void *sched, uint32_t now_us);
void bench_poll(void *sched, uint32_t now_us)
{
    j288_sched_poll((j288_sched_t *)sched, now_us);
}
int bench_start(uint32_t now_us);
int bench_start(uint32_t now_us)
{
    return j288_sched_start_sweep(&sch, now_us);
}

static int setup(unsigned nservos, uint32_t turnaround_ns, uint32_t rx_latency_ns,
                 uint32_t guard_us, bool isr, meter_t *m)
{
    j288_bus_config_t bc;
    j288_sched_config_t sc;
    unsigned i;

    memset(&bc, 0, sizeof bc);
    memset(&sc, 0, sizeof sc);
    bc.advance_in_isr = isr;
    bc.turnaround_us = turnaround_ns / 1000u + 20u; /* allowance above the servo's delay */
    bc.guard_us = guard_us;
    sc.continuous = true;
    sc.on_sweep = on_sweep;
    sc.user = m;
    fake_port_init(&fp);
    fp.turnaround_ns = (turnaround_ns == 0u) ? 1u : turnaround_ns;
    fp.rx_latency_ns = rx_latency_ns;
    if ((j288_bus_init(&bus, &fp.ops, &fp, &bc) != J288_OK) ||
        (j288_sched_init(&sch, &bus, &sc) != J288_OK)) {
        return -1;
    }
    fake_port_attach(&fp, &bus);
    if (!isr) {
        fp.poll_fn = bench_poll;
        fp.poll_user = &sch;
    }
    for (i = 0u; i < nservos; i++) {
        j288_reply_raw_t r;
        memset(&r, 0, sizeof r);
        r.status = 1u;
        r.voltage_raw = 48u;
        r.pos = (int32_t)i * 100;
        fake_port_add_servo(&fp, (uint8_t)i, &r);
        (void)j288_sched_enable(&sch, (uint8_t)i, true);
    }
    return bench_start(0u);
}

/* Mean sweep time in us over MEASURE back-to-back sweeps, or a negative value on failure. */
static double sweep_us(unsigned nservos, uint32_t turnaround_ns, uint32_t rx_latency_ns,
                       uint32_t guard_us)
{
    meter_t m;
    unsigned i;
    memset(&m, 0, sizeof m);
    if (setup(nservos, turnaround_ns, rx_latency_ns, guard_us, true, &m) != J288_OK) {
        return -1.0;
    }
    while (!m.done && fp.now_ns < 10000000000ull) {
        fake_port_run_for(&fp, 1000000u);
    }
    if (!m.done) {
        return -1.0;
    }
    for (i = 0u; i < nservos; i++) {
        const j288_slot_t *sl = j288_sched_slot(&sch, (uint8_t)i);
        if (sl->stats.successes != sl->stats.transactions) {
            return -2.0; /* the model must not time out */
        }
    }
    return (double)(m.t1 - m.t0) / MEASURE;
}

static int table(const char *turnarounds, uint32_t rx_latency_ns, uint32_t guard_us)
{
    static const unsigned counts[3] = {1u, 4u, 15u};
    char buf[256];
    char *tok;

    printf("| servo turnaround | servos | sweep (us) | wire time (us) | ratio | sweeps/s |\n");
    printf("|---:|---:|---:|---:|---:|---:|\n");
    strncpy(buf, turnarounds, sizeof buf - 1u);
    buf[sizeof buf - 1u] = '\0';
    for (tok = strtok(buf, " ,"); tok != NULL; tok = strtok(NULL, " ,")) {
        uint32_t t_us = (uint32_t)strtoul(tok, NULL, 10);
        unsigned k;
        for (k = 0u; k < 3u; k++) {
            double s = sweep_us(counts[k], t_us * 1000u, rx_latency_ns, guard_us);
            double wire = counts[k] * WIRE_NS_PER_SERVO / 1000.0;
            if (s < 0.0) {
                fprintf(stderr, "bus_timing: model failed (%d servos, %u us)\n", counts[k],
                        (unsigned)t_us);
                return 1;
            }
            printf("| %u us | %u | %.1f | %.1f | %.3f | %.0f |\n", (unsigned)t_us, counts[k], s,
                   wire, s / wire, 1e6 / s);
        }
    }
    return 0;
}

/* N transactions over 15 servos, for instruction counting. */
static int count_run(unsigned long n, bool isr)
{
    meter_t m;
    memset(&m, 0, sizeof m);
    if (setup(15u, 10000u, 0u, 0u, isr, &m) != J288_OK) {
        return 1;
    }
    while (j288_bus_stats(&bus)->transactions < n) {
        fake_port_run_for(&fp, 100000u);
    }
    printf("%lu transactions, %lu ok\n", (unsigned long)j288_bus_stats(&bus)->transactions,
           (unsigned long)j288_bus_stats(&bus)->ok);
    return 0;
}

int main(int argc, char **argv)
{
    const char *turn = "0 10 20 50";
    uint32_t rx_latency_ns = 0u, guard_us = 0u;
    unsigned long count = 0u;
    bool poll = false;
    int i;

    for (i = 1; i < argc; i++) {
        if ((strcmp(argv[i], "--turnaround") == 0) && (i + 1 < argc)) {
            turn = argv[++i];
        } else if ((strcmp(argv[i], "--rx-latency") == 0) && (i + 1 < argc)) {
            rx_latency_ns = (uint32_t)strtoul(argv[++i], NULL, 10);
        } else if ((strcmp(argv[i], "--guard") == 0) && (i + 1 < argc)) {
            guard_us = (uint32_t)strtoul(argv[++i], NULL, 10);
        } else if ((strcmp(argv[i], "--count") == 0) && (i + 1 < argc)) {
            count = strtoul(argv[++i], NULL, 10);
        } else if (strcmp(argv[i], "--poll") == 0) {
            poll = true;
        } else {
            fprintf(stderr, "usage: bus_timing [--turnaround \"0 10 20 50\"] [--rx-latency NS] "
                            "[--guard US] | --count N [--poll]\n");
            return 2;
        }
    }
    if (count != 0u) {
        return count_run(count, !poll);
    }
    return table(turn, rx_latency_ns, guard_us);
}
