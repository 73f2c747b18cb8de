/*
 * j288 fault soak: the Linux port and the cycle scheduler against j288-sim on a pseudo-terminal,
 * with faults injected by the simulator, then without.
 *
 *   soak SIM [--txns N] [--ids LIST] [--margin-us N] [--seed N]
 *
 * Phase 1 (faults): j288-sim --corrupt 0.01 --drop 0.01 --late 0.001 --late-us 30000
 * --noise 0.01 --dup D (a second servo answers to id D: duplicate-id replies on the wire), and
 * scheduler sweeps over every id in LIST until N transactions have run. Every servo holds a
 * lock command, so a genuine reply from servo i reports the same position, speed, torque,
 * voltage and faults every time (the duplicate servo at id D has its own position: two values
 * are allowed there). After each sweep every slot has had exactly one transaction, and:
 *  - a successful one carries a reply with the slot's id and those constant values: a corrupt
 *    frame accepted or a reply credited to the wrong servo or transaction would show up here;
 *  - its result is tallied by cause; at the end each slot's statistics must equal the tally
 *    (every failure counted, under the cause the transaction reported), the slot counters
 *    must add up (transactions = successes + failures), and the bus's transaction count must
 *    equal the slots' sum;
 *  - failures are explained by the injected faults: no more failures than faults the
 *    simulator reports having injected (its statistics line), and at least one timeout and
 *    one CRC error when it dropped and corrupted replies.
 * Phase 2 (faults stop): a fresh j288-sim without faults (same seed: the same servos), the
 * same scheduler (its slots keep their offline/failure state) on a re-initialised bus: the
 * first sweep must bring every servo back (all successful, all online), and 1000 more
 * transactions must all succeed.
 * Leaks: the process's open file descriptors are the same before and after; run it under
 * valgrind (make soak-short does when valgrind is there) for memory.
 * Exit status 0 when every check passed; one summary line on stdout either way.
 */
#define _GNU_SOURCE 1 /* kill, fork, pipe, waitpid, dirent under -std=c99 */

#include <dirent.h>
#include <errno.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include "j288/j288.h"
#include "j288_linux.h"

#define MAX_ARGS 40

typedef struct {
    pid_t pid;
    int err_fd;
    char pty[256];
} sim_t;

typedef struct {
    unsigned long long replies, dropped, corrupted, late, noise, duplicates, lost;
    int parsed;
} sim_stats_t;

typedef struct {
    uint32_t transactions, successes, timeouts, crc_errors, wrong_id, collisions, other;
} tally_t;

typedef struct {
    bool have;
    int nvalues;
    int32_t pos[2];
    int16_t speed, torque;
    uint8_t voltage;
    uint32_t faults;
} baseline_t;

static unsigned long g_failures;

#define CHECK(cond, ...)                                                                       \
    do {                                                                                       \
        if (!(cond)) {                                                                         \
            fprintf(stderr, "soak: FAIL %s:%d: ", __FILE__, __LINE__);                         \
            fprintf(stderr, __VA_ARGS__);                                                      \
            fputc('\n', stderr);                                                               \
            g_failures++;                                                                      \
        }                                                                                      \
    } while (0)

static int count_fds(void)
{
    DIR *d = opendir("/proc/self/fd");
    struct dirent *e;
    int n = 0;
    if (d == NULL) {
        return -1;
    }
    while ((e = readdir(d)) != NULL) {
        if (e->d_name[0] != '.') {
            n++;
        }
    }
    closedir(d);
    return n - 1; /* the directory's own descriptor */
}

/* Start j288-sim with args; read the pty path from its stdout; keep its stderr. */
static int sim_start(sim_t *s, const char *sim, const char *const *args)
{
    int out[2], err[2];
    const char *argv[MAX_ARGS];
    size_t n = 0, got = 0;
    struct pollfd pfd;

    argv[n++] = sim;
    while (args[n - 1u] != NULL && n < MAX_ARGS - 1u) {
        argv[n] = args[n - 1u];
        n++;
    }
    argv[n] = NULL;
    if (pipe(out) != 0 || pipe(err) != 0) {
        return -1;
    }
    s->pid = fork();
    if (s->pid < 0) {
        return -1;
    }
    if (s->pid == 0) {
        (void)dup2(out[1], 1);
        (void)dup2(err[1], 2);
        (void)close(out[0]);
        (void)close(out[1]);
        (void)close(err[0]);
        (void)close(err[1]);
        execv(sim, (char *const *)argv);
        fprintf(stderr, "soak: cannot run %s: %s\n", sim, strerror(errno));
        _exit(127);
    }
    (void)close(out[1]);
    (void)close(err[1]);
    s->err_fd = err[0];
    pfd.fd = out[0];
    pfd.events = POLLIN;
    while (got < sizeof s->pty - 1u) {
        if (poll(&pfd, 1, 5000) <= 0 || read(out[0], &s->pty[got], 1) != 1 ||
            s->pty[got] == '\n') {
            break;
        }
        got++;
    }
    s->pty[got] = '\0';
    (void)close(out[0]);
    return (strncmp(s->pty, "/dev/", 5) == 0) ? 0 : -1;
}

