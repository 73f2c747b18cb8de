/* j288 port for the STM32Cube HAL; the contract and the application's duties are in
 * j288_stm32.h, the reasoning and the timing budget in docs/stm32.md. */
#include "j288_stm32.h"

#include <string.h>

#include "j288/crc32.h"
#include "j288/frame.h"

/* Cache maintenance needs a core with a data cache: CMSIS declares SCB_CleanDCache_by_Addr()
 * and friends only where the device header sets __DCACHE_PRESENT (Cortex-M7). */
#if defined(__DCACHE_PRESENT) && (__DCACHE_PRESENT == 1U)
#define J288_STM32_CACHE_OPS J288_STM32_DCACHE
#define J288_STM32_CACHE_CORE 1
#else
#define J288_STM32_CACHE_OPS 0
#define J288_STM32_CACHE_CORE 0
#if J288_STM32_DCACHE
#error "J288_STM32_DCACHE=1 needs a core with a data cache (Cortex-M7: __DCACHE_PRESENT = 1 in the device header); this device has none, so set J288_STM32_DCACHE=0"
#endif
#endif

/* Compile-time checks (C99: a negative array size fails the build). */
typedef char j288_stm32_rx_holds_reply[(J288_STM32_RX_BUF_SIZE > J288_REPLY_LEN) ? 1 : -1];
/* The echo and a reply fit in half a buffer's time of deferral (docs/stm32.md, timing budget). */
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

/* Every access to a peripheral register, so that a model of the silicon can watch them (the
 * tests' fake HAL defines J288_STM32_REG; see the header). */
#ifndef J288_STM32_REG
#define J288_STM32_REG(reg) (reg)
#endif
#define R(reg) J288_STM32_REG(reg)

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

/* The F4's two accesses with side effects (the tests' fake HAL watches them whole): SR's write
 * is rc_w0 (a 1 leaves a flag alone), its DR read ends the SR-then-DR sequence that clears
 * IDLE, NE, FE and ORE. */
#ifndef J288_STM32_SR_CLEAR
#define J288_STM32_SR_CLEAR(u, bits) (R((u)->SR) = ~(uint32_t)(bits))
#endif
#ifndef J288_STM32_DR_READ
#define J288_STM32_DR_READ(u) (R((u)->DR))
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
#define UART_STATUS(u) R((u)->SR)
#define UART_RX_DATA_ADDR(u) (&(u)->DR)
#define UART_TX_DATA_ADDR(u) (&(u)->DR)
#define UART_IDLE USART_SR_IDLE
#define UART_TC USART_SR_TC
#define UART_PE USART_SR_PE
#define UART_FE USART_SR_FE
#define UART_NE USART_SR_NE
#define UART_ORE USART_SR_ORE
/* Flags that say a received byte never reached the DMA: an overrun. (A flagged byte is still
 * stored on this USART.) */
#define UART_LOST USART_SR_ORE
/* IDLE and the error flags clear by a read of SR then a read of DR. SR is read again here,
 * right before DR (not taken from the interrupt's entry, with the transmit's end between): a
 * byte that came meanwhile (RXNE) is the DMA's, whose own read of DR then ends the sequence;
 * otherwise our read does. Returns what this read saw: what the sequence clears. (entry_sr, the
 * interrupt's first read, is stale by then.) */
static uint32_t uart_clear(USART_TypeDef *u, uint32_t entry_sr)
{
    uint32_t sr = UART_STATUS(u);
    (void)entry_sr;
    if ((sr & USART_SR_RXNE) == 0u) {
        (void)J288_STM32_DR_READ(u);
    }
    return sr;
}
/* A stale IDLE or error from before the bus was ours: the full sequence (no DMA request yet). */
static void uart_clear_all(USART_TypeDef *u)
{
    (void)UART_STATUS(u);
    (void)J288_STM32_DR_READ(u);
}
static void uart_clear_tc(USART_TypeDef *u) { J288_STM32_SR_CLEAR(u, USART_SR_TC); }
#else /* ISR/ICR: F0, F3, F7, G0, G4, H7, L4, ... */
#define UART_STATUS(u) R((u)->ISR)
#define UART_RX_DATA_ADDR(u) (&(u)->RDR)
#define UART_TX_DATA_ADDR(u) (&(u)->TDR)
#define UART_IDLE USART_ISR_IDLE
#define UART_TC USART_ISR_TC
#define UART_PE USART_ISR_PE
#define UART_FE USART_ISR_FE
#define UART_NE USART_ISR_NE
#define UART_ORE USART_ISR_ORE
/* With CR3.DDRE = 0 (reset value) a byte flagged with a framing, noise or parity error is not
 * given to the DMA; an overrun loses one too. */
#define UART_LOST (USART_ISR_PE | USART_ISR_FE | USART_ISR_NE | USART_ISR_ORE)
#define UART_CLEARABLE (USART_ICR_IDLECF | USART_ICR_PECF | USART_ICR_FECF | USART_ICR_NECF | USART_ICR_ORECF)
/* The ICR bits are the ISR bits of the same flags: those the entry saw are cleared (one
 * raised since stays, for the next entry). */
static uint32_t uart_clear(USART_TypeDef *u, uint32_t entry_sr)
{
    R(u->ICR) = entry_sr & UART_CLEARABLE;
    return entry_sr;
}
static void uart_clear_all(USART_TypeDef *u) { R(u->ICR) = UART_CLEARABLE; }
static void uart_clear_tc(USART_TypeDef *u) { R(u->ICR) = USART_ICR_TCCF; }
#endif
#define UART_ERRORS (UART_PE | UART_FE | UART_NE | UART_ORE)
#define UART_IT_ALL (USART_CR1_IDLEIE | USART_CR1_TCIE | USART_CR1_TXEIE | USART_CR1_RXNEIE | USART_CR1_PEIE)

