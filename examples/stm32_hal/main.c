/*
 * j288 firmware example: a 1 kHz control loop over four servos (ids 0-3) on one bus, with the
 * cycle scheduler, the CRC unit as the frame CRC, and a safe stop. The same file runs on each
 * board (board.h): NUCLEO-F446RE (nucleo_f446re/board.c, the reference board), NUCLEO-G474RE
 * (nucleo_g474re/board.c); `make firmware` builds both against ST's HAL.
 *
 * Hardware (as configured in the board file, the part CubeMX would generate):
 *   USART1 in single-wire half-duplex mode on PA9 (Arduino D8) at exactly 6 Mbps, a DMA
 *   stream/channel each way (TX normal mode, RX circular), byte width; TIM2 free running at 1 MHz (32 bits):
 *   the microsecond tick and, on channel 1, the reply timeout; the CRC unit in its reset
 *   configuration; the blue user button B1 (PC13) as emergency stop.
 *
 * Loop: every 1000 us the main loop writes the four commands (a slow 0.5 Hz sweep of +-0.2 rad
 * at the output shaft around each servo's starting position) and starts a sweep; the sweep
 * itself runs from the UART/DMA/timer interrupts (advance_in_isr), four transactions of about
 * 130 us each. Safe stop: the button, a servo going offline, any fault bit, a tripped servo
 * watchdog, or three control periods in a row whose sweep had not finished, make the loop
 * broadcast "lock" (j288_sched_estop) and keep re-broadcasting it every 100 ms; leaving the
 * stop needs a reset. The servos' own 1 s communication watchdog (enabled in every command)
 * locks them should this firmware stop talking altogether.
 */
#include <math.h>
#include <stdbool.h>
#include <stdint.h>

#include "main.h"

/* Where the bus DMA buffers go: the linker script's .dma_buffer, in plain SRAM. */
#define J288_STM32_DMA_SECTION __attribute__((section(".dma_buffer")))

#include "board.h"
#include "j288/j288.h"
#include "j288_stm32.h"

#define SERVO_COUNT 4u
#define LOOP_PERIOD_US 1000u
#define STOP_REPEAT_US 100000u
#define MAX_OVERRUNS 3u

#define SWEEP_AMPLITUDE_RAD 0.2f
#define SWEEP_HZ 0.5f
#define STIFFNESS_OUT 20.0f /* N*m/rad at the output shaft */
#define DAMPING_OUT 0.5f    /* N*m*s/rad at the output shaft */

/* DMA buffers in plain SRAM (not the F4's CCM RAM, which the DMA cannot reach). */
J288_STM32_DMA_BUFFER(bus1_dma);
static j288_stm32_t bus1;
static j288_sched_t sched;

static volatile bool stop_requested;
static volatile uint32_t stop_cause; /* the j288_event_kind_t bit, or 1u << 31 for overruns */
static float home_rad[SERVO_COUNT];
static bool home_known[SERVO_COUNT];

/* ---- interrupts: the bus UART's and RX stream's go to the port, the timer's via the HAL ---- */

void board_bus_uart_irq(void) { j288_stm32_on_uart_irq(&bus1); }
void board_bus_dma_rx_irq(void) { j288_stm32_on_dma_rx_irq(&bus1); }

void HAL_TIM_OC_DelayElapsedCallback(TIM_HandleTypeDef *htim) { (void)j288_stm32_on_timer(htim); }

/* ---- scheduler events (interrupt context: record only) --------------------------------- */

static void on_servo_event(void *user, const j288_event_t *ev)
{
    (void)user;
    switch (ev->kind) {
    case J288_EV_OFFLINE:
    case J288_EV_WATCHDOG_TRIPPED:
        stop_cause |= 1u << (unsigned)ev->kind;
        stop_requested = true;
        break;
    case J288_EV_FAULTS_CHANGED:
        if (ev->new_bits != 0u) {
            stop_cause |= 1u << (unsigned)ev->kind;
            stop_requested = true;
        }
        break;
    default:
        break;
    }
}

/* ---- control ----------------------------------------------------------------------------- */

