/*
 * j288/config.h - compile-time configuration.
 *
 * Every option has a default here; override it with -D on the command line, or define
 * J288_USER_CONFIG and provide "j288_user_config.h" on the include path. No option changes a
 * function's name or the set of arguments it takes; J288_CONFIG_SI_FLOAT selects the width of
 * j288_real_t and J288_CONFIG_SI removes the SI-unit API altogether.
 */
#ifndef J288_CONFIG_H
#define J288_CONFIG_H

#ifdef J288_USER_CONFIG
#include "j288_user_config.h"
#endif

/* 1: compile the SI-unit (floating point) API in units.h. 0: raw integers only, for FPU-less
 * parts that must not pull in a soft-float library. */
#ifndef J288_CONFIG_SI
#define J288_CONFIG_SI 1
#endif

/* j288_real_t is double by default: a double holds every int32 position exactly, so
 * raw -> SI -> raw round trips are exact. Set 1 on a single-precision FPU (Cortex-M4F/M33)
 * to make it float; positions beyond about 2^24 LSB (3217 rad rotor, 11 rad output) then
 * round trip to within a few LSB instead of exactly. */
#ifndef J288_CONFIG_SI_FLOAT
#define J288_CONFIG_SI_FLOAT 0
#endif

/* Which CRC32 backend serves a NULL j288_crc_t (see crc32.h); docs/performance.md gives
 * their speed and flash on Cortex-M. */
#define J288_CRC_BACKEND_TABLE 1   /* 256-entry table, 1 KiB flash                        */
#define J288_CRC_BACKEND_NIBBLE 2  /* 16-entry table, 64 bytes flash                      */
#define J288_CRC_BACKEND_BITWISE 3 /* no table, slowest: the reference                     */
#define J288_CRC_BACKEND_HW 4      /* J288_CONFIG_CRC_HW_FUNCTION, e.g. the STM32 CRC unit */
#define J288_CRC_BACKEND_SLICE4 5  /* slicing by 4: four 256-entry tables, 4 KiB flash,
                                      fastest in software                                 */

#ifndef J288_CONFIG_CRC_BACKEND
#define J288_CONFIG_CRC_BACKEND J288_CRC_BACKEND_TABLE
#endif

#if J288_CONFIG_CRC_BACKEND == J288_CRC_BACKEND_HW
/* The user supplies, with external linkage:
 *   uint32_t J288_CONFIG_CRC_HW_FUNCTION(const uint8_t *data, size_t nwords);
 * computing the manual's crc32_core over nwords little-endian words (see crc32.h). */
#ifndef J288_CONFIG_CRC_HW_FUNCTION
#error "J288_CONFIG_CRC_BACKEND is HW but J288_CONFIG_CRC_HW_FUNCTION names no function"
#endif
#elif (J288_CONFIG_CRC_BACKEND != J288_CRC_BACKEND_TABLE) &&                                 \
    (J288_CONFIG_CRC_BACKEND != J288_CRC_BACKEND_SLICE4) &&                                    \
    (J288_CONFIG_CRC_BACKEND != J288_CRC_BACKEND_NIBBLE) &&                                    \
    (J288_CONFIG_CRC_BACKEND != J288_CRC_BACKEND_BITWISE)
#error "J288_CONFIG_CRC_BACKEND must be one of the J288_CRC_BACKEND_* values"
#endif

/* Receive ring inside each bus object (bytes). Must be a power of two, at least 32: it holds
 * one reply (26 bytes) plus the echo of a command when the transceiver hears itself. */
#ifndef J288_CONFIG_RX_RING_SIZE
#define J288_CONFIG_RX_RING_SIZE 64u
#endif
#if (J288_CONFIG_RX_RING_SIZE < 32u) ||                                                       \
    ((J288_CONFIG_RX_RING_SIZE & (J288_CONFIG_RX_RING_SIZE - 1u)) != 0u)
#error "J288_CONFIG_RX_RING_SIZE must be a power of two and at least 32"
#endif

/* Most retries a bus may be configured for; each attempt's failure reason is kept. */
#ifndef J288_CONFIG_MAX_RETRIES
#define J288_CONFIG_MAX_RETRIES 3u
#endif
#if J288_CONFIG_MAX_RETRIES > 15u
#error "J288_CONFIG_MAX_RETRIES must be 15 or less"
#endif

#endif /* J288_CONFIG_H */
