/* Unit tests of the robot config reader and writer (host/j288_robot_config.c). */
#define _XOPEN_SOURCE 700 /* mkdtemp, symlink, readlink under -std=c99 */

#include "unity.h"

#include <dirent.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "j288_robot_config.h"

#define NAME "robot.yaml"

static j288_robot_config_t g_cfg;
static char g_err[J288_ROBOT_CONFIG_ERROR_MAX];
static char g_out[8192];
static size_t g_outlen;

void setUp(void)
{
    memset(&g_cfg, 0, sizeof g_cfg);
    g_err[0] = '\0';
}

void tearDown(void) {}

#ifdef J288_HAVE_LIBYAML

static int parse(const char *text)
{
    return j288_robot_config_parse(text, strlen(text), NAME, &g_cfg, g_err, sizeof g_err);
}

/* text must fail with "robot.yaml:LINE: " and a message holding part. */
static void check_error(const char *text, unsigned line, const char *part)
{
    char prefix[64];
    char msg[1200];
    (void)snprintf(prefix, sizeof prefix, NAME ":%u: ", line);
    (void)snprintf(msg, sizeof msg, "text:\n%s\nerror: %s", text, g_err);
    TEST_ASSERT_EQUAL_INT_MESSAGE(-1, parse(text), text);
    (void)snprintf(msg, sizeof msg, "text:\n%s\nerror: %s", text, g_err);
    TEST_ASSERT_EQUAL_STRING_LEN_MESSAGE(prefix, g_err, strlen(prefix), msg);
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(g_err, part), msg);
    TEST_ASSERT_NULL_MESSAGE(strchr(g_err, '\n'), msg); /* one line */
}

static const char *const k_full = "# A robot with two legs.\n"
                                  "buses:\n"
                                  "  - name: left            # the left leg\n"
                                  "    port: /dev/ttyUSB0\n"
                                  "    baud: 4000000\n"
                                  "    margin_us: 3000\n"
                                  "    echo: true\n"
                                  "  - {name: right, port: /dev/ttyUSB1}\n"
                                  "\n"
                                  "joints:\n"
                                  "  - name: hip\n"
                                  "    bus: left\n"
                                  "    id: 1\n"
                                  "    direction: -1\n"
                                  "    zero: 0.25\n"
                                  "    limits: [-1.5, 1.5]\n"
                                  "    max_speed: 6.0\n"
                                  "    max_torque: 30\n"
                                  "    kp: 20.0\n"
                                  "    kd: 0.5\n"
                                  "    phase: 2.1\n"
                                  "    clamp: true\n"
                                  "  - name: knee\n"
                                  "    bus: left\n"
                                  "    id: 2\n"
                                  "    limits:\n"
                                  "      - 0\n"
                                  "      - 2.5\n"
                                  "    # the right leg\n"
                                  "  - name: hip_r\n"
                                  "    bus: right\n"
                                  "    id: 1\n";

static void test_full_file(void)
{
    const j288_robot_config_joint_t *j;
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, parse(k_full), g_err);
    TEST_ASSERT_EQUAL_UINT(2, g_cfg.nbuses);
    TEST_ASSERT_EQUAL_STRING("left", g_cfg.bus[0].name);
    TEST_ASSERT_EQUAL_STRING("/dev/ttyUSB0", g_cfg.bus[0].port);
    TEST_ASSERT_TRUE(g_cfg.bus[0].has_baud && g_cfg.bus[0].has_margin_us && g_cfg.bus[0].has_echo);
    TEST_ASSERT_EQUAL_UINT32(4000000u, g_cfg.bus[0].baud);
    TEST_ASSERT_EQUAL_UINT32(3000u, g_cfg.bus[0].margin_us);
    TEST_ASSERT_TRUE(g_cfg.bus[0].echo);
    TEST_ASSERT_EQUAL_UINT(3, g_cfg.bus[0].line);
    TEST_ASSERT_EQUAL_STRING("right", g_cfg.bus[1].name);
    TEST_ASSERT_FALSE(g_cfg.bus[1].has_baud || g_cfg.bus[1].has_margin_us || g_cfg.bus[1].has_echo);
    TEST_ASSERT_EQUAL_UINT(3, g_cfg.njoints);
    j = j288_robot_config_find_joint(&g_cfg, "hip");
    TEST_ASSERT_NOT_NULL(j);
    TEST_ASSERT_EQUAL_INT(0, j->bus);
    TEST_ASSERT_EQUAL_UINT8(1, j->id);
    TEST_ASSERT_EQUAL_INT(-1, j->direction);
    TEST_ASSERT_EQUAL_DOUBLE(0.25, j->zero);
    TEST_ASSERT_TRUE(j->has_limits);
    TEST_ASSERT_EQUAL_DOUBLE(-1.5, j->pos_min);
    TEST_ASSERT_EQUAL_DOUBLE(1.5, j->pos_max);
    TEST_ASSERT_TRUE(j->has_max_speed && j->has_max_torque && j->has_kp && j->has_kd);
    TEST_ASSERT_EQUAL_DOUBLE(6.0, j->max_speed);
    TEST_ASSERT_EQUAL_DOUBLE(30.0, j->max_torque);
    TEST_ASSERT_EQUAL_DOUBLE(20.0, j->kp);
    TEST_ASSERT_EQUAL_DOUBLE(0.5, j->kd);
    TEST_ASSERT_TRUE(j->has_phase);
    TEST_ASSERT_EQUAL_DOUBLE(2.1, j->phase);
    TEST_ASSERT_TRUE(j->clamp);
    TEST_ASSERT_EQUAL_UINT(11, j->line);
    j = j288_robot_config_find_joint(&g_cfg, "knee");
    TEST_ASSERT_NOT_NULL(j);
    TEST_ASSERT_EQUAL_DOUBLE(0.0, j->pos_min);
    TEST_ASSERT_EQUAL_DOUBLE(2.5, j->pos_max);
    TEST_ASSERT_FALSE(j->has_phase || j->clamp || j->has_kp);
    j = j288_robot_config_find_joint(&g_cfg, "hip_r");
    TEST_ASSERT_NOT_NULL(j);
    TEST_ASSERT_EQUAL_INT(1, j->bus); /* the same id on another bus is fine */
    TEST_ASSERT_NULL(j288_robot_config_find_joint(&g_cfg, "ankle"));
    TEST_ASSERT_EQUAL_INT(1, j288_robot_config_find_bus(&g_cfg, "right"));
    TEST_ASSERT_EQUAL_INT(-1, j288_robot_config_find_bus(&g_cfg, "middle"));
}

