/* j288_robot_config.c - the robot config file; see j288_robot_config.h. */
#define _XOPEN_SOURCE 700 /* realpath, mkstemp, fchmod, fsync under -std=c99 */

#include "j288_robot_config.h"

#include "j288_number.h"
#include "j288_range.h"

#include <dirent.h>
#include <errno.h>
#include <limits.h>
#include <signal.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#ifdef J288_HAVE_LIBYAML
#include <yaml.h>
#endif

/* Formats checked as C99's (%zu); mingw-w64's "printf" would check Microsoft's. */
#ifdef __MINGW_PRINTF_FORMAT
#define PRINTF_LIKE(f, a) __attribute__((format(__MINGW_PRINTF_FORMAT, f, a)))
#else
#define PRINTF_LIKE(f, a) __attribute__((format(printf, f, a)))
#endif

/* One line of error text: "prefix" then the formatted message. */
static int set_error(char *err, size_t errlen, const char *fmt, ...) PRINTF_LIKE(3, 4);

static int set_error(char *err, size_t errlen, const char *fmt, ...)
{
    va_list ap;
    if (err != NULL && errlen > 0u) {
        va_start(ap, fmt);
        (void)vsnprintf(err, errlen, fmt, ap);
        va_end(ap);
    }
    return -1;
}

const j288_robot_config_joint_t *j288_robot_config_find_joint(const j288_robot_config_t *cfg, const char *name)
{
    size_t i;
    for (i = 0; i < cfg->njoints; i++)
        if (strcmp(cfg->joint[i].name, name) == 0)
            return &cfg->joint[i];
    return NULL;
}

int j288_robot_config_find_bus(const j288_robot_config_t *cfg, const char *name)
{
    size_t i;
    for (i = 0; i < cfg->nbuses; i++)
        if (strcmp(cfg->bus[i].name, name) == 0)
            return (int)i;
    return -1;
}

void j288_robot_config_joint_config(const j288_robot_config_joint_t *rj, j288_joint_config_t *jc)
{
    if (rj == NULL || jc == NULL)
        return;
    memset(jc, 0, sizeof *jc);
    jc->id = rj->id;
    jc->direction = (int8_t)(rj->direction < 0 ? -1 : 1);
    jc->clamp = rj->clamp;
    jc->zero = (j288_real_t)rj->zero;
    /* Without limits the file means the library's default range: both 0 say so. */
    if (rj->has_limits) {
        jc->pos_min = (j288_real_t)rj->pos_min;
        jc->pos_max = (j288_real_t)rj->pos_max;
    }
    jc->max_speed = rj->has_max_speed ? (j288_real_t)rj->max_speed : 0;
    jc->max_torque = rj->has_max_torque ? (j288_real_t)rj->max_torque : 0;
    jc->kp = rj->has_kp ? (j288_real_t)rj->kp : 0;
    jc->kd = rj->has_kd ? (j288_real_t)rj->kd : 0;
    jc->has_phase = rj->has_phase;
    jc->phase = rj->has_phase ? (j288_real_t)rj->phase : 0;
}

/* The whole file into a malloc'ed buffer (NUL-terminated for convenience), growing it as
 * needed up to J288_ROBOT_CONFIG_FILE_MAX bytes. */
static int read_file(const char *path, char **text, size_t *len, char *err, size_t errlen)
{
    FILE *f = fopen(path, "rb");
    char *buf = NULL;
    size_t cap = 0, n = 0;
    if (f == NULL)
        return set_error(err, errlen, "%s: cannot read: %s", path, strerror(errno));
    for (;;) {
        if (n == cap) {
            char *bigger;
            if (cap > J288_ROBOT_CONFIG_FILE_MAX) {
                (void)fclose(f);
                free(buf);
                return set_error(err, errlen, "%s: larger than %u bytes: not a robot config", path,
                                 J288_ROBOT_CONFIG_FILE_MAX);
            }
            cap = (cap == 0u) ? 4096u : 2u * cap;
            bigger = realloc(buf, cap + 1u);
            if (bigger == NULL) {
                (void)fclose(f);
                free(buf);
                return set_error(err, errlen, "%s: out of memory", path);
            }
            buf = bigger;
        }
        n += fread(buf + n, 1, cap - n, f);
        if (n < cap)
            break; /* end of file or an error */
    }
    if (ferror(f)) {
        (void)fclose(f);
        free(buf);
        return set_error(err, errlen, "%s: cannot read: %s", path, strerror(errno));
    }
    (void)fclose(f);
    if (n > J288_ROBOT_CONFIG_FILE_MAX) {
        free(buf);
        return set_error(err, errlen, "%s: larger than %u bytes: not a robot config", path,
                         J288_ROBOT_CONFIG_FILE_MAX);
    }
    buf[n] = '\0';
    *text = buf;
    *len = n;
    return 0;
}

/* A relative port names a device beside the file (a simulator's link in the robot's
 * folder), wherever the tool was started: path's folder goes in front of it. */
static int resolve_ports(const char *path, j288_robot_config_t *cfg, char *err, size_t errlen)
{
    const char *slash = strrchr(path, '/');
    size_t dirlen = (slash == NULL) ? 0u : (size_t)(slash - path) + 1u; /* with the '/' */
    size_t i;
    for (i = 0; i < cfg->nbuses && dirlen > 0u; i++) {
        j288_robot_config_bus_t *b = &cfg->bus[i];
        char joined[J288_ROBOT_CONFIG_PORT_MAX];
        if (b->port[0] == '/')
            continue;
        if ((size_t)snprintf(joined, sizeof joined, "%.*s%s", (int)dirlen, path, b->port) >=
            sizeof joined)
            return set_error(err, errlen,
                             "%s:%u: bus '%s': port: %s within the file's folder is longer than "
                             "%u bytes",
                             path, b->line, b->name, b->port, J288_ROBOT_CONFIG_PORT_MAX - 1u);
        memcpy(b->port, joined, sizeof joined);
    }
    return 0;
}

int j288_robot_config_load(const char *path, j288_robot_config_t *cfg, char *err, size_t errlen)
{
    char *text = NULL;
    size_t len = 0;
    int rc;
    if (!j288_robot_config_available()) /* say that first, not whether the file exists */
        return j288_robot_config_parse("", 0, path, cfg, err, errlen);
    if (read_file(path, &text, &len, err, errlen) != 0)
        return -1;
    rc = j288_robot_config_parse(text, len, path, cfg, err, errlen);
    free(text);
    return (rc == 0) ? resolve_ports(path, cfg, err, errlen) : rc;
}

#ifndef J288_HAVE_LIBYAML

/* Built without libyaml: every entry point says so. */
#define NO_YAML "robot config files need libyaml: this build has none (install libyaml-dev)"

bool j288_robot_config_available(void)
{
    return false;
}

int j288_robot_config_parse(const char *text, size_t len, const char *name, j288_robot_config_t *cfg, char *err,
                      size_t errlen)
{
    (void)text;
    (void)len;
    (void)cfg;
    return set_error(err, errlen, "%s: %s", name, NO_YAML);
}

int j288_robot_config_edit(const char *text, size_t len, const char *name, const char *joint,
                     const j288_robot_config_update_t *upd, char *out, size_t outcap, size_t *outlen,
                     char *err, size_t errlen)
{
    (void)text;
    (void)len;
    (void)joint;
    (void)upd;
    (void)out;
    (void)outcap;
    (void)outlen;
    return set_error(err, errlen, "%s: %s", name, NO_YAML);
}

