/*
 * icount.h - the instruction counter of the benchmarks run under QEMU with -icount shift=0
 * (every instruction takes 1 ns of virtual time). Cortex-M: SysTick on the processor clock
 * (24 bits, counting down; the ticks-to-instructions factor is measured on a loop of known
 * length, icount_calibrate()). RISC-V: minstret, the retired-instruction counter itself
 * (factor 1, which the same calibration confirms). Header-only, for test/target and test/bench.
 */
#ifndef J288_TEST_ICOUNT_H
#define J288_TEST_ICOUNT_H

#include <stdint.h>

#if defined(__riscv)

static inline void icount_start(void) {}

static inline uint32_t icount_now(void)
{
    uint32_t v;
    __asm volatile("csrr %0, minstret" : "=r"(v));
    return v;
}

/* Counter units from t0 to t1 (t1 read later). */
static inline uint32_t icount_between(uint32_t t0, uint32_t t1) { return t1 - t0; }

/* n iterations of two instructions. */
static inline void icount_loop(uint32_t n)
{
    __asm volatile("1: addi %0, %0, -1\n\tbnez %0, 1b" : "+r"(n));
}

#else /* Cortex-M */

#define ICOUNT_SYST_CSR (*(volatile uint32_t *)0xE000E010u)
#define ICOUNT_SYST_RVR (*(volatile uint32_t *)0xE000E014u)
#define ICOUNT_SYST_CVR (*(volatile uint32_t *)0xE000E018u)

static inline void icount_start(void)
{
    ICOUNT_SYST_CSR = 0u;
    ICOUNT_SYST_RVR = 0x00FFFFFFu;
    ICOUNT_SYST_CVR = 0u;
    ICOUNT_SYST_CSR = 5u; /* enable, processor clock, no interrupt */
}

static inline uint32_t icount_now(void) { return ICOUNT_SYST_CVR; }

static inline uint32_t icount_between(uint32_t t0, uint32_t t1)
{
    return (t0 - t1) & 0x00FFFFFFu; /* counts down */
}

static inline void icount_loop(uint32_t n)
{
    __asm volatile(".syntax unified\n1: subs %0, %0, #1\n\tbne 1b" : "+l"(n) : : "cc");
}

#endif

/* Instructions per counter unit, x1000, from a loop of 2 x loops instructions. */
static inline uint32_t icount_calibrate(uint32_t loops)
{
    uint32_t t0, t1;
    t0 = icount_now();
    icount_loop(loops);
    t1 = icount_now();
    return (uint32_t)((2ull * loops * 1000u + icount_between(t0, t1) / 2u) /
                      icount_between(t0, t1));
}

#endif /* J288_TEST_ICOUNT_H */
