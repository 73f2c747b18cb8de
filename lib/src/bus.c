/* bus.c - the half-duplex bus engine (stub: full implementation follows). */
#include "j288/bus.h"

#include <string.h>

int j288_bus_init(j288_bus_t *bus, const j288_port_t *port, void *port_ctx,
                  const j288_bus_config_t *cfg)
{
    (void)port_ctx;
    (void)cfg;
    if (bus == NULL || port == NULL) return J288_ERR_NULL;
    memset(bus, 0, sizeof *bus);
    return J288_ERR_PORT_OPS;
}

int j288_bus_submit(j288_bus_t *bus, const j288_cmd_raw_t *cmd, uint32_t now_us,
                    j288_bus_done_fn done, void *user)
{
    (void)now_us;
    (void)done;
    (void)user;
    if (bus == NULL || cmd == NULL) return J288_ERR_NULL;
    return J288_ERR_BUSY;
}

void j288_bus_poll(j288_bus_t *bus, uint32_t now_us) { (void)bus; (void)now_us; }
void j288_bus_on_tx_done(j288_bus_t *bus) { (void)bus; }
void j288_bus_on_rx(j288_bus_t *bus, const uint8_t *data, size_t len)
{
    (void)bus;
    (void)data;
    (void)len;
}
void j288_bus_on_rx_idle(j288_bus_t *bus) { (void)bus; }
void j288_bus_on_error(j288_bus_t *bus, uint32_t line_flags) { (void)bus; (void)line_flags; }
void j288_bus_on_timer(j288_bus_t *bus) { (void)bus; }

int j288_bus_estop(j288_bus_t *bus, uint32_t now_us)
{
    (void)now_us;
    return bus == NULL ? J288_ERR_NULL : J288_OK;
}

int j288_bus_transfer_blocking(j288_bus_t *bus, const j288_cmd_raw_t *cmd, j288_txn_t *txn)
{
    (void)txn;
    if (bus == NULL || cmd == NULL) return J288_ERR_NULL;
    return J288_ERR_PORT_OPS;
}

j288_bus_state_t j288_bus_state(const j288_bus_t *bus)
{
    return bus == NULL ? J288_BUS_IDLE : (j288_bus_state_t)bus->state;
}
bool j288_bus_is_idle(const j288_bus_t *bus) { return j288_bus_state(bus) == J288_BUS_IDLE; }
const j288_bus_stats_t *j288_bus_stats(const j288_bus_t *bus)
{
    return bus == NULL ? NULL : &bus->stats;
}
const j288_parser_stats_t *j288_bus_parser_stats(const j288_bus_t *bus)
{
    return bus == NULL ? NULL : &bus->parser.stats;
}

uint32_t j288_wire_time_us(uint32_t baud, uint32_t nbytes)
{
    uint64_t bits = (uint64_t)nbytes * 10u * 1000000u;
    if (baud == 0u) return 0u;
    return (uint32_t)((bits + baud - 1u) / baud);
}

uint32_t j288_bus_reply_budget_us(const j288_bus_t *bus)
{
    return bus == NULL ? 0u : bus->reply_budget_us;
}
