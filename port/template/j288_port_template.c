/*
 * j288_port_template.c - annotated skeleton of a j288 port; see j288_port_template.h and
 * docs/porting.md. Every "TODO" is a hardware access you write for your MCU. Nothing here
 * allocates, blocks or busy-waits.
 */
#include "j288_port_template.h"

#include <string.h>

/* ------------------------------------------------------------------------------------------
 * start_tx (REQUIRED). Called by the bus from where it advances: j288_bus_poll() in thread
 * context, or an ISR when the bus advances there (advance_in_isr). So it must be ISR-safe:
 * no blocking, no waiting for the transmit to end.
 *
 * data is the bus's own 20-byte buffer (inside j288_bus_t). It stays untouched until you
 * call j288_bus_on_tx_done(), so the DMA may read it directly. On a Cortex-M7 with D-cache,
 * clean it to memory first (cleaning whole cache lines around it is harmless), or copy the
 * 20 bytes into a buffer in non-cacheable RAM and send from there.
 *
 * The bus has already called set_dir(J288_DIR_TX) (and, with config.echo, start_rx).
 * Return 0, or a negative code (e.g. the UART is not ready): the attempt then fails with
 * J288_ERR_PORT, and is retried if the bus is configured for retries.
 * ---------------------------------------------------------------------------------------- */
static int port_start_tx(void *ctx, const uint8_t *data, size_t len)
{
    j288_port_template_t *p = (j288_port_template_t *)ctx;
    (void)p;
    (void)data;
    (void)len;
    /* TODO Cortex-M7 with D-cache: SCB_CleanDCache_by_Addr((uint32_t *)((uintptr_t)data &
     *      ~31u), 64);
     * TODO clear the UART's transmission-complete flag, enable its TC interrupt, and start
     *      the transmit DMA: e.g. HAL_UART_Transmit_DMA(p->uart, data, len). Report the end
     *      from the TC interrupt (j288_port_template_tx_complete_isr), not from the DMA's
     *      transfer-complete, which fires while the last byte is still being shifted out.
     * An OS-like driver whose write completes at once may call j288_bus_on_tx_done(&p->bus)
     * right here, before returning: the bus expects that. */
    return 0;
}

/* ------------------------------------------------------------------------------------------
 * now_us (REQUIRED). Monotonic microseconds, wrapping at 2^32 (the bus compares modulo
 * 2^32). Any context, so read a free-running counter: a 32-bit timer clocked at 1 MHz, or
 * DWT->CYCCNT / (SystemCoreClock / 1000000) on a Cortex-M3/4/7 (mind that the cycle counter
 * wraps long before 2^32 us: keep a 32-bit microsecond count then). Never a counter that
 * only advances in an interrupt of lower priority than the UART.
 * ---------------------------------------------------------------------------------------- */
static uint32_t port_now_us(void *ctx)
{
    (void)ctx;
    return 0u; /* TODO: return TIMx->CNT; (a 32-bit timer at 1 MHz) */
}

/* ------------------------------------------------------------------------------------------
 * start_rx (optional). The bus calls it from j288_bus_on_tx_done(), i.e. in your TC
 * interrupt, so the receiver listens before the servo answers (the reply starts within tens
 * of microseconds). With a circular receive DMA that runs all the time there is nothing to
 * do: leave the pointer NULL instead. With a one-shot "receive to idle" DMA, re-arm it here.
 * With config.echo the bus calls it before start_tx instead (the receiver must hear our own
 * frame).
 * ---------------------------------------------------------------------------------------- */
static void port_start_rx(void *ctx)
{
    j288_port_template_t *p = (j288_port_template_t *)ctx;
    (void)p;
    /* TODO one-shot DMA only: HAL_UARTEx_ReceiveToIdle_DMA(p->uart, p->rx_dma,
     *      sizeof p->rx_dma); p->rx_read_pos = 0; */
}

/* ------------------------------------------------------------------------------------------
 * set_dir (optional). A DE/RE pin or a half-duplex switch: J288_DIR_TX just before
 * start_tx, J288_DIR_RX from j288_bus_on_tx_done() (interrupt context). A single-wire UART
 * in half-duplex mode (STM32 HDSEL) turns its transmitter off by itself: NULL is fine.
 * ---------------------------------------------------------------------------------------- */
static void port_set_dir(void *ctx, j288_dir_t dir)
{
    (void)ctx;
    (void)dir;
    /* TODO: HAL_GPIO_WritePin(DE_GPIO_Port, DE_Pin, dir == J288_DIR_TX ? GPIO_PIN_SET
     *                                                                 : GPIO_PIN_RESET); */
}

/* ------------------------------------------------------------------------------------------
 * arm_timeout (optional, recommended). One-shot: call j288_bus_on_timer() at or soon after
 * deadline_us (same clock as now_us). Re-arming replaces the previous deadline. The bus arms
 * it for every reply deadline and every guard gap; without it, the application must call
 * j288_bus_poll() often enough, and back-to-back sweeps from interrupts stall at each guard.
 * A compare channel of the now_us timer is ideal: CCR = deadline, enable its interrupt. If
 * the deadline has already passed, fire at once (set the interrupt pending).
 * ---------------------------------------------------------------------------------------- */
static void port_arm_timeout(void *ctx, uint32_t deadline_us)
{
    j288_port_template_t *p = (j288_port_template_t *)ctx;
    (void)p;
    (void)deadline_us;
    /* TODO: __HAL_TIM_SET_COMPARE(p->timer, TIM_CHANNEL_1, deadline_us);
     *       __HAL_TIM_CLEAR_FLAG(...); __HAL_TIM_ENABLE_IT(p->timer, TIM_IT_CC1);
     *       if ((int32_t)(deadline_us - port_now_us(p)) <= 0) set the interrupt pending. */
}

