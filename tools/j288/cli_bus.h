/*
 * cli_bus.h - what the bus commands share: the options every one of them takes (--port,
 * --baud, --margin-us, --echo, --retries), opening the Linux port and binding a bus, one
 * blocking transaction, the SIGINT/SIGTERM stop flag, and the safe stop (lock every servo a
 * command drove).
 *
 * Signals: cli_signals_install() sets handlers (without SA_RESTART) that only record the
 * signal in cli_stop_signal; the port's sleeps return early on it (j288_linux_set_stop_flag)
 * and the command loops see it within a millisecond or so, then send the locks themselves.
 */
#ifndef J288_CLI_BUS_H
#define J288_CLI_BUS_H

#include <signal.h>
#include <stdbool.h>
#include <stdint.h>

#include "args.h"
#include "cli.h"
#include "j288_linux.h"

/* Keys of the common options; commands number their own below CLI_BUS_OPT_BASE. */
#define CLI_BUS_OPT_BASE 100
enum {
    CLI_OPT_PORT = CLI_BUS_OPT_BASE,
    CLI_OPT_BAUD,
    CLI_OPT_MARGIN,
    CLI_OPT_ECHO,
    CLI_OPT_RETRIES,
    CLI_OPT_JSON
};
#define CLI_BUS_COMMON_OPTS                                                                        \
    {"--port", true, CLI_OPT_PORT}, {"--baud", true, CLI_OPT_BAUD},                                \
        {"--margin-us", true, CLI_OPT_MARGIN}, {"--echo", false, CLI_OPT_ECHO},                    \
        {"--retries", true, CLI_OPT_RETRIES},                                                      \
    {                                                                                              \
        "--json", false, CLI_OPT_JSON                                                              \
    }

#define CLI_BUS_COMMON_HELP                                                                        \
    "common options:\n"                                                                            \
    "  --port DEV       serial device (or give it before the command; default $J288_PORT)\n"       \
    "  --baud N         line rate, default 6000000\n"                                              \
    "  --margin-us N    reply deadline margin for host latency; default 20000 for a USB\n"         \
    "                   adapter, 5000 for a pseudo-terminal (the simulator)\n"                     \
    "  --echo           the adapter hears its own transmit (skip and check the echo)\n"            \
    "  --retries N      re-send a failed command up to N times (0-3)\n"                            \
    "  --json           machine-readable output\n"

typedef struct {
    const char *port;
    uint32_t baud;      /* 0: default */
    uint32_t margin_us; /* 0: by device kind */
    bool echo;
    int retries; /* -1: the command's default */
    bool json;
} cli_bus_opts_t;

typedef struct {
    j288_linux_t lp;
    j288_bus_t bus;
    bool open;
    const char *dev;
    uint16_t driven; /* ids this command has sent a moving (FOC) command to */
} cli_bus_t;

extern volatile sig_atomic_t cli_stop_signal;

/* Start from the global options (cli_global_t). */
void cli_bus_opts_init(cli_bus_opts_t *o, const cli_global_t *g);

/* Handle a common option key; returns 0, or -1 after an error message. Keys below
 * CLI_BUS_OPT_BASE are not common: returns 1 (not handled). */
int cli_bus_common_opt(cli_bus_opts_t *o, int key, const char *value);

/* SIGINT/SIGTERM record the signal in cli_stop_signal (the first one wins). */
void cli_signals_install(void);

/* Exit code for a command stopped by a signal (130 or 143). */
int cli_signal_exit_code(void);

/* Open the device and bind a bus. Prints the port's notices (low latency refused, ...) as
 * "note:" lines on stderr only when J288_VERBOSE is set, and one error line on failure.
 * Returns CLI_EXIT_OK or CLI_EXIT_FAIL / CLI_EXIT_USAGE. */
int cli_bus_open(cli_bus_t *b, const cli_bus_opts_t *o, int default_retries);
void cli_bus_close(cli_bus_t *b);

/* One blocking transaction (retries as configured). Returns the library result. */
int cli_bus_transfer(cli_bus_t *b, const j288_cmd_raw_t *cmd, j288_txn_t *txn);

/* A lock command (status 0, all fields 0) for id, watchdog bit 0: a locked servo needs no
 * watchdog, and the bit 0 also clears a tripped one. */
void cli_lock_cmd(uint8_t id, j288_cmd_raw_t *cmd);

/* Send lock to every id in b->driven (each confirmed by its reply, re-sent up to three
 * times), then, if any stayed silent, a broadcast lock. Runs even after a stop signal.
 * Returns the number of servos that did not confirm. */
int cli_bus_lock_driven(cli_bus_t *b);

/* A one-line description of a failed transaction for id: "no reply from servo 3 (timeout)"
 * or the port's own message when the device is gone. */
void cli_report_txn_failure(cli_bus_t *b, uint8_t id, int rc);

/* Sleep until until_us (j288_linux_now_us() time) while keeping the port serviced.
 * Returns J288_OK, J288_ERR_ABORTED (stop signal) or J288_ERR_OFFLINE. */
int cli_bus_sleep_until(cli_bus_t *b, uint32_t until_us);

#endif /* J288_CLI_BUS_H */
