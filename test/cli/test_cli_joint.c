/* Unit tests of the j288 tool's robot config and joint selection (tools/j288/cli_joint.c):
 * --id / --joint / --config resolved to a joint configuration and the bus options, with
 * exactly one error line for every refusal. */
#define _XOPEN_SOURCE 700 /* mkdtemp under -std=c99 */

#include "unity.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cli_bus.h"
#include "cli_capture.h"

static cli_robot_t robot;
static char dir[64];
static char path[128];

void setUp(void)
{
    cli_capture_begin();
    memset(&robot, 0, sizeof robot);
}

void tearDown(void)
{
    cli_capture_end();
}

static void opts(cli_bus_opts_t *o)
{
    cli_global_t g;
    memset(&g, 0, sizeof g);
    cli_bus_opts_init(o, &g);
}

/* No file: the id's all-zero configuration, the library's defaults filled in by the library
 * (j288_joint_config()): the range [-pi, pi], 8 start samples, direction +1. */
static void test_no_config(void)
{
    cli_bus_opts_t o;
    cli_joint_sel_t sel;
    char line[200];
    opts(&o);
    TEST_ASSERT_EQUAL_INT(0, cli_robot_load(&robot, NULL));
    TEST_ASSERT_EQUAL_INT(0, cli_joint_select(&robot, NULL, 3, &o, &sel));
    TEST_ASSERT_EQUAL_UINT8(3, sel.id);
    TEST_ASSERT_NULL(sel.rj);
    TEST_ASSERT_EQUAL_STRING("servo 3", sel.name);
    TEST_ASSERT_EQUAL_UINT8(3, sel.jc.id);
    TEST_ASSERT_FALSE(sel.jc.has_phase || sel.jc.clamp);
    TEST_ASSERT_EQUAL_DOUBLE((double)(j288_real_t)-J288_PI, (double)sel.jc.pos_min);
    TEST_ASSERT_EQUAL_DOUBLE((double)(j288_real_t)J288_PI, (double)sel.jc.pos_max);
    TEST_ASSERT_EQUAL_UINT8(8, sel.jc.init_samples);
    TEST_ASSERT_EQUAL_INT8(1, sel.jc.direction);
    TEST_ASSERT_NULL(o.port);
    TEST_ASSERT_EQUAL_INT(0, cli_error_lines(line, sizeof line));
}

static void test_no_config_refusals(void)
{
    cli_bus_opts_t o;
    cli_joint_sel_t sel;
    opts(&o);
    TEST_ASSERT_EQUAL_INT(-1, cli_joint_select(&robot, "hip", -1, &o, &sel));
    cli_expect_one_error("--joint hip needs --config FILE");
}

static void test_neither_or_both(void)
{
    cli_bus_opts_t o;
    cli_joint_sel_t sel;
    opts(&o);
    TEST_ASSERT_EQUAL_INT(-1, cli_joint_select(&robot, NULL, -1, &o, &sel));
    cli_expect_one_error("--id N or --joint NAME is required");
}

static void test_both(void)
{
    cli_bus_opts_t o;
    cli_joint_sel_t sel;
    opts(&o);
    TEST_ASSERT_EQUAL_INT(-1, cli_joint_select(&robot, "hip", 1, &o, &sel));
    cli_expect_one_error("exclude each other");
}

/* The range of a configuration the library filled in ([-pi, pi] when both limits were 0); the
 * configured one; clamp allows all; a continuous joint has no range. */
static void test_pos_allowed(void)
{
    j288_joint_config_t jc;
    j288_joint_t j;
    memset(&jc, 0, sizeof jc);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&j, &jc));
    jc = *j288_joint_config(&j);
    TEST_ASSERT_TRUE(cli_joint_pos_allowed(&jc, 3.14));
    TEST_ASSERT_TRUE(cli_joint_pos_allowed(&jc, -3.14));
    TEST_ASSERT_FALSE(cli_joint_pos_allowed(&jc, 3.15));
    TEST_ASSERT_FALSE(cli_joint_pos_allowed(&jc, -3.15));
    jc.pos_min = (j288_real_t)5.8;
    jc.pos_max = (j288_real_t)6.8;
    TEST_ASSERT_TRUE(cli_joint_pos_allowed(&jc, 6.2));
    TEST_ASSERT_FALSE(cli_joint_pos_allowed(&jc, 0.0));
    jc.clamp = true;
    TEST_ASSERT_TRUE(cli_joint_pos_allowed(&jc, 0.0));
    memset(&jc, 0, sizeof jc);
    jc.continuous = true;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_joint_init(&j, &jc));
    jc = *j288_joint_config(&j);
    TEST_ASSERT_TRUE(cli_joint_pos_allowed(&jc, 100.0));
    TEST_ASSERT_EQUAL_DOUBLE(-7.0, cli_joint_nearest_inside(&jc, -7.0));
}

#ifdef J288_HAVE_LIBYAML

static void write_config(const char *text)
{
    FILE *f = fopen(path, "w");
    TEST_ASSERT_NOT_NULL(f);
    fputs(text, f);
    fclose(f);
}

static const char k_two_buses[] = "buses:\n"
                                  "  - name: left\n"
                                  "    port: /dev/left\n"
                                  "    baud: 4000000\n"
                                  "    margin_us: 3000\n"
                                  "    echo: true\n"
                                  "  - {name: right, port: /dev/right}\n"
                                  "joints:\n"
                                  "  - name: hip\n"
                                  "    bus: left\n"
                                  "    id: 1\n"
                                  "    direction: -1\n"
                                  "    limits: [-1, 1]\n"
                                  "  - {name: hip_r, bus: right, id: 1}\n"
                                  "  - {name: knee, bus: left, id: 2, zero: 0.5}\n";

