/*
 * fake_hal.h - a host-side model of the STM32 silicon the port drives, written from the
 * reference manuals (RM0090/RM0390 for the F4, RM0440 for the G4, RM0433 for the H7), not from
 * what the port expects. One fake, three models, chosen as the stub is (-DJ288_STUB_F4/G4/H7):
 *   F4: USART SR/DR, DMA streams (flags in LISR/HISR);
 *   G4: USART ISR/ICR, DMA channels (flags in ISR/IFCR), DMAMUX;
 *   H7: USART ISR/ICR, DMA streams, DMAMUX, a Cortex-M7 with a data cache and an MPU.
 *
 * Time. A simulated timeline in ticks of 1/60 us: a bit at 6 Mbps is 10 ticks, a character
 * (start, 8 data, stop) 100 ticks. The hardware runs on it: the transmitter shifts characters
 * out, the TX stream refills its data register (after a configurable stall), TC rises only when
 * the shift register and the data register are both empty, the receiver takes each character
 * at the middle of its stop bit, IDLE rises one character after the last one, the RX stream
 * stores bytes, counts down and raises its half/complete flags. Every register access the port
 * makes (J288_STM32_REG, built with J288_STUB_FAKE) costs a tick of CPU time and brings the
 * hardware up to that moment; so does every HAL call.
 *
 * Rules kept, per family: flags clear as the manual says (F4: IDLE/ORE/NE/FE/PE by a read of SR
 * then a read of DR, by the CPU or by the DMA, clearing what that SR read saw; TC by writing 0
 * to it, or by an SR read and a DR write; G4/H7: through ICR, TC also by a write to TDR); UE=0
 * stops the line (G4/H7: the status flags go to their reset value); a disabled stream takes no
 * request (a byte waiting in the data register then overruns); a stream's EN bit reads 1 for a
 * while after it is cleared, and a stream refuses EN while any of its flags is set; writing a
 * stream's configuration while EN reads 1, or a G4/H7 bit that needs UE=0 while UE=1, is a
 * violation; on the G4/H7 a byte flagged with a framing, parity or noise error is not given to
 * the DMA (CR3.DDRE = 0); an overrun loses the byte; the DE pin's level is recorded against
 * time (GPIO or the G4/H7's hardware DE).
 *
 * Interrupts. Level-triggered, as the NVIC takes a peripheral's line: an interrupt pends while
 * a flag and its enable are both set, is taken when not masked (PRIMASK, BASEPRI against its
 * priority) after its latency, and a handler that returns with its cause still set is entered
 * again. Sixteen entries in a row that leave the same cause set are an interrupt storm: the
 * fake calls fake_app_fail() (it never gives up silently). Interrupts are taken between any two
 * register accesses of code that runs at thread level, as on the silicon.
 *
 * A broken rule or a storm calls fake_app_fail(message), which the test defines (Unity's
 * TEST_FAIL_MESSAGE): it does not return.
 */
#ifndef J288_FAKE_HAL_H
#define J288_FAKE_HAL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "stm32_hal_stub.h"

/* ---- time --------------------------------------------------------------------------------- */
#define FAKE_TICKS_PER_US 60u
#define FAKE_BIT 10u   /* ticks per bit at 6 Mbps */
#define FAKE_CHAR 100u /* ticks per character (10 bits) */
#define FAKE_NEVER UINT64_MAX

uint64_t fake_hal_time(void);
/* The application's microsecond clock on this timeline (the port's now_us in the tests). */
uint32_t fake_hal_now_us(void);
/* The hardware runs for ticks (or us), interrupts taken as they come. */
void fake_hal_run(uint64_t ticks);
void fake_hal_run_us(uint32_t us);
/* For a harness that sees every memory access of the code under test (compiler
 * instrumentation): whether an address is one of the fake's registers (then call
 * stub_reg_touch), and a point between two other accesses where an interrupt may come. */
bool fake_hal_is_register(const volatile void *addr);
void fake_hal_cpu_point(void);
/* Register accesses (and HAL calls) made since the reset. */
unsigned long fake_hal_accesses(void);