static void learn_home_positions(void)
{
    for (uint8_t id = 0; id < SERVO_COUNT; id++) {
        const j288_slot_t *slot = j288_sched_slot(&sched, id);
        if (!home_known[id] && (slot != NULL) && slot->has_reply) {
            home_rad[id] = (float)j288_pos_from_raw(slot->reply.pos, J288_SIDE_OUTPUT);
            home_known[id] = true;
        }
    }
}

/* FOC commands once a servo's position is known; until then a lock command that only
 * collects its reply. */
static int write_commands(uint32_t now_us)
{
    const float t = (float)now_us * 1e-6f;
    const float offset = SWEEP_AMPLITUDE_RAD * sinf(2.0f * 3.14159265f * SWEEP_HZ * t);
    int rc = J288_OK;

    learn_home_positions();
    for (uint8_t id = 0; (id < SERVO_COUNT) && (rc == J288_OK); id++) {
        j288_cmd_si_t c = {0};
        c.id = id;
        c.watchdog = true;
        if (home_known[id]) {
            c.status = J288_MODE_FOC;
            c.pos = home_rad[id] + offset;
            c.kp = STIFFNESS_OUT;
            c.kd = DAMPING_OUT;
        } else {
            c.status = J288_MODE_LOCK;
        }
        rc = j288_sched_set_cmd_si(&sched, &c, J288_SIDE_OUTPUT);
    }
    return rc;
}

/* Broadcast lock now, and again every STOP_REPEAT_US, forever. */
static void safe_stop_forever(void)
{
    uint32_t last = j288_stm32_now_us(&bus1);
    (void)j288_sched_estop(&sched, last);
    for (;;) {
        uint32_t now = j288_stm32_now_us(&bus1);
        j288_sched_poll(&sched, now);
        if ((uint32_t)(now - last) >= STOP_REPEAT_US) {
            last = now;
            (void)j288_bus_estop(j288_stm32_bus(&bus1), now);
        }
    }
}

static void bus_setup(void)
{
    j288_stm32_config_t pc = {0};
    j288_bus_config_t bc = {0};
    j288_sched_config_t sc = {0};

    pc.huart = &huart1;
    pc.dma = &bus1_dma;
    pc.now_us = NULL; /* TIM2's 32-bit counter at 1 MHz is the tick */
    pc.htim = &htim2;
    pc.tim_channel = TIM_CHANNEL_1;
    pc.hcrc = &hcrc;
    pc.irq_priority = BOARD_BUS_IRQ_PRIORITY; /* the bus lock masks the bus's interrupts only */

    bc.advance_in_isr = true; /* sweeps run back to back from the interrupts */

    sc.on_event = on_servo_event;

    if ((j288_stm32_init(&bus1, &pc, &bc) != J288_OK) ||
        (j288_sched_init(&sched, j288_stm32_bus(&bus1), &sc) != J288_OK)) {
        /* a refused configuration: bus1.init_error in the debugger, or
         * j288_stm32_init_error_str(j288_stm32_init_error(&bus1)) */
        board_fatal();
    }
    for (uint8_t id = 0; id < SERVO_COUNT; id++) {
        (void)j288_sched_enable(&sched, id, true);
    }
}

int main(void)
{
    uint32_t next_tick;
    unsigned overruns = 0u;

    board_init();
    bus_setup();

    next_tick = j288_stm32_now_us(&bus1);
    for (;;) {
        uint32_t now = j288_stm32_now_us(&bus1);

        if (stop_requested || board_estop_pressed()) {
            safe_stop_forever();
        }
        j288_sched_poll(&sched, now);
        if ((int32_t)(now - next_tick) < 0) {
            continue;
        }
        next_tick += LOOP_PERIOD_US;
        if (j288_sched_busy(&sched)) {
            if (++overruns >= MAX_OVERRUNS) {
                stop_cause |= 1u << 31;
                stop_requested = true;
            }
            continue;
        }
        overruns = 0u;
        if ((write_commands(now) != J288_OK) || (j288_sched_start_sweep(&sched, now) != J288_OK)) {
            stop_requested = true;
        }
    }
}
