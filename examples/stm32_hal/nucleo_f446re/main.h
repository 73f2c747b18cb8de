/* main.h - what CubeMX's main.h does for the port and the example: bring in the family's HAL. */
#ifndef J288_NUCLEO_F446RE_MAIN_H
#define J288_NUCLEO_F446RE_MAIN_H
#include "stm32f4xx_hal.h"
#endif
