/*
 * The CRC unit of test/bench/bus_target.c (the STM32's, in its reset configuration), modelled
 * by its registers: a reset bit in CR, a data register taking one word per write. QEMU's mps2
 * boards have no such unit, so the answer the silicon would give is read from a two-entry
 * table (command, reply, alternating: the order in which both the library and the floor ask)
 * filled from the software CRC before the run; that read costs about three instructions more
 * than a register load, in the library's rows and in the floor's alike.
 *
 * Also the model of a CRC backend a firmware writes for J288_CRC_BACKEND_HW: bench_crc_unit_
 * inline() is what test/bench/hw_inline/j288_user_config.h hands the library as a static
 * inline J288_CONFIG_CRC_HW_FUNCTION. Includes nothing of the library (the user configuration
 * comes before the library's headers).
 */
#ifndef BENCH_CRC_UNIT_MODEL_H
#define BENCH_CRC_UNIT_MODEL_H

#include <stddef.h>
#include <stdint.h>

typedef struct {
    volatile uint32_t DR;
    volatile uint32_t CR;
} bench_crc_unit_t;

extern bench_crc_unit_t bench_unit;
extern uint32_t bench_unit_answer[2];
extern uint32_t bench_unit_next;

static inline uint32_t bench_unit_result(void)
{
    uint32_t v = bench_unit_answer[bench_unit_next];
    bench_unit_next ^= 1u;
    return v;
}

/* Reset, one write per little-endian word, one read. Inlined where the word count is a
 * constant (a frame: four or five), the loop is unrolled: gcc -O2 does not unroll a loop
 * with a volatile store by itself, and an unrolled body written out would no longer be
 * inlined at -Os. */
static inline uint32_t bench_crc_unit_inline(const uint8_t *data, size_t nwords)
{
    size_t i;
    bench_unit.CR = 1u;
#pragma GCC unroll 5
    for (i = 0u; i < nwords; i++) {
        const uint8_t *p = &data[4u * i];
        bench_unit.DR = (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) |
                        ((uint32_t)p[3] << 24);
    }
    return bench_unit_result();
}

#endif /* BENCH_CRC_UNIT_MODEL_H */
