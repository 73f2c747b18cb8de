/* The object named after this build's [layout] options (config.h, bus.h): a program built
 * with other values refers to another name and does not link. */
#include "j288/bus.h"

const unsigned char J288_ABI_TAG = 1u;
