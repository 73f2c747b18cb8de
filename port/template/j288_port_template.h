/*
 * j288_port_template.h - annotated skeleton of a j288 port for a new MCU.
 *
 * Copy port/template/ to port/<your_mcu>/, rename "template" to your MCU, and fill in every
 * place marked TODO. docs/porting.md walks through it. The skeleton compiles as it is (every
 * hardware access is a TODO that does nothing), so you can build your copy first and then
 * bring it to life one operation at a time.
 *
 * The shape most MCUs want (and the one this skeleton assumes):
 * - transmit by DMA from the bus's own 20-byte buffer, "transmission complete" interrupt
 *   (the last stop bit has left, not just the last byte written) -> j288_bus_on_tx_done();
 * - receive by circular DMA into a port-owned buffer; the half-transfer, transfer-complete
 *   and idle-line interrupts forward the new bytes -> j288_bus_on_rx() (+ _on_rx_idle());
 * - UART error interrupt -> j288_bus_on_error();
 * - a one-shot hardware timer -> j288_bus_on_timer();
 * - a free-running 32-bit microsecond counter for now_us;
 * - optionally a DE/RE pin for an RS-485 style transceiver (set_dir).
 *
 * One j288_port_template_t per UART: several buses in one program are fine.
 */
#ifndef J288_PORT_TEMPLATE_H
#define J288_PORT_TEMPLATE_H

#include <stdbool.h>
#include <stdint.h>

#include "j288/bus.h"
#include "j288/port.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Receive DMA buffer size: a power of two >= 64 is convenient (echo 20 + reply 26 fit, and
 * the half-transfer interrupt fires every 32 bytes). On a Cortex-M7 with D-cache keep it a
 * multiple of the 32-byte cache line (see docs/porting.md, "D-cache"). */
#ifndef J288_PORT_TEMPLATE_RX_DMA_SIZE
#define J288_PORT_TEMPLATE_RX_DMA_SIZE 64u
#endif

typedef struct {
    j288_bus_t bus; /* the engine; the application reaches it as &port->bus */

    /* Receive DMA target, written by the DMA engine only. On a Cortex-M7 put it in a
     * non-cacheable MPU region, or keep it 32-byte aligned and invalidate before reading
     * (the skeleton marks the spot). */
    uint8_t rx_dma[J288_PORT_TEMPLATE_RX_DMA_SIZE];
    uint32_t rx_read_pos; /* next rx_dma index not yet forwarded to the bus (ISR only) */

    /* TODO: your handles, e.g. UART_HandleTypeDef *huart, TIM_HandleTypeDef *htim, the DE
     * pin's port and pin. They are only used by the port operations below. */
    void *uart;
    void *timer;

    uint32_t irq_state; /* saved interrupt mask for lock/unlock */
} j288_port_template_t;

/* The operations table: hand &j288_port_template_ops and the port object to j288_bus_init().
 * Defined const so that it lives in flash. */
extern const j288_port_t j288_port_template_ops;

/* Set up the hardware (TODO in the .c) and the bus. cfg may be NULL (defaults: 6 Mbps,
 * MCU margins, advance in poll). Thread only, before interrupts are enabled. */
int j288_port_template_init(j288_port_template_t *p, const j288_bus_config_t *cfg);

/* Interrupt glue: call these from your interrupt handlers (or from the HAL's callbacks).
 * The library never defines a vector or a weak HAL callback itself. All of them run in
 * interrupt context and take a few microseconds at most. */

/* UART "transmission complete" (TC), after the transmit DMA has finished. */
void j288_port_template_tx_complete_isr(j288_port_template_t *p);

/* Receive DMA half-transfer, transfer-complete or UART idle-line event. dma_pos is the
 * index the DMA will write next (buffer size minus the DMA's remaining count). idle: the
 * event was the idle line. */
void j288_port_template_rx_event_isr(j288_port_template_t *p, uint32_t dma_pos, bool idle);

/* UART error interrupt: framing, noise, overrun or parity, as J288_LINE_* flags. */
void j288_port_template_error_isr(j288_port_template_t *p, uint32_t line_flags);

/* The one-shot timer armed by arm_timeout expired. */
void j288_port_template_timer_isr(j288_port_template_t *p);

#ifdef __cplusplus
}
#endif

#endif /* J288_PORT_TEMPLATE_H */
