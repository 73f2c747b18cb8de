/*
 * board_fault.c - the NUCLEO boards' HardFault handler (Cortex-M3/M4/M7: the fault status
 * registers of the SCB): records what a debugger needs in board_fault, then stops. The
 * firmware falls silent, and every servo locks itself when its watchdog (enabled in every
 * command) sees no frame for a second. Not in the stub's link check: the stub has no SCB.
 */
#include "board.h"

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
