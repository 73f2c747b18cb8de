/*
 * Fuzz target: the robot config reader and its write-back edit (host/j288_robot_config.h),
 * linked with libyaml as the tools are.
 *
 * Input: the file's text (any bytes).
 *
 * Invariants:
 * - j288_robot_config_parse() returns 0 or -1; -1 comes with one line "config.yaml:LINE: ..."
 *   (LINE a positive number within the text's lines + 1, counting every YAML line break: a
 *   CR alone is one; no newline in the message).
 * - On 0 every value is within what the header promises: at most 16 buses and 64 joints,
 *   names non-empty without blanks or control characters, ports non-empty, ids 0-14 and
 *   unique per bus, a joint's bus an index of a bus (or none when the file has no buses),
 *   direction +-1, limits ordered within +-J288_JOINT_MAX_ANGLE and at most 2 pi wide, zero
 *   within +-J288_JOINT_MAX_ANGLE, phase within +-2 pi, speeds and torques above 0, gains 0 or
 *   more, all finite and at most 1e30; and the library takes every joint (j288_joint_init).
 * - On 0, for the first joint, an edit of its zero to 0.5 either fails with a message or gives
 *   a text that parses to the same configuration with that zero (the edit's own check, done
 *   again here from outside), at most 320 bytes longer than the input.
 * The reader's time is bounded as well: nesting beyond J288_ROBOT_CONFIG_MAX_DEPTH stops the
 * parse where it is crossed (a deep input cannot make a slow unit).
 */
#include "fuzz_common.h"

#include "j288_range.h"
#include "j288_robot_config.h"

#include <math.h>
#include <string.h>

#define NAME "config.yaml"
#define TWO_PI (2.0 * 3.14159265358979323846)

static j288_robot_config_t g_cfg, g_after;

static void check_text(const char *s, size_t cap, bool is_name)
{
    const char *nul = memchr(s, '\0', cap);
    size_t n, i;
    FUZZ_CHECK(nul != NULL);
    n = (size_t)(nul - s);
    FUZZ_CHECK(n > 0u);
    for (i = 0; i < n; i++) {
        unsigned char c = (unsigned char)s[i];
        FUZZ_CHECK(c >= 0x20u && c != 0x7Fu);
        FUZZ_CHECK(!is_name || c != ' ');
    }
}

static void check_error(const char *err, const uint8_t *data, size_t size)
{
    size_t prefix = strlen(NAME ":"), lines = 1, i;
    char *end = NULL;
    unsigned long line;
    /* YAML's line breaks: LF, CR (alone too), NEL (C2 85), LS and PS (E2 80 A8/A9); the last
     * byte of each counted, which may over-count: a bound, not the number. */
    for (i = 0; i < size; i++)
        lines += (data[i] == '\n' || data[i] == '\r' || data[i] == 0x85u || data[i] == 0xA8u ||
                  data[i] == 0xA9u)
                     ? 1u
                     : 0u;
    FUZZ_CHECK(strncmp(err, NAME ":", prefix) == 0);
    line = strtoul(err + prefix, &end, 10);
    FUZZ_CHECK(end != err + prefix && *end == ':');
    FUZZ_CHECK(line >= 1u && line <= lines + 1u);
    FUZZ_CHECK(strchr(err, '\n') == NULL);
}

static bool finite_within(double v, double lo, double hi)
{
    return isfinite(v) && v >= lo && v <= hi;
}

