/*
 * The spec's worked command as a j288_cmd_raw_t: FOC servo 3, watchdog on, pos 5215, k_pos
 * 1280, k_spd 12800 (its 20 bytes are in test/unit/test_bus.c, from the spec). Header only, so
 * that the bus benchmark on the target, which links no test/support source, shares it too
 * (test/target/bench.c fills the same command field by field inside its counted loop: a
 * struct returned by value there would change the figures docs/performance.md quotes).
 */
#ifndef J288_TEST_WORKED_CMD_H
#define J288_TEST_WORKED_CMD_H

#include <string.h>

#include "j288/j288.h"

static inline j288_cmd_raw_t worked_cmd(void)
{
    j288_cmd_raw_t c;
    memset(&c, 0, sizeof c);
    c.id = 3u;
    c.status = J288_MODE_FOC;
    c.watchdog = true;
    c.pos = 5215;
    c.kp = 1280;
    c.kd = 12800;
    return c;
}

#endif /* J288_TEST_WORKED_CMD_H */