int j288_robot_config_write_joint(const char *path, const char *joint, const j288_robot_config_update_t *upd,
                            char *err, size_t errlen)
{
    (void)joint;
    (void)upd;
    return set_error(err, errlen, "%s: %s", path, NO_YAML);
}

int j288_robot_config_check_writable(const char *path, char *err, size_t errlen)
{
    return set_error(err, errlen, "%s: %s", path, NO_YAML);
}

#else /* J288_HAVE_LIBYAML */

#define PI          3.141592653589793
#define TWO_PI      (2.0 * PI)

bool j288_robot_config_available(void)
{
    return true;
}

/* ---- reading -------------------------------------------------------------------------------- */

/* One parse: the text, the libyaml document, where the joints' nodes are, the result. */
typedef struct {
    const char *name;          /* the file, in messages */
    const unsigned char *text; /* after a UTF-8 byte order mark, if any */
    size_t len;
    yaml_document_t doc;
    bool have_doc;
    j288_robot_config_t *cfg;
    yaml_node_t *joint_node[J288_ROBOT_CONFIG_MAX_JOINTS];
    yaml_node_t *joint_bus[J288_ROBOT_CONFIG_MAX_JOINTS]; /* the value of 'bus:', or NULL */
    size_t joints_line;                             /* the 'joints:' key, 1-based; 0: none */
    char label[J288_ROBOT_CONFIG_NAME_MAX + 16];          /* "joint 'hip': ", for messages */
    char *err;
    size_t errlen;
} ctx_t;

static int fail(ctx_t *x, size_t line, const char *fmt, ...) PRINTF_LIKE(3, 4);

/* "FILE:LINE: <label>message"; LINE counts from 1. */
static int fail(ctx_t *x, size_t line, const char *fmt, ...)
{
    va_list ap;
    int n;
    if (x->err == NULL || x->errlen == 0u)
        return -1;
    n = snprintf(x->err, x->errlen, "%s:%zu: %s", x->name, line, x->label);
    if (n >= 0 && (size_t)n < x->errlen) {
        va_start(ap, fmt);
        (void)vsnprintf(x->err + n, x->errlen - (size_t)n, fmt, ap);
        va_end(ap);
    }
    return -1;
}

static size_t line_of(const yaml_node_t *n)
{
    return n->start_mark.line + 1u;
}

static yaml_node_t *node_at(ctx_t *x, yaml_node_item_t id)
{
    return yaml_document_get_node(&x->doc, id);
}

static const char *scalar(const yaml_node_t *n)
{
    return (const char *)n->data.scalar.value;
}

static bool is_null(const yaml_node_t *n)
{
    static const char *const nulls[] = {"", "~", "null", "Null", "NULL"};
    size_t i;
    if (n->type != YAML_SCALAR_NODE || n->data.scalar.style != YAML_PLAIN_SCALAR_STYLE)
        return false;
    for (i = 0; i < sizeof nulls / sizeof nulls[0]; i++)
        if (strcmp(scalar(n), nulls[i]) == 0)
            return true;
    return false;
}

/* s for a message: its first 40 bytes, control characters (a folded scalar's line breaks)
 * as '?', "..." when cut: a message stays one line whatever the file holds. */
static const char *printable(const char *s, char *buf, size_t cap)
{
    size_t i, n = 0;
    for (i = 0; s[i] != '\0' && i < 40u && n + 4u < cap; i++)
        buf[n++] = ((unsigned char)s[i] < 0x20u || s[i] == 0x7F) ? '?' : s[i];
    if (s[i] != '\0' && n + 4u <= cap) {
        memcpy(buf + n, "...", 3);
        n += 3u;
    }
    buf[n] = '\0';
    return buf;
}

/* What a node is, for "expected X, got Y". */
static const char *describe(const yaml_node_t *n, char *buf, size_t cap)
{
    char text[48];
    if (n->type == YAML_MAPPING_NODE)
        return "a mapping";
    if (n->type == YAML_SEQUENCE_NODE)
        return "a list";
    if (is_null(n))
        return "nothing";
    (void)snprintf(buf, cap, "%s'%s'",
                   n->data.scalar.style != YAML_PLAIN_SCALAR_STYLE ? "the quoted text " : "",
                   printable(scalar(n), text, sizeof text));
    return buf;
}

static int expected(ctx_t *x, const yaml_node_t *v, const char *key, const char *what)
{
    char buf[64];
    return fail(x, line_of(v), "%s: expected %s, got %s", key, what, describe(v, buf, sizeof buf));
}

static bool plain_scalar(const yaml_node_t *v)
{
    return v->type == YAML_SCALAR_NODE && v->data.scalar.style == YAML_PLAIN_SCALAR_STYLE;
}

/* A number in the syntax the tool's options take too (j288_number.h): decimal, no "inf",
 * "nan" or hexadecimal. */
static int get_number(ctx_t *x, const yaml_node_t *v, const char *key, double *out)
{
    j288_number_result_t rc = plain_scalar(v) ? j288_number_real(scalar(v), out)
                                              : J288_NUMBER_SYNTAX;
    if (rc == J288_NUMBER_SYNTAX)
        return expected(x, v, key, "a number");
    if (rc == J288_NUMBER_RANGE)
        return fail(x, line_of(v), "%s: %s is out of range", key, scalar(v));
    return 0;
}

/* A whole number (decimal or 0x hexadecimal, as on the command line) in [lo, hi]. */
static int get_long(ctx_t *x, const yaml_node_t *v, const char *key, long lo, long hi, long *out)
{
    char what[64];
    long long n = 0;
    j288_number_result_t rc = plain_scalar(v) ? j288_number_int(scalar(v), &n)
                                              : J288_NUMBER_SYNTAX;
    (void)snprintf(what, sizeof what, "an integer %ld-%ld", lo, hi);
    if (rc == J288_NUMBER_SYNTAX)
        return expected(x, v, key, what);
    if (rc == J288_NUMBER_RANGE || n < lo || n > hi)
        return fail(x, line_of(v), "%s: %s is out of range (%ld-%ld)", key, scalar(v), lo, hi);
    *out = (long)n;
    return 0;
}

static int get_bool(ctx_t *x, const yaml_node_t *v, const char *key, bool *out)
{
    static const char *const yes[] = {"true", "True", "TRUE"};
    static const char *const no[] = {"false", "False", "FALSE"};
    size_t i;
    if (plain_scalar(v)) {
        for (i = 0; i < 3u; i++) {
            if (strcmp(scalar(v), yes[i]) == 0) {
                *out = true;
                return 0;
            }
            if (strcmp(scalar(v), no[i]) == 0) {
                *out = false;
                return 0;
            }
        }
    }
    return expected(x, v, key, "true or false");
}

/* Text into buf (cap bytes): a scalar, not empty, no control characters; a name also has no
 * blanks (it is typed on command lines). */
