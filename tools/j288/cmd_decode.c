/* `j288 decode`: recognise, check and explain one command or reply frame given as hex. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "args.h"
#include "cli.h"
#include "frameview.h"
#include "hexparse.h"
#include "json.h"

static const char decode_help[] =
    "usage: j288 decode [--json] HEX...\n"
    "       j288 decode [--json] -          (read the hex from standard input)\n"
    "\n"
    "Recognise a command (fe ee, 20 bytes) or a reply (fc ee, 26 bytes), check its CRC and\n"
    "print every field: raw, and in SI units on the rotor side and on the output side\n"
    "(288.35:1 gear), with fault and warning names.\n"
    "\n"
    "HEX: pairs of hex digits with or without separators (spaces, ',', ':', 0x prefixes);\n"
    "several arguments are joined, so an unquoted capture works too.\n"
    "  --json   one JSON object instead of the table. Command keys: frame, id, mode,\n"
    "           watchdog, tau_raw, speed_raw, pos_raw, kp_raw, kd_raw. Reply keys: frame, id,\n"
    "           mode, watchdog, case_temp_c, winding_temp_c, voltage_raw, voltage_v,\n"
    "           torque_raw, speed_raw, pos_raw, faults, fault_names, out_pos_raw, warnings.\n"
    "           Both add SI values under \"rotor\" and \"output\".\n"
    "\n"
    "Exit status: 0 valid frame; 1 not hex, odd digit count, wrong length, unknown header\n"
    "or CRC mismatch; 2 bad command line.\n"
    "\n"
    "example: j288 decode fe ee 80 00 00 00 00 00 00 00 00 00 00 00 00 00 1d 99 fb 6e\n";

enum { OPT_JSON };
static const cli_opt_t decode_opts[] = {{"--json", false, OPT_JSON}, {NULL, false, 0}};

#define MAX_TEXT 4096u

/* Append s (and a separating space) to text; -1 when the text would not fit. */
static int append_text(char *text, size_t *used, const char *s)
{
    size_t n = strlen(s);
    if (*used + n + 2u > MAX_TEXT) {
        return -1;
    }
    memcpy(text + *used, s, n);
    *used += n;
    text[(*used)++] = ' ';
    text[*used] = '\0';
    return 0;
}

static int read_stdin(char *text, size_t *used)
{
    size_t n = fread(text + *used, 1u, MAX_TEXT - 1u - *used, stdin);
    if (ferror(stdin)) {
        cli_error("cannot read standard input");
        return -1;
    }
    *used += n;
    text[*used] = '\0';
    if (!feof(stdin)) {
        cli_error("input longer than %u characters: not a single frame", MAX_TEXT - 1u);
        return -1;
    }
    if (memchr(text, '\0', *used) != NULL) {
        cli_error("not hex: the input contains a NUL byte");
        return -1;
    }
    return 0;
}

/* Which frame the bytes are, by head and length; one message on failure. */
static int classify(const uint8_t *b, size_t len, bool *is_reply)
{
    bool cmd_head = len >= 2u && b[0] == J288_CMD_HEAD0 && b[1] == J288_CMD_HEAD1;
    bool reply_head = len >= 2u && b[0] == J288_REPLY_HEAD0 && b[1] == J288_REPLY_HEAD1;

    if (cmd_head && len != J288_CMD_LEN) {
        cli_error("wrong length: %zu bytes with a command header (fe ee); a command is 20", len);
        return -1;
    }
    if (reply_head && len != J288_REPLY_LEN) {
        cli_error("wrong length: %zu bytes with a reply header (fc ee); a reply is 26", len);
        return -1;
    }
    if (!cmd_head && !reply_head) {
        if (len == J288_CMD_LEN || len == J288_REPLY_LEN) {
            cli_error("wrong header %02x %02x: a command starts fe ee, a reply fc ee", b[0], b[1]);
        } else {
            cli_error("wrong length: %zu bytes; a command is 20 bytes (fe ee ...), a reply 26 "
                      "(fc ee ...)",
                      len);
        }
        return -1;
    }
    *is_reply = reply_head;
    return 0;
}

