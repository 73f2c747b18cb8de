/*
 * j288 - the command-line tool: an offline frame calculator (encode, decode) and, with
 * --port, a bus master for J288/S288 servos (scan, status, hold, move, torque, stop, log,
 * top), plus plot for the CSV that log writes.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "args.h"
#include "cli.h"

typedef int (*command_fn)(int argc, char **argv, const cli_global_t *g);

typedef struct {
    const char *name;
    command_fn fn;
    const char *summary;
} command_t;

static const command_t commands[] = {
    {"encode", cli_cmd_encode, "print a command frame as hex (offline)"},
    {"decode", cli_cmd_decode, "check and explain a command or reply given as hex (offline)"},
    {"scan", cli_cmd_scan, "list every servo id 0-14 that answers"},
    {"status", cli_cmd_status, "read and decode one servo's reply"},
    {"hold", cli_cmd_hold, "hold a servo at its current position"},
    {"move", cli_cmd_move, "move a servo to a position"},
    {"torque", cli_cmd_torque, "apply a feed-forward torque"},
    {"stop", cli_cmd_stop, "lock one servo, or all (broadcast)"},
    {"log", cli_cmd_log, "run the cycle scheduler and log replies to CSV"},
    {"plot", cli_cmd_plot, "plot a log CSV to PNG with gnuplot"},
    {"zero", cli_cmd_zero, "make a joint's current pose its zero (written to --config)"},
    {"calibrate", cli_cmd_calibrate, "fit a joint's rotor phase (written to --config)"},
    {"top", cli_cmd_top, "live view of every joint and the bus counters (q quits)"},
    {"jog", cli_cmd_jog, "step a joint with the arrow keys and tune its gains, live"},
    {NULL, NULL, NULL}};

static void usage(FILE *f)
{
    const command_t *c;
    fputs("usage: j288 [--port DEV] [--baud N] COMMAND [options]\n"
          "       j288 COMMAND --help\n"
          "\n"
          "commands:\n",
          f);
    for (c = commands; c->name != NULL; c++) {
        fprintf(f, "  %-10s %s\n", c->name, c->summary); /* 2 blanks at least: help2man */
    }
    fputs("\n"
          "global options (bus commands also take them after the command):\n"
          "  --port DEV   serial device of the bus (default: $J288_PORT)\n"
          "  --baud N     line rate in bit/s (default: $J288_BAUD, else 6000000)\n"
          "  --config F   robot config: log, status, hold, stop without --id/--joint drive\n"
          "               every bus and joint in it (j288 --config F log --help)\n"
          "  --margin-us N, --echo, --retries N   as each bus command's (j288 scan --help)\n"
          "  --version    print the library version\n"
          "\n"
          "exit status: 0 success; 1 invalid frame, device or bus failure (no reply, servo\n"
          "absent, device in use or gone); 2 bad command line; 3 optional helper missing\n"
          "(plot without gnuplot); 130/143/129/131 stopped by SIGINT/SIGTERM/SIGHUP/SIGQUIT\n"
          "after locking every servo the command drove.\n",
          f);
}

enum { OPT_PORT, OPT_BAUD, OPT_VERSION, OPT_CONFIG, OPT_MARGIN, OPT_ECHO, OPT_RETRIES };
static const cli_opt_t global_opts[] = {{"--port", true, OPT_PORT},
                                        {"--config", true, OPT_CONFIG},
                                        {"--baud", true, OPT_BAUD},
                                        {"--version", false, OPT_VERSION},
                                        {"--margin-us", true, OPT_MARGIN},
                                        {"--echo", false, OPT_ECHO},
                                        {"--retries", true, OPT_RETRIES},
                                        {NULL, false, 0}};

/* A global option with a value: 0, or -1 after an error line. */
static int global_value(cli_global_t *g, int key, const char *v)
{
    double x;
    if (key == OPT_PORT) {
        g->port = v;
    } else if (key == OPT_CONFIG) {
        g->config = v;
    } else if (key == OPT_BAUD && cli_parse_qty(J288_QTY_BAUD, "--baud", v, &x) == 0) {
        g->baud = (uint32_t)x;
    } else if (key == OPT_MARGIN && cli_parse_qty(J288_QTY_MARGIN_US, "--margin-us", v, &x) == 0) {
        g->margin_us = (uint32_t)x;
    } else if (key == OPT_RETRIES && cli_parse_qty(J288_QTY_RETRIES, "--retries", v, &x) == 0) {
        g->retries = (uint8_t)x;
        g->has_retries = true;
    } else {
        return -1;
    }
    return 0;
}

/* A servo whose watchdog tripped was cleared and reported (cli_bus.h): never exit 0 then. */
static int watchdog_exit(int code)
{
    return (code == CLI_EXIT_OK && cli_watchdog_trips != 0u) ? CLI_EXIT_FAIL : code;
}

int main(int argc, char **argv)
{
    cli_global_t g;
    cli_args_t a;
    const char *v;
    const command_t *c;
    int key;

    memset(&g, 0, sizeof g);
    cli_set_command(NULL);
    cli_args_init(&a, argc, argv);
    /* Global options stop at the first positional argument: the command. */
    for (;;) {
        key = cli_args_next(&a, global_opts, &v);
        if (key == CLI_ARG_END) {
            cli_error("no command given (try j288 --help)");
            return CLI_EXIT_USAGE;
        }
        if (key == CLI_ARG_HELP) {
            usage(stdout);
            return CLI_EXIT_OK;
        }
        if (key == CLI_ARG_ERROR) {
            return CLI_EXIT_USAGE;
        }
        if (key == CLI_ARG_POSITIONAL) {
            break;
        }
        if (key == OPT_VERSION) {
            printf("j288 %s\n", J288_VERSION_STRING);
            return CLI_EXIT_OK;
        }
        if (key == OPT_ECHO) {
            g.echo = true;
        } else if (global_value(&g, key, v) != 0) {
            return CLI_EXIT_USAGE;
        }
    }
    if (strcmp(v, "help") == 0) {
        /* `j288 help CMD` is `j288 CMD --help`. */
        if (a.index < argc) {
            for (c = commands; c->name != NULL; c++) {
                if (strcmp(argv[a.index], c->name) == 0) {
                    char *help_argv[3];
                    help_argv[0] = argv[a.index];
                    help_argv[1] = (char *)"--help";
                    help_argv[2] = NULL;
                    cli_set_command(c->name);
                    return c->fn(2, help_argv, &g);
                }
            }
        }
        usage(stdout);
        return CLI_EXIT_OK;
    }
    if (cli_robot_takes(v, argc - (a.index - 1), argv + (a.index - 1), &g)) {
        cli_set_command(v);
        return watchdog_exit(cli_cmd_robot(argc - (a.index - 1), argv + (a.index - 1), &g));
    }
    for (c = commands; c->name != NULL; c++) {
        if (strcmp(v, c->name) == 0) {
            cli_set_command(c->name);
            return watchdog_exit(c->fn(argc - (a.index - 1), argv + (a.index - 1), &g));
        }
    }
    cli_error("unknown command '%s' (try j288 --help)", v);
    return CLI_EXIT_USAGE;
}