/* ------------------------------------------------------------------------------------------
 * crc32 (optional). A CRC unit that computes the manual's crc32_core (STM32: the CRC
 * peripheral in its reset configuration). data is NOT necessarily 4-byte aligned: assemble
 * each little-endian word from bytes. Called from where the bus advances (poll or ISR); if
 * other code shares the CRC unit, protect it. NULL: the software table.
 * ---------------------------------------------------------------------------------------- */
static uint32_t port_crc32(void *ctx, const uint8_t *data, size_t nwords)
{
    (void)ctx;
    /* TODO: CRC->CR = CRC_CR_RESET; for each word: CRC->DR = j288_get_u32le(&data[4 * i]);
     *       return CRC->DR; -- until then, the software backend: */
    return j288_crc32(data, nwords);
}

/* ------------------------------------------------------------------------------------------
 * lock / unlock (optional, as a pair). Only used with config.advance_in_isr: the bus wraps
 * its thread-context entry points (submit, poll, estop, scheduler changes) in them, so that
 * the UART, DMA and timer interrupts, which advance the same bus, cannot run in between.
 * Mask exactly those interrupts (they share one priority, see docs/porting.md), or all of
 * them with PRIMASK / BASEPRI. Never called from interrupt context, never nested.
 * ---------------------------------------------------------------------------------------- */
static void port_lock(void *ctx)
{
    j288_port_template_t *p = (j288_port_template_t *)ctx;
    p->irq_state = 0u; /* TODO: p->irq_state = __get_PRIMASK(); __disable_irq(); */
}

static void port_unlock(void *ctx)
{
    j288_port_template_t *p = (j288_port_template_t *)ctx;
    (void)p->irq_state; /* TODO: __set_PRIMASK(p->irq_state); */
}

/* wait is for OS ports (j288_bus_transfer_blocking); an MCU port leaves it out. */
const j288_port_t j288_port_template_ops = {
    .start_tx = port_start_tx,
    .now_us = port_now_us,
    .start_rx = port_start_rx, /* leave out with an always-running circular DMA */
    .set_dir = port_set_dir,   /* leave out without a DE pin */
    .arm_timeout = port_arm_timeout,
    .crc32 = port_crc32, /* leave out: software CRC */
    .lock = port_lock,
    .unlock = port_unlock,
};

int j288_port_template_init(j288_port_template_t *p, const j288_bus_config_t *cfg)
{
    if (p == NULL) {
        return J288_ERR_NULL;
    }
    memset(p->rx_dma, 0, sizeof p->rx_dma);
    p->rx_read_pos = 0u;
    /* TODO: configure the UART (6 Mbps 8N1, single-wire half duplex or DE pin), its DMA
     *       channels, the microsecond timer; give the UART, both DMA channels and the timer
     *       ONE interrupt priority; start the circular receive DMA into p->rx_dma. */
    return j288_bus_init(&p->bus, &j288_port_template_ops, p, cfg);
}

/* ---- interrupt glue ------------------------------------------------------------------- */

void j288_port_template_tx_complete_isr(j288_port_template_t *p)
{
    /* TODO: disable the TC interrupt / clear its flag. */
    j288_bus_on_tx_done(&p->bus); /* switches to RX (set_dir, start_rx) at once */
}

void j288_port_template_rx_event_isr(j288_port_template_t *p, uint32_t dma_pos, bool idle)
{
    uint32_t pos = (dma_pos >= J288_PORT_TEMPLATE_RX_DMA_SIZE) ? 0u : dma_pos;

    /* TODO Cortex-M7 with D-cache (buffer not in non-cacheable RAM):
     *      SCB_InvalidateDCache_by_Addr((uint32_t *)p->rx_dma, sizeof p->rx_dma);
     *      (rx_dma must be 32-byte aligned and a multiple of 32 bytes long, else the
     *      invalidation throws away neighbouring data.) */
    if (pos > p->rx_read_pos) {
        j288_bus_on_rx(&p->bus, &p->rx_dma[p->rx_read_pos], pos - p->rx_read_pos);
    } else if (pos < p->rx_read_pos) { /* the DMA wrapped: the tail, then the head */
        j288_bus_on_rx(&p->bus, &p->rx_dma[p->rx_read_pos],
                       J288_PORT_TEMPLATE_RX_DMA_SIZE - p->rx_read_pos);
        if (pos > 0u) {
            j288_bus_on_rx(&p->bus, p->rx_dma, pos);
        }
    }
    p->rx_read_pos = pos;
    if (idle) {
        j288_bus_on_rx_idle(&p->bus);
    }
}

void j288_port_template_error_isr(j288_port_template_t *p, uint32_t line_flags)
{
    /* TODO: read and clear the UART's error flags (ORE/FE/NE/PE) and map them:
     *       FE -> J288_LINE_FRAMING, NE -> J288_LINE_NOISE, ORE -> J288_LINE_OVERRUN,
     *       PE -> J288_LINE_PARITY, a DMA transfer error -> J288_LINE_DMA. Restart the
     *       receive DMA if the HAL stopped it. */
    j288_bus_on_error(&p->bus, line_flags);
}

void j288_port_template_timer_isr(j288_port_template_t *p)
{
    /* TODO: clear the compare flag and disable the compare interrupt (one-shot). */
    j288_bus_on_timer(&p->bus);
}
