/* servo_model.c - the simulated servos and bus; see servo_model.h. */
#include "servo_model.h"

#include <math.h>
#include <string.h>

#include "j288/units.h"

#define TWO_PI (2.0 * J288_PI)

/* Thermal model: winding and case nodes. */
#define C_WIND      15.0  /* J/K */
#define R_WIND_CASE 1.5   /* K/W */
#define C_CASE      150.0 /* J/K */
#define R_CASE_AMB  3.0   /* K/W */
#define P_IDLE      0.5   /* W, electronics */

/* Speeds below this count as standing still for stiction. */
#define W_STILL 1e-6

void j288_sim_params_default(j288_sim_params_t *prm)
{
    prm->inertia = 2.0e-6;
    prm->viscous = 2.0e-6;
    prm->coulomb = 2.0e-4;
    prm->tau_max = 0.127;
    prm->load_inertia = 0.0;
    prm->load_torque = 0.0;
    prm->voltage = 24.0;
    prm->ambient_c = 25.0;
    prm->loss_per_nm2 = 2400.0;
    prm->backlash = 0.0;
}

static double wrap_2pi(double a)
{
    double r = fmod(a, TWO_PI);
    if (r < 0.0)
        r += TWO_PI;
    if (r >= TWO_PI)
        r = 0.0;
    return r;
}

/* ---- the joint: r = N * theta_gear + c, p = r - 2 pi k ----------------------------------- */

static double rotor_angle(const j288_sim_servo_t *s)
{
    return s->p + TWO_PI * (double)s->k;
}

static double gear_angle(const j288_sim_servo_t *s)
{
    return (rotor_angle(s) - s->c) / J288_GEAR_RATIO;
}

/* What the single-turn rotor encoder makes of r at power-up: p in [0, 2 pi), k turns lost. */
static void rotor_power_up(j288_sim_servo_t *s, double r)
{
    double k = floor(r / TWO_PI);
    double p = r - k * TWO_PI;
    /* r / TWO_PI may round across an integer: bring p back into [0, 2 pi). */
    if (p >= TWO_PI) {
        p -= TWO_PI;
        k += 1.0;
    } else if (p < 0.0) {
        p += TWO_PI;
        k -= 1.0;
    }
    s->p = p;
    s->k = (long)k;
}

/* Which side of the play the load keeps the shaft on: -1, +1, or 0 (no load: it stays where
 * the gear left it). A positive load torque pulls the output backwards (see step()). */
static double load_side(const j288_sim_servo_t *s)
{
    if (s->prm.load_torque > 0.0)
        return -1.0;
    if (s->prm.load_torque < 0.0)
        return 1.0;
    return 0.0;
}

/* The massless output shaft inside the play: pressed against the load's side, or pushed
 * along by the gear when it reaches an edge. Without backlash it is the gear side. */
static void shaft_follow(j288_sim_servo_t *s)
{
    double g = gear_angle(s);
    double half = 0.5 * s->prm.backlash;
    double side = load_side(s);
    if (side != 0.0)
        s->theta = g + side * half;
    else if (s->theta > g + half)
        s->theta = g + half;
    else if (s->theta < g - half)
        s->theta = g - half;
}

void j288_sim_servo_init(j288_sim_servo_t *s, uint8_t id, const j288_sim_params_t *prm, double c,
                         double out_angle)
{
    memset(s, 0, sizeof *s);
    s->id = id;
    if (prm != NULL)
        s->prm = *prm;
    else
        j288_sim_params_default(&s->prm);
    s->c = c;
    s->theta = out_angle;
    /* The gear side sits where the load keeps the shaft against it, else at the shaft. */
    rotor_power_up(s, J288_GEAR_RATIO * (out_angle - load_side(s) * 0.5 * s->prm.backlash) + c);
    s->t_wind = s->prm.ambient_c;
    s->t_case = s->prm.ambient_c;
    s->mode = J288_MODE_LOCK;
    s->cmd.id = id;
    s->powered = true;
}

