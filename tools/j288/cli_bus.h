/*
 * cli_bus.h - what the bus commands share: the options every one of them takes (--port,
 * --baud, --margin-us, --echo, --retries), opening a bus through the host layer (the runner,
 * host/j288_robot.h: its loop, its stop, its watchdog policy), one transaction, the
 * SIGINT/SIGTERM stop flag, and the safe stop (lock every servo a command drove).
 *
 * Signals: cli_signals_install() sets handlers (without SA_RESTART) that only record the
 * signal in cli_stop_signal; the runner's waits return early on it (j288_robot_set_stop_flag)
 * and the command loops see it within a millisecond or so, then send the locks themselves.
 *
 * Watchdog: a servo found tripped under an FOC command is cleared by the runner; cli_bus_*
 * prints one line for it and counts it in cli_watchdog_trips, and main() turns a command's
 * success into exit 1 when that count is not 0 (never a silent success).
 */
#ifndef J288_CLI_BUS_H
#define J288_CLI_BUS_H

#include <signal.h>
#include <stdbool.h>
#include <stdint.h>

#include "args.h"
#include "cli.h"
#include "j288_robot.h"
#include "j288_robot_config.h"
#include "json.h"

/* Keys of the common options; commands number their own below CLI_BUS_OPT_BASE. */
#define CLI_BUS_OPT_BASE 100
enum {
    CLI_OPT_PORT = CLI_BUS_OPT_BASE,
    CLI_OPT_BAUD,
    CLI_OPT_MARGIN,
    CLI_OPT_ECHO,
    CLI_OPT_RETRIES,
    CLI_OPT_JSON,
    CLI_OPT_CONFIG,
    CLI_OPT_REALTIME,
    CLI_OPT_CPU
};
#define CLI_BUS_COMMON_OPTS                                                                        \
    {"--port", true, CLI_OPT_PORT}, {"--baud", true, CLI_OPT_BAUD},                                \
        {"--margin-us", true, CLI_OPT_MARGIN}, {"--echo", false, CLI_OPT_ECHO},                    \
        {"--retries", true, CLI_OPT_RETRIES}, {"--json", false, CLI_OPT_JSON},                     \
    {                                                                                              \
        "--config", true, CLI_OPT_CONFIG                                                           \
    }

#define CLI_BUS_COMMON_HELP                                                                        \
    "common options:\n"                                                                            \
    "  --port DEV       serial device (or give it before the command; default $J288_PORT)\n"       \
    "  --baud N         line rate, default $J288_BAUD, else 6000000\n"                            \
    "  --margin-us N    reply deadline margin for host latency; default 20000 for a USB\n"         \
    "                   adapter, 5000 for a pseudo-terminal (the simulator)\n"                     \
    "  --echo           the adapter hears its own transmit (skip and check the echo)\n"            \
    "  --retries N      re-send a failed command up to N times (0-3)\n"                            \
    "  --json           machine-readable output\n"                                                \
    "  --config FILE    robot config (YAML): joints by name (--joint), their zero, direction,\n"  \
    "                   limits, gains and phase, and the bus port when --port is not given\n"

/* The options of the commands that run a loop (log, hold, move, torque, top, the robot
 * forms): the runner's real time (j288_rt.h), handled by cli_bus_common_opt(). */
#define CLI_BUS_RT_OPTS                                                                            \
    {"--realtime", CLI_VALUE_OPTIONAL, CLI_OPT_REALTIME}, { "--cpu", true, CLI_OPT_CPU }

#define CLI_BUS_RT_HELP                                                                            \
    "real time (docs/realtime.md):\n"                                                              \
    "  --realtime[=PRIO] lock the process's memory and run the loop under SCHED_FIFO at\n"         \
    "                   PRIO (1-99, default 80); without the rights a notice says how to\n"        \
    "                   get them (ulimit -r, limits.d, CAP_SYS_NICE) and the loop runs on\n"      \
    "  --cpu N          pin the loop to CPU N\n"                                                   \
    "Pacing: cycle k is due at the first cycle's time + k/HZ. A cycle that overruns makes\n"       \
    "the next start at once (a missed deadline); periods wholly missed are skipped, never\n"      \
    "sent back to back. The summary's timing lines: cycles, deadlines missed, periods\n"          \
    "skipped, cycles cut at their bound; wake-up lateness and cycle duration (p50, p99,\n"       \
    "p99.9, max).\n"

