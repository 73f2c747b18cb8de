/* Showing frames as tables and JSON; see frameview.h. */
#include "frameview.h"

#include <string.h>

const char *cli_mode_name(unsigned status)
{
    static const char *const names[8] = {"lock",     "foc",      "status 2", "status 3",
                                         "status 4", "status 5", "status 6", "status 7"};
    return names[status & 7u];
}

/* Append s to buf (separated by ", "), truncating safely. */
static void append(char *buf, size_t len, const char *s)
{
    size_t used = strlen(buf);
    if (used != 0u && used + 2u < len) {
        memcpy(buf + used, ", ", 3u);
        used += 2u;
    }
    while (*s != '\0' && used + 1u < len) {
        buf[used++] = *s++;
    }
    buf[used] = '\0';
}

/* The name of fault bit n, with the bit number for unknown ones (they all share a name). */
static const char *fault_label(unsigned bit, char *tmp, size_t len)
{
    if (bit < J288_FAULT_COUNT) {
        return j288_fault_name(bit);
    }
    snprintf(tmp, len, "%s (bit %u)", j288_fault_name(bit), bit);
    return tmp;
}

static const char *warning_label(unsigned bit, char *tmp, size_t len)
{
    if (bit < 1u) {
        return j288_warning_name(bit);
    }
    snprintf(tmp, len, "%s (bit %u)", j288_warning_name(bit), bit);
    return tmp;
}

const char *cli_fault_list(uint32_t faults, char *buf, size_t len)
{
    unsigned bit;
    char tmp[48];
    buf[0] = '\0';
    for (bit = 0; bit < 32u; bit++) {
        if ((faults & (1ul << bit)) != 0u) {
            append(buf, len, fault_label(bit, tmp, sizeof tmp));
        }
    }
    if (buf[0] == '\0') {
        append(buf, len, "none");
    }
    return buf;
}

const char *cli_warning_list(unsigned warnings, char *buf, size_t len)
{
    unsigned bit;
    char tmp[48];
    buf[0] = '\0';
    for (bit = 0; bit < 8u; bit++) {
        if ((warnings & (1u << bit)) != 0u) {
            append(buf, len, warning_label(bit, tmp, sizeof tmp));
        }
    }
    if (buf[0] == '\0') {
        append(buf, len, "none");
    }
    return buf;
}

typedef j288_real_t (*from_raw_fn)(int32_t raw, j288_side_t side);

static void show_quantity(FILE *f, const char *name, long raw, from_raw_fn conv, const char *unit)
{
    char rotor[40];
    snprintf(rotor, sizeof rotor, "%.7g %s", (double)conv((int32_t)raw, J288_SIDE_ROTOR), unit);
    fprintf(f, "  %-13s %11ld   %-22s %.7g %s\n", name, raw, rotor,
            (double)conv((int32_t)raw, J288_SIDE_OUTPUT), unit);
}

static void show_quantity_header(FILE *f)
{
    fprintf(f, "  %-13s %11s   %-22s %s\n", "", "raw", "rotor side", "output side");
}

void cli_show_cmd(FILE *f, const j288_cmd_raw_t *c, const char *title)
{
    fprintf(f, "%s\n", title);
    fprintf(f, "  %-13s %u%s\n", "id", (unsigned)c->id,
            c->id == J288_BROADCAST_ID ? " (broadcast)" : "");
    fprintf(f, "  %-13s %u (%s)\n", "mode", (unsigned)c->status, cli_mode_name(c->status));
    fprintf(f, "  %-13s %u (%s)\n", "watchdog", c->watchdog ? 1u : 0u,
            c->watchdog ? "enabled" : "disabled");
    fprintf(f, "  %-13s %u\n", "reserved", (unsigned)c->reserved);
    show_quantity_header(f);
    show_quantity(f, "tau", c->tau, j288_torque_from_raw, "N*m");
    show_quantity(f, "speed", c->speed, j288_speed_from_raw, "rad/s");
    show_quantity(f, "pos", (long)c->pos, j288_pos_from_raw, "rad");
    show_quantity(f, "kp", c->kp, j288_kp_from_raw, "N*m/rad");
    show_quantity(f, "kd", c->kd, j288_kd_from_raw, "N*m*s/rad");
}

