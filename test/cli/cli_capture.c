/* The tool's error stream in a temporary file (see cli_capture.h). */
#include "cli_capture.h"

#include <string.h>

#include "cli.h"
#include "unity.h"

static FILE *captured;

FILE *cli_capture_begin(void)
{
    captured = tmpfile();
    cli_set_error_stream(captured);
    cli_set_command("test");
    return captured;
}

void cli_capture_end(void)
{
    cli_set_error_stream(NULL);
    if (captured != NULL)
        fclose(captured);
    captured = NULL;
}

int cli_error_lines(char *line, size_t len)
{
    int n = 0, c;
    size_t i = 0;
    TEST_ASSERT_NOT_NULL_MESSAGE(captured, "no temporary file for the error stream");
    fflush(captured);
    rewind(captured);
    line[0] = '\0';
    while ((c = fgetc(captured)) != EOF) {
        if (c == '\n') {
            n++;
        } else if (n == 0 && i + 1u < len) {
            line[i++] = (char)c;
            line[i] = '\0';
        }
    }
    return n;
}

void cli_expect_one_error(const char *part)
{
    char line[600];
    TEST_ASSERT_EQUAL_INT_MESSAGE(1, cli_error_lines(line, sizeof line), line);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(line, part), line);
}
