/*
 * Fuzz target: the j288 tool's text parsing (tools/j288/hexparse.c and args.c), linked as
 * functions (no exec). cli_error() is replaced here by a stub that formats into a buffer.
 *
 * Input: byte 0 chooses the case, bytes 1-2 are parameters, the rest is the text (or, for
 * the argument case, NUL-separated arguments). Text buffers are heap-allocated to their exact
 * size so that ASan sees any read or write beyond them.
 *
 * Invariants:
 * - hex: success only for text made of hex digits, whitespace, ',', ':' and x/X; the bytes
 *   stored never exceed cap; a larger cap gives the same length and bytes; formatting the
 *   bytes and parsing that gives them back; a failure leaves a NUL-terminated, non-empty
 *   message within err_len.
 * - options: cli_args_next() ends (CLI_ARG_END, _ERROR or _HELP) within argc + 1 calls; keys
 *   are from the table; a value is inside one of the arguments.
 * - numbers: cli_parse_int() agrees with a reference written from args.h (optional sign,
 *   decimal or 0x hex, nothing else, in [lo, hi]); cli_parse_real() accepts only finite
 *   decimal numbers strtod reads completely; cli_parse_id_list() sets one bit per listed id, all
 *   within max_id.
 */
#include "fuzz_common.h"

#include "args.h"
#include "hexparse.h"

#include <ctype.h>
#include <math.h>
#include <stdarg.h>
#include <string.h>

static char last_error[512];

void cli_error(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    (void)vsnprintf(last_error, sizeof last_error, fmt, ap);
    va_end(ap);
}

void cli_set_command(const char *name)
{
    (void)name;
}

static char *text_copy(const uint8_t *d, size_t n)
{
    char *t = malloc(n + 1u);
    FUZZ_CHECK(t != NULL);
    memcpy(t, d, n);
    t[n] = '\0';
    return t;
}

static void case_hex(uint8_t p1, uint8_t p2, const uint8_t *d, size_t n)
{
    char *text = text_copy(d, n);
    size_t cap = p1 % 40u, err_len = 1u + p2 % 80u, len = 12345u, len2 = 0u, i;
    uint8_t *out = malloc(cap == 0u ? 1u : cap);
    char *err = malloc(err_len);
    static uint8_t big[8192];
    int rc;
    bool clean = true;

    FUZZ_CHECK(out != NULL && err != NULL);
    memset(err, 'Z', err_len);
    for (i = 0; text[i] != '\0'; i++) {
        char c = text[i];
        clean = clean && (isxdigit((unsigned char)c) || isspace((unsigned char)c) || c == ',' ||
                          c == ':' || c == 'x' || c == 'X');
    }
    rc = cli_hex_parse(text, out, cap, &len, err, err_len);
    FUZZ_CHECK(rc == 0 || rc == -1);
    if (rc != 0) {
        FUZZ_CHECK(memchr(err, '\0', err_len) != NULL);
        FUZZ_CHECK(err_len == 1u || err[0] != '\0');
    } else {
        char *fmt;
        uint8_t *back;
        size_t len3 = 0u;
        FUZZ_CHECK(clean);
        FUZZ_CHECK(len >= 1u && len <= strlen(text) / 2u);
        FUZZ_CHECK(cli_hex_parse(text, big, sizeof big, &len2, err, err_len) == 0);
        FUZZ_CHECK(len2 == len);
        FUZZ_CHECK(memcmp(out, big, (len < cap) ? len : cap) == 0);
        fmt = malloc(2u * len + 1u);
        back = malloc(len);
        FUZZ_CHECK(fmt != NULL && back != NULL);
        cli_hex_format(big, len, fmt);
        FUZZ_CHECK(strlen(fmt) == 2u * len);
        FUZZ_CHECK(cli_hex_parse(fmt, back, len, &len3, err, err_len) == 0);
        FUZZ_CHECK(len3 == len && memcmp(back, big, len) == 0);
        free(fmt);
        free(back);
    }
    free(out);
    free(err);
    free(text);
}

static void case_args(const uint8_t *d, size_t n)
{
    static const cli_opt_t opts[] = {{"--id", true, 1}, {"--flag", false, 2},
                                     {"--tau", true, 3}, {"--port", true, 4},
                                     {NULL, false, 0}};
    char *buf = text_copy(d, n);
    char *argv[18];
    int argc = 0, calls = 0, r, prev_index = 1;
    size_t i = 0;
    cli_args_t a;

    argv[argc++] = (char *)"j288";
    while (argc < 17 && i <= n) {
        argv[argc++] = &buf[i];
        i += strlen(&buf[i]) + 1u;
    }
    argv[argc] = NULL;
    cli_args_init(&a, argc, argv);
    for (;;) {
        const char *value = NULL;
        r = cli_args_next(&a, opts, &value);
        calls++;
        FUZZ_CHECK(calls <= argc + 1);
        FUZZ_CHECK(a.index >= prev_index && a.index <= argc);
        prev_index = a.index;
        if (r == CLI_ARG_END || r == CLI_ARG_ERROR || r == CLI_ARG_HELP) {
            break;
        }
        FUZZ_CHECK(r == CLI_ARG_POSITIONAL || (r >= 1 && r <= 4));
        if (r == CLI_ARG_POSITIONAL || r == 1 || r == 3 || r == 4) {
            bool inside = false;
            int k;
            FUZZ_CHECK(value != NULL);
            for (k = 1; k < argc; k++) {
                inside = inside || (value >= argv[k] && value <= argv[k] + strlen(argv[k]));
            }
            FUZZ_CHECK(inside);
        }
    }
    free(buf);
}

