/*
 * j288_stm32.h - j288 port for the STM32Cube HAL: one bus per UART in single-wire
 * half-duplex mode, DMA both ways, idle-line reception, optional DE pin, response timeout
 * from a timer compare channel, and the CRC unit as the frame CRC.
 *
 * What the application does (see examples/stm32_hal/, docs/stm32.md and docs/porting.md):
 *  - configures each UART with HAL_HalfDuplex_Init() at the bus baud (6 Mbps), 8N1, with a
 *    DMA stream for TX (normal mode) and one for RX (circular mode recommended: a pause
 *    inside a reply then loses nothing; normal mode works, but a byte arriving while the
 *    port re-arms after an idle line, a few microseconds, is lost), byte width, both linked
 *    to the UART handle (hdmatx, hdmarx), and enables the UART and both DMA stream
 *    interrupts at ONE priority (also the timer's, when advance_in_isr);
 *  - declares the DMA buffers with J288_STM32_DMA_BUFFER() in RAM the DMA can reach;
 *  - calls j288_stm32_init() per bus, then forwards from its own HAL callbacks (the port
 *    never defines the HAL's weak callbacks):
 *        HAL_UART_TxCpltCallback(h)           -> j288_stm32_on_tx_cplt(h)
 *        HAL_UARTEx_RxEventCallback(h, size)  -> j288_stm32_on_rx_event(h, size)
 *        HAL_UART_ErrorCallback(h)            -> j288_stm32_on_error(h)
 *        HAL_TIM_OC_DelayElapsedCallback(t)   -> j288_stm32_on_timer(t)
 *    Each returns true when the handle belonged to a registered bus, so one callback can
 *    serve several buses and unrelated UARTs/timers.
 *
 * Several buses: up to J288_STM32_MAX_BUSES are registered at once (one per UART); the
 * callbacks find the bus by handle with a short linear search.
 *
 * Interrupt context: every j288_stm32_on_* function is ISR-safe and is meant to be called from
 * the HAL callbacks above (i.e. from the UART/DMA/timer IRQ). init/deinit are thread only.
 *
 * Pauses: an idle line inside a reply never ends the transaction (bus.h): the port keeps
 * receiving, and a frame still incomplete at the deadline is J288_ERR_TRUNCATED.
 * HAL failures: every one is counted (hal_failures) and ends the attempt with an error the
 * application sees: J288_ERR_PORT when the line could not be turned to transmit or the
 * transmit not started, J288_ERR_LINE (flag J288_LINE_DMA) when the turn to receive or the
 * reception could not be started. A transfer left running by an earlier transaction (a lost
 * completion interrupt) is aborted before the next one (dma_resets), so the next
 * transaction works.
 */
#ifndef J288_STM32_H
#define J288_STM32_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "j288/bus.h"
#include "j288/port.h"

/* The HAL header. "main.h" is what CubeMX generates in every project and it includes the
 * family's HAL (stm32f4xx_hal.h, stm32h7xx_hal.h, ...), so the default works on any family;
 * test/stm32/stub/ provides a main.h of its own for builds without the HAL. */
#ifndef J288_STM32_HAL_HEADER
#define J288_STM32_HAL_HEADER "main.h"
#endif
#include J288_STM32_HAL_HEADER