static int get_text(ctx_t *x, const yaml_node_t *v, const char *key, bool is_name, char *buf,
                    size_t cap)
{
    char shown[48];
    size_t i, n;
    if (v->type != YAML_SCALAR_NODE || is_null(v))
        return expected(x, v, key, is_name ? "a name" : "text");
    n = v->data.scalar.length;
    if (n == 0u) /* quoted "" is not null to YAML, but a port or name it cannot be */
        return expected(x, v, key, is_name ? "a name" : "text");
    if (n >= cap)
        return fail(x, line_of(v), "%s: longer than %zu bytes", key, cap - 1u);
    for (i = 0; i < n; i++) {
        unsigned char ch = v->data.scalar.value[i];
        if (ch < 0x20u || ch == 0x7Fu || (is_name && ch == ' '))
            return fail(x, line_of(v), "%s: '%s' has a %s", key,
                        printable(scalar(v), shown, sizeof shown),
                        ch == ' ' ? "blank" : "control character");
    }
    memcpy(buf, v->data.scalar.value, n);
    buf[n] = '\0';
    return 0;
}

/* The mapping's pairs, keys checked against the allowed list and for repeats. */
static int check_keys(ctx_t *x, const yaml_node_t *m, const char *const *allowed, size_t nallowed,
                      const char *allowed_text)
{
    char shown[48];
    yaml_node_pair_t *p, *q;
    for (p = m->data.mapping.pairs.start; p < m->data.mapping.pairs.top; p++) {
        yaml_node_t *k = node_at(x, p->key);
        size_t i;
        bool known = false;
        if (k->type != YAML_SCALAR_NODE)
            return fail(x, line_of(k), "a key must be a name, got %s",
                        k->type == YAML_MAPPING_NODE ? "a mapping" : "a list");
        for (i = 0; i < nallowed; i++)
            known = known || strcmp(scalar(k), allowed[i]) == 0;
        if (!known)
            return fail(x, line_of(k), "unknown key '%s' (known: %s)",
                        printable(scalar(k), shown, sizeof shown), allowed_text);
        for (q = m->data.mapping.pairs.start; q < p; q++)
            if (strcmp(scalar(node_at(x, q->key)), scalar(k)) == 0)
                return fail(x, line_of(k), "'%s' given twice (first on line %zu)",
                            printable(scalar(k), shown, sizeof shown),
                            line_of(node_at(x, q->key)));
    }
    return 0;
}

/* The value of key in mapping m, or NULL (keys are checked first: no repeats). */
static yaml_node_t *value_of(ctx_t *x, const yaml_node_t *m, const char *key)
{
    yaml_node_pair_t *p;
    for (p = m->data.mapping.pairs.start; p < m->data.mapping.pairs.top; p++)
        if (strcmp(scalar(node_at(x, p->key)), key) == 0)
            return node_at(x, p->value);
    return NULL;
}

/* The entry's name for messages before its keys are checked (a typo in another key is then
 * reported against the joint's name), when it is there and plain text. */
static const char *peek_name(ctx_t *x, const yaml_node_t *m)
{
    yaml_node_pair_t *p;
    for (p = m->data.mapping.pairs.start; p < m->data.mapping.pairs.top; p++) {
        yaml_node_t *k = node_at(x, p->key);
        yaml_node_t *v = node_at(x, p->value);
        size_t i, n;
        if (k->type != YAML_SCALAR_NODE || strcmp(scalar(k), "name") != 0 ||
            v->type != YAML_SCALAR_NODE || v->data.scalar.length >= J288_ROBOT_CONFIG_NAME_MAX)
            continue;
        for (i = 0, n = v->data.scalar.length; i < n; i++)
            if (v->data.scalar.value[i] < 0x20u || v->data.scalar.value[i] == 0x7Fu)
                return NULL; /* get_text() will say what is wrong with it */
        return scalar(v);
    }
    return NULL;
}

static void set_label(ctx_t *x, const char *kind, const char *name, size_t index)
{
    if (name != NULL && name[0] != '\0')
        (void)snprintf(x->label, sizeof x->label, "%s '%s': ", kind, name);
    else
        (void)snprintf(x->label, sizeof x->label, "%s %zu: ", kind, index + 1u);
}

static const char *const bus_keys[] = {"name", "port", "baud", "margin_us", "echo"};
static const char *const joint_keys[] = {"name", "bus",    "id",        "direction",
                                         "zero", "limits", "max_speed", "max_torque",
                                         "kp",   "kd",     "phase",     "clamp"};
#define JOINT_KEYS_TEXT                                                                            \
    "name, bus, id, direction, zero, limits, max_speed, max_torque, kp, kd, phase, clamp"

/* What a bus and a joint entry have in common. */
typedef struct {
    const char *kind; /* in messages: "bus", "joint" */
    const char *list; /* the key of their list */
    const char *const *keys;
    size_t nkeys;
    const char *keys_text;
} entry_kind_t;

static const entry_kind_t k_bus = {"bus", "buses", bus_keys, sizeof bus_keys / sizeof bus_keys[0],
                                   "name, port, baud, margin_us, echo"};
static const entry_kind_t k_joint = {"joint", "joints", joint_keys,
                                     sizeof joint_keys / sizeof joint_keys[0], JOINT_KEYS_TEXT};

/* Entry i of its list: a mapping of known keys with a name, copied into name
 * (J288_ROBOT_CONFIG_NAME_MAX bytes); messages from here on name it. The name's node, or NULL. */
static yaml_node_t *entry_name(ctx_t *x, yaml_node_t *m, size_t i, const entry_kind_t *k,
                               char *name)
{
    char what[64];
    yaml_node_t *v;
    set_label(x, k->kind, NULL, i);
    (void)snprintf(what, sizeof what, "a mapping per %s (- name: ...)", k->kind);
    if (m->type != YAML_MAPPING_NODE) {
        (void)expected(x, m, k->list, what);
        return NULL;
    }
    set_label(x, k->kind, peek_name(x, m), i);
    if (check_keys(x, m, k->keys, k->nkeys, k->keys_text) != 0)
        return NULL;
    if ((v = value_of(x, m, "name")) == NULL) {
        (void)fail(x, line_of(m), "'name' is missing");
        return NULL;
    }
    if (get_text(x, v, "name", true, name, J288_ROBOT_CONFIG_NAME_MAX) != 0)
        return NULL;
    set_label(x, k->kind, name, i);
    return v;
}

static int parse_bus(ctx_t *x, yaml_node_t *m, size_t i)
{
    j288_robot_config_bus_t *b = &x->cfg->bus[i];
    yaml_node_t *v;
    long n;
    size_t j;
    memset(b, 0, sizeof *b);
    b->line = (unsigned)line_of(m);
    if ((v = entry_name(x, m, i, &k_bus, b->name)) == NULL)
        return -1;
    for (j = 0; j < i; j++)
        if (strcmp(x->cfg->bus[j].name, b->name) == 0)
            return fail(x, line_of(v), "name: already used by the bus on line %u",
                        x->cfg->bus[j].line);
    if ((v = value_of(x, m, "port")) == NULL)
        return fail(x, line_of(m), "'port' is missing");
    if (get_text(x, v, "port", false, b->port, sizeof b->port) != 0)
        return -1;
    for (j = 0; j < i; j++)
        if (strcmp(x->cfg->bus[j].port, b->port) == 0)
            return fail(x, line_of(v), "port: %s is already bus '%s' (line %u)", b->port,
                        x->cfg->bus[j].name, x->cfg->bus[j].line);
    if ((v = value_of(x, m, "baud")) != NULL) {
        if (get_long(x, v, "baud", (long)j288_range(J288_QTY_BAUD)->lo,
                     (long)j288_range(J288_QTY_BAUD)->hi, &n) != 0)
            return -1;
        b->has_baud = true;
        b->baud = (uint32_t)n;
    }
    if ((v = value_of(x, m, "margin_us")) != NULL) {
        if (get_long(x, v, "margin_us", (long)j288_range(J288_QTY_MARGIN_US)->lo,
                     (long)j288_range(J288_QTY_MARGIN_US)->hi, &n) != 0)
            return -1;
        b->has_margin_us = true;
        b->margin_us = (uint32_t)n;
    }
    if ((v = value_of(x, m, "echo")) != NULL) {
        if (get_bool(x, v, "echo", &b->echo) != 0)
            return -1;
        b->has_echo = true;
    }
    return 0;
}