/* The reference for cli_parse_int, from args.h. */
static int ref_int(const char *t, long long lo, long long hi, long long *out)
{
    bool neg = false;
    int base = 10;
    unsigned long long v = 0, lim;
    const char *p = t;
    if (*p == '+' || *p == '-') {
        neg = (*p == '-');
        p++;
    }
    if (p[0] == '0' && (p[1] == 'x' || p[1] == 'X')) {
        base = 16;
        p += 2;
    }
    if (*p == '\0') {
        return -1;
    }
    lim = neg ? 9223372036854775808ull : 9223372036854775807ull;
    for (; *p != '\0'; p++) {
        unsigned dgt;
        if (*p >= '0' && *p <= '9') {
            dgt = (unsigned)(*p - '0');
        } else if (base == 16 && isxdigit((unsigned char)*p)) {
            dgt = (unsigned)(tolower((unsigned char)*p) - 'a' + 10);
        } else {
            return -1;
        }
        if (v > (lim - dgt) / (unsigned)base) {
            return -2; /* out of range */
        }
        v = v * (unsigned)base + dgt;
    }
    {
        long long s = neg ? ((v == 9223372036854775808ull) ? (-9223372036854775807LL - 1)
                                                          : -(long long)v)
                          : (long long)v;
        if (s < lo || s > hi) {
            return -2;
        }
        *out = s;
    }
    return 0;
}

static void case_int(uint8_t p1, uint8_t p2, const uint8_t *d, size_t n)
{
    static const long long bounds[8] = {0, 14, -32768, 32767, -2147483647LL - 1, 2147483647LL,
                                        -9223372036854775807LL - 1, 9223372036854775807LL};
    char *text = text_copy(d, n);
    long long lo = bounds[p1 % 8u], hi = bounds[p2 % 8u], v = 77, want = 88;
    int rc, ref;
    if (lo > hi) {
        long long t = lo;
        lo = hi;
        hi = t;
    }
    rc = cli_parse_int("--x", text, lo, hi, &v);
    ref = ref_int(text, lo, hi, &want);
    FUZZ_CHECK((rc == 0) == (ref == 0));
    if (rc == 0) {
        FUZZ_CHECK(v == want && v >= lo && v <= hi);
    }
    free(text);
}

static void case_real(const uint8_t *d, size_t n)
{
    char *text = text_copy(d, n);
    double v = 0.0;
    if (cli_parse_real("--x", text, &v) == 0) {
        char *end = NULL;
        double w = strtod(text, &end);
        FUZZ_CHECK(isfinite(v));
        FUZZ_CHECK(end != text && *end == '\0');
        FUZZ_CHECK(v == w);
        /* Decimal only (host/j288_number.h, the robot config file's syntax too): no
         * hexadecimal, no "inf", no blanks. */
        FUZZ_CHECK(strspn(text, "0123456789+-.eE") == strlen(text));
    }
    free(text);
}

static void case_ids(uint8_t p1, const uint8_t *d, size_t n)
{
    char *text = text_copy(d, n);
    unsigned max_id = p1 % 31u;
    uint32_t mask = 0xDEADu;
    if (cli_parse_id_list("--ids", text, max_id, &mask) == 0) {
        unsigned items = 1u, bits = 0u, k;
        const char *c;
        for (c = text; *c != '\0'; c++) {
            items += (*c == ',') ? 1u : 0u;
        }
        for (k = 0; k < 32u; k++) {
            bits += ((mask >> k) & 1u);
            if (k > max_id) {
                FUZZ_CHECK(((mask >> k) & 1u) == 0u);
            }
        }
        FUZZ_CHECK(bits == items);
    }
    free(text);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 3u) {
        return 0;
    }
    switch (data[0] % 5u) {
    case 0: case_hex(data[1], data[2], &data[3], size - 3u); break;
    case 1: case_args(&data[3], size - 3u); break;
    case 2: case_int(data[1], data[2], &data[3], size - 3u); break;
    case 3: case_real(&data[3], size - 3u); break;
    default: case_ids(data[1], &data[3], size - 3u); break;
    }
    return 0;
}