/* SIGTERM, reap, and parse its statistics line. */
static void sim_stop(sim_t *s, sim_stats_t *st)
{
    char buf[8192];
    size_t got = 0;
    int status = 0;
    const char *line;
    memset(st, 0, sizeof *st);
    (void)kill(s->pid, SIGTERM);
    for (;;) {
        ssize_t r = read(s->err_fd, &buf[got], sizeof buf - 1u - got);
        if (r <= 0) {
            break;
        }
        got += (size_t)r;
        if (got == sizeof buf - 1u) {
            break;
        }
    }
    buf[got] = '\0';
    (void)close(s->err_fd);
    (void)waitpid(s->pid, &status, 0);
    line = strstr(buf, "j288-sim: stats:");
    if (line != NULL) {
        unsigned long long b, c, bc, bad, oth;
        st->parsed = sscanf(line,
                            "j288-sim: stats: bytes %llu commands %llu broadcast %llu bad-crc "
                            "%llu other-ids %llu replies %llu dropped %llu corrupted %llu late "
                            "%llu noise %llu duplicates %llu",
                            &b, &c, &bc, &bad, &oth, &st->replies, &st->dropped, &st->corrupted,
                            &st->late, &st->noise, &st->duplicates) == 11;
        printf("%.*s", (int)strcspn(line, "\n") + 1, line);
    }
}

static void tally_result(tally_t *t, int result)
{
    t->transactions++;
    switch (result) {
    case J288_OK: t->successes++; break;
    case J288_ERR_TIMEOUT: t->timeouts++; break;
    case J288_ERR_CRC:
    case J288_ERR_TRUNCATED: t->crc_errors++; break;
    case J288_ERR_WRONG_ID: t->wrong_id++; break;
    case J288_ERR_COLLISION: t->collisions++; break;
    default: t->other++; break;
    }
}

/* A genuine reply from servo id: its id, and the values a locked servo keeps. */
static void check_reply(baseline_t *b, uint8_t id, const j288_reply_raw_t *r, bool dup)
{
    int k;
    bool known = false;
    CHECK(r->id == id, "slot %u credited a reply from id %u", id, r->id);
    if (!b->have) {
        b->have = true;
        b->nvalues = 1;
        b->pos[0] = r->pos;
        b->speed = r->speed;
        b->torque = r->torque;
        b->voltage = r->voltage_raw;
        b->faults = r->faults;
        return;
    }
    for (k = 0; k < b->nvalues; k++) {
        known = known || (b->pos[k] == r->pos);
    }
    if (!known && dup && b->nvalues < 2) {
        b->pos[b->nvalues++] = r->pos; /* the duplicate servo at this id */
        known = true;
    }
    CHECK(known, "servo %u: position %ld never seen before (corrupt or misattributed reply)",
          id, (long)r->pos);
    CHECK(r->speed == b->speed && r->torque == b->torque,
          "servo %u: speed/torque changed (%d/%d, was %d/%d)", id, r->speed, r->torque, b->speed,
          b->torque);
    CHECK(r->voltage_raw == b->voltage && r->faults == b->faults,
          "servo %u: voltage/faults changed", id);
}

static uint16_t parse_ids(const char *s)
{
    uint16_t m = 0;
    while (*s != '\0') {
        char *end;
        long v = strtol(s, &end, 10);
        if (end == s || v < 0 || v > 14) {
            return 0;
        }
        m = (uint16_t)(m | (1u << v));
        s = (*end == ',') ? end + 1 : end;
        if (*end != ',' && *end != '\0') {
            return 0;
        }
    }
    return m;
}

static int open_bus(j288_linux_t *lp, j288_bus_t *bus, const char *pty, uint32_t margin_us)
{
    j288_linux_options_t opt;
    memset(&opt, 0, sizeof opt);
    opt.margin_us = margin_us;
    opt.no_low_latency = true;
    if (j288_linux_open(lp, pty, 0, &opt) != J288_OK) {
        fprintf(stderr, "soak: %s\n", j288_linux_error(lp));
        return -1;
    }
    return (j288_linux_bus_init(lp, bus, NULL) == J288_OK) ? 0 : -1;
}

