/* `j288 encode`: build one command frame from options and print it as hex. */
#include <stdio.h>
#include <string.h>

#include "args.h"
#include "cli.h"
#include "hexparse.h"

static const char encode_help[] =
    "usage: j288 encode --id N [--mode lock|foc] [--watchdog on|off]\n"
    "                   [--tau-raw N] [--speed-raw N] [--pos-raw N] [--kp-raw N] [--kd-raw N]\n"
    "                   [--tau NM] [--speed RAD_S] [--pos RAD] [--kp NM_RAD] [--kd NMS_RAD]\n"
    "                   [--side output|rotor]\n"
    "\n"
    "Print the 20-byte command frame as 40 lowercase hex digits.\n"
    "\n"
    "  --id N           servo id 0-14, or 15 for broadcast (required)\n"
    "  --mode M         lock (no torque) or foc (closed loop); default foc\n"
    "  --watchdog W     on: the servo's 1 s communication watchdog is enabled; default on\n"
    "  --tau-raw N      feed-forward torque, int16 (256000 LSB per N*m, rotor)\n"
    "  --speed-raw N    speed target, int16 (2.56/2pi LSB per rad/s, rotor)\n"
    "  --pos-raw N      position target, int32 (32768/2pi LSB per rad, rotor)\n"
    "  --kp-raw N       stiffness, 0..32767 (1280000 LSB per N*m/rad, rotor)\n"
    "  --kd-raw N       damping, 0..32767 (128000000 LSB per N*m*s/rad, rotor)\n"
    "  --tau, --speed, --pos, --kp, --kd\n"
    "                   the same in SI units (N*m, rad/s, rad, N*m/rad, N*m*s/rad), rounded\n"
    "                   to nearest; out of range is an error, never a wrap\n"
    "  --side S         which side of the 288.35:1 gear the SI values refer to: output\n"
    "                   (default) or rotor\n"
    "All fields default to 0. Numbers may be decimal or 0x-prefixed hex (raw options).\n"
    "\n"
    "example: j288 encode --id 3 --pos-raw 5215 --kp-raw 1280 --kd-raw 12800\n";

enum {
    OPT_ID,
    OPT_MODE,
    OPT_WATCHDOG,
    OPT_SIDE,
    /* raw fields, then SI fields, in the order of the field table below */
    OPT_TAU_RAW,
    OPT_SPEED_RAW,
    OPT_POS_RAW,
    OPT_KP_RAW,
    OPT_KD_RAW,
    OPT_TAU,
    OPT_SPEED,
    OPT_POS,
    OPT_KP,
    OPT_KD
};

#define NFIELDS 5

static const cli_opt_t encode_opts[] = {{"--id", true, OPT_ID},
                                        {"--mode", true, OPT_MODE},
                                        {"--watchdog", true, OPT_WATCHDOG},
                                        {"--side", true, OPT_SIDE},
                                        {"--tau-raw", true, OPT_TAU_RAW},
                                        {"--speed-raw", true, OPT_SPEED_RAW},
                                        {"--pos-raw", true, OPT_POS_RAW},
                                        {"--kp-raw", true, OPT_KP_RAW},
                                        {"--kd-raw", true, OPT_KD_RAW},
                                        {"--tau", true, OPT_TAU},
                                        {"--speed", true, OPT_SPEED},
                                        {"--pos", true, OPT_POS},
                                        {"--kp", true, OPT_KP},
                                        {"--kd", true, OPT_KD},
                                        {NULL, false, 0}};

typedef struct {
    const char *raw_opt;
    const char *si_opt;
    long long lo, hi;
    const char *unit;
} field_info_t;

static const field_info_t fields[NFIELDS] = {
    {"--tau-raw", "--tau", INT16_MIN, INT16_MAX, "N*m"},
    {"--speed-raw", "--speed", INT16_MIN, INT16_MAX, "rad/s"},
    {"--pos-raw", "--pos", INT32_MIN, INT32_MAX, "rad"},
    {"--kp-raw", "--kp", 0, INT16_MAX, "N*m/rad"},
    {"--kd-raw", "--kd", 0, INT16_MAX, "N*m*s/rad"},
};

/* What the user gave for each field: nothing, a raw integer or an SI value. */
typedef struct {
    enum { FIELD_UNSET, FIELD_RAW, FIELD_SI } kind;
    long long raw;
    double si;
} field_value_t;

static j288_real_t field_from_raw(int f, int32_t raw, j288_side_t side)
{
    switch (f) {
    case 0:
        return j288_torque_from_raw(raw, side);
    case 1:
        return j288_speed_from_raw(raw, side);
    case 2:
        return j288_pos_from_raw(raw, side);
    case 3:
        return j288_kp_from_raw(raw, side);
    default:
        return j288_kd_from_raw(raw, side);
    }
}