/* ---- the test's side ------------------------------------------------------------------------ */
/* A rule broken or an interrupt storm (defined by the test; must not return). */
void fake_app_fail(const char *msg);
/* The application's IRQ handlers for huart's UART and RX stream (the test defines them). */
void fake_app_uart_irq(UART_HandleTypeDef *huart);
void fake_app_dma_rx_irq(UART_HandleTypeDef *huart);

/* ---- call log (CRC unit, cache maintenance, GPIO) -------------------------------------------- */
typedef enum {
    FAKE_GPIO_WRITE = 0,
    FAKE_CRC_CALCULATE,
    FAKE_CRC_ACCUMULATE,
    FAKE_CACHE_CLEAN,
    FAKE_CACHE_INVALIDATE,
    FAKE_FN_COUNT
} fake_hal_fn_t;

typedef struct {
    fake_hal_fn_t fn;
    const void *handle; /* GPIO port, hcrc or buffer address */
    uint32_t arg;       /* pin state, word count, size */
} fake_hal_call_t;

#define FAKE_HAL_LOG_SIZE 256u

/* Forget everything (time, log, counters, UART models, timer hooks, masks). */
void fake_hal_reset(void);
size_t fake_hal_log_len(void);
const fake_hal_call_t *fake_hal_log_at(size_t i);
void fake_hal_log_clear(void);
/* Index of the first logged call of fn on handle at or after from, or -1. handle NULL: any. */
long fake_hal_log_find(fake_hal_fn_t fn, const void *handle, size_t from);
unsigned fake_hal_count(fake_hal_fn_t fn);

/* ---- a UART and its DMA -------------------------------------------------------------------- */
/* Give huart a UART (USART1, 2, 3 in order of setup) and two streams (channels on the G4) as
 * HAL_HalfDuplex_Init and HAL_DMA_Init leave them: UE, TE, RE and HDSEL on, the streams set up
 * byte-wide in their directions (TX normal, RX circular), DMAMUX requests for this UART (G4,
 * H7), handles linked. Returns false when no UART is left. */
bool fake_hal_uart_setup(UART_HandleTypeDef *huart);
USART_TypeDef *fake_hal_usart(const UART_HandleTypeDef *huart);
J288_STUB_DMA_INSTANCE *fake_hal_rx_stream(const UART_HandleTypeDef *huart);
J288_STUB_DMA_INSTANCE *fake_hal_tx_stream(const UART_HandleTypeDef *huart);
/* The RX stream's flags as the silicon shows them (shifted down to stream 0's / channel 1's). */
uint32_t fake_hal_rx_flags(const UART_HandleTypeDef *huart);

/* ---- the line ------------------------------------------------------------------------------ */
/* Per-byte line conditions: FAKE_NOISE (right value, noise seen: the G4/H7 drop it unless one-
 * bit sampling hides the noise), FAKE_FRAMING (no stop bit), FAKE_PARITY, FAKE_OVERRUN (the byte
 * is lost behind a full data register, ORE set). */
#define FAKE_NOISE 0x1u
#define FAKE_FRAMING 0x2u
#define FAKE_PARITY 0x4u
#define FAKE_OVERRUN 0x8u
#define FAKE_NOISE_START 0x10u /* noise on the start bit: NE even with one-bit sampling */

/* Bytes put on the line from now (after anything already on it), back to back with gap_ticks
 * between characters; flags (NULL: none) per byte. Only scheduled: run the fake to hear them. */
void fake_hal_line_put(UART_HandleTypeDef *huart, const uint8_t *data, size_t len, const uint8_t *flags,
                       uint32_t gap_ticks);
/* Bytes on the line back to back, the first delay_ticks from now (whatever is on the line). */
void fake_hal_line_put_after(UART_HandleTypeDef *huart, uint64_t delay_ticks, const uint8_t *data, size_t len);
/* A register as the HAL's initialisation left it: written without the rules a CPU write
 * would meet (a G4 bit that needs UE=0, a stream's configuration while it runs). */
void fake_hal_set_reg(volatile uint32_t *reg, uint32_t value);
/* The same, then run until all were received (and a tick for the DMA). Returns how many the
 * receiver took into its data register. */