#ifdef __cplusplus
extern "C" {
#endif

/* ---- configuration macros (define before including, or with -D) ------------------------ */

/* How many buses (UARTs) may be registered at once. */
#ifndef J288_STM32_MAX_BUSES
#define J288_STM32_MAX_BUSES 4u
#endif

/* 1: use the CRC unit for frames (j288_stm32_config_t.hcrc). 0: compile the hardware path
 * out; frames use the library's compile-time software backend (J288_CONFIG_CRC_BACKEND). */
#ifndef J288_STM32_HW_CRC
#define J288_STM32_HW_CRC 1
#endif

/* The CRC unit is shared by everything on the chip (other libraries, firmware image checks).
 * One frame CRC resets the unit and feeds 4 or 5 words (well under a microsecond at 168 MHz)
 * inside J288_STM32_CRC_LOCK()/J288_STM32_CRC_UNLOCK(). The default masks all interrupts
 * (PRIMASK) around the computation, which is safe when the other users run at thread level or
 * below the bus interrupts and themselves take the same lock. Replace both with your RTOS
 * mutex only if the bus never advances in an ISR (advance_in_isr = false). The variable named
 * by the argument (a uint32_t) may hold saved state. */
#ifndef J288_STM32_CRC_LOCK
#define J288_STM32_CRC_LOCK(saved) ((saved) = __get_PRIMASK(), __disable_irq())
#define J288_STM32_CRC_UNLOCK(saved) __set_PRIMASK(saved)
#endif

/* 1 on cores with a data cache in use (Cortex-M7 with SCB_EnableDCache()): the port cleans the
 * TX buffer before each transmit and invalidates the RX buffer before and after each
 * reception. The DMA buffers are then aligned to and sized in whole 32-byte cache lines, so
 * maintenance never touches a neighbour's data. 0 (default): no cache maintenance; leave it 0
 * when the buffers live in non-cacheable RAM (MPU region, or DTCM where the DMA reaches it). */
#ifndef J288_STM32_DCACHE
#define J288_STM32_DCACHE 0
#endif

/* Cache line / DMA buffer alignment in bytes (32 on Cortex-M7). */
#ifndef J288_STM32_DCACHE_LINE
#define J288_STM32_DCACHE_LINE 32u
#endif

/* Placement of the DMA buffers: e.g. __attribute__((section(".dma_buffer"))) to put them in
 * an SRAM the DMA controller can reach (not the F4's CCM RAM, not the H7's DTCM) or in a
 * non-cacheable MPU region. Empty by default (.bss). */
#ifndef J288_STM32_DMA_SECTION
#define J288_STM32_DMA_SECTION
#endif

/* Alignment attribute for the DMA buffers (GCC, Clang and Arm Compiler 6 syntax; IAR users
 * define it as their equivalent). */
#ifndef J288_STM32_DMA_ALIGN
#define J288_STM32_DMA_ALIGN __attribute__((aligned(J288_STM32_DCACHE_LINE)))
#endif

/* Receive DMA buffer size: a whole number of cache lines, larger than one reply so that the
 * idle line, not a full buffer, ends a normal reception. */
#ifndef J288_STM32_RX_BUF_SIZE
#define J288_STM32_RX_BUF_SIZE 64u
#endif

/* Transmit DMA buffer size: one command rounded up to whole cache lines. */
#define J288_STM32_TX_BUF_SIZE                                                                 \
    (((J288_CMD_LEN + J288_STM32_DCACHE_LINE - 1u) / J288_STM32_DCACHE_LINE) * J288_STM32_DCACHE_LINE)

/* ---- types ----------------------------------------------------------------------------- */

/* The DMA buffers of one bus. Declare with J288_STM32_DMA_BUFFER(name) at file scope, so that
 * placement and alignment apply; the port copies each command in (20 bytes) rather than let
 * the DMA read the bus object, which may live in RAM the DMA cannot reach. */
typedef struct {
    uint8_t tx[J288_STM32_TX_BUF_SIZE];
    uint8_t rx[J288_STM32_RX_BUF_SIZE];
} j288_stm32_dma_t;

#define J288_STM32_DMA_BUFFER(name) J288_STM32_DMA_SECTION J288_STM32_DMA_ALIGN j288_stm32_dma_t name

/* All pointers must outlive the bus. Fields marked optional may be NULL/0. */
typedef struct {
    UART_HandleTypeDef *huart; /* required: initialised with HAL_HalfDuplex_Init() */
    j288_stm32_dma_t *dma;     /* required: declared with J288_STM32_DMA_BUFFER() */

    /* Optional driver-enable pin of an external transceiver: driven active while we
     * transmit, inactive otherwise. de_port NULL: no pin. */
    GPIO_TypeDef *de_port;
    uint16_t de_pin;
    bool de_active_low;

    /* Time. now_us: the application's monotonic microsecond tick (callable from any
     * context, wraps at 2^32). When NULL, htim's counter is the tick; it must then count at
     * 1 MHz with a 32-bit reload of 0xFFFFFFFF (TIM2/TIM5 on the F4), which init checks.
     * Either way this one clock sets every transaction's start, deadline and guard: pass
     * j288_stm32_now_us() (or the same now_us) to j288_bus_submit/poll/estop and j288_sched_*.
     * With both now_us and htim, the timer only times the wait: the compare is set to the
     * deadline's distance from now_us, so both must count microseconds. */
    uint32_t (*now_us)(void);

    /* Optional response timeout: a timer counting at 1 MHz, started by the application
     * (HAL_TIM_Base_Start), whose capture/compare channel tim_channel (TIM_CHANNEL_1..4) is
     * free and in its reset (frozen output compare) mode. The port writes the compare value,
     * enables that channel's interrupt and, for a deadline already due, raises the channel's
     * event through the timer's EGR; forward HAL_TIM_OC_DelayElapsedCallback to
     * j288_stm32_on_timer(). Several buses may share one timer on different channels. NULL:
     * no timer; call j288_bus_poll() (or j288_sched_poll()) often enough yourself. */
    TIM_HandleTypeDef *htim;
    uint32_t tim_channel;

    /* Optional CRC unit in its reset configuration (J288_STM32_HW_CRC = 1): polynomial
     * 0x04C11DB7, initial value 0xFFFFFFFF, no reversal, 32-bit input; on families with a
     * configurable unit (G4, H7, F7, L4...) the handle must say so: InputDataFormat =
     * CRC_INPUTDATA_FORMAT_WORDS, default polynomial and initial value (or the same values
     * spelled out), no input or output inversion. Initialised (HAL_CRC_Init) before
     * j288_stm32_init(). NULL: software CRC. */
    CRC_HandleTypeDef *hcrc;
} j288_stm32_config_t;

/* Port-side counters. */
typedef struct {
    uint32_t tx_frames;    /* transmits started */
    uint32_t rx_events;    /* receive events taken (half, idle, full) */
    uint32_t rx_bytes;     /* bytes handed to the bus */
    uint32_t line_errors;  /* error callbacks */
    uint32_t hal_failures; /* HAL calls that did not return HAL_OK */
    uint32_t dma_resets;   /* transfers found still running from an earlier transaction and
                              aborted before the next (a lost TX complete or DMA interrupt) */
    uint32_t timer_events; /* compare interrupts taken (timer_rearms included) */
    uint32_t timer_rearms; /* of those, early ones (before the deadline): re-armed for the
                              rest, the bus not called */
} j288_stm32_stats_t;

/* One bus on one UART. Caller-allocated (statically, usually); must not move while
 * registered. Private: use the functions below. */
typedef struct j288_stm32 {
    j288_bus_t bus;
    j288_port_t ops; /* the port's operations, as this configuration uses them */
    j288_stm32_config_t cfg;
    volatile uint16_t rx_pos;  /* bytes of the current reception already handed out */
    volatile uint8_t dir;      /* j288_dir_t last set */
    volatile bool tx_refused;  /* the turn to transmit failed: start_tx refuses */
    uint32_t lock_saved;
    volatile uint32_t tim_deadline; /* last arm_timeout deadline (now_us clock) */
    j288_stm32_stats_t stats;
} j288_stm32_t;

/* ---- functions ------------------------------------------------------------------------- */

/* Set up p, register it and initialise its bus (j288_bus_init with bus_cfg, which may be
 * NULL for defaults). cfg and bus_cfg are copied; what cfg points to must outlive the bus.
 * The application initialises the UART, its DMA streams, the timer (started) and the CRC
 * unit before. Leaves the line in receive direction with the DE pin inactive.
 * Errors: J288_ERR_NULL (p, cfg, huart or dma), J288_ERR_BUSY (this UART is registered
 * already, or J288_STM32_MAX_BUSES are), J288_ERR_BAD_CONFIG for any of:
 *   - no now_us and no 32-bit 1 MHz timer, or a tim_channel that is no TIM_CHANNEL_n;
 *   - the UART handle has no DMA stream linked (hdmatx or hdmarx NULL);
 *   - bus_cfg->echo: the receiver is off while the port transmits, so no echo can come;
 *   - the CRC unit does not compute the servo's CRC: a handle in another configuration (see
 *     hcrc above), or a unit that fails a known-answer check (its clock not enabled,
 *     HAL_CRC_Init not called, registers reprogrammed by other code);
 * J288_ERR_PORT (the HAL refused to turn the line to receive), or j288_bus_init()'s codes.
 * Thread only. */
int j288_stm32_init(j288_stm32_t *p, const j288_stm32_config_t *cfg,
                    const j288_bus_config_t *bus_cfg);

/* Unregister p: the callbacks ignore its handles from now on, a transfer in flight is
 * aborted (a command on the wire is cut short; its transaction gets no completion
 * callback), the timer channel's interrupt is disabled and the DE pin made inactive. p may
 * then be initialised again. Does nothing for a p that is not registered. Thread only. */
void j288_stm32_deinit(j288_stm32_t *p);

/* The bus driven by p (NULL for NULL), for j288_bus_* and j288_sched_*; valid as long as p.
 * Any context. */
j288_bus_t *j288_stm32_bus(j288_stm32_t *p);

/* The microsecond tick p uses (its now_us, or the timer counter). Any context. This is the
 * clock the bus reads in its event calls (advance_in_isr), so the now_us the application
 * passes to j288_bus_submit/poll/estop and j288_sched_* must come from it too (bus.h). */
uint32_t j288_stm32_now_us(const j288_stm32_t *p);

/* p's counters (NULL for NULL), valid as long as p. Any context; the interrupts keep
 * updating them, so two fields read one after the other may be from different moments. */
const j288_stm32_stats_t *j288_stm32_stats(const j288_stm32_t *p);

/* Callback forwarding, ISR-safe; call them from the HAL callbacks named at the top, i.e. from
 * the bus's UART, DMA and timer interrupts, never from two priorities at once. Each returns
 * false (and does nothing) when the handle belongs to no registered bus (or is NULL). Bytes
 * of a receive event are handed to the bus during the call; the port's DMA buffer is not
 * read after it returns. */
bool j288_stm32_on_tx_cplt(UART_HandleTypeDef *huart);
bool j288_stm32_on_rx_event(UART_HandleTypeDef *huart, uint16_t size);
bool j288_stm32_on_error(UART_HandleTypeDef *huart);
bool j288_stm32_on_timer(TIM_HandleTypeDef *htim);

#if J288_STM32_HW_CRC
/* The manual's crc32_core over nwords little-endian words at data (any alignment; read only
 * during the call) on the CRC unit hcrc, inside J288_STM32_CRC_LOCK. Words are assembled from
 * bytes into an aligned scratch buffer (never a cast of data), 8 words at a time:
 * HAL_CRC_Calculate for the first chunk (it resets the unit), HAL_CRC_Accumulate for the rest.
 * A frame is 4 or 5 words. hcrc NULL: computed in software instead; data NULL: the CRC of no
 * words. Returns the CRC. ISR-safe. */
uint32_t j288_stm32_crc32(CRC_HandleTypeDef *hcrc, const uint8_t *data, size_t nwords);

/* The same as a context-free function for J288_CONFIG_CRC_BACKEND = J288_CRC_BACKEND_HW with
 * J288_CONFIG_CRC_HW_FUNCTION=j288_stm32_crc32_default, after j288_stm32_crc_attach(). Before
 * an attach (or with NULL) it computes in software, bit-identically. attach: thread, before
 * the buses start (hcrc must outlive its use, in the reset configuration as for
 * j288_stm32_config_t.hcrc; attach does not check it). crc32_default: ISR-safe. */
void j288_stm32_crc_attach(CRC_HandleTypeDef *hcrc);
uint32_t j288_stm32_crc32_default(const uint8_t *data, size_t nwords);
#endif

#ifdef __cplusplus
}
#endif

#endif /* J288_STM32_H */