typedef struct {
    const char *port;
    uint32_t baud;      /* 0: default */
    uint32_t margin_us; /* 0: by device kind */
    bool echo;
    int retries; /* -1: the command's default */
    bool json;
    const char *config; /* --config FILE, or NULL */
    int realtime;       /* --realtime[=PRIO]: the priority; 0: not asked */
    int cpu;            /* --cpu N; -1: not asked */
} cli_bus_opts_t;

typedef struct {
    j288_robot_t *robot; /* the host layer's runner on this one bus (no joints) */
    bool open;
    const char *dev;
    uint16_t driven; /* ids this command has sent a moving (FOC) command to */
} cli_bus_t;

extern volatile sig_atomic_t cli_stop_signal;

/* Print the port's notices (low latency refused, latency timer advice) on stderr, once per
 * process: they explain late replies, so a user sees them without J288_VERBOSE. Scripts that
 * want a quiet stderr set J288_QUIET=1. */
void cli_print_notices(const char *notices);

/* Count and report a trip the runner cleared on servo id (j288_robot_transfer()'s flag, a
 * J288_ROBOT_EV_WATCHDOG event). */
void cli_report_watchdog(const char *what);

/* Say in one error line which buses were lost (went down or vanished) since r was opened:
 * "bus 'leg1' lost during the command (exit 1)". Returns how many; 0 says nothing. A front end
 * that drives joints exits CLI_EXIT_FAIL on any (issue 29: no silent robot fault). */
unsigned cli_report_lost_buses(const j288_robot_t *r);

/* Start from the global options (cli_global_t). */
void cli_bus_opts_init(cli_bus_opts_t *o, const cli_global_t *g);

/* The parse loop of a bus command: common options go to o, the command's own keys (and
 * positional arguments, key CLI_ARG_POSITIONAL) to fn (NULL: none), which returns 0, -1 after
 * an error message, or 1 for "not mine". Returns 0 when done, or -1 with *exit_code set
 * (CLI_EXIT_OK after --help, which prints help; CLI_EXIT_USAGE). */
typedef int (*cli_own_opt_fn)(void *ctx, int key, const char *value);
int cli_parse_bus_args(int argc, char **argv, const cli_opt_t *opts, const char *help,
                       cli_bus_opts_t *o, cli_own_opt_fn fn, void *ctx, int *exit_code);

/* Handle a common option key; returns 0, or -1 after an error message. Keys below
 * CLI_BUS_OPT_BASE are not common: returns 1 (not handled). */
int cli_bus_common_opt(cli_bus_opts_t *o, int key, const char *value);

/* SIGINT, SIGTERM, SIGHUP (a closed terminal or SSH session) and SIGQUIT record the signal
 * in cli_stop_signal (the first one wins): each stops a command the same way. A SIGHUP or
 * SIGQUIT the process was started ignoring (nohup, a background job) stays ignored. */
void cli_signals_install(void);

/* Exit code for a command stopped by a signal, 128 + its number as a shell reports a process
 * killed by it: 130 SIGINT, 143 SIGTERM, 129 SIGHUP, 131 SIGQUIT. */
int cli_signal_exit_code(void);

/* The line rate: given (a --baud, or 0), else $J288_BAUD when set, else 0 (the default). 0, or
 * -1 after one error line ($J288_BAUD out of range or not a number). For every bus a command
 * opens whose config entry gives no baud. */
int cli_bus_baud(uint32_t given, uint32_t *baud);

/* Open the device through the runner (j288_robot_open_port()). Prints the port's notices
 * once (cli_print_notices()), and one error line on failure. Returns CLI_EXIT_OK or
 * CLI_EXIT_FAIL / CLI_EXIT_USAGE. */
