/* j288 port for the STM32Cube HAL; the contract and the application's duties are in
 * j288_stm32.h, the walk-through in docs/porting.md. */
#include "j288_stm32.h"

#include <string.h>

#include "j288/crc32.h"
#include "j288/frame.h"

/* Cache maintenance needs a core with a data cache: CMSIS declares SCB_CleanDCache_by_Addr()
 * and friends only where the device header sets __DCACHE_PRESENT (Cortex-M7). */
#if defined(__DCACHE_PRESENT) && (__DCACHE_PRESENT == 1U)
#define J288_STM32_CACHE_OPS J288_STM32_DCACHE
#else
#define J288_STM32_CACHE_OPS 0
#if J288_STM32_DCACHE
#error "J288_STM32_DCACHE=1 needs a core with a data cache (Cortex-M7: __DCACHE_PRESENT = 1 in the device header); this device has none, so set J288_STM32_DCACHE=0"
#endif
#endif

/* Compile-time checks (C99: a negative array size fails the build). */
typedef char j288_stm32_rx_holds_reply[(J288_STM32_RX_BUF_SIZE > J288_REPLY_LEN) ? 1 : -1];
/* The echo plus half a buffer (the most that waits for a transmit's end) stays under a buffer. */
typedef char j288_stm32_rx_holds_echo[(J288_STM32_RX_BUF_SIZE > 2u * J288_CMD_LEN) ? 1 : -1];
typedef char j288_stm32_rx_whole_lines[(J288_STM32_RX_BUF_SIZE % J288_STM32_DCACHE_LINE) == 0u ? 1 : -1];
typedef char j288_stm32_rx_fits_hal[(J288_STM32_RX_BUF_SIZE <= 0xFFFFu) ? 1 : -1];

/* The callbacks carry only a HAL handle; this table maps it back to the bus. Written only by
 * init/deinit in thread context, read by the ISRs: a slot is filled before it is published,
 * and a pointer store is atomic on Cortex-M. */
static j288_stm32_t *volatile registry[J288_STM32_MAX_BUSES];

/* Kept out of line: the rare paths, so that the common one stays short. */
#if defined(__GNUC__)
#define PORT_NOINLINE __attribute__((noinline))
#else
#define PORT_NOINLINE
#endif

/* ---- cache maintenance (Cortex-M7 D-cache) ---------------------------------------------- */

static void cache_clean(void *buf, size_t len)
{
#if J288_STM32_CACHE_OPS
    SCB_CleanDCache_by_Addr(buf, (int32_t)len);
#else
    (void)buf;
    (void)len;
#endif
}

static void cache_invalidate(void *buf, size_t len)
{
#if J288_STM32_CACHE_OPS
    SCB_InvalidateDCache_by_Addr(buf, (int32_t)len);
#else
    (void)buf;
    (void)len;
#endif
}

/* ---- registers: the two USART models and the two DMA models ----------------------------- */

/* What the application overrides only to watch the accesses (the fake HAL of the tests): the
 * F4's SR write is rc_w0 (a 1 leaves a flag alone), its DR read ends the SR-then-DR sequence
 * that clears IDLE, NE, FE and ORE. */
#ifndef J288_STM32_SR_CLEAR
#define J288_STM32_SR_CLEAR(u, bits) ((u)->SR = ~(uint32_t)(bits))
#endif
#ifndef J288_STM32_DR_READ
#define J288_STM32_DR_READ(u) ((u)->DR)
#endif
/* A bus address in a DMA address register (32 bits on the silicon). */
#ifndef J288_STM32_DMA_ADDR
#define J288_STM32_DMA_ADDR(a) ((uint32_t)(uintptr_t)(a))
#endif
/* Where received bytes go: the bus (a test may watch them on the way). */
#ifdef J288_STM32_RX_SINK
void J288_STM32_RX_SINK(j288_bus_t *bus, const uint8_t *data, size_t len);
#else
#define J288_STM32_RX_SINK j288_bus_on_rx
#endif

#if defined(USART_SR_TC) /* F1, F2, F4: SR/DR */
#define UART_STATUS(u) ((u)->SR)
#define UART_DATA_ADDR(u) (&(u)->DR)
#define UART_IDLE USART_SR_IDLE
#define UART_TC USART_SR_TC
#define UART_PE USART_SR_PE
#define UART_FE USART_SR_FE
#define UART_NE USART_SR_NE
#define UART_ORE USART_SR_ORE
#define UART_TX_DATA_ADDR(u) (&(u)->DR)
/* IDLE and the error flags clear by reading SR (done: sr) then DR. A byte waiting in DR
 * (RXNE) is the DMA's: its own read of DR ends the sequence instead of ours stealing it. */
static void uart_clear(USART_TypeDef *u, uint32_t sr)
{
    if ((sr & USART_SR_RXNE) == 0u) {
        (void)J288_STM32_DR_READ(u);
    }
}
static void uart_clear_tc(USART_TypeDef *u) { J288_STM32_SR_CLEAR(u, USART_SR_TC); }
#else /* ISR/ICR: F0, F3, F7, G0, G4, H7, L4, ... */
#define UART_STATUS(u) ((u)->ISR)
#define UART_DATA_ADDR(u) (&(u)->RDR)
#define UART_IDLE USART_ISR_IDLE
#define UART_TC USART_ISR_TC
#define UART_PE USART_ISR_PE
#define UART_FE USART_ISR_FE
#define UART_NE USART_ISR_NE
#define UART_ORE USART_ISR_ORE
#define UART_TX_DATA_ADDR(u) (&(u)->TDR)
/* The ICR bits are the ISR bits of the same flags. */
static void uart_clear(USART_TypeDef *u, uint32_t sr)
{
    u->ICR = sr & (USART_ICR_IDLECF | USART_ICR_PECF | USART_ICR_FECF | USART_ICR_NECF | USART_ICR_ORECF);
}
static void uart_clear_tc(USART_TypeDef *u) { u->ICR = USART_ICR_TCCF; }
#endif
#define UART_ERRORS (UART_PE | UART_FE | UART_NE | UART_ORE)

