/* sched.c - the cycle scheduler (stub: full implementation follows). */
#include "j288/sched.h"

#include <string.h>

int j288_sched_init(j288_sched_t *s, j288_bus_t *bus, const j288_sched_config_t *cfg)
{
    (void)cfg;
    if (s == NULL || bus == NULL) return J288_ERR_NULL;
    memset(s, 0, sizeof *s);
    s->bus = bus;
    return J288_OK;
}

int j288_sched_enable(j288_sched_t *s, uint8_t id, bool enabled)
{
    if (s == NULL) return J288_ERR_NULL;
    if (id > J288_MAX_ID) return J288_ERR_BAD_ID;
    s->slot[id].enabled = enabled;
    return J288_OK;
}

int j288_sched_set_cmd(j288_sched_t *s, const j288_cmd_raw_t *cmd)
{
    if (s == NULL || cmd == NULL) return J288_ERR_NULL;
    return J288_ERR_BAD_ID;
}

#if J288_CONFIG_SI
int j288_sched_set_cmd_si(j288_sched_t *s, const j288_cmd_si_t *cmd, j288_side_t side)
{
    (void)side;
    if (s == NULL || cmd == NULL) return J288_ERR_NULL;
    return J288_ERR_BAD_ID;
}
#endif

int j288_sched_start_sweep(j288_sched_t *s, uint32_t now_us)
{
    (void)now_us;
    return s == NULL ? J288_ERR_NULL : J288_ERR_BUSY;
}

void j288_sched_poll(j288_sched_t *s, uint32_t now_us) { (void)s; (void)now_us; }
bool j288_sched_busy(const j288_sched_t *s) { return s != NULL && s->sweeping; }

int j288_sched_clear_watchdog(j288_sched_t *s, uint8_t id)
{
    if (s == NULL) return J288_ERR_NULL;
    if (id > J288_MAX_ID) return J288_ERR_BAD_ID;
    return J288_OK;
}

int j288_sched_estop(j288_sched_t *s, uint32_t now_us)
{
    (void)now_us;
    return s == NULL ? J288_ERR_NULL : J288_OK;
}

const j288_slot_t *j288_sched_slot(const j288_sched_t *s, uint8_t id)
{
    if (s == NULL || id > J288_MAX_ID) return NULL;
    return &s->slot[id];
}

uint32_t j288_sched_sweeps(const j288_sched_t *s) { return s == NULL ? 0u : s->sweeps; }
