/* Unit tests of the j288 tool's parsing and output helpers (tools/j288): hex text, strict
 * numbers, id lists, the option scanner, the JSON writer and fault names. Every refusal must
 * print exactly one error line. */
#include "unity.h"

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "args.h"
#include "cli.h"
#include "cli_capture.h"
#include "frameview.h"
#include "hexparse.h"
#include "json.h"

static FILE *err;

void setUp(void) { err = cli_capture_begin(); }

void tearDown(void) { cli_capture_end(); }

static void assert_no_error(void)
{
    char line[256];
    TEST_ASSERT_EQUAL_INT_MESSAGE(0, cli_error_lines(line, sizeof line), line);
}

/* ---- hex ------------------------------------------------------------------------------------- */

static void test_hex_forms_agree(void)
{
    static const char *const forms[] = {"fe ee 80", "FEEE80",       "0xfe,0xee,0x80",
                                        "fe:ee:80", " fe\tee\n80 ", "0xFE 0XEE 0x80"};
    size_t i;
    for (i = 0; i < sizeof forms / sizeof forms[0]; i++) {
        uint8_t b[4] = {0};
        size_t len = 0;
        char msg[64];
        TEST_ASSERT_EQUAL_INT_MESSAGE(
            0, cli_hex_parse(forms[i], b, sizeof b, &len, msg, sizeof msg), forms[i]);
        TEST_ASSERT_EQUAL_UINT(3, len);
        TEST_ASSERT_EQUAL_HEX8(0xfe, b[0]);
        TEST_ASSERT_EQUAL_HEX8(0xee, b[1]);
        TEST_ASSERT_EQUAL_HEX8(0x80, b[2]);
    }
}

static void test_hex_single_digit_after_prefix(void)
{
    uint8_t b[4] = {0xAA, 0xAA, 0xAA, 0xAA};
    size_t len = 0;
    char msg[64];
    TEST_ASSERT_EQUAL_INT(0, cli_hex_parse("0x0,0x1,0xf", b, sizeof b, &len, msg, sizeof msg));
    TEST_ASSERT_EQUAL_UINT(3, len);
    TEST_ASSERT_EQUAL_HEX8(0x00, b[0]);
    TEST_ASSERT_EQUAL_HEX8(0x01, b[1]);
    TEST_ASSERT_EQUAL_HEX8(0x0f, b[2]);
    TEST_ASSERT_EQUAL_HEX8(0xAA, b[3]);
}

static void test_hex_refusals(void)
{
    uint8_t b[4];
    size_t len = 0;
    char msg[96];
    TEST_ASSERT_EQUAL_INT(-1, cli_hex_parse("fee", b, sizeof b, &len, msg, sizeof msg));
    TEST_ASSERT_NOT_NULL(strstr(msg, "odd number of hex digits (3)"));
    TEST_ASSERT_EQUAL_INT(-1, cli_hex_parse("fe eg", b, sizeof b, &len, msg, sizeof msg));
    TEST_ASSERT_NOT_NULL(strstr(msg, "'g' at character 5"));
    TEST_ASSERT_EQUAL_INT(-1, cli_hex_parse("fe\x01", b, sizeof b, &len, msg, sizeof msg));
    TEST_ASSERT_NOT_NULL(strstr(msg, "byte 0x01"));
    TEST_ASSERT_EQUAL_INT(-1, cli_hex_parse(" , ", b, sizeof b, &len, msg, sizeof msg));
    TEST_ASSERT_NOT_NULL(strstr(msg, "no hex digits"));
    /* "0x" in the middle of a byte is not a prefix. */
    TEST_ASSERT_EQUAL_INT(-1, cli_hex_parse("f0x1", b, sizeof b, &len, msg, sizeof msg));
}