/* The file's joints as the library takes them; the library accepts each. */
static void test_joint_config(void)
{
    j288_joint_config_t jc;
    j288_joint_t joint;
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, parse(k_full), g_err);
    memset(&jc, 0x5a, sizeof jc);
    j288_robot_config_joint_config(j288_robot_config_find_joint(&g_cfg, "hip"), &jc);
    TEST_ASSERT_EQUAL_UINT8(1, jc.id);
    TEST_ASSERT_EQUAL_INT8(-1, jc.direction);
    TEST_ASSERT_TRUE(jc.clamp);
    TEST_ASSERT_TRUE(jc.has_phase);
    TEST_ASSERT_EQUAL_DOUBLE(2.1, (double)jc.phase);
    TEST_ASSERT_EQUAL_DOUBLE(0.25, (double)jc.zero);
    TEST_ASSERT_EQUAL_DOUBLE(-1.5, (double)jc.pos_min);
    TEST_ASSERT_EQUAL_DOUBLE(1.5, (double)jc.pos_max);
    TEST_ASSERT_EQUAL_DOUBLE(6.0, (double)jc.max_speed);
    TEST_ASSERT_EQUAL_DOUBLE(30.0, (double)jc.max_torque);
    TEST_ASSERT_EQUAL_DOUBLE(20.0, (double)jc.kp);
    TEST_ASSERT_EQUAL_DOUBLE(0.5, (double)jc.kd);
    TEST_ASSERT_EQUAL_UINT8(0, jc.init_samples);
    TEST_ASSERT_EQUAL_DOUBLE(0.0, (double)jc.track_tol);
    TEST_ASSERT_EQUAL_DOUBLE(0.0, (double)jc.cal_tol);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &jc));
    /* Nothing given: the all-zero configuration but the id, the library's defaults. */
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, parse("joints:\n  - name: a\n    id: 7\n"), g_err);
    memset(&jc, 0x5a, sizeof jc);
    j288_robot_config_joint_config(&g_cfg.joint[0], &jc);
    TEST_ASSERT_EQUAL_UINT8(7, jc.id);
    TEST_ASSERT_EQUAL_INT8(1, jc.direction);
    TEST_ASSERT_FALSE(jc.clamp || jc.has_phase);
    TEST_ASSERT_EQUAL_DOUBLE(0.0, (double)jc.zero);
    TEST_ASSERT_EQUAL_DOUBLE(0.0, (double)jc.pos_min);
    TEST_ASSERT_EQUAL_DOUBLE(0.0, (double)jc.pos_max);
    TEST_ASSERT_EQUAL_DOUBLE(0.0, (double)jc.max_speed);
    TEST_ASSERT_EQUAL_DOUBLE(0.0, (double)jc.max_torque);
    TEST_ASSERT_EQUAL_DOUBLE(0.0, (double)jc.kp);
    TEST_ASSERT_EQUAL_DOUBLE(0.0, (double)jc.kd);
    TEST_ASSERT_EQUAL_DOUBLE(0.0, (double)jc.phase);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &jc));
    /* Limits only partly in the default range still come through as given. */
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, parse("joints:\n  - {name: a, id: 2, limits: [5.8, 6.8]}\n"),
                                  g_err);
    j288_robot_config_joint_config(&g_cfg.joint[0], &jc);
    TEST_ASSERT_EQUAL_DOUBLE(5.8, (double)jc.pos_min);
    TEST_ASSERT_EQUAL_DOUBLE(6.8, (double)jc.pos_max);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&joint, &jc));
    j288_robot_config_joint_config(NULL, &jc); /* ignored */
    j288_robot_config_joint_config(&g_cfg.joint[0], NULL);
}

static void test_defaults(void)
{
    const j288_robot_config_joint_t *j;
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, parse("joints:\n  - name: a\n    id: 0\n"), g_err);
    TEST_ASSERT_EQUAL_UINT(0, g_cfg.nbuses);
    j = &g_cfg.joint[0];
    TEST_ASSERT_EQUAL_INT(J288_ROBOT_CONFIG_NO_BUS, j->bus);
    TEST_ASSERT_EQUAL_INT(1, j->direction);
    TEST_ASSERT_EQUAL_DOUBLE(0.0, j->zero);
    TEST_ASSERT_FALSE(j->has_limits || j->has_max_speed || j->has_max_torque || j->has_kp ||
                      j->has_kd || j->has_phase || j->clamp);
    TEST_ASSERT_EQUAL_DOUBLE(-3.141592653589793, j->pos_min);
    TEST_ASSERT_EQUAL_DOUBLE(3.141592653589793, j->pos_max);
    /* One bus: a joint without 'bus' is on it. Null lists are empty. */
    TEST_ASSERT_EQUAL_INT_MESSAGE(
        0, parse("buses: [{name: b, port: /dev/x}]\njoints:\n  - {name: a, id: 3}\n"), g_err);
    TEST_ASSERT_EQUAL_INT(0, g_cfg.joint[0].bus);
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, parse("buses:\njoints: ~\n"), g_err);
    TEST_ASSERT_EQUAL_UINT(0, g_cfg.njoints);
    /* Limits of exactly 2 pi, as written by someone typing pi out. */
    TEST_ASSERT_EQUAL_INT_MESSAGE(
        0,
        parse("joints:\n  - {name: a, id: 1, limits: [-3.141592653589793, 3.141592653589793]}\n"),
        g_err);
}

static void test_byte_order_mark_crlf_and_unicode(void)
{
    const char *text = "\xEF\xBB\xBF# caf\xC3\xA9 \xE2\x82\xAC\r\njoints:\r\n"
                       "  - name: h\xC3\xBC"
                       "fte   # \xE6\x9C\xBA\xE5\x99\xA8\r\n"
                       "    id: 4\r\n    zero: -0.5\r\n";
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, parse(text), g_err);
    TEST_ASSERT_EQUAL_STRING("h\xC3\xBC"
                             "fte",
                             g_cfg.joint[0].name);
    TEST_ASSERT_EQUAL_DOUBLE(-0.5, g_cfg.joint[0].zero);
    TEST_ASSERT_EQUAL_UINT(3, g_cfg.joint[0].line);
}

static void test_errors_keys(void)
{
    check_error("joints:\n  - name: a\n    id: 1\n    zeroo: 0.1\n", 4,
                "joint 'a': unknown key 'zeroo' (known: name, bus, id,");
    check_error("buses:\n  - name: l\n    port: /dev/a\n    speed: 3\njoints: []\n", 4,
                "bus 'l': unknown key 'speed'");
    check_error("joint:\n  - name: a\n", 1, "unknown key 'joint' (known: buses, joints)");
    check_error("joints:\n  - name: a\n    id: 1\n    id: 2\n", 4,
                "joint 'a': 'id' given twice (first on line 3)");
    check_error("joints:\n  - id: 1\n", 2, "joint 1: 'name' is missing");
    check_error("joints:\n  - name: a\n", 2, "joint 'a': 'id' is missing");
    check_error("buses:\n  - name: l\njoints: []\n", 2, "bus 'l': 'port' is missing");
    check_error("buses:\n  - port: /dev/a\n", 2, "bus 1: 'name' is missing");
    check_error("joints:\n  - name: a\n    id: 1\n    [x]: 2\n", 4, "a key must be a name");
    /* A folded scalar holds line breaks: the message shows them as '?', one line (found by
     * fuzz_config). */
    check_error("joints:\n  - name: a\n    id: 1\n    clamp: ab\n\n      cd\n", 4,
                "clamp: expected true or false, got 'ab?cd'");
    check_error("joints:\n  - name: a\n    id: 1\n    ? ab\n\n      cd\n    : 1\n", 4,
                "unknown key 'ab?cd'");
    check_error("joints:\n  - {name: \"a\\nb\", id: 1}\n", 2, "name: 'a?b' has a control character");
    check_error("joints:\n  - name: a\n    id: !a%0Ab 1\n", 3, "YAML tags (!a?b)");
}

