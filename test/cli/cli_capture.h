/* The j288 tool's error stream captured in a temporary file, for the tool's unit tests: each
 * refusal must print exactly one error line. Not thread-safe; test code only. */
#ifndef CLI_CAPTURE_H
#define CLI_CAPTURE_H

#include <stddef.h>
#include <stdio.h>

/* Point the tool's error stream at a new temporary file and name the command "test"; returns
 * the file (valid until cli_capture_end), or NULL when no temporary file could be made. */
FILE *cli_capture_begin(void);

/* Give the error stream back to stderr and close the file. */
void cli_capture_end(void);

/* The lines written to the file so far; the first of them (cut to len - 1 bytes) in line. */
int cli_error_lines(char *line, size_t len);

/* Unity assertion: exactly one error line so far, and it contains part. */
void cli_expect_one_error(const char *part);

#endif
