/*
 * j288/config.h - compile-time configuration.
 *
 * Every option has a default here; override it with -D on the command line, or define
 * J288_USER_CONFIG and provide "j288_user_config.h" on the include path. No option changes a
 * function's name or the set of arguments it takes; J288_CONFIG_SI_FLOAT selects the width of
 * j288_real_t and J288_CONFIG_SI removes the SI-unit API altogether.
 *
 * Options marked [layout] change the layout of a public struct: the library and every file
 * that uses its headers must be built with the same values. They make up J288_ABI_TAG, the
 * name of an object the library defines and j288_bus_init() refers to, so that a program
 * built with other values does not link: the linker reports an undefined reference to
 * j288_abi_r<ring size>_m<max retries>_f<SI float>, the program's values.
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

/* The joint core (j288/jointq.h) is always compiled: it is the one joint state machine, in
 * integers, which the float API of j288/joint.h runs under J288_CONFIG_SI. An FPU-less
 * firmware sets J288_CONFIG_SI=0 and calls j288_jointq_*: no floating point at all.
 * (J288_CONFIG_JOINT_FIXED, which chose it before, has no effect any more.) */

/* [layout] j288_real_t is double by default: a double holds every int32 position exactly, so
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
 * computing the manual's crc32_core over nwords little-endian words (see crc32.h; data need
 * not be aligned), safe wherever frames are built or checked (the ISR with advance_in_isr).
 * Or, defined in j288_user_config.h (J288_USER_CONFIG), the same function static inline: the
 * library then inlines it where a frame is built or checked, with the word count a constant
 * there, e.g. reset, four or five register writes and a read for a CRC unit (docs/
 * performance.md: 160 instead of 209 instructions per codec transaction on a Cortex-M4, 307
 * instead of 448 on a Cortex-M0). Where the core cannot load unaligned words, the library
 * hands it a frame's words in an aligned buffer, so that an inlined function loads them as
 * words. */
#ifndef J288_CONFIG_CRC_HW_FUNCTION
#error "J288_CONFIG_CRC_BACKEND is HW but J288_CONFIG_CRC_HW_FUNCTION names no function"
#endif
#elif (J288_CONFIG_CRC_BACKEND != J288_CRC_BACKEND_TABLE) &&                                 \
    (J288_CONFIG_CRC_BACKEND != J288_CRC_BACKEND_SLICE4) &&                                    \
    (J288_CONFIG_CRC_BACKEND != J288_CRC_BACKEND_NIBBLE) &&                                    \
    (J288_CONFIG_CRC_BACKEND != J288_CRC_BACKEND_BITWISE)
#error "J288_CONFIG_CRC_BACKEND must be one of the J288_CRC_BACKEND_* values"
#endif

/* [layout] Receive ring inside each bus object (bytes): a power of two from 32 to 4096. It
 * holds one reply (26 bytes) plus the echo of a command when the transceiver hears itself. */
#ifndef J288_CONFIG_RX_RING_SIZE
#define J288_CONFIG_RX_RING_SIZE 64u
#endif
#if (J288_CONFIG_RX_RING_SIZE < 32u) ||                                                       \
    ((J288_CONFIG_RX_RING_SIZE & (J288_CONFIG_RX_RING_SIZE - 1u)) != 0u)
#error "J288_CONFIG_RX_RING_SIZE must be a power of two and at least 32"
#endif

/* [layout] Most retries a bus may be configured for; each attempt's failure reason is kept
 * (j288_txn_t). */
#ifndef J288_CONFIG_MAX_RETRIES
#define J288_CONFIG_MAX_RETRIES 3u
#endif
#if J288_CONFIG_MAX_RETRIES > 15u
#error "J288_CONFIG_MAX_RETRIES must be 15 or less"
#endif

/* J288_ABI_TAG: the [layout] options' values as one name (see the top of this file). Each
 * value is matched, not pasted, so that 64, 64u and (64u) give the same name. */
#define J288_ABI_NAME(r, m, f) J288_ABI_NAME_(r, m, f)
/* cppcheck-suppress misra-c2012-20.10 ; only ## makes a name (docs/misra.md) */
#define J288_ABI_NAME_(r, m, f) j288_abi_##r##_##m##_##f
#if J288_CONFIG_RX_RING_SIZE == 32u
#define J288_ABI_R r32
#elif J288_CONFIG_RX_RING_SIZE == 64u
#define J288_ABI_R r64
#elif J288_CONFIG_RX_RING_SIZE == 128u
#define J288_ABI_R r128
#elif J288_CONFIG_RX_RING_SIZE == 256u
#define J288_ABI_R r256
#elif J288_CONFIG_RX_RING_SIZE == 512u
#define J288_ABI_R r512
#elif J288_CONFIG_RX_RING_SIZE == 1024u
#define J288_ABI_R r1024
#elif J288_CONFIG_RX_RING_SIZE == 2048u
#define J288_ABI_R r2048
#elif J288_CONFIG_RX_RING_SIZE == 4096u
#define J288_ABI_R r4096
#else
#error "J288_CONFIG_RX_RING_SIZE must be at most 4096"
#endif
#if J288_CONFIG_MAX_RETRIES == 1u
#define J288_ABI_M m1
#elif J288_CONFIG_MAX_RETRIES == 2u
#define J288_ABI_M m2
#elif J288_CONFIG_MAX_RETRIES == 3u
#define J288_ABI_M m3
#elif J288_CONFIG_MAX_RETRIES == 4u
#define J288_ABI_M m4
#elif J288_CONFIG_MAX_RETRIES == 5u
#define J288_ABI_M m5
#elif J288_CONFIG_MAX_RETRIES == 6u
#define J288_ABI_M m6
#elif J288_CONFIG_MAX_RETRIES == 7u
#define J288_ABI_M m7
#elif J288_CONFIG_MAX_RETRIES == 8u
#define J288_ABI_M m8
#elif J288_CONFIG_MAX_RETRIES == 9u
#define J288_ABI_M m9
#elif J288_CONFIG_MAX_RETRIES == 10u
#define J288_ABI_M m10
#elif J288_CONFIG_MAX_RETRIES == 11u
#define J288_ABI_M m11
#elif J288_CONFIG_MAX_RETRIES == 12u
#define J288_ABI_M m12
#elif J288_CONFIG_MAX_RETRIES == 13u
#define J288_ABI_M m13
#elif J288_CONFIG_MAX_RETRIES == 14u
#define J288_ABI_M m14
#else
#define J288_ABI_M m15
#endif
#if J288_CONFIG_SI_FLOAT
#define J288_ABI_F f1
#else
#define J288_ABI_F f0
#endif
#define J288_ABI_TAG J288_ABI_NAME(J288_ABI_R, J288_ABI_M, J288_ABI_F)

#endif /* J288_CONFIG_H */