#if defined(DMA_SxCR_EN) /* streams: F2, F4, F7, H7 (DMA1/2) */
typedef DMA_Stream_TypeDef dma_regs_t;
#define DMA_CTRL(s) ((s)->CR)
#define DMA_COUNT(s) ((s)->NDTR)
#define DMA_EN DMA_SxCR_EN
#define DMA_CIRC DMA_SxCR_CIRC
#define DMA_IT_ALL (DMA_SxCR_TCIE | DMA_SxCR_HTIE | DMA_SxCR_TEIE | DMA_SxCR_DMEIE)
#define DMA_IT_RX (DMA_SxCR_TCIE | DMA_SxCR_HTIE | DMA_SxCR_TEIE)
#define DMA_F_HT DMA_LISR_HTIF0
#define DMA_F_TC DMA_LISR_TCIF0
#define DMA_F_TE DMA_LISR_TEIF0
#define DMA_F_ALL (DMA_LISR_FEIF0 | DMA_LISR_DMEIF0 | DMA_LISR_TEIF0 | DMA_LISR_HTIF0 | DMA_LISR_TCIF0)
/* The HAL keeps where a stream's flags are: LISR or HISR (IFCR 8 bytes on), and the shift. */
static volatile uint32_t *dma_isr_of(const DMA_HandleTypeDef *h)
{
    return (volatile uint32_t *)(uintptr_t)h->StreamBaseAddress;
}
static volatile uint32_t *dma_ifcr_of(const DMA_HandleTypeDef *h) { return &dma_isr_of(h)[2]; }
static uint8_t dma_shift_of(const DMA_HandleTypeDef *h) { return (uint8_t)h->StreamIndex; }
static void dma_point(dma_regs_t *s, const volatile uint32_t *periph, const void *mem)
{
    s->PAR = J288_STM32_DMA_ADDR(periph);
    s->M0AR = J288_STM32_DMA_ADDR(mem);
}
/* Direct mode: in FIFO mode the counter moves when a byte leaves the UART, but the byte
 * reaches memory only at the FIFO's threshold, so positions read from the counter would
 * point past what is in the buffer. */
static void dma_direct(dma_regs_t *s) { s->FCR &= ~(uint32_t)DMA_SxFCR_DMDIS; }
#else /* channels: F0, F1, F3, G0, G4, L4, ... */
typedef DMA_Channel_TypeDef dma_regs_t;
#define DMA_CTRL(s) ((s)->CCR)
#define DMA_COUNT(s) ((s)->CNDTR)
#define DMA_EN DMA_CCR_EN
#define DMA_CIRC DMA_CCR_CIRC
#define DMA_IT_ALL (DMA_CCR_TCIE | DMA_CCR_HTIE | DMA_CCR_TEIE)
#define DMA_IT_RX DMA_IT_ALL
#define DMA_F_HT DMA_ISR_HTIF1
#define DMA_F_TC DMA_ISR_TCIF1
#define DMA_F_TE DMA_ISR_TEIF1
#define DMA_F_ALL (DMA_ISR_GIF1 | DMA_ISR_TCIF1 | DMA_ISR_HTIF1 | DMA_ISR_TEIF1)
static volatile uint32_t *dma_isr_of(const DMA_HandleTypeDef *h) { return &h->DmaBaseAddress->ISR; }
static volatile uint32_t *dma_ifcr_of(const DMA_HandleTypeDef *h) { return &h->DmaBaseAddress->IFCR; }
static uint8_t dma_shift_of(const DMA_HandleTypeDef *h) { return (uint8_t)(h->ChannelIndex & 0x1Fu); }
static void dma_point(dma_regs_t *s, const volatile uint32_t *periph, const void *mem)
{
    s->CPAR = J288_STM32_DMA_ADDR(periph);
    s->CMAR = J288_STM32_DMA_ADDR(mem);
}
static void dma_direct(dma_regs_t *s) { (void)s; } /* a channel has no FIFO */
#endif

/* Stop a stream: clear its enable bit and wait, a bounded number of reads, for the stream to
 * finish its current single transfer (never SysTick: this runs in the bus's interrupts).
 * Returns whether it stopped. */
static bool dma_stop(dma_regs_t *s)
{
    DMA_CTRL(s) &= ~(uint32_t)DMA_EN;
    for (uint32_t i = 0; (i < J288_STM32_STOP_SPINS) && ((DMA_CTRL(s) & DMA_EN) != 0u); i++) {
    }
    return (DMA_CTRL(s) & DMA_EN) == 0u;
}

/* ---- port operations -------------------------------------------------------------------- */

static uint32_t timer_now(const j288_stm32_t *p)
{
    return (uint32_t)__HAL_TIM_GET_COUNTER(p->cfg.htim);
}