/* Where a number may lie: [lo, hi], lo itself excluded when lo_open. */
typedef struct {
    double lo, hi;
    bool lo_open;
} range_t;

/* The library's own bounds (j288_joint_init()), so that what the file takes the runner's
 * joints take too: angles within J288_JOINT_MAX_ANGLE, the phase within 2 pi, speeds and
 * torques up to 1e30 (beyond that a float build would hold infinities). The gains have the
 * command line's range (shared_range()): the wire's. */
#define GAIN_MAX 1e30
static const range_t k_angle = {-J288_JOINT_MAX_ANGLE, J288_JOINT_MAX_ANGLE, false};
static const range_t k_phase = {-TWO_PI, TWO_PI, false};
static const range_t k_above_0 = {0.0, GAIN_MAX, true};

/* The range of quantity q (j288_range.h: the command line's too). */
static range_t shared_range(j288_quantity_t q)
{
    range_t r;
    r.lo = j288_range(q)->lo;
    r.hi = j288_range(q)->hi;
    r.lo_open = false;
    return r;
}

/* v's number d within r, else an error naming key, the value as written and the range. */
static int check_range(ctx_t *x, const yaml_node_t *v, const char *key, double d, const range_t *r)
{
    if (r->lo == 0.0 && (r->lo_open ? !(d > 0.0) : !(d >= 0.0)))
        return fail(x, line_of(v), "%s: %s must be %s", key, scalar(v),
                    r->lo_open ? "above 0" : "0 or more");
    if (d < r->lo || d > r->hi)
        return fail(x, line_of(v), "%s: %s is out of range (%.10g to %.10g)", key, scalar(v),
                    r->lo, r->hi);
    return 0;
}

static int get_limits(ctx_t *x, const yaml_node_t *v, j288_robot_config_joint_t *jt)
{
    yaml_node_t *lo, *hi;
    if (v->type != YAML_SEQUENCE_NODE ||
        v->data.sequence.items.top - v->data.sequence.items.start != 2)
        return expected(x, v, "limits", "two numbers [min, max]");
    lo = node_at(x, v->data.sequence.items.start[0]);
    hi = node_at(x, v->data.sequence.items.start[1]);
    if (get_number(x, lo, "limits", &jt->pos_min) != 0 ||
        check_range(x, lo, "limits", jt->pos_min, &k_angle) != 0 ||
        get_number(x, hi, "limits", &jt->pos_max) != 0 ||
        check_range(x, hi, "limits", jt->pos_max, &k_angle) != 0)
        return -1;
    if (!(jt->pos_min < jt->pos_max))
        return fail(x, line_of(v), "limits: [%s, %s] are reversed or empty: [min, max]", scalar(lo),
                    scalar(hi));
    /* Wider than a turn, the output encoder could not tell the ends apart (1e-9: a bound
     * written as +-3.141592653589793 must pass). */
    if (jt->pos_max - jt->pos_min > TWO_PI + 1e-9)
        return fail(x, line_of(v), "limits: [%s, %s] span %.6f rad, more than 2 pi (%.9f)",
                    scalar(lo), scalar(hi), jt->pos_max - jt->pos_min, TWO_PI);
    jt->has_limits = true;
    return 0;
}

/* key's number in mapping m into *out, when it is there (then *has, if given, is set). */
static int opt_number(ctx_t *x, const yaml_node_t *m, const char *key, const range_t *r,
                      bool *has, double *out)
{
    yaml_node_t *v = value_of(x, m, key);
    if (v == NULL)
        return 0;
    if (get_number(x, v, key, out) != 0 || check_range(x, v, key, *out, r) != 0)
        return -1;
    if (has != NULL)
        *has = true;
    return 0;
}

/* The optional numbers of a joint. */
static int parse_joint_numbers(ctx_t *x, const yaml_node_t *m, j288_robot_config_joint_t *jt)
{
    yaml_node_t *v;
    range_t kp = shared_range(J288_QTY_KP), kd = shared_range(J288_QTY_KD);
    if ((v = value_of(x, m, "limits")) != NULL && get_limits(x, v, jt) != 0)
        return -1;
    if (opt_number(x, m, "zero", &k_angle, NULL, &jt->zero) != 0 ||
        opt_number(x, m, "max_speed", &k_above_0, &jt->has_max_speed, &jt->max_speed) != 0 ||
        opt_number(x, m, "max_torque", &k_above_0, &jt->has_max_torque, &jt->max_torque) != 0 ||
        opt_number(x, m, "kp", &kp, &jt->has_kp, &jt->kp) != 0 ||
        opt_number(x, m, "kd", &kd, &jt->has_kd, &jt->kd) != 0 ||
        opt_number(x, m, "phase", &k_phase, &jt->has_phase, &jt->phase) != 0)
        return -1;
    return 0;
}

static int parse_joint(ctx_t *x, yaml_node_t *m, size_t i)
{
    j288_robot_config_joint_t *jt = &x->cfg->joint[i];
    yaml_node_t *v;
    long n;
    size_t j;
    memset(jt, 0, sizeof *jt);
    jt->line = (unsigned)line_of(m);
    jt->bus = J288_ROBOT_CONFIG_NO_BUS;
    jt->direction = 1;
    jt->pos_min = -PI;
    jt->pos_max = PI;
    x->joint_node[i] = m;
    x->joint_bus[i] = NULL;
    if ((v = entry_name(x, m, i, &k_joint, jt->name)) == NULL)
        return -1;
    for (j = 0; j < i; j++)
        if (strcmp(x->cfg->joint[j].name, jt->name) == 0)
            return fail(x, line_of(v), "name: already used by the joint on line %u",
                        x->cfg->joint[j].line);
    if ((v = value_of(x, m, "id")) == NULL)
        return fail(x, line_of(m), "'id' is missing");
    if (v->type == YAML_SCALAR_NODE && strcmp(scalar(v), "15") == 0)
        return fail(x, line_of(v), "id: 15 is the broadcast address; servo ids are 0-14");
    if (get_long(x, v, "id", 0, 14, &n) != 0)
        return -1;
    jt->id = (uint8_t)n;
    if ((v = value_of(x, m, "direction")) != NULL) {
        long long d = 0;
        if (!plain_scalar(v) || j288_number_int(scalar(v), &d) != J288_NUMBER_OK ||
            (d != 1 && d != -1))
            return expected(x, v, "direction", "1 or -1");
        jt->direction = (int)d;
    }
    x->joint_bus[i] = value_of(x, m, "bus");
    if ((v = value_of(x, m, "clamp")) != NULL && get_bool(x, v, "clamp", &jt->clamp) != 0)
        return -1;
    return parse_joint_numbers(x, m, jt);
}

