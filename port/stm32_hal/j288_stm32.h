/*
 * j288_stm32.h - j288 port for STM32: one bus per UART in single-wire half-duplex mode, DMA
 * both ways, the response timeout from a timer compare channel, and the CRC unit as the frame
 * CRC. The HAL initialises (clocks, pins, UART, DMA streams, timer, CRC unit); every
 * transaction then runs on the registers (start transmit, transmit complete, receive events),
 * because the HAL's per-transaction path cost more than the library it serves
 * (docs/performance.md). Register models: the F1/F2/F4 USART (SR/DR) or the newer one
 * (ISR/ICR: F0, F3, F7, G0, G4, H7, L4...), and DMA streams (F2, F4, F7, H7 DMA1/2) or
 * channels (F0, F1, F3, G0, G4, L4...); checked against the F4, G4 and H7 HAL.
 *
 * How the line runs (docs/stm32.md says why):
 *  - The receiver is never switched off and the receive stream runs circular from init on,
 *    so there is no moment at the turnaround where a reply byte can be lost. The line hears
 *    our own 20 bytes (unless it is deaf_while_transmitting): with the bus's echo option they
 *    are handed to the bus, which checks them (collisions); without, skipped.
 *  - A transmit ends at the UART's transmit complete (TC) with the TX stream's count at 0: at
 *    TC's interrupt with a DE pin (dropped first thing there) or a deaf line, else at the idle
 *    line after the echo, TC then being set (a TC raised mid-frame by a stall of the stream is
 *    waited past). The echo's end is where it started plus its length when the line hears us
 *    and no flag says a byte of it was lost; otherwise every byte from its start goes to the
 *    bus after the transmit's end, whose parser finds the reply among them: a lost echo byte
 *    costs nothing, and a broadcast ends (with the echo option, the echo the bus checks is then
 *    a byte short: J288_ERR_COLLISION).
 *  - The receive position is read from the stream's counter (NDTR/CNDTR) at every event: idle
 *    line, half and whole buffer. The events may come in any order, late or twice: every byte
 *    is handed to the bus once, in order, as long as each event is served within the timing
 *    budget (below). A lap beyond it (the stream overwrote bytes not handed over) is detected
 *    from the half/complete flags and reported as J288_LINE_OVERRUN (rx_laps).
 *  - Line errors are left to the CRC: one-bit sampling (no noise flag, which on the newer
 *    USART keeps a good byte from the DMA) and the error interrupt masked; nothing aborts the
 *    reception. Flags seen at the next event are counted and reported to the bus.
 *
 * Timing budget (docs/stm32.md works it out): each of the bus's interrupts (UART, RX stream)
 * must be served within J288_STM32_RX_BUF_SIZE/4 - 1 character times of being raised (105 us
 * at the default 256 bytes and 6 Mbps, 52 us at 128): later, bytes may be overwritten before
 * they are handed over (reported as J288_LINE_OVERRUN, rx_laps, not silent). A reply reaches
 * the bus at its idle line plus the UART interrupt's latency: the bus's margin_us (20 us by
 * default) must cover that latency. The DE pin drops within the UART interrupt's latency of
 * the last stop bit; a servo answering sooner meets our driver still on (hardware DE,
 * de_hardware, has no such delay).
 *
 * What the application does (examples/stm32_hal/, docs/stm32.md):
 *  - HAL_HalfDuplex_Init() at the bus baud (6 Mbps), 8N1; a DMA stream/channel for TX and one
 *    for RX, byte width, memory increment, linked to the UART handle (hdmatx, hdmarx) and
 *    initialised with HAL_DMA_Init (the port sets the RX one circular itself);
 *  - the UART, the RX stream's and the timer's interrupts enabled at ONE priority (the TX
 *    stream's interrupt is not used); its IRQ handlers call j288_stm32_on_uart_irq() and
 *    j288_stm32_on_dma_rx_irq() instead of the HAL's handlers, and the timer's
 *    HAL_TIM_OC_DelayElapsedCallback forwards to j288_stm32_on_timer();
 *  - j288_stm32_dma_t buffers in RAM the DMA reaches (init refuses the F4's CCM RAM and the
 *    H7's TCMs); j288_stm32_init() per bus. After init the UART belongs to the port: no HAL
 *    UART call on it until j288_stm32_deinit().
 *
 * Interrupt context: j288_stm32_on_* are ISR-safe and meant for the bus's IRQs. init/deinit
 * are thread only. No function of the port waits on SysTick: a stream that must stop is
 * stopped at the register with a bounded wait.
 *
 * The bus lock (the port's lock/unlock operations, taken by the bus around thread-context calls
 * of a bus with advance_in_isr) masks the bus's interrupts: BASEPRI at irq_priority, or PRIMASK.
 * Locks nest, across buses and in any order (one depth count for the port: the first lock saves
 * PRIMASK and BASEPRI, the last unlock restores them). Code that runs under it (the bus's
 * completion callbacks) must not lower BASEPRI or clear PRIMASK: an RTOS critical section that
 * ends by writing BASEPRI = 0 (FreeRTOS taskEXIT_CRITICAL outside a nested section) unmasks the
 * bus's interrupts while the bus believes itself locked; use the RTOS's nesting-aware form or
 * leave the work to thread code after the call.
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

/* Bytes the bus is given in one piece when a reception wraps round the end of the circular
 * buffer (copied into a scratch of this size; larger runs go as two pieces). */
