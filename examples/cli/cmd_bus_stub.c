/* Placeholder for the bus commands until the Linux port lands. */
#include "cli.h"

static int not_yet(void)
{
    cli_error("bus commands are not built yet");
    return CLI_EXIT_FAIL;
}

int cli_cmd_scan(int argc, char **argv, const cli_global_t *g) { (void)argc; (void)argv; (void)g; return not_yet(); }
int cli_cmd_status(int argc, char **argv, const cli_global_t *g) { (void)argc; (void)argv; (void)g; return not_yet(); }
int cli_cmd_hold(int argc, char **argv, const cli_global_t *g) { (void)argc; (void)argv; (void)g; return not_yet(); }
int cli_cmd_move(int argc, char **argv, const cli_global_t *g) { (void)argc; (void)argv; (void)g; return not_yet(); }
int cli_cmd_torque(int argc, char **argv, const cli_global_t *g) { (void)argc; (void)argv; (void)g; return not_yet(); }
int cli_cmd_stop(int argc, char **argv, const cli_global_t *g) { (void)argc; (void)argv; (void)g; return not_yet(); }
int cli_cmd_log(int argc, char **argv, const cli_global_t *g) { (void)argc; (void)argv; (void)g; return not_yet(); }
int cli_cmd_plot(int argc, char **argv, const cli_global_t *g) { (void)argc; (void)argv; (void)g; return not_yet(); }