int cli_bus_open(cli_bus_t *b, const cli_bus_opts_t *o, int default_retries);
/* The real-time part of the runner's options from o (--realtime, --cpu). */
void cli_bus_rt_options(const cli_bus_opts_t *o, j288_robot_options_t *ro);

/* What the runner's real-time set-up refused and how to allow it, on stderr (nothing under
 * J288_QUIET=1). */
void cli_print_rt_notice(const j288_robot_t *r);

/* The loop's timing (j288_robot_timing()): its three "timing: " lines on f, or a "timing"
 * object in a JSON object being written. */
void cli_print_timing(FILE *f, const j288_robot_t *r);
void cli_json_timing(cli_json_t *j, const j288_robot_t *r);

/* Close; servos the command drove and did not lock are stopped by the runner. */
void cli_bus_close(cli_bus_t *b);
/* Close leaving the last command in force (--keep). */
void cli_bus_close_keep(cli_bus_t *b);
/* The host layer's latest message without its "bus 'NAME': " prefix (one bus here). */
const char *cli_bus_error(const cli_bus_t *b);

/* Whether the device has vanished. */
bool cli_bus_gone(const cli_bus_t *b);

/* One transaction (retries as configured) through the runner (j288_robot_transfer(): a lock
 * goes out with the watchdog bit 0; a trip under FOC is cleared, reported and counted).
 * Returns the library result. */
int cli_bus_transfer(cli_bus_t *b, const j288_cmd_raw_t *cmd, j288_txn_t *txn);

/* A lock command (status 0, all fields 0) for id, watchdog bit 0: a locked servo needs no
 * watchdog, and the bit 0 also clears a tripped one. */
void cli_lock_cmd(uint8_t id, j288_cmd_raw_t *cmd);

/* Send lock to every id in b->driven (each confirmed by its reply; one not confirmed is
 * re-sent at least three times and until 0.5 s after the call began, so that a slow answer
 * from a busy machine or adapter is still taken), then, if any stayed silent, a broadcast
 * lock. Runs even after a stop signal. Takes at most 0.5 s plus three transactions per
 * silent servo. Returns the number of servos that did not confirm. */
int cli_bus_lock_driven(cli_bus_t *b);

/* A one-line description of a failed transaction for id: "no reply from servo 3 (timeout)"
 * or the port's own message when the device is gone. */
void cli_report_txn_failure(cli_bus_t *b, uint8_t id, int rc);

/* Sleep until until_us (j288_robot_now_us() time) while the runner keeps the port serviced
 * (j288_robot_idle()). Returns J288_OK, J288_ERR_ABORTED (stop signal) or J288_ERR_OFFLINE. */
int cli_bus_sleep_until(cli_bus_t *b, uint32_t until_us);

/* ---- the robot config and the joint frame (cli_joint.c) -------------------------------------
 *
 * A bus command that addresses one servo finds it with --id N or --joint NAME (NAME needs
 * --config). cli_joint_select() resolves that to a joint configuration: the file's joint
 * (j288_robot_config_joint_config()), or without a file the library's all-zero configuration,
 * in which the joint angle is the output encoder angle wrapped to [-pi, pi). It also fills
 * the bus options the command line left open (port, baud, margin, echo) from the joint's bus
 * in the file. Other commands (a multi-bus runner) can call the same functions. */

/* A loaded robot config (large: keep it static or on the heap). */
typedef struct {
    const char *path; /* NULL: no --config */
    j288_robot_config_t cfg;
} cli_robot_t;

/* What cli_joint_select() resolved. */
typedef struct {
    uint8_t id;
    const j288_robot_config_joint_t *rj; /* the file's joint, or NULL (no file, or not in it) */
    j288_joint_config_t jc;             /* checked, the library's defaults filled in
                                           (j288_joint_config()) */
    char name[J288_ROBOT_CONFIG_NAME_MAX + 16]; /* "hip" or "servo 3", for messages */
} cli_joint_sel_t;