static void test_hex_counts_beyond_capacity(void)
{
    uint8_t b[2] = {0, 0};
    size_t len = 0;
    char msg[64];
    TEST_ASSERT_EQUAL_INT(0, cli_hex_parse("01 02 03 04 05", b, sizeof b, &len, msg, sizeof msg));
    TEST_ASSERT_EQUAL_UINT(5, len);
    TEST_ASSERT_EQUAL_HEX8(0x01, b[0]);
    TEST_ASSERT_EQUAL_HEX8(0x02, b[1]);
}

static void test_hex_format(void)
{
    static const uint8_t b[3] = {0x00, 0xab, 0xF0};
    char text[7];
    cli_hex_format(b, sizeof b, text);
    TEST_ASSERT_EQUAL_STRING("00abf0", text);
}

/* ---- numbers --------------------------------------------------------------------------------- */

static void test_int_accepts(void)
{
    long long v = 0;
    TEST_ASSERT_EQUAL_INT(0, cli_parse_int("--x", "0x10", 0, 100, &v));
    TEST_ASSERT_EQUAL_INT64(16, v);
    TEST_ASSERT_EQUAL_INT(0, cli_parse_int("--x", "-32768", INT16_MIN, INT16_MAX, &v));
    TEST_ASSERT_EQUAL_INT64(-32768, v);
    TEST_ASSERT_EQUAL_INT(0, cli_parse_int("--x", "+7", 0, 10, &v));
    TEST_ASSERT_EQUAL_INT64(7, v);
    TEST_ASSERT_EQUAL_INT(0, cli_parse_int("--x", "-0x80000000", INT32_MIN, INT32_MAX, &v));
    TEST_ASSERT_EQUAL_INT64(INT32_MIN, v);
    assert_no_error();
}

static void test_int_refusals(void)
{
    static const char *const bad[] = {"3x", " 3", "", "0x", "+-3", "--1", "1.0", "3 ", "x"};
    size_t i;
    for (i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        long long v = 42;
        rewind(err);
        TEST_ASSERT_EQUAL_INT_MESSAGE(-1, cli_parse_int("--id", bad[i], 0, 100, &v), bad[i]);
        TEST_ASSERT_EQUAL_INT64(42, v);
    }
}

static void test_int_range_message(void)
{
    long long v = 42;
    TEST_ASSERT_EQUAL_INT(-1, cli_parse_int("--id", "16", 0, 15, &v));
    cli_expect_one_error("j288 test: --id: 16 is out of range 0..15");
    TEST_ASSERT_EQUAL_INT64(42, v);
}

static void test_int_overflow(void)
{
    long long v = 42;
    TEST_ASSERT_EQUAL_INT(
        -1, cli_parse_int("--pos-raw", "99999999999999999999", INT32_MIN, INT32_MAX, &v));
    cli_expect_one_error("out of range");
}

static void test_real(void)
{
    double v = 0.0;
    TEST_ASSERT_EQUAL_INT(0, cli_parse_real("--tau", "1e-3", &v));
    TEST_ASSERT_EQUAL_DOUBLE(1e-3, v);
    TEST_ASSERT_EQUAL_INT(0, cli_parse_real("--tau", "-.5", &v));
    TEST_ASSERT_EQUAL_DOUBLE(-0.5, v);
    assert_no_error();
}

static void test_real_refusals(void)
{
    static const char *const bad[] = {"nan", "inf", "-inf", "1e999",  "1.5rad",
                                      "",    " 1",  ".",    "0x1p3x", "e5",
                                      "0x1p1", "0x10", "1e", "1e+", "1.2.3", "+-1", "1 "};
    size_t i;
    for (i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        double v = 42.0;
        TEST_ASSERT_EQUAL_INT_MESSAGE(-1, cli_parse_real("--tau", bad[i], &v), bad[i]);
        TEST_ASSERT_EQUAL_DOUBLE(42.0, v);
    }
}