static int check_crc(const uint8_t *b, bool is_reply)
{
    uint32_t carried = j288_frame_crc_field(b, is_reply ? J288_REPLY_LEN : J288_CMD_LEN);
    uint32_t expected =
        is_reply ? j288_reply_crc_expected(b, NULL) : j288_cmd_crc_expected(b, NULL);
    if (carried != expected) {
        cli_error("CRC mismatch: the %s carries 0x%08lx, its bytes give 0x%08lx",
                  is_reply ? "reply" : "command", (unsigned long)carried, (unsigned long)expected);
        return -1;
    }
    return 0;
}

int cli_cmd_decode(int argc, char **argv, const cli_global_t *g)
{
    static char text[MAX_TEXT];
    uint8_t bytes[J288_REPLY_LEN];
    size_t used = 0, len = 0;
    bool json = false, from_stdin = false, any = false, is_reply = false;
    char err[128];
    cli_args_t a;
    const char *v;
    int key;

    (void)g;
    text[0] = '\0';
    cli_args_init(&a, argc, argv);
    while ((key = cli_args_next(&a, decode_opts, &v)) != CLI_ARG_END) {
        if (key == CLI_ARG_HELP) {
            fputs(decode_help, stdout);
            return CLI_EXIT_OK;
        }
        if (key == CLI_ARG_ERROR) {
            return CLI_EXIT_USAGE;
        }
        if (key == OPT_JSON) {
            json = true;
        } else if (strcmp(v, "-") == 0) {
            from_stdin = true;
        } else {
            any = true;
            if (append_text(text, &used, v) != 0) {
                cli_error("input longer than %u characters: not a single frame", MAX_TEXT - 1u);
                return CLI_EXIT_FAIL;
            }
        }
    }
    if (from_stdin && any) {
        cli_error("give the hex either as arguments or on standard input ('-'), not both");
        return CLI_EXIT_USAGE;
    }
    if (!from_stdin && !any) {
        cli_error("no frame given: j288 decode HEX (try --help)");
        return CLI_EXIT_USAGE;
    }
    if (from_stdin && read_stdin(text, &used) != 0) {
        return CLI_EXIT_FAIL;
    }
    if (cli_hex_parse(text, bytes, sizeof bytes, &len, err, sizeof err) != 0) {
        cli_error("%s", err);
        return CLI_EXIT_FAIL;
    }
    if (classify(bytes, len, &is_reply) != 0 || check_crc(bytes, is_reply) != 0) {
        return CLI_EXIT_FAIL;
    }
    if (is_reply) {
        j288_reply_raw_t r;
        j288_reply_unpack(bytes, &r);
        if (json) {
            cli_json_t j;
            cli_json_init(&j, stdout);
            cli_json_begin_object(&j, NULL);
            cli_json_reply_members(&j, &r);
            cli_json_end_object(&j);
            cli_json_newline(&j);
        } else {
            char title[64];
            snprintf(title, sizeof title, "reply frame: 26 bytes, CRC 0x%08lx ok",
                     (unsigned long)j288_frame_crc_field(bytes, J288_REPLY_LEN));
            cli_show_reply(stdout, &r, title);
        }
    } else {
        j288_cmd_raw_t c;
        j288_cmd_unpack(bytes, &c);
        if (json) {
            cli_json_t j;
            cli_json_init(&j, stdout);
            cli_json_begin_object(&j, NULL);
            cli_json_cmd_members(&j, &c);
            cli_json_end_object(&j);
            cli_json_newline(&j);
        } else {
            char title[64];
            snprintf(title, sizeof title, "command frame: 20 bytes, CRC 0x%08lx ok",
                     (unsigned long)j288_frame_crc_field(bytes, J288_CMD_LEN));
            cli_show_cmd(stdout, &c, title);
        }
    }
    return CLI_EXIT_OK;
}