/* SI -> raw through the library, with a message naming the option and its SI range. */
static int field_to_raw(int f, double si, j288_side_t side, long long *raw)
{
    int16_t r16 = 0;
    int32_t r32 = 0;
    int rc;
    switch (f) {
    case 0:
        rc = j288_torque_to_raw((j288_real_t)si, side, &r16);
        break;
    case 1:
        rc = j288_speed_to_raw((j288_real_t)si, side, &r16);
        break;
    case 2:
        rc = j288_pos_to_raw((j288_real_t)si, side, &r32);
        break;
    case 3:
        rc = j288_kp_to_raw((j288_real_t)si, side, &r16);
        break;
    default:
        rc = j288_kd_to_raw((j288_real_t)si, side, &r16);
        break;
    }
    if (rc == J288_ERR_NEG_GAIN) {
        cli_error("%s: %g is negative; gains must be >= 0", fields[f].si_opt, si);
        return -1;
    }
    if (rc != J288_OK) {
        cli_error("%s: %g is out of range %.7g..%.7g %s (%s side)", fields[f].si_opt, si,
                  (double)field_from_raw(f, (int32_t)fields[f].lo, side),
                  (double)field_from_raw(f, (int32_t)fields[f].hi, side), fields[f].unit,
                  side == J288_SIDE_ROTOR ? "rotor" : "output");
        return -1;
    }
    *raw = f == 2 ? (long long)r32 : (long long)r16;
    return 0;
}

static int parse_field(int f, bool is_si, const char *text, field_value_t *v)
{
    const char *opt = is_si ? fields[f].si_opt : fields[f].raw_opt;
    if (v->kind != FIELD_UNSET) {
        cli_error("%s: the field is already set (by %s)", opt,
                  v->kind == FIELD_SI ? fields[f].si_opt : fields[f].raw_opt);
        return -1;
    }
    if (is_si) {
        v->kind = FIELD_SI;
        return cli_parse_real(opt, text, &v->si);
    }
    v->kind = FIELD_RAW;
    if (f >= 3 && text[0] == '-' && text[1] != '\0') {
        long long tmp;
        if (cli_parse_int(opt, text, INT32_MIN, INT32_MAX, &tmp) == 0) {
            cli_error("%s: %s is negative; gains must be 0..32767", opt, text);
        }
        return -1;
    }
    return cli_parse_int(opt, text, fields[f].lo, fields[f].hi, &v->raw);
}

int cli_cmd_encode(int argc, char **argv, const cli_global_t *g)
{
    static const char *const modes[] = {"lock", "foc", NULL};
    static const char *const onoff[] = {"off", "on", NULL};
    static const char *const sides[] = {"rotor", "output", NULL};
    field_value_t val[NFIELDS];
    cli_args_t a;
    const char *v;
    long long id = -1;
    int mode = 1, watchdog = 1, side = 1;
    int key, f, rc;
    j288_cmd_raw_t cmd;
    uint8_t frame[J288_CMD_LEN];
    char hex[2 * J288_CMD_LEN + 1];

    (void)g;
    memset(val, 0, sizeof val);
    cli_args_init(&a, argc, argv);
    while ((key = cli_args_next(&a, encode_opts, &v)) != CLI_ARG_END) {
        switch (key) {
        case CLI_ARG_HELP:
            fputs(encode_help, stdout);
            return CLI_EXIT_OK;
        case CLI_ARG_ERROR:
            return CLI_EXIT_USAGE;
        case CLI_ARG_POSITIONAL:
            cli_error("unexpected argument '%s' (try --help)", v);
            return CLI_EXIT_USAGE;
        case OPT_ID:
            rc = cli_parse_int("--id", v, 0, J288_BROADCAST_ID, &id);
            break;
        case OPT_MODE:
            rc = cli_parse_choice("--mode", v, modes, &mode);
            break;
        case OPT_WATCHDOG:
            rc = cli_parse_choice("--watchdog", v, onoff, &watchdog);
            break;
        case OPT_SIDE:
            rc = cli_parse_choice("--side", v, sides, &side);
            break;
        default:
            f = key >= OPT_TAU ? key - OPT_TAU : key - OPT_TAU_RAW;
            rc = parse_field(f, key >= OPT_TAU, v, &val[f]);
            break;
        }
        if (rc != 0) {
            return CLI_EXIT_USAGE;
        }
    }
    if (id < 0) {
        cli_error("--id is required (0-14, or 15 for broadcast)");
        return CLI_EXIT_USAGE;
    }
    /* SI values are converted only now, once --side is known wherever it appeared. */
    for (f = 0; f < NFIELDS; f++) {
        if (val[f].kind == FIELD_SI &&
            field_to_raw(f, val[f].si, side == 0 ? J288_SIDE_ROTOR : J288_SIDE_OUTPUT,
                         &val[f].raw) != 0) {
            return CLI_EXIT_USAGE;
        }
    }
    memset(&cmd, 0, sizeof cmd);
    cmd.id = (uint8_t)id;
    cmd.status = (uint8_t)(mode == 0 ? J288_MODE_LOCK : J288_MODE_FOC);
    cmd.watchdog = watchdog != 0;
    cmd.tau = (int16_t)val[0].raw;
    cmd.speed = (int16_t)val[1].raw;
    cmd.pos = (int32_t)val[2].raw;
    cmd.kp = (int16_t)val[3].raw;
    cmd.kd = (int16_t)val[4].raw;
    rc = j288_cmd_encode(&cmd, frame, NULL);
    if (rc != J288_OK) {
        /* Every field was range-checked above; this is a library disagreement. */
        cli_error("cannot encode: %s", j288_strerror(rc));
        return CLI_EXIT_FAIL;
    }
    cli_hex_format(frame, sizeof frame, hex);
    printf("%s\n", hex);
    return CLI_EXIT_OK;
}