static void test_errors_types(void)
{
    check_error("joints:\n  - name: a\n    id: abc\n", 3,
                "id: expected an integer 0-14, got 'abc'");
    check_error("joints:\n  - name: a\n    id: \"1\"\n", 3,
                "id: expected an integer 0-14, got the quoted text '1'");
    check_error("joints:\n  - name: a\n    id: 1.0\n", 3, "id: expected an integer");
    check_error("joints:\n  - name: a\n    id: 1\n    zero: [1]\n", 4,
                "zero: expected a number, got a list");
    check_error("joints:\n  - name: a\n    id: 1\n    zero:\n", 4,
                "zero: expected a number, got nothing");
    check_error("joints:\n  - name: a\n    id: 1\n    kp: \"20\"\n", 4, "kp: expected a number");
    check_error("joints:\n  - name: a\n    id: 1\n    zero: .inf\n", 4, "zero: expected a number");
    check_error("joints:\n  - name: a\n    id: 1\n    zero: nan\n", 4, "zero: expected a number");
    check_error("joints:\n  - name: a\n    id: 1\n    zero: 0x10\n", 4, "zero: expected a number");
    /* The tool's options refuse these too (host/j288_number.h): one syntax for both. */
    check_error("joints:\n  - name: a\n    id: 1\n    zero: 0x1p1\n", 4, "zero: expected a number");
    check_error("joints:\n  - name: a\n    id: 1\n    zero: 1e\n", 4, "zero: expected a number");
    check_error("joints:\n  - name: a\n    id: 1\n    zero: 1-2\n", 4, "zero: expected a number");
    check_error("joints:\n  - name: a\n    id: 1\n    zero: +-1\n", 4, "zero: expected a number");
    check_error("joints:\n  - name: a\n    id: 1\n    zero: 1e999\n", 4,
                "zero: 1e999 is out of range");
    check_error("joints:\n  - name: a\n    id: 1\n    clamp: yes\n", 4,
                "clamp: expected true or false, got 'yes'");
    check_error("buses:\n  - name: l\n    port: /dev/a\n    echo: 1\n", 4,
                "echo: expected true or false");
    check_error("buses:\n  - name: l\n    port: /dev/a\n    baud: 0\n", 4,
                "baud: 0 is out of range (9600-100000000)");
    check_error("buses:\n  - name: l\n    port: [a]\n", 3, "port: expected text, got a list");
    check_error("joints:\n  - name: {a: 1}\n    id: 1\n", 2,
                "name: expected a name, got a mapping");
    /* Quoted empty text is a string to YAML, not null: it was taken as a port (found by
     * fuzz_config). */
    check_error("buses:\n  - name: l\n    port: \"\"\n", 3,
                "port: expected text, got the quoted text ''");
    check_error("joints:\n  - name: ''\n    id: 1\n", 2,
                "name: expected a name, got the quoted text ''");
    check_error("joints:\n  - name: 'left hip'\n    id: 1\n", 2, "name: 'left hip' has a blank");
    check_error("joints:\n  - name: abcdefghijabcdefghijabcdefghijabc\n    id: 1\n", 2,
                "name: longer than 31 bytes");
    check_error("joints:\n  - name: a\n    id: 1\n    limits: 1.5\n", 4,
                "limits: expected two numbers [min, max], got '1.5'");
    check_error("joints:\n  - name: a\n    id: 1\n    limits: [1, 2, 3]\n", 4,
                "limits: expected two numbers");
    check_error("joints:\n  - name: a\n    id: 1\n    limits:\n      - -1\n      - x\n", 6,
                "limits: expected a number, got 'x'");
    check_error("joints: 5\n", 1, "joints: expected a list (- name: ...), got '5'");
    check_error("joints:\n  - 5\n", 2, "joint 1: joints: expected a mapping per joint");
    check_error("- a\n- b\n", 1, "the file: expected a mapping with 'buses:' and 'joints:'");
}

/* What the tool's options take, the file takes: hexadecimal whole numbers, decimal reals in
 * every form strtod shares with that syntax. */
static void test_numbers_as_on_the_command_line(void)
{
    TEST_ASSERT_EQUAL_INT_MESSAGE(
        0, parse("joints:\n  - {name: a, id: 0xE, zero: -.5, kp: 2e1, kd: 5., max_speed: +3}\n"),
        g_err);
    TEST_ASSERT_EQUAL_UINT8(14, g_cfg.joint[0].id);
    TEST_ASSERT_EQUAL_DOUBLE(-0.5, g_cfg.joint[0].zero);
    TEST_ASSERT_EQUAL_DOUBLE(20.0, g_cfg.joint[0].kp);
    TEST_ASSERT_EQUAL_DOUBLE(5.0, g_cfg.joint[0].kd);
    TEST_ASSERT_EQUAL_DOUBLE(3.0, g_cfg.joint[0].max_speed);
    check_error("joints:\n  - {name: a, id: 0xF}\n", 2, "id: 0xF is out of range (0-14)");
}

/* Every range error names the key, the value as written and the range. */
static void test_errors_ranges(void)
{
    check_error("joints:\n  - name: a\n    id: 1\n    kp: 1e308\n", 4,
                "joint 'a': kp: 1e308 is out of range (0 to 2128.4)");
    check_error("joints:\n  - name: a\n    id: 1\n    kd: 2e30\n", 4,
                "kd: 2e30 is out of range (0 to 21.284)");
    /* The gains and the buses' numbers have the command line's ranges (j288_range.h): a gain
     * the wire cannot carry is this file's error, not a --kp the user never gave. */
    check_error("joints:\n  - name: a\n    id: 1\n    kp: 1e9\n", 4,
                "joint 'a': kp: 1e9 is out of range (0 to 2128.4)");
    check_error("joints:\n  - name: a\n    id: 1\n    kd: 21.3\n", 4,
                "kd: 21.3 is out of range (0 to 21.284)");
    check_error("buses:\n  - name: l\n    port: /dev/a\n    margin_us: 0\n", 4,
                "bus 'l': margin_us: 0 is out of range (1-10000000)");
    check_error("buses:\n  - name: l\n    port: /dev/a\n    margin_us: 10000001\n", 4,
                "margin_us: 10000001 is out of range (1-10000000)");
    check_error("buses:\n  - name: l\n    port: /dev/a\n    baud: 4800\n", 4,
                "baud: 4800 is out of range (9600-100000000)");
    check_error("joints:\n  - name: a\n    id: 1\n    max_speed: 1e31\n", 4,
                "max_speed: 1e31 is out of range (0 to 1e+30)");
    check_error("joints:\n  - name: a\n    id: 1\n    max_torque: 1e300\n", 4,
                "max_torque: 1e300 is out of range");
    check_error("joints:\n  - name: a\n    id: 1\n    zero: 100\n", 4,
                "zero: 100 is out of range (-64 to 64)");
    check_error("joints:\n  - name: a\n    id: 1\n    phase: -7\n", 4,
                "phase: -7 is out of range (-6.283185307 to 6.283185307)");
    check_error("joints:\n  - name: a\n    id: 1\n    limits: [-65, -63]\n", 4,
                "limits: -65 is out of range (-64 to 64)");
    check_error("joints:\n  - name: a\n    id: 1\n    limits: [63, 1e100]\n", 4,
                "limits: 1e100 is out of range (-64 to 64)");
    /* The bounds themselves are in range. */
    TEST_ASSERT_EQUAL_INT_MESSAGE(
        0, parse("joints:\n  - {name: a, id: 1, zero: -64, phase: 6.283185307, kp: 2128.4, "
                 "kd: 21.284}\n"),
        g_err);
    TEST_ASSERT_EQUAL_INT_MESSAGE(
        0, parse("buses:\n  - {name: l, port: /dev/a, baud: 9600, margin_us: 10000000}\n"), g_err);
}

