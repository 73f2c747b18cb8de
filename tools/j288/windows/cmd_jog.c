/* `j288 jog` on Windows: not there. Like top it is a POSIX terminal program (termios raw mode,
 * the arrow keys' escape sequences, poll() on the keyboard); j288.exe links this instead of
 * ../cmd_jog.c and says so, with the commands that drive and tune a joint without a screen. */
#include "cli.h"

int cli_cmd_jog(int argc, char **argv, const cli_global_t *g)
{
    (void)argc;
    (void)argv;
    (void)g;
    cli_set_command("jog");
    cli_error("not available on Windows (a POSIX terminal program); move --pos and hold "
              "--kp --kd drive a joint, log --csv and plot show how it followed");
    return CLI_EXIT_USAGE;
}
