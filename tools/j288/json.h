/*
 * json.h - a minimal streaming JSON writer (objects, arrays, integers, reals, strings,
 * booleans) producing one compact line per top-level value.
 *
 * Keys are given with each value inside an object and NULL inside an array. Reals are
 * printed with 10 significant digits; a non-finite real becomes null (JSON has no NaN).
 * Strings are escaped. Nesting deeper than CLI_JSON_MAX_DEPTH is ignored (not needed here).
 */
#ifndef J288_CLI_JSON_H
#define J288_CLI_JSON_H

#include <stdbool.h>
#include <stdio.h>

#define CLI_JSON_MAX_DEPTH 8

typedef struct {
    FILE *f;
    int depth;
    bool has_items[CLI_JSON_MAX_DEPTH + 1];
} cli_json_t;

void cli_json_init(cli_json_t *j, FILE *f);
void cli_json_begin_object(cli_json_t *j, const char *key);
void cli_json_end_object(cli_json_t *j);
void cli_json_begin_array(cli_json_t *j, const char *key);
void cli_json_end_array(cli_json_t *j);
void cli_json_int(cli_json_t *j, const char *key, long long v);
void cli_json_uint(cli_json_t *j, const char *key, unsigned long long v);
void cli_json_real(cli_json_t *j, const char *key, double v);
void cli_json_str(cli_json_t *j, const char *key, const char *s);
void cli_json_bool(cli_json_t *j, const char *key, bool v);
/* End the top-level value with a newline. */
void cli_json_newline(cli_json_t *j);

#endif /* J288_CLI_JSON_H */