/* Tags are refused, not ignored: "id: !!str 1" read as the number 1 said nothing. */
static void test_errors_tags(void)
{
    check_error("joints:\n  - name: a\n    id: !!str 1\n", 3,
                "YAML tags (!!str) are not supported");
    check_error("joints:\n  - name: a\n    id: 1\n    clamp: !!bool 1\n", 4,
                "YAML tags (!!bool) are not supported");
    check_error("joints:\n  - name: a\n    id: !!int 1\n", 3, "YAML tags (!!int)");
    check_error("joints: !!seq\n  - {name: a, id: 1}\n", 1, "YAML tags (!!seq)");
    check_error("joints:\n  - !joint {name: a, id: 1}\n", 2, "YAML tags (!joint)");
    check_error("--- !!map\njoints: []\n", 1, "YAML tags (!!map)");
}

/* A file nested past the bound is refused where the bound is crossed, before libyaml reads
 * further: 100,000 levels took minutes before (no time is measured here: the message says
 * which check refused it, and the deeper file would not finish within the test's budget). */
static void test_errors_depth(void)
{
    static char text[210000];
    size_t depth = 100000, n = 0, i;
    n += (size_t)snprintf(text, sizeof text, "joints: ");
    for (i = 0; i < depth; i++)
        text[n++] = '[';
    for (i = 0; i < depth; i++)
        text[n++] = ']';
    text[n] = '\0';
    check_error(text, 1, "nested deeper than 8 lists and mappings");
    /* Block style the same; the bound itself (8 levels) is only a content error. */
    check_error("joints:\n- - - - - - - - x\n", 2, "nested deeper than 8");
    check_error("joints:\n- - - - - - - x\n", 2, "joint 1: joints: expected a mapping per joint");
}

static void test_errors_values(void)
{
    check_error("joints:\n  - name: a\n    id: 15\n", 3,
                "id: 15 is the broadcast address; servo ids are 0-14");
    check_error("joints:\n  - name: a\n    id: -1\n", 3, "id: -1 is out of range (0-14)");
    check_error("joints:\n  - name: a\n    id: 99\n", 3, "id: 99 is out of range (0-14)");
    check_error("joints:\n  - name: a\n    id: 1\n    direction: 2\n", 4,
                "direction: expected 1 or -1, got '2'");
    check_error("joints:\n  - name: a\n    id: 1\n    direction: 0\n", 4, "direction: expected");
    check_error("joints:\n  - name: a\n    id: 1\n    direction: 1.0\n", 4, "direction: expected");
    check_error("joints:\n  - name: a\n    id: 1\n    limits: [1, -1]\n", 4,
                "limits: [1, -1] are reversed or empty");
    check_error("joints:\n  - name: a\n    id: 1\n    limits: [1, 1]\n", 4,
                "limits: [1, 1] are reversed or empty");
    check_error("joints:\n  - name: a\n    id: 1\n    limits: [-3.1416, 3.1416]\n", 4,
                "limits: [-3.1416, 3.1416] span 6.283200 rad, more than 2 pi (6.283185307)");
    check_error("joints:\n  - name: a\n    id: 1\n    kp: -1\n", 4, "kp: -1 must be 0 or more");
    check_error("joints:\n  - name: a\n    id: 1\n    kd: -0.1\n", 4, "kd: -0.1 must be 0 or more");
    check_error("joints:\n  - name: a\n    id: 1\n    max_speed: 0\n", 4,
                "max_speed: 0 must be above 0");
    check_error("joints:\n  - name: a\n    id: 1\n    max_torque: -5\n", 4,
                "max_torque: -5 must be above 0");
    /* kp and kd of 0 are fine (pure torque, no damping). */
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, parse("joints:\n  - {name: a, id: 1, kp: 0, kd: 0.0}\n"),
                                  g_err);
}

static void test_errors_across_entries(void)
{
    check_error("buses:\n  - {name: l, port: /dev/a}\n  - {name: l, port: /dev/b}\n", 3,
                "bus 'l': name: already used by the bus on line 2");
    check_error("buses:\n  - {name: l, port: /dev/a}\n  - {name: r, port: /dev/a}\n", 3,
                "bus 'r': port: /dev/a is already bus 'l' (line 2)");
    check_error("joints:\n  - {name: a, id: 1}\n  - {name: a, id: 2}\n", 3,
                "joint 'a': name: already used by the joint on line 2");
    check_error("joints:\n  - {name: a, id: 1}\n  - name: b\n    id: 1\n", 4,
                "joint 'b': id: 1 is already joint 'a' (line 2)");
    check_error("buses:\n  - {name: l, port: /dev/a}\njoints:\n  - {name: a, id: 1}\n"
                "  - {name: b, id: 1, bus: l}\n",
                5, "joint 'b': id: 1 is already joint 'a' (line 4) on bus 'l'");
    check_error("buses:\n  - {name: l, port: /dev/a}\n  - {name: r, port: /dev/b}\n"
                "joints:\n  - name: a\n    id: 1\n",
                5, "joint 'a': 'bus' is missing (the file has 2 buses)");
    check_error("buses:\n  - {name: l, port: /dev/a}\njoints:\n  - {name: a, id: 1, bus: x}\n", 4,
                "joint 'a': bus: no bus is named 'x'");
    check_error("joints:\n  - {name: a, id: 1, bus: x}\n", 2,
                "bus: no bus is named 'x' (the file has no 'buses:')");
}