static uint32_t now_of(const j288_stm32_t *p)
{
    return (p->cfg.now_us != NULL) ? p->cfg.now_us() : timer_now(p);
}

static uint32_t op_now_us(void *ctx)
{
    return now_of(ctx);
}

static void de_write(const j288_stm32_t *p, bool active)
{
    if (p->cfg.de_port != NULL) {
        bool high = active != p->cfg.de_active_low;
        HAL_GPIO_WritePin(p->cfg.de_port, p->cfg.de_pin, high ? GPIO_PIN_SET : GPIO_PIN_RESET);
    }
}

/* Position the RX stream has reached in the circular buffer. */
static uint32_t rx_head(const j288_stm32_t *p)
{
    uint32_t left = DMA_COUNT((dma_regs_t *)p->rx_stream);
    return (left - 1u < J288_STM32_RX_BUF_SIZE) ? J288_STM32_RX_BUF_SIZE - left : 0u;
}

static uint32_t rx_pending(const j288_stm32_t *p, uint32_t head)
{
    return (head + J288_STM32_RX_BUF_SIZE - p->rx_pos) % J288_STM32_RX_BUF_SIZE;
}

/* Hand the bus the received bytes from rx_pos up to head, in order, once. */
static void rx_take(j288_stm32_t *p, uint32_t head)
{
    const uint8_t *rx = p->cfg.dma->rx;
    uint32_t from = p->rx_pos;
    uint32_t n = rx_pending(p, head);

    if (n == 0u) {
        return;
    }
    cache_invalidate(p->cfg.dma->rx, J288_STM32_RX_BUF_SIZE);
    p->rx_pos = (uint16_t)head;
    p->stats.rx_bytes += n;
    if (head > from) {
        J288_STM32_RX_SINK(&p->bus, &rx[from], n);
    } else if (n <= J288_STM32_BOUNCE_SIZE) { /* wrapped: one piece for the bus's fast path */
        uint32_t tail = J288_STM32_RX_BUF_SIZE - from;
        memcpy(p->bounce, &rx[from], tail);
        memcpy(&p->bounce[tail], rx, head);
        J288_STM32_RX_SINK(&p->bus, p->bounce, n);
    } else {
        J288_STM32_RX_SINK(&p->bus, &rx[from], J288_STM32_RX_BUF_SIZE - from);
        J288_STM32_RX_SINK(&p->bus, rx, head);
    }
}

/* Bytes up to position to that are not handed over: heard before a transmit (nobody's) or
 * our own echo. */
static void rx_skip(j288_stm32_t *p, uint32_t to)
{
    p->stats.rx_skipped += rx_pending(p, to);
    p->rx_pos = (uint16_t)to;
}

/* The line is driven only through DE: the receiver never goes off. */
static void op_set_dir(void *ctx, j288_dir_t dir)
{
    de_write(ctx, dir == J288_DIR_TX);
}

/* A transmit still running (its complete interrupt lost) is stopped first. A stream stops
 * by itself at the end of a transfer; a channel keeps its enable bit, so only a count left
 * says it is still running. */
static bool tx_stream_ready(j288_stm32_t *p, dma_regs_t *s)
{
    uint32_t ctrl = DMA_CTRL(s);
    if ((ctrl & DMA_EN) == 0u) {
        return true;
    }
    if (DMA_COUNT(s) != 0u) {
        p->stats.dma_resets++;
    }
#if defined(DMA_SxCR_EN)
    return dma_stop(s);
#else
    DMA_CTRL(s) = ctrl & ~(uint32_t)DMA_EN; /* a channel stops at once */
    return true;
#endif
}

static int op_start_tx(void *ctx, const uint8_t *data, size_t len)
{
    j288_stm32_t *p = ctx;
    dma_regs_t *s = p->tx_stream;
    USART_TypeDef *u = p->uart;

    if ((data == NULL) || (len == 0u) || (len > J288_CMD_LEN)) {
        return J288_ERR_BAD_ARG;
    }
    if (!tx_stream_ready(p, s)) {
        return J288_ERR_PORT;
    }
    /* Copy into the DMA buffer: the bus object may sit where the DMA cannot read. The usual
     * length is a constant copy the compiler inlines. */
    if (len == J288_CMD_LEN) {
        memcpy(p->cfg.dma->tx, data, J288_CMD_LEN);
    } else {
        memcpy(p->cfg.dma->tx, data, len);
    }
    cache_clean(p->cfg.dma->tx, J288_STM32_TX_BUF_SIZE);
    /* The echo starts here; what was heard before is nobody's (skipped at the end). */
    p->tx_start = (uint16_t)rx_head(p);
    p->tx_len = (uint16_t)len;
    p->tx_on = true;
    p->stats.tx_frames++;
    *p->tx_ifcr = (uint32_t)DMA_F_ALL << p->tx_shift;
    DMA_COUNT(s) = (uint32_t)len;
    if (p->tc_ends_tx) {
        uart_clear_tc(u);
        u->CR1 |= USART_CR1_TCIE;
    }
    DMA_CTRL(s) |= DMA_EN;
    return J288_OK;
}

static uint32_t channel_it(uint32_t channel)
{
    switch (channel) {
    case TIM_CHANNEL_1: return TIM_IT_CC1;
    case TIM_CHANNEL_2: return TIM_IT_CC2;
    case TIM_CHANNEL_3: return TIM_IT_CC3;
    case TIM_CHANNEL_4: return TIM_IT_CC4;
    default: return 0u;
    }
}

