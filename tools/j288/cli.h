/*
 * cli.h - what the j288 command-line tool's files share: exit codes, error reporting and the
 * command entry points.
 *
 * Output discipline: a command checks everything it can before writing to stdout, so that a
 * failure leaves stdout empty and says exactly one line on stderr ("j288 CMD: what went
 * wrong"). Help goes to stdout and exits 0.
 */
#ifndef J288_CLI_H
#define J288_CLI_H

#include <stdbool.h>
#include <stdint.h>
#include <stdio.h>

#include "j288/j288.h"

#if !J288_CONFIG_SI
#error "the j288 tool needs the SI-unit API (J288_CONFIG_SI=1)"
#endif

/* Exit codes, documented in `j288 --help`. */
#define CLI_EXIT_OK      0
#define CLI_EXIT_FAIL    1 /* invalid frame, device or bus failure, no reply */
#define CLI_EXIT_USAGE   2 /* bad command line: unknown option, bad or out-of-range value */
#define CLI_EXIT_NO_TOOL 3 /* an optional helper program (gnuplot) is not installed */
#define CLI_EXIT_SIGINT  130
#define CLI_EXIT_SIGTERM 143
#define CLI_EXIT_SIGHUP  129 /* a closed terminal or SSH session: handled as SIGTERM */
#define CLI_EXIT_SIGQUIT 131 /* Ctrl-\: handled as SIGTERM */

/* Global options given before the command (`j288 --port DEV --baud N COMMAND`). Commands
 * that talk to a bus take the same options after the command too, which override them. */
typedef struct {
    const char *port; /* NULL: $J288_PORT, else an error for bus commands */
    uint32_t baud;    /* 0: J288_DEFAULT_BAUD */
    const char *config; /* --config FILE before the command, or NULL */
    /* The bus commands' other common options, accepted before the command too. All-zero:
     * none given. */
    uint32_t margin_us; /* 0: by device kind */
    bool echo;
    bool has_retries;
    uint8_t retries;
} cli_global_t;

/* Watchdog trips the host layer found and cleared in this process (cli_bus.c): main() turns
 * a command's success into exit 1 when it is not 0. */
extern unsigned cli_watchdog_trips;

/* Name used as the message prefix ("encode" -> "j288 encode: ..."). NULL: plain "j288". */
void cli_set_command(const char *name);

/* Where cli_error() writes: NULL (the default) is stderr. For tests. */
void cli_set_error_stream(FILE *f);

/* One line on stderr, prefixed and newline-terminated. */
void cli_error(const char *fmt, ...)
#if defined(__MINGW_PRINTF_FORMAT)
    __attribute__((format(__MINGW_PRINTF_FORMAT, 1, 2))) /* C99 formats (%zu) on Windows */
#elif defined(__GNUC__)
    __attribute__((format(printf, 1, 2)))
#endif
    ;

/* Each command: argv[0] is the command's own name; returns the process exit code. */
int cli_cmd_encode(int argc, char **argv, const cli_global_t *g);
int cli_cmd_decode(int argc, char **argv, const cli_global_t *g);
int cli_cmd_scan(int argc, char **argv, const cli_global_t *g);
int cli_cmd_status(int argc, char **argv, const cli_global_t *g);
int cli_cmd_hold(int argc, char **argv, const cli_global_t *g);
int cli_cmd_move(int argc, char **argv, const cli_global_t *g);
int cli_cmd_torque(int argc, char **argv, const cli_global_t *g);
int cli_cmd_stop(int argc, char **argv, const cli_global_t *g);
int cli_cmd_log(int argc, char **argv, const cli_global_t *g);
int cli_cmd_plot(int argc, char **argv, const cli_global_t *g);
int cli_cmd_zero(int argc, char **argv, const cli_global_t *g);
int cli_cmd_calibrate(int argc, char **argv, const cli_global_t *g);
int cli_cmd_top(int argc, char **argv, const cli_global_t *g);
int cli_cmd_jog(int argc, char **argv, const cli_global_t *g);
/* log, status, hold, stop over every bus of a robot config (cmd_robot.c): taken instead of
 * the one-servo command when cli_robot_takes() says so (a --config, no --id or --joint). */
int cli_cmd_robot(int argc, char **argv, const cli_global_t *g);
bool cli_robot_takes(const char *command, int argc, char **argv, const cli_global_t *g);

#endif /* J288_CLI_H */