static void test_errors_capacity(void)
{
    static char text[8192];
    size_t n, i;
    n = (size_t)snprintf(text, sizeof text, "joints:\n");
    for (i = 0; i < J288_ROBOT_CONFIG_MAX_JOINTS + 1u; i++)
        n += (size_t)snprintf(text + n, sizeof text - n, "  - {name: j%zu, id: %zu, bus: b%zu}\n",
                              i, i % 15u, i / 15u);
    n += (size_t)snprintf(text + n, sizeof text - n, "buses:\n");
    for (i = 0; i < 5u; i++)
        n += (size_t)snprintf(text + n, sizeof text - n, "  - {name: b%zu, port: /dev/p%zu}\n", i,
                              i);
    /* The 65th joint's line and name, not the 64th's. */
    check_error(text, 2u + J288_ROBOT_CONFIG_MAX_JOINTS, "joint 'j64': joints: more than 64");
    n = (size_t)snprintf(text, sizeof text, "buses:\n");
    for (i = 0; i < J288_ROBOT_CONFIG_MAX_BUSES + 1u; i++)
        n += (size_t)snprintf(text + n, sizeof text - n, "  - {name: b%zu, port: /dev/p%zu}\n", i,
                              i);
    check_error(text, 2u + J288_ROBOT_CONFIG_MAX_BUSES, "bus 'b16': buses: more than 16");
    /* Exactly the capacity is fine. */
    n = (size_t)snprintf(text, sizeof text, "buses:\n");
    for (i = 0; i < 5u; i++)
        n += (size_t)snprintf(text + n, sizeof text - n, "  - {name: b%zu, port: /dev/p%zu}\n", i,
                              i);
    n += (size_t)snprintf(text + n, sizeof text - n, "joints:\n");
    for (i = 0; i < J288_ROBOT_CONFIG_MAX_JOINTS; i++)
        n += (size_t)snprintf(text + n, sizeof text - n, "  - {name: j%zu, id: %zu, bus: b%zu}\n",
                              i, i % 15u, i / 15u);
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, parse(text), g_err);
    TEST_ASSERT_EQUAL_UINT(J288_ROBOT_CONFIG_MAX_JOINTS, g_cfg.njoints);
}

static void test_errors_malformed(void)
{
    check_error("joints:\n\t- name: a\n", 2,
                "syntax error at column 1: found character that cannot start any token");
    check_error("joints:\n\t- name: a\n", 2, "YAML indents with spaces, not tabs");
    check_error("joints:\n  - name: a\n\tid: 1\n", 3, "not tabs");
    check_error("joints:\n  - name: a\n    limits: [1, 2\n  - name: b\n", 4,
                "did not find expected ',' or ']' (while parsing a flow sequence that starts on "
                "line 3)");
    check_error("joints:\n  - {name: a, id: 1\n", 3, "syntax error");
    check_error("joints:\n  - name: \"a\n    id: 1\n", 4, "found unexpected end of stream");
    check_error("joints:\n  - name: a\n   id: 1\n", 3, "syntax error");
    check_error("joints:\n  - name: a\n    id: 1\n  zero: 2\n", 4, "syntax error");
    check_error("joints:\n  - name: a\n    id: 1\n    zero: \xFF\n", 4, "not UTF-8 text");
    check_error("joints:\n  - name: a\n    id: 1\n---\njoints: []\n", 4, "a second YAML document");
    check_error("joints:\n  - name: a\n    id: 1\n    zero: &z 0.5\n  - name: b\n    id: 2\n"
                "    zero: *z\n",
                7, "aliases (*z) are not supported");
    check_error("", 1, "the file is empty");
    check_error("# only a comment\n", 1, "the file is empty");
}

/* ---- write-back ------------------------------------------------------------------------- */

static int edit(const char *text, const char *joint, const j288_robot_config_update_t *upd)
{
    return j288_robot_config_edit(text, strlen(text), NAME, joint, upd, g_out, sizeof g_out - 1u,
                            &g_outlen, g_err, sizeof g_err);
}

static j288_robot_config_update_t zero_upd(double z)
{
    j288_robot_config_update_t u;
    memset(&u, 0, sizeof u);
    u.set_zero = true;
    u.zero = z;
    return u;
}

static j288_robot_config_update_t phase_upd(double c)
{
    j288_robot_config_update_t u;
    memset(&u, 0, sizeof u);
    u.set_phase = true;
    u.phase = c;
    return u;
}

/* The output is expected with every byte as the input but for the given text. */
static void check_output(const char *expected)
{
    TEST_ASSERT_EQUAL_UINT_MESSAGE(strlen(expected), g_outlen, g_out);
    g_out[g_outlen] = '\0';
    TEST_ASSERT_EQUAL_STRING(expected, g_out);
}

static void test_edit_replaces_in_place(void)
{
    j288_robot_config_update_t u = zero_upd(0.125);
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, edit(k_full, "hip", &u), g_err);
    {
        /* k_full with "zero: 0.25" -> "zero: 0.125" and nothing else. */
        char expected[2048];
        const char *at = strstr(k_full, "zero: 0.25");
        size_t pre = (size_t)(at - k_full) + 6u;
        (void)snprintf(expected, sizeof expected, "%.*s0.125%s", (int)pre, k_full,
                       at + strlen("zero: 0.25"));
        check_output(expected);
    }
    u = phase_upd(-3.0);
    TEST_ASSERT_EQUAL_INT_MESSAGE(
        0, edit("joints:\n  - {name: a, id: 1, phase: 1.5}  # c\n", "a", &u), g_err);
    check_output("joints:\n  - {name: a, id: 1, phase: -3.0}  # c\n");
}

static void test_edit_adds_missing_key(void)
{
    j288_robot_config_update_t u = phase_upd(2.718281828459);
    char expected[2048];
    const char *at;
    /* knee ends with a block list and a comment: the new line goes after the list's last
     * item, indented as knee's keys, before the comment. */
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, edit(k_full, "knee", &u), g_err);
    at = strstr(k_full, "      - 2.5\n") + strlen("      - 2.5\n");
    (void)snprintf(expected, sizeof expected, "%.*s    phase: 2.718281828\n%s", (int)(at - k_full),
                   k_full, at);
    check_output(expected);
    /* The last joint of the file. */
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, edit(k_full, "hip_r", &u), g_err);
    (void)snprintf(expected, sizeof expected, "%s    phase: 2.718281828\n", k_full);
    check_output(expected);
    /* Both values: zero replaced, phase added. */
    u.set_zero = true;
    u.zero = -1.0;
    TEST_ASSERT_EQUAL_INT_MESSAGE(
        0, edit("joints:\n- name: a\n  id: 1   # one\n  zero: 3  # z\n\n", "a", &u), g_err);
    check_output(
        "joints:\n- name: a\n  id: 1   # one\n  zero: -1.0  # z\n  phase: 2.718281828\n\n");
    /* Deeper indentation, a trailing comment on the last line. */
    u = zero_upd(0.5);
    TEST_ASSERT_EQUAL_INT_MESSAGE(
        0, edit("joints:\n    -   name: a\n        id: 1 # last\nbuses: []\n", "a", &u), g_err);
    check_output("joints:\n    -   name: a\n        id: 1 # last\n        zero: 0.5\nbuses: []\n");
}