size_t fake_hal_rx_bytes(UART_HandleTypeDef *huart, const uint8_t *data, size_t len);
bool fake_hal_rx_flagged(UART_HandleTypeDef *huart, uint8_t byte, unsigned flags);
/* Run until the line has been idle two characters; returns whether IDLE rose meanwhile. */
bool fake_hal_line_idle(UART_HandleTypeDef *huart);
/* The servo: when our next transmit's last stop bit has gone out, len bytes of reply start
 * delay_ticks later, back to back, with flags per byte (NULL: none). One shot. */
void fake_hal_reply_after_tx(UART_HandleTypeDef *huart, const uint8_t *data, size_t len, uint32_t delay_ticks,
                             const uint8_t *flags);
/* The receiver hears our byte `index` of every following transmit with these flags. */
void fake_hal_echo_flags(UART_HandleTypeDef *huart, size_t index, unsigned flags);
/* The line does not hear our own transmit, nor anything while DE is active (a transceiver with
 * /RE tied to DE). */
void fake_hal_line_deaf(UART_HandleTypeDef *huart, bool deaf);
/* The RX stream takes a received byte from the data register this many ticks after it arrived
 * (default 2; more than a character overruns). */
void fake_hal_rx_dma_delay(UART_HandleTypeDef *huart, uint32_t ticks);
/* The TX stream waits this many ticks more before writing byte `index` of every transmit into
 * the data register (a refill stall: the bus busy elsewhere). */
void fake_hal_tx_stall(UART_HandleTypeDef *huart, size_t index, uint32_t ticks);
/* Ticks a stream's EN bit keeps reading 1 after software clears it (default 3). */
void fake_hal_dma_stop_delay(uint32_t ticks);
/* A transfer error on the RX stream: it stops, TEIF rises; with FAKE_DMA_ALSO_DME the stream's
 * direct mode error flag too (a channel has none); with FAKE_DMA_STUCK a stream's EN bit keeps
 * reading 1 for 100000 ticks (a stream that cannot be stopped; a channel stops at once). */
#define FAKE_DMA_ALSO_DME 0x1u
#define FAKE_DMA_STUCK 0x2u
void fake_hal_dma_rx_error(UART_HandleTypeDef *huart, unsigned how);
/* Received bytes lost to a CPU read of the data register while they waited for the DMA. */
unsigned fake_hal_bytes_stolen(const UART_HandleTypeDef *huart);
/* Times a stream refused EN because its flags were set. */
unsigned fake_hal_en_refused(const UART_HandleTypeDef *huart);

/* ---- our transmit -------------------------------------------------------------------------- */
/* Whether a transmit is loaded and not fully on the wire. */
bool fake_hal_tx_busy(const UART_HandleTypeDef *huart);
/* Run until the loaded transmit's last stop bit is out; then (then_idle) the line idles two
 * characters. false if nothing was loaded. fake_hal_tx_complete: then_idle. */
bool fake_hal_tx_complete(UART_HandleTypeDef *huart);
bool fake_hal_tx_complete_ex(UART_HandleTypeDef *huart, bool then_idle);
/* The last frame the transmitter sent (or is sending), and its timing. */
const uint8_t *fake_hal_tx_data(const UART_HandleTypeDef *huart, size_t *len);
typedef struct {
    uint64_t first_start; /* the first start bit's edge */
    uint64_t last_end;    /* the end of the last stop bit (FAKE_NEVER while sending) */
    uint64_t reply_start; /* the servo's first start bit (FAKE_NEVER: none) */
    size_t sent;
} fake_hal_tx_info_t;
fake_hal_tx_info_t fake_hal_tx_info(const UART_HandleTypeDef *huart);

/* ---- DE ------------------------------------------------------------------------------------- */
/* The GPIO pin that is this line's driver enable (recorded against time). The G4/H7's hardware
 * DE (CR3.DEM) is recorded as well. */
void fake_hal_de_pin(UART_HandleTypeDef *huart, const GPIO_TypeDef *port, uint16_t pin, bool active_low);
bool fake_hal_de_active_at(const UART_HandleTypeDef *huart, uint64_t t);
/* The first moment at or after t when DE is inactive (t if it is), FAKE_NEVER if never. */
uint64_t fake_hal_de_off_after(const UART_HandleTypeDef *huart, uint64_t t);
/* Level last written to a GPIO pin (0/1), or -1 if never written. */
int fake_hal_gpio_level(const GPIO_TypeDef *port, uint16_t pin);