static uint32_t channel_egr(uint32_t channel)
{
    switch (channel) {
    case TIM_CHANNEL_1: return TIM_EGR_CC1G;
    case TIM_CHANNEL_2: return TIM_EGR_CC2G;
    case TIM_CHANNEL_3: return TIM_EGR_CC3G;
    case TIM_CHANNEL_4: return TIM_EGR_CC4G;
    default: return 0u;
    }
}

static HAL_TIM_ActiveChannel channel_active(uint32_t channel)
{
    switch (channel) {
    case TIM_CHANNEL_1: return HAL_TIM_ACTIVE_CHANNEL_1;
    case TIM_CHANNEL_2: return HAL_TIM_ACTIVE_CHANNEL_2;
    case TIM_CHANNEL_3: return HAL_TIM_ACTIVE_CHANNEL_3;
    case TIM_CHANNEL_4: return HAL_TIM_ACTIVE_CHANNEL_4;
    default: return HAL_TIM_ACTIVE_CHANNEL_CLEARED;
    }
}

/* Ticks from `from` to `to` on a counter that wraps after arr. */
static uint32_t ticks_between(uint32_t from, uint32_t to, uint32_t arr)
{
    uint32_t d = to - from;
    return ((arr == 0xFFFFFFFFu) || (to >= from)) ? d : d + arr + 1u;
}

/* The timer counts at 1 MHz, free running (maybe 16 bits): the compare goes delay ticks
 * ahead of the counter, modulo its period, whatever clock now_us comes from. A delay longer
 * than the period is cut to one period; on_timer then sees that the deadline has not passed
 * and sets the compare again for the rest.
 * The counter runs on while this executes (1 us is a few hundred instructions, and delays of
 * 1-2 us happen: the default guard is 2 us). So the old flag is cleared BEFORE the compare is
 * written (a match after the write then stays seen), and once armed the counter is read again:
 * if it may have passed the compare before the write took effect, or the deadline is already
 * due, the compare event is generated by software (EGR) rather than waiting a whole timer
 * period (65.5 ms at 16 bits, 71.6 minutes at 32) for the next match. An extra event only
 * costs a re-arm in on_timer. */
static void timer_set(j288_stm32_t *p, uint32_t deadline_us)
{
    TIM_HandleTypeDef *htim = p->cfg.htim;
    uint32_t it = channel_it(p->cfg.tim_channel);
    uint32_t arr = (uint32_t)__HAL_TIM_GET_AUTORELOAD(htim);
    int32_t delay;
    uint32_t ticks, start, cmp;

    __HAL_TIM_DISABLE_IT(htim, it);
    __HAL_TIM_CLEAR_FLAG(htim, it); /* TIM_FLAG_CCn has the same bit as TIM_IT_CCn */
    delay = (int32_t)(deadline_us - now_of(p));
    if (delay < 1) {
        htim->Instance->EGR = channel_egr(p->cfg.tim_channel); /* due already */
        __HAL_TIM_ENABLE_IT(htim, it);
        return;
    }
    ticks = ((arr != 0xFFFFFFFFu) && ((uint32_t)delay > arr)) ? arr : (uint32_t)delay;
    start = (uint32_t)__HAL_TIM_GET_COUNTER(htim);
    cmp = start + ticks;
    if ((arr != 0xFFFFFFFFu) && ((cmp > arr) || (cmp < start))) {
        cmp -= arr + 1u;
    }
    __HAL_TIM_SET_COMPARE(htim, p->cfg.tim_channel, cmp);
    __HAL_TIM_ENABLE_IT(htim, it);
    if (ticks_between(start, (uint32_t)__HAL_TIM_GET_COUNTER(htim), arr) >= ticks) {
        htim->Instance->EGR = channel_egr(p->cfg.tim_channel);
    }
}

/* The deadline is stored before the compare is written, so a compare interrupt taken in
 * between re-arms for the new deadline, which the write below then repeats. */
static void op_arm_timeout(void *ctx, uint32_t deadline_us)
{
    j288_stm32_t *p = ctx;
    p->tim_deadline = deadline_us;
    timer_set(p, deadline_us);
}

#if J288_STM32_HW_CRC
static uint32_t op_crc32(void *ctx, const uint8_t *data, size_t nwords)
{
    const j288_stm32_t *p = ctx;
    return j288_stm32_crc32(p->cfg.hcrc, data, nwords);
}
#endif

/* Thread-context sections of the bus against its own interrupts. BASEPRI at the bus's
 * priority masks the bus's interrupts and the less urgent ones only; __set_BASEPRI_MAX never
 * lowers a mask the caller already holds. PRIMASK (every interrupt) where BASEPRI cannot
 * serve: priority 0, or a core without it. The previous state is restored either way. */
#if defined(__ARM_ARCH_6M__) || defined(__ARM_ARCH_8M_BASE__)
#define J288_STM32_HAS_BASEPRI 0
#else
#define J288_STM32_HAS_BASEPRI 1
#endif

static void op_lock(void *ctx)
{
    j288_stm32_t *p = ctx;
    uint32_t saved;
#if J288_STM32_HAS_BASEPRI
    if (p->cfg.irq_priority != 0u) {
        saved = __get_BASEPRI();
        __set_BASEPRI_MAX((uint32_t)p->cfg.irq_priority << (8u - __NVIC_PRIO_BITS));
        p->lock_saved = saved;
        return;
    }
#endif
    saved = __get_PRIMASK();
    __disable_irq();
    p->lock_saved = saved;
}

