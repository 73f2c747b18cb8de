/*
 * hal_conf_common.h - the part of the HAL configuration both boards share, included by each
 * board's stm32<family>xx_hal_conf.h (which adds its oscillator values and its family's
 * module headers): the HAL modules the firmware uses, SysTick's priority, flash accelerators,
 * callbacks by weak function.
 */
#ifndef J288_EXAMPLE_HAL_CONF_COMMON_H
#define J288_EXAMPLE_HAL_CONF_COMMON_H

#define HAL_MODULE_ENABLED
#define HAL_CORTEX_MODULE_ENABLED
#define HAL_CRC_MODULE_ENABLED
#define HAL_DMA_MODULE_ENABLED
#define HAL_FLASH_MODULE_ENABLED
#define HAL_GPIO_MODULE_ENABLED
#define HAL_PWR_MODULE_ENABLED
#define HAL_RCC_MODULE_ENABLED
#define HAL_TIM_MODULE_ENABLED
#define HAL_UART_MODULE_ENABLED

#define VDD_VALUE 3300U
#define TICK_INT_PRIORITY 0x0FU /* SysTick lowest: HAL_GetTick only feeds timeouts */
#define USE_RTOS 0U
#define PREFETCH_ENABLE 1U
#define INSTRUCTION_CACHE_ENABLE 1U
#define DATA_CACHE_ENABLE 1U
#define USE_SPI_CRC 0U

/* Callbacks are the weak functions the application overrides (the port relies on it). */
#define USE_HAL_TIM_REGISTER_CALLBACKS 0U
#define USE_HAL_UART_REGISTER_CALLBACKS 0U

#define assert_param(expr) ((void)0U)

#endif /* J288_EXAMPLE_HAL_CONF_COMMON_H */
