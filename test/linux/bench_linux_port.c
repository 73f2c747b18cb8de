/*
 * bench_linux_port - the Linux port against j288-sim over a pseudo-terminal: round-trip
 * latency of blocking transfers, back-to-back scheduler sweeps over three servos, and the
 * port's system-call work per transaction. Wall-clock figures on a shared machine are
 * indicative only; the per-transaction counts are not timing-dependent.
 *
 * usage: bench_linux_port [SIM [N]]   (SIM default: the path compiled in, N default 5000)
 */
#define _GNU_SOURCE 1

#include <errno.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "j288/j288.h"
#include "j288_serial.h"
#include "serial_loop.h"

#ifndef J288_SIM_DEFAULT
#define J288_SIM_DEFAULT "build/bin/j288-sim"
#endif

static pid_t start_sim(const char *sim, char *pty, size_t cap)
{
    int fds[2];
    size_t got = 0;
    struct pollfd pfd;
    pid_t pid;
    if (pipe(fds) != 0)
        return -1;
    pid = fork();
    if (pid == 0) {
        (void)dup2(fds[1], 1);
        (void)close(fds[0]);
        (void)close(fds[1]);
        execl(sim, sim, "--quiet", "--ids", "1,2,3", "--exit-after", "120", (char *)NULL);
        _exit(127);
    }
    (void)close(fds[1]);
    pfd.fd = fds[0];
    pfd.events = POLLIN;
    while (got + 1u < cap && poll(&pfd, 1, 5000) > 0) {
        if (read(fds[0], pty + got, 1) != 1 || pty[got] == '\n')
            break;
        got++;
    }
    pty[got] = '\0';
    (void)close(fds[0]);
    return pid;
}

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

int main(int argc, char **argv)
{
    const char *sim = (argc > 1) ? argv[1] : J288_SIM_DEFAULT;
    long n = (argc > 2) ? strtol(argv[2], NULL, 10) : 5000;
    char pty[128];
    j288_serial_t sp;
    j288_serial_options_t opt;
    j288_bus_t bus;
    j288_sched_t s;
    j288_cmd_raw_t c;
    j288_txn_t txn;
    uint32_t *lat, t0, t1, waits0;
    j288_serial_stats_t st0;
    long i, ok = 0, sweeps = 0;
    pid_t pid;
    int status, rc = 0;

    if (n < 10 || n > 1000000) {
        fprintf(stderr, "N must be 10..1000000\n");
        return 2;
    }
    lat = calloc((size_t)n, sizeof *lat);
    pid = start_sim(sim, pty, sizeof pty);
    if (lat == NULL || pid < 0 || strncmp(pty, "/dev/", 5) != 0) {
        fprintf(stderr, "cannot start %s\n", sim);
        return 1;
    }
    memset(&opt, 0, sizeof opt);
    opt.margin_us = 10000;
    if (j288_serial_open(&sp, pty, 0, &opt) != J288_OK ||
        j288_serial_bus_init(&sp, &bus, NULL) != J288_OK) {
        fprintf(stderr, "%s\n", j288_serial_error(&sp));
        rc = 1;
        goto out;
    }
    memset(&c, 0, sizeof c);
    c.id = 1;
    c.watchdog = true;

    st0 = *j288_serial_stats(&sp);
    t0 = j288_serial_now_us();
    for (i = 0; i < n; i++) {
        if (j288_bus_transfer_blocking(&bus, &c, &txn) == J288_OK)
            lat[ok++] = txn.latency_us;
    }
    t1 = j288_serial_now_us();
    qsort(lat, (size_t)ok, sizeof *lat, cmp_u32);
    printf("blocking transfers: %ld of %ld ok, %.0f per second\n", ok, n,
           (double)n * 1e6 / (double)(t1 - t0));
    if (ok > 0)
        printf("  latency us (command start to reply taken): p50 %lu  p90 %lu  p99 %lu  "
               "max %lu\n",
               (unsigned long)lat[ok / 2], (unsigned long)lat[ok * 9 / 10],
               (unsigned long)lat[ok * 99 / 100], (unsigned long)lat[ok - 1]);
    {
        const j288_serial_stats_t *st = j288_serial_stats(&sp);
        printf("  per transaction: %.2f waits (ppoll), %.1f bytes out, %.1f bytes in, "
               "%.2f partial writes\n",
               (double)(st->waits - st0.waits) / (double)n,
               (double)(st->tx_bytes - st0.tx_bytes) / (double)n,
               (double)(st->rx_bytes - st0.rx_bytes) / (double)n,
               (double)(st->partial_writes - st0.partial_writes) / (double)n);
    }

    (void)j288_sched_init(&s, &bus, NULL);
    for (c.id = 1; c.id <= 3; c.id++)
        (void)j288_sched_enable(&s, c.id, true);
    waits0 = j288_serial_stats(&sp)->waits;
    t0 = j288_serial_now_us();
    for (i = 0; i < n / 3; i++)
        if (serial_loop_sweep(&sp, &bus, &s, 0) == J288_OK)
            sweeps++;
    t1 = j288_serial_now_us();
    printf("back-to-back sweeps over 3 servos: %ld of %ld complete, %.0f sweeps per second, "
           "%.2f waits per sweep\n",
           sweeps, n / 3, (double)(n / 3) * 1e6 / (double)(t1 - t0),
           (double)(j288_serial_stats(&sp)->waits - waits0) / (double)(n / 3));
    for (c.id = 1; c.id <= 3; c.id++) {
        const j288_slot_t *sl = j288_sched_slot(&s, c.id);
        printf("  servo %u: %lu ok, %lu timeouts, worst latency %lu us\n", (unsigned)c.id,
               (unsigned long)sl->stats.successes, (unsigned long)sl->stats.timeouts,
               (unsigned long)sl->stats.worst_latency_us);
    }
    j288_serial_close(&sp);
out:
    (void)kill(pid, SIGTERM);
    (void)waitpid(pid, &status, 0);
    free(lat);
    return rc;
}