/* After every bus and joint is read: each joint's bus, and ids unique per bus. */
static int resolve_joints(ctx_t *x)
{
    j288_robot_config_t *cfg = x->cfg;
    size_t i, j;
    for (i = 0; i < cfg->njoints; i++) {
        j288_robot_config_joint_t *jt = &cfg->joint[i];
        yaml_node_t *v = x->joint_bus[i];
        char name[J288_ROBOT_CONFIG_NAME_MAX];
        set_label(x, "joint", jt->name, i);
        if (v == NULL) {
            if (cfg->nbuses > 1u)
                return fail(x, jt->line, "'bus' is missing (the file has %zu buses)", cfg->nbuses);
            jt->bus = (cfg->nbuses == 1u) ? 0 : J288_ROBOT_CONFIG_NO_BUS;
        } else {
            if (get_text(x, v, "bus", true, name, sizeof name) != 0)
                return -1;
            jt->bus = j288_robot_config_find_bus(cfg, name);
            if (jt->bus < 0)
                return fail(x, line_of(v), "bus: no bus is named '%s'%s", name,
                            cfg->nbuses == 0u ? " (the file has no 'buses:')" : "");
        }
        for (j = 0; j < i; j++) {
            char on_bus[J288_ROBOT_CONFIG_NAME_MAX + 16] = "";
            if (cfg->joint[j].bus != jt->bus || cfg->joint[j].id != jt->id)
                continue;
            if (jt->bus >= 0)
                (void)snprintf(on_bus, sizeof on_bus, " on bus '%s'", cfg->bus[jt->bus].name);
            return fail(x, line_of(value_of(x, x->joint_node[i], "id")),
                        "id: %u is already joint '%s' (line %u)%s", (unsigned)jt->id,
                        cfg->joint[j].name, cfg->joint[j].line, on_bus);
        }
    }
    x->label[0] = '\0';
    return 0;
}

/* buses: or joints: - a list (or nothing) of at most max entries; parse each with fn. */
static int parse_list(ctx_t *x, yaml_node_t *v, const entry_kind_t *k, size_t max, size_t *count,
                      int (*fn)(ctx_t *, yaml_node_t *, size_t))
{
    yaml_node_item_t *it;
    *count = 0;
    if (v == NULL || is_null(v))
        return 0;
    if (v->type != YAML_SEQUENCE_NODE)
        return expected(x, v, k->list, "a list (- name: ...)");
    for (it = v->data.sequence.items.start; it < v->data.sequence.items.top; it++) {
        yaml_node_t *e = node_at(x, *it);
        if (*count == max) { /* named as the entry one too many, not as the last one read */
            set_label(x, k->kind, e->type == YAML_MAPPING_NODE ? peek_name(x, e) : NULL, *count);
            return fail(x, line_of(e), "%s: more than %zu", k->list, max);
        }
        if (fn(x, e, *count) != 0)
            return -1;
        (*count)++;
    }
    return 0;
}

static int parse_root(ctx_t *x)
{
    static const char *const top_keys[] = {"buses", "joints"};
    yaml_node_t *root = yaml_document_get_root_node(&x->doc);
    yaml_node_pair_t *p;
    memset(x->cfg, 0, sizeof *x->cfg);
    x->label[0] = '\0';
    if (root == NULL || is_null(root))
        return fail(x, 1, "the file is empty: expected 'joints:' (and 'buses:')");
    if (root->type != YAML_MAPPING_NODE)
        return expected(x, root, "the file", "a mapping with 'buses:' and 'joints:'");
    if (check_keys(x, root, top_keys, 2, "buses, joints") != 0)
        return -1;
    if (parse_list(x, value_of(x, root, "buses"), &k_bus, J288_ROBOT_CONFIG_MAX_BUSES,
                   &x->cfg->nbuses, parse_bus) != 0)
        return -1;
    x->label[0] = '\0';
    if (parse_list(x, value_of(x, root, "joints"), &k_joint, J288_ROBOT_CONFIG_MAX_JOINTS,
                   &x->cfg->njoints, parse_joint) != 0)
        return -1;
    for (p = root->data.mapping.pairs.start; p < root->data.mapping.pairs.top; p++)
        if (strcmp(scalar(node_at(x, p->key)), "joints") == 0)
            x->joints_line = line_of(node_at(x, p->key));
    return resolve_joints(x);
}

/* Byte offset of libyaml's mark index: libyaml counts characters (code points; CR LF is
 * two), the text is UTF-8 (libyaml has checked it). */
static size_t byte_offset(const ctx_t *x, size_t index)
{
    size_t off = 0, chars = 0;
    while (off < x->len && chars < index) {
        off++;
        while (off < x->len && (x->text[off] & 0xC0u) == 0x80u)
            off++;
        chars++;
    }
    return off;
}

/* The line (1-based) a byte offset is on, for errors libyaml gives as an offset. */
static size_t line_at(const ctx_t *x, size_t off)
{
    size_t i, line = 1;
    for (i = 0; i < off && i < x->len; i++)
        if (x->text[i] == '\n')
            line++;
    return line;
}

static int syntax_error(ctx_t *x, const yaml_parser_t *p)
{
    const char *problem = (p->problem != NULL) ? p->problem : "unreadable";
    char context[96] = "";
    size_t off;
    x->label[0] = '\0';
    if (p->error == YAML_READER_ERROR)
        return fail(x, line_at(x, p->problem_offset), "not UTF-8 text: %s", problem);
    if (p->error == YAML_MEMORY_ERROR)
        return fail(x, 1, "out of memory");
    if (p->context != NULL && p->context_mark.line != p->problem_mark.line)
        (void)snprintf(context, sizeof context, " (%s that starts on line %zu)", p->context,
                       p->context_mark.line + 1u);
    else if (p->context != NULL)
        (void)snprintf(context, sizeof context, " (%s)", p->context);
    off = byte_offset(x, p->problem_mark.index);
    return fail(x, p->problem_mark.line + 1u, "syntax error at column %zu: %s%s%s",
                p->problem_mark.column + 1u, problem, context,
                (off < x->len && x->text[off] == '\t') ? "; YAML indents with spaces, not tabs"
                                                       : "");
}

static void parser_setup(ctx_t *x, yaml_parser_t *p)
{
    (void)yaml_parser_initialize(p);
    yaml_parser_set_encoding(p, YAML_UTF8_ENCODING);
    yaml_parser_set_input_string(p, x->text, x->len);
}

/* An event's explicit tag (!!str, !foo), or NULL: libyaml gives none for untagged values. */
static const char *event_tag(const yaml_event_t *e)
{
    const yaml_char_t *tag = NULL;
    if (e->type == YAML_SCALAR_EVENT)
        tag = e->data.scalar.tag;
    else if (e->type == YAML_SEQUENCE_START_EVENT)
        tag = e->data.sequence_start.tag;
    else if (e->type == YAML_MAPPING_START_EVENT)
        tag = e->data.mapping_start.tag;
    return (const char *)tag;
}