static void test_edit_line_endings_and_unicode(void)
{
    j288_robot_config_update_t u = phase_upd(1.0);
    /* CRLF: the new line ends as the others do. */
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, edit("joints:\r\n  - name: a\r\n    id: 1\r\n", "a", &u),
                                  g_err);
    check_output("joints:\r\n  - name: a\r\n    id: 1\r\n    phase: 1.0\r\n");
    /* No line ending at the end of the file. */
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, edit("joints:\n  - name: a\n    id: 1", "a", &u), g_err);
    check_output("joints:\n  - name: a\n    id: 1\n    phase: 1.0");
    /* A byte order mark and multi-byte characters before the value: libyaml counts
     * characters, the edit must land on bytes. */
    u = zero_upd(-0.75);
    TEST_ASSERT_EQUAL_INT_MESSAGE(
        0,
        edit("\xEF\xBB\xBF# \xE6\x9C\xBA\xE5\x99\xA8\xE4\xBA\xBA \xC3\xA9\njoints:\n"
             "  - name: \xC3\xA9t\xC3\xA9  # \xE2\x82\xAC\n    id: 1\n    zero: 0.1  # \xC3\xA9\n",
             "\xC3\xA9t\xC3\xA9", &u),
        g_err);
    check_output(
        "\xEF\xBB\xBF# \xE6\x9C\xBA\xE5\x99\xA8\xE4\xBA\xBA \xC3\xA9\njoints:\n"
        "  - name: \xC3\xA9t\xC3\xA9  # \xE2\x82\xAC\n    id: 1\n    zero: -0.75  # \xC3\xA9\n");
}

static void test_edit_value_format(void)
{
    static const struct {
        double v;
        const char *text;
    } cases[] = {{0.0, "0.0"},
                 {-0.0, "0.0"},
                 {2.1, "2.1"},
                 {1.0, "1.0"},
                 {-1e-10, "0.0"},
                 {1e-9, "0.000000001"},
                 {-63.5, "-63.5"},
                 {3.14159265358979, "3.141592654"}};
    size_t i;
    for (i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        j288_robot_config_update_t u = zero_upd(cases[i].v);
        char expected[128];
        TEST_ASSERT_EQUAL_INT_MESSAGE(0, edit("joints: [{name: a, id: 1, zero: 9}]\n", "a", &u),
                                      g_err);
        (void)snprintf(expected, sizeof expected, "joints: [{name: a, id: 1, zero: %s}]\n",
                       cases[i].text);
        check_output(expected);
    }
}

static void test_edit_refusals(void)
{
    j288_robot_config_update_t u = phase_upd(1.0);
    /* A flow mapping can have values replaced (above), not added. */
    TEST_ASSERT_EQUAL_INT(-1, edit("joints:\n  - {name: a, id: 1}\n", "a", &u));
    TEST_ASSERT_EQUAL_STRING_LEN(NAME ":2: joint 'a': is written as a flow mapping", g_err,
                                 strlen(NAME ":2: joint 'a': is written as a flow mapping"));
    TEST_ASSERT_EQUAL_INT(-1, edit("joints:\n  - name: a\n    id: 1\n", "b", &u));
    TEST_ASSERT_EQUAL_STRING(NAME ":1: no joint is named 'b'", g_err);
    /* A file that does not read is not edited. */
    TEST_ASSERT_EQUAL_INT(-1, edit("joints:\n  - name: a\n    id: 1\n    kp: -1\n", "a", &u));
    TEST_ASSERT_NOT_NULL(strstr(g_err, "kp: -1 must be 0 or more"));
    u.phase = NAN;
    TEST_ASSERT_EQUAL_INT(-1, edit("joints:\n  - name: a\n    id: 1\n", "a", &u));
    TEST_ASSERT_NOT_NULL(strstr(g_err, "phase nan is not a finite value"));
    u = zero_upd(2e6);
    TEST_ASSERT_EQUAL_INT(-1, edit("joints:\n  - name: a\n    id: 1\n", "a", &u));
    TEST_ASSERT_NOT_NULL(strstr(g_err, "zero 2e+06 is not a finite value within +-64"));
    memset(&u, 0, sizeof u);
    TEST_ASSERT_EQUAL_INT(-1, edit("joints:\n  - name: a\n    id: 1\n", "a", &u));
    TEST_ASSERT_NOT_NULL(strstr(g_err, "nothing to change"));
    /* Too small an output buffer is an error, not an overflow. */
    u = zero_upd(1.0);
    TEST_ASSERT_EQUAL_INT(-1, j288_robot_config_edit("joints:\n  - name: a\n    id: 1\n", 30u, NAME, "a",
                                               &u, g_out, 30u, &g_outlen, g_err, sizeof g_err));
    TEST_ASSERT_NOT_NULL(strstr(g_err, "output buffer too small"));
}

/* ---- files -------------------------------------------------------------------------------- */

static char g_dir[64];

static void write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "wb");
    TEST_ASSERT_NOT_NULL(f);
    TEST_ASSERT_EQUAL_UINT(strlen(text), fwrite(text, 1, strlen(text), f));
    TEST_ASSERT_EQUAL_INT(0, fclose(f));
}

static const char *read_text(const char *path)
{
    static char buf[8192];
    FILE *f = fopen(path, "rb");
    size_t n;
    TEST_ASSERT_NOT_NULL(f);
    n = fread(buf, 1, sizeof buf - 1u, f);
    (void)fclose(f);
    buf[n] = '\0';
    return buf;
}

static size_t files_in_dir(void)
{
    DIR *d = opendir(g_dir);
    struct dirent *e;
    size_t n = 0;
    TEST_ASSERT_NOT_NULL(d);
    while ((e = readdir(d)) != NULL)
        if (strcmp(e->d_name, ".") != 0 && strcmp(e->d_name, "..") != 0)
            n++;
    (void)closedir(d);
    return n;
}

