/*
 * j288_robot.c - the host layer's runner (see j288_robot.h for the contract).
 *
 * Every bus is driven from one loop: poll each bus, then sleep in j288_serial_wait_any() over
 * all of their devices until bytes come or the earliest port deadline
 * (j288_serial_next_deadline()), then let each ready port service itself
 * (j288_serial_service()), so that reading, flushing and the vanished-device handling
 * stay in the port. Cycles, single transactions (j288_robot_transfer()), idle waits and the
 * stop all go through that loop.
 */
#include "j288_robot.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

/* While a transaction is pending, wake at least this often to let each bus check its reply
 * deadline (the port's timer gives the exact time when it is armed). */
#define SLICE_US 1000u
/* With a stop flag, never sleep longer than this. */
#define STOP_SLICE_US 20000u

/* Formats checked as C99's (%zu); mingw-w64's "printf" would check Microsoft's. */
#ifdef __MINGW_PRINTF_FORMAT
static void set_err(j288_robot_t *r, const char *fmt, ...)
    __attribute__((format(__MINGW_PRINTF_FORMAT, 2, 3)));
#else
static void set_err(j288_robot_t *r, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
#endif

static void set_err(j288_robot_t *r, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    (void)vsnprintf(r->err, sizeof r->err, fmt, ap);
    va_end(ap);
}

static int32_t us_until(uint32_t t, uint32_t now) { return (int32_t)(t - now); }

size_t j288_robot_sizeof(void) { return sizeof(j288_robot_t); }

const char *j288_robot_version(void) { return J288_VERSION_STRING; }

uint32_t j288_robot_now_us(void) { return j288_serial_now_us(); }

static bool bus_live(const j288_robot_bus_t *b) { return b->open && !b->stats.gone; }

static void emit(j288_robot_t *r, const j288_robot_event_t *ev)
{
    if (r->opt.on_event != NULL)
        r->opt.on_event(r->opt.user, ev);
}

/* A bus event, counted where no caller can miss it (cycle info, robot and bus stats). */
static void emit_bus(j288_robot_t *r, j288_robot_event_kind_t kind, unsigned bus)
{
    j288_robot_event_t ev;
    bool lost = kind == J288_ROBOT_EV_BUS_DOWN || kind == J288_ROBOT_EV_BUS_GONE;
    if (lost) {
        r->lost_pending++;
        r->stats.bus_losses++;
        r->bus[bus].stats.lost_at_us = j288_serial_now_us();
    } else {
        r->back_pending++;
        r->stats.bus_returns++;
        r->bus[bus].stats.back_at_us = j288_serial_now_us();
    }
    if (r->opt.stop_on_bus_loss && !r->bus_lost && lost) {
        r->bus_lost = true;
        r->lost_bus = bus;
    }
    memset(&ev, 0, sizeof ev);
    ev.kind = kind;
    ev.bus = bus;
    ev.joint = -1;
    emit(r, &ev);
}

/* ---- scheduler and joint hooks (called from inside j288_sched_poll) -------------------------- */

/* An event about servo id on bus b, with the joint that servo drives (-1: none). */
static j288_robot_event_t servo_on_bus(const j288_robot_bus_t *b, j288_robot_event_kind_t kind,
                                       uint8_t id)
{
    j288_robot_event_t ev;
    memset(&ev, 0, sizeof ev);
    ev.kind = kind;
    ev.bus = b->index;
    ev.id = id;
    ev.joint = (id < J288_MAX_SERVOS) ? b->joint_of[id] : -1;
    return ev;
}

static void on_servo_event(void *user, const j288_event_t *sev)
{
    j288_robot_bus_t *b = user;
    j288_robot_event_t ev = servo_on_bus(b, J288_ROBOT_EV_SERVO, sev->id);
    ev.servo_ev = *sev;
    emit(b->robot, &ev);
}

static void on_joint_event(void *user, const j288_joint_event_t *jev)
{
    j288_robot_bus_t *b = user;
    j288_robot_event_t ev = servo_on_bus(b, J288_ROBOT_EV_JOINT, jev->id);
    ev.joint_kind = jev->kind;
    ev.value = (double)jev->value;
    emit(b->robot, &ev);
}

/* A lock command: no torque, watchdog bit 0 (the watchdog policy in j288_robot.h). */
static void lock_cmd(uint8_t id, j288_cmd_raw_t *cmd)
{
    memset(cmd, 0, sizeof *cmd);
    cmd->id = id;
    cmd->status = J288_MODE_LOCK;
    cmd->watchdog = false;
}

/* Clear servo id's watchdog trip (its next command goes out with the bit 0) and report it. */
static void clear_trip(j288_robot_bus_t *b, uint8_t id, double why)
{
    j288_robot_event_t ev = servo_on_bus(b, J288_ROBOT_EV_WATCHDOG, id);
    (void)j288_sched_clear_watchdog(&b->sched, id);
    b->robot->wd_cleared++;
    ev.value = why;
    emit(b->robot, &ev);
}

/* The watchdog policy on a cycle's reply: a trip reported, or lock-mode replies to FOC
 * commands twice in a row (once could be a command set while the previous one was on the
 * wire), is cleared and reported. */
static void watch_reply(j288_robot_bus_t *b, uint8_t id, const j288_slot_t *slot)
{
    bool ignored = slot->cmd.status == J288_MODE_FOC && slot->reply.status == J288_MODE_LOCK;
    if (slot->reply.watchdog_tripped && !slot->clear_watchdog) {
        b->lock_under_foc[id] = 0;
        clear_trip(b, id, 1.0);
    } else if (ignored && !slot->clear_watchdog && ++b->lock_under_foc[id] >= 2u) {
        b->lock_under_foc[id] = 0;
        clear_trip(b, id, 2.0);
    } else if (!ignored) {
        b->lock_under_foc[id] = 0;
    }
}

static void on_reply(void *user, uint8_t id, const j288_slot_t *slot)
{
    j288_robot_bus_t *b = user;
    b->swept_ok = true;
    if (id >= J288_MAX_SERVOS)
        return;
    watch_reply(b, id, slot);
    j288_joint_bus_on_reply(&b->jb, id, slot);
    if (slot->cmd.status == J288_MODE_LOCK && slot->cmd.watchdog) {
        j288_cmd_raw_t lock; /* the joint layer's safe lock (angle lost): bit 0 as every lock */
        lock_cmd(id, &lock);
        (void)j288_sched_set_cmd(&b->sched, &lock);
    }
    if (b->joint_of[id] >= 0)
        b->robot->fresh_at[b->joint_of[id]] = b->robot->cycle;
}

/* A sweep ended: a bus whose sweeps keep coming back empty goes down, a reply brings it up. */
static void on_sweep(void *user, uint32_t sweep, uint32_t now_us)
{
    j288_robot_bus_t *b = user;
    j288_robot_t *r = b->robot;
    uint32_t took = now_us - b->sweep_start_us;
    (void)sweep;
    b->stats.sweeps++;
    b->stats.last_sweep_us = took;
    if (took > b->stats.worst_sweep_us)
        b->stats.worst_sweep_us = took;
    if (b->swept_ok) {
        b->empty_run = 0;
        if (!b->stats.up) {
            b->stats.up = true;
            b->stats.up_events++;
            emit_bus(r, J288_ROBOT_EV_BUS_UP, b->index);
        }
        return;
    }
    b->stats.empty_sweeps++;
    if (b->empty_run < UINT8_MAX)
        b->empty_run++;
    if (b->stats.up && b->empty_run >= r->opt.down_after) {
        b->stats.up = false;
        b->stats.down_events++;
        emit_bus(r, J288_ROBOT_EV_BUS_DOWN, b->index);
    }
}

/* ---- open and close -------------------------------------------------------------------------- */

static void reset_robot(j288_robot_t *r, const j288_robot_options_t *opt)
{
    memset(r, 0, sizeof *r);
    if (opt != NULL)
        r->opt = *opt;
    if (r->opt.down_after == 0u)
        r->opt.down_after = J288_ROBOT_DEFAULT_DOWN_AFTER;
    r->cycle = 1;
}

/* Names, devices and ids are checked here too: a config may be built by hand. */
static int check_config(j288_robot_t *r, const j288_robot_config_t *cfg)
{
    size_t i, k;
    if (cfg->nbuses > J288_ROBOT_MAX_BUSES) {
        set_err(r, "%zu buses: at most %u", cfg->nbuses, J288_ROBOT_MAX_BUSES);
        return J288_ERR_BAD_CONFIG;
    }
    if (cfg->njoints > J288_ROBOT_MAX_JOINTS) {
        set_err(r, "%zu joints: at most %u", cfg->njoints, J288_ROBOT_MAX_JOINTS);
        return J288_ERR_BAD_CONFIG;
    }
    if (cfg->nbuses == 0u && (r->opt.port == NULL || r->opt.port[0] == '\0')) {
        set_err(r, "the config names no bus and no port was given");
        return J288_ERR_BAD_CONFIG;
    }
    for (i = 0; i < cfg->nbuses; i++) {
        for (k = 0; k < i; k++) {
            if (strcmp(cfg->bus[i].name, cfg->bus[k].name) == 0) {
                set_err(r, "bus '%s' is named twice", cfg->bus[i].name);
                return J288_ERR_BAD_CONFIG;
            }
            if (strcmp(cfg->bus[i].port, cfg->bus[k].port) == 0) {
                set_err(r, "buses '%s' and '%s' are both on %s", cfg->bus[k].name,
                        cfg->bus[i].name, cfg->bus[i].port);
                return J288_ERR_BAD_CONFIG;
            }
        }
    }
    for (i = 0; i < cfg->njoints; i++) {
        const j288_robot_config_joint_t *a = &cfg->joint[i];
        int bi = (cfg->nbuses == 0u) ? 0 : a->bus;
        if (bi < 0 || (cfg->nbuses != 0u && (size_t)bi >= cfg->nbuses)) {
            set_err(r, "joint '%s' names no bus of the config", a->name);
            return J288_ERR_BAD_CONFIG;
        }
        if (a->id >= J288_MAX_SERVOS) {
            set_err(r, "joint '%s': id %u is not 0-14", a->name, (unsigned)a->id);
            return J288_ERR_BAD_CONFIG;
        }
        for (k = 0; k < i; k++) {
            const j288_robot_config_joint_t *b = &cfg->joint[k];
            int bk = (cfg->nbuses == 0u) ? 0 : b->bus;
            if (strcmp(a->name, b->name) == 0) {
                set_err(r, "joint '%s' is named twice", a->name);
                return J288_ERR_BAD_CONFIG;
            }
            if (bk == bi && a->id == b->id) {
                set_err(r, "joints '%s' and '%s' both use id %u on one bus", b->name, a->name,
                        (unsigned)a->id);
                return J288_ERR_BAD_CONFIG;
            }
        }
    }
    return J288_OK;
}

/* Two names for one device (a symlink and its target) would open it twice: the second open
 * would fail as "in use" by this very process, which says less than this. Checked before
 * opening bus i; a path that cannot be examined is left to the open to report. */
static int check_same_device(j288_robot_t *r, unsigned i, const char *port)
{
    unsigned k;
    for (k = 0; k < i; k++) {
        if (j288_serial_same_device(&r->bus[k].serial, port)) {
            set_err(r, "buses '%s' and '%s' are the same device", r->bus[k].name,
                    r->bus[i].name);
            return J288_ERR_BAD_CONFIG;
        }
    }
    return J288_OK;
}

/* Bus engine and scheduler on the open port (at open, and anew at a reopen). */
static int start_engine(j288_robot_t *r, j288_robot_bus_t *b)
{
    j288_bus_config_t bc;
    j288_sched_config_t sc;
    int rc;
    j288_serial_bus_config(&b->serial, &bc);
    bc.retries = r->opt.retries;
    rc = j288_serial_bus_init(&b->serial, &b->bus, &bc);
    if (rc != J288_OK)
        return rc;
    memset(&sc, 0, sizeof sc);
    sc.on_event = on_servo_event;
    sc.on_sweep = on_sweep;
    sc.on_reply = on_reply;
    sc.user = b;
    return j288_sched_init(&b->sched, &b->bus, &sc);
}

static int open_bus(j288_robot_t *r, unsigned i, const char *name, const char *port,
                    const j288_robot_config_bus_t *cb)
{
    j288_robot_bus_t *b = &r->bus[i];
    j288_serial_options_t lo;
    uint32_t baud = r->opt.baud;
    int rc;
    unsigned id;

    memset(&lo, 0, sizeof lo);
    lo.margin_us = r->opt.margin_us;
    lo.no_low_latency = r->opt.no_low_latency;
    lo.echo = r->opt.echo;
    if (cb != NULL) {
        if (cb->has_baud)
            baud = cb->baud;
        if (cb->has_margin_us)
            lo.margin_us = cb->margin_us;
        if (cb->has_echo)
            lo.echo = cb->echo;
    }
    b->robot = r;
    b->index = i;
    (void)snprintf(b->name, sizeof b->name, "%s", name);
    for (id = 0; id < J288_MAX_SERVOS; id++)
        b->joint_of[id] = -1;
    rc = check_same_device(r, i, port);
    if (rc != J288_OK)
        return rc;
    (void)snprintf(b->port, sizeof b->port, "%s", port);
    b->baud = baud;
    b->sopt = lo;
    rc = j288_serial_open(&b->serial, port, baud, &lo);
    if (rc != J288_OK) {
        set_err(r, "bus '%s': %s", name, j288_serial_error(&b->serial));
        return rc;
    }
    b->open = true;
    b->stats.up = true;
    rc = start_engine(r, b);
    if (rc == J288_OK)
        rc = j288_joint_bus_init(&b->jb, &b->sched, on_joint_event, b);
    if (rc != J288_OK)
        set_err(r, "bus '%s': %s", name, j288_strerror(rc));
    return rc;
}

static int add_joint(j288_robot_t *r, const j288_robot_config_joint_t *cj, unsigned bi)
{
    j288_robot_bus_t *b = &r->bus[bi];
    unsigned j = r->njoints;
    j288_joint_config_t jc;
    int rc;
    j288_robot_config_joint_config(cj, &jc);
    if (!cj->has_kp)
        jc.kp = (j288_real_t)J288_ROBOT_DEFAULT_KP;
    if (!cj->has_kd)
        jc.kd = (j288_real_t)J288_ROBOT_DEFAULT_KD;
    rc = j288_joint_init(&r->joint[j], &jc);
    if (rc == J288_OK)
        rc = j288_joint_bus_add(&b->jb, &r->joint[j]);
    if (rc == J288_OK)
        rc = j288_sched_enable(&b->sched, cj->id, true);
    if (rc == J288_OK) {
        j288_cmd_raw_t lock; /* the start-up reads: lock, bit 0 (clears an earlier trip) */
        lock_cmd(cj->id, &lock);
        rc = j288_sched_set_cmd(&b->sched, &lock);
    }
    if (rc != J288_OK) {
        set_err(r, "joint '%s': %s", cj->name, j288_strerror(rc));
        return (rc == J288_ERR_NULL) ? rc : J288_ERR_BAD_CONFIG;
    }
    b->joint_of[cj->id] = (int)j;
    r->joint_bus[j] = bi;
    (void)snprintf(r->joint_name[j], sizeof r->joint_name[j], "%s", cj->name);
    r->njoints++;
    return J288_OK;
}

/* The thread's real time (j288_rt.h), before any bus is opened: a CPU it may not run on is
 * refused with nothing opened (an open that fails later undoes it). */
static int setup_rt(j288_robot_t *r)
{
    j288_rt_options_t o;
    int rc;
    j288_rt_options_init(&o);
    o.priority = r->opt.realtime;
    if (r->opt.pin_cpu)
        o.cpu = r->opt.cpu;
    if (o.priority == 0 && o.cpu < 0)
        return J288_OK;
    rc = j288_rt_setup(&o, &r->rt);
    if (rc != J288_OK)
        set_err(r, "%.*s", (int)strcspn(r->rt.notice, "\n"), r->rt.notice);
    return rc;
}

static void close_buses(j288_robot_t *r)
{
    unsigned i;
    for (i = 0; i < J288_ROBOT_MAX_BUSES; i++) {
        if (r->bus[i].open)
            j288_serial_close(&r->bus[i].serial);
        r->bus[i].open = false;
    }
}

int j288_robot_open(j288_robot_t *r, const j288_robot_config_t *cfg,
                    const j288_robot_options_t *opt)
{
    size_t i;
    int rc;
    if (r == NULL)
        return J288_ERR_NULL;
    reset_robot(r, opt);
    if (cfg == NULL) {
        set_err(r, "no config");
        return J288_ERR_NULL;
    }
    rc = check_config(r, cfg);
    if (rc == J288_OK)
        rc = setup_rt(r);
    if (rc != J288_OK)
        return rc;
    if (cfg->nbuses == 0u) {
        rc = open_bus(r, 0, "bus", r->opt.port, NULL);
        r->nbuses = 1;
    }
    for (i = 0; rc == J288_OK && i < cfg->nbuses; i++) {
        rc = open_bus(r, (unsigned)i, cfg->bus[i].name, cfg->bus[i].port, &cfg->bus[i]);
        r->nbuses = (unsigned)i + 1u;
    }
    for (i = 0; rc == J288_OK && i < cfg->njoints; i++)
        rc = add_joint(r, &cfg->joint[i], (cfg->nbuses == 0u) ? 0u : (unsigned)cfg->joint[i].bus);
    if (rc != J288_OK) {
        j288_rt_restore(&r->rt);
        close_buses(r);
        r->nbuses = 0;
        r->njoints = 0;
    }
    return rc;
}

int j288_robot_open_file(j288_robot_t *r, const char *path, const j288_robot_options_t *opt)
{
    j288_robot_config_t cfg;
    char err[J288_ROBOT_CONFIG_ERROR_MAX];
    if (r == NULL)
        return J288_ERR_NULL;
    if (path == NULL) {
        reset_robot(r, opt);
        set_err(r, "no config file");
        return J288_ERR_NULL;
    }
    if (j288_robot_config_load(path, &cfg, err, sizeof err) != 0) {
        reset_robot(r, opt);
        set_err(r, "%s", err);
        return J288_ERR_BAD_CONFIG;
    }
    return j288_robot_open(r, &cfg, opt);
}

int j288_robot_open_port(j288_robot_t *r, const char *port, const j288_robot_options_t *opt)
{
    j288_robot_options_t o;
    static const j288_robot_config_t empty; /* zero buses, zero joints */
    if (r == NULL)
        return J288_ERR_NULL;
    if (opt != NULL)
        o = *opt;
    else
        memset(&o, 0, sizeof o);
    o.port = port;
    if (port == NULL || port[0] == '\0') {
        reset_robot(r, &o);
        set_err(r, "no port given");
        return J288_ERR_NULL;
    }
    return j288_robot_open(r, &empty, &o);
}

void j288_robot_close(j288_robot_t *r)
{
    if (r == NULL)
        return;
    if (r->driven)
        (void)j288_robot_stop(r);
    close_buses(r);
    j288_rt_restore(&r->rt);
}

void j288_robot_close_keep(j288_robot_t *r)
{
    if (r != NULL) {
        close_buses(r);
        j288_rt_restore(&r->rt);
    }
}

void j288_robot_set_stop_flag(j288_robot_t *r, const volatile sig_atomic_t *flag)
{
    if (r != NULL)
        r->stop_flag = flag;
}

/* ---- the loop -------------------------------------------------------------------------------- */

static bool stop_requested(const j288_robot_t *r)
{
    return r->stop_flag != NULL && *r->stop_flag != 0;
}

/* The device of bus b vanished: said once, the device closed at once (a USB adapter that
 * re-enumerates gets its old name back only once nobody holds the old node), its joints'
 * angles forgotten (the servos may well be power-cycled by the time it returns), and its
 * first reopen attempt due one interval later. */
static void bus_gone(j288_robot_t *r, j288_robot_bus_t *b, uint32_t now)
{
    unsigned j;
    b->stats.gone = true;
    b->stats.up = false;
    b->stats.gone_events++;
    set_err(r, "bus '%s': %s", b->name, j288_serial_error(&b->serial));
    j288_serial_close(&b->serial);
    for (j = 0; j < r->njoints; j++) {
        if (r->joint_bus[j] == b->index)
            j288_joint_reset(&r->joint[j]);
    }
    b->reopen_at_us = now + J288_ROBOT_REOPEN_US;
    emit_bus(r, J288_ROBOT_EV_BUS_GONE, b->index);
}

/* Poll every bus; report and leave out a bus whose device vanished. */
static void poll_all(j288_robot_t *r, uint32_t now)
{
    unsigned i;
    for (i = 0; i < r->nbuses; i++) {
        j288_robot_bus_t *b = &r->bus[i];
        if (!bus_live(b))
            continue;
        j288_sched_poll(&b->sched, now);
        if (j288_serial_offline(&b->serial))
            bus_gone(r, b, now);
    }
}

/* Open gone bus b's device again and restart the bus from scratch (j288_robot.h:
 * reconnection): engine and scheduler anew, the slots that were enabled enabled at lock
 * (watchdog bit 0), every joint's angle to be found again (reset when it went). False when
 * the device is not there (yet): the next attempt is an interval later. */
static bool reopen_bus(j288_robot_t *r, j288_robot_bus_t *b, uint32_t now)
{
    uint16_t enabled = 0;
    uint8_t id;
    b->reopen_at_us = now + J288_ROBOT_REOPEN_US;
    b->stats.reopen_attempts++;
    for (id = 0; id < J288_MAX_SERVOS; id++) {
        if (j288_sched_slot(&b->sched, id)->enabled)
            enabled = (uint16_t)(enabled | (1u << id));
    }
    if (j288_serial_open(&b->serial, b->port, b->baud, &b->sopt) != J288_OK)
        return false;
    if (start_engine(r, b) != J288_OK) { /* cannot fail on a port that opened: be safe */
        j288_serial_close(&b->serial);
        return false;
    }
    for (id = 0; id < J288_MAX_SERVOS; id++) {
        j288_cmd_raw_t lock;
        lock_cmd(id, &lock);
        (void)j288_sched_set_cmd(&b->sched, &lock);
        (void)j288_sched_enable(&b->sched, id, (enabled & (1u << id)) != 0u);
    }
    memset(b->lock_under_foc, 0, sizeof b->lock_under_foc);
    for (id = 0; id < J288_MAX_SERVOS; id++) /* the servo level's joints start anew too */
        if ((b->servo_joint_on & (1u << id)) != 0u)
            j288_joint_reset(&b->servo_joint[id]); /* (their configuration kept) */
    b->swept_ok = false;
    b->txn_done = false;
    b->empty_run = 0;
    b->stats.gone = false;
    b->stats.up = true;
    b->stats.reopens++;
    emit_bus(r, J288_ROBOT_EV_BUS_BACK, b->index);
    return true;
}

/* A gone bus that may be reopened: not one named by its pseudo-terminal (/dev/pts/N), whose
 * number goes to the next program that asks for a terminal (a link to it, as j288-sim's
 * --link, is removed and placed anew by whoever serves it). */
static bool reopenable(const j288_robot_bus_t *b)
{
    return b->open && b->stats.gone && strncmp(b->port, "/dev/pts/", 9) != 0;
}

/* Reconnection: every gone bus whose attempt is due tries its device once. */
static void reopen_due(j288_robot_t *r, uint32_t now)
{
    unsigned i;
    if (r->opt.no_reopen)
        return;
    for (i = 0; i < r->nbuses; i++) {
        j288_robot_bus_t *b = &r->bus[i];
        if (reopenable(b) && us_until(b->reopen_at_us, now) <= 0)
            (void)reopen_bus(r, b, now);
    }
}

/* The earliest reopen attempt due among the gone buses (false: none, or no reopening). */
static bool next_reopen(const j288_robot_t *r, uint32_t now, uint32_t *at)
{
    unsigned i;
    bool any = false;
    if (r->opt.no_reopen)
        return false;
    for (i = 0; i < r->nbuses; i++) {
        const j288_robot_bus_t *b = &r->bus[i];
        if (reopenable(b) && (!any || us_until(b->reopen_at_us, now) < us_until(*at, now))) {
            *at = b->reopen_at_us;
            any = true;
        }
    }
    return any;
}

static bool bus_pending(const j288_robot_bus_t *b)
{
    return j288_sched_busy(&b->sched) || !j288_bus_is_idle(&b->bus);
}

/* Sleep over every live bus until bytes come, a port's deadline is due (while a transaction
 * is pending, at least every SLICE_US), or until_us; then let each ready port read its device. */
static void wait_all(j288_robot_t *r, uint32_t now, uint32_t until_us)
{
    j288_serial_t *ports[J288_ROBOT_MAX_BUSES];
    bool ready[J288_ROBOT_MAX_BUSES];
    unsigned n = 0, i;
    int32_t left = us_until(until_us, now);

    for (i = 0; i < r->nbuses; i++) {
        j288_robot_bus_t *b = &r->bus[i];
        uint32_t at;
        if (!bus_live(b))
            continue;
        if (bus_pending(b) && left > (int32_t)SLICE_US)
            left = (int32_t)SLICE_US;
        if (j288_serial_next_deadline(&b->serial, &at) && us_until(at, now) <= 0) {
            (void)j288_serial_service(&b->serial); /* due now: deliver it rather than sleep 0 */
            left = 0;
        } else if (j288_serial_next_deadline(&b->serial, &at) && us_until(at, now) < left) {
            left = us_until(at, now);
        }
        ports[n++] = &b->serial;
    }
    if (r->stop_flag != NULL && left > (int32_t)STOP_SLICE_US)
        left = (int32_t)STOP_SLICE_US;
    if (left < 0)
        left = 0;
    if (j288_serial_wait_any(ports, n, (uint32_t)left, ready) == 0u)
        return; /* timeout, or a signal: the caller looks at its flags */
    for (i = 0; i < n; i++) {
        if (ready[i])
            (void)j288_serial_service(ports[i]);
    }
}

/* The cycle is over when no bus that is up has a sweep running. */
static bool cycle_done(const j288_robot_t *r)
{
    unsigned i;
    for (i = 0; i < r->nbuses; i++) {
        const j288_robot_bus_t *b = &r->bus[i];
        if (bus_live(b) && b->stats.up && bus_pending(b))
            return false;
    }
    return true;
}

static bool any_live(const j288_robot_t *r)
{
    unsigned i;
    for (i = 0; i < r->nbuses; i++) {
        if (bus_live(&r->bus[i]))
            return true;
    }
    return false;
}

/* Every bus is gone: sleep (bounded by until and the stop flag) until the next reopen
 * attempt is due, and make it. True when a bus is back. */
static bool wait_for_a_bus(j288_robot_t *r, uint32_t now, uint32_t until)
{
    uint32_t due = until; /* (next_reopen sets it; initialised for the compiler) */
    if (!next_reopen(r, now, &due))
        return false;
    if (us_until(due, until) > 0)
        due = until;
    while (us_until(due, now) > 0 && !stop_requested(r)) {
        wait_all(r, now, due); /* no live port: a plain bounded sleep */
        now = j288_serial_now_us();
    }
    if (stop_requested(r))
        return false;
    reopen_due(r, now);
    return any_live(r);
}

static void start_sweeps(j288_robot_t *r, uint32_t now)
{
    unsigned i;
    for (i = 0; i < r->nbuses; i++) {
        j288_robot_bus_t *b = &r->bus[i];
        /* A down bus still sweeping from an earlier cycle goes on in the background. */
        if (!bus_live(b) || j288_sched_busy(&b->sched))
            continue;
        b->swept_ok = false;
        b->sweep_start_us = now;
        (void)j288_sched_start_sweep(&b->sched, now);
    }
}

static void finish_cycle(j288_robot_t *r, uint32_t start, j288_robot_cycle_t *info)
{
    unsigned j, fresh = 0;
    uint32_t took = j288_serial_now_us() - start;
    for (j = 0; j < r->njoints; j++) {
        if (r->fresh_at[j] == r->cycle) {
            fresh++;
            r->jstats[j].fresh_cycles++;
        } else {
            r->jstats[j].stale_cycles++;
        }
    }
    r->stats.cycles++;
    if (fresh == r->njoints)
        r->stats.complete_cycles++;
    r->stats.last_cycle_us = took;
    if (took > r->stats.worst_cycle_us)
        r->stats.worst_cycle_us = took;
    info->cycle = r->stats.cycles;
    info->start_us = start;
    info->duration_us = took;
    info->fresh = fresh;
    info->joints = r->njoints;
    info->complete = fresh == r->njoints;
    info->watchdog = r->wd_cleared;
    info->lost = r->lost_pending;
    info->back = r->back_pending;
    r->wd_cleared = 0;
    r->lost_pending = 0;
    r->back_pending = 0;
    r->cycle++;
    if (r->opt.on_cycle != NULL)
        r->opt.on_cycle(r->opt.user, r, info);
}

/* stop_on_bus_loss: a bus went down or vanished in this cycle; stop them all. */
static int stop_on_loss(j288_robot_t *r)
{
    unsigned lost = r->lost_bus;
    bool gone = r->bus[lost].stats.gone;
    r->bus_lost = false;
    (void)j288_robot_stop(r);
    set_err(r, "bus '%s' %s: every bus stopped (stop on bus loss)", r->bus[lost].name,
            gone ? "vanished" : "stopped answering");
    return J288_ERR_OFFLINE;
}

int j288_robot_cycle(j288_robot_t *r, uint32_t timeout_us, j288_robot_cycle_t *info)
{
    j288_robot_cycle_t local;
    uint32_t start, until;
    bool drained = false;
    if (r == NULL)
        return J288_ERR_NULL;
    if (info == NULL)
        info = &local;
    memset(info, 0, sizeof *info);
    if (timeout_us == 0u)
        timeout_us = J288_ROBOT_DEFAULT_CYCLE_TIMEOUT_US;
    if (timeout_us > (uint32_t)INT32_MAX)
        timeout_us = (uint32_t)INT32_MAX; /* beyond it the wrapped clock reads as past */
    start = j288_serial_now_us();
    until = start + timeout_us;
    reopen_due(r, start);
    if (!any_live(r) && !wait_for_a_bus(r, start, until)) {
        if (stop_requested(r))
            return J288_ERR_ABORTED; /* nothing to stop: every bus is gone */
        set_err(r, "every bus is gone");
        return J288_ERR_OFFLINE;
    }
    start = j288_serial_now_us();
    start_sweeps(r, start);
    for (;;) {
        uint32_t now = j288_serial_now_us();
        poll_all(r, now);
        if (stop_requested(r)) {
            (void)j288_robot_stop(r);
            return J288_ERR_ABORTED;
        }
        if (cycle_done(r))
            break;
        if (us_until(until, now) <= 0) {
            if (drained) {
                r->timing.cut++; /* ended by its bound, not by its buses */
                break;
            }
            /* A host woken past the bound (a loaded machine) first takes the replies that
             * came meanwhile, as the ports do before a reply's deadline. */
            drained = true;
            until = now;
        }
        wait_all(r, now, until);
    }
    finish_cycle(r, start, info);
    if (r->bus_lost)
        return stop_on_loss(r);
    if (!any_live(r))
        return J288_ERR_OFFLINE;
    return info->complete ? J288_OK : J288_ERR_TIMEOUT;
}

static bool any_pending(const j288_robot_t *r)
{
    unsigned i;
    for (i = 0; i < r->nbuses; i++) {
        if (bus_live(&r->bus[i]) && bus_pending(&r->bus[i]))
            return true;
    }
    return false;
}

/* Sleep until the monotonic time until_ns, still serving buses that sweep in the background
 * (then in the ports' wait, to the microsecond); with nothing in flight, in one absolute
 * clock_nanosleep (in slices of STOP_SLICE_US with a stop flag, which a signal landing just
 * before the sleep could otherwise miss). *woke_ns: the first clock reading past until_ns,
 * taken before anything else runs. */
static int sleep_until_ns(j288_robot_t *r, uint64_t until_ns, uint64_t *woke_ns)
{
    for (;;) {
        uint64_t now_ns = j288_rt_now_ns();
        uint32_t now = j288_serial_now_us();
        if (now_ns >= until_ns) {
            *woke_ns = now_ns;
            poll_all(r, now);
            reopen_due(r, now);
            return J288_OK;
        }
        poll_all(r, now);
        reopen_due(r, now);
        if (!any_live(r) && r->opt.no_reopen)
            return J288_ERR_OFFLINE;
        if (stop_requested(r))
            return J288_ERR_ABORTED;
        if (any_pending(r)) {
            uint64_t left_us = (until_ns - now_ns + 999u) / 1000u;
            wait_all(r, now, now + (uint32_t)(left_us < STOP_SLICE_US ? left_us : STOP_SLICE_US));
        } else {
            /* (every bus gone: a reopen attempt falling due waits for the deadline) */
            uint64_t t = until_ns;
            if (r->stop_flag != NULL && t - now_ns > (uint64_t)STOP_SLICE_US * 1000u)
                t = now_ns + (uint64_t)STOP_SLICE_US * 1000u;
            (void)j288_rt_sleep_until(t);
        }
    }
}

int j288_robot_pace(j288_robot_t *r, uint32_t period_us)
{
    uint64_t until = 0, woke;
    bool slept = false;
    int rc;
    if (r == NULL)
        return J288_ERR_NULL;
    woke = j288_rt_now_ns();
    if (j288_rt_pace_begin(&r->pacer, &r->timing, (uint64_t)period_us * 1000u, woke, &until)) {
        rc = sleep_until_ns(r, until, &woke);
        if (rc != J288_OK)
            return rc;
        slept = true;
    }
    j288_rt_pace_woke(&r->pacer, &r->timing, woke, slept);
    if (!any_live(r) && r->opt.no_reopen) /* (else the cycle waits for a bus to come back) */
        return J288_ERR_OFFLINE;
    return stop_requested(r) ? J288_ERR_ABORTED : J288_OK;
}

void j288_robot_pace_restart(j288_robot_t *r)
{
    if (r != NULL)
        j288_rt_pace_restart(&r->pacer);
}

/* Whether a run of duration_us from t0_ns is over before its next cycle. */
static bool run_over(const j288_robot_t *r, uint32_t period_us, uint64_t t0_ns,
                     uint32_t duration_us)
{
    uint64_t end = t0_ns + (uint64_t)duration_us * 1000u, due;
    if (duration_us == 0u)
        return false;
    if (j288_rt_pace_next_due(&r->pacer, (uint64_t)period_us * 1000u, &due))
        return due >= end;
    return j288_rt_now_ns() >= end;
}

int j288_robot_run(j288_robot_t *r, uint32_t period_us, uint32_t ncycles, uint32_t duration_us)
{
    uint64_t t0;
    uint32_t done = 0;
    if (r == NULL)
        return J288_ERR_NULL;
    t0 = j288_rt_now_ns();
    for (;;) {
        int rc;
        if ((ncycles != 0u && done >= ncycles) || run_over(r, period_us, t0, duration_us))
            return J288_OK;
        rc = j288_robot_pace(r, period_us);
        if (rc == J288_ERR_ABORTED)
            (void)j288_robot_stop(r);
        if (rc != J288_OK)
            return rc;
        rc = j288_robot_cycle(r, 0, NULL);
        if (rc == J288_ERR_ABORTED || rc == J288_ERR_NULL)
            return rc;
        /* Every bus gone (the cycle waited for a reopen attempt): the run goes on unless
         * the loss ends it (stop_on_bus_loss) or nothing can come back (no_reopen). */
        if (rc == J288_ERR_OFFLINE && (r->opt.stop_on_bus_loss || r->opt.no_reopen))
            return rc;
        done++;
    }
}

/* How long the stop frames may take: the transaction in flight ends by its deadline, the
 * guard after a failure lasts one reply budget, and a stop frame whose transmit fails is
 * re-sent (J288_ESTOP_ATTEMPTS in all), so a bus with a long margin needs longer. */
static uint32_t stop_bound_us(const j288_robot_t *r)
{
    uint32_t bound = J288_ROBOT_STOP_TIMEOUT_US;
    unsigned i;
    for (i = 0; i < r->nbuses; i++) {
        if (bus_live(&r->bus[i])) {
            uint64_t b = (uint64_t)j288_bus_reply_budget_us(&r->bus[i].bus) *
                             (J288_ESTOP_ATTEMPTS + 2u) + J288_ROBOT_STOP_TIMEOUT_US;
            if (b > 60000000u)
                b = 60000000u;
            if (b > bound)
                bound = (uint32_t)b;
        }
    }
    return bound;
}

int j288_robot_stop(j288_robot_t *r)
{
    uint32_t start, now, bound;
    unsigned i;
    int rc = J288_OK;
    if (r == NULL)
        return J288_ERR_NULL;
    start = j288_serial_now_us();
    bound = stop_bound_us(r);
    for (i = 0; i < r->nbuses; i++) {
        if (bus_live(&r->bus[i])) {
            uint8_t id;
            (void)j288_sched_estop(&r->bus[i].sched, start);
            for (id = 0; id < J288_MAX_SERVOS; id++) {
                j288_cmd_raw_t lock; /* estop keeps each slot's bit: the policy wants 0 */
                lock_cmd(id, &lock);
                (void)j288_sched_set_cmd(&r->bus[i].sched, &lock);
            }
        } else if (r->bus[i].open) {
            rc = J288_ERR_OFFLINE;
        }
    }
    r->driven = false;
    for (;;) {
        bool pending = false;
        now = j288_serial_now_us();
        for (i = 0; i < r->nbuses; i++) {
            j288_robot_bus_t *b = &r->bus[i];
            if (!bus_live(b))
                continue;
            j288_bus_poll(&b->bus, now);
            if (j288_serial_offline(&b->serial)) {
                bus_gone(r, b, now);
                rc = J288_ERR_OFFLINE;
                continue;
            }
            if (!j288_bus_is_idle(&b->bus))
                pending = true;
        }
        if (!pending)
            return rc;
        if (now - start >= bound) {
            set_err(r, "the stop frames did not go out within %u ms", (unsigned)(bound / 1000u));
            return J288_ERR_TIMEOUT;
        }
        wait_all(r, now, start + bound);
    }
}

/* ---- joints ---------------------------------------------------------------------------------- */

unsigned j288_robot_njoints(const j288_robot_t *r) { return (r == NULL) ? 0u : r->njoints; }
unsigned j288_robot_nbuses(const j288_robot_t *r) { return (r == NULL) ? 0u : r->nbuses; }

int j288_robot_find_joint(const j288_robot_t *r, const char *name)
{
    unsigned j;
    if (r == NULL || name == NULL)
        return -1;
    for (j = 0; j < r->njoints; j++) {
        if (strcmp(r->joint_name[j], name) == 0)
            return (int)j;
    }
    return -1;
}

const char *j288_robot_joint_name(const j288_robot_t *r, unsigned joint)
{
    return (r == NULL || joint >= r->njoints) ? "" : r->joint_name[joint];
}

const char *j288_robot_bus_name(const j288_robot_t *r, unsigned bus)
{
    return (r == NULL || bus >= r->nbuses) ? "" : r->bus[bus].name;
}

int j288_robot_joint_bus(const j288_robot_t *r, unsigned joint)
{
    return (r == NULL || joint >= r->njoints) ? -1 : (int)r->joint_bus[joint];
}

int j288_robot_joint_id(const j288_robot_t *r, unsigned joint)
{
    return (r == NULL || joint >= r->njoints) ? -1 : (int)j288_joint_config(&r->joint[joint])->id;
}

int j288_robot_joint_config(const j288_robot_t *r, unsigned joint, j288_joint_config_t *out)
{
    if (r == NULL || out == NULL)
        return J288_ERR_NULL;
    if (joint >= r->njoints)
        return J288_ERR_BAD_ARG;
    *out = *j288_joint_config(&r->joint[joint]);
    return J288_OK;
}

/* Whether the joint's servo answers on a bus that is up and not gone: a lost joint's last
 * angle is history, never reported as known. */
static bool joint_not_lost(const j288_robot_t *r, unsigned joint)
{
    const j288_robot_bus_t *b = &r->bus[r->joint_bus[joint]];
    uint8_t id = j288_joint_config(&r->joint[joint])->id;
    return bus_live(b) && b->stats.up && j288_sched_slot(&b->sched, id)->online;
}

int j288_robot_read(const j288_robot_t *r, unsigned joint, j288_robot_state_t *st)
{
    const j288_joint_state_t *js;
    const j288_slot_t *slot;
    const j288_robot_bus_t *b;
    if (r == NULL || st == NULL)
        return J288_ERR_NULL;
    if (joint >= r->njoints)
        return J288_ERR_BAD_ARG;
    b = &r->bus[r->joint_bus[joint]];
    js = j288_joint_state(&r->joint[joint]);
    slot = j288_sched_slot(&b->sched, j288_joint_config(&r->joint[joint])->id);
    memset(st, 0, sizeof *st);
    st->online = slot->online && bus_live(b);
    st->known = js->known && joint_not_lost(r, joint);
    st->fresh = r->fresh_at[joint] != 0u && r->fresh_at[joint] + 1u == r->cycle;
    st->pos = st->known ? (double)js->pos : 0.0;
    st->speed = (double)js->speed;
    st->torque = (double)js->torque;
    if (slot->has_reply) {
        st->faults = slot->reply.faults;
        st->warnings = slot->reply.warnings;
        st->case_temp_c = (double)slot->reply.case_temp_c;
        st->winding_temp_c = (double)slot->reply.winding_temp_c;
        st->voltage_v = (double)slot->reply.voltage_raw * 0.5;
    }
    return J288_OK;
}

int j288_robot_read_all(const j288_robot_t *r, size_t n, double *pos, double *speed,
                        double *torque, uint8_t *known)
{
    unsigned j;
    if (r == NULL)
        return J288_ERR_NULL;
    if (n < r->njoints)
        return J288_ERR_BAD_ARG;
    for (j = 0; j < r->njoints; j++) {
        const j288_joint_state_t *js = j288_joint_state(&r->joint[j]);
        bool ok = js->known && joint_not_lost(r, j);
        if (pos != NULL)
            pos[j] = ok ? (double)js->pos : 0.0;
        if (speed != NULL)
            speed[j] = (double)js->speed;
        if (torque != NULL)
            torque[j] = (double)js->torque;
        if (known != NULL)
            known[j] = ok ? 1u : 0u;
    }
    return J288_OK;
}

static int target_check(const j288_robot_t *r, unsigned joint)
{
    if (joint >= r->njoints)
        return J288_ERR_BAD_ARG;
    if (!bus_live(&r->bus[r->joint_bus[joint]]))
        return J288_ERR_OFFLINE;
    return J288_OK;
}

static void to_joint_target(const j288_robot_target_t *t, j288_joint_target_t *jt)
{
    jt->pos = (j288_real_t)t->pos;
    jt->speed = (j288_real_t)t->speed;
    jt->torque = (j288_real_t)t->torque;
    jt->kp = (j288_real_t)t->kp;
    jt->kd = (j288_real_t)t->kd;
}

/* The checks both target calls make, then t as the joint layer's target. */
static int joint_target_of(const j288_robot_t *r, unsigned joint, const j288_robot_target_t *t,
                           j288_joint_target_t *jt)
{
    int rc;
    if (r == NULL || t == NULL)
        return J288_ERR_NULL;
    rc = target_check(r, joint);
    if (rc == J288_OK)
        to_joint_target(t, jt);
    return rc;
}

int j288_robot_set_target(j288_robot_t *r, unsigned joint, const j288_robot_target_t *t)
{
    j288_joint_target_t jt;
    int rc = joint_target_of(r, joint, t, &jt);
    if (rc != J288_OK)
        return rc;
    rc = j288_joint_bus_set_target(&r->bus[r->joint_bus[joint]].jb, &r->joint[joint], &jt, NULL);
    if (rc == J288_OK)
        r->driven = true;
    return rc;
}

int j288_robot_check_target(const j288_robot_t *r, unsigned joint, const j288_robot_target_t *t)
{
    j288_joint_target_t jt;
    j288_cmd_raw_t cmd;
    int rc = joint_target_of(r, joint, t, &jt);
    if (rc != J288_OK)
        return rc;
    return j288_joint_command(&r->joint[joint], &jt, &cmd, NULL);
}

/* Joint j's target from the arrays of j288_robot_set_targets() (gains NULL: the joint's). */
static void target_of_arrays(const j288_robot_t *r, unsigned j, const double *pos,
                             const double *speed, const double *torque, const double *kp,
                             const double *kd, j288_joint_target_t *jt)
{
    j288_joint_target_init(&r->joint[j], jt);
    jt->pos = (j288_real_t)pos[j];
    jt->speed = (speed != NULL) ? (j288_real_t)speed[j] : (j288_real_t)0;
    jt->torque = (torque != NULL) ? (j288_real_t)torque[j] : (j288_real_t)0;
    if (kp != NULL)
        jt->kp = (j288_real_t)kp[j];
    if (kd != NULL)
        jt->kd = (j288_real_t)kd[j];
}

int j288_robot_set_targets(j288_robot_t *r, size_t n, const double *pos, const double *speed,
                           const double *torque, const double *kp, const double *kd,
                           unsigned *bad)
{
    j288_cmd_raw_t cmd[J288_ROBOT_MAX_JOINTS];
    unsigned j;
    int rc;
    if (r == NULL || pos == NULL)
        return J288_ERR_NULL;
    if (n < r->njoints)
        return J288_ERR_BAD_ARG;
    /* Every command is built (and so checked) before any slot changes. */
    for (j = 0; j < r->njoints; j++) {
        j288_joint_target_t jt;
        target_of_arrays(r, j, pos, speed, torque, kp, kd, &jt);
        rc = target_check(r, j);
        if (rc == J288_OK)
            rc = j288_joint_command(&r->joint[j], &jt, &cmd[j], NULL);
        if (rc != J288_OK) {
            if (bad != NULL)
                *bad = j;
            return rc;
        }
    }
    /* Through the binding, which makes again on every reply the command of a target that
     * drives toward a limit (the same command now: it was just made). */
    for (j = 0; j < r->njoints; j++) {
        j288_joint_target_t jt;
        target_of_arrays(r, j, pos, speed, torque, kp, kd, &jt);
        (void)j288_joint_bus_set_target(&r->bus[r->joint_bus[j]].jb, &r->joint[j], &jt, NULL);
    }
    r->driven = true;
    return J288_OK;
}

int j288_robot_hold(j288_robot_t *r, unsigned joint)
{
    j288_joint_target_t jt;
    int rc;
    if (r == NULL)
        return J288_ERR_NULL;
    rc = target_check(r, joint);
    if (rc != J288_OK)
        return rc;
    if (!j288_joint_state(&r->joint[joint])->known)
        return J288_ERR_ANGLE_UNKNOWN;
    j288_joint_target_init(&r->joint[joint], &jt); /* at the nearest limit, if just beyond */
    rc = j288_joint_bus_set_target(&r->bus[r->joint_bus[joint]].jb, &r->joint[joint], &jt, NULL);
    if (rc == J288_OK)
        r->driven = true;
    return rc;
}

int j288_robot_lock(j288_robot_t *r, unsigned joint)
{
    j288_cmd_raw_t lock;
    if (r == NULL)
        return J288_ERR_NULL;
    if (joint >= r->njoints)
        return J288_ERR_BAD_ARG;
    lock_cmd(j288_joint_config(&r->joint[joint])->id, &lock);
    return j288_sched_set_cmd(&r->bus[r->joint_bus[joint]].sched, &lock);
}

/* ---- statistics ------------------------------------------------------------------------------ */

int j288_robot_stats(const j288_robot_t *r, j288_robot_stats_t *out)
{
    if (r == NULL || out == NULL)
        return J288_ERR_NULL;
    *out = r->stats;
    return J288_OK;
}

int j288_robot_timing(const j288_robot_t *r, j288_rt_report_t *out)
{
    if (r == NULL || out == NULL)
        return J288_ERR_NULL;
    j288_rt_report(&r->timing, &r->rt, out);
    return J288_OK;
}

void j288_robot_timing_reset(j288_robot_t *r)
{
    if (r != NULL)
        j288_rt_timing_reset(&r->timing);
}

const char *j288_robot_rt_notice(const j288_robot_t *r)
{
    return (r == NULL) ? "" : r->rt.notice;
}

int j288_robot_bus_stats(const j288_robot_t *r, unsigned bus, j288_robot_bus_stats_t *out)
{
    if (r == NULL || out == NULL)
        return J288_ERR_NULL;
    if (bus >= r->nbuses)
        return J288_ERR_BAD_ARG;
    *out = r->bus[bus].stats;
    return J288_OK;
}

const j288_bus_stats_t *j288_robot_bus_wire_stats(const j288_robot_t *r, unsigned bus)
{
    if (r == NULL || bus >= r->nbuses)
        return NULL;
    return j288_bus_stats(&r->bus[bus].bus);
}

int j288_robot_joint_stats(const j288_robot_t *r, unsigned joint, j288_robot_joint_stats_t *out)
{
    const j288_slot_t *slot;
    if (r == NULL || out == NULL)
        return J288_ERR_NULL;
    if (joint >= r->njoints)
        return J288_ERR_BAD_ARG;
    *out = r->jstats[joint];
    slot = j288_sched_slot(&r->bus[r->joint_bus[joint]].sched,
                           j288_joint_config(&r->joint[joint])->id);
    out->servo = slot->stats;
    return J288_OK;
}

/* ---- servo level ----------------------------------------------------------------------------- */

static void servo_from_reply(const j288_txn_t *txn, j288_robot_servo_t *out)
{
    j288_reply_si_t si;
    memset(out, 0, sizeof *out);
    (void)j288_reply_to_si(&txn->reply, J288_SIDE_OUTPUT, &si);
    out->id = si.id;
    out->mode = si.status;
    out->watchdog_tripped = si.watchdog_tripped;
    out->pos = (double)si.pos;
    out->speed = (double)si.speed;
    out->torque = (double)si.torque;
    out->out_pos = (double)si.out_pos;
    out->case_temp_c = (double)si.case_temp_c;
    out->winding_temp_c = (double)si.winding_temp_c;
    out->voltage_v = (double)si.voltage_v;
    out->faults = si.faults;
    out->warnings = si.warnings;
    out->latency_us = txn->latency_us;
}

/* The result lands in the bus object, not on the caller's stack: a transaction given up by
 * run_txn()'s bound (a process frozen past it) still ends later, into memory that lives. */
static void txn_done(void *user, const j288_txn_t *txn)
{
    j288_robot_bus_t *b = user;
    b->txn = *txn;
    b->txn_done = true;
}

/* The longest one submit on bus b can take: each attempt a reply budget and, after a failure,
 * a guard of one more (bus.h), plus the stop's flushing allowance; never less than the estop's
 * bound (stop_bound_us), which alone was too short: a silent servo's every re-send outlasted
 * it, and the submit was then left unfinished, the bus refusing every later one as busy. */
static uint32_t txn_bound_us(const j288_robot_t *r, const j288_robot_bus_t *b)
{
    uint64_t attempts = j288_bus_config(&b->bus)->retries + 1u;
    uint64_t t = (uint64_t)j288_bus_reply_budget_us(&b->bus) * 2u * attempts +
                 J288_ROBOT_STOP_TIMEOUT_US;
    uint32_t stop = stop_bound_us(r);
    if (t > 60000000u)
        t = 60000000u;
    return (uint32_t)t > stop ? (uint32_t)t : stop;
}

/* One submit, driven by the runner's loop until it ends (its retries and reply budgets, the
 * guard: bounded by txn_bound_us). */
static int run_txn(j288_robot_t *r, j288_robot_bus_t *b, const j288_cmd_raw_t *cmd,
                   j288_txn_t *out)
{
    uint32_t start = j288_serial_now_us(), bound = txn_bound_us(r, b);
    int rc;
    b->txn_done = false;
    rc = j288_bus_submit(&b->bus, cmd, start, txn_done, b);
    if (rc != J288_OK)
        return rc;
    for (;;) {
        uint32_t now = j288_serial_now_us();
        poll_all(r, now);
        if (b->txn_done)
            break;
        if (!bus_live(b))
            return J288_ERR_OFFLINE;
        if (now - start >= bound) {
            set_err(r, "bus '%s': the transaction did not end within %u ms", b->name,
                    (unsigned)(bound / 1000u));
            return J288_ERR_TIMEOUT;
        }
        wait_all(r, now, start + bound);
    }
    if (out != NULL)
        *out = b->txn;
    if (b->txn.result == J288_ERR_OFFLINE || !bus_live(b))
        return J288_ERR_OFFLINE;
    return b->txn.result;
}

/* Servo id's joint for servo-level use (all-zero configuration), set up on first use. */
static j288_joint_t *servo_joint(j288_robot_bus_t *b, uint8_t id)
{
    if ((b->servo_joint_on & (1u << id)) == 0u) {
        j288_joint_config_t jc;
        memset(&jc, 0, sizeof jc);
        jc.id = id;
        (void)j288_joint_init(&b->servo_joint[id], &jc); /* valid: defaults and an id 0-14 */
        b->servo_joint_on = (uint16_t)(b->servo_joint_on | (1u << id));
    }
    return &b->servo_joint[id];
}

static void joint_into_servo(const j288_joint_t *j, j288_robot_servo_t *out)
{
    const j288_joint_state_t *st = j288_joint_state(j);
    out->joint_known = st->known;
    out->joint_pos = st->known ? (double)st->pos : 0.0;
    out->joint_speed = (double)st->speed;
    out->joint_torque = (double)st->torque;
}

/* Whether a reply to an FOC command shows a servo that did not take it: a trip reported, or
 * lock mode. */
static bool foc_ignored(const j288_cmd_raw_t *cmd, const j288_reply_raw_t *reply)
{
    return cmd->status == J288_MODE_FOC &&
           (reply->watchdog_tripped || reply->status == J288_MODE_LOCK);
}

int j288_robot_transfer(j288_robot_t *r, unsigned bus, const j288_cmd_raw_t *cmd,
                        j288_txn_t *txn, bool *wd_cleared)
{
    j288_cmd_raw_t c;
    j288_txn_t t;
    j288_robot_bus_t *b;
    int rc;
    if (wd_cleared != NULL)
        *wd_cleared = false;
    if (r == NULL || cmd == NULL)
        return J288_ERR_NULL;
    if (bus >= r->nbuses)
        return J288_ERR_BAD_ARG;
    if (cmd->id >= J288_MAX_SERVOS)
        return J288_ERR_BAD_ID;
    b = &r->bus[bus];
    if (!bus_live(b))
        return J288_ERR_OFFLINE;
    if (j288_sched_busy(&b->sched))
        return J288_ERR_BUSY;
    c = *cmd;
    if (c.status == J288_MODE_LOCK)
        c.watchdog = false;
    else
        r->driven = true; /* it may reach the servo even if its reply does not reach us */
    rc = run_txn(r, b, &c, &t);
    if (rc == J288_OK && foc_ignored(&c, &t.reply)) {
        j288_robot_event_t ev = servo_on_bus(b, J288_ROBOT_EV_WATCHDOG, c.id);
        ev.value = t.reply.watchdog_tripped ? 1.0 : 2.0;
        c.watchdog = false; /* clears the trip; the servo takes this very command */
        rc = run_txn(r, b, &c, &t);
        if (wd_cleared != NULL)
            *wd_cleared = true;
        emit(r, &ev);
    }
    if (rc == J288_OK)
        (void)j288_joint_take_reply(servo_joint(b, c.id), &t.reply, NULL);
    if (txn != NULL)
        *txn = t;
    return rc;
}

int j288_robot_exchange(j288_robot_t *r, unsigned bus, uint8_t id, const j288_robot_target_t *foc,
                        j288_robot_servo_t *out)
{
    j288_cmd_raw_t cmd;
    j288_txn_t txn;
    bool cleared = false;
    int rc;
    if (r == NULL)
        return J288_ERR_NULL;
    if (id >= J288_MAX_SERVOS)
        return J288_ERR_BAD_ID;
    lock_cmd(id, &cmd);
    if (foc != NULL) {
        j288_cmd_si_t si;
        memset(&si, 0, sizeof si);
        si.id = id;
        si.status = J288_MODE_FOC;
        si.watchdog = true;
        si.pos = (j288_real_t)foc->pos;
        si.speed = (j288_real_t)foc->speed;
        si.tau = (j288_real_t)foc->torque;
        si.kp = (j288_real_t)foc->kp;
        si.kd = (j288_real_t)foc->kd;
        rc = j288_cmd_from_si(&si, J288_SIDE_OUTPUT, &cmd);
        if (rc != J288_OK)
            return rc;
    }
    rc = j288_robot_transfer(r, bus, &cmd, &txn, &cleared);
    if (rc == J288_OK && out != NULL) {
        servo_from_reply(&txn, out);
        out->watchdog_cleared = cleared;
        joint_into_servo(servo_joint(&r->bus[bus], id), out);
    }
    return rc;
}

int j288_robot_servo_joint_setup(j288_robot_t *r, unsigned bus, const j288_joint_config_t *jc)
{
    j288_joint_t j;
    int rc;
    if (r == NULL || jc == NULL)
        return J288_ERR_NULL;
    if (bus >= r->nbuses)
        return J288_ERR_BAD_ARG;
    rc = j288_joint_init(&j, jc); /* checked before the servo's joint is touched */
    if (rc != J288_OK)
        return rc;
    r->bus[bus].servo_joint[jc->id] = j;
    r->bus[bus].servo_joint_on = (uint16_t)(r->bus[bus].servo_joint_on | (1u << jc->id));
    return J288_OK;
}

const j288_joint_t *j288_robot_servo_joint(j288_robot_t *r, unsigned bus, uint8_t id)
{
    if (r == NULL || bus >= r->nbuses || id >= J288_MAX_SERVOS)
        return NULL;
    return servo_joint(&r->bus[bus], id);
}

/* Failed exchanges in a row that end the start-up reads. */
#define ACQUIRE_MAX_FAILS 5u

int j288_robot_acquire_joint(j288_robot_t *r, unsigned bus, uint8_t id, j288_txn_t *last,
                             unsigned *replies)
{
    const j288_joint_state_t *st;
    unsigned samples, tries, n, got = 0, fails = 0;
    j288_cmd_raw_t cmd;
    j288_txn_t txn;
    int rc = J288_ERR_TIMEOUT;
    if (replies != NULL)
        *replies = 0;
    if (r == NULL)
        return J288_ERR_NULL;
    if (bus >= r->nbuses)
        return J288_ERR_BAD_ARG;
    if (id >= J288_MAX_SERVOS)
        return J288_ERR_BAD_ID;
    st = j288_joint_state(servo_joint(&r->bus[bus], id));
    samples = j288_joint_config(servo_joint(&r->bus[bus], id))->init_samples;
    tries = samples * 4u > J288_ROBOT_ACQUIRE_TRIES ? samples * 4u : J288_ROBOT_ACQUIRE_TRIES;
    lock_cmd(id, &cmd);
    for (n = 0; n < tries && !st->known && !stop_requested(r); n++) {
        rc = j288_robot_transfer(r, bus, &cmd, &txn, NULL);
        /* A servo that does not answer the first exchange (after the bus's retries) is
         * treated as absent, as a single exchange would be; later, a run of failures ends it. */
        if (rc == J288_ERR_OFFLINE || (rc != J288_OK && got == 0u))
            break;
        fails = rc == J288_OK ? 0u : fails + 1u;
        if (fails >= ACQUIRE_MAX_FAILS)
            break;
        if (rc == J288_OK) {
            got++;
            if (last != NULL)
                *last = txn;
        }
        if ((st->encoder_fault || st->cal_mismatch) && got >= 2u * samples)
            break;
    }
    if (replies != NULL)
        *replies = got;
    if (st->known)
        return J288_OK;
    if (stop_requested(r))
        return J288_ERR_ABORTED;
    if (rc != J288_OK)
        return rc;
    return st->cal_mismatch ? J288_ERR_CAL_MISMATCH : J288_ERR_ANGLE_UNKNOWN;
}

int j288_robot_exchange_joint(j288_robot_t *r, unsigned bus, uint8_t id,
                              const j288_robot_target_t *foc, j288_robot_servo_t *out)
{
    j288_robot_servo_t local;
    const j288_joint_t *j;
    j288_joint_target_t jt;
    j288_cmd_raw_t cmd;
    j288_txn_t txn;
    bool cleared = false;
    unsigned n = 0;
    int rc;
    if (out == NULL)
        out = &local;
    rc = j288_robot_acquire_joint(r, bus, id, &txn, &n); /* the start-up reads */
    if (n != 0u) {
        servo_from_reply(&txn, out);
        joint_into_servo(servo_joint(&r->bus[bus], id), out);
    }
    if (rc != J288_OK)
        return rc;
    j = servo_joint(&r->bus[bus], id);
    if (foc == NULL) {
        lock_cmd(id, &cmd);
    } else {
        jt.pos = (j288_real_t)foc->pos;
        jt.speed = (j288_real_t)foc->speed;
        jt.torque = (j288_real_t)foc->torque;
        jt.kp = (j288_real_t)foc->kp;
        jt.kd = (j288_real_t)foc->kd;
        rc = j288_joint_command(j, &jt, &cmd, NULL); /* watchdog bit 1 */
        if (rc != J288_OK)
            return rc;
    }
    rc = j288_robot_transfer(r, bus, &cmd, &txn, &cleared);
    if (rc == J288_OK) {
        servo_from_reply(&txn, out);
        out->watchdog_cleared = cleared;
        joint_into_servo(j, out);
    }
    return rc;
}

int j288_robot_idle(j288_robot_t *r, uint32_t until_us)
{
    if (r == NULL)
        return J288_ERR_NULL;
    for (;;) {
        uint32_t now = j288_serial_now_us();
        poll_all(r, now);
        if (!any_live(r))
            return J288_ERR_OFFLINE;
        if (stop_requested(r))
            return J288_ERR_ABORTED;
        if (us_until(until_us, now) <= 0)
            return J288_OK;
        wait_all(r, now, until_us);
    }
}

const char *j288_robot_notices(const j288_robot_t *r, unsigned bus)
{
    if (r == NULL || bus >= r->nbuses || !r->bus[bus].open)
        return "";
    return j288_serial_notices(&r->bus[bus].serial);
}

j288_sched_t *j288_robot_bus_sched(j288_robot_t *r, unsigned bus)
{
    return (r == NULL || bus >= r->nbuses) ? NULL : &r->bus[bus].sched;
}

const j288_bus_t *j288_robot_bus_engine(const j288_robot_t *r, unsigned bus)
{
    return (r == NULL || bus >= r->nbuses) ? NULL : &r->bus[bus].bus;
}

const char *j288_robot_error(const j288_robot_t *r) { return (r == NULL) ? "no robot" : r->err; }