#ifndef J288_STM32_BOUNCE_SIZE
#define J288_STM32_BOUNCE_SIZE 64u
#endif

/* Reads of a stream's enable bit that a stop waits for at most (a stream finishes its
 * current single transfer, a few bus cycles, before the bit reads 0). */
#ifndef J288_STM32_STOP_SPINS
#define J288_STM32_STOP_SPINS 64u
#endif

/* Reads of the RX stream's counter that the end of a transmit waits for at most, for the last
 * echoed byte to be stored (normally there already) or, after a TX stream stall, to finish on
 * the wire: a character time and more on any core (a read is a few cycles). */
#ifndef J288_STM32_ECHO_SPINS
#define J288_STM32_ECHO_SPINS 256u
#endif

/* Every peripheral register access of the port is J288_STM32_REG(reg), an lvalue: plain by
 * default. A model of the silicon (the tests' fake HAL, test/stm32/) defines it to watch them.
 * Leave it alone in firmware. */

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

/* Receive DMA buffer size (circular): a whole number of cache lines, at least two frames of
 * a transaction (command echo and reply, 46 bytes). Larger means fewer half/complete events
 * per transaction (one every RX_BUF_SIZE/2 bytes). */
#ifndef J288_STM32_RX_BUF_SIZE
#define J288_STM32_RX_BUF_SIZE 256u
#endif

/* Transmit DMA buffer size: one command rounded up to whole cache lines. */
#define J288_STM32_TX_BUF_SIZE                                                                 \
    (((J288_CMD_LEN + J288_STM32_DCACHE_LINE - 1u) / J288_STM32_DCACHE_LINE) * J288_STM32_DCACHE_LINE)

/* ---- types ----------------------------------------------------------------------------- */

/* The DMA buffers of one bus. The type carries the alignment (whole cache lines on a core with
 * a D-cache), so any declaration is aligned; J288_STM32_DMA_BUFFER(name) adds the placement
 * (J288_STM32_DMA_SECTION). The port copies each command in (20 bytes) rather than let the
 * DMA read the bus object, which may live in RAM the DMA cannot reach. */
typedef struct J288_STM32_DMA_ALIGN {
    uint8_t tx[J288_STM32_TX_BUF_SIZE];
    uint8_t rx[J288_STM32_RX_BUF_SIZE];
} j288_stm32_dma_t;

#define J288_STM32_DMA_BUFFER(name) J288_STM32_DMA_SECTION j288_stm32_dma_t name

/* How the port drives the UART's pin (j288_stm32_config_t.tx_drive; docs/stm32.md has the
 * reasoning and the reference wiring). */
typedef enum {
    J288_STM32_PIN_AS_CONFIGURED = 0, /* leave the pin as the application set it up */
    J288_STM32_PIN_PUSH_PULL,         /* drives both levels: fast edges at 6 Mbps; a series
                                         resistor limits a collision's current */
    J288_STM32_PIN_OPEN_DRAIN         /* drives low only, a pull-up makes the high: no
                                         collision can short two drivers */
} j288_stm32_pin_drive_t;