/* One event's verdict: an alias, a tag, a second document, nesting beyond the bound. */
static int check_event(ctx_t *x, const yaml_event_t *e, int *docs, unsigned *depth)
{
    static const char yaml_prefix[] = "tag:yaml.org,2002:"; /* what libyaml makes of "!!" */
    const char *tag = event_tag(e);
    char shown[48];
    size_t line = e->start_mark.line + 1u;
    if (e->type == YAML_ALIAS_EVENT)
        return fail(x, line, "aliases (*%s) are not supported: write the value out",
                    (const char *)e->data.alias.anchor);
    if (e->type == YAML_DOCUMENT_START_EVENT && ++*docs > 1)
        return fail(x, line, "a second YAML document: one per file");
    /* Each key has one type, checked as written: a tag would either repeat it or ask for
     * another (id: !!str 1), and ignoring it would silently read what the tag contradicts. */
    if (tag != NULL) {
        bool core = strncmp(tag, yaml_prefix, sizeof yaml_prefix - 1u) == 0;
        return fail(x, line, "YAML tags (%s%s) are not supported: write the value alone",
                    core ? "!!" : "",
                    printable(core ? tag + sizeof yaml_prefix - 1u : tag, shown, sizeof shown));
    }
    if (e->type == YAML_SEQUENCE_START_EVENT || e->type == YAML_MAPPING_START_EVENT) {
        if (++*depth > J288_ROBOT_CONFIG_MAX_DEPTH)
            return fail(x, line, "nested deeper than %u lists and mappings: not a robot config",
                        J288_ROBOT_CONFIG_MAX_DEPTH);
    } else if (e->type == YAML_SEQUENCE_END_EVENT || e->type == YAML_MAPPING_END_EVENT) {
        --*depth;
    }
    return 0;
}

/* A pass over the events, before libyaml builds the document: syntax errors and what
 * check_event() refuses. It stops at the first refusal: libyaml's time grows with the square
 * of the nesting depth (200 KB of '[' took minutes), so a file nested too deep is refused
 * as soon as the bound is crossed, before the rest is read. */
static int scan_events(ctx_t *x)
{
    yaml_parser_t p;
    yaml_event_t e;
    int docs = 0, rc = 0;
    unsigned depth = 0;
    parser_setup(x, &p);
    for (;;) {
        bool end;
        if (!yaml_parser_parse(&p, &e)) {
            rc = syntax_error(x, &p);
            break;
        }
        end = (e.type == YAML_STREAM_END_EVENT);
        rc = check_event(x, &e, &docs, &depth);
        yaml_event_delete(&e);
        if (end || rc != 0)
            break;
    }
    yaml_parser_delete(&p);
    return rc;
}

static void ctx_done(ctx_t *x)
{
    if (x->have_doc)
        yaml_document_delete(&x->doc);
    x->have_doc = false;
}

/* Parse text into x->cfg, keeping the document for an edit (ctx_done() frees it). */
static int ctx_parse(ctx_t *x, const char *text, size_t len, const char *name, j288_robot_config_t *cfg,
                     char *err, size_t errlen)
{
    yaml_parser_t p;
    memset(x, 0, sizeof *x);
    x->name = name;
    x->text = (const unsigned char *)text;
    x->len = len;
    x->cfg = cfg;
    x->err = err;
    x->errlen = errlen;
    /* A byte order mark is not content; marks then count from after it. */
    if (len >= 3u && memcmp(text, "\xEF\xBB\xBF", 3) == 0) {
        x->text += 3;
        x->len -= 3u;
    }
    if (scan_events(x) != 0)
        return -1;
    parser_setup(x, &p);
    if (!yaml_parser_load(&p, &x->doc)) {
        int rc = syntax_error(x, &p);
        yaml_parser_delete(&p);
        return rc;
    }
    yaml_parser_delete(&p);
    x->have_doc = true;
    if (parse_root(x) != 0) {
        ctx_done(x);
        return -1;
    }
    return 0;
}

int j288_robot_config_parse(const char *text, size_t len, const char *name, j288_robot_config_t *cfg, char *err,
                      size_t errlen)
{
    ctx_t x;
    if (ctx_parse(&x, text, len, name, cfg, err, errlen) != 0)
        return -1;
    ctx_done(&x);
    return 0;
}

/* ---- writing back ------------------------------------------------------------------------- */

/* v as the file shows it: fixed point, nine decimals (nanoradians), trailing zeros dropped but
 * one kept after the point, so that every YAML reader takes it for a float. */
static void format_value(double v, char *buf, size_t cap)
{
    size_t n;
    if (v == 0.0)
        v = 0.0; /* no "-0.0" */
    (void)snprintf(buf, cap, "%.9f", v);
    n = strlen(buf);
    while (n > 2u && buf[n - 1u] == '0' && buf[n - 2u] != '.')
        buf[--n] = '\0';
    if (strcmp(buf, "-0.0") == 0) /* a tiny negative value */
        memmove(buf, buf + 1, 4);
}

/* The last character index the mapping's content reaches: the end of its last scalar or
 * flow collection (a block collection's end mark lies at the next token, past comments). */
static size_t content_end(ctx_t *x, const yaml_node_t *n)
{
    size_t end = 0;
    if (n->type == YAML_SCALAR_NODE)
        return n->end_mark.index;
    if (n->type == YAML_MAPPING_NODE) {
        yaml_node_pair_t *p;
        if (n->data.mapping.style == YAML_FLOW_MAPPING_STYLE)
            return n->end_mark.index;
        for (p = n->data.mapping.pairs.start; p < n->data.mapping.pairs.top; p++) {
            size_t e = content_end(x, node_at(x, p->value));
            size_t k = content_end(x, node_at(x, p->key));
            end = (e > end) ? e : end;
            end = (k > end) ? k : end;
        }
        return end;
    }
    if (n->data.sequence.style == YAML_FLOW_SEQUENCE_STYLE)
        return n->end_mark.index;
    {
        yaml_node_item_t *it;
        for (it = n->data.sequence.items.start; it < n->data.sequence.items.top; it++) {
            size_t e = content_end(x, node_at(x, *it));
            end = (e > end) ? e : end;
        }
    }
    return end;
}

/* The file's line ending: that of its first line, "\n" when it has none. */
static const char *line_ending(const ctx_t *x)
{
    const unsigned char *nl = memchr(x->text, '\n', x->len);
    return (nl != NULL && nl > x->text && nl[-1] == '\r') ? "\r\n" : "\n";
}

/* One change to the text: bytes [off, end) become repl. */
typedef struct {
    size_t off, end;
    char repl[160];
} edit_t;

/* The edit that gives key the value text in joint mapping m. */
static int plan_edit(ctx_t *x, yaml_node_t *m, const char *key, const char *value, edit_t *ed)
{
    yaml_node_t *v = value_of(x, m, key);
    yaml_node_t *first;
    const char *eol = line_ending(x);
    size_t at, indent;
    if (v != NULL) {
        /* Numbers are plain scalars on one line (the reader checked): the text between the
         * marks is the value itself; check it all the same before changing a byte. */
        ed->off = byte_offset(x, v->start_mark.index);
        ed->end = byte_offset(x, v->end_mark.index);
        if (ed->end < ed->off || ed->end - ed->off != v->data.scalar.length ||
            memcmp(x->text + ed->off, v->data.scalar.value, v->data.scalar.length) != 0)
            return fail(x, line_of(v), "%s: cannot find the value's text to replace it", key);
        (void)snprintf(ed->repl, sizeof ed->repl, "%s", value);
        return 0;
    }
    if (m->data.mapping.style == YAML_FLOW_MAPPING_STYLE)
        return fail(x, line_of(m),
                    "is written as a flow mapping ({...}): its '%s' can be replaced, not added; "
                    "add '%s: 0.0' to it by hand, or write the joint as a block mapping",
                    key, key);
    /* A new line after the mapping's last content line, indented as its first key. */
    first = node_at(x, m->data.mapping.pairs.start->key);
    indent = first->start_mark.column;
    if (indent > 100u)
        return fail(x, line_of(m), "indented by more than 100 columns: add '%s:' by hand", key);
    at = byte_offset(x, content_end(x, m));
    if (at > 0u && x->text[at - 1u] != '\n') {
        const unsigned char *nl = memchr(x->text + at, '\n', x->len - at);
        at = (nl != NULL) ? (size_t)(nl - x->text) + 1u : x->len;
    }
    ed->off = at;
    ed->end = at;
    if (at == x->len && at > 0u && x->text[at - 1u] != '\n') /* last line, no line ending */
        (void)snprintf(ed->repl, sizeof ed->repl, "%s%*s%s: %s", eol, (int)indent, "", key, value);
    else
        (void)snprintf(ed->repl, sizeof ed->repl, "%*s%s: %s%s", (int)indent, "", key, value, eol);
    return 0;
}

