/*
 * j288_number.h - the one syntax for numbers typed by people: the j288 tool's options and the
 * robot config file read numbers through these, so that "1.5" or "0x10" means the same in both
 * (host side; plain C99 and the C library, no state).
 *
 * A real number is decimal: an optional sign, digits with at most one '.' (at least one digit:
 * "5", "-.5", "5." and "2.5e-3" are numbers), then an optional exponent: 'e' or 'E', an
 * optional sign, digits. Nothing else: no blanks, no hexadecimal ("0x1p1"), no "inf" or "nan",
 * nothing after the number. A value too large for a double is out of range; one too small
 * rounds towards 0 (it is a number, just a tiny one).
 *
 * A whole number is an optional sign, then decimal digits or "0x"/"0X" and hexadecimal digits
 * ("-0x10" is -16). Nothing else, as above; beyond a long long it is out of range.
 *
 * Both are reentrant and thread-safe (errno is saved and restored); they read text only.
 */
#ifndef J288_NUMBER_H
#define J288_NUMBER_H

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    J288_NUMBER_OK = 0,
    J288_NUMBER_SYNTAX, /* not a number of that kind */
    J288_NUMBER_RANGE   /* a number, but beyond what the type holds */
} j288_number_result_t;

/* text as a real number into *out (untouched unless J288_NUMBER_OK). */
j288_number_result_t j288_number_real(const char *text, double *out);

/* text as a whole number into *out (untouched unless J288_NUMBER_OK). */
j288_number_result_t j288_number_int(const char *text, long long *out);

#ifdef __cplusplus
}
#endif

#endif /* J288_NUMBER_H */
