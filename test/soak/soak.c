/*
 * j288 fault soak: the Linux port and the cycle scheduler against j288-sim on a pseudo-terminal,
 * with faults injected by the simulator, then, in the same run, without.
 *
 *   soak SIM [--txns N] [--ids LIST] [--margin-us N] [--seed N]
 *
 * One simulator process, one pty, one bus object and one scheduler for the whole run.
 *
 * Phase 1 (faults): j288-sim --corrupt 0.01 --drop 0.01 --late 0.001 --late-us 30000
 * --noise 0.01 --dup D (a second servo answers to id D: duplicate-id replies on the wire), and
 * scheduler sweeps over every id in LIST until N transactions have run, then on until a
 * sweep ends with a failure, so that the faults stop on an unhealthy bus. The scheduler
 * takes a servo offline at its first failure (offline_after 1) for the same reason: the
 * recovery below must bring offline servos back, not merely find them well. Every servo holds a
 * lock command, so a genuine reply from servo i reports the same position, speed, torque,
 * voltage and faults every time (the duplicate servo at id D has its own position: two values
 * are allowed there). After each sweep every slot has had exactly one transaction, and:
 *  - a successful one carries a reply with the slot's id and those constant values: a corrupt
 *    frame accepted or a reply credited to the wrong servo or transaction would show up here;
 *  - its result is tallied by cause; at the end each slot's statistics must equal the tally
 *    (every failure counted, under the cause the transaction reported), the slot counters
 *    must add up (transactions = successes + failures), and the bus's transaction, success
 *    and failure counts must equal the slots' sums (ok + failed + aborted = transactions);
 *  - failures are explained by the injected faults: no more failures than faults the
 *    simulator reports having injected, and at least one timeout and one CRC error when it
 *    dropped and corrupted replies;
 *  - a slot is online exactly when its last transaction succeeded, its ONLINE and OFFLINE
 *    events alternate, and no fault, warning or watchdog event ever comes from the locked
 *    servos (a corrupt reply taken for good could raise one).
 * Phase 2 (the faults stop): SIGUSR1 to the same simulator, which switches its wire faults
 * off and acknowledges on stderr with its statistics so far (phase 1's injected faults).
 * A late reply already scheduled still arrives when due, as a reply already on its way
 * would; so the soak first lets the bus sit idle for the late delay plus two reply budgets
 * (the last late reply has arrived, and had it fallen into a reply window that window and
 * the failure guard after it would be over; the stale bytes are counted, not taken). Then:
 * the very next sweep must bring every servo back (every slot successful and online, one
 * ONLINE event per servo that was offline), and
 * 1000 more transactions must all succeed, with no new timeout, CRC, wrong-id, collision,
 * line error or stale byte on the bus, and the simulator must report no fault injected
 * after the switch (each command after it answered exactly once). The phase 1 checks on the
 * statistics are repeated over the whole run.
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
#include "j288_serial.h"
#include "serial_loop.h"

#define MAX_ARGS         40
#define SIM_LATE_US      30000u /* --late-us below */
#define SIM_ERR_MAX      8192u
#define CLEAN_TXNS       1000ul /* phase 2, after the recovery sweep */
#define ACK_TIMEOUT_MS   10000
#define MAX_EXTRA_SWEEPS 10000ul /* to end the fault phase on a failed sweep */

typedef struct {
    pid_t pid;
    int err_fd;
    char pty[256];
    char err[SIM_ERR_MAX]; /* its stderr so far */
    size_t err_len;
} sim_t;

typedef struct {
    unsigned long long commands, replies, dropped, corrupted, late, noise, duplicates;
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

#define CHECK(cond, ...)                                                                           \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            fprintf(stderr, "soak: FAIL %s:%d: ", __FILE__, __LINE__);                             \
            fprintf(stderr, __VA_ARGS__);                                                          \
            fputc('\n', stderr);                                                                   \
            g_failures++;                                                                          \
        }                                                                                          \
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
    s->err_len = 0;
    s->err[0] = '\0';
    pfd.fd = out[0];
    pfd.events = POLLIN;
    while (got < sizeof s->pty - 1u) {
        if (poll(&pfd, 1, 5000) <= 0 || read(out[0], &s->pty[got], 1) != 1 || s->pty[got] == '\n') {
            break;
        }
        got++;
    }
    s->pty[got] = '\0';
    (void)close(out[0]);
    return (strncmp(s->pty, "/dev/", 5) == 0) ? 0 : -1;
}