static bool same_bus(const j288_robot_config_bus_t *a, const j288_robot_config_bus_t *b)
{
    return strcmp(a->name, b->name) == 0 && strcmp(a->port, b->port) == 0 &&
           a->has_baud == b->has_baud && a->baud == b->baud &&
           a->has_margin_us == b->has_margin_us && a->margin_us == b->margin_us &&
           a->has_echo == b->has_echo && a->echo == b->echo;
}

/* Equal but for the line and, when skip_zero / skip_phase, those values. */
static bool same_joint(const j288_robot_config_joint_t *a, const j288_robot_config_joint_t *b, bool skip_zero,
                       bool skip_phase)
{
    return strcmp(a->name, b->name) == 0 && a->bus == b->bus && a->id == b->id &&
           a->direction == b->direction && (skip_zero || a->zero == b->zero) &&
           a->has_limits == b->has_limits && a->pos_min == b->pos_min && a->pos_max == b->pos_max &&
           a->has_max_speed == b->has_max_speed && a->max_speed == b->max_speed &&
           a->has_max_torque == b->has_max_torque && a->max_torque == b->max_torque &&
           a->has_kp == b->has_kp && a->kp == b->kp && a->has_kd == b->has_kd && a->kd == b->kd &&
           (skip_phase || (a->has_phase == b->has_phase && a->phase == b->phase)) &&
           a->clamp == b->clamp;
}

/* The edited text must read as the old one with only the new values changed. */
static int check_edit(const j288_robot_config_t *before, const j288_robot_config_t *after, size_t ji,
                      const j288_robot_config_update_t *upd, const char *name, char *err, size_t errlen)
{
    const j288_robot_config_joint_t *jt = &after->joint[ji];
    size_t i;
    bool same = before->nbuses == after->nbuses && before->njoints == after->njoints;
    for (i = 0; same && i < before->nbuses; i++)
        same = same_bus(&before->bus[i], &after->bus[i]);
    for (i = 0; same && i < before->njoints; i++)
        same = same_joint(&before->joint[i], &after->joint[i], i == ji && upd->set_zero,
                          i == ji && upd->set_phase);
    /* The text holds nine decimals: the value read back is within 5e-10 of the one asked. */
    if (same && upd->set_zero)
        same = fabs(jt->zero - upd->zero) <= 1e-9;
    if (same && upd->set_phase)
        same = jt->has_phase && fabs(jt->phase - upd->phase) <= 1e-9;
    if (!same)
        return set_error(err, errlen, "%s: the edit would not read back as intended; not written",
                         name);
    return 0;
}

static int check_update(const j288_robot_config_update_t *upd, const char *name, char *err, size_t errlen)
{
    if (!upd->set_zero && !upd->set_phase)
        return set_error(err, errlen, "%s: nothing to change (neither zero nor phase)", name);
    /* The bounds the file is read with (a value written must read back). */
    if (upd->set_zero && !(fabs(upd->zero) <= k_angle.hi))
        return set_error(err, errlen, "%s: zero %g is not a finite value within +-%g", name,
                         upd->zero, k_angle.hi);
    if (upd->set_phase && !(fabs(upd->phase) <= k_phase.hi))
        return set_error(err, errlen, "%s: phase %g is not a finite value within +-%.9g", name,
                         upd->phase, k_phase.hi);
    return 0;
}

/* Apply up to two edits (sorted by offset; equal offsets keep their order) into out. */
static int apply_edits(const ctx_t *x, edit_t *ed, size_t n, char *out, size_t outcap,
                       size_t *outlen)
{
    size_t i, pos = 0, w = 0;
    if (n == 2u && ed[1].off < ed[0].off) {
        edit_t t = ed[0];
        ed[0] = ed[1];
        ed[1] = t;
    }
    for (i = 0; i <= n; i++) {
        size_t upto = (i < n) ? ed[i].off : x->len;
        size_t r = (i < n) ? strlen(ed[i].repl) : 0u;
        if (w + (upto - pos) + r > outcap)
            return -1;
        memcpy(out + w, x->text + pos, upto - pos);
        w += upto - pos;
        if (i < n) {
            memcpy(out + w, ed[i].repl, r);
            w += r;
            pos = ed[i].end;
        }
    }
    *outlen = w;
    return 0;
}

/* The edit, with the configurations before and after in caller-given (heap) space. */
static int edit_text(const char *text, size_t len, const char *name, const char *joint,
                     const j288_robot_config_update_t *upd, char *out, size_t outcap, size_t *outlen,
                     j288_robot_config_t *before, j288_robot_config_t *after, char *err, size_t errlen)
{
    ctx_t x;
    edit_t ed[2];
    size_t n = 0, ji, bom;
    char value[64];
    int rc = 0;
    if (check_update(upd, name, err, errlen) != 0 ||
        ctx_parse(&x, text, len, name, before, err, errlen) != 0)
        return -1;
    for (ji = 0; ji < before->njoints && strcmp(before->joint[ji].name, joint) != 0; ji++)
        ;
    if (ji == before->njoints)
        rc = fail(&x, x.joints_line ? x.joints_line : 1u, "no joint is named '%s'", joint);
    set_label(&x, "joint", joint, ji);
    if (rc == 0 && upd->set_zero) {
        format_value(upd->zero, value, sizeof value);
        rc = plan_edit(&x, x.joint_node[ji], "zero", value, &ed[n++]);
    }
    if (rc == 0 && upd->set_phase) {
        format_value(upd->phase, value, sizeof value);
        rc = plan_edit(&x, x.joint_node[ji], "phase", value, &ed[n++]);
    }
    /* Offsets count from after a byte order mark; the output keeps it. */
    bom = (size_t)(x.text - (const unsigned char *)text);
    if (rc == 0 && bom > outcap)
        rc = set_error(err, errlen, "%s: output buffer too small", name);
    if (rc == 0) {
        memcpy(out, text, bom);
        if (apply_edits(&x, ed, n, out + bom, outcap - bom, outlen) != 0)
            rc = set_error(err, errlen, "%s: output buffer too small", name);
        else
            *outlen += bom;
    }
    ctx_done(&x);
    if (rc == 0 && j288_robot_config_parse(out, *outlen, name, after, err, errlen) != 0)
        return -1;
    return (rc == 0) ? check_edit(before, after, ji, upd, name, err, errlen) : -1;
}