static void op_unlock(void *ctx)
{
    const j288_stm32_t *p = ctx;
#if J288_STM32_HAS_BASEPRI
    if (p->cfg.irq_priority != 0u) {
        __set_BASEPRI(p->lock_saved);
        return;
    }
#endif
    __set_PRIMASK(p->lock_saved);
}

/* The one operations table. Each bus gets a copy (j288_stm32_t.ops) without the optional
 * operations its configuration lacks: no timer, or a bus that does not advance in its
 * interrupts, no arm_timeout (the application polls, and a poll looks at the clock); no CRC
 * unit, no crc32 (the library's compile-time backend). */
static const j288_port_t port_ops = {
    .start_tx = op_start_tx,
    .now_us = op_now_us,
    .set_dir = op_set_dir, /* no start_rx: the receiver never stops */
    .arm_timeout = op_arm_timeout,
#if J288_STM32_HW_CRC
    .crc32 = op_crc32,
#endif
    .lock = op_lock,
    .unlock = op_unlock,
};

static void pick_ops(j288_stm32_t *p, bool advance_in_isr)
{
    p->ops = port_ops;
    if ((p->cfg.htim == NULL) || !advance_in_isr) {
        p->ops.arm_timeout = NULL; /* polled, the bus reads the clock itself (bus.h) */
    }
#if J288_STM32_HW_CRC
    if (p->cfg.hcrc == NULL) {
        p->ops.crc32 = NULL;
    }
#endif
}

/* ---- lifecycle -------------------------------------------------------------------------- */

#if J288_STM32_HW_CRC
/* Families with a configurable unit (G4, H7, F7, L4, ...; their HAL defines the input
 * formats) compute whatever the handle says: it must say the unit's reset configuration. */
static bool crc_handle_is_servo_crc(const CRC_HandleTypeDef *hcrc)
{
#if defined(CRC_INPUTDATA_FORMAT_WORDS)
    const CRC_InitTypeDef *in = &hcrc->Init;
    bool poly = (in->DefaultPolynomialUse == DEFAULT_POLYNOMIAL_ENABLE) ||
                ((in->GeneratingPolynomial == 0x04C11DB7u) && (in->CRCLength == CRC_POLYLENGTH_32B));
    bool init = (in->DefaultInitValueUse == DEFAULT_INIT_VALUE_ENABLE) || (in->InitValue == 0xFFFFFFFFu);
    return poly && init && (hcrc->InputDataFormat == CRC_INPUTDATA_FORMAT_WORDS) &&
           (in->InputDataInversionMode == CRC_INPUTDATA_INVERSION_NONE) &&
           (in->OutputDataInversionMode == CRC_OUTPUTDATA_INVERSION_DISABLE);
#else
    (void)hcrc; /* the F4-class unit has one fixed configuration */
    return true;
#endif
}

/* A known answer from the unit itself: catches what no handle field shows (the unit's clock
 * off, HAL_CRC_Init never called, registers reprogrammed by other code). */
static bool crc_unit_is_servo_crc(CRC_HandleTypeDef *hcrc)
{
    static const uint8_t probe[8] = {0x6a, 0x32, 0x38, 0x38, 0xfe, 0xee, 0x00, 0x5a};
    return crc_handle_is_servo_crc(hcrc) &&
           (j288_stm32_crc32(hcrc, probe, 2u) == j288_crc32_update_bitwise(J288_CRC32_INIT, probe, 2u));
}
#endif

/* RAM the DMA controllers cannot reach, per family (reference manuals' bus matrices). */
static bool dma_reaches(const void *buf)
{
    uintptr_t a = (uintptr_t)buf;
#if defined(STM32H7)
    return (a >= 0x00040000u) && ((a < 0x20000000u) || (a >= 0x20020000u)); /* ITCM, DTCM */
#elif defined(STM32F4)
    return (a < 0x10000000u) || (a >= 0x10010000u); /* CCM data RAM (F405/407/42x/43x/469) */
#else
    (void)a;
    return true;
#endif
}

static int check_config(const j288_stm32_config_t *cfg, const j288_bus_config_t *bus_cfg)
{
    if ((cfg->huart == NULL) || (cfg->dma == NULL)) {
        return J288_ERR_NULL;
    }
    if ((cfg->huart->hdmatx == NULL) || (cfg->huart->hdmarx == NULL) ||
        (cfg->huart->Instance == NULL)) {
        return J288_ERR_BAD_CONFIG; /* the UART has no DMA streams linked */
    }
    if (!dma_reaches(cfg->dma) ||
        (J288_STM32_CACHE_OPS && (((uintptr_t)cfg->dma % J288_STM32_DCACHE_LINE) != 0u))) {
        return J288_ERR_BAD_CONFIG;
    }
    if (cfg->irq_priority >= (1u << __NVIC_PRIO_BITS)) {
        return J288_ERR_BAD_CONFIG; /* shifted into BASEPRI it would mask the wrong level, or none */
    }
    if ((bus_cfg != NULL) && bus_cfg->echo && cfg->deaf_while_transmitting) {
        return J288_ERR_BAD_CONFIG; /* the line cannot hear the echo the bus would wait for */
    }
    if ((cfg->htim != NULL) && (channel_it(cfg->tim_channel) == 0u)) {
        return J288_ERR_BAD_CONFIG;
    }
#if J288_STM32_HW_CRC
    if ((cfg->hcrc != NULL) && !crc_unit_is_servo_crc(cfg->hcrc)) {
        return J288_ERR_BAD_CONFIG;
    }
#endif
    if (cfg->now_us == NULL) {
        if ((cfg->htim == NULL) || (__HAL_TIM_GET_AUTORELOAD(cfg->htim) != 0xFFFFFFFFu)) {
            return J288_ERR_BAD_CONFIG;
        }
    }
    return J288_OK;
}