/* Read what the simulator wrote on stderr, waiting up to timeout_ms for it. Returns 1 when
 * something was read, 0 when nothing came in time, -1 at end of file or with the buffer
 * full. */
static int sim_read_err(sim_t *s, int timeout_ms)
{
    struct pollfd pfd;
    ssize_t r;
    pfd.fd = s->err_fd;
    pfd.events = POLLIN;
    if (s->err_len >= sizeof s->err - 1u) {
        return -1;
    }
    if (poll(&pfd, 1, timeout_ms) <= 0) {
        return 0;
    }
    r = read(s->err_fd, &s->err[s->err_len], sizeof s->err - 1u - s->err_len);
    if (r <= 0) {
        return -1;
    }
    s->err_len += (size_t)r;
    s->err[s->err_len] = '\0';
    return 1;
}

/* Parse the complete statistics line that follows label ("j288-sim: stats:"). */
static bool sim_parse_stats(const sim_t *s, const char *label, sim_stats_t *st)
{
    const char *line = strstr(s->err, label);
    unsigned long long b, bc, bad, oth;
    memset(st, 0, sizeof *st);
    if (line == NULL || strchr(line, '\n') == NULL) {
        return false;
    }
    st->parsed = sscanf(line + strlen(label),
                        " bytes %llu commands %llu broadcast %llu bad-crc %llu other-ids %llu "
                        "replies %llu dropped %llu corrupted %llu late %llu noise %llu "
                        "duplicates %llu",
                        &b, &st->commands, &bc, &bad, &oth, &st->replies, &st->dropped,
                        &st->corrupted, &st->late, &st->noise, &st->duplicates) == 11;
    printf("%.*s", (int)strcspn(line, "\n") + 1, line);
    return st->parsed != 0;
}

/* SIGUSR1: the simulator's wire faults off. Waits for its acknowledgement, which carries
 * the statistics at the switch. */
static bool sim_faults_off(sim_t *s, sim_stats_t *st)
{
    static const char label[] = "j288-sim: faults off: stats:";
    int waited_ms = 0;
    if (kill(s->pid, SIGUSR1) != 0) {
        return false;
    }
    while (!sim_parse_stats(s, label, st)) {
        int rc = sim_read_err(s, 100);
        if (rc == 0) {
            waited_ms += 100;
        }
        if (rc < 0 || waited_ms >= ACK_TIMEOUT_MS) {
            return false;
        }
    }
    return true;
}

/* SIGTERM, reap, and parse its final statistics line. */
static void sim_stop(sim_t *s, sim_stats_t *st)
{
    int status = 0;
    (void)kill(s->pid, SIGTERM);
    while (sim_read_err(s, 5000) > 0) {
    }
    (void)close(s->err_fd);
    (void)waitpid(s->pid, &status, 0);
    (void)sim_parse_stats(s, "j288-sim: stats:", st);
}

