/*
 * Minimal Cortex-M startup for the unit tests under QEMU with semihosting: vector table,
 * .data copy, .bss clear, FPU enable on hard-float builds, semihosting stdio, then
 * exit(main()). Our own Reset_Handler: newlib's rdimon crt0 asks QEMU for a heap address
 * and hangs there. Any fault ends the run with status 127, so a crash is a failed test, never
 * a hang.
 */
#include <stdint.h>
#include <stdlib.h>

extern uint32_t _sidata, _sdata, _edata, _sbss, _ebss, _estack;
extern void initialise_monitor_handles(void);
extern int main(void);

void Reset_Handler(void);
void Fault_Handler(void);
void Default_Handler(void);

void Reset_Handler(void)
{
    uint32_t *src = &_sidata;
    for (uint32_t *dst = &_sdata; dst < &_edata; dst++) {
        *dst = *src++;
    }
    for (uint32_t *dst = &_sbss; dst < &_ebss; dst++) {
        *dst = 0u;
    }
#if defined(__ARM_ARCH_6M__)
    /* ARMv6-M code may run on the M3 machine when it needs more RAM than the micro:bit has:
     * trap unaligned accesses there as a Cortex-M0 would (CCR.UNALIGN_TRP; read-only and
     * already set on a real M0). */
    *(volatile uint32_t *)0xE000ED14u |= (1u << 3);
#endif
#if defined(__ARM_FP)
    /* CP10 and CP11 full access, before any floating-point instruction runs. */
    *(volatile uint32_t *)0xE000ED88u |= (0xFu << 20);
    __asm volatile("dsb\n\tisb" ::: "memory");
#endif
    initialise_monitor_handles();
    exit(main());
}

void Fault_Handler(void)
{
    _Exit(127);
}

void Default_Handler(void)
{
    _Exit(126);
}

typedef void (*vector_t)(void);

__attribute__((section(".isr_vector"), used)) const vector_t j288_target_vectors[16] = {
    (vector_t)(uintptr_t)&_estack,
    Reset_Handler,
    Fault_Handler, /* NMI */
    Fault_Handler, /* HardFault */
    Fault_Handler, /* MemManage */
    Fault_Handler, /* BusFault */
    Fault_Handler, /* UsageFault */
    0, 0, 0, 0,
    Default_Handler, /* SVCall */
    Default_Handler, /* DebugMon */
    0,
    Default_Handler, /* PendSV */
    Default_Handler, /* SysTick */
};