static void pin_drive(const j288_stm32_config_t *cfg)
{
    if ((cfg->tx_port == NULL) || (cfg->tx_drive == J288_STM32_PIN_AS_CONFIGURED)) {
        return;
    }
    if (cfg->tx_drive == J288_STM32_PIN_OPEN_DRAIN) {
        cfg->tx_port->OTYPER |= cfg->tx_pin;
    } else {
        cfg->tx_port->OTYPER &= ~(uint32_t)cfg->tx_pin;
    }
}

/* The registers behind the handles, kept so that no interrupt walks the handles. */
static void take_registers(j288_stm32_t *p)
{
    const DMA_HandleTypeDef *tx = p->cfg.huart->hdmatx;
    const DMA_HandleTypeDef *rx = p->cfg.huart->hdmarx;
    p->uart = p->cfg.huart->Instance;
    p->tx_stream = tx->Instance;
    p->rx_stream = rx->Instance;
    p->tx_ifcr = dma_ifcr_of(tx);
    p->tx_shift = dma_shift_of(tx);
    p->rx_isr = dma_isr_of(rx);
    p->rx_ifcr = dma_ifcr_of(rx);
    p->rx_shift = dma_shift_of(rx);
}

/* The UART as the port runs it: one-bit sampling (written with the UART off, as the newer
 * USART requires), the error interrupt off, both directions and both DMA requests on for
 * good, the idle-line interrupt. Then the streams: TX pointed at its buffer with no
 * interrupt (the UART's transmit complete ends a transmit); RX circular and direct (no FIFO)
 * over its buffer, started before the receiver is on, with its half/complete/error
 * interrupts. */
static bool take_line(j288_stm32_t *p)
{
    USART_TypeDef *u = p->uart;
    dma_regs_t *tx = p->tx_stream;
    dma_regs_t *rx = p->rx_stream;

    u->CR1 &= ~(uint32_t)(USART_CR1_UE | USART_CR1_RE | USART_CR1_TCIE);
    u->CR3 = (u->CR3 | USART_CR3_ONEBIT | USART_CR3_DMAR | USART_CR3_DMAT) & ~(uint32_t)USART_CR3_EIE;
    if (!dma_stop(tx) || !dma_stop(rx)) {
        return false;
    }
    dma_point(tx, UART_TX_DATA_ADDR(u), p->cfg.dma->tx);
    DMA_CTRL(tx) &= ~(uint32_t)(DMA_IT_ALL | DMA_CIRC);
    *p->tx_ifcr = (uint32_t)DMA_F_ALL << p->tx_shift;
    dma_point(rx, UART_DATA_ADDR(u), p->cfg.dma->rx);
    dma_direct(rx);
    DMA_COUNT(rx) = J288_STM32_RX_BUF_SIZE;
    cache_invalidate(p->cfg.dma->rx, J288_STM32_RX_BUF_SIZE);
    *p->rx_ifcr = (uint32_t)DMA_F_ALL << p->rx_shift;
    DMA_CTRL(rx) = (DMA_CTRL(rx) & ~(uint32_t)DMA_IT_ALL) | DMA_CIRC | DMA_IT_RX | DMA_EN;
    p->rx_pos = 0u;
    u->CR1 = (u->CR1 & ~(uint32_t)USART_CR1_PEIE) | USART_CR1_UE | USART_CR1_TE | USART_CR1_RE | USART_CR1_IDLEIE;
    return true;
}

int j288_stm32_init(j288_stm32_t *p, const j288_stm32_config_t *cfg,
                    const j288_bus_config_t *bus_cfg)
{
    size_t free_slot = J288_STM32_MAX_BUSES;
    int rc;

    if ((p == NULL) || (cfg == NULL)) {
        return J288_ERR_NULL;
    }
    rc = check_config(cfg, bus_cfg);
    if (rc != J288_OK) {
        return rc;
    }
    for (size_t i = 0; i < J288_STM32_MAX_BUSES; i++) {
        const j288_stm32_t *q = registry[i];
        if ((q == p) || ((q != NULL) && (q->cfg.huart == cfg->huart))) {
            return J288_ERR_BUSY;
        }
        if ((q == NULL) && (free_slot == J288_STM32_MAX_BUSES)) {
            free_slot = i;
        }
    }
    if (free_slot == J288_STM32_MAX_BUSES) {
        return J288_ERR_BUSY;
    }

    memset(p, 0, sizeof *p);
    p->cfg = *cfg;
    p->echo = (bus_cfg != NULL) && bus_cfg->echo;
    p->tc_ends_tx = (cfg->de_port != NULL) || cfg->deaf_while_transmitting;
    pick_ops(p, (bus_cfg != NULL) && bus_cfg->advance_in_isr);
    take_registers(p);
    rc = j288_bus_init(&p->bus, &p->ops, p, bus_cfg);
    if (rc != J288_OK) {
        return rc;
    }
    if (cfg->htim != NULL) {
        __HAL_TIM_DISABLE_IT(cfg->htim, channel_it(cfg->tim_channel));
    }
    de_write(p, false);
    pin_drive(cfg);
    if (!take_line(p)) {
        return J288_ERR_PORT;
    }
    registry[free_slot] = p;
    p->live = true;
    return J288_OK;
}