static void check_config(const j288_robot_config_t *c)
{
    size_t i, k;
    FUZZ_CHECK(c->nbuses <= J288_ROBOT_CONFIG_MAX_BUSES);
    FUZZ_CHECK(c->njoints <= J288_ROBOT_CONFIG_MAX_JOINTS);
    for (i = 0; i < c->nbuses; i++) {
        check_text(c->bus[i].name, sizeof c->bus[i].name, true);
        check_text(c->bus[i].port, sizeof c->bus[i].port, false);
        FUZZ_CHECK(!c->bus[i].has_baud || j288_range_has(J288_QTY_BAUD, (double)c->bus[i].baud));
        FUZZ_CHECK(!c->bus[i].has_margin_us ||
                   j288_range_has(J288_QTY_MARGIN_US, (double)c->bus[i].margin_us));
        for (k = 0; k < i; k++)
            FUZZ_CHECK(strcmp(c->bus[k].name, c->bus[i].name) != 0);
    }
    for (i = 0; i < c->njoints; i++) {
        const j288_robot_config_joint_t *j = &c->joint[i];
        j288_joint_config_t jc;
        j288_joint_t joint;
        check_text(j->name, sizeof j->name, true);
        FUZZ_CHECK(j->id <= 14u);
        FUZZ_CHECK(c->nbuses == 0u ? j->bus == J288_ROBOT_CONFIG_NO_BUS
                                   : (j->bus >= 0 && (size_t)j->bus < c->nbuses));
        FUZZ_CHECK(j->direction == 1 || j->direction == -1);
        FUZZ_CHECK(finite_within(j->zero, -J288_JOINT_MAX_ANGLE, J288_JOINT_MAX_ANGLE));
        FUZZ_CHECK(finite_within(j->pos_min, -J288_JOINT_MAX_ANGLE, J288_JOINT_MAX_ANGLE));
        FUZZ_CHECK(finite_within(j->pos_max, -J288_JOINT_MAX_ANGLE, J288_JOINT_MAX_ANGLE));
        FUZZ_CHECK(j->pos_min < j->pos_max && j->pos_max - j->pos_min <= TWO_PI + 1e-9);
        FUZZ_CHECK(!j->has_max_speed || (j->max_speed > 0.0 && j->max_speed <= 1e30));
        FUZZ_CHECK(!j->has_max_torque || (j->max_torque > 0.0 && j->max_torque <= 1e30));
        FUZZ_CHECK(!j->has_kp || j288_range_has(J288_QTY_KP, j->kp));
        FUZZ_CHECK(!j->has_kd || j288_range_has(J288_QTY_KD, j->kd));
        FUZZ_CHECK(!j->has_phase || finite_within(j->phase, -TWO_PI, TWO_PI));
        for (k = 0; k < i; k++) {
            FUZZ_CHECK(strcmp(c->joint[k].name, j->name) != 0);
            FUZZ_CHECK(c->joint[k].bus != j->bus || c->joint[k].id != j->id);
        }
        j288_robot_config_joint_config(j, &jc);
        FUZZ_CHECK(j288_joint_init(&joint, &jc) == J288_OK);
    }
}

/* The first joint's zero set to 0.5 through the editor. */
static void check_edit(const char *text, size_t size)
{
    static char out[8192 + 512];
    char err[J288_ROBOT_CONFIG_ERROR_MAX];
    j288_robot_config_update_t upd;
    size_t outlen = 0, i;
    if (g_cfg.njoints == 0u || size + 320u > sizeof out)
        return;
    memset(&upd, 0, sizeof upd);
    upd.set_zero = true;
    upd.zero = 0.5;
    if (j288_robot_config_edit(text, size, NAME, g_cfg.joint[0].name, &upd, out, sizeof out,
                               &outlen, err, sizeof err) != 0) {
        FUZZ_CHECK(err[0] != '\0' && strchr(err, '\n') == NULL);
        return;
    }
    FUZZ_CHECK(outlen <= size + 320u);
    FUZZ_CHECK(j288_robot_config_parse(out, outlen, NAME, &g_after, err, sizeof err) == 0);
    FUZZ_CHECK(g_after.njoints == g_cfg.njoints && g_after.nbuses == g_cfg.nbuses);
    FUZZ_CHECK(g_after.joint[0].zero == 0.5);
    for (i = 0; i < g_cfg.njoints; i++) {
        FUZZ_CHECK(strcmp(g_after.joint[i].name, g_cfg.joint[i].name) == 0);
        FUZZ_CHECK(g_after.joint[i].id == g_cfg.joint[i].id);
        FUZZ_CHECK(g_after.joint[i].bus == g_cfg.joint[i].bus);
        FUZZ_CHECK(g_after.joint[i].has_phase == g_cfg.joint[i].has_phase);
        FUZZ_CHECK(i == 0u || g_after.joint[i].zero == g_cfg.joint[i].zero);
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char err[J288_ROBOT_CONFIG_ERROR_MAX];
    const char *text = (const char *)data;
    err[0] = '\0';
    if (!j288_robot_config_available()) { /* a build without libyaml: every parse says so */
        FUZZ_CHECK(j288_robot_config_parse(text, size, NAME, &g_cfg, err, sizeof err) == -1);
        return 0;
    }
    if (j288_robot_config_parse(text, size, NAME, &g_cfg, err, sizeof err) != 0) {
        check_error(err, data, size);
        return 0;
    }
    check_config(&g_cfg);
    check_edit(text, size);
    return 0;
}
