/*
 * j288_range.h - one range per quantity that people give the host tools, on a command line
 * (an option, an environment variable) or in a robot config file: the config reader and the
 * j288 tool both check a value against its entry here, where it is given, and name where it
 * came from: "--margin-us: 0 is out of range 1..10000000", "$J288_BAUD: ...",
 * "robot.yaml:4: bus 'left': margin_us: 0 is out of range (1 to 10000000)". The syntax of the
 * numbers is j288_number.h's, the same in both places.
 *
 * The gains' range is the wire's on the joint (output) side (kp and kd are 16-bit rotor-side
 * fields: the largest is 32767 / scale * N^2), so that a gain from a file that the wire could
 * not carry is refused when the file is read, never later under an option's name the user
 * did not give. Header only (a static table), plain C99, no state: usable by every front end.
 */
#ifndef J288_RANGE_H
#define J288_RANGE_H

#include <stdbool.h>

#include "j288/config.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    J288_QTY_BAUD = 0, /* bit/s: --baud, $J288_BAUD, a bus's baud */
    J288_QTY_MARGIN_US, /* us: --margin-us, a bus's margin_us */
    J288_QTY_RETRIES,   /* re-sends of a failed transaction: --retries */
    J288_QTY_KP,        /* N*m/rad, joint side: --kp, a joint's kp */
    J288_QTY_KD,        /* N*m*s/rad, joint side: --kd, a joint's kd */
    J288_QTY_COUNT
} j288_quantity_t;

typedef struct {
    const char *option; /* its command-line option, or NULL */
    const char *key;    /* its robot config key, or NULL */
    double lo, hi;      /* both included */
    bool whole;         /* whole numbers only */
    const char *unit;
} j288_range_t;

/* The entry of quantity q (q < J288_QTY_COUNT). */
static inline const j288_range_t *j288_range(j288_quantity_t q)
{
    /* kp, kd: just below the wire's largest (32767 / 1280000 * 288.35^2 = 2128.4655..., and
     * a hundredth of it for kd), so that every value in range encodes (test_range.c). */
    static const j288_range_t table[J288_QTY_COUNT] = {
        {"--baud", "baud", 9600.0, 100000000.0, true, "bit/s"},
        {"--margin-us", "margin_us", 1.0, 10000000.0, true, "us"},
        {"--retries", NULL, 0.0, (double)J288_CONFIG_MAX_RETRIES, true, ""},
        {"--kp", "kp", 0.0, 2128.4, false, "N*m/rad"},
        {"--kd", "kd", 0.0, 21.284, false, "N*m*s/rad"},
    };
    return &table[q];
}

/* Whether v lies in q's range (NaN never does). */
static inline bool j288_range_has(j288_quantity_t q, double v)
{
    const j288_range_t *r = j288_range(q);
    return v >= r->lo && v <= r->hi;
}

#ifdef __cplusplus
}
#endif

#endif /* J288_RANGE_H */
