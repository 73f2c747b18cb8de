/*
 * stm32_hal_stub.c - do-nothing bodies for the HAL slice declared in stm32_hal_stub.h, so that
 * firmware built against the stub links (examples/stm32_hal). Nothing here touches hardware:
 * the image shows that the port and the example compile and link for the target, it does not
 * drive a UART. In a real project the STM32Cube HAL and CMSIS provide these functions and this
 * file is not compiled.
 */
#include "stm32_hal_stub.h"

/* The UARTs' register blocks (a device header names fixed addresses; RAM here). */
USART_TypeDef stub_usart[3];

HAL_StatusTypeDef HAL_Init(void) { return HAL_OK; }
uint32_t HAL_GetTick(void) { return 0u; }
void HAL_NVIC_SetPriority(IRQn_Type IRQn, uint32_t PreemptPriority, uint32_t SubPriority)
{
    (void)IRQn;
    (void)PreemptPriority;
    (void)SubPriority;
}
void HAL_NVIC_EnableIRQ(IRQn_Type IRQn) { (void)IRQn; }

void HAL_GPIO_WritePin(GPIO_TypeDef *GPIOx, uint16_t GPIO_Pin, GPIO_PinState PinState)
{
    GPIOx->BSRR = (PinState == GPIO_PIN_SET) ? GPIO_Pin : ((uint32_t)GPIO_Pin << 16);
}

GPIO_PinState HAL_GPIO_ReadPin(GPIO_TypeDef *GPIOx, uint16_t GPIO_Pin)
{
    return ((GPIOx->ODR & GPIO_Pin) != 0u) ? GPIO_PIN_SET : GPIO_PIN_RESET;
}

void HAL_DMA_IRQHandler(DMA_HandleTypeDef *hdma) { (void)hdma; }
HAL_DMA_StateTypeDef HAL_DMA_GetState(DMA_HandleTypeDef *hdma) { return hdma->State; }
HAL_StatusTypeDef HAL_DMA_Abort(DMA_HandleTypeDef *hdma)
{
    hdma->State = HAL_DMA_STATE_READY;
    return HAL_OK;
}

HAL_StatusTypeDef HAL_HalfDuplex_Init(UART_HandleTypeDef *huart)
{
    huart->gState = HAL_UART_STATE_READY;
    huart->RxState = HAL_UART_STATE_READY;
    return HAL_OK;
}
void HAL_UART_IRQHandler(UART_HandleTypeDef *huart) { (void)huart; }

HAL_StatusTypeDef HAL_TIM_Base_Init(TIM_HandleTypeDef *htim) { (void)htim; return HAL_OK; }
HAL_StatusTypeDef HAL_TIM_Base_Start(TIM_HandleTypeDef *htim) { (void)htim; return HAL_OK; }
void HAL_TIM_IRQHandler(TIM_HandleTypeDef *htim) { (void)htim; }

uint32_t stub_tim_read(TIM_TypeDef *tim, volatile uint32_t *reg)
{
    (void)tim;
    return *reg;
}

void stub_tim_write(TIM_TypeDef *tim, volatile uint32_t *reg, uint32_t value)
{
    (void)tim;
    *reg = value;
}

HAL_StatusTypeDef HAL_CRC_Init(CRC_HandleTypeDef *hcrc) { (void)hcrc; return HAL_OK; }

/* J288_STUB_OMIT_CRC: the benchmark brings its own CRC-unit model. */
#ifndef J288_STUB_OMIT_CRC

uint32_t HAL_CRC_Accumulate(CRC_HandleTypeDef *hcrc, uint32_t pBuffer[], uint32_t BufferLength)
{
    for (uint32_t i = 0; i < BufferLength; i++) {
        hcrc->Instance->DR = pBuffer[i];
    }
    return hcrc->Instance->DR;
}

uint32_t HAL_CRC_Calculate(CRC_HandleTypeDef *hcrc, uint32_t pBuffer[], uint32_t BufferLength)
{
    hcrc->Instance->CR = 1u; /* reset to the initial value */
    return HAL_CRC_Accumulate(hcrc, pBuffer, BufferLength);
}
#endif

#if defined(__arm__)
uint32_t __get_PRIMASK(void)
{
    uint32_t r;
    __asm volatile("mrs %0, primask" : "=r"(r));
    return r;
}
void __set_PRIMASK(uint32_t priMask) { __asm volatile("msr primask, %0" : : "r"(priMask) : "memory"); }
void __disable_irq(void) { __asm volatile("cpsid i" : : : "memory"); }
void __enable_irq(void) { __asm volatile("cpsie i" : : : "memory"); }
void __DMB(void) { __asm volatile("dmb 0xF" : : : "memory"); }
void __DSB(void) { __asm volatile("dsb 0xF" : : : "memory"); }
void __ISB(void) { __asm volatile("isb 0xF" : : : "memory"); }
#else
static uint32_t primask_shadow;
uint32_t __get_PRIMASK(void) { return primask_shadow; }
void __set_PRIMASK(uint32_t priMask) { primask_shadow = priMask; }
void __disable_irq(void) { primask_shadow = 1u; }
void __enable_irq(void) { primask_shadow = 0u; }
void __DMB(void) {}
void __DSB(void) {}
void __ISB(void) {}
#endif

#if __DCACHE_PRESENT
SCB_Type stub_scb;
MPU_Type stub_mpu;
void SCB_CleanDCache_by_Addr(volatile void *addr, int32_t dsize)
{
    (void)addr;
    (void)dsize;
}
void SCB_InvalidateDCache_by_Addr(volatile void *addr, int32_t dsize)
{
    (void)addr;
    (void)dsize;
}
#endif

/* BASEPRI on a bare variable: the link check does not run. */
static uint32_t stub_basepri;
uint32_t __get_BASEPRI(void) { return stub_basepri; }
void __set_BASEPRI(uint32_t basePri) { stub_basepri = basePri; }
void __set_BASEPRI_MAX(uint32_t basePri)
{
    if ((basePri != 0u) && ((stub_basepri == 0u) || (basePri < stub_basepri))) {
        stub_basepri = basePri;
    }
}

#if !defined(J288_STUB_ISR_USART)
/* The F4's SR (rc_w0) and DR accesses, plain. */
void stub_usart_sr_clear(USART_TypeDef *u, uint32_t bits) { u->SR = ~bits; }
uint32_t stub_usart_dr_read(USART_TypeDef *u) { return u->DR; }
#endif