static void test_real_in_range(void)
{
    double v = 0.0;
    TEST_ASSERT_EQUAL_INT(0, cli_parse_real_in("--rate", "50", 50.0, 5000.0, &v));
    TEST_ASSERT_EQUAL_DOUBLE(50.0, v);
    TEST_ASSERT_EQUAL_INT(0, cli_parse_real_in("--rate", "5000", 50.0, 5000.0, &v));
    assert_no_error();
    TEST_ASSERT_EQUAL_INT(-1, cli_parse_real_in("--rate", "5000.1", 50.0, 5000.0, &v));
    TEST_ASSERT_EQUAL_INT(-1, cli_parse_real_in("--rate", "nan", 50.0, 5000.0, &v));
}

static void test_real_in_range_message(void)
{
    double v = 0.0;
    TEST_ASSERT_EQUAL_INT(-1, cli_parse_real_in("--rate", "49.9", 50.0, 5000.0, &v));
    cli_expect_one_error("j288 test: --rate: 49.9 is out of range 50..5000");
}

/* One range per quantity (host/j288_range.h): the option's message names it and the range
 * the robot config file checks too; the gains' bounds are the wire's. */
static void test_quantity_ranges(void)
{
    double v = -1.0;
    TEST_ASSERT_EQUAL_INT(0, cli_parse_qty(J288_QTY_MARGIN_US, "--margin-us", "10000000", &v));
    TEST_ASSERT_EQUAL_DOUBLE(10000000.0, v);
    TEST_ASSERT_EQUAL_INT(0, cli_parse_qty(J288_QTY_KP, "--kp", "2128.4", &v));
    TEST_ASSERT_EQUAL_INT(0, cli_parse_qty(J288_QTY_RETRIES, "--retries", "0x3", &v));
    TEST_ASSERT_EQUAL_DOUBLE(3.0, v);
    assert_no_error();
    TEST_ASSERT_EQUAL_INT(-1, cli_parse_qty(J288_QTY_MARGIN_US, "--margin-us", "0", &v));
    cli_expect_one_error("test: --margin-us: 0 is out of range 1..10000000");
}

static void test_quantity_refusals_name_their_source(void)
{
    double v = -1.0;
    TEST_ASSERT_EQUAL_INT(-1, cli_parse_qty(J288_QTY_BAUD, "$J288_BAUD", "fast", &v));
    cli_expect_one_error("test: $J288_BAUD: 'fast' is not a whole number");
    TEST_ASSERT_EQUAL_DOUBLE(-1.0, v);
}

static void test_quantity_gain_is_not_whole(void)
{
    double v = -1.0;
    TEST_ASSERT_EQUAL_INT(-1, cli_parse_qty(J288_QTY_KD, "--kd", "21.3", &v));
    cli_expect_one_error("test: --kd: 21.3 is out of range 0..21.284");
}

/* Every gain in range encodes; just beyond the table's bound the wire refuses. */
static void test_quantity_gains_fit_the_wire(void)
{
    int16_t raw;
    double kp = j288_range(J288_QTY_KP)->hi, kd = j288_range(J288_QTY_KD)->hi;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_kp_to_raw((j288_real_t)kp, J288_SIDE_OUTPUT, &raw));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_kd_to_raw((j288_real_t)kd, J288_SIDE_OUTPUT, &raw));
    TEST_ASSERT_EQUAL_INT(J288_ERR_RANGE_KP,
                          j288_kp_to_raw((j288_real_t)(kp * 1.0001), J288_SIDE_OUTPUT, &raw));
    TEST_ASSERT_EQUAL_INT(J288_ERR_RANGE_KD,
                          j288_kd_to_raw((j288_real_t)(kd * 1.0001), J288_SIDE_OUTPUT, &raw));
}

static void test_choice(void)
{
    static const char *const modes[] = {"lock", "foc", NULL};
    int c = -1;
    TEST_ASSERT_EQUAL_INT(0, cli_parse_choice("--mode", "foc", modes, &c));
    TEST_ASSERT_EQUAL_INT(1, c);
    TEST_ASSERT_EQUAL_INT(-1, cli_parse_choice("--mode", "FOC", modes, &c));
    cli_expect_one_error("--mode: 'FOC' is not lock or foc");
}

