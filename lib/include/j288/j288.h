/*
 * j288/j288.h - umbrella header for the j288 servo bus library.
 */
#ifndef J288_J288_H
#define J288_J288_H

#include "j288/config.h"
#include "j288/error.h"
#include "j288/crc32.h"
#include "j288/frame.h"
#include "j288/units.h"
#include "j288/parser.h"
#include "j288/port.h"
#include "j288/bus.h"
#include "j288/sched.h"
#include "j288/joint.h"
#include "j288/jointq.h"

#define J288_VERSION_MAJOR 0
#define J288_VERSION_MINOR 1
#define J288_VERSION_PATCH 0
#define J288_VERSION_STRING "0.1.0"

#endif /* J288_J288_H */
