/*
 * Instructions per host-side transaction on Cortex-M and RISC-V under QEMU (-icount shift=0): encode a
 * command (with its CRC), feed the 26-byte reply through the parser (CRC check), decode it.
 * One run measures every CRC backend side by side, against the manual's bitwise crc32_core as
 * the baseline. SysTick counts processor clocks (RISC-V: minstret counts instructions); with
 * -icount shift=0 each instruction takes 1 ns, and the factor from ticks to instructions is
 * measured first on a loop of known length (icount.h).
 *
 * The "hw" row is the CPU's share of the CRC unit path (j288_stm32_crc32: word assembly, the
 * lock, the HAL call writing each word to DR); QEMU has no STM32 CRC unit, so the unit's
 * answer is taken from a table here. On silicon each DR write also stalls about 4 AHB cycles.
 */
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "icount.h"
#include "j288/j288.h"
#include "j288_stm32.h"

#define ITERATIONS 500u

/* The spec's worked frames. */
static const uint8_t k_reply3[J288_REPLY_LEN] = {
    0xfc, 0xee, 0x13, 0x24, 0x29, 0x30, 0x00, 0x05, 0xd7, 0xff, 0x5f, 0x14, 0x00,
    0x00, 0x00, 0x00, 0x00, 0x00, 0xe8, 0x03, 0x00, 0x00, 0x49, 0xc2, 0x3b, 0xee};
#define CMD_CRC 0x3f304ba6u
#define REPLY_CRC 0xee3bc249u

/* ---- backends ---------------------------------------------------------------------------- */

static uint32_t be_table(void *ctx, const uint8_t *d, size_t n)
{
    (void)ctx;
    return j288_crc32_update_table(J288_CRC32_INIT, d, n);
}
static uint32_t be_nibble(void *ctx, const uint8_t *d, size_t n)
{
    (void)ctx;
    return j288_crc32_update_nibble(J288_CRC32_INIT, d, n);
}
static uint32_t be_bitwise(void *ctx, const uint8_t *d, size_t n)
{
    (void)ctx;
    return j288_crc32_update_bitwise(J288_CRC32_INIT, d, n);
}

/* The manual's crc32_core, as printed (word loop, a bit loop testing the top bit and feeding
 * the data bit by bit), with the words assembled from bytes instead of a uint32_t * cast. */
static uint32_t be_manual(void *ctx, const uint8_t *d, size_t n)
{
    uint32_t crc = 0xFFFFFFFFu;
    (void)ctx;
    for (size_t i = 0; i < n; i++) {
        uint32_t data = j288_get_u32le(&d[4u * i]);
        uint32_t xbit = 1u << 31;
        for (unsigned bits = 0; bits < 32u; bits++) {
            if ((crc & 0x80000000u) != 0u) {
                crc <<= 1;
                crc ^= 0x04C11DB7u;
            } else {
                crc <<= 1;
            }
            if ((data & xbit) != 0u) {
                crc ^= 0x04C11DB7u;
            }
            xbit >>= 1;
        }
    }
    return crc;
}

/* A stand-in CRC unit: the words go to a data register as the HAL writes them; the answer
 * the silicon would compute comes from a table keyed by the word count. */
static CRC_TypeDef fake_unit;
static CRC_HandleTypeDef hcrc = {.Instance = &fake_unit};

uint32_t HAL_CRC_Accumulate(CRC_HandleTypeDef *h, uint32_t pBuffer[], uint32_t BufferLength)
{
    for (uint32_t i = 0; i < BufferLength; i++) {
        h->Instance->DR = pBuffer[i];
    }
    return (BufferLength == 4u) ? CMD_CRC : REPLY_CRC;
}

uint32_t HAL_CRC_Calculate(CRC_HandleTypeDef *h, uint32_t pBuffer[], uint32_t BufferLength)
{
    h->Instance->CR = 1u;
    return HAL_CRC_Accumulate(h, pBuffer, BufferLength);
}

static uint32_t be_hw(void *ctx, const uint8_t *d, size_t n)
{
    return j288_stm32_crc32(ctx, d, n);
}

/* ---- measurement ------------------------------------------------------------------------- */

static volatile uint32_t sink;

static uint32_t calibrate(void)
{
    uint32_t t0, t1;
    icount_start();
    t0 = icount_now();
    icount_loop(100000u); /* 2 instructions per iteration */
    t1 = icount_now();
    return icount_between(t0, t1);
}

