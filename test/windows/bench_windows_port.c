/*
 * bench_windows_port - the Windows port against j288-sim (through Wine's COM mapping, or a
 * real adapter on Windows): round-trip latency of blocking transfers, back-to-back scheduler
 * sweeps over three servos, and the port's work per transaction (reads, waits). Under Wine the
 * figures are Wine's serial layer (a wineserver round trip per call), not Windows'.
 *
 * usage: bench_windows_port COMn [N [BAUD]]   (N default 5000, BAUD default 4000000: Wine's
 *        highest on a pseudo-terminal)
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "j288/j288.h"
#include "j288_serial.h"
#include "serial_loop.h"

static int cmp_u32(const void *a, const void *b)
{
    uint32_t x = *(const uint32_t *)a, y = *(const uint32_t *)b;
    return (x > y) - (x < y);
}

static void transfers(j288_serial_t *sp, j288_bus_t *bus, long n, uint32_t *lat)
{
    j288_serial_stats_t st0 = *j288_serial_stats(sp);
    const j288_serial_stats_t *st = j288_serial_stats(sp);
    j288_cmd_raw_t c;
    j288_txn_t txn;
    uint32_t t0, t1;
    long i, ok = 0;
    memset(&c, 0, sizeof c);
    c.id = 1;
    c.watchdog = true;
    t0 = j288_serial_now_us();
    for (i = 0; i < n; i++) {
        if (j288_bus_transfer_blocking(bus, &c, &txn) == J288_OK)
            lat[ok++] = txn.latency_us;
    }
    t1 = j288_serial_now_us();
    qsort(lat, (size_t)ok, sizeof *lat, cmp_u32);
    printf("blocking transfers: %ld of %ld ok, %.0f per second\n", ok, n,
           (double)n * 1e6 / (double)(t1 - t0));
    if (ok > 0)
        printf("  latency us (command start to reply taken): p50 %lu  p90 %lu  p99 %lu  max %lu\n",
               (unsigned long)lat[ok / 2], (unsigned long)lat[ok * 9 / 10],
               (unsigned long)lat[ok * 99 / 100], (unsigned long)lat[ok - 1]);
    printf("  per transaction: %.2f waits, %.2f reads in flight (%.2f ended empty), %.1f bytes "
           "out, %.1f bytes in\n",
           (double)(st->waits - st0.waits) / (double)n, (double)(st->reads - st0.reads) / (double)n,
           (double)(st->empty_reads - st0.empty_reads) / (double)n,
           (double)(st->tx_bytes - st0.tx_bytes) / (double)n,
           (double)(st->rx_bytes - st0.rx_bytes) / (double)n);
}

static void sweeps(j288_serial_t *sp, j288_bus_t *bus, long n)
{
    j288_sched_t s;
    uint32_t t0, t1, waits0;
    uint8_t id;
    long i, done = 0;
    (void)j288_sched_init(&s, bus, NULL);
    for (id = 1; id <= 3; id++)
        (void)j288_sched_enable(&s, id, true);
    waits0 = j288_serial_stats(sp)->waits;
    t0 = j288_serial_now_us();
    for (i = 0; i < n; i++)
        if (serial_loop_sweep(sp, bus, &s, 0) == J288_OK)
            done++;
    t1 = j288_serial_now_us();
    printf("back-to-back sweeps over 3 servos: %ld of %ld complete, %.0f sweeps per second, "
           "%.2f waits per sweep\n",
           done, n, (double)n * 1e6 / (double)(t1 - t0),
           (double)(j288_serial_stats(sp)->waits - waits0) / (double)n);
    for (id = 1; id <= 3; id++) {
        const j288_slot_t *sl = j288_sched_slot(&s, id);
        printf("  servo %u: %lu ok, %lu timeouts, worst latency %lu us\n", (unsigned)id,
               (unsigned long)sl->stats.successes, (unsigned long)sl->stats.timeouts,
               (unsigned long)sl->stats.worst_latency_us);
    }
}

int main(int argc, char **argv)
{
    long n = (argc > 2) ? strtol(argv[2], NULL, 10) : 5000;
    uint32_t baud = (argc > 3) ? (uint32_t)strtoul(argv[3], NULL, 10) : 4000000u;
    j288_serial_options_t opt;
    j288_serial_t sp;
    j288_bus_t bus;
    uint32_t *lat;
    if (argc < 2 || n < 10 || n > 1000000) {
        fprintf(stderr, "usage: %s COMn [N (10..1000000) [BAUD]]\n", argv[0]);
        return 2;
    }
    lat = calloc((size_t)n, sizeof *lat);
    memset(&opt, 0, sizeof opt);
    opt.margin_us = 10000;
    if (lat == NULL || j288_serial_open(&sp, argv[1], baud, &opt) != J288_OK ||
        j288_serial_bus_init(&sp, &bus, NULL) != J288_OK) {
        fprintf(stderr, "%s\n", j288_serial_error(&sp));
        free(lat);
        return 1;
    }
    printf("%s at %lu baud\n", argv[1], (unsigned long)j288_serial_baud(&sp));
    transfers(&sp, &bus, n, lat);
    sweeps(&sp, &bus, n / 3);
    j288_serial_close(&sp);
    free(lat);
    return 0;
}