/* All pointers must outlive the bus. Fields marked optional may be NULL/0. */
typedef struct {
    UART_HandleTypeDef *huart; /* required: initialised with HAL_HalfDuplex_Init() */
    j288_stm32_dma_t *dma;     /* required: in RAM the DMA reaches (J288_STM32_DMA_BUFFER) */

    /* The NVIC preemption priority of the bus's interrupts (UART, RX stream, timer: one
     * priority). The bus lock raises BASEPRI to it, masking those and anything less urgent
     * while other interrupts keep their latency. 0, or a core without BASEPRI (Cortex-M0/M0+/
     * M23): the lock masks every interrupt (PRIMASK); BASEPRI cannot mask priority 0.
     * At most (1 << __NVIC_PRIO_BITS) - 1 (15 on the F4, G4 and H7): init refuses more. */
    uint8_t irq_priority;

    /* The line does not hear our own transmit: a transceiver whose receiver is switched off
     * with DE (/RE tied to DE). false (the single-wire line, or a transceiver whose receiver
     * stays on): the 20 echoed bytes are skipped or, with the bus's echo option, checked. */
    bool deaf_while_transmitting;

    /* Optional: the UART's TX pin and how to drive it (set in the GPIO's OTYPER at init).
     * tx_port NULL: leave the pin as configured. */
    GPIO_TypeDef *tx_port;
    uint16_t tx_pin;
    j288_stm32_pin_drive_t tx_drive;

    /* Optional driver-enable pin of an external transceiver: driven active while we
     * transmit, inactive otherwise (dropped first thing at transmit complete, within the UART
     * interrupt's latency). de_port NULL: no pin. */
    GPIO_TypeDef *de_port;
    uint16_t de_pin;
    bool de_active_low;

    /* The UART drives the transceiver's DE itself (USARTs with CR3.DEM: F0, F3, F7, G0, G4,
     * H7, L4...): set up by the application with HAL_RS485Ex_Init (polarity, assertion and
     * deassertion times) and the pin in its USART_DE alternate function. DE then drops DEDT
     * after the last stop bit whatever the interrupt latency. The port only checks it: init
     * refuses it without CR3.DEM set, together with de_port, or on a family without it (F1,
     * F2, F4). */
    bool de_hardware;

    /* Time. now_us: the application's monotonic microsecond tick (callable from any
     * context, wraps at 2^32). When NULL, htim's counter is the tick; it must then count at
     * 1 MHz with a 32-bit reload of 0xFFFFFFFF (TIM2/TIM5 on the F4), which init checks.
     * Either way this one clock sets every transaction's start, deadline and guard: pass
     * j288_stm32_now_us() (or the same now_us) to j288_bus_submit/poll/estop and j288_sched_*.
     * With both now_us and htim, the timer only times the wait: the compare is set to the
     * deadline's distance from now_us, so both must count microseconds. */
    uint32_t (*now_us)(void);

    /* Optional response timeout, used by a bus that advances in its interrupts
     * (advance_in_isr; a polled bus reads the clock when polled): a timer counting at 1 MHz,
     * started by the application (HAL_TIM_Base_Start), whose capture/compare channel
     * tim_channel (TIM_CHANNEL_1..4) is free and in its reset (frozen output compare) mode. The port writes the compare value,
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
    uint32_t rx_events;    /* receive events taken (idle line, half, complete) */
    uint32_t rx_bytes;     /* bytes handed to the bus */
    uint32_t rx_skipped;   /* bytes not handed over: our own echo (without the echo option),
                              bytes heard before a transmit, which belong to nobody, and
                              bytes lost to a lap or a stream restart */
    uint32_t rx_laps;      /* times the RX stream overwrote bytes not yet handed over (an
                              event served beyond the timing budget): reported to the bus as
                              J288_LINE_OVERRUN */
    uint32_t noise_errors;   /* line error flags seen at an event (the byte was still stored */
    uint32_t framing_errors; /* on the F4; the newer USART drops a flagged byte): each reported */
    uint32_t overruns;       /* to the bus as a line error, the frame left to the CRC */
    uint32_t parity_errors;
    uint32_t dma_errors;   /* RX stream transfer errors: the stream was restarted */
    uint32_t dma_resets;   /* transmits found still running from an earlier transaction and
                              stopped before the next (a lost TX complete interrupt) */
    uint32_t tx_stalls;    /* transmits found idle mid-frame (the TX stream stalled a
                              character or more: TC, or the echo's idle line, raised early) and
                              waited past; seen only when the interrupt comes during the stall */
    uint32_t timer_events; /* compare interrupts taken (timer_rearms included) */
    uint32_t timer_rearms; /* of those, early ones (before the deadline): re-armed for the
                              rest, the bus not called */
} j288_stm32_stats_t;

