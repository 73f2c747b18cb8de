/*
 * A typical MCU user of j288, linked only to measure it (make size): the STM32 port on one
 * UART, the bus engine, the cycle scheduler, SI conversion and error strings. Never run.
 * With SIZE_PROBE_JOINTQ (the FPU-less build, J288_CONFIG_SI=0): the joint core (j288/jointq.h)
 * for 15 joints bound to the scheduler instead of the SI conversion.
 */
#include <stdint.h>

#include "j288/j288.h"
#include "j288_stm32.h"

#ifndef SIZE_PROBE_JOINTQ
#define SIZE_PROBE_JOINTQ 0
#endif

extern uint32_t _estack;
void Reset_Handler(void);
int main(void);

__attribute__((section(".isr_vector"), used)) void (*const probe_vectors[2])(void) = {
    (void (*)(void))(uintptr_t)&_estack, Reset_Handler};

void Reset_Handler(void)
{
    (void)main();
    for (;;) {
    }
}

/* Application state, kept apart so that its RAM shows per object (nm). */
J288_STM32_DMA_BUFFER(probe_dma);
j288_stm32_t probe_port;
j288_sched_t probe_sched;

#if SIZE_PROBE_JOINTQ
j288_jointq_t probe_joints[J288_MAX_SERVOS];
j288_jointq_bus_t probe_jbus;
#endif

static UART_HandleTypeDef huart;
static TIM_HandleTypeDef htim;
static CRC_HandleTypeDef hcrc;
static volatile uint32_t tick;
static volatile int sink;

static uint32_t now_us(void) { return tick; }

static void uart_irq(void) { j288_stm32_on_uart_irq(&probe_port); }
static void dma_rx_irq(void) { j288_stm32_on_dma_rx_irq(&probe_port); }
void HAL_TIM_OC_DelayElapsedCallback(TIM_HandleTypeDef *h) { (void)j288_stm32_on_timer(h); }

/* The bus's interrupt handlers (the UART's and the RX stream's call the port, the timer's the
 * HAL, which calls the callback): kept here as the vector table keeps them, so that the event
 * calls count in the sizes. */
__attribute__((section(".isr_vector"), used)) const uintptr_t probe_callbacks[3] = {
    (uintptr_t)uart_irq, (uintptr_t)dma_rx_irq, (uintptr_t)HAL_TIM_OC_DelayElapsedCallback};

int main(void)
{
    j288_stm32_config_t pc = {0};
    pc.huart = &huart;
    pc.dma = &probe_dma;
    pc.now_us = now_us;
    pc.htim = &htim;
    pc.tim_channel = TIM_CHANNEL_1;
    pc.hcrc = &hcrc;
    if (j288_stm32_init(&probe_port, &pc, NULL) != J288_OK) {
        return 1;
    }
#if SIZE_PROBE_JOINTQ
    {
        /* 15 joints on the scheduler, targets set from the main loop below. */
        j288_sched_config_t sc = {0};
        j288_jointq_config_t jc = {0};
        uint8_t id;
        sc.on_reply = j288_jointq_bus_on_reply;
        sc.user = &probe_jbus;
        (void)j288_sched_init(&probe_sched, j288_stm32_bus(&probe_port), &sc);
        (void)j288_jointq_bus_init(&probe_jbus, &probe_sched, NULL, NULL);
        for (id = 0u; id < J288_MAX_SERVOS; id++) {
            jc.id = id;
            (void)j288_jointq_init(&probe_joints[id], &jc);
            (void)j288_jointq_bus_add(&probe_jbus, &probe_joints[id]);
            (void)j288_sched_enable(&probe_sched, id, true);
        }
    }
#else
    {
        j288_cmd_raw_t cmd = {0};
        (void)j288_sched_init(&probe_sched, j288_stm32_bus(&probe_port), NULL);
        (void)j288_sched_enable(&probe_sched, 0u, true);
        (void)j288_sched_set_cmd(&probe_sched, &cmd);
    }
#endif
#if J288_CONFIG_SI
    {
        j288_cmd_si_t si = {0};
        j288_reply_si_t rsi;
        (void)j288_sched_set_cmd_si(&probe_sched, &si, J288_SIDE_OUTPUT);
        sink = j288_reply_to_si(&j288_sched_slot(&probe_sched, 0u)->reply, J288_SIDE_OUTPUT, &rsi);
    }
#endif
    for (;;) {
        if (!j288_sched_busy(&probe_sched)) {
            sink = j288_sched_start_sweep(&probe_sched, tick);
        }
        j288_sched_poll(&probe_sched, tick);
#if SIZE_PROBE_JOINTQ
        {
            j288_jointq_target_t t;
            uint8_t id = (uint8_t)(tick % J288_MAX_SERVOS);
            j288_jointq_target_init(&probe_joints[id], &t);
            sink = j288_jointq_bus_set_target(&probe_jbus, &probe_joints[id], &t, NULL);
        }
#endif
        if (sink == J288_ERR_OFFLINE) {
            (void)j288_sched_estop(&probe_sched, tick);
            sink = (int)j288_strerror(sink)[0];
        }
    }
}