int main(int argc, char **argv)
{
    static j288_linux_t lp;
    static j288_bus_t bus;
    static j288_sched_t sched;
    static baseline_t base[J288_MAX_SERVOS];
    static tally_t tally[J288_MAX_SERVOS];
    const char *sim_path;
    const char *ids_text = "1,2,3,4,5";
    unsigned long txns = 100000ul, done_txns = 0;
    uint32_t margin_us = 10000u;
    const char *seed = "288";
    uint16_t ids;
    uint8_t dup_id = 0, id;
    char dup_text[8];
    sim_t sim;
    sim_stats_t st1, st2;
    tally_t sum;
    unsigned long sweeps = 0, injected, failures;
    int fds_before, fds_after, i;

    if (argc < 2) {
        fprintf(stderr, "usage: soak SIM [--txns N] [--ids LIST] [--margin-us N] [--seed N]\n");
        return 2;
    }
    sim_path = argv[1];
    for (i = 2; i + 1 < argc; i += 2) {
        if (strcmp(argv[i], "--txns") == 0) {
            txns = strtoul(argv[i + 1], NULL, 10);
        } else if (strcmp(argv[i], "--ids") == 0) {
            ids_text = argv[i + 1];
        } else if (strcmp(argv[i], "--margin-us") == 0) {
            margin_us = (uint32_t)strtoul(argv[i + 1], NULL, 10);
        } else if (strcmp(argv[i], "--seed") == 0) {
            seed = argv[i + 1];
        } else {
            fprintf(stderr, "soak: unknown option %s\n", argv[i]);
            return 2;
        }
    }
    ids = parse_ids(ids_text);
    if (ids == 0u || txns == 0u) {
        fprintf(stderr, "soak: bad --ids or --txns\n");
        return 2;
    }
    for (id = 0; id < J288_MAX_SERVOS; id++) {
        if ((ids & (1u << id)) != 0u) {
            dup_id = id; /* the highest id gets a duplicate */
        }
    }
    snprintf(dup_text, sizeof dup_text, "%u", dup_id);
    fds_before = count_fds();

    /* ---- phase 1: faults */
    {
        const char *args[] = {"--ids", ids_text, "--seed", seed, "--quiet", "--exit-after", "3600",
                              "--corrupt", "0.01", "--drop", "0.01", "--late", "0.001",
                              "--late-us", "30000", "--noise", "0.01", "--dup", dup_text, NULL};
        if (sim_start(&sim, sim_path, args) != 0 || open_bus(&lp, &bus, sim.pty, margin_us) != 0) {
            fprintf(stderr, "soak: cannot start the simulator or open %s\n", sim.pty);
            return 1;
        }
    }
    if (j288_sched_init(&sched, &bus, NULL) != J288_OK) {
        return 1;
    }
    for (id = 0; id < J288_MAX_SERVOS; id++) {
        if ((ids & (1u << id)) != 0u) {
            j288_cmd_raw_t c;
            memset(&c, 0, sizeof c);
            c.id = id;
            c.status = J288_MODE_LOCK;
            c.watchdog = true;
            (void)j288_sched_set_cmd(&sched, &c);
            (void)j288_sched_enable(&sched, id, true);
        }
    }
    while (done_txns < txns) {
        int rc = j288_linux_sweep(&lp, &sched, 0);
        CHECK(rc == J288_OK, "sweep %lu: %s", sweeps, j288_strerror(rc));
        if (rc != J288_OK) {
            break;
        }
        sweeps++;
        for (id = 0; id < J288_MAX_SERVOS; id++) {
            const j288_slot_t *sl = j288_sched_slot(&sched, id);
            if ((ids & (1u << id)) == 0u) {
                continue;
            }
            tally_result(&tally[id], sl->last_result);
            CHECK(sl->stats.transactions == tally[id].transactions,
                  "slot %u: %u transactions after %lu sweeps", id, sl->stats.transactions, sweeps);
            if (sl->last_result == J288_OK) {
                check_reply(&base[id], id, &sl->reply, id == dup_id);
            }
            done_txns++;
        }
        if (g_failures > 20u) {
            break;
        }
    }
    memset(&sum, 0, sizeof sum);
    for (id = 0; id < J288_MAX_SERVOS; id++) {
        const j288_slot_t *sl = j288_sched_slot(&sched, id);
        const j288_slot_stats_t *ss = &sl->stats;
        const tally_t *t = &tally[id];
        if ((ids & (1u << id)) == 0u) {
            continue;
        }
        CHECK(ss->successes == t->successes && ss->timeouts == t->timeouts &&
                  ss->crc_errors == t->crc_errors && ss->wrong_id == t->wrong_id &&
                  ss->collisions == t->collisions && ss->other_errors == t->other,
              "slot %u: statistics (ok %u to %u crc %u wid %u col %u oth %u) differ from the "
              "transactions' results (ok %u to %u crc %u wid %u col %u oth %u)",
              id, ss->successes, ss->timeouts, ss->crc_errors, ss->wrong_id, ss->collisions,
              ss->other_errors, t->successes, t->timeouts, t->crc_errors, t->wrong_id,
              t->collisions, t->other);
        CHECK(ss->transactions == ss->successes + ss->timeouts + ss->crc_errors + ss->wrong_id +
                                      ss->collisions + ss->other_errors,
              "slot %u: counters do not add up", id);
        sum.transactions += t->transactions;
        sum.successes += t->successes;
        sum.timeouts += t->timeouts;
        sum.crc_errors += t->crc_errors;
        sum.wrong_id += t->wrong_id;
        sum.collisions += t->collisions;
        sum.other += t->other;
    }
    CHECK(j288_bus_stats(&bus)->transactions == sum.transactions,
          "bus counted %u transactions, the slots %u", j288_bus_stats(&bus)->transactions,
          sum.transactions);
    j288_linux_close(&lp);
    sim_stop(&sim, &st1);
    CHECK(st1.parsed, "no statistics line from the simulator");
    failures = sum.transactions - sum.successes;
    injected = (unsigned long)(st1.dropped + st1.corrupted + st1.late + st1.noise +
                               st1.duplicates);
    printf("soak: phase 1: %u transactions in %lu sweeps: ok %u, timeout %u, crc %u, "
           "wrong-id %u, collision %u, other %u; bus: stale bytes %u, crc %u, wrong-id %u\n",
           sum.transactions, sweeps, sum.successes, sum.timeouts, sum.crc_errors, sum.wrong_id,
           sum.collisions, sum.other, j288_bus_stats(&bus)->stale_bytes,
           j288_bus_stats(&bus)->crc_errors, j288_bus_stats(&bus)->wrong_id);
    CHECK(failures <= injected, "%lu failures but only %lu injected faults", failures, injected);
    CHECK(st1.dropped == 0u || sum.timeouts > 0u, "replies dropped but no timeout counted");
    CHECK(st1.corrupted == 0u || sum.crc_errors + sum.timeouts > 0u,
          "replies corrupted but no CRC error counted");
    CHECK(sum.other == 0u && sum.collisions == 0u, "failures of an unexpected kind");

    /* ---- phase 2: the faults stop */
    {
        const char *args[] = {"--ids", ids_text, "--seed", seed, "--quiet", "--exit-after", "3600",
                              NULL};
        unsigned long n = 0;
        int rc;
        if (sim_start(&sim, sim_path, args) != 0 || open_bus(&lp, &bus, sim.pty, margin_us) != 0) {
            fprintf(stderr, "soak: cannot restart the simulator\n");
            return 1;
        }
        rc = j288_linux_sweep(&lp, &sched, 0);
        CHECK(rc == J288_OK, "first clean sweep: %s", j288_strerror(rc));
        for (id = 0; id < J288_MAX_SERVOS; id++) {
            const j288_slot_t *sl = j288_sched_slot(&sched, id);
            if ((ids & (1u << id)) != 0u) {
                CHECK(sl->last_result == J288_OK && sl->online,
                      "servo %u not back within one sweep (%s)", id,
                      j288_strerror(sl->last_result));
            }
        }
        while (n < 1000u && rc == J288_OK) {
            rc = j288_linux_sweep(&lp, &sched, 0);
            for (id = 0; id < J288_MAX_SERVOS; id++) {
                const j288_slot_t *sl = j288_sched_slot(&sched, id);
                if ((ids & (1u << id)) != 0u) {
                    CHECK(sl->last_result == J288_OK, "clean bus: servo %u failed (%s)", id,
                          j288_strerror(sl->last_result));
                    if (sl->last_result == J288_OK) {
                        check_reply(&base[id], id, &sl->reply, false);
                    }
                    n++;
                }
            }
            if (g_failures > 20u) {
                break;
            }
        }
        printf("soak: phase 2: %lu clean transactions, bus ok %u of %u\n", n,
               j288_bus_stats(&bus)->ok, j288_bus_stats(&bus)->transactions);
        j288_linux_close(&lp);
        sim_stop(&sim, &st2);
        CHECK(st2.dropped + st2.corrupted + st2.late + st2.noise + st2.duplicates == 0u,
              "the clean simulator injected faults");
    }
    fds_after = count_fds();
    CHECK(fds_before == fds_after, "file descriptors leaked: %d before, %d after", fds_before,
          fds_after);
    printf("soak: %s: %lu transactions with faults (%lu injected: dropped %llu corrupted %llu "
           "late %llu noise %llu duplicates %llu), %lu check failures\n",
           (g_failures == 0u) ? "PASS" : "FAIL", done_txns, injected, st1.dropped, st1.corrupted,
           st1.late, st1.noise, st1.duplicates, g_failures);
    return (g_failures == 0u) ? 0 : 1;
}