#if defined(DMA_SxCR_EN) /* streams: F2, F4, F7, H7 (DMA1/2) */
typedef DMA_Stream_TypeDef dma_regs_t;
#define DMA_CTRL(s) R((s)->CR)
#define DMA_COUNT(s) R((s)->NDTR)
#define DMA_EN DMA_SxCR_EN
#define DMA_CIRC DMA_SxCR_CIRC
#define DMA_DIR_MASK DMA_SxCR_DIR
#define DMA_DIR_M2P DMA_SxCR_DIR_0
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
    R(s->PAR) = J288_STM32_DMA_ADDR(periph);
    R(s->M0AR) = J288_STM32_DMA_ADDR(mem);
}
/* Direct mode: in FIFO mode the counter moves when a byte leaves the peripheral (RX) or the
 * memory (TX), not when it reaches the other side, so positions (RX) and "all sent" (TX) read
 * from the counter would run ahead of the bytes. */
static void dma_direct(dma_regs_t *s) { R(s->FCR) &= ~(uint32_t)DMA_SxFCR_DMDIS; }
#else /* channels: F0, F1, F3, G0, G4, L4, ... */
typedef DMA_Channel_TypeDef dma_regs_t;
#define DMA_CTRL(s) R((s)->CCR)
#define DMA_COUNT(s) R((s)->CNDTR)
#define DMA_EN DMA_CCR_EN
#define DMA_CIRC DMA_CCR_CIRC
#define DMA_DIR_MASK DMA_CCR_DIR
#define DMA_DIR_M2P DMA_CCR_DIR
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
    R(s->CPAR) = J288_STM32_DMA_ADDR(periph);
    R(s->CMAR) = J288_STM32_DMA_ADDR(mem);
}
static void dma_direct(dma_regs_t *s) { (void)s; } /* a channel has no FIFO */
#endif

/* Stop a stream: clear its enable bit and wait, a bounded number of reads, for the stream to
 * finish its current single transfer (never SysTick: this runs in the bus's interrupts). A
 * channel stops at once. Returns whether it stopped. */
static bool dma_stop(dma_regs_t *s)
{
    DMA_CTRL(s) &= ~(uint32_t)DMA_EN;
#if defined(DMA_SxCR_EN)
    for (uint32_t i = 0; (i < J288_STM32_STOP_SPINS) && ((DMA_CTRL(s) & DMA_EN) != 0u); i++) {
    }
    return (DMA_CTRL(s) & DMA_EN) == 0u;
#else
    return true;
#endif
}

/* ---- the receive position ---------------------------------------------------------------
 * Indices in the circular buffer: rx_pos, the next byte to hand over; the stream's head, read
 * from its counter at each event. Less than a buffer passes between two events within the
 * timing budget; beyond it, the half/complete flags show the lap (lapped). */

static uint32_t rx_head(const j288_stm32_t *p)
{
    uint32_t left = DMA_COUNT((dma_regs_t *)p->rx_stream);
    return (left - 1u < J288_STM32_RX_BUF_SIZE) ? J288_STM32_RX_BUF_SIZE - left : 0u;
}

/* Bytes from index `from` forward to index `to` (0 when equal). */
static uint32_t idx_sub(uint32_t to, uint32_t from)
{
    return (to >= from) ? to - from : to + J288_STM32_RX_BUF_SIZE - from;
}

static uint32_t idx_add(uint32_t idx, uint32_t n)
{
    idx += n;
    return (idx >= J288_STM32_RX_BUF_SIZE) ? idx - J288_STM32_RX_BUF_SIZE : idx;
}

/* Bytes up to index `to` that are not handed over: heard before a transmit (nobody's) or our
 * own echo. */
static void rx_skip(j288_stm32_t *p, uint32_t to)
{
    p->stats.rx_skipped += idx_sub(to, p->rx_pos);
    p->rx_pos = to;
}

/* The stream went round more than once since the bytes were last handed over: the oldest were
 * overwritten before anyone read them, and what is left is not in order: skipped, the bus told
 * (overrun). */
PORT_NOINLINE static void rx_lap(j288_stm32_t *p, uint32_t to)
{
    p->lapped = false;
    p->stats.rx_laps++;
    p->stats.rx_skipped += J288_STM32_RX_BUF_SIZE;
    rx_skip(p, to);
    j288_bus_on_error(&p->bus, J288_LINE_OVERRUN);
}

/* Hand the bus the received bytes from rx_pos up to index `to`, in order, once. */
static void rx_take(j288_stm32_t *p, uint32_t to)
{
    const uint8_t *rx = p->cfg.dma->rx;
    uint32_t from = p->rx_pos;
    uint32_t n = idx_sub(to, from);

    if (p->lapped) {
        rx_lap(p, to);
        return;
    }
    cache_invalidate(p->cfg.dma->rx, J288_STM32_RX_BUF_SIZE);
    p->rx_pos = to;
    p->stats.rx_bytes += n;
    if (to >= from) { /* (nothing, when equal: the bus takes no empty run) */
        J288_STM32_RX_SINK(&p->bus, &rx[from], n);
    } else if (n <= J288_STM32_BOUNCE_SIZE) { /* wrapped: one piece for the bus's fast path */
        uint32_t tail = J288_STM32_RX_BUF_SIZE - from;
        memcpy(p->bounce, &rx[from], tail);
        memcpy(&p->bounce[tail], rx, to);
        J288_STM32_RX_SINK(&p->bus, p->bounce, n);
    } else {
        J288_STM32_RX_SINK(&p->bus, &rx[from], J288_STM32_RX_BUF_SIZE - from);
        J288_STM32_RX_SINK(&p->bus, rx, to);
    }
}

/* The half/complete flags witness laps the counter cannot show: each flag raised means the
 * stream crossed that boundary (half or end of the buffer) since the flags were last cleared,
 * at index flag_idx. A flag whose boundary lies beyond what the counter says was written since
 * (to index head) means the stream went round once more. */
