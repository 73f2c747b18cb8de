/* Smoke test of the build skeleton: the spec's worked frames, byte for byte. */
#include "unity.h"

#include "j288/j288.h"

#include <string.h>

void setUp(void) {}
void tearDown(void) {}

static void test_worked_lock_frame(void)
{
    static const uint8_t want[J288_CMD_LEN] = {0xfe, 0xee, 0x80, 0, 0, 0, 0, 0, 0, 0,
                                               0,    0,    0,    0, 0, 0, 0x1d, 0x99, 0xfb, 0x6e};
    j288_cmd_raw_t cmd = {0};
    uint8_t out[J288_CMD_LEN];
    cmd.watchdog = true;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_cmd_encode(&cmd, out, NULL));
    TEST_ASSERT_EQUAL_HEX8_ARRAY(want, out, J288_CMD_LEN);
}

static void test_crc_check_value(void)
{
    TEST_ASSERT_EQUAL_HEX32(0x0376E6E7u,
                            j288_crc32_mpeg2_bytes((const uint8_t *)"123456789", 9u));
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_worked_lock_frame);
    RUN_TEST(test_crc_check_value);
    return UNITY_END();
}
