/*
 * board_nucleo.c - what both NUCLEO boards share against ST's HAL, whatever the family (not
 * the stub's link check: the stub has no RCC, MSP or SCB): the timer's and the CRC unit's MSP,
 * SysTick, and the HardFault handler.
 */
#include "board_common.h"

void HAL_TIM_Base_MspInit(TIM_HandleTypeDef *htim)
{
    if (htim->Instance == TIM2) {
        __HAL_RCC_TIM2_CLK_ENABLE();
        board_timer_irq_enable();
    }
}

void HAL_CRC_MspInit(CRC_HandleTypeDef *h)
{
    (void)h;
    __HAL_RCC_CRC_CLK_ENABLE();
}

void SysTick_Handler(void) { HAL_IncTick(); }

/* Faults: record the fault status registers (Cortex-M3/M4/M7's SCB) and the stacked PC in
 * board_fault for a debugger, then stop. The firmware falls silent, and every servo locks
 * itself when its watchdog (enabled in every command) sees no frame for a second. */
void board_fault_record(const uint32_t *frame);
void board_fault_record(const uint32_t *frame)
{
    board_fault.cfsr = SCB->CFSR;
    board_fault.hfsr = SCB->HFSR;
    board_fault.mmfar = SCB->MMFAR;
    board_fault.bfar = SCB->BFAR;
    board_fault.pc = frame[6];
    board_fault.lr = frame[5];
    board_fault.count++;
    board_fatal();
}

/* Naked: pick the stack the fault frame was pushed on (MSP or PSP, bit 2 of EXC_RETURN). */
__attribute__((naked)) void HardFault_Handler(void)
{
    __asm volatile("tst lr, #4\n\t"
                   "ite eq\n\t"
                   "mrseq r0, msp\n\t"
                   "mrsne r0, psp\n\t"
                   "b board_fault_record\n\t");
}
/* MemManage, BusFault and UsageFault are not enabled (SHCSR), so they escalate to HardFault. */