static void rx_laps_seen(j288_stm32_t *p, uint32_t flags, uint32_t head)
{
    uint32_t since = idx_sub(head, p->flag_idx);
    /* the first crossing of a boundary after flag_idx: 1 to a whole buffer away */
    if ((((flags & DMA_F_HT) != 0u) &&
         (idx_sub(J288_STM32_RX_BUF_SIZE / 2u - 1u, p->flag_idx) + 1u > since)) ||
        (((flags & DMA_F_TC) != 0u) && (J288_STM32_RX_BUF_SIZE - p->flag_idx > since))) {
        p->lapped = true;
    }
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

/* The line is driven only through DE: the receiver never goes off. */
static void op_set_dir(void *ctx, j288_dir_t dir)
{
    de_write(ctx, dir == J288_DIR_TX);
}

/* A transmit still running (its end never seen) is stopped first. A stream stops by itself
 * at the end of a transfer; a channel keeps its enable bit, so only a count left says it is
 * still running; either way it must be disabled before its count is written. */
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

PORT_NOINLINE static bool rx_restart(j288_stm32_t *p);

static int op_start_tx(void *ctx, const uint8_t *data, size_t len)
{
    j288_stm32_t *p = ctx;
    dma_regs_t *s = p->tx_stream;
    USART_TypeDef *u = p->uart;

    if ((data == NULL) || (len == 0u) || (len > J288_CMD_LEN)) {
        return J288_ERR_BAD_ARG;
    }
    if (!tx_stream_ready(p, s) || (p->rx_dead && !rx_restart(p))) {
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
    __DMB(); /* the buffer's writes before the stream's first read */
    *p->tx_ifcr = (uint32_t)DMA_F_ALL << p->tx_shift;
    DMA_COUNT(s) = (uint32_t)len;
    if (p->tc_irq) {
        uart_clear_tc(u); /* a TC left from the last transmit must not end this one */
    }
    /* The echo starts at the stream's head; what was heard before is nobody's (skipped at the
     * end). In this order, with no lock (a polled bus calls it unlocked): the count first, so
     * that no interrupt can end the transmit early; then tx_on, from which an interrupt hands
     * nothing over; then the echo's start, read after it. */
    p->echo_len = p->cfg.deaf_while_transmitting ? 0u : (uint16_t)len; /* a deaf line: none */
    p->tx_on = true;
    p->tx_start = rx_head(p);
    p->stats.tx_frames++;
    if (p->tc_irq) {
        R(u->CR1) |= USART_CR1_TCIE;
    }
    DMA_CTRL(s) |= DMA_EN;
    return J288_OK;
}

/* The index (0-3) of TIM_CHANNEL_1..4 (ST's 0, 4, 8, 12), or 4 for anything else: each
 * channel's interrupt enable, flag and event generation bit, and its HAL active-channel value,
 * are the first channel's shifted by it. */
static uint32_t channel_index(uint32_t channel)
{
    return (((channel % 4u) == 0u) && (channel <= TIM_CHANNEL_4)) ? channel / 4u : 4u;
}

static uint32_t channel_it(uint32_t channel)
{
    uint32_t n = channel_index(channel);
    return (n < 4u) ? (uint32_t)TIM_IT_CC1 << n : 0u;
}

static uint32_t channel_egr(uint32_t channel) { return (uint32_t)TIM_EGR_CC1G << channel_index(channel); }

static HAL_TIM_ActiveChannel channel_active(uint32_t channel)
{
    return (HAL_TIM_ActiveChannel)((uint32_t)HAL_TIM_ACTIVE_CHANNEL_1 << channel_index(channel));
}

/* The channel's output compare preload (OCxPE): with it on, a compare written waits for the
 * next update event, so a deadline would come up to a timer period late. */
static bool channel_preloaded(const TIM_TypeDef *t, uint32_t channel)
{
    switch (channel) {
    case TIM_CHANNEL_1: return (R(t->CCMR1) & TIM_CCMR1_OC1PE) != 0u;
    case TIM_CHANNEL_2: return (R(t->CCMR1) & TIM_CCMR1_OC2PE) != 0u;
    case TIM_CHANNEL_3: return (R(t->CCMR2) & TIM_CCMR2_OC3PE) != 0u;
    default: return (R(t->CCMR2) & TIM_CCMR2_OC4PE) != 0u;
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
        R(htim->Instance->EGR) = channel_egr(p->cfg.tim_channel); /* due already */
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
        R(htim->Instance->EGR) = channel_egr(p->cfg.tim_channel);
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
 * priority masks the bus's interrupts and the less urgent ones only; PRIMASK (every interrupt)
 * where BASEPRI cannot serve: priority 0, or a core without it. One depth count for every bus:
 * the first lock saves both masks, the last unlock restores them, so locks nest across buses
 * in any order. BASEPRI is raised with PRIMASK set: on a Cortex-M7 r0p1 (erratum 837070) an
 * interrupt the new BASEPRI masks can still be taken right after the write otherwise. */
#if defined(__ARM_ARCH_6M__) || defined(__ARM_ARCH_8M_BASE__)
#define J288_STM32_HAS_BASEPRI 0
#else
#define J288_STM32_HAS_BASEPRI 1
#endif

static uint32_t lock_depth;
static uint32_t lock_primask;
#if J288_STM32_HAS_BASEPRI
static uint32_t lock_basepri;
#endif

static void op_lock(void *ctx)
{
    const j288_stm32_t *p = ctx;
    uint32_t pm = __get_PRIMASK();
    __disable_irq();
    if (lock_depth++ == 0u) {
        lock_primask = pm;
#if J288_STM32_HAS_BASEPRI
        lock_basepri = __get_BASEPRI();
#endif
    }
#if J288_STM32_HAS_BASEPRI
    if (p->cfg.irq_priority != 0u) {
        __set_BASEPRI_MAX((uint32_t)p->cfg.irq_priority << (8u - __NVIC_PRIO_BITS));
        __set_PRIMASK(pm);
    }
#else
    (void)p;
#endif
}

static void op_unlock(void *ctx)
{
    (void)ctx;
    if ((lock_depth != 0u) && (--lock_depth == 0u)) {
#if J288_STM32_HAS_BASEPRI
        __set_BASEPRI(lock_basepri);
#endif
        __set_PRIMASK(lock_primask);
    }
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

/* ---- configuration checks ---------------------------------------------------------------- */

#if J288_STM32_HW_CRC && defined(CRC_INPUTDATA_FORMAT_WORDS)
/* Families with a configurable unit (G4, H7, F7, L4, ...; their HAL defines the input
 * formats) compute whatever the handle says: it must say the unit's reset configuration. (The
 * F4-class unit has one fixed configuration.) */
static bool crc_handle_is_servo_crc(const CRC_HandleTypeDef *hcrc)
{
    const CRC_InitTypeDef *in = &hcrc->Init;
    bool poly = (in->DefaultPolynomialUse == DEFAULT_POLYNOMIAL_ENABLE) ||
                ((in->GeneratingPolynomial == 0x04C11DB7u) && (in->CRCLength == CRC_POLYLENGTH_32B));
    bool init = (in->DefaultInitValueUse == DEFAULT_INIT_VALUE_ENABLE) || (in->InitValue == 0xFFFFFFFFu);
    return poly && init && (hcrc->InputDataFormat == CRC_INPUTDATA_FORMAT_WORDS) &&
           (in->InputDataInversionMode == CRC_INPUTDATA_INVERSION_NONE) &&
           (in->OutputDataInversionMode == CRC_OUTPUTDATA_INVERSION_DISABLE);
}
#endif

#if J288_STM32_HW_CRC
/* A known answer from the unit itself: catches what no handle field shows (the unit's clock
 * off, HAL_CRC_Init never called, registers reprogrammed by other code). */
static bool crc_unit_is_servo_crc(CRC_HandleTypeDef *hcrc)
{
    static const uint8_t probe[8] = {0x6a, 0x32, 0x38, 0x38, 0xfe, 0xee, 0x00, 0x5a};
    return j288_stm32_crc32(hcrc, probe, 2u) == j288_crc32_update_bitwise(J288_CRC32_INIT, probe, 2u);
}
#endif

/* RAM the DMA controllers cannot reach, per family (reference manuals' bus matrices). */
#if defined(STM32H7) || defined(STM32F4) || defined(STM32F3)
#define J288_STM32_DMA_HOLES 1
static bool dma_reaches(const void *buf)
{
    uintptr_t a = (uintptr_t)buf;
#if defined(STM32H7)
    return (a >= 0x00040000u) && ((a < 0x20000000u) || (a >= 0x20020000u)); /* ITCM, DTCM */
#elif defined(STM32F4)
    return (a < 0x10000000u) || (a >= 0x10010000u); /* CCM data RAM (F405/407/42x/43x/469) */
#else
    return (a < 0x10000000u) || (a >= 0x10004000u); /* CCM SRAM (up to 16 KiB, F303xD/E) */
#endif
}
#else
#define J288_STM32_DMA_HOLES 0 /* G4 (its CCM SRAM is reachable), L4, G0, ... */
#endif

#if J288_STM32_CACHE_CORE && !J288_STM32_DCACHE
/* Whether the data cache holds the DMA buffers: the cache on (SCB->CCR.DC), and the memory not
 * made non-cacheable by the MPU region that covers it (the highest-numbered enabled one):
 * strongly-ordered or device memory, normal memory non-cacheable (TEX=001, C=0, B=0), or
 * shareable (the M7 does not cache shareable normal memory). Without an MPU region the default
 * memory map's SRAM is write-back cacheable. */
static bool dma_buffers_cached(const void *buf)
{
    uint32_t a = (uint32_t)(uintptr_t)buf;
    uint32_t regions;

    if ((R(SCB->CCR) & SCB_CCR_DC_Msk) == 0u) {
        return false;
    }
    if ((R(MPU->CTRL) & MPU_CTRL_ENABLE_Msk) == 0u) {
        return true;
    }
    regions = (R(MPU->TYPE) & MPU_TYPE_DREGION_Msk) >> MPU_TYPE_DREGION_Pos;
    while (regions-- > 0u) {
        uint32_t rasr, base, size_log2;
        R(MPU->RNR) = regions;
        rasr = R(MPU->RASR);
        base = R(MPU->RBAR) & MPU_RBAR_ADDR_Msk;
        size_log2 = ((rasr & MPU_RASR_SIZE_Msk) >> MPU_RASR_SIZE_Pos) + 1u;
        if (((rasr & MPU_RASR_ENABLE_Msk) == 0u) ||
            (a - base >= ((size_log2 >= 32u) ? 0xFFFFFFFFu : (1u << size_log2)))) {
            continue;
        }
        if ((rasr & MPU_RASR_S_Msk) != 0u) {
            return false;
        }
        return ((rasr & MPU_RASR_TEX_Msk) & (4u << MPU_RASR_TEX_Pos)) != 0u
                   ? ((rasr & (MPU_RASR_C_Msk | MPU_RASR_B_Msk)) != 0u)
                   : ((rasr & MPU_RASR_C_Msk) != 0u);
    }
    return true;
}
#endif

#if defined(DMAMUX_CxCR_DMAREQ_ID)
/* The DMAMUX request ids of each UART (the device's HAL names them), to check the channels. */
typedef struct {
    const USART_TypeDef *uart;
    uint32_t rx, tx;
} uart_requests_t;
static const uart_requests_t k_requests[] = {
#if defined(USART1) && defined(DMA_REQUEST_USART1_RX)
    {USART1, DMA_REQUEST_USART1_RX, DMA_REQUEST_USART1_TX},
#endif
#if defined(USART2) && defined(DMA_REQUEST_USART2_RX)
    {USART2, DMA_REQUEST_USART2_RX, DMA_REQUEST_USART2_TX},
#endif
#if defined(USART3) && defined(DMA_REQUEST_USART3_RX)
    {USART3, DMA_REQUEST_USART3_RX, DMA_REQUEST_USART3_TX},
#endif
#if defined(UART4) && defined(DMA_REQUEST_UART4_RX)
    {UART4, DMA_REQUEST_UART4_RX, DMA_REQUEST_UART4_TX},
#endif
#if defined(UART5) && defined(DMA_REQUEST_UART5_RX)
    {UART5, DMA_REQUEST_UART5_RX, DMA_REQUEST_UART5_TX},
#endif
#if defined(USART6) && defined(DMA_REQUEST_USART6_RX)
    {USART6, DMA_REQUEST_USART6_RX, DMA_REQUEST_USART6_TX},
#endif
#if defined(UART7) && defined(DMA_REQUEST_UART7_RX)
    {UART7, DMA_REQUEST_UART7_RX, DMA_REQUEST_UART7_TX},
#endif
#if defined(UART8) && defined(DMA_REQUEST_UART8_RX)
    {UART8, DMA_REQUEST_UART8_RX, DMA_REQUEST_UART8_TX},
#endif
#if defined(LPUART1) && defined(DMA_REQUEST_LPUART1_RX)
    {LPUART1, DMA_REQUEST_LPUART1_RX, DMA_REQUEST_LPUART1_TX},
#endif
    {NULL, 0u, 0u}};

static bool request_is(const DMA_HandleTypeDef *h, uint32_t id)
{
    return (h->DMAmuxChannel == NULL) || ((R(h->DMAmuxChannel->CCR) & DMAMUX_CxCR_DMAREQ_ID) == id);
}

static bool dmamux_requests_ok(const UART_HandleTypeDef *huart)
{
    for (size_t i = 0; k_requests[i].uart != NULL; i++) {
        if (k_requests[i].uart == huart->Instance) {
            return request_is(huart->hdmarx, k_requests[i].rx) && request_is(huart->hdmatx, k_requests[i].tx);
        }
    }
    return true; /* a UART this table does not know: not checked */
}
#endif

/* The UART and its streams as HAL_HalfDuplex_Init and HAL_DMA_Init must have left them. */
static j288_stm32_init_error_t check_line(const UART_HandleTypeDef *huart)
{
    const DMA_HandleTypeDef *tx = huart->hdmatx;
    const DMA_HandleTypeDef *rx = huart->hdmarx;
    if ((tx == NULL) || (rx == NULL) || (huart->Instance == NULL) || (tx->Instance == NULL) ||
        (rx->Instance == NULL)) {
        return J288_STM32_INIT_NO_DMA;
    }
#if defined(IS_BDMA_CHANNEL_INSTANCE)
    if (IS_BDMA_CHANNEL_INSTANCE(tx->Instance) || IS_BDMA_CHANNEL_INSTANCE(rx->Instance)) {
        return J288_STM32_INIT_BDMA;
    }
#endif
    if ((R(huart->Instance->CR3) & USART_CR3_HDSEL) == 0u) {
        return J288_STM32_INIT_NOT_HALF_DUPLEX;
    }
    if (((DMA_CTRL((dma_regs_t *)tx->Instance) & DMA_DIR_MASK) != DMA_DIR_M2P) ||
        ((DMA_CTRL((dma_regs_t *)rx->Instance) & DMA_DIR_MASK) != 0u)) {
        return J288_STM32_INIT_DMA_DIRECTION;
    }
#if defined(DMAMUX_CxCR_DMAREQ_ID)
    if (!dmamux_requests_ok(huart)) {
        return J288_STM32_INIT_DMA_REQUEST;
    }
#endif
    return J288_STM32_INIT_OK;
}

static j288_stm32_init_error_t check_buffers(const j288_stm32_dma_t *dma)
{
#if J288_STM32_DMA_HOLES
    if (!dma_reaches(dma)) {
        return J288_STM32_INIT_BUFFER_UNREACHABLE;
    }
#endif
    if (J288_STM32_CACHE_OPS && (((uintptr_t)dma % J288_STM32_DCACHE_LINE) != 0u)) {
        return J288_STM32_INIT_BUFFER_ALIGNMENT;
    }
#if J288_STM32_CACHE_CORE && !J288_STM32_DCACHE
    if (dma_buffers_cached(dma)) {
        return J288_STM32_INIT_DCACHE;
    }
#endif
    return J288_STM32_INIT_OK;
}

static j288_stm32_init_error_t check_time(const j288_stm32_config_t *cfg)
{
    if (cfg->htim != NULL) {
        if (channel_it(cfg->tim_channel) == 0u) {
            return J288_STM32_INIT_TIMER_CHANNEL;
        }
        if (channel_preloaded(cfg->htim->Instance, cfg->tim_channel)) {
            return J288_STM32_INIT_TIMER_PRELOAD;
        }
    }
    if ((cfg->now_us == NULL) &&
        ((cfg->htim == NULL) || (__HAL_TIM_GET_AUTORELOAD(cfg->htim) != 0xFFFFFFFFu))) {
        return J288_STM32_INIT_NO_CLOCK;
    }
    return J288_STM32_INIT_OK;
}

static j288_stm32_init_error_t check_de(const j288_stm32_config_t *cfg)
{
    if (!cfg->de_hardware) {
        return J288_STM32_INIT_OK;
    }
#if defined(USART_CR3_DEM)
    if ((cfg->de_port == NULL) && ((R(cfg->huart->Instance->CR3) & USART_CR3_DEM) != 0u)) {
        return J288_STM32_INIT_OK;
    }
#endif
    return J288_STM32_INIT_DE_HARDWARE;
}

static j288_stm32_init_error_t check_config(const j288_stm32_config_t *cfg, const j288_bus_config_t *bus_cfg)
{
    j288_stm32_init_error_t e = check_line(cfg->huart);
    if (e == J288_STM32_INIT_OK) {
        e = check_buffers(cfg->dma);
    }
    if ((e == J288_STM32_INIT_OK) && (cfg->irq_priority >= (1u << __NVIC_PRIO_BITS))) {
        e = J288_STM32_INIT_PRIORITY; /* shifted into BASEPRI it would mask the wrong level, or none */
    }
    if ((e == J288_STM32_INIT_OK) && (bus_cfg != NULL) && bus_cfg->echo && cfg->deaf_while_transmitting) {
        e = J288_STM32_INIT_ECHO_DEAF; /* the line cannot hear the echo the bus would wait for */
    }
    if (e == J288_STM32_INIT_OK) {
        e = check_time(cfg);
    }
    if (e == J288_STM32_INIT_OK) {
        e = check_de(cfg);
    }
#if J288_STM32_HW_CRC && defined(CRC_INPUTDATA_FORMAT_WORDS)
    if ((e == J288_STM32_INIT_OK) && (cfg->hcrc != NULL) && !crc_handle_is_servo_crc(cfg->hcrc)) {
        e = J288_STM32_INIT_CRC_CONFIG;
    }
#endif
#if J288_STM32_HW_CRC
    if ((e == J288_STM32_INIT_OK) && (cfg->hcrc != NULL) && !crc_unit_is_servo_crc(cfg->hcrc)) {
        e = J288_STM32_INIT_CRC_ANSWER;
    }
#endif
    return e;
}

const char *j288_stm32_init_error_str(j288_stm32_init_error_t e)
{
    switch (e) {
    case J288_STM32_INIT_OK: return "no configuration error";
    case J288_STM32_INIT_NO_DMA: return "the UART handle has no DMA stream linked (hdmatx, hdmarx)";
    case J288_STM32_INIT_BDMA: return "a BDMA channel (H7 D3 domain): the port drives DMA1/DMA2 streams only";
    case J288_STM32_INIT_NOT_HALF_DUPLEX: return "the UART is not in single-wire mode (CR3.HDSEL: HAL_HalfDuplex_Init)";
    case J288_STM32_INIT_DMA_DIRECTION: return "a DMA stream in the wrong direction (TX memory-to-peripheral, RX peripheral-to-memory)";
    case J288_STM32_INIT_DMA_REQUEST: return "a DMAMUX request that is not this UART's TX or RX";
    case J288_STM32_INIT_BUFFER_UNREACHABLE: return "the DMA buffers are in RAM the DMA cannot reach (CCM, TCM)";
    case J288_STM32_INIT_BUFFER_ALIGNMENT: return "the DMA buffers are not on a cache line (J288_STM32_DCACHE)";
    case J288_STM32_INIT_DCACHE: return "the D-cache is on and caches the DMA buffers: J288_STM32_DCACHE=1, or a non-cacheable MPU region";
    case J288_STM32_INIT_PRIORITY: return "irq_priority beyond the NVIC's priority bits";
    case J288_STM32_INIT_ECHO_DEAF: return "the bus's echo option on a line deaf while transmitting";
    case J288_STM32_INIT_TIMER_CHANNEL: return "tim_channel is not TIM_CHANNEL_1..4";
    case J288_STM32_INIT_TIMER_PRELOAD: return "the timer channel's compare preload (OCxPE) is on";
    case J288_STM32_INIT_NO_CLOCK: return "no now_us and no 32-bit timer at 1 MHz to be the clock";
    case J288_STM32_INIT_DE_HARDWARE: return "hardware DE asked for: no CR3.DEM on this UART, DEM not set (HAL_RS485Ex_Init), or a DE pin too";
    case J288_STM32_INIT_CRC_CONFIG: return "the CRC handle is not in the unit's reset configuration";
    case J288_STM32_INIT_CRC_ANSWER: return "the CRC unit does not compute the servo's CRC (clock off, not initialised)";
    default: return "unknown configuration error";
    }
}

j288_stm32_init_error_t j288_stm32_init_error(const j288_stm32_t *p)
{
    return (p != NULL) ? p->init_error : J288_STM32_INIT_OK;
}

/* ---- lifecycle -------------------------------------------------------------------------- */

static void pin_drive(const j288_stm32_config_t *cfg)
{
    if ((cfg->tx_port == NULL) || (cfg->tx_drive == J288_STM32_PIN_AS_CONFIGURED)) {
        return;
    }
    if (cfg->tx_drive == J288_STM32_PIN_OPEN_DRAIN) {
        R(cfg->tx_port->OTYPER) |= cfg->tx_pin;
    } else {
        R(cfg->tx_port->OTYPER) &= ~(uint32_t)cfg->tx_pin;
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

/* Every interrupt source of the line off: the UART's and both streams'. */
static void line_mask(const j288_stm32_t *p)
{
    R(p->uart->CR1) &= ~(uint32_t)UART_IT_ALL;
    R(p->uart->CR3) &= ~(uint32_t)USART_CR3_EIE;
    DMA_CTRL((dma_regs_t *)p->rx_stream) &= ~(uint32_t)DMA_IT_ALL;
    DMA_CTRL((dma_regs_t *)p->tx_stream) &= ~(uint32_t)DMA_IT_ALL;
}

/* Restart the RX stream at the start of its buffer: stopped (checked), every flag of the
 * stream cleared (RM0090: a stream refuses EN while any is set), enabled, and checked running.
 * The receive positions start a new lap; bytes not handed over are lost. */
PORT_NOINLINE static bool rx_restart(j288_stm32_t *p)
{
    dma_regs_t *rx = p->rx_stream;
    bool ok = dma_stop(rx);
    if (ok) {
        dma_point(rx, UART_RX_DATA_ADDR(p->uart), p->cfg.dma->rx);
        DMA_COUNT(rx) = J288_STM32_RX_BUF_SIZE;
        *p->rx_ifcr = (uint32_t)DMA_F_ALL << p->rx_shift;
        DMA_CTRL(rx) |= DMA_EN;
        ok = (DMA_CTRL(rx) & DMA_EN) != 0u;
    }
    p->rx_pos = 0u;
    p->flag_idx = 0u;
    p->tx_start = 0u;
    p->lapped = false;
    p->echo_len = 0u; /* an echo under way lost its bytes: none to count */
    p->rx_dead = !ok;
    return ok;
}

/* The UART as the port runs it, set up with every interrupt source masked and the bus not yet
 * live, so that nothing runs in between: the UART off while its mode bits are written (the
 * newer USART requires it): one-bit sampling, the error interrupt off; the streams stopped and
 * set up, their flags cleared: TX pointed at its buffer, direct, no interrupt (the UART's
 * transmit complete ends a transmit); RX circular and direct over its buffer, running. Then
 * the UART on again and its stale flags (IDLE, an overrun from bytes heard before) cleared.
 * line_enable() gives it the DMA requests and the interrupts once the bus is live. */
static bool take_line(j288_stm32_t *p)
{
    USART_TypeDef *u = p->uart;
    dma_regs_t *tx = p->tx_stream;
    dma_regs_t *rx = p->rx_stream;

    line_mask(p);
    R(u->CR1) &= ~(uint32_t)(USART_CR1_UE | USART_CR1_RE | USART_CR1_TE);
    R(u->CR3) = (R(u->CR3) | USART_CR3_ONEBIT) & ~(uint32_t)(USART_CR3_EIE | USART_CR3_DMAR | USART_CR3_DMAT);
#if defined(USART_CR1_FIFOEN)
    R(u->CR1) &= ~(uint32_t)USART_CR1_FIFOEN; /* the port's positions count bytes, not FIFO levels */
#endif
    if (!dma_stop(tx) || !dma_stop(rx)) {
        return false;
    }
    dma_point(tx, UART_TX_DATA_ADDR(u), p->cfg.dma->tx);
    DMA_CTRL(tx) &= ~(uint32_t)(DMA_IT_ALL | DMA_CIRC);
    dma_direct(tx);
    *p->tx_ifcr = (uint32_t)DMA_F_ALL << p->tx_shift;
    dma_point(rx, UART_RX_DATA_ADDR(u), p->cfg.dma->rx);
    dma_direct(rx);
    DMA_COUNT(rx) = J288_STM32_RX_BUF_SIZE;
    cache_invalidate(p->cfg.dma->rx, J288_STM32_RX_BUF_SIZE);
    *p->rx_ifcr = (uint32_t)DMA_F_ALL << p->rx_shift;
    __DMB();
    DMA_CTRL(rx) = (DMA_CTRL(rx) & ~(uint32_t)DMA_IT_ALL) | DMA_CIRC | DMA_EN;
    R(u->CR1) = (R(u->CR1) & ~(uint32_t)USART_CR1_PEIE) | USART_CR1_UE | USART_CR1_TE | USART_CR1_RE;
    uart_clear_all(u);
    return true;
}

/* The last enables, with the bus live: DMA requests, the RX stream's interrupts, IDLE. */
static void line_enable(const j288_stm32_t *p)
{
    R(p->uart->CR3) |= USART_CR3_DMAR | USART_CR3_DMAT;
    DMA_CTRL((dma_regs_t *)p->rx_stream) |= DMA_IT_RX;
    R(p->uart->CR1) |= USART_CR1_IDLEIE;
}

int j288_stm32_init(j288_stm32_t *p, const j288_stm32_config_t *cfg,
                    const j288_bus_config_t *bus_cfg)
{
    size_t free_slot = J288_STM32_MAX_BUSES;
    j288_stm32_init_error_t e;
    int rc;

    if ((p == NULL) || (cfg == NULL) || (cfg->huart == NULL) || (cfg->dma == NULL)) {
        return J288_ERR_NULL;
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
    e = check_config(cfg, bus_cfg);
    if (e != J288_STM32_INIT_OK) {
        p->init_error = e;
        return J288_ERR_BAD_CONFIG;
    }

    memset(p, 0, sizeof *p);
    p->cfg = *cfg;
    p->echo = (bus_cfg != NULL) && bus_cfg->echo;
    p->tc_irq = (cfg->de_port != NULL) || cfg->deaf_while_transmitting;
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
    line_enable(p);
    return J288_OK;
}

void j288_stm32_deinit(j288_stm32_t *p)
{
    for (size_t i = 0; i < J288_STM32_MAX_BUSES; i++) {
        if ((p != NULL) && (registry[i] == p)) {
            /* Masked first: an event of the window below would find nobody to clear it. */
            line_mask(p);
            if (p->cfg.htim != NULL) {
                __HAL_TIM_DISABLE_IT(p->cfg.htim, channel_it(p->cfg.tim_channel));
            }
            p->live = false;
            registry[i] = NULL;
            /* A command still on the wire is cut short rather than left to finish after the
             * transceiver has been released; the UART is left quiet for the HAL. */
            R(p->uart->CR3) &= ~(uint32_t)(USART_CR3_DMAR | USART_CR3_DMAT);
            if (dma_stop(p->tx_stream) && dma_stop(p->rx_stream)) {
                DMA_CTRL((dma_regs_t *)p->rx_stream) &= ~(uint32_t)DMA_CIRC;
            }
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

/* An entry for a bus that is not live (an NVIC pending bit latched before init finished or
 * after deinit): its own sources masked, so that it cannot come back; unless another live bus
 * has taken the same UART since. A p never initialised has no registers. */
PORT_NOINLINE static void not_live(const j288_stm32_t *p)
{
    if (p->uart == NULL) {
        return;
    }
    for (size_t i = 0; i < J288_STM32_MAX_BUSES; i++) {
        const j288_stm32_t *q = registry[i];
        if ((q != NULL) && (q->uart == p->uart)) {
            return;
        }
    }
    line_mask(p);
}

/* Error flags seen: counted one by one and reported to the bus as one line error; the bytes
 * themselves stay where the DMA put them (or were dropped by the newer USART), for the CRC to
 * judge. */
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

/* Transmit complete with the echo not all in and none of it lost: its last byte waits in the
 * data register for the RX stream (a few bus cycles), or it is still on the wire, this TC having
 * been raised by a stall of the TX stream before it wrote that byte (the F4 clears TC only with
 * an SR read and a DR write, so a TC from a stall survives the stream's next write). Waited
 * for, a bounded number of reads (J288_STM32_ECHO_SPINS: a character and more). */
PORT_NOINLINE static uint32_t echo_wait(const j288_stm32_t *p, uint32_t start, uint32_t head)
{
    for (uint32_t i = 0; (i < J288_STM32_ECHO_SPINS) && (idx_sub(head, start) < p->echo_len); i++) {
        head = rx_head(p);
    }
    return head;
}

/* The end of a transmit: transmit complete (TC) with the TX stream's count at 0, taken at TC's
 * interrupt with a DE pin or a deaf line (DE drops first, before anything else is done), else
 * at the idle line after the echo (or a later one, when the reply follows at once). The echo's
 * end: the line hears us and no byte of it was lost (no flag says so): echo_len bytes from where
 * it started, or what came of them (cut short by a collision); otherwise every byte from its
 * start goes to the bus after the transmit's end, whose parser finds the reply among our bytes.
 * Returns the stream's head (the transmit still on if an idle line came mid-frame). */
static uint32_t tx_end(j288_stm32_t *p, uint32_t sr, uint32_t head)
{
    uint32_t start = p->tx_start;
    uint32_t len = p->echo_len;
    uint32_t in = idx_sub(head, start);
    uint32_t end = start;
    bool whole = (sr & UART_LOST) == 0u;

    if (!whole || (in < len)) {
        /* at an idle line, with the echo not (known to be) all in: the end only if the TX
         * stream has written everything (a stall mid-frame idles the line too) */
        if (!p->tc_irq && (DMA_COUNT((dma_regs_t *)p->tx_stream) != 0u)) {
            p->stats.tx_stalls++;
            return head;
        }
        if (whole) {
            head = echo_wait(p, start, head);
            in = idx_sub(head, start);
        }
    }
    if (p->tc_irq) {
        de_write(p, false);
        R(p->uart->CR1) &= ~(uint32_t)USART_CR1_TCIE;
    }
    p->tx_on = false;
    if (whole) {
        end = (in < len) ? head : idx_add(start, len);
    }
    if (p->echo) {
        rx_skip(p, start);
        rx_take(p, end);
    } else {
        rx_skip(p, end);
    }
    j288_bus_on_tx_done(&p->bus);
    return head;
}

void j288_stm32_on_uart_irq(j288_stm32_t *p)
{
    USART_TypeDef *u;
    uint32_t sr, head;

    if (p == NULL) {
        return;
    }
    if (!p->live) {
        not_live(p);
        return;
    }
    u = p->uart;
    sr = UART_STATUS(u);
    head = rx_head(p);
    if (p->tx_on && ((sr & UART_TC) != 0u)) {
        if (!p->tc_irq) {
            if ((sr & UART_IDLE) != 0u) {
                head = tx_end(p, sr, head); /* the echo all in: the stream wrote everything */
            }
        } else if (DMA_COUNT((dma_regs_t *)p->tx_stream) != 0u) {
            uart_clear_tc(u); /* mid-frame: the TX stream stalled; TC comes again at the end */
            p->stats.tx_stalls++;
        } else {
            head = tx_end(p, sr, head);
        }
    }
    if ((sr & (UART_IDLE | UART_ERRORS)) != 0u) {
        sr |= uart_clear(u, sr);
        p->stats.rx_events++;
        if (!p->tx_on && (head != p->rx_pos)) {
            rx_take(p, head);
        }
        if ((sr & UART_ERRORS) != 0u) {
            line_errors(p, sr);
        }
    }
}

/* A transfer error stops the stream: what it had stored is handed over, it is restarted at the
 * start of its buffer, and the bus told. */
PORT_NOINLINE static void rx_error(j288_stm32_t *p, uint32_t head)
{
    if (!p->tx_on) {
        rx_take(p, head);
    }
    p->stats.dma_errors++;
    /* A stream that will not restart leaves the bus deaf: the line is gone for the bus (the
     * attempt ends J288_ERR_OFFLINE); the next transmit tries the restart again. */
    j288_bus_on_error(&p->bus, rx_restart(p) ? J288_LINE_DMA : (J288_LINE_DMA | J288_LINE_GONE));
}

/* Half and complete: the bytes up to the stream's head are handed over once a quarter of the
 * buffer waits (so that a reply usually goes whole at its idle line; not during a transmit: its
 * end decides which are the echo). This sets the timing budget: after a half event that left
 * less than a quarter waiting, the next event comes half a buffer later and must be served
 * within a quarter buffer less a character. The flags also say whether the stream went round
 * more than its counter shows. A transfer error restarts the stream. */
void j288_stm32_on_dma_rx_irq(j288_stm32_t *p)
{
    uint32_t flags, before, head;

    if (p == NULL) {
        return;
    }
    if (!p->live) {
        not_live(p);
        return;
    }
    before = rx_head(p); /* where the flags read next may have been raised from */
    flags = (*p->rx_isr >> p->rx_shift) & (DMA_F_HT | DMA_F_TC | DMA_F_TE);
    *p->rx_ifcr = flags << p->rx_shift;
    head = rx_head(p);
    p->stats.rx_events++;
    if ((flags & DMA_F_TE) != 0u) {
        rx_error(p, head);
        return;
    }
    rx_laps_seen(p, flags, head);
    p->flag_idx = before;
    if (!p->tx_on && ((idx_sub(head, p->rx_pos) >= J288_STM32_RX_BUF_SIZE / 4u) || p->lapped)) {
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