int j288_robot_config_edit(const char *text, size_t len, const char *name, const char *joint,
                     const j288_robot_config_update_t *upd, char *out, size_t outcap, size_t *outlen,
                     char *err, size_t errlen)
{
    j288_robot_config_t *cfg = malloc(2u * sizeof *cfg);
    int rc;
    if (cfg == NULL)
        return set_error(err, errlen, "%s: out of memory", name);
    rc = edit_text(text, len, name, joint, upd, out, outcap, outlen, &cfg[0], &cfg[1], err, errlen);
    free(cfg);
    return rc;
}

#ifdef _WIN32
/* Writing back is POSIX (permissions, a hidden temporary file renamed over the config, stale
 * ones found by process id): on Windows it is refused, before anything is sent, so that
 * j288 zero and calibrate say so instead of moving a joint for nothing. */
#define NO_WRITE_BACK "writing a config back (j288 zero, calibrate) is not available on Windows " \
                      "yet: run it on Linux, or edit zero:/phase: by hand"

int j288_robot_config_check_writable(const char *path, char *err, size_t errlen)
{
    return set_error(err, errlen, "%s: %s", path, NO_WRITE_BACK);
}

int j288_robot_config_write_joint(const char *path, const char *joint,
                                  const j288_robot_config_update_t *upd, char *err, size_t errlen)
{
    (void)joint;
    (void)upd;
    return set_error(err, errlen, "%s: %s", path, NO_WRITE_BACK);
}
#else
/* The temporary file of a write-back: hidden, beside the config (rename is atomic within a
 * folder), named after the config and the writing process: ".robot.yaml.j288-PID.XXXXXX". */
#define TEMP_TAG ".j288-"

/* The folder of real (an absolute path from realpath) into dir, and where its name starts. */
static int split_path(const char *real, char *dir, size_t cap, const char **base)
{
    const char *slash = strrchr(real, '/');
    size_t n = (slash == NULL || slash == real) ? 1u : (size_t)(slash - real);
    if (slash == NULL || n >= cap)
        return -1;
    memcpy(dir, real, n);
    dir[n] = '\0';
    *base = slash + 1;
    return 0;
}

/* A write-back killed between creating its temporary file and renaming it (SIGKILL, a
 * power cut) leaves the file behind: the next write-back of the same config removes those
 * whose process is gone. A live process's file is its own business. */
static void remove_stale_temps(const char *dir, const char *base)
{
    char prefix[NAME_MAX + 16];
    char full[PATH_MAX + NAME_MAX + 2];
    size_t plen;
    struct dirent *e;
    DIR *d;
    if ((size_t)snprintf(prefix, sizeof prefix, ".%s" TEMP_TAG, base) >= sizeof prefix ||
        (d = opendir(dir)) == NULL)
        return;
    plen = strlen(prefix);
    while ((e = readdir(d)) != NULL) {
        char *end;
        long pid;
        if (strncmp(e->d_name, prefix, plen) != 0)
            continue;
        errno = 0;
        pid = strtol(e->d_name + plen, &end, 10);
        if (errno != 0 || pid <= 0 || end[0] != '.' || strlen(end) != 7u)
            continue; /* not ours: ".XXXXXX" follows the process id */
        if (kill((pid_t)pid, 0) == 0 || errno != ESRCH)
            continue;
        if ((size_t)snprintf(full, sizeof full, "%s/%s", dir, e->d_name) < sizeof full)
            (void)unlink(full);
    }
    (void)closedir(d);
}

int j288_robot_config_check_writable(const char *path, char *err, size_t errlen)
{
    char real[PATH_MAX], dir[PATH_MAX];
    const char *base;
    struct stat st;
    if (realpath(path, real) == NULL || stat(real, &st) != 0)
        return set_error(err, errlen, "%s: %s", path, strerror(errno));
    if (!S_ISREG(st.st_mode))
        return set_error(err, errlen, "%s: not a regular file: cannot write it back", path);
    /* A file without any write permission says "keep this as it is", to root too (whom
     * access() lets write anything); renaming over it in a writable folder would not ask. */
    if ((st.st_mode & 0222) == 0 || access(real, W_OK) != 0)
        return set_error(err, errlen,
                         "%s: read-only: the new value could not be written back (make it "
                         "writable, or work on a copy)",
                         path);
    if (split_path(real, dir, sizeof dir, &base) != 0 || access(dir, W_OK | X_OK) != 0)
        return set_error(err, errlen,
                         "%s: its folder %s is not writable: the new value could not be written "
                         "back (a temporary file is renamed over the file)",
                         path, dir);
    return 0;
}

/* Write len bytes to a new file beside real with mode, then rename it over real. */
static int replace_file(const char *real, const char *shown, const char *data, size_t len,
                        mode_t mode, char *err, size_t errlen)
{
    char tmp[PATH_MAX + 64], dir[PATH_MAX];
    const char *base;
    size_t done = 0;
    int fd;
    if (split_path(real, dir, sizeof dir, &base) != 0 ||
        (size_t)snprintf(tmp, sizeof tmp, "%s/.%s" TEMP_TAG "%ld.XXXXXX", dir, base,
                         (long)getpid()) >= sizeof tmp)
        return set_error(err, errlen, "%s: path too long", shown);
    fd = mkstemp(tmp);
    if (fd < 0)
        return set_error(err, errlen, "%s: cannot create a file beside it: %s", shown,
                         strerror(errno));
    if (fchmod(fd, mode & 07777) != 0)
        goto fail;
    while (done < len) {
        ssize_t w = write(fd, data + done, len - done);
        if (w < 0 && errno == EINTR)
            continue;
        if (w < 0)
            goto fail;
        done += (size_t)w;
    }
    if (fsync(fd) != 0)
        goto fail;
    if (close(fd) != 0) {
        fd = -1;
        goto fail;
    }
    fd = -1;
    if (rename(tmp, real) != 0)
        goto fail;
    return 0;
fail:
    (void)set_error(err, errlen, "%s: cannot write: %s", shown, strerror(errno));
    if (fd >= 0)
        (void)close(fd);
    (void)unlink(tmp);
    return -1;
}

int j288_robot_config_write_joint(const char *path, const char *joint, const j288_robot_config_update_t *upd,
                            char *err, size_t errlen)
{
    char real[PATH_MAX];
    struct stat st;
    char *text = NULL, *out;
    size_t len, outlen, outcap;
    int rc;
    char dir[PATH_MAX];
    const char *base;
    if (j288_robot_config_check_writable(path, err, errlen) != 0)
        return -1;
    /* The file a symlink points at is the one to replace, not the link. */
    if (realpath(path, real) == NULL || stat(real, &st) != 0)
        return set_error(err, errlen, "%s: %s", path, strerror(errno));
    if (split_path(real, dir, sizeof dir, &base) == 0)
        remove_stale_temps(dir, base); /* whatever this write-back's own outcome */
    if (read_file(real, &text, &len, err, errlen) != 0)
        return -1;
    /* Each added line is at most 160 bytes (indentation up to 100, then key and value). */
    outcap = len + 2u * 160u;
    out = malloc(outcap);
    if (out == NULL) {
        free(text);
        return set_error(err, errlen, "%s: out of memory", path);
    }
    rc = j288_robot_config_edit(text, len, path, joint, upd, out, outcap, &outlen, err, errlen);
    if (rc == 0)
        rc = replace_file(real, path, out, outlen, st.st_mode, err, errlen);
    free(out);
    free(text);
    return rc;
}
#endif /* _WIN32 */

#endif /* J288_HAVE_LIBYAML */