static bool torque_inhibited(const j288_sim_servo_t *s)
{
    const uint32_t stop = J288_FAULT_WINDING_TEMP | J288_FAULT_CASE_TEMP |
                          J288_FAULT_UNDER_VOLTAGE | J288_FAULT_OVER_VOLTAGE;
    return !s->powered || s->mode != J288_MODE_FOC || (s->faults_active & stop) != 0u;
}

/* The hybrid law on the rotor, from the last command, saturated at the motor's limit. */
static double motor_torque(const j288_sim_servo_t *s)
{
    double tau, p_des, w_des;
    if (torque_inhibited(s))
        return 0.0;
    p_des = (double)s->cmd.pos / J288_SCALE_POS;
    w_des = (double)s->cmd.speed / J288_SCALE_SPEED;
    tau = (double)s->cmd.tau / J288_SCALE_TORQUE +
          ((double)s->cmd.kp / J288_SCALE_KP) * (p_des - s->p) +
          ((double)s->cmd.kd / J288_SCALE_KD) * (w_des - s->w);
    if (tau > s->prm.tau_max)
        tau = s->prm.tau_max;
    if (tau < -s->prm.tau_max)
        tau = -s->prm.tau_max;
    return tau;
}

static void update_conditions(j288_sim_servo_t *s)
{
    uint32_t f = s->faults_active;
    double v = s->prm.voltage;
    if (s->t_wind > J288_SIM_WIND_LIMIT_C)
        f |= J288_FAULT_WINDING_TEMP;
    else if (s->t_wind < J288_SIM_WIND_LIMIT_C - J288_SIM_TEMP_HYST_C)
        f &= ~(uint32_t)J288_FAULT_WINDING_TEMP;
    if (s->t_case > J288_SIM_CASE_LIMIT_C)
        f |= J288_FAULT_CASE_TEMP;
    else if (s->t_case < J288_SIM_CASE_LIMIT_C - J288_SIM_TEMP_HYST_C)
        f &= ~(uint32_t)J288_FAULT_CASE_TEMP;
    f &= ~(uint32_t)(J288_FAULT_UNDER_VOLTAGE | J288_FAULT_OVER_VOLTAGE);
    if (v < J288_SIM_UNDER_VOLTAGE_V)
        f |= J288_FAULT_UNDER_VOLTAGE;
    if (v > J288_SIM_OVER_VOLTAGE_V)
        f |= J288_FAULT_OVER_VOLTAGE;
    s->faults_active = f;
}

/* One step of dt seconds: semi-implicit Euler with stiction. */
static void step(j288_sim_servo_t *s, double dt)
{
    const double n = J288_GEAR_RATIO;
    double j = s->prm.inertia + s->prm.load_inertia / (n * n);
    double tau_m = motor_torque(s);
    double drive = tau_m - s->prm.load_torque / n - s->prm.viscous * s->w;
    double w_new;
    double p_loss;
    s->tau = tau_m;
    if (fabs(s->w) < W_STILL && fabs(drive) <= s->prm.coulomb) {
        s->w = 0.0; /* static friction holds */
    } else {
        double dir =
            (fabs(s->w) >= W_STILL) ? (s->w > 0.0 ? 1.0 : -1.0) : (drive > 0.0 ? 1.0 : -1.0);
        w_new = s->w + (drive - dir * s->prm.coulomb) / j * dt;
        /* Dry friction stops the rotor; it never reverses it. */
        if (fabs(s->w) >= W_STILL && (w_new > 0.0) != (s->w > 0.0))
            w_new = 0.0;
        s->w = w_new;
    }
    s->p += s->w * dt;
    shaft_follow(s);

    p_loss = s->prm.loss_per_nm2 * tau_m * tau_m + (s->powered ? P_IDLE : 0.0);
    {
        double q_wc = (s->t_wind - s->t_case) / R_WIND_CASE;
        double q_ca = (s->t_case - s->prm.ambient_c) / R_CASE_AMB;
        s->t_wind += (p_loss - q_wc) / C_WIND * dt;
        s->t_case += (q_wc - q_ca) / C_CASE * dt;
    }
}

