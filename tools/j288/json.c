/* Minimal JSON writer; see json.h. */
#include "json.h"

#include <math.h>

void cli_json_init(cli_json_t *j, FILE *f)
{
    int i;
    j->f = f;
    j->depth = 0;
    for (i = 0; i <= CLI_JSON_MAX_DEPTH; i++) {
        j->has_items[i] = false;
    }
}

static void put_string(FILE *f, const char *s)
{
    fputc('"', f);
    for (; *s != '\0'; s++) {
        unsigned char c = (unsigned char)*s;
        if (c == '"' || c == '\\') {
            fputc('\\', f);
            fputc((int)c, f);
        } else if (c == '\n') {
            fputs("\\n", f);
        } else if (c == '\t') {
            fputs("\\t", f);
        } else if (c < 0x20u) {
            fprintf(f, "\\u%04x", (unsigned)c);
        } else {
            fputc((int)c, f);
        }
    }
    fputc('"', f);
}

/* Separator and key before a value at the current depth. */
static void start_value(cli_json_t *j, const char *key)
{
    if (j->has_items[j->depth]) {
        fputs(", ", j->f);
    }
    j->has_items[j->depth] = true;
    if (key != NULL) {
        put_string(j->f, key);
        fputs(": ", j->f);
    }
}

static void open_container(cli_json_t *j, const char *key, char bracket)
{
    start_value(j, key);
    fputc(bracket, j->f);
    if (j->depth < CLI_JSON_MAX_DEPTH) {
        j->depth++;
    }
    j->has_items[j->depth] = false;
}

static void close_container(cli_json_t *j, char bracket)
{
    fputc(bracket, j->f);
    if (j->depth > 0) {
        j->depth--;
    }
}

void cli_json_begin_object(cli_json_t *j, const char *key)
{
    open_container(j, key, '{');
}
void cli_json_end_object(cli_json_t *j)
{
    close_container(j, '}');
}
void cli_json_begin_array(cli_json_t *j, const char *key)
{
    open_container(j, key, '[');
}
void cli_json_end_array(cli_json_t *j)
{
    close_container(j, ']');
}

void cli_json_int(cli_json_t *j, const char *key, long long v)
{
    start_value(j, key);
    fprintf(j->f, "%lld", v);
}

void cli_json_uint(cli_json_t *j, const char *key, unsigned long long v)
{
    start_value(j, key);
    fprintf(j->f, "%llu", v);
}

void cli_json_real(cli_json_t *j, const char *key, double v)
{
    start_value(j, key);
    if (isfinite(v)) {
        /* Normalise -0 so that output does not depend on the sign of a zero product. */
        fprintf(j->f, "%.10g", v == 0.0 ? 0.0 : v);
    } else {
        fputs("null", j->f);
    }
}

void cli_json_str(cli_json_t *j, const char *key, const char *s)
{
    start_value(j, key);
    put_string(j->f, s);
}

void cli_json_bool(cli_json_t *j, const char *key, bool v)
{
    start_value(j, key);
    fputs(v ? "true" : "false", j->f);
}

void cli_json_newline(cli_json_t *j)
{
    fputc('\n', j->f);
    j->has_items[0] = false;
}