static void test_file_round_trip(void)
{
    char path[128], link[128], target[128];
    j288_robot_config_update_t u = phase_upd(0.333);
    struct stat st;
    ssize_t n;
    (void)snprintf(path, sizeof path, "%s/robot.yaml", g_dir);
    (void)snprintf(link, sizeof link, "%s/link.yaml", g_dir);
    write_text(path, k_full);
    TEST_ASSERT_EQUAL_INT(0, chmod(path, 0640));
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, j288_robot_config_write_joint(path, "knee", &u, g_err, sizeof g_err),
                                  g_err);
    TEST_ASSERT_EQUAL_INT(0, stat(path, &st));
    TEST_ASSERT_EQUAL_UINT(0640, st.st_mode & 07777);
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, j288_robot_config_load(path, &g_cfg, g_err, sizeof g_err), g_err);
    TEST_ASSERT_EQUAL_DOUBLE(0.333, j288_robot_config_find_joint(&g_cfg, "knee")->phase);
    TEST_ASSERT_EQUAL_DOUBLE(2.1, j288_robot_config_find_joint(&g_cfg, "hip")->phase);
    TEST_ASSERT_EQUAL_UINT(1, files_in_dir()); /* no temporary file left */
    /* Writing the same value again changes nothing; through a symlink, the target changes
     * and the link stays a link. */
    {
        char before[8192];
        (void)snprintf(before, sizeof before, "%s", read_text(path));
        TEST_ASSERT_EQUAL_INT(0, symlink("robot.yaml", link));
        TEST_ASSERT_EQUAL_INT_MESSAGE(
            0, j288_robot_config_write_joint(link, "knee", &u, g_err, sizeof g_err), g_err);
        TEST_ASSERT_EQUAL_STRING(before, read_text(path));
        u.phase = 0.5;
        TEST_ASSERT_EQUAL_INT_MESSAGE(
            0, j288_robot_config_write_joint(link, "knee", &u, g_err, sizeof g_err), g_err);
        n = readlink(link, target, sizeof target - 1u);
        TEST_ASSERT_EQUAL_INT(10, n);
        TEST_ASSERT_NOT_NULL(strstr(read_text(path), "    phase: 0.5\n"));
    }
    /* A refused edit leaves the file as it was. */
    {
        char before[8192];
        (void)snprintf(before, sizeof before, "%s", read_text(path));
        TEST_ASSERT_EQUAL_INT(-1, j288_robot_config_write_joint(path, "hip_x", &u, g_err, sizeof g_err));
        TEST_ASSERT_EQUAL_STRING(before, read_text(path));
    }
    TEST_ASSERT_EQUAL_INT(0, unlink(link));
    TEST_ASSERT_EQUAL_INT(0, unlink(path));
    TEST_ASSERT_EQUAL_INT(-1, j288_robot_config_write_joint(path, "a", &u, g_err, sizeof g_err));
    TEST_ASSERT_NOT_NULL(strstr(g_err, "No such file"));
    TEST_ASSERT_EQUAL_INT(-1, j288_robot_config_load(path, &g_cfg, g_err, sizeof g_err));
    TEST_ASSERT_NOT_NULL(strstr(g_err, "robot.yaml: cannot read: No such file"));
}

/* A relative port is beside the config file, wherever the program runs. */
static void test_file_relative_port(void)
{
    char path[128], want[192];
    (void)snprintf(path, sizeof path, "%s/robot.yaml", g_dir);
    write_text(path, "buses:\n  - {name: a, port: sim/bus0}\n  - {name: b, port: ./b}\n"
                     "  - {name: c, port: /dev/ttyUSB0}\njoints: []\n");
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, j288_robot_config_load(path, &g_cfg, g_err, sizeof g_err), g_err);
    (void)snprintf(want, sizeof want, "%s/sim/bus0", g_dir);
    TEST_ASSERT_EQUAL_STRING(want, g_cfg.bus[0].port);
    (void)snprintf(want, sizeof want, "%s/./b", g_dir);
    TEST_ASSERT_EQUAL_STRING(want, g_cfg.bus[1].port);
    TEST_ASSERT_EQUAL_STRING("/dev/ttyUSB0", g_cfg.bus[2].port);
    /* From memory there is no folder: as written. */
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, parse("buses:\n  - {name: a, port: sim/bus0}\n"), g_err);
    TEST_ASSERT_EQUAL_STRING("sim/bus0", g_cfg.bus[0].port);
    TEST_ASSERT_EQUAL_INT(0, unlink(path));
}

/* A read-only config is refused before anything is read or written, root or not: renaming a
 * new file over it in a writable folder would otherwise replace it without asking. */
static void test_file_read_only(void)
{
    char path[128];
    j288_robot_config_update_t u = phase_upd(1.0);
    const char *text = "joints:\n  - name: a\n    id: 1\n";
    (void)snprintf(path, sizeof path, "%s/robot.yaml", g_dir);
    write_text(path, text);
    TEST_ASSERT_EQUAL_INT(0, chmod(path, 0444));
    TEST_ASSERT_EQUAL_INT(-1, j288_robot_config_check_writable(path, g_err, sizeof g_err));
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(g_err, "robot.yaml: read-only"), g_err);
    TEST_ASSERT_EQUAL_INT(-1, j288_robot_config_write_joint(path, "a", &u, g_err, sizeof g_err));
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(g_err, "robot.yaml: read-only"), g_err);
    TEST_ASSERT_EQUAL_STRING(text, read_text(path));
    TEST_ASSERT_EQUAL_UINT(1, files_in_dir());
    TEST_ASSERT_EQUAL_INT(0, chmod(path, 0600));
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, j288_robot_config_check_writable(path, g_err, sizeof g_err),
                                  g_err);
    TEST_ASSERT_EQUAL_INT(-1, j288_robot_config_check_writable(g_dir, g_err, sizeof g_err));
    TEST_ASSERT_NOT_NULL_MESSAGE(strstr(g_err, "not a regular file"), g_err);
    TEST_ASSERT_EQUAL_INT(0, unlink(path));
}

static void make_file(const char *name)
{
    char path[192];
    (void)snprintf(path, sizeof path, "%s/%s", g_dir, name);
    write_text(path, "joints: [{name: partial");
}

static bool file_exists(const char *name)
{
    char path[192];
    struct stat st;
    (void)snprintf(path, sizeof path, "%s/%s", g_dir, name);
    return stat(path, &st) == 0;
}

/* A write-back killed after creating its temporary file leaves it; the next write-back
 * removes it when its process is gone, and leaves a live process's and foreign files. */
static void test_file_stale_temp_removed(void)
{
    char path[256], dead[96], live[96];
    j288_robot_config_update_t u = phase_upd(1.0);
    pid_t child = fork();
    TEST_ASSERT_TRUE(child >= 0);
    if (child == 0)
        _exit(0);
    TEST_ASSERT_EQUAL_INT(child, waitpid(child, NULL, 0)); /* reaped: that id is gone */
    (void)snprintf(dead, sizeof dead, ".robot.yaml.j288-%ld.Ab12Cd", (long)child);
    (void)snprintf(live, sizeof live, ".robot.yaml.j288-%ld.Ab12Cd", (long)getppid());
    make_file(dead);
    make_file(live);
    make_file(".robot.yaml.j288-notes");
    make_file(".other.yaml.j288-1.Ab12Cd");
    (void)snprintf(path, sizeof path, "%s/robot.yaml", g_dir);
    write_text(path, "joints:\n  - name: a\n    id: 1\n");
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, j288_robot_config_write_joint(path, "a", &u, g_err, sizeof g_err),
                                  g_err);
    TEST_ASSERT_FALSE(file_exists(dead));
    TEST_ASSERT_TRUE(file_exists(live));
    TEST_ASSERT_TRUE(file_exists(".robot.yaml.j288-notes"));
    TEST_ASSERT_TRUE(file_exists(".other.yaml.j288-1.Ab12Cd"));
    TEST_ASSERT_EQUAL_UINT(4, files_in_dir()); /* and none of its own */
    (void)snprintf(path, sizeof path, "%s/%s", g_dir, live);
    TEST_ASSERT_EQUAL_INT(0, unlink(path));
    (void)snprintf(path, sizeof path, "%s/.robot.yaml.j288-notes", g_dir);
    TEST_ASSERT_EQUAL_INT(0, unlink(path));
    (void)snprintf(path, sizeof path, "%s/.other.yaml.j288-1.Ab12Cd", g_dir);
    TEST_ASSERT_EQUAL_INT(0, unlink(path));
    (void)snprintf(path, sizeof path, "%s/robot.yaml", g_dir);
    TEST_ASSERT_EQUAL_INT(0, unlink(path));
}