static void trip_watchdog(j288_sim_servo_t *s)
{
    s->wd_tripped = true;
    s->mode = J288_MODE_LOCK;
    s->watchdog_trips++;
}

static void integrate(j288_sim_servo_t *s, uint64_t until_us)
{
    while (s->now_us < until_us) {
        uint64_t dt_us = until_us - s->now_us;
        if (dt_us > J288_SIM_STEP_US)
            dt_us = J288_SIM_STEP_US;
        step(s, (double)dt_us * 1e-6);
        s->now_us += dt_us;
        update_conditions(s);
    }
}

/* Back from a power cycle: the turn count is gone, the rest is as at the first power-up. */
static void power_on(j288_sim_servo_t *s)
{
    rotor_power_up(s, rotor_angle(s));
    s->powered = true;
}

void j288_sim_servo_advance(j288_sim_servo_t *s, uint64_t now_us)
{
    if (!s->powered && s->power_on_us <= now_us) {
        integrate(s, s->power_on_us);
        power_on(s);
    }
    if (s->wd_enabled && !s->wd_tripped) {
        uint64_t trip_at = s->last_cmd_us + J288_SIM_WATCHDOG_US;
        if (trip_at <= now_us) {
            integrate(s, trip_at);
            trip_watchdog(s);
        }
    }
    integrate(s, now_us);
    update_conditions(s);
}

bool j288_sim_servo_command(j288_sim_servo_t *s, const j288_cmd_raw_t *cmd, uint64_t now_us)
{
    j288_sim_servo_advance(s, now_us);
    if (!s->powered)
        return false;
    s->last_cmd_us = now_us;
    if (s->wd_tripped) {
        if (cmd->watchdog)
            return true; /* stays locked, keeps reporting the trip */
        s->wd_tripped = false;
    }
    s->wd_enabled = cmd->watchdog;
    s->cmd = *cmd;
    s->mode = (cmd->status == J288_MODE_FOC) ? J288_MODE_FOC : J288_MODE_LOCK;
    return true;
}

void j288_sim_servo_bad_crc(j288_sim_servo_t *s)
{
    if (s->powered)
        s->faults_latched |= J288_FAULT_COMM_CHECKSUM;
}

void j288_sim_servo_power_cycle(j288_sim_servo_t *s, uint64_t now_us, uint32_t off_us)
{
    j288_sim_servo_advance(s, now_us);
    s->powered = false;
    s->power_on_us = s->now_us + off_us; /* the model may already be past now_us */
    s->power_cycles++;
    /* Power-up state: lock, watchdog off and clear, nothing latched. */
    s->mode = J288_MODE_LOCK;
    s->wd_enabled = false;
    s->wd_tripped = false;
    s->faults_latched = 0u;
    if (off_us == 0u)
        power_on(s);
}

double j288_sim_servo_out_angle(const j288_sim_servo_t *s)
{
    return s->theta;
}

uint16_t j288_sim_servo_out_pos(const j288_sim_servo_t *s)
{
    double frac = wrap_2pi(j288_sim_servo_out_angle(s)) / TWO_PI;
    long counts = (long)floor(frac * (double)J288_OUT_POS_COUNTS);
    return (uint16_t)((unsigned long)counts & (J288_OUT_POS_COUNTS - 1u));
}

void j288_sim_servo_truth(const j288_sim_servo_t *s, j288_sim_truth_t *t)
{
    t->theta = s->theta;
    t->theta_gear = gear_angle(s);
    t->c = s->c;
    t->r = rotor_angle(s);
    t->p = s->p;
    t->k = s->k;
    t->out_pos = j288_sim_servo_out_pos(s);
    t->powered = s->powered;
    t->power_cycles = s->power_cycles;
}

static long round_clamp(double v, double lo, double hi)
{
    if (!(v >= lo)) /* also NaN */
        return (long)lo;
    if (v > hi)
        return (long)hi;
    return lround(v);
}

