/* Strict command-line parsing; see args.h. */
#include "args.h"

#include <string.h>

#include "cli.h"
#include "j288_number.h"

void cli_args_init(cli_args_t *a, int argc, char **argv)
{
    a->argc = argc;
    a->argv = argv;
    a->index = 1;
    a->only_positional = false;
    a->opt_name = NULL;
}

static const cli_opt_t *find_opt(const cli_opt_t *opts, const char *name, size_t name_len)
{
    for (; opts->name != NULL; opts++) {
        if (strlen(opts->name) == name_len && strncmp(opts->name, name, name_len) == 0) {
            return opts;
        }
    }
    return NULL;
}

int cli_args_next(cli_args_t *a, const cli_opt_t *opts, const char **value)
{
    const char *arg;
    const char *eq;
    const cli_opt_t *o;
    size_t name_len;

    *value = NULL;
    if (a->index >= a->argc) {
        return CLI_ARG_END;
    }
    arg = a->argv[a->index++];
    if (a->only_positional || arg[0] != '-' || arg[1] == '\0') {
        *value = arg;
        return CLI_ARG_POSITIONAL;
    }
    if (strcmp(arg, "--") == 0) {
        a->only_positional = true;
        return cli_args_next(a, opts, value);
    }
    if (strcmp(arg, "-h") == 0 || strcmp(arg, "--help") == 0) {
        return CLI_ARG_HELP;
    }
    eq = strchr(arg, '=');
    name_len = eq != NULL ? (size_t)(eq - arg) : strlen(arg);
    o = find_opt(opts, arg, name_len);
    if (o == NULL) {
        cli_error("unknown option '%.*s' (try --help)", (int)name_len, arg);
        return CLI_ARG_ERROR;
    }
    a->opt_name = o->name;
    if (!o->has_value) {
        if (eq != NULL) {
            cli_error("option %s takes no value", o->name);
            return CLI_ARG_ERROR;
        }
        return o->key;
    }
    if (eq != NULL) {
        *value = eq + 1;
    } else if (a->index < a->argc) {
        *value = a->argv[a->index++];
    } else {
        cli_error("option %s needs a value", o->name);
        return CLI_ARG_ERROR;
    }
    return o->key;
}

int cli_parse_int(const char *opt, const char *text, long long lo, long long hi, long long *out)
{
    long long v;
    j288_number_result_t rc = j288_number_int(text, &v);

    if (rc == J288_NUMBER_SYNTAX) {
        cli_error("%s: '%s' is not a whole number", opt, text);
        return -1;
    }
    if (rc == J288_NUMBER_RANGE || v < lo || v > hi) {
        cli_error("%s: %s is out of range %lld..%lld", opt, text, lo, hi);
        return -1;
    }
    *out = v;
    return 0;
}

int cli_parse_real(const char *opt, const char *text, double *out)
{
    j288_number_result_t rc = j288_number_real(text, out);

    if (rc == J288_NUMBER_SYNTAX) {
        cli_error("%s: '%s' is not a number", opt, text);
        return -1;
    }
    if (rc == J288_NUMBER_RANGE) {
        cli_error("%s: %s is out of range", opt, text);
        return -1;
    }
    return 0;
}

int cli_parse_real_in(const char *opt, const char *text, double lo, double hi, double *out)
{
    if (cli_parse_real(opt, text, out) != 0) {
        return -1;
    }
    if (*out < lo || *out > hi) {
        cli_error("%s: %s is out of range %g..%g", opt, text, lo, hi);
        return -1;
    }
    return 0;
}

int cli_parse_qty(j288_quantity_t q, const char *from, const char *text, double *out)
{
    const j288_range_t *r = j288_range(q);
    long long n;
    if (!r->whole) {
        return cli_parse_real_in(from, text, r->lo, r->hi, out);
    }
    if (cli_parse_int(from, text, (long long)r->lo, (long long)r->hi, &n) != 0) {
        return -1;
    }
    *out = (double)n;
    return 0;
}

int cli_parse_gain(j288_quantity_t q, const char *text, bool *given, double *out)
{
    if (cli_parse_qty(q, j288_range(q)->option, text, out) != 0) {
        return -1;
    }
    *given = true;
    return 0;
}

int cli_parse_choice(const char *opt, const char *text, const char *const *choices, int *out)
{
    int i;
    for (i = 0; choices[i] != NULL; i++) {
        if (strcmp(text, choices[i]) == 0) {
            *out = i;
            return 0;
        }
    }
    if (choices[0] != NULL && choices[1] != NULL && choices[2] == NULL) {
        cli_error("%s: '%s' is not %s or %s", opt, text, choices[0], choices[1]);
    } else {
        cli_error("%s: '%s' is not a valid choice", opt, text);
    }
    return -1;
}

int cli_parse_id_list(const char *opt, const char *text, unsigned max_id, uint32_t *mask)
{
    char item[32];
    const char *p = text;
    uint32_t m = 0;

    if (*p == '\0') {
        cli_error("%s: empty id list", opt);
        return -1;
    }
    for (;;) {
        const char *comma = strchr(p, ',');
        size_t n = comma != NULL ? (size_t)(comma - p) : strlen(p);
        long long id;
        if (n == 0 || n >= sizeof item) {
            cli_error("%s: '%s' is not a comma-separated list of ids", opt, text);
            return -1;
        }
        memcpy(item, p, n);
        item[n] = '\0';
        if (cli_parse_int(opt, item, 0, (long long)max_id, &id) != 0) {
            return -1;
        }
        if ((m & (1ul << id)) != 0u) {
            cli_error("%s: id %lld is listed twice", opt, id);
            return -1;
        }
        m |= (uint32_t)(1ul << id);
        if (comma == NULL) {
            break;
        }
        p = comma + 1;
    }
    *mask = m;
    return 0;
}