static int one_transaction(const j288_crc_t *crc, j288_parser_t *p)
{
    uint8_t out[J288_CMD_LEN];
    j288_cmd_raw_t cmd;
    j288_reply_raw_t reply;
    size_t used = 0;
    memset(&cmd, 0, sizeof cmd);
    cmd.id = 3u;
    cmd.status = J288_MODE_FOC;
    cmd.watchdog = true;
    cmd.pos = 5215;
    cmd.kp = 1280;
    cmd.kd = 12800;
    if (j288_cmd_encode(&cmd, out, crc) != J288_OK) {
        return -1;
    }
    if (j288_parser_feed(p, k_reply3, J288_REPLY_LEN, &used) != J288_PARSE_FRAME) {
        return -2;
    }
    j288_reply_unpack(j288_parser_frame(p), &reply);
    sink = (uint32_t)reply.pos + out[16];
    return (reply.pos == 5215) ? 0 : -3;
}

static uint32_t measure(const j288_crc_t *crc, int *err)
{
    j288_parser_t p;
    uint32_t t0, t1;
    (void)j288_parser_init(&p, J288_PARSE_REPLY, crc);
    *err = 0;
    icount_start();
    t0 = icount_now();
    for (uint32_t i = 0; i < ITERATIONS; i++) {
        *err |= one_transaction(crc, &p);
    }
    t1 = icount_now();
    return icount_between(t0, t1);
}

/* The CRC alone: one command (4 words) and one reply (5 words), as a transaction needs. */
static uint32_t measure_crc_only(const j288_crc_t *crc)
{
    static const uint8_t cmd[J288_CMD_LEN] = {0xfe, 0xee, 0x93, 0x00, 0x00, 0x00, 0x00,
                                              0x00, 0x5f, 0x14, 0x00, 0x00, 0x00, 0x05,
                                              0x00, 0x32, 0xa6, 0x4b, 0x30, 0x3f};
    uint32_t t0, t1, acc = 0;
    icount_start();
    t0 = icount_now();
    for (uint32_t i = 0; i < ITERATIONS; i++) {
        acc += crc->fn(crc->ctx, cmd, 4u);
        acc += crc->fn(crc->ctx, &k_reply3[2], 5u);
    }
    t1 = icount_now();
    sink = acc;
    return icount_between(t0, t1);
}

static uint32_t per_iteration(uint32_t ticks, uint64_t ipt_milli)
{
    return (uint32_t)(((uint64_t)ticks * ipt_milli / 1000u + ITERATIONS / 2u) / ITERATIONS);
}

int main(void)
{
    static const struct {
        const char *name;
        j288_crc_t crc;
    } rows[] = {
        {"manual crc32_core (baseline)", {be_manual, NULL}},
        {"bitwise", {be_bitwise, NULL}},
        {"nibble (16 entries)", {be_nibble, NULL}},
        {"table (256 entries)", {be_table, NULL}},
        {"hw: CRC unit, CPU share", {be_hw, &hcrc}},
    };
    uint32_t cal = calibrate();
    /* instructions per tick, in 1/1000 */
    uint64_t ipt_milli = (200000ull * 1000ull + cal / 2u) / cal;
    uint32_t base = 0;
    int failed = 0;

    printf("bench: %u transactions per backend; %lu.%03lu instructions per counter tick\n",
           (unsigned)ITERATIONS, (unsigned long)(ipt_milli / 1000u), (unsigned long)(ipt_milli % 1000u));
    printf("| CRC backend | instructions per transaction | vs baseline | CRC alone (4 + 5 words) |\n");
    printf("|---|---:|---:|---:|\n");
    for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++) {
        int err;
        uint32_t ticks = measure(&rows[i].crc, &err);
        uint32_t insns = per_iteration(ticks, ipt_milli);
        uint32_t crc_only = per_iteration(measure_crc_only(&rows[i].crc), ipt_milli);
        if (i == 0) {
            base = insns;
        }
        printf("| %s | %lu | %lu.%02lux | %lu |\n", rows[i].name, (unsigned long)insns,
               (unsigned long)(base / insns), (unsigned long)((base % insns) * 100u / insns),
               (unsigned long)crc_only);
        if (err != 0) {
            printf("bench: backend %s gave a wrong result (%d)\n", rows[i].name, err);
            failed = 1;
        }
    }
    return failed;
}