void j288_stm32_deinit(j288_stm32_t *p)
{
    for (size_t i = 0; i < J288_STM32_MAX_BUSES; i++) {
        if ((p != NULL) && (registry[i] == p)) {
            p->live = false;
            registry[i] = NULL;
            if (p->cfg.htim != NULL) {
                __HAL_TIM_DISABLE_IT(p->cfg.htim, channel_it(p->cfg.tim_channel));
            }
            /* A command still on the wire is cut short rather than left to finish after the
             * transceiver has been released; the UART is left quiet for the HAL. */
            p->uart->CR1 &= ~(uint32_t)(USART_CR1_TCIE | USART_CR1_IDLEIE);
            p->uart->CR3 &= ~(uint32_t)(USART_CR3_DMAR | USART_CR3_DMAT);
            (void)dma_stop(p->tx_stream);
            (void)dma_stop(p->rx_stream);
            DMA_CTRL((dma_regs_t *)p->rx_stream) &= ~(uint32_t)(DMA_IT_ALL | DMA_CIRC);
            de_write(p, false);
        }
    }
}

j288_bus_t *j288_stm32_bus(j288_stm32_t *p)
{
    return (p != NULL) ? &p->bus : NULL;
}

uint32_t j288_stm32_now_us(const j288_stm32_t *p)
{
    return (p != NULL) ? now_of(p) : 0u;
}

const j288_stm32_stats_t *j288_stm32_stats(const j288_stm32_t *p)
{
    return (p != NULL) ? &p->stats : NULL;
}

/* ---- interrupts ------------------------------------------------------------------------- */

/* Registered: init sets it last, deinit clears it first (the IRQ entries look at nothing
 * else, so that they need no search). */
static bool registered(const j288_stm32_t *p)
{
    return (p != NULL) && p->live;
}

/* Error flags seen: counted one by one and reported to the bus as one line error; the bytes
 * themselves stay where the DMA put them, for the CRC to judge. */
PORT_NOINLINE static void line_errors(j288_stm32_t *p, uint32_t sr)
{
    uint32_t f = 0u;
    if ((sr & UART_NE) != 0u) {
        p->stats.noise_errors++;
        f |= J288_LINE_NOISE;
    }
    if ((sr & UART_FE) != 0u) {
        p->stats.framing_errors++;
        f |= J288_LINE_FRAMING;
    }
    if ((sr & UART_ORE) != 0u) {
        p->stats.overruns++;
        f |= J288_LINE_OVERRUN;
    }
    if ((sr & UART_PE) != 0u) {
        p->stats.parity_errors++;
        f |= J288_LINE_PARITY;
    }
    j288_bus_on_error(&p->bus, f);
}

/* Our transmit has come back whole: the receiver hears the line, so the end of the echo is
 * the end of the transmit (its last stop bit sampled). Seen at the idle line that follows it,
 * or at a half/complete event when the reply follows without a pause. */
static bool echo_heard(const j288_stm32_t *p, uint32_t head)
{
    uint32_t since = (head + J288_STM32_RX_BUF_SIZE - p->tx_start) % J288_STM32_RX_BUF_SIZE;
    return !p->cfg.deaf_while_transmitting && (since >= p->tx_len);
}

/* Where the echo ends. At transmit complete (a DE pin) the last echoed byte was sampled half a
 * bit earlier and the DMA stores it within a few bus cycles: waited for, a bounded number of
 * reads; an echo cut short (a collision) ends where the bytes end. */
static uint32_t echo_end(const j288_stm32_t *p)
{
    return ((uint32_t)p->tx_start + p->tx_len) % J288_STM32_RX_BUF_SIZE;
}

PORT_NOINLINE static uint32_t echo_end_at_tc(const j288_stm32_t *p)
{
    uint32_t head = rx_head(p);
    if (p->cfg.deaf_while_transmitting) {
        return p->tx_start; /* no echo */
    }
    for (uint32_t i = 0; (i < J288_STM32_STOP_SPINS) && !echo_heard(p, head); i++) {
        head = rx_head(p);
    }
    return echo_heard(p, head) ? echo_end(p) : head;
}

/* The end of a transmit: the whole echo is in (the line hears us), or transmit complete (a DE
 * pin to drop at once, or a deaf line). The echo is handed to the bus to check, or skipped;
 * then the bus turns the line (DE) and waits for the reply, whose bytes may already follow. */
static void tx_complete(j288_stm32_t *p, uint32_t end)
{
    p->tx_on = false;
    if (p->tc_ends_tx) {
        p->uart->CR1 &= ~(uint32_t)USART_CR1_TCIE;
    }
    if (p->echo) {
        rx_skip(p, p->tx_start);
        rx_take(p, end);
    }
    rx_skip(p, end);
    j288_bus_on_tx_done(&p->bus);
}

