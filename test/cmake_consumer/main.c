/* Consumer check: encode the protocol's worked lock frame through an installed or embedded
 * j288 and compare it byte for byte. Exit status 0 on success. */
#include <stdio.h>
#include <string.h>

#include "j288/j288.h"

int main(void)
{
    static const uint8_t want[J288_CMD_LEN] = {0xfe, 0xee, 0x80, 0, 0, 0, 0,    0,    0,    0,
                                               0,    0,    0,    0, 0, 0, 0x1d, 0x99, 0xfb, 0x6e};
    j288_cmd_raw_t cmd;
    uint8_t out[J288_CMD_LEN];
    memset(&cmd, 0, sizeof cmd);
    cmd.watchdog = true;
    if (j288_cmd_encode(&cmd, out, NULL) != J288_OK || memcmp(out, want, sizeof want) != 0) {
        fprintf(stderr, "j288 consumer: wrong frame\n");
        return 1;
    }
    printf("j288 %s consumer: ok\n", J288_VERSION_STRING);
    return 0;
}