/* Why j288_stm32_init() returned J288_ERR_BAD_CONFIG (j288_stm32_init_error()). */
typedef enum {
    J288_STM32_INIT_OK = 0,
    J288_STM32_INIT_NO_DMA,             /* the UART handle has no DMA stream linked */
    J288_STM32_INIT_BDMA,               /* H7: a BDMA channel (D3 domain, LPUART1) */
    J288_STM32_INIT_NOT_HALF_DUPLEX,    /* CR3.HDSEL clear: HAL_HalfDuplex_Init not called */
    J288_STM32_INIT_DMA_DIRECTION,      /* TX not memory-to-peripheral, RX not the reverse */
    J288_STM32_INIT_DMA_REQUEST,        /* a DMAMUX request that is not this UART's */
    J288_STM32_INIT_BUFFER_UNREACHABLE, /* DMA buffers in CCM or TCM RAM */
    J288_STM32_INIT_BUFFER_ALIGNMENT,   /* J288_STM32_DCACHE and not on a cache line */
    J288_STM32_INIT_DCACHE,             /* D-cache on, J288_STM32_DCACHE=0, buffers cached */
    J288_STM32_INIT_PRIORITY,           /* irq_priority beyond the NVIC's bits */
    J288_STM32_INIT_ECHO_DEAF,          /* the echo option on a deaf line */
    J288_STM32_INIT_TIMER_CHANNEL,      /* tim_channel not TIM_CHANNEL_1..4 */
    J288_STM32_INIT_TIMER_PRELOAD,      /* the channel's compare preload (OCxPE) on */
    J288_STM32_INIT_NO_CLOCK,           /* no now_us, no 32-bit 1 MHz timer */
    J288_STM32_INIT_DE_HARDWARE,        /* de_hardware without CR3.DEM, or with de_port */
    J288_STM32_INIT_CRC_CONFIG,         /* CRC handle not in the reset configuration */
    J288_STM32_INIT_CRC_ANSWER          /* CRC unit fails its known answer */
} j288_stm32_init_error_t;

/* One bus on one UART. Caller-allocated (statically, usually); must not move while
 * registered. Private: use the functions below. */
typedef struct j288_stm32 {
    j288_bus_t bus;
    j288_port_t ops; /* the port's operations, as this configuration uses them */
    j288_stm32_config_t cfg;
    USART_TypeDef *uart;       /* the registers, from the handles at init */
    void *tx_stream;
    void *rx_stream;
    volatile uint32_t *tx_ifcr; /* flag clear register of each stream/channel, and its shift */
    volatile uint32_t *rx_isr;
    volatile uint32_t *rx_ifcr;
    uint8_t tx_shift;
    uint8_t rx_shift;
    bool echo;                 /* the bus checks the echo: hand it over */
    bool tc_irq;               /* TC's interrupt ends a transmit (a DE pin to drop at once, or a
                                  deaf line); else the echo's idle line does */
    volatile bool live;        /* registered: the IRQ entries serve it */
    volatile bool tx_on;       /* a transmit is in flight */
    bool rx_dead;              /* the RX stream would not restart (retried at a transmit) */
    bool lapped;               /* the RX stream went round unseen: what waits is overwritten */
    uint16_t echo_len;         /* bytes of the last transmit's echo: its length, or 0 (a deaf
                                  line, or lost to a stream restart) */
    /* Indices in the receive buffer. Written in the bus's interrupts, and by start_tx in an
     * order that needs no lock (j288_stm32.c). */
    uint32_t rx_pos;           /* the next byte to hand over */
    uint32_t flag_idx;         /* where the half/complete flags were last cleared */
    volatile uint32_t tx_start; /* where the last transmit's echo starts */
    uint8_t bounce[J288_STM32_BOUNCE_SIZE]; /* a wrapped run, handed over in one piece */
    volatile uint32_t tim_deadline; /* last arm_timeout deadline (now_us clock) */
    j288_stm32_init_error_t init_error;
    j288_stm32_stats_t stats;
} j288_stm32_t;

/* ---- functions ------------------------------------------------------------------------- */

