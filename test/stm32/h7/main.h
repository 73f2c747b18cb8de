/* main.h - for the port's compile check against ST's STM32H7 HAL (mk/firmware.mk). */
#ifndef J288_H7_CHECK_MAIN_H
#define J288_H7_CHECK_MAIN_H
#include "stm32h7xx_hal.h"
#endif