static void test_id_list(void)
{
    uint32_t m = 0;
    TEST_ASSERT_EQUAL_INT(0, cli_parse_id_list("--id", "1,2,14", 14, &m));
    TEST_ASSERT_EQUAL_HEX32(0x4006u, m);
    TEST_ASSERT_EQUAL_INT(0, cli_parse_id_list("--id", "0", 14, &m));
    TEST_ASSERT_EQUAL_HEX32(0x1u, m);
    assert_no_error();
}

static void test_id_list_refusals(void)
{
    static const char *const bad[] = {"", "1,", ",1", "1,,2", "15", "1,1", "a", "1;2"};
    size_t i;
    for (i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        uint32_t m = 0xdead;
        TEST_ASSERT_EQUAL_INT_MESSAGE(-1, cli_parse_id_list("--id", bad[i], 14, &m), bad[i]);
        TEST_ASSERT_EQUAL_HEX32(0xdead, m);
    }
}

/* ---- option scanner -------------------------------------------------------------------------- */

enum { K_ID, K_JSON };
static const cli_opt_t opts[] = {{"--id", true, K_ID}, {"--json", false, K_JSON}, {NULL, false, 0}};

static void test_args_forms(void)
{
    char *argv[] = {"cmd", "--id=3", "--id", "-4", "--json", "pos", "--", "--json", NULL};
    cli_args_t a;
    const char *v;
    cli_args_init(&a, 8, argv);
    TEST_ASSERT_EQUAL_INT(K_ID, cli_args_next(&a, opts, &v));
    TEST_ASSERT_EQUAL_STRING("3", v);
    TEST_ASSERT_EQUAL_INT(K_ID, cli_args_next(&a, opts, &v));
    TEST_ASSERT_EQUAL_STRING("-4", v); /* a value may start with '-' */
    TEST_ASSERT_EQUAL_INT(K_JSON, cli_args_next(&a, opts, &v));
    TEST_ASSERT_EQUAL_INT(CLI_ARG_POSITIONAL, cli_args_next(&a, opts, &v));
    TEST_ASSERT_EQUAL_STRING("pos", v);
    TEST_ASSERT_EQUAL_INT(CLI_ARG_POSITIONAL, cli_args_next(&a, opts, &v));
    TEST_ASSERT_EQUAL_STRING("--json", v); /* after "--" */
    TEST_ASSERT_EQUAL_INT(CLI_ARG_END, cli_args_next(&a, opts, &v));
    assert_no_error();
}

static void test_args_errors(void)
{
    char *missing[] = {"cmd", "--id", NULL};
    char *unknown[] = {"cmd", "--idd=1", NULL};
    char *flagval[] = {"cmd", "--json=1", NULL};
    char *prefix[] = {"cmd", "--i", NULL};
    char *help[] = {"cmd", "-h", NULL};
    cli_args_t a;
    const char *v;
    cli_args_init(&a, 2, missing);
    TEST_ASSERT_EQUAL_INT(CLI_ARG_ERROR, cli_args_next(&a, opts, &v));
    cli_expect_one_error("option --id needs a value");
    rewind(err);
    cli_args_init(&a, 2, unknown);
    TEST_ASSERT_EQUAL_INT(CLI_ARG_ERROR, cli_args_next(&a, opts, &v));
    cli_args_init(&a, 2, flagval);
    TEST_ASSERT_EQUAL_INT(CLI_ARG_ERROR, cli_args_next(&a, opts, &v));
    cli_args_init(&a, 2, prefix); /* no abbreviations */
    TEST_ASSERT_EQUAL_INT(CLI_ARG_ERROR, cli_args_next(&a, opts, &v));
    cli_args_init(&a, 2, help);
    TEST_ASSERT_EQUAL_INT(CLI_ARG_HELP, cli_args_next(&a, opts, &v));
}

/* ---- JSON ------------------------------------------------------------------------------------ */

