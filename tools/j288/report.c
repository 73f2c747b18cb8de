/* Error reporting shared by every command (cli.h): one prefixed line on stderr. */
#include <stdarg.h>
#include <stdio.h>

#include "cli.h"

static const char *current_command;
static FILE *error_stream;

void cli_set_error_stream(FILE *f)
{
    error_stream = f;
}

void cli_set_command(const char *name)
{
    current_command = name;
}

void cli_error(const char *fmt, ...)
{
    va_list ap;
    FILE *f = error_stream != NULL ? error_stream : stderr;
    fflush(stdout);
    if (current_command != NULL) {
        fprintf(f, "j288 %s: ", current_command);
    } else {
        fputs("j288: ", f);
    }
    va_start(ap, fmt);
    vfprintf(f, fmt, ap);
    va_end(ap);
    fputc('\n', f);
}