/* A write-back killed at any point (SIGKILL: nothing runs after it) leaves the config whole,
 * old or new, and the next write-back leaves no temporary file, wherever the kill landed.
 * The kills land where they land (no timing is asserted); each round waits until the child
 * has replaced the file at least once, so that it is killed while writing on and on. */
static void test_file_killed_write_back(void)
{
    static char big[600000];
    char path[128];
    size_t n = 0, round;
    j288_robot_config_update_t u = phase_upd(0.25);
    (void)snprintf(path, sizeof path, "%s/robot.yaml", g_dir);
    n += (size_t)snprintf(big, sizeof big, "joints:\n  - name: a\n    id: 1\n    phase: 0.5\n");
    while (n + 64u < sizeof big) /* a large file: the write takes a while */
        n += (size_t)snprintf(big + n, sizeof big - n, "# padding padding padding padding\n");
    for (round = 0; round < 10u; round++) {
        struct stat st0, st;
        unsigned waited;
        pid_t child;
        write_text(path, big);
        TEST_ASSERT_EQUAL_INT(0, stat(path, &st0));
        child = fork();
        TEST_ASSERT_TRUE(child >= 0);
        if (child == 0) {
            char err[J288_ROBOT_CONFIG_ERROR_MAX];
            for (;;) {
                u.phase = (u.phase == 0.25) ? -0.25 : 0.25;
                (void)j288_robot_config_write_joint(path, "a", &u, err, sizeof err);
            }
        }
        /* Until the child has replaced the file once (a new inode), at most 60 s. */
        for (waited = 0; waited < 60000u; waited++) {
            if (stat(path, &st) == 0 && st.st_ino != st0.st_ino)
                break;
            const struct timespec ms = {0, 1000000L};
            (void)nanosleep(&ms, NULL);
        }
        TEST_ASSERT_EQUAL_INT(0, kill(child, SIGKILL));
        TEST_ASSERT_EQUAL_INT(child, waitpid(child, NULL, 0));
        TEST_ASSERT_TRUE_MESSAGE(st.st_ino != st0.st_ino, "the child never replaced the file");
        TEST_ASSERT_EQUAL_INT_MESSAGE(0, j288_robot_config_load(path, &g_cfg, g_err, sizeof g_err),
                                      g_err);
        TEST_ASSERT_EQUAL_DOUBLE(0.25, fabs(g_cfg.joint[0].phase)); /* one write or another */
        TEST_ASSERT_EQUAL_INT_MESSAGE(
            0, j288_robot_config_write_joint(path, "a", &u, g_err, sizeof g_err), g_err);
        TEST_ASSERT_EQUAL_UINT(1, files_in_dir());
    }
    TEST_ASSERT_EQUAL_INT(0, unlink(path));
}

/* The example every doc points at is a file this reader takes. */
static void test_example_loads(void)
{
    TEST_ASSERT_EQUAL_INT_MESSAGE(
        0, j288_robot_config_load(J288_EXAMPLE_CONFIG, &g_cfg, g_err, sizeof g_err), g_err);
    TEST_ASSERT_TRUE(g_cfg.nbuses >= 1u);
    TEST_ASSERT_TRUE(g_cfg.njoints >= 2u);
}

static void test_file_too_large(void)
{
    char path[128];
    FILE *f;
    size_t i;
    (void)snprintf(path, sizeof path, "%s/big.yaml", g_dir);
    f = fopen(path, "wb");
    TEST_ASSERT_NOT_NULL(f);
    for (i = 0; i <= J288_ROBOT_CONFIG_FILE_MAX / 16u; i++)
        (void)fputs("# padding......\n", f);
    (void)fclose(f);
    TEST_ASSERT_EQUAL_INT(-1, j288_robot_config_load(path, &g_cfg, g_err, sizeof g_err));
    TEST_ASSERT_NOT_NULL(strstr(g_err, "larger than 1048576 bytes"));
    TEST_ASSERT_EQUAL_INT(0, unlink(path));
}

int main(void)
{
    (void)snprintf(g_dir, sizeof g_dir, "/tmp/j288-config-XXXXXX");
    if (mkdtemp(g_dir) == NULL) {
        perror("mkdtemp");
        return 1;
    }
    UNITY_BEGIN();
    RUN_TEST(test_full_file);
    RUN_TEST(test_defaults);
    RUN_TEST(test_joint_config);
    RUN_TEST(test_byte_order_mark_crlf_and_unicode);
    RUN_TEST(test_errors_keys);
    RUN_TEST(test_errors_types);
    RUN_TEST(test_numbers_as_on_the_command_line);
    RUN_TEST(test_errors_ranges);
    RUN_TEST(test_errors_tags);
    RUN_TEST(test_errors_depth);
    RUN_TEST(test_errors_values);
    RUN_TEST(test_errors_across_entries);
    RUN_TEST(test_errors_capacity);
    RUN_TEST(test_errors_malformed);
    RUN_TEST(test_edit_replaces_in_place);
    RUN_TEST(test_edit_adds_missing_key);
    RUN_TEST(test_edit_line_endings_and_unicode);
    RUN_TEST(test_edit_value_format);
    RUN_TEST(test_edit_refusals);
    RUN_TEST(test_file_round_trip);
    RUN_TEST(test_file_relative_port);
    RUN_TEST(test_file_read_only);
    RUN_TEST(test_file_stale_temp_removed);
    RUN_TEST(test_file_killed_write_back);
    RUN_TEST(test_example_loads);
    RUN_TEST(test_file_too_large);
    (void)rmdir(g_dir);
    return UNITY_END();
}

#else /* no libyaml in this build */

/* Built without libyaml: the functions say so. CI installs libyaml-dev, so there this is a
 * failure. */
static void test_without_libyaml(void)
{
    const char *ci = getenv("CI");
    TEST_ASSERT_FALSE(j288_robot_config_available());
    TEST_ASSERT_EQUAL_INT(-1, j288_robot_config_load("robot.yaml", &g_cfg, g_err, sizeof g_err));
    TEST_ASSERT_NOT_NULL(strstr(g_err, "robot.yaml: robot config files need libyaml"));
    if (ci != NULL && strcmp(ci, "true") == 0)
        TEST_FAIL_MESSAGE("built without libyaml under CI=true: install libyaml-dev");
    (void)g_out;
    (void)g_outlen;
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_without_libyaml);
    return UNITY_END();
}

#endif