void j288_sim_servo_reply(j288_sim_servo_t *s, j288_reply_raw_t *r)
{
    memset(r, 0, sizeof *r);
    r->id = s->id;
    r->status = s->mode;
    r->watchdog_tripped = s->wd_tripped;
    r->case_temp_c = (int8_t)round_clamp(s->t_case, -128.0, 127.0);
    r->winding_temp_c = (uint8_t)round_clamp(s->t_wind, 0.0, 255.0);
    r->voltage_raw = (uint8_t)round_clamp(s->prm.voltage / J288_SCALE_VOLTAGE, 0.0, 255.0);
    r->torque = (int16_t)round_clamp(s->tau * J288_SCALE_TORQUE, -32768.0, 32767.0);
    r->speed = (int16_t)round_clamp(s->w * J288_SCALE_SPEED, -32768.0, 32767.0);
    r->pos = (int32_t)round_clamp(s->p * J288_SCALE_POS, -2147483648.0, 2147483647.0);
    r->faults = s->faults_latched | s->faults_active | s->faults_injected;
    r->out_pos = j288_sim_servo_out_pos(s);
    r->warnings = (s->prm.voltage < J288_SIM_LOW_SUPPLY_V) ? (uint8_t)J288_WARN_LOW_SUPPLY : 0u;
    s->faults_latched = 0u;
}

/* ---- the bus -------------------------------------------------------------------------------- */

