/*
 * main.h - stand-in for the main.h that STM32CubeMX generates (which includes the family's
 * HAL header, e.g. stm32f4xx_hal.h). The port includes J288_STM32_HAL_HEADER, "main.h" by
 * default, so the same source finds this stub here and the real HAL in a CubeMX project.
 */
#ifndef J288_STUB_MAIN_H
#define J288_STUB_MAIN_H
#include "stm32_hal_stub.h"
#endif
