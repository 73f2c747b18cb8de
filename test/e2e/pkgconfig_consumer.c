/*
 * A program built the pkg-config way against an installed j288 (scripts/check-consumers.sh):
 *   cc main.c $(pkg-config --cflags --libs j288)
 * It uses the library (the protocol's worked frame), the Linux port and the runner from the
 * shared library, and prints the version it linked.
 */
#include <stdio.h>
#include <string.h>

#include "j288/j288.h"
#include "j288_robot.h"

int main(void)
{
    static const char expect[] = "feee9300000000005f14000000050032a64b303f";
    j288_cmd_raw_t cmd;
    uint8_t out[J288_CMD_LEN];
    char hex[2 * J288_CMD_LEN + 1];
    size_t i;
    memset(&cmd, 0, sizeof cmd);
    cmd.id = 3;
    cmd.status = J288_MODE_FOC;
    cmd.watchdog = true;
    cmd.pos = 5215;
    cmd.kp = 1280;
    cmd.kd = 12800;
    if (j288_cmd_encode(&cmd, out, NULL) != J288_OK)
        return 1;
    for (i = 0; i < J288_CMD_LEN; i++)
        (void)snprintf(hex + 2 * i, 3, "%02x", out[i]);
    if (strcmp(hex, expect) != 0 || !j288_serial_baud_ok(6000000u, 6000000u) ||
        strcmp(j288_robot_version(), J288_VERSION_STRING) != 0) {
        fprintf(stderr, "pkgconfig_consumer: got %s\n", hex);
        return 1;
    }
    printf("frame ok, libj288 %s\n", j288_robot_version());
    return 0;
}