/* ---- interrupts ----------------------------------------------------------------------------- */
typedef enum { FAKE_IRQ_UART = 0, FAKE_IRQ_DMA_RX, FAKE_IRQ_COUNT } fake_irq_t;
/* An interrupt is taken latency ticks after it pends (at the earliest). */
void fake_hal_irq_latency(UART_HandleTypeDef *huart, fake_irq_t irq, uint32_t ticks);
/* NVIC preemption priority of the UART's interrupts (default 5). */
void fake_hal_irq_priority(UART_HandleTypeDef *huart, uint8_t prio);
/* Which of the two is taken first when both wait (default: the lower vector number of the
 * family's reference board: the UART on the F4 and H7, the DMA channel on the G4). */
void fake_hal_irq_uart_first(UART_HandleTypeDef *huart, bool uart_first);
/* Held (true): interrupts pend but are not taken; fake_hal_irq_service() takes one by hand.
 * fake_hal_irq_release_at(n): held until the n-th register access from now, then taken there
 * (an interrupt arriving at that point of the code that runs). */
void fake_hal_irq_hold(bool hold);
void fake_hal_irq_release_at(unsigned long n);
bool fake_hal_irq_service(UART_HandleTypeDef *huart, bool uart);
bool fake_hal_irq_pending(UART_HandleTypeDef *huart, bool uart);
unsigned fake_hal_irq_entries(const UART_HandleTypeDef *huart, fake_irq_t irq);
/* Replace the failure hook for the fake's own tests (NULL: fake_app_fail). */
void fake_hal_on_fail(void (*fail)(const char *msg));

/* Interrupt mask state: PRIMASK and how often interrupts were disabled; BASEPRI; how often
 * BASEPRI was raised with interrupts enabled on a core with erratum 837070 (Cortex-M7 r0p1). */
uint32_t fake_hal_primask(void);
unsigned fake_hal_irq_disables(void);
uint32_t fake_hal_basepri(void);
unsigned fake_hal_basepri_raised_unmasked(void);
/* __DMB() calls; with require (true), enabling a TX stream with no barrier since its last
 * enable is a violation (the buffer's writes may not have reached memory). */
unsigned fake_hal_dmb_count(void);
void fake_hal_require_dmb(bool require);

/* ---- Cortex-M7: the D-cache and the MPU (H7) ----------------------------------------------- */
void fake_hal_dcache(bool on);
/* MPU region n: base, size 2^(size_log2) bytes, the RASR attribute bits (TEX, C, B, S). */
void fake_hal_mpu_region(unsigned n, uintptr_t base, unsigned size_log2, uint32_t attrs);
void fake_hal_mpu_enable(bool on);

/* ---- timer --------------------------------------------------------------------------------- */
/* Capture/compare channel ch (TIM_CHANNEL_n) matched: fires the OC callback if its interrupt
 * is enabled. Returns whether it fired. */
bool fake_hal_tim_fire(TIM_HandleTypeDef *htim, uint32_t ch);
/* The counter runs `ticks` ticks before timer register access number `access` from now
 * (0 = the next one), raising the flag of each channel whose compare value it reaches. */
void fake_hal_tim_advance_at(TIM_HandleTypeDef *htim, unsigned access, uint32_t ticks);
unsigned fake_hal_tim_accesses(void);
/* Run the counter ticks ticks; whenever a compare flag is up with its interrupt enabled (also
 * before the first tick), do what HAL_TIM_IRQHandler does: clear it, call the OC callback.
 * Returns the callbacks made. */
unsigned fake_hal_tim_run(TIM_HandleTypeDef *htim, uint32_t ticks);

/* ---- CRC unit ------------------------------------------------------------------------------ */
/* The CRC unit's clock off (true): it reads as zeros, as an unclocked peripheral does. */
void fake_hal_crc_unclocked(bool off);

#endif /* J288_FAKE_HAL_H */