/* By name: the file's joint, and its bus's options where the command line left them open. */
static void test_by_name_fills_bus(void)
{
    cli_bus_opts_t o;
    cli_joint_sel_t sel;
    write_config(k_two_buses);
    opts(&o);
    TEST_ASSERT_EQUAL_INT(0, cli_robot_load(&robot, path));
    TEST_ASSERT_EQUAL_INT(0, cli_joint_select(&robot, "hip", -1, &o, &sel));
    TEST_ASSERT_NOT_NULL(sel.rj);
    TEST_ASSERT_EQUAL_STRING("joint hip", sel.name);
    TEST_ASSERT_EQUAL_UINT8(1, sel.id);
    TEST_ASSERT_EQUAL_INT8(-1, sel.jc.direction);
    TEST_ASSERT_EQUAL_DOUBLE(-1.0, (double)sel.jc.pos_min);
    TEST_ASSERT_EQUAL_STRING("/dev/left", o.port);
    TEST_ASSERT_EQUAL_UINT32(4000000u, o.baud);
    TEST_ASSERT_EQUAL_UINT32(3000u, o.margin_us);
    TEST_ASSERT_TRUE(o.echo);
    /* The command line wins. */
    opts(&o);
    o.port = "/dev/given";
    o.baud = 1000000u;
    o.margin_us = 7u;
    TEST_ASSERT_EQUAL_INT(0, cli_joint_select(&robot, "hip_r", -1, &o, &sel));
    TEST_ASSERT_EQUAL_STRING("/dev/given", o.port);
    TEST_ASSERT_EQUAL_UINT32(1000000u, o.baud);
    TEST_ASSERT_EQUAL_UINT32(7u, o.margin_us);
}

/* By id: ambiguous across buses until --port names one; an id not in the file is the
 * library's default joint. */
static void test_by_id(void)
{
    cli_bus_opts_t o;
    cli_joint_sel_t sel;
    write_config(k_two_buses);
    TEST_ASSERT_EQUAL_INT(0, cli_robot_load(&robot, path));
    opts(&o);
    o.port = "/dev/right";
    TEST_ASSERT_EQUAL_INT(0, cli_joint_select(&robot, NULL, 1, &o, &sel));
    TEST_ASSERT_NOT_NULL(sel.rj);
    TEST_ASSERT_EQUAL_STRING("hip_r", sel.rj->name);
    opts(&o);
    TEST_ASSERT_EQUAL_INT(0, cli_joint_select(&robot, NULL, 5, &o, &sel));
    TEST_ASSERT_NULL(sel.rj);
    TEST_ASSERT_EQUAL_STRING("servo 5", sel.name);
    opts(&o);
    TEST_ASSERT_EQUAL_INT(-1, cli_joint_select(&robot, NULL, 1, &o, &sel));
    cli_expect_one_error("id 1 is used on 2 buses");
}

static void test_unknown_name(void)
{
    cli_bus_opts_t o;
    cli_joint_sel_t sel;
    write_config(k_two_buses);
    TEST_ASSERT_EQUAL_INT(0, cli_robot_load(&robot, path));
    opts(&o);
    TEST_ASSERT_EQUAL_INT(-1, cli_joint_select(&robot, "ankle", -1, &o, &sel));
    cli_expect_one_error("no joint named 'ankle'");
}

/* A value the library would refuse (|zero| > 64) is refused by the file already, with its
 * line, key and value. */
static void test_library_refusal_names_the_line(void)
{
    char text[sizeof k_two_buses + 8], want[200];
    (void)snprintf(text, sizeof text, "%.*s100}\n", (int)(sizeof k_two_buses - 6u), k_two_buses);
    write_config(text);
    TEST_ASSERT_EQUAL_INT(-1, cli_robot_load(&robot, path));
    snprintf(want, sizeof want, "%s:15: joint 'knee': zero: 100 is out of range (-64 to 64)", path);
    cli_expect_one_error(want);
}

static void test_load_error(void)
{
    char want[200];
    write_config("joints:\n  - name: a\n    id: 99\n");
    TEST_ASSERT_EQUAL_INT(-1, cli_robot_load(&robot, path));
    snprintf(want, sizeof want, "%s:3: ", path);
    cli_expect_one_error(want);
}

#endif

int main(void)
{
    UNITY_BEGIN();
    strcpy(dir, "/tmp/j288-cli-joint.XXXXXX");
    if (mkdtemp(dir) == NULL) {
        return 1;
    }
    snprintf(path, sizeof path, "%s/robot.yaml", dir);
    RUN_TEST(test_no_config);
    RUN_TEST(test_no_config_refusals);
    RUN_TEST(test_neither_or_both);
    RUN_TEST(test_both);
    RUN_TEST(test_pos_allowed);
#ifdef J288_HAVE_LIBYAML
    RUN_TEST(test_by_name_fills_bus);
    RUN_TEST(test_by_id);
    RUN_TEST(test_unknown_name);
    RUN_TEST(test_library_refusal_names_the_line);
    RUN_TEST(test_load_error);
#endif
    (void)unlink(path);
    (void)rmdir(dir);
    return UNITY_END();
}