static void tally_result(tally_t *t, int result)
{
    t->transactions++;
    switch (result) {
    case J288_OK:
        t->successes++;
        break;
    case J288_ERR_TIMEOUT:
        t->timeouts++;
        break;
    case J288_ERR_CRC:
    case J288_ERR_TRUNCATED:
        t->crc_errors++;
        break;
    case J288_ERR_WRONG_ID:
        t->wrong_id++;
        break;
    case J288_ERR_COLLISION:
        t->collisions++;
        break;
    default:
        t->other++;
        break;
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
    CHECK(known, "servo %u: position %ld never seen before (corrupt or misattributed reply)", id,
          (long)r->pos);
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

static int open_bus(j288_serial_t *sp, j288_bus_t *bus, const char *pty, uint32_t margin_us)
{
    j288_serial_options_t opt;
    memset(&opt, 0, sizeof opt);
    opt.margin_us = margin_us;
    opt.no_low_latency = true;
    if (j288_serial_open(sp, pty, 0, &opt) != J288_OK) {
        fprintf(stderr, "soak: %s\n", j288_serial_error(sp));
        return -1;
    }
    return (j288_serial_bus_init(sp, bus, NULL) == J288_OK) ? 0 : -1;
}

/* The whole run's state: one simulator, one port, one bus, one scheduler. */
typedef struct {
    j288_serial_t sp;
    j288_bus_t bus;
    j288_sched_t sched;
    baseline_t base[J288_MAX_SERVOS];
    tally_t tally[J288_MAX_SERVOS];
    uint16_t ids;
    uint8_t dup_id;
    unsigned long sweeps;
    unsigned long online_ev[J288_MAX_SERVOS], offline_ev[J288_MAX_SERVOS];
    unsigned long other_ev; /* fault, warning or watchdog events: a locked servo has none */
} soak_t;

static void on_event(void *user, const j288_event_t *ev)
{
    soak_t *k = user;
    if (ev->id >= J288_MAX_SERVOS) {
        k->other_ev++;
    } else if (ev->kind == J288_EV_ONLINE) {
        k->online_ev[ev->id]++;
    } else if (ev->kind == J288_EV_OFFLINE) {
        k->offline_ev[ev->id]++;
    } else {
        k->other_ev++;
    }
}

static bool in_ids(const soak_t *k, uint8_t id)
{
    return (k->ids & (1u << id)) != 0u;
}

static void enable_slots(soak_t *k)
{
    uint8_t id;
    for (id = 0; id < J288_MAX_SERVOS; id++) {
        if (in_ids(k, id)) {
            j288_cmd_raw_t c;
            memset(&c, 0, sizeof c);
            c.id = id;
            c.status = J288_MODE_LOCK;
            c.watchdog = true;
            (void)j288_sched_set_cmd(&k->sched, &c);
            (void)j288_sched_enable(&k->sched, id, true);
        }
    }
}

/* One sweep; every slot's result tallied and, when good, its reply checked. With clean, a
 * failure or an offline slot is a check failure too. Returns the sweep's status. */
static int sweep_checked(soak_t *k, bool clean, const char *what)
{
    uint8_t id;
    int rc = serial_loop_sweep(&k->sp, &k->bus, &k->sched, 0);
    CHECK(rc == J288_OK, "%s: sweep %lu: %s", what, k->sweeps, j288_strerror(rc));
    if (rc != J288_OK) {
        return rc;
    }
    k->sweeps++;
    for (id = 0; id < J288_MAX_SERVOS; id++) {
        const j288_slot_t *sl = j288_sched_slot(&k->sched, id);
        if (!in_ids(k, id)) {
            continue;
        }
        tally_result(&k->tally[id], sl->last_result);
        CHECK(sl->stats.transactions == k->tally[id].transactions,
              "slot %u: %u transactions after %lu sweeps", id, sl->stats.transactions, k->sweeps);
        if (sl->last_result == J288_OK) {
            check_reply(&k->base[id], id, &sl->reply, !clean && id == k->dup_id);
        }
        /* offline_after 1: online exactly when the last transaction succeeded, and the
         * events alternate (ONLINE first). */
        CHECK(sl->online == (sl->last_result == J288_OK), "slot %u: online %d after %s", id,
              (int)sl->online, j288_strerror(sl->last_result));
        CHECK(k->online_ev[id] - k->offline_ev[id] == (sl->online ? 1u : 0u),
              "slot %u: %lu ONLINE and %lu OFFLINE events, online %d", id, k->online_ev[id],
              k->offline_ev[id], (int)sl->online);
        if (clean) {
            CHECK(sl->last_result == J288_OK && sl->online, "%s: servo %u %s (%s)", what, id,
                  sl->online ? "failed" : "offline", j288_strerror(sl->last_result));
        }
    }
    return rc;
}

/* Each slot's statistics equal its tally and add up; the bus's counts equal the slots'
 * sums. Fills sum. */
static void check_statistics(const soak_t *k, tally_t *sum, const char *when)
{
    const j288_bus_stats_t *bs = j288_bus_stats(&k->bus);
    uint8_t id;
    memset(sum, 0, sizeof *sum);
    for (id = 0; id < J288_MAX_SERVOS; id++) {
        const j288_slot_stats_t *ss = &j288_sched_slot(&k->sched, id)->stats;
        const tally_t *t = &k->tally[id];
        if (!in_ids(k, id)) {
            continue;
        }
        CHECK(ss->successes == t->successes && ss->timeouts == t->timeouts &&
                  ss->crc_errors == t->crc_errors && ss->wrong_id == t->wrong_id &&
                  ss->collisions == t->collisions && ss->other_errors == t->other,
              "%s: slot %u: statistics (ok %u to %u crc %u wid %u col %u oth %u) differ from "
              "the transactions' results (ok %u to %u crc %u wid %u col %u oth %u)",
              when, id, ss->successes, ss->timeouts, ss->crc_errors, ss->wrong_id, ss->collisions,
              ss->other_errors, t->successes, t->timeouts, t->crc_errors, t->wrong_id,
              t->collisions, t->other);
        CHECK(ss->transactions == ss->successes + ss->timeouts + ss->crc_errors + ss->wrong_id +
                                      ss->collisions + ss->other_errors,
              "%s: slot %u: counters do not add up", when, id);
        sum->transactions += t->transactions;
        sum->successes += t->successes;
        sum->timeouts += t->timeouts;
        sum->crc_errors += t->crc_errors;
        sum->wrong_id += t->wrong_id;
        sum->collisions += t->collisions;
        sum->other += t->other;
    }
    CHECK(bs->transactions == sum->transactions, "%s: bus counted %u transactions, the slots %u",
          when, bs->transactions, sum->transactions);
    CHECK(bs->ok == sum->successes, "%s: bus counted %u successes, the slots %u", when, bs->ok,
          sum->successes);
    CHECK(bs->failed == sum->transactions - sum->successes && bs->aborted == 0u,
          "%s: bus counted %u failed and %u aborted, the slots %u failures", when, bs->failed,
          bs->aborted, sum->transactions - sum->successes);
    CHECK(bs->transactions == bs->ok + bs->failed + bs->aborted,
          "%s: bus transactions %u != ok %u + failed %u + aborted %u between sweeps", when,
          bs->transactions, bs->ok, bs->failed, bs->aborted);
}

/* The bus's failure and stale-byte counters, to compare before and after the clean phase. */
static void failure_counters(const j288_bus_t *bus, uint32_t c[6])
{
    const j288_bus_stats_t *bs = j288_bus_stats(bus);
    c[0] = bs->timeouts;
    c[1] = bs->crc_errors;
    c[2] = bs->wrong_id;
    c[3] = bs->collisions;
    c[4] = bs->line_errors;
    c[5] = bs->stale_bytes;
}

static unsigned long long injected_faults(const sim_stats_t *st)
{
    return st->dropped + st->corrupted + st->late + st->noise + st->duplicates;
}

int main(int argc, char **argv)
{
    static soak_t k;
    const char *sim_path;
    const char *ids_text = "1,2,3,4,5";
    unsigned long txns = 100000ul, done_txns = 0, clean_txns = 0;
    uint32_t margin_us = 10000u, settle_us, stale_settle, recovery_us;
    const char *seed = "288";
    char dup_text[8], late_text[16];
    sim_t sim;
    sim_stats_t st_off, st_end;
    tally_t sum1, sum;
    uint32_t fail_before[6], fail_after[6];
    unsigned long failures, offline_at_switch = 0, failed_last_sweep = 0, extra_sweeps = 0;
    unsigned long online_ev_at_switch = 0, online_ev_recovery = 0;
    j288_sched_config_t scfg;
    int fds_before, fds_after, i;
    bool recovered;
    uint8_t id;

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
    k.ids = parse_ids(ids_text);
    if (k.ids == 0u || txns == 0u) {
        fprintf(stderr, "soak: bad --ids or --txns\n");
        return 2;
    }
    for (id = 0; id < J288_MAX_SERVOS; id++) {
        if (in_ids(&k, id)) {
            k.dup_id = id; /* the highest id gets a duplicate */
        }
    }
    snprintf(dup_text, sizeof dup_text, "%u", k.dup_id);
    snprintf(late_text, sizeof late_text, "%u", SIM_LATE_US);
    fds_before = count_fds();

    /* Not --quiet: the simulator acknowledges SIGUSR1 on stderr. */
    {
        const char *args[] = {"--ids",  ids_text,    "--seed",    seed,      "--exit-after",
                              "3600",   "--corrupt", "0.01",      "--drop",  "0.01",
                              "--late", "0.001",     "--late-us", late_text, "--noise",
                              "0.01",   "--dup",     dup_text,    NULL};
        if (sim_start(&sim, sim_path, args) != 0 ||
            open_bus(&k.sp, &k.bus, sim.pty, margin_us) != 0) {
            fprintf(stderr, "soak: cannot start the simulator or open %s\n", sim.pty);
            return 1;
        }
    }
    /* A servo goes offline at its first failure, so that the switch below finds servos
     * offline and the recovery sweep has to bring them back. */
    memset(&scfg, 0, sizeof scfg);
    scfg.offline_after = 1u;
    scfg.on_event = on_event;
    scfg.user = &k;
    if (j288_sched_init(&k.sched, &k.bus, &scfg) != J288_OK) {
        return 1;
    }
    enable_slots(&k);

    /* ---- phase 1: faults, for txns transactions and then until a sweep ends with a servo
     * failed (offline): the faults stop on an unhealthy bus. */
    while ((done_txns < txns || failed_last_sweep == 0u) && g_failures <= 20u &&
           extra_sweeps < MAX_EXTRA_SWEEPS) {
        int rc = sweep_checked(&k, false, "faults");
        if (rc != J288_OK) {
            break;
        }
        extra_sweeps += (done_txns >= txns) ? 1u : 0u;
        failed_last_sweep = 0;
        for (id = 0; id < J288_MAX_SERVOS; id++) {
            if (in_ids(&k, id)) {
                done_txns++;
                failed_last_sweep +=
                    (j288_sched_slot(&k.sched, id)->last_result == J288_OK) ? 0u : 1u;
            }
        }
    }
    CHECK(failed_last_sweep > 0u, "no failed sweep in %lu more sweeps with faults", extra_sweeps);
    for (id = 0; id < J288_MAX_SERVOS; id++) {
        if (in_ids(&k, id)) {
            offline_at_switch += j288_sched_slot(&k.sched, id)->online ? 0u : 1u;
            online_ev_at_switch += k.online_ev[id];
        }
    }
    check_statistics(&k, &sum1, "faults");
    printf("soak: phase 1: %u transactions in %lu sweeps: ok %u, timeout %u, crc %u, "
           "wrong-id %u, collision %u, other %u; bus: stale bytes %u, crc %u, wrong-id %u\n",
           sum1.transactions, k.sweeps, sum1.successes, sum1.timeouts, sum1.crc_errors,
           sum1.wrong_id, sum1.collisions, sum1.other, j288_bus_stats(&k.bus)->stale_bytes,
           j288_bus_stats(&k.bus)->crc_errors, j288_bus_stats(&k.bus)->wrong_id);

    /* ---- the faults stop: same simulator, pty, bus and scheduler */
    if (!sim_faults_off(&sim, &st_off)) {
        CHECK(false, "no acknowledgement of SIGUSR1 from the simulator (stderr: %s)", sim.err);
    }
    failures = sum1.transactions - sum1.successes;
    CHECK(failures <= injected_faults(&st_off), "%lu failures but only %llu injected faults",
          failures, injected_faults(&st_off));
    /* (With one id, its duplicate answers too and covers a dropped reply.) */
    CHECK(st_off.dropped == 0u || sum1.timeouts > 0u || k.ids == (1u << k.dup_id),
          "replies dropped but no timeout counted");
    CHECK(st_off.corrupted == 0u || sum1.crc_errors + sum1.timeouts > 0u,
          "replies corrupted but no CRC error counted");
    CHECK(sum1.other == 0u && sum1.collisions == 0u, "failures of an unexpected kind");

    /* A late reply scheduled before the switch still comes, up to the late delay after its
     * command; the bus discards it, and a reply window it fell into (one budget) and the
     * failure guard after that (one budget) are over before the next sweep. */
    settle_us = SIM_LATE_US + 2u * j288_bus_reply_budget_us(&k.bus);
    stale_settle = j288_bus_stats(&k.bus)->stale_bytes;
    (void)serial_loop_run(&k.sp, &k.bus, &k.sched, j288_serial_now_us() + settle_us, 0u);
    stale_settle = j288_bus_stats(&k.bus)->stale_bytes - stale_settle;

    /* ---- phase 2: the very next sweep brings every servo back, then a clean bus */
    failure_counters(&k.bus, fail_before);
    {
        unsigned long before = g_failures;
        uint32_t t0 = j288_serial_now_us();
        int rc = sweep_checked(&k, true, "first sweep after the faults stopped");
        recovery_us = j288_serial_now_us() - t0;
        recovered = (rc == J288_OK && g_failures == before);
        for (id = 0; id < J288_MAX_SERVOS; id++) {
            online_ev_recovery += in_ids(&k, id) ? k.online_ev[id] : 0u;
        }
        online_ev_recovery -= online_ev_at_switch;
        CHECK(online_ev_recovery == offline_at_switch,
              "first sweep after the faults stopped: %lu ONLINE events for %lu servos offline",
              online_ev_recovery, offline_at_switch);
        while (rc == J288_OK && clean_txns < CLEAN_TXNS && g_failures <= 20u) {
            rc = sweep_checked(&k, true, "clean bus");
            for (id = 0; id < J288_MAX_SERVOS; id++) {
                clean_txns += in_ids(&k, id) ? 1u : 0u;
            }
        }
    }
    failure_counters(&k.bus, fail_after);
    CHECK(memcmp(fail_before, fail_after, sizeof fail_before) == 0,
          "clean bus: bus counters moved: timeouts %u->%u crc %u->%u wrong-id %u->%u "
          "collisions %u->%u line %u->%u stale bytes %u->%u",
          fail_before[0], fail_after[0], fail_before[1], fail_after[1], fail_before[2],
          fail_after[2], fail_before[3], fail_after[3], fail_before[4], fail_after[4],
          fail_before[5], fail_after[5]);
    check_statistics(&k, &sum, "whole run");
    CHECK(k.other_ev == 0u, "%lu fault, warning or watchdog events from locked servos", k.other_ev);
    printf("soak: phase 2: faults off, %u us settle (%u stale bytes discarded), first sweep "
           "after: %s; then %lu clean transactions; bus ok %u of %u\n",
           settle_us, stale_settle, recovered ? "all ok and online" : "NOT healthy", clean_txns,
           j288_bus_stats(&k.bus)->ok, j288_bus_stats(&k.bus)->transactions);
    printf("soak: at the switch %lu servo(s) offline (%lu extra sweeps to end on a failure); "
           "the first sweep after brought %lu back in %u us\n",
           offline_at_switch, extra_sweeps, online_ev_recovery, recovery_us);

    j288_serial_close(&k.sp);
    sim_stop(&sim, &st_end);
    CHECK(st_end.parsed, "no statistics line from the simulator");
    CHECK(injected_faults(&st_end) == injected_faults(&st_off),
          "the simulator injected faults after SIGUSR1 (%llu at the switch, %llu at the end)",
          injected_faults(&st_off), injected_faults(&st_end));
    CHECK(st_end.commands - st_off.commands == sum.transactions - sum1.transactions &&
              st_end.replies - st_off.replies == sum.transactions - sum1.transactions,
          "after SIGUSR1 the simulator saw %llu commands and sent %llu replies for %u "
          "transactions",
          st_end.commands - st_off.commands, st_end.replies - st_off.replies,
          sum.transactions - sum1.transactions);

    fds_after = count_fds();
    CHECK(fds_before == fds_after, "file descriptors leaked: %d before, %d after", fds_before,
          fds_after);
    printf("soak: %s: %lu transactions with faults (%llu injected: dropped %llu corrupted %llu "
           "late %llu noise %llu duplicates %llu), %lu check failures\n",
           (g_failures == 0u) ? "PASS" : "FAIL", done_txns, injected_faults(&st_off),
           st_off.dropped, st_off.corrupted, st_off.late, st_off.noise, st_off.duplicates,
           g_failures);
    return (g_failures == 0u) ? 0 : 1;
}