void j288_stm32_on_uart_irq(j288_stm32_t *p)
{
    USART_TypeDef *u;
    uint32_t sr;

    if (!registered(p)) {
        return;
    }
    u = p->uart;
    sr = UART_STATUS(u);
    if (p->tc_ends_tx && ((sr & UART_TC) != 0u) && ((u->CR1 & USART_CR1_TCIE) != 0u)) {
        tx_complete(p, echo_end_at_tc(p)); /* DE to drop at once, or a deaf line */
    }
    if ((sr & (UART_IDLE | UART_ERRORS)) != 0u) {
        uint32_t head = rx_head(p);
        uart_clear(u, sr);
        p->stats.rx_events++;
        if (p->tx_on && !p->tc_ends_tx && echo_heard(p, head)) {
            tx_complete(p, echo_end(p));
        }
        if (!p->tx_on && (head != p->rx_pos)) {
            rx_take(p, head);
        }
        if ((sr & UART_ERRORS) != 0u) {
            line_errors(p, sr);
        }
    }
}

/* Half and complete: handed over only once a quarter of the buffer waits, so that a reply is
 * usually handed over whole at its idle line; the next half event comes at most half a buffer
 * later, so less than three quarters ever wait. During a transmit they find our echo: left
 * until it is whole (at most the 20 bytes and half a buffer wait: the buffer holds more than
 * twice a command), then the transmit ends here. A transfer error stops the stream: it is
 * restarted at the start of the buffer. */
void j288_stm32_on_dma_rx_irq(j288_stm32_t *p)
{
    uint32_t flags, head;

    if (!registered(p)) {
        return;
    }
    flags = (*p->rx_isr >> p->rx_shift) & (DMA_F_HT | DMA_F_TC | DMA_F_TE);
    *p->rx_ifcr = flags << p->rx_shift;
    p->stats.rx_events++;
    if ((flags & DMA_F_TE) != 0u) {
        dma_regs_t *rx = p->rx_stream;
        rx_take(p, rx_head(p));
        p->stats.dma_errors++;
        (void)dma_stop(rx);
        dma_point(rx, UART_DATA_ADDR(p->uart), p->cfg.dma->rx);
        DMA_COUNT(rx) = J288_STM32_RX_BUF_SIZE;
        p->rx_pos = 0u;
        DMA_CTRL(rx) |= DMA_EN;
        j288_bus_on_error(&p->bus, J288_LINE_DMA);
        return;
    }
    head = rx_head(p);
    if (p->tx_on) {
        if (p->tc_ends_tx || !echo_heard(p, head)) {
            return; /* our own echo, not whole yet, or transmit complete to come */
        }
        tx_complete(p, echo_end(p));
    }
    if (rx_pending(p, head) >= J288_STM32_RX_BUF_SIZE / 4u) {
        rx_take(p, head);
    }
}

bool j288_stm32_on_timer(TIM_HandleTypeDef *htim)
{
    bool mine = false;
    for (size_t i = 0; i < J288_STM32_MAX_BUSES; i++) {
        j288_stm32_t *p = registry[i];
        if ((p == NULL) || (htim == NULL) || (p->cfg.htim != htim) ||
            (htim->Channel != channel_active(p->cfg.tim_channel))) {
            continue;
        }
        p->stats.timer_events++;
        mine = true;
        /* The contract is "at or after the deadline": an early compare (a delay cut to the
         * timer's period, or a timer running a little ahead of now_us) only re-arms, since
         * the bus would take nothing from it and would not arm the timer again. */
        if ((int32_t)(now_of(p) - p->tim_deadline) < 0) {
            p->stats.timer_rearms++;
            timer_set(p, p->tim_deadline);
            continue;
        }
        __HAL_TIM_DISABLE_IT(htim, channel_it(p->cfg.tim_channel)); /* one-shot */
        j288_bus_on_timer(&p->bus);
    }
    return mine;
}

/* ---- CRC unit --------------------------------------------------------------------------- */

#if J288_STM32_HW_CRC
#define CRC_CHUNK_WORDS 8u

uint32_t j288_stm32_crc32(CRC_HandleTypeDef *hcrc, const uint8_t *data, size_t nwords)
{
    uint32_t scratch[CRC_CHUNK_WORDS];
    uint32_t crc = J288_CRC32_INIT;
    uint32_t saved;
    bool first = true;

    if ((hcrc == NULL) || ((data == NULL) && (nwords != 0u))) {
        return j288_crc32_update_nibble(J288_CRC32_INIT, data, (data == NULL) ? 0u : nwords);
    }
    J288_STM32_CRC_LOCK(saved);
    while (first || (nwords > 0u)) {
        size_t n = (nwords < CRC_CHUNK_WORDS) ? nwords : CRC_CHUNK_WORDS;
        for (size_t i = 0; i < n; i++) {
            scratch[i] = j288_get_u32le(&data[4u * i]);
        }
        crc = first ? HAL_CRC_Calculate(hcrc, scratch, (uint32_t)n)
                    : HAL_CRC_Accumulate(hcrc, scratch, (uint32_t)n);
        first = false;
        data = (n > 0u) ? &data[4u * n] : data;
        nwords -= n;
    }
    J288_STM32_CRC_UNLOCK(saved);
    return crc;
}

/* The one mutable global the library-wide HW backend needs: it has no context argument. */
static CRC_HandleTypeDef *volatile default_crc;

void j288_stm32_crc_attach(CRC_HandleTypeDef *hcrc)
{
    default_crc = hcrc;
}

uint32_t j288_stm32_crc32_default(const uint8_t *data, size_t nwords)
{
    return j288_stm32_crc32(default_crc, data, nwords);
}
#endif