/* Load path (NULL: r->path = NULL, nothing else). 0, or -1 after one error line. */
int cli_robot_load(cli_robot_t *r, const char *path);

/* The joint by name (--joint, needs a file) or by id (id >= 0: the file's joint with that id,
 * if any; one on the bus of o->port when several buses use the id). Fills o's open bus
 * options from the joint's bus, or from the file's only bus. 0, or -1 after one error line
 * (unknown name, --joint without --config, id ambiguous, configuration the library refuses:
 * "FILE:LINE: joint NAME: ..."). */
int cli_joint_select(const cli_robot_t *r, const char *joint_name, long long id,
                     cli_bus_opts_t *o, cli_joint_sel_t *sel);

/* The joint of configuration jc on the open bus, through the host layer: the runner's
 * servo-level joint set to jc (j288_robot_servo_joint_setup()), which every transfer on b
 * feeds, in *j; then its start-up reads (j288_robot_acquire_joint(): locks until its angle is
 * known, bounded). The last good exchange in *last, the replies in *replies. CLI_EXIT_OK; the
 * signal exit code; or CLI_EXIT_FAIL after one error line (no reply, or with report_unknown:
 * encoder fault, calibration mismatch, no agreement; without it *j's state says why). */
int cli_joint_start(cli_bus_t *b, const j288_joint_config_t *jc, const char *name,
                    const j288_joint_t **j, j288_txn_t *last, unsigned *replies,
                    bool report_unknown);

/* Why j's angle is unknown after replies replies, as one line (no prefix) in buf. */
void cli_joint_why_unknown(const j288_joint_t *j, const char *name, unsigned replies, char *buf,
                           size_t len);

/* Fill o's open bus options (port, baud, margin, echo) from rj's bus, or with rj NULL or
 * without a bus from the file's only bus. Nothing without a file. */
void cli_robot_fill_bus(const cli_robot_t *r, const j288_robot_config_joint_t *rj,
                        cli_bus_opts_t *o);

/* One line for a library error on joint name's target, naming the value and the limit:
 * "hip: --pos 2: target position outside the joint's limits [-1.5, 1.5]; nothing sent". */
void cli_joint_target_error(const j288_joint_config_t *jc, const char *name, const char *what,
                            double value, int rc);

/* The gains of a drive: the command line's (have_*), else the file's joint's, else the host
 * layer's defaults (J288_ROBOT_DEFAULT_KP / _KD: the same as the robot form's hold). */
void cli_joint_gains(const j288_robot_config_joint_t *rj, bool have_kp, double kp, bool have_kd,
                     double kd, double *out_kp, double *out_kd);

/* How far beyond its limits a joint may be for hold and move to start: from the nearest
 * limit, so that the first command pulls it in by at most this (rad); the runner's hold
 * allows the same. */
#define CLI_JOINT_START_OUTSIDE_MAX J288_ROBOT_HOLD_BEYOND_MAX

/* The joint-frame pose hold and move start from, given the joint's angle q: q inside the
 * limits (or a clamping joint), else the nearest limit when q is beyond it by at most
 * CLI_JOINT_START_OUTSIDE_MAX. Farther out: an error line and -1. */
int cli_joint_start_inside(const j288_joint_config_t *jc, const char *name, double q,
                           double *q_start);

/* q, or the nearest limit of jc (filled in) when q is beyond it; q itself for a continuous
 * joint. */
double cli_joint_nearest_inside(const j288_joint_config_t *jc, double q);

/* Whether a position target lies within the joint configuration's limits (filled in:
 * cli_joint_select()), the joint is continuous, or it clamps. For checks before the bus is
 * opened. */
bool cli_joint_pos_allowed(const j288_joint_config_t *jc, double pos);

/* The joint-frame members of a JSON object: joint_known, joint_calibrated, joint_pos (rad,
 * only when known), joint_speed, joint_torque, encoder_fault, cal_mismatch, beyond_limit. */
void cli_json_joint_members(cli_json_t *jw, const j288_joint_t *j);

#endif /* J288_CLI_BUS_H */
