/* `j288 top` on Windows: not there. The live view is a POSIX terminal program (termios raw
 * mode, poll() on the keyboard and the buses); j288.exe links this instead of ../cmd_top.c
 * and says so, with the commands that give the same figures once. */
#include "cli.h"

int cli_cmd_top(int argc, char **argv, const cli_global_t *g)
{
    (void)argc;
    (void)argv;
    (void)g;
    cli_set_command("top");
    cli_error("not available on Windows (a POSIX terminal program); status --json, or "
              "--config FILE status, give the same figures once");
    return CLI_EXIT_USAGE;
}
