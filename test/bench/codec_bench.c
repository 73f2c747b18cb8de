/*
 * Host benchmark of the codec's hot paths, for instruction counts under valgrind callgrind
 * (scripts: `make bench-codec`). `codec_bench MODE N` runs MODE N times; the instructions per
 * call are (Ir(MODE, N) - Ir(none, N)) / N, so start-up and the loop skeleton cancel out.
 * Modes: none, crc-table, crc-nibble, crc-bitwise (one reply's 5 words), cmd-encode,
 * reply-decode, parse-chunk (a 26-byte reply in one feed), parse-bytes (26 single-byte feeds),
 * cmd-from-si (output side, all five fields).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "j288/j288.h"

static const uint8_t reply3[J288_REPLY_LEN] = {0xfc, 0xee, 0x13, 0x24, 0x29, 0x30, 0x00, 0x05, 0xd7,
                                               0xff, 0x5f, 0x14, 0x00, 0x00, 0x00, 0x00, 0x00, 0x00,
                                               0xe8, 0x03, 0x00, 0x00, 0x49, 0xc2, 0x3b, 0xee};

/* Keeps results alive so the optimiser cannot drop the work. */
static volatile uint32_t sink;

int main(int argc, char **argv)
{
    static const char *const modes[] = {"none",        "crc-table",   "crc-nibble",
                                        "crc-bitwise", "cmd-encode",  "reply-decode",
                                        "parse-chunk", "parse-bytes", "cmd-from-si"};
    const char *name = argc > 1 ? argv[1] : "none";
    int mode = -1, m;
    unsigned long n = argc > 2 ? strtoul(argv[2], NULL, 10) : 10000ul;
    unsigned long i;
    j288_cmd_raw_t cmd;
    j288_reply_raw_t rep;
    j288_parser_t parser;
    uint8_t frame[J288_REPLY_LEN];
    volatile uint8_t salt = 0; /* varies the input so nothing is hoisted out of the loop */

    memset(&cmd, 0, sizeof cmd);
    cmd.id = 3;
    cmd.status = 1;
    cmd.watchdog = true;
    cmd.pos = 5215;
    cmd.kp = 1280;
    cmd.kd = 12800;
    memcpy(frame, reply3, sizeof frame);
    j288_parser_init(&parser, J288_PARSE_REPLY, NULL);

    for (m = 0; m < (int)(sizeof modes / sizeof modes[0]); m++) {
        if (strcmp(name, modes[m]) == 0) {
            mode = m;
        }
    }
    if (mode < 0) {
        fprintf(stderr, "codec_bench: unknown mode %s\n", name);
        return 2;
    }
    for (i = 0; i < n; i++) {
        switch (mode) {
        case 0:
            sink += salt;
            break;
        case 1:
            sink += j288_crc32_update_table(J288_CRC32_INIT, &frame[2], 5u) + salt;
            break;
        case 2:
            sink += j288_crc32_update_nibble(J288_CRC32_INIT, &frame[2], 5u) + salt;
            break;
        case 3:
            sink += j288_crc32_update_bitwise(J288_CRC32_INIT, &frame[2], 5u) + salt;
            break;
        case 4: {
            uint8_t out[J288_CMD_LEN];
            cmd.tau = (int16_t)salt;
            sink += (uint32_t)j288_cmd_encode(&cmd, out, NULL) + out[16];
            break;
        }
        case 5:
            sink += (uint32_t)j288_reply_decode(frame, &rep, NULL) + (uint32_t)rep.pos + salt;
            break;
        case 6: {
            size_t used;
            sink += (uint32_t)j288_parser_feed(&parser, frame, sizeof frame, &used) + salt;
            break;
        }
        case 7: {
            size_t k, used;
            for (k = 0; k < sizeof frame; k++) {
                sink += (uint32_t)j288_parser_feed(&parser, &frame[k], 1u, &used);
            }
            sink += salt;
            break;
        }
        case 8: {
#if J288_CONFIG_SI
            j288_cmd_si_t si;
            memset(&si, 0, sizeof si);
            si.id = 3;
            si.status = 1;
            si.tau = (j288_real_t)(2.5 + salt);
            si.speed = (j288_real_t)6.28;
            si.pos = (j288_real_t)1.57;
            si.kp = (j288_real_t)50.0;
            si.kd = (j288_real_t)2.0;
            sink += (uint32_t)j288_cmd_from_si(&si, J288_SIDE_OUTPUT, &cmd) + (uint32_t)cmd.pos;
#endif
            break;
        }
        default:
            break;
        }
    }
    return (parser.stats.crc_errors == 0u) ? 0 : 1;
}
