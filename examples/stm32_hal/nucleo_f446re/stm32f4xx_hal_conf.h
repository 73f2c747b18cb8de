/*
 * stm32f4xx_hal_conf.h - the HAL configuration of the NUCLEO-F446RE firmware (the HAL includes
 * this file by name): the oscillator values and the family's module headers; the rest is
 * ../hal_conf_common.h.
 */
#ifndef STM32F4xx_HAL_CONF_H
#define STM32F4xx_HAL_CONF_H

/* The NUCLEO's HSE is the ST-LINK's 8 MHz MCO output (bypass mode). */
#define HSE_VALUE 8000000U
#define HSE_STARTUP_TIMEOUT 100U
#define HSI_VALUE 16000000U
#define LSI_VALUE 32000U
#define LSE_VALUE 32768U
#define LSE_STARTUP_TIMEOUT 5000U
#define EXTERNAL_CLOCK_VALUE 12288000U

#include "../hal_conf_common.h" /* modules, SysTick priority, callbacks */

#include "stm32f4xx_hal_rcc.h"
#include "stm32f4xx_hal_gpio.h"
#include "stm32f4xx_hal_dma.h"
#include "stm32f4xx_hal_cortex.h"
#include "stm32f4xx_hal_crc.h"
#include "stm32f4xx_hal_flash.h"
#include "stm32f4xx_hal_pwr.h"
#include "stm32f4xx_hal_tim.h"
#include "stm32f4xx_hal_uart.h"

#endif /* STM32F4xx_HAL_CONF_H */
