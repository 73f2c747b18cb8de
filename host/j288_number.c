/* j288_number.c - the numbers people type; see j288_number.h. */
#include "j288_number.h"

#include <errno.h>
#include <math.h>
#include <stdbool.h>
#include <stdlib.h>

static bool is_digit(char c)
{
    return c >= '0' && c <= '9';
}

static bool is_hex_digit(char c)
{
    return is_digit(c) || (c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F');
}

/* The decimal syntax of j288_number.h, checked before strtod (which would also take blanks,
 * hexadecimal, "inf" and "nan"). */
static bool decimal_real(const char *p)
{
    unsigned digits = 0;
    if (*p == '+' || *p == '-')
        p++;
    for (; is_digit(*p); p++)
        digits++;
    if (*p == '.')
        for (p++; is_digit(*p); p++)
            digits++;
    if (digits == 0u)
        return false;
    if (*p == 'e' || *p == 'E') {
        p++;
        if (*p == '+' || *p == '-')
            p++;
        if (!is_digit(*p))
            return false;
        while (is_digit(*p))
            p++;
    }
    return *p == '\0';
}

j288_number_result_t j288_number_real(const char *text, double *out)
{
    j288_number_result_t rc = J288_NUMBER_OK;
    int saved = errno;
    char *end = NULL;
    double v;
    if (text == NULL || !decimal_real(text))
        return J288_NUMBER_SYNTAX;
    errno = 0;
    v = strtod(text, &end);
    if (end == text || *end != '\0')
        rc = J288_NUMBER_SYNTAX;
    else if (!isfinite(v) || (errno == ERANGE && fabs(v) > 1.0))
        rc = J288_NUMBER_RANGE; /* overflow; an underflow's tiny result is kept */
    else
        *out = v;
    errno = saved;
    return rc;
}

j288_number_result_t j288_number_int(const char *text, long long *out)
{
    j288_number_result_t rc = J288_NUMBER_OK;
    int saved = errno, base = 10;
    const char *p = text;
    char *end = NULL;
    long long v;
    if (text == NULL)
        return J288_NUMBER_SYNTAX;
    if (*p == '+' || *p == '-')
        p++;
    if (p[0] == '0' && (p[1] == 'x' || p[1] == 'X')) {
        base = 16;
        p += 2;
    }
    if (*p == '\0')
        return J288_NUMBER_SYNTAX;
    for (; *p != '\0'; p++)
        if (base == 10 ? !is_digit(*p) : !is_hex_digit(*p))
            return J288_NUMBER_SYNTAX;
    errno = 0;
    v = strtoll(text, &end, base);
    if (end == text || *end != '\0')
        rc = J288_NUMBER_SYNTAX;
    else if (errno == ERANGE)
        rc = J288_NUMBER_RANGE;
    else
        *out = v;
    errno = saved;
    return rc;
}