static void test_json_writer(void)
{
    char buf[512];
    size_t n;
    FILE *f = tmpfile();
    cli_json_t j;
    cli_json_init(&j, f);
    cli_json_begin_object(&j, NULL);
    cli_json_str(&j, "s", "a\"b\\c\n\x01");
    cli_json_int(&j, "i", -5);
    cli_json_uint(&j, "u", 4294967295ull);
    cli_json_real(&j, "r", 0.25);
    cli_json_real(&j, "nan", NAN);
    cli_json_real(&j, "negzero", -0.0);
    cli_json_bool(&j, "b", true);
    cli_json_begin_array(&j, "a");
    cli_json_int(&j, NULL, 1);
    cli_json_begin_object(&j, NULL);
    cli_json_end_object(&j);
    cli_json_end_array(&j);
    cli_json_begin_array(&j, "empty");
    cli_json_end_array(&j);
    cli_json_end_object(&j);
    cli_json_newline(&j);
    rewind(f);
    n = fread(buf, 1, sizeof buf - 1u, f);
    buf[n] = '\0';
    fclose(f);
    TEST_ASSERT_EQUAL_STRING("{\"s\": \"a\\\"b\\\\c\\n\\u0001\", \"i\": -5, \"u\": 4294967295, "
                             "\"r\": 0.25, \"nan\": null, \"negzero\": 0, \"b\": true, "
                             "\"a\": [1, {}], \"empty\": []}\n",
                             buf);
}

/* ---- names ----------------------------------------------------------------------------------- */

static void test_fault_list(void)
{
    char buf[256];
    TEST_ASSERT_EQUAL_STRING("none", cli_fault_list(0, buf, sizeof buf));
    TEST_ASSERT_EQUAL_STRING(
        "over-current, unknown fault (bit 22)",
        cli_fault_list(J288_FAULT_OVER_CURRENT | (1ul << 22), buf, sizeof buf));
    TEST_ASSERT_EQUAL_STRING("none", cli_warning_list(0, buf, sizeof buf));
    TEST_ASSERT_NOT_NULL(strstr(cli_warning_list(6, buf, sizeof buf), "(bit 2)"));
}

static void test_fault_list_truncates_safely(void)
{
    char buf[16];
    memset(buf, 'x', sizeof buf);
    cli_fault_list(0xFFFFFFFFu, buf, sizeof buf);
    TEST_ASSERT_EQUAL_UINT(15, strlen(buf));
}

static void test_mode_names(void)
{
    TEST_ASSERT_EQUAL_STRING("lock", cli_mode_name(0));
    TEST_ASSERT_EQUAL_STRING("foc", cli_mode_name(1));
    TEST_ASSERT_EQUAL_STRING("status 7", cli_mode_name(7));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_hex_forms_agree);
    RUN_TEST(test_hex_single_digit_after_prefix);
    RUN_TEST(test_hex_refusals);
    RUN_TEST(test_hex_counts_beyond_capacity);
    RUN_TEST(test_hex_format);
    RUN_TEST(test_int_accepts);
    RUN_TEST(test_int_refusals);
    RUN_TEST(test_int_range_message);
    RUN_TEST(test_int_overflow);
    RUN_TEST(test_real);
    RUN_TEST(test_real_refusals);
    RUN_TEST(test_real_in_range);
    RUN_TEST(test_real_in_range_message);
    RUN_TEST(test_quantity_ranges);
    RUN_TEST(test_quantity_refusals_name_their_source);
    RUN_TEST(test_quantity_gain_is_not_whole);
    RUN_TEST(test_quantity_gains_fit_the_wire);
    RUN_TEST(test_choice);
    RUN_TEST(test_id_list);
    RUN_TEST(test_id_list_refusals);
    RUN_TEST(test_args_forms);
    RUN_TEST(test_args_errors);
    RUN_TEST(test_json_writer);
    RUN_TEST(test_fault_list);
    RUN_TEST(test_fault_list_truncates_safely);
    RUN_TEST(test_mode_names);
    return UNITY_END();
}
