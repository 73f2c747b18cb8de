/* A program that sets up a bus: test/abi/check-abi.sh builds it with the library's [layout]
 * options (it must link and run) and with other values (it must not link). */
#include "j288/j288.h"

int main(void)
{
    static j288_bus_t bus;
    return j288_bus_init(&bus, NULL, NULL, NULL) == J288_ERR_NULL ? 0 : 1;
}
