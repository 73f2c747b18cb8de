/* A user configuration for bench-bus-target: the CRC unit as the compile-time backend, its
 * function static inline here, so that the library inlines it where a frame is built or
 * checked (the word count a constant there). */
#ifndef J288_USER_CONFIG_H
#define J288_USER_CONFIG_H

#include "../crc_unit_model.h"

#define J288_CONFIG_CRC_BACKEND 4 /* J288_CRC_BACKEND_HW */
#define J288_CONFIG_CRC_HW_FUNCTION bench_crc_unit_inline

#endif
