/*
 * Minimal startup for the link check of the example against the HAL stub (an STM32F4: F405,
 * F407, F446 share these vectors): vector table with the interrupts the example uses, .data
 * copy, .bss clear, FPU enable, main(). The firmware (`make firmware`) and CubeMX projects use
 * ST's startup_stm32f4xx.s; this one exists so that the example links without ST's files.
 */
#include <stdint.h>

extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _estack;
extern int main(void);

void Reset_Handler(void);
void Default_Handler(void);
void USART1_IRQHandler(void);
void DMA2_Stream2_IRQHandler(void);
void TIM2_IRQHandler(void);
void SysTick_Handler(void);

void Reset_Handler(void)
{
    uint32_t *src = &_sidata;
    for (uint32_t *dst = &_sdata; dst < &_edata; dst++) {
        *dst = *src++;
    }
    for (uint32_t *dst = &_sbss; dst < &_ebss; dst++) {
        *dst = 0u;
    }
    *(volatile uint32_t *)0xE000ED88u |= (0xFu << 20); /* CP10/CP11: the FPU */
    __asm volatile("dsb\n\tisb" ::: "memory");
    (void)main();
    for (;;) {
    }
}

void Default_Handler(void)
{
    for (;;) {
    }
}

void SysTick_Handler(void) {}

typedef void (*vector_t)(void);
#define IRQ(n) (16 + (n))

__attribute__((section(".isr_vector"), used)) const vector_t example_vectors[16 + 82] = {
    [0] = (vector_t)(uintptr_t)&_estack,
    [1] = Reset_Handler,
    [2] = Default_Handler,  /* NMI */
    [3] = Default_Handler,  /* HardFault */
    [4] = Default_Handler,  /* MemManage */
    [5] = Default_Handler,  /* BusFault */
    [6] = Default_Handler,  /* UsageFault */
    [11] = Default_Handler, /* SVCall */
    [14] = Default_Handler, /* PendSV */
    [15] = SysTick_Handler,
    [IRQ(28)] = TIM2_IRQHandler,
    [IRQ(37)] = USART1_IRQHandler,
    [IRQ(58)] = DMA2_Stream2_IRQHandler,
};