/* Set up p, register it and initialise its bus (j288_bus_init with bus_cfg, which may be
 * NULL for defaults). cfg and bus_cfg are copied; what cfg points to must outlive the bus.
 * The application initialises the UART (HAL_HalfDuplex_Init), its DMA streams (HAL_DMA_Init,
 * linked to the handle), the timer (started) and the CRC unit before. Init then takes the
 * UART's registers with every interrupt source masked and the bus not yet live: the UART off
 * while one-bit sampling is set (error interrupt off), the streams stopped and set up, their
 * flags cleared (the TX stream pointed at dma->tx, the RX stream circular over dma->rx,
 * started), the UART on again and its stale IDLE and error flags cleared; then the bus is live
 * and the last enables follow (DMA requests, the RX stream's half/complete/error interrupts,
 * the idle-line interrupt). The DE pin is left inactive and the TX pin driven as tx_drive says.
 * Errors: J288_ERR_NULL (p, cfg, huart or dma), J288_ERR_BUSY (this UART or p is registered
 * already, or J288_STM32_MAX_BUSES are), J288_ERR_BAD_CONFIG with its reason in
 * j288_stm32_init_error(p) (p's other fields untouched):
 *   J288_STM32_INIT_NO_DMA              hdmatx or hdmarx NULL (or their Instance);
 *   J288_STM32_INIT_BDMA                an H7 BDMA channel (LPUART1's D3 DMA): not driven;
 *   J288_STM32_INIT_NOT_HALF_DUPLEX     CR3.HDSEL clear;
 *   J288_STM32_INIT_DMA_DIRECTION       the TX stream not memory-to-peripheral, or the RX
 *                                       stream not peripheral-to-memory;
 *   J288_STM32_INIT_DMA_REQUEST         (G4, H7...) a DMAMUX channel whose request id is not
 *                                       this UART's TX (resp. RX);
 *   J288_STM32_INIT_BUFFER_UNREACHABLE  dma in RAM the DMA controller cannot reach: the F4's
 *                                       CCM data RAM (0x10000000-0x1000FFFF), the F3's CCM SRAM
 *                                       (0x10000000-0x10003FFF), the H7's ITCM (below
 *                                       0x00040000) and DTCM (0x20000000-0x2001FFFF);
 *   J288_STM32_INIT_BUFFER_ALIGNMENT    with J288_STM32_DCACHE, not on a cache line;
 *   J288_STM32_INIT_DCACHE              a core with a D-cache, J288_STM32_DCACHE=0, the cache
 *                                       on (SCB->CCR.DC) and the buffers not in a region the
 *                                       MPU makes non-cacheable (or shareable);
 *   J288_STM32_INIT_PRIORITY            irq_priority >= 1 << __NVIC_PRIO_BITS;
 *   J288_STM32_INIT_ECHO_DEAF           bus_cfg->echo with deaf_while_transmitting;
 *   J288_STM32_INIT_TIMER_CHANNEL       a tim_channel that is no TIM_CHANNEL_1..4;
 *   J288_STM32_INIT_TIMER_PRELOAD       its output compare preload (OCxPE) on;
 *   J288_STM32_INIT_NO_CLOCK            no now_us and no 32-bit 1 MHz timer;
 *   J288_STM32_INIT_DE_HARDWARE         de_hardware on a USART without CR3.DEM, with DEM not
 *                                       set, or together with de_port;
 *   J288_STM32_INIT_CRC_CONFIG          the CRC handle in another configuration (hcrc above);
 *   J288_STM32_INIT_CRC_ANSWER          a CRC unit that fails a known-answer check (its clock
 *                                       not enabled, HAL_CRC_Init not called, registers
 *                                       reprogrammed by other code);
 * J288_ERR_PORT (a DMA stream that would not stop, or would not start), or j288_bus_init()'s
 * codes. Thread only. */
int j288_stm32_init(j288_stm32_t *p, const j288_stm32_config_t *cfg,
                    const j288_bus_config_t *bus_cfg);

/* Why the last j288_stm32_init(p, ...) returned J288_ERR_BAD_CONFIG (J288_STM32_INIT_OK for
 * NULL, or after a successful init), and a short English description of a reason (never NULL).
 * Any context. */
j288_stm32_init_error_t j288_stm32_init_error(const j288_stm32_t *p);
const char *j288_stm32_init_error_str(j288_stm32_init_error_t e);

/* Unregister p, its interrupt sources masked first: the callbacks ignore its handles from now on, a transfer in flight is
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

/* Interrupt entries, ISR-safe; each does nothing for NULL, and for a p that is not registered
 * masks the interrupt sources of its UART and RX stream (unless another bus has taken that UART
 * since), so that a pending entry from before init or after deinit cannot come back.
 * on_uart_irq: call from the UART's IRQ handler (instead of HAL_UART_IRQHandler): the idle
 *   line (received bytes handed over), line error flags (counted, reported), transmit
 *   complete (DE dropped, the echo skipped or handed over, the bus told).
 * on_dma_rx_irq: call from the RX stream's IRQ handler (instead of HAL_DMA_IRQHandler): half
 *   and complete (received bytes handed over), transfer error (stream restarted, reported).
 * Bytes are handed to the bus during the call; the DMA buffer is not read after it returns. */
void j288_stm32_on_uart_irq(j288_stm32_t *p);
void j288_stm32_on_dma_rx_irq(j288_stm32_t *p);

/* Call from HAL_TIM_OC_DelayElapsedCallback (HAL_TIM_IRQHandler serves the timer, which is
 * not per transaction). Returns false (and does nothing) when htim's active channel belongs
 * to no registered bus, so one callback can serve several buses and other timers. */
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
