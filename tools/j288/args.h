/*
 * args.h - strict command-line parsing for the j288 tool.
 *
 * Options are long ("--id 3" or "--id=3"); "-h" is --help; "--" ends the options. A value is
 * always the next argument, even when it starts with '-' (so "--tau -0.5" works). Numbers
 * must be complete: "3x", "", " 3" and "0x" are refused, as are NaN and infinities. Every
 * parse function prints one error line (cli_error) naming the option and returns -1, or
 * returns 0 with the value stored.
 */
#ifndef J288_CLI_ARGS_H
#define J288_CLI_ARGS_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "j288_range.h"

typedef struct {
    const char *name; /* "--id" */
    bool has_value;
    int key; /* >= 0, returned by cli_args_next() */
} cli_opt_t;

#define CLI_ARG_END        (-1)
#define CLI_ARG_POSITIONAL (-2)
#define CLI_ARG_ERROR      (-3)
#define CLI_ARG_HELP       (-4)

typedef struct {
    int argc;
    char **argv;
    int index;            /* next argument to look at */
    bool only_positional; /* after "--" */
    const char *opt_name; /* the option just returned, for messages */
} cli_args_t;

/* Start after argv[0] (the command name). */
void cli_args_init(cli_args_t *a, int argc, char **argv);

/*
 * Next item: an option's key (its value, if any, in *value), CLI_ARG_POSITIONAL (*value is
 * the argument), CLI_ARG_HELP (-h/--help), CLI_ARG_END, or CLI_ARG_ERROR (unknown option,
 * missing value, value given to a flag; already reported). opts ends with a NULL name.
 */
int cli_args_next(cli_args_t *a, const cli_opt_t *opts, const char **value);

/* Whole number in [lo, hi]: j288_number_int()'s syntax (host/j288_number.h, the robot config
 * file's too): decimal or 0x-prefixed hexadecimal, optional sign. */
int cli_parse_int(const char *opt, const char *text, long long lo, long long hi, long long *out);

/* Finite real number: j288_number_real()'s decimal syntax (host/j288_number.h, the robot
 * config file's too): "1.5", "-.5", "2e-3"; not "0x1p1", "inf" or "nan". */
int cli_parse_real(const char *opt, const char *text, double *out);

/* Finite real number in [lo, hi] ("OPT: TEXT is out of range LO..HI" otherwise). */
int cli_parse_real_in(const char *opt, const char *text, double lo, double hi, double *out);

/* A value of quantity q (host/j288_range.h: the range the robot config checks too), given
 * as text by from (the option, or e.g. "$J288_BAUD", for the message): a whole number for the
 * whole quantities, else a real one, in the entry's range ("FROM: TEXT is out of range
 * LO..HI" otherwise). */
int cli_parse_qty(j288_quantity_t q, const char *from, const char *text, double *out);

/* A gain option (q J288_QTY_KP or _KD, named as the table names it): cli_parse_qty(), and
 * *given set when it parsed. */
int cli_parse_gain(j288_quantity_t q, const char *text, bool *given, double *out);

/* One of choices (NULL-terminated); *out is its index. */
int cli_parse_choice(const char *opt, const char *text, const char *const *choices, int *out);

/* A mask (bit per id) of every servo id, 0 to J288_MAX_ID. */
#define CLI_ALL_IDS ((uint32_t)((1ul << (J288_MAX_ID + 1u)) - 1u))

/* Comma-separated servo ids, each in [0, max_id], no duplicates: sets bits of *mask. */
int cli_parse_id_list(const char *opt, const char *text, unsigned max_id, uint32_t *mask);

#endif /* J288_CLI_ARGS_H */