void cli_show_reply(FILE *f, const j288_reply_raw_t *r, const char *title)
{
    char list[512];
    fprintf(f, "%s\n", title);
    fprintf(f, "  %-13s %u\n", "id", (unsigned)r->id);
    fprintf(f, "  %-13s %u (%s)\n", "mode", (unsigned)r->status, cli_mode_name(r->status));
    fprintf(f, "  %-13s %u (%s)\n", "watchdog", r->watchdog_tripped ? 1u : 0u,
            r->watchdog_tripped ? "tripped" : "not tripped");
    fprintf(f, "  %-13s %d C\n", "case temp", (int)r->case_temp_c);
    fprintf(f, "  %-13s %u C\n", "winding temp", (unsigned)r->winding_temp_c);
    fprintf(f, "  %-13s %u (%.1f V)\n", "voltage", (unsigned)r->voltage_raw,
            (double)r->voltage_raw * J288_SCALE_VOLTAGE);
    show_quantity_header(f);
    show_quantity(f, "torque", r->torque, j288_torque_from_raw, "N*m");
    show_quantity(f, "speed", r->speed, j288_speed_from_raw, "rad/s");
    show_quantity(f, "pos", (long)r->pos, j288_pos_from_raw, "rad");
    fprintf(f, "  %-13s %u (%.7g rad output, absolute within one turn)\n", "out_pos",
            (unsigned)r->out_pos, (double)j288_out_pos_to_rad(r->out_pos));
    fprintf(f, "  %-13s 0x%08lx (%s)\n", "faults", (unsigned long)r->faults,
            cli_fault_list(r->faults, list, sizeof list));
    fprintf(f, "  %-13s %u (%s)\n", "warnings", (unsigned)r->warnings,
            cli_warning_list(r->warnings, list, sizeof list));
    fprintf(f, "  %-13s %u\n", "reserved", (unsigned)r->reserved);
}

void cli_json_cmd_members(cli_json_t *j, const j288_cmd_raw_t *c)
{
    static const j288_side_t sides[2] = {J288_SIDE_ROTOR, J288_SIDE_OUTPUT};
    static const char *const side_names[2] = {"rotor", "output"};
    int s;

    cli_json_str(j, "frame", "command");
    cli_json_int(j, "id", c->id);
    cli_json_int(j, "mode", c->status);
    cli_json_str(j, "mode_name", cli_mode_name(c->status));
    cli_json_int(j, "watchdog", c->watchdog ? 1 : 0);
    cli_json_int(j, "reserved", c->reserved);
    cli_json_int(j, "tau_raw", c->tau);
    cli_json_int(j, "speed_raw", c->speed);
    cli_json_int(j, "pos_raw", c->pos);
    cli_json_int(j, "kp_raw", c->kp);
    cli_json_int(j, "kd_raw", c->kd);
    for (s = 0; s < 2; s++) {
        cli_json_begin_object(j, side_names[s]);
        cli_json_real(j, "tau_nm", j288_torque_from_raw(c->tau, sides[s]));
        cli_json_real(j, "speed_rad_s", j288_speed_from_raw(c->speed, sides[s]));
        cli_json_real(j, "pos_rad", j288_pos_from_raw(c->pos, sides[s]));
        cli_json_real(j, "kp_nm_per_rad", j288_kp_from_raw(c->kp, sides[s]));
        cli_json_real(j, "kd_nms_per_rad", j288_kd_from_raw(c->kd, sides[s]));
        cli_json_end_object(j);
    }
}

void cli_json_reply_members(cli_json_t *j, const j288_reply_raw_t *r)
{
    static const j288_side_t sides[2] = {J288_SIDE_ROTOR, J288_SIDE_OUTPUT};
    static const char *const side_names[2] = {"rotor", "output"};
    char tmp[48];
    unsigned bit;
    int s;

    cli_json_str(j, "frame", "reply");
    cli_json_int(j, "id", r->id);
    cli_json_int(j, "mode", r->status);
    cli_json_str(j, "mode_name", cli_mode_name(r->status));
    cli_json_int(j, "watchdog", r->watchdog_tripped ? 1 : 0);
    cli_json_int(j, "case_temp_c", r->case_temp_c);
    cli_json_int(j, "winding_temp_c", r->winding_temp_c);
    cli_json_int(j, "voltage_raw", r->voltage_raw);
    cli_json_real(j, "voltage_v", (double)r->voltage_raw * J288_SCALE_VOLTAGE);
    cli_json_int(j, "torque_raw", r->torque);
    cli_json_int(j, "speed_raw", r->speed);
    cli_json_int(j, "pos_raw", r->pos);
    cli_json_uint(j, "faults", r->faults);
    cli_json_begin_array(j, "fault_names");
    for (bit = 0; bit < 32u; bit++) {
        if ((r->faults & (1ul << bit)) != 0u) {
            cli_json_str(j, NULL, fault_label(bit, tmp, sizeof tmp));
        }
    }
    cli_json_end_array(j);
    cli_json_int(j, "out_pos_raw", r->out_pos);
    cli_json_real(j, "out_pos_rad", j288_out_pos_to_rad(r->out_pos));
    cli_json_int(j, "warnings", r->warnings);
    cli_json_begin_array(j, "warning_names");
    for (bit = 0; bit < 8u; bit++) {
        if ((r->warnings & (1u << bit)) != 0u) {
            cli_json_str(j, NULL, warning_label(bit, tmp, sizeof tmp));
        }
    }
    cli_json_end_array(j);
    cli_json_int(j, "reserved", r->reserved);
    for (s = 0; s < 2; s++) {
        cli_json_begin_object(j, side_names[s]);
        cli_json_real(j, "torque_nm", j288_torque_from_raw(r->torque, sides[s]));
        cli_json_real(j, "speed_rad_s", j288_speed_from_raw(r->speed, sides[s]));
        cli_json_real(j, "pos_rad", j288_pos_from_raw(r->pos, sides[s]));
        cli_json_end_object(j);
    }
}