/* splitmix64: small, seedable, identical everywhere. */
static uint64_t rng_next(uint64_t *state)
{
    uint64_t z = (*state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* Uniform in [0, 1). */
static double rng_unit(uint64_t *state)
{
    return (double)(rng_next(state) >> 11) * 0x1.0p-53;
}

static bool has_dup(const j288_sim_bus_t *b, uint8_t id)
{
    return (b->cfg.dup_ids & (1u << id)) != 0u;
}

int j288_sim_bus_init(j288_sim_bus_t *b, uint16_t ids, const j288_sim_bus_config_t *cfg,
                      const j288_sim_params_t *prm, j288_sim_send_fn send, j288_sim_log_fn log,
                      void *user)
{
    uint8_t id;
    if (ids == 0u || (ids & 0x8000u) != 0u)
        return -1;
    memset(b, 0, sizeof *b);
    if (cfg != NULL)
        b->cfg = *cfg;
    if (b->cfg.late_us == 0u)
        b->cfg.late_us = 50000u;
    if (b->cfg.idle_flush_us == 0u)
        b->cfg.idle_flush_us = 5000u;
    b->rng = b->cfg.seed;
    b->present = ids;
    b->send = send;
    b->log = log;
    b->user = user;
    (void)j288_parser_init(&b->parser, J288_PARSE_COMMAND, NULL);
    /* Rotor phase and start angle drawn for every id, present or not, so that a servo's
     * start does not depend on which others are on the bus. Four draws per id whatever they
     * are used for: the fault sequence after them depends on the seed alone. */
    for (id = 0u; id < J288_MAX_SERVOS; id++) {
        double c = rng_unit(&b->rng) * TWO_PI;
        double o = rng_unit(&b->rng) * TWO_PI - J288_PI;
        double c2 = rng_unit(&b->rng) * TWO_PI;
        double o2 = rng_unit(&b->rng) * TWO_PI - J288_PI;
        j288_sim_servo_init(&b->servo[id], id, prm, c, o);
        j288_sim_servo_init(&b->dup[id], id, prm, c2, o2);
    }
    return 0;
}

int j288_sim_bus_set_joint(j288_sim_bus_t *b, uint8_t id, double c, double theta)
{
    j288_sim_servo_t *s = j288_sim_bus_servo(b, id);
    j288_sim_params_t prm;
    uint32_t injected;
    if (s == NULL)
        return -1;
    prm = s->prm;
    injected = s->faults_injected;
    j288_sim_servo_init(s, id, &prm, c, theta);
    s->faults_injected = injected;
    return 0;
}

int j288_sim_bus_power_cycle(j288_sim_bus_t *b, uint16_t ids, uint64_t now_us)
{
    uint8_t id;
    int n = 0;
    if ((ids & ~b->present) != 0u)
        return -1;
    if (now_us > b->now_us)
        b->now_us = now_us;
    for (id = 0u; id < J288_MAX_SERVOS; id++) {
        if ((ids & (1u << id)) == 0u)
            continue;
        j288_sim_servo_power_cycle(&b->servo[id], now_us, b->cfg.power_off_us);
        n++;
        if (has_dup(b, id)) {
            j288_sim_servo_power_cycle(&b->dup[id], now_us, b->cfg.power_off_us);
            n++;
        }
    }
    b->stats.power_cycles += (uint64_t)n;
    return n;
}

int j288_sim_bus_inject_faults(j288_sim_bus_t *b, uint8_t id, uint32_t bits)
{
    if (id > J288_MAX_ID || (b->present & (1u << id)) == 0u)
        return -1;
    b->servo[id].faults_injected = bits;
    b->dup[id].faults_injected = bits;
    return 0;
}

void j288_sim_bus_set_faults(j288_sim_bus_t *b, bool on)
{
    b->faults_off = !on;
}

j288_sim_servo_t *j288_sim_bus_servo(j288_sim_bus_t *b, uint8_t id)
{
    if (id > J288_MAX_ID || (b->present & (1u << id)) == 0u)
        return NULL;
    return &b->servo[id];
}

/* The watchdog's silence clock held over [from_us, to_us): its last command moves later by
 * the part of the stretch that came after it. */
static void excuse_stall(j288_sim_servo_t *s, uint64_t from_us, uint64_t to_us)
{
    uint64_t start = s->last_cmd_us > from_us ? s->last_cmd_us : from_us;
    if (start < to_us)
        s->last_cmd_us += to_us - start;
}

void j288_sim_bus_excuse_stall(j288_sim_bus_t *b, uint64_t from_us, uint64_t to_us)
{
    uint8_t id;
    for (id = 0u; id < J288_MAX_SERVOS; id++) {
        if ((b->present & (1u << id)) == 0u)
            continue;
        excuse_stall(&b->servo[id], from_us, to_us);
        if (has_dup(b, id))
            excuse_stall(&b->dup[id], from_us, to_us);
    }
}

void j288_sim_bus_advance(j288_sim_bus_t *b, uint64_t now_us)
{
    uint8_t id;
    uint64_t trips = 0;
    if (now_us > b->now_us)
        b->now_us = now_us;
    for (id = 0u; id < J288_MAX_SERVOS; id++) {
        if ((b->present & (1u << id)) == 0u)
            continue;
        j288_sim_servo_advance(&b->servo[id], now_us);
        trips += b->servo[id].watchdog_trips;
        if (has_dup(b, id))
            j288_sim_servo_advance(&b->dup[id], now_us);
    }
    b->stats.watchdog_trips = trips;
}

static void emit(j288_sim_bus_t *b, uint64_t at_us, const uint8_t *data, size_t len)
{
    if (b->send != NULL)
        b->send(b->user, at_us, data, len);
}

/* One servo's answer, with the injected faults unless they are switched off. Draws the same
 * random numbers whatever is decided, so one fault's probability (or the switch) does not
 * shift the others' sequence. */
static void answer(j288_sim_bus_t *b, j288_sim_servo_t *s, uint64_t now_us)
{
    j288_reply_raw_t r;
    uint8_t frame[J288_REPLY_LEN];
    uint8_t noise[8];
    size_t nnoise, i;
    double u_drop = rng_unit(&b->rng);
    double u_corrupt = rng_unit(&b->rng);
    double u_late = rng_unit(&b->rng);
    double u_noise = rng_unit(&b->rng);
    uint64_t r1 = rng_next(&b->rng);
    uint64_t r2 = rng_next(&b->rng);
    uint64_t at = now_us + b->cfg.turnaround_us;

    j288_sim_servo_reply(s, &r);
    if (j288_reply_encode(&r, frame, NULL) != J288_OK)
        return; /* cannot happen: every field comes from the model within range */
    if (b->faults_off) {
        emit(b, at, frame, sizeof frame);
        b->stats.replies++;
        return;
    }
    if (u_drop < b->cfg.drop) {
        b->stats.dropped++;
        return;
    }
    if (u_corrupt < b->cfg.corrupt) {
        size_t pos = (size_t)(r1 % J288_REPLY_LEN);
        uint8_t flip = (uint8_t)(1u + (r2 % 255u));
        frame[pos] = (uint8_t)(frame[pos] ^ flip);
        b->stats.corrupted++;
    }
    if (u_late < b->cfg.late) {
        at += b->cfg.late_us;
        b->stats.late++;
    }
    if (u_noise < b->cfg.noise) {
        nnoise = 1u + (size_t)((r1 >> 16) % 8u);
        for (i = 0u; i < nnoise; i++)
            noise[i] = (uint8_t)(r2 >> (8u * i));
        emit(b, at, noise, nnoise);
        b->stats.noise++;
    }
    emit(b, at, frame, sizeof frame);
    b->stats.replies++;
}

static void dispatch(j288_sim_bus_t *b, const j288_cmd_raw_t *cmd, uint64_t now_us)
{
    uint8_t id;
    if (cmd->id == J288_BROADCAST_ID) {
        b->stats.broadcasts++;
        for (id = 0u; id < J288_MAX_SERVOS; id++) {
            if ((b->present & (1u << id)) == 0u)
                continue;
            (void)j288_sim_servo_command(&b->servo[id], cmd, now_us);
            if (has_dup(b, id))
                (void)j288_sim_servo_command(&b->dup[id], cmd, now_us);
        }
        return; /* obeyed silently */
    }
    id = cmd->id;
    if ((b->present & (1u << id)) == 0u) {
        b->stats.for_others++;
        return;
    }
    if (j288_sim_servo_command(&b->servo[id], cmd, now_us))
        answer(b, &b->servo[id], now_us);
    if (has_dup(b, id)) {
        if (j288_sim_servo_command(&b->dup[id], cmd, now_us) && !b->faults_off) {
            answer(b, &b->dup[id], now_us);
            b->stats.duplicates++;
        }
    }
}

static void bad_crc(j288_sim_bus_t *b)
{
    uint8_t id = (uint8_t)(b->window[2] & 0x0Fu);
    uint8_t i;
    b->stats.bad_crc++;
    for (i = 0u; i < J288_MAX_SERVOS; i++) {
        if ((b->present & (1u << i)) == 0u || (id != J288_BROADCAST_ID && id != i))
            continue;
        j288_sim_servo_bad_crc(&b->servo[i]);
        if (has_dup(b, i))
            j288_sim_servo_bad_crc(&b->dup[i]);
    }
}

void j288_sim_bus_feed(j288_sim_bus_t *b, const uint8_t *data, size_t len, uint64_t now_us)
{
    size_t i;
    if (len == 0u)
        return;
    if (now_us > b->now_us)
        b->now_us = now_us;
    /* A real servo's receiver restarts after a quiet line: a half command from long ago
     * must not swallow the next one. */
    if (now_us - b->last_byte_us >= b->cfg.idle_flush_us)
        (void)j288_parser_flush(&b->parser);
    b->last_byte_us = now_us;
    for (i = 0u; i < len; i++) {
        uint32_t crc_before = j288_parser_stats(&b->parser)->crc_errors;
        size_t used = 0u;
        int rc;
        memmove(b->window, b->window + 1, J288_CMD_LEN - 1u);
        b->window[J288_CMD_LEN - 1u] = data[i];
        b->stats.bytes++;
        /* Byte by byte, so that the window holds exactly the frame the parser judged. */
        rc = j288_parser_feed(&b->parser, &data[i], 1u, &used);
        if (rc == J288_PARSE_FRAME) {
            j288_cmd_raw_t cmd;
            if (j288_cmd_decode(j288_parser_frame(&b->parser), &cmd, NULL) == J288_OK) {
                b->stats.commands++;
                if (b->log != NULL)
                    b->log(b->user, now_us, b->window, &cmd);
                dispatch(b, &cmd, now_us);
            }
        } else if (j288_parser_stats(&b->parser)->crc_errors != crc_before) {
            if (b->log != NULL)
                b->log(b->user, now_us, b->window, NULL);
            bad_crc(b);
        }
    }
}
