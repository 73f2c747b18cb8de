/*
 * stm32g4xx_hal_conf.h - the HAL configuration of the NUCLEO-G474RE firmware (the HAL includes
 * this file by name): the oscillator values and the family's module headers; the rest is
 * ../hal_conf_common.h.
 */
#ifndef STM32G4xx_HAL_CONF_H
#define STM32G4xx_HAL_CONF_H

/* The NUCLEO-G474RE's HSE is a 24 MHz crystal (X3). */
#define HSE_VALUE 24000000UL
#define HSE_STARTUP_TIMEOUT 100UL
#define HSI_VALUE 16000000UL
#define HSI48_VALUE 48000000UL
#define LSI_VALUE 32000UL
#define LSE_VALUE 32768UL
#define LSE_STARTUP_TIMEOUT 5000UL
#define EXTERNAL_CLOCK_VALUE 48000UL

#include "../hal_conf_common.h" /* modules, SysTick priority, callbacks */

#include "stm32g4xx_hal_rcc.h"
#include "stm32g4xx_hal_gpio.h"
#include "stm32g4xx_hal_dma.h"
#include "stm32g4xx_hal_cortex.h"
#include "stm32g4xx_hal_crc.h"
#include "stm32g4xx_hal_flash.h"
#include "stm32g4xx_hal_pwr.h"
#include "stm32g4xx_hal_tim.h"
#include "stm32g4xx_hal_uart.h"

#endif /* STM32G4xx_HAL_CONF_H */
