/*
 * hints.h - compiler hints the library's modules share (lib/src only, not installed): where a
 * function goes out of line or is forced inline. Only hints: without GCC-style attributes
 * they are nothing.
 */
#ifndef J288_HINTS_H
#define J288_HINTS_H

/* Keeps a rarely taken path out of its caller, so that the common path stays short (no
 * register spills for the slow path's state). Only a hint. */
#if defined(__GNUC__)
#define J288_NOINLINE __attribute__((noinline))
#else
#define J288_NOINLINE
#endif

/* A small function on a hot path that has more than one caller: inlined in each (the
 * compiler would otherwise keep one out-of-line copy and a call). Only a hint, and only when
 * optimising: at -O0 (make coverage, debugging) forced inlining speeds nothing and would
 * multiply the branches that coverage counts, each inlined copy of a test on a constant
 * argument counting as a branch taken one way. */
#if defined(__GNUC__) && defined(__OPTIMIZE__)
#define J288_INLINE_HOT inline __attribute__((always_inline))
#else
#define J288_INLINE_HOT inline
#endif

#endif /* J288_HINTS_H */
