/* The STM32 silicon the port drives, modelled on a simulated timeline; see fake_hal.h. */
#include "fake_hal.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#define FAKE_UARTS 3u
#define FAKE_PINS 16u
#define LINE_MAX 512u     /* characters waiting on one line */
#define FRAME_MAX 64u     /* bytes of one transmit recorded */
#define TRACE_MAX 512u    /* DE transitions recorded per line */
#define STORM_LIMIT 16u   /* entries in a row that leave their cause set */
#define RX_AT (FAKE_CHAR - FAKE_BIT / 2u) /* the receiver takes a character mid stop bit */

/* ---- the register models -------------------------------------------------------------------- */
#if defined(J288_STUB_ISR_USART)
#define U_STATUS(u) ((u)->ISR)
#define ST_RXNE USART_ISR_RXNE_RXFNE
#define ST_TXE USART_ISR_TXE_TXFNF
#define ST_TC USART_ISR_TC
#define ST_IDLE USART_ISR_IDLE
#define ST_PE USART_ISR_PE
#define ST_FE USART_ISR_FE
#define ST_NE USART_ISR_NE
#define ST_ORE USART_ISR_ORE
/* Bits that need UE=0 to be written (RM0440/RM0433): changing them with UE=1 is ignored by
 * the silicon and a violation here. */
#define CR1_LOCKED (USART_CR1_M0 | USART_CR1_M1 | USART_CR1_OVER8 | USART_CR1_DEAT | USART_CR1_DEDT | \
                    USART_CR1_FIFOEN | USART_CR1_PCE)
#define CR3_LOCKED (USART_CR3_HDSEL | USART_CR3_ONEBIT | USART_CR3_OVRDIS | USART_CR3_DDRE | USART_CR3_DEM | \
                    USART_CR3_DEP)
#else
#define U_STATUS(u) ((u)->SR)
#define ST_RXNE USART_SR_RXNE
#define ST_TXE USART_SR_TXE
#define ST_TC USART_SR_TC
#define ST_IDLE USART_SR_IDLE
#define ST_PE USART_SR_PE
#define ST_FE USART_SR_FE
#define ST_NE USART_SR_NE
#define ST_ORE USART_SR_ORE
#endif
#define ST_ERRORS (ST_PE | ST_FE | ST_NE | ST_ORE)

#if defined(J288_STUB_CHANNELS)
#define D_CR(s) ((s)->CCR)
#define D_CNT(s) ((s)->CNDTR)
#define D_MEM(s) ((s)->CMAR)
#define D_PAR(s) ((s)->CPAR)
#define D_EN DMA_CCR_EN
#define D_CIRC DMA_CCR_CIRC
#define D_M2P DMA_CCR_DIR
#define D_DIRMASK DMA_CCR_DIR
#define D_IE (DMA_CCR_TCIE | DMA_CCR_HTIE | DMA_CCR_TEIE)
#define D_HT DMA_ISR_HTIF1
#define D_TC DMA_ISR_TCIF1
#define D_TE DMA_ISR_TEIF1
#define D_ALL (DMA_ISR_GIF1 | DMA_ISR_TCIF1 | DMA_ISR_HTIF1 | DMA_ISR_TEIF1)
#define D_CAUSE(fl, cr)                                                                        \
    ((((fl) & D_TC) != 0u && ((cr) & DMA_CCR_TCIE) != 0u ? D_TC : 0u) |                       \
     (((fl) & D_HT) != 0u && ((cr) & DMA_CCR_HTIE) != 0u ? D_HT : 0u) |                       \
     (((fl) & D_TE) != 0u && ((cr) & DMA_CCR_TEIE) != 0u ? D_TE : 0u))
#define TX_SHIFT 0u /* channel 1 */
#define RX_SHIFT 4u /* channel 2 */
#else
#define D_CR(s) ((s)->CR)
#define D_CNT(s) ((s)->NDTR)
#define D_MEM(s) ((s)->M0AR)
#define D_PAR(s) ((s)->PAR)
#define D_EN DMA_SxCR_EN
#define D_CIRC DMA_SxCR_CIRC
#define D_M2P DMA_SxCR_DIR_0
#define D_DIRMASK DMA_SxCR_DIR
#define D_IE (DMA_SxCR_TCIE | DMA_SxCR_HTIE | DMA_SxCR_TEIE | DMA_SxCR_DMEIE)
#define D_HT DMA_LISR_HTIF0
#define D_TC DMA_LISR_TCIF0
#define D_TE DMA_LISR_TEIF0
#define D_DME DMA_LISR_DMEIF0
#define D_ALL (DMA_LISR_FEIF0 | DMA_LISR_DMEIF0 | DMA_LISR_TEIF0 | DMA_LISR_HTIF0 | DMA_LISR_TCIF0)
#define D_CAUSE(fl, cr)                                                                        \
    ((((fl) & D_TC) != 0u && ((cr) & DMA_SxCR_TCIE) != 0u ? D_TC : 0u) |                      \
     (((fl) & D_HT) != 0u && ((cr) & DMA_SxCR_HTIE) != 0u ? D_HT : 0u) |                      \
     (((fl) & D_TE) != 0u && ((cr) & DMA_SxCR_TEIE) != 0u ? D_TE : 0u) |                      \
     (((fl) & D_DME) != 0u && ((cr) & DMA_SxCR_DMEIE) != 0u ? D_DME : 0u))
#define TX_SHIFT 22u /* stream 7: HISR */
#define RX_SHIFT 16u /* stream 2: LISR */
#endif

typedef J288_STUB_DMA_INSTANCE dma_regs_t;

typedef struct {
    uint64_t start; /* the start bit's edge */
    uint8_t byte;
    uint8_t flags;
    bool own; /* sent by our transmitter */
} line_char_t;

typedef struct {
    bool on;       /* running (takes requests) */
    bool stopping; /* EN cleared by software, still reading 1 */
    uint64_t off_at;
    uint32_t size; /* NDTR at enable */
} dstream_t;

typedef struct {
    bool pending; /* latched in the NVIC */
    bool active;
    uint64_t ready_at;
    uint32_t latency;
    unsigned storm;
    unsigned entries;
} irq_t;

typedef struct {
    uint64_t t;
    bool active;
} trace_t;

typedef struct {
    UART_HandleTypeDef *huart;
    USART_TypeDef *u;
    dma_regs_t txs, rxs;
    DMA_TypeDef dma;
    DMA_HandleTypeDef htx, hrx;
#if defined(J288_STUB_DMAMUX)
    DMAMUX_Channel_TypeDef mux_tx, mux_rx;
#endif
    /* what the hardware last wrote: a register differing from it was written by the CPU */
    USART_TypeDef su;
    dma_regs_t stx, srx;
    DMA_TypeDef sdma;

    /* the USART */
    uint32_t st; /* the status flags */
    bool rdr_full;
    uint8_t rdr;
    bool tdr_full;
    uint8_t tdr;
    bool shifting;
    uint64_t shift_start, shift_end;
    uint32_t f4_armed; /* flags an SR read saw: a DR read clears them */
    bool f4_tc_armed;  /* TC seen by an SR read: a DR write clears it */
    bool idle_armed;
    uint64_t idle_at;
    unsigned idles;
    bool hwde;
    uint64_t hwde_off_at;

    /* the line */
    size_t qn;
    uint64_t line_end;
    bool deaf;
    unsigned heard;

    /* the streams */
    dstream_t tx, rx;
    uint32_t dfl[2]; /* the flags: LISR, HISR (streams); ISR (channels) */
    uint64_t tx_fill_at, rx_take_at;
    uint32_t rx_delay;
    uint32_t tx_stall[FRAME_MAX];
    uint8_t echo_flags[FRAME_MAX];
    bool dmb_since_tx_en;

    /* the transmit on the wire */
    uint8_t frame[FRAME_MAX];
    size_t frame_len;
    uint32_t programmed;
    size_t started, sent;
    uint64_t first_start, last_end, reply_start;

    /* the servo */
    bool reply_armed;
    uint8_t reply[FRAME_MAX], reply_flags[FRAME_MAX];
    size_t reply_len;
    uint32_t reply_delay;

    /* DE */
    const GPIO_TypeDef *de_port;
    uint16_t de_pin;
    bool de_low;
    size_t gpio_de_n, hw_de_n;

    unsigned stolen, refused;
    irq_t irq[FAKE_IRQ_COUNT];
    uint8_t prio;
    bool uart_first;

    /* Last: the big arrays, valid up to their counts above (a reset clears only the rest). */
    line_char_t q[LINE_MAX];
    trace_t gpio_de[TRACE_MAX], hw_de[TRACE_MAX];
} fake_uart_t;

/* What a reset clears of a UART's model: everything before its arrays. */
#define UART_RESET_SIZE offsetof(fake_uart_t, q)

typedef struct {
    const GPIO_TypeDef *port;
    uint16_t pin;
    int level;
} fake_pin_t;

USART_TypeDef stub_usart[3];
#if __DCACHE_PRESENT
SCB_Type stub_scb;
MPU_Type stub_mpu;
static uint32_t mpu_rbar[16], mpu_rasr[16];
#endif
#if defined(J288_STUB_H7)
BDMA_Channel_TypeDef stub_bdma_channel[8];
#endif

static fake_uart_t uarts[FAKE_UARTS];
static size_t n_uarts;
static uint64_t now_t;
static unsigned long accesses;
static int in_isr;
static bool irq_hold;
static unsigned long release_at;
static uint32_t stop_delay = 3u;
static void (*fail_hook)(const char *msg);
static bool failed; /* a failure reported: no more interrupts until the next reset */
static fake_hal_call_t call_log[FAKE_HAL_LOG_SIZE];
static size_t log_len;
static unsigned counts[FAKE_FN_COUNT];
static fake_pin_t pins[FAKE_PINS];
static uint32_t primask;
static uint32_t basepri;
static unsigned irq_disables;
static unsigned basepri_unmasked;
static unsigned dmb_count;
static bool require_dmb;
static uint32_t crc_reg = 0xFFFFFFFFu;
static bool crc_unclocked;
static TIM_TypeDef *hook_tim;
static unsigned hook_countdown;
static uint32_t hook_ticks;
static unsigned tim_accesses;

static void sync_writes(void);
static void mirror_all(void);
static void mirror(fake_uart_t *f);
static void process_all(void);
static void kick(fake_uart_t *f);

/* ---- failures -------------------------------------------------------------------------------- */

static void fail(const char *fmt, ...)
{
    static char msg[320];
    va_list ap;
    va_start(ap, fmt);
    (void)vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    /* the test goes on (or the next one starts) from thread level */
    in_isr = 0;
    for (size_t i = 0; i < n_uarts; i++) {
        uarts[i].irq[FAKE_IRQ_UART].active = false;
        uarts[i].irq[FAKE_IRQ_DMA_RX].active = false;
    }
    failed = true;
    if (fail_hook != NULL) {
        fail_hook(msg);
    } else {
        fake_app_fail(msg);
    }
}

void fake_hal_on_fail(void (*hook)(const char *msg))
{
    fail_hook = hook;
    failed = false; /* a test that caught a failure goes on */
}

/* ---- the log ---------------------------------------------------------------------------------- */

static void record(fake_hal_fn_t fn, const void *handle, uint32_t arg)
{
    counts[fn]++;
    if (log_len < FAKE_HAL_LOG_SIZE) {
        call_log[log_len].fn = fn;
        call_log[log_len].handle = handle;
        call_log[log_len].arg = arg;
        log_len++;
    }
}

size_t fake_hal_log_len(void) { return log_len; }
const fake_hal_call_t *fake_hal_log_at(size_t i) { return (i < log_len) ? &call_log[i] : NULL; }
void fake_hal_log_clear(void) { log_len = 0u; }
unsigned fake_hal_count(fake_hal_fn_t fn) { return counts[fn]; }

long fake_hal_log_find(fake_hal_fn_t fn, const void *handle, size_t from)
{
    for (size_t i = from; i < log_len; i++) {
        if ((call_log[i].fn == fn) && ((handle == NULL) || (call_log[i].handle == handle))) {
            return (long)i;
        }
    }
    return -1;
}

/* ---- lookups ---------------------------------------------------------------------------------- */

static fake_uart_t *uart_of(const UART_HandleTypeDef *huart)
{
    for (size_t i = 0; i < n_uarts; i++) {
        if (uarts[i].huart == huart) {
            return &uarts[i];
        }
    }
    fail("fake: a UART handle that fake_hal_uart_setup() did not set up");
    return &uarts[0]; /* not reached: fail does not return */
}

static uint32_t *flag_word(fake_uart_t *f, bool rx)
{
#if defined(J288_STUB_CHANNELS)
    (void)rx;
    return &f->dfl[0];
#else
    return rx ? &f->dfl[0] : &f->dfl[1];
#endif
}

static uint32_t stream_flags(fake_uart_t *f, bool rx)
{
    return (*flag_word(f, rx) >> (rx ? RX_SHIFT : TX_SHIFT)) & D_ALL;
}

static void stream_flag_set(fake_uart_t *f, bool rx, uint32_t bits)
{
#if defined(J288_STUB_CHANNELS)
    bits |= DMA_ISR_GIF1;
#endif
    *flag_word(f, rx) |= bits << (rx ? RX_SHIFT : TX_SHIFT);
}

/* ---- DE -------------------------------------------------------------------------------------- */

static void trace_add(trace_t *tr, size_t *n, bool active)
{
    if ((*n > 0u) && (tr[*n - 1u].active == active)) {
        return;
    }
    if (*n >= TRACE_MAX) {
        fail("fake: DE trace full (%lu transitions)", (unsigned long)TRACE_MAX);
    }
    tr[*n].t = now_t;
    tr[*n].active = active;
    (*n)++;
}

static bool trace_at(const trace_t *tr, size_t n, uint64_t t)
{
    bool level = false;
    for (size_t i = 0; (i < n) && (tr[i].t <= t); i++) {
        level = tr[i].active;
    }
    return level;
}

bool fake_hal_de_active_at(const UART_HandleTypeDef *huart, uint64_t t)
{
    const fake_uart_t *f = uart_of(huart);
    return trace_at(f->gpio_de, f->gpio_de_n, t) || trace_at(f->hw_de, f->hw_de_n, t);
}

uint64_t fake_hal_de_off_after(const UART_HandleTypeDef *huart, uint64_t t)
{
    const fake_uart_t *f = uart_of(huart);
    if (!fake_hal_de_active_at(huart, t)) {
        return t;
    }
    for (size_t i = 0; i < f->gpio_de_n; i++) {
        if ((f->gpio_de[i].t > t) && !fake_hal_de_active_at(huart, f->gpio_de[i].t)) {
            return f->gpio_de[i].t;
        }
    }
    for (size_t i = 0; i < f->hw_de_n; i++) {
        if ((f->hw_de[i].t > t) && !fake_hal_de_active_at(huart, f->hw_de[i].t)) {
            return f->hw_de[i].t;
        }
    }
    return FAKE_NEVER;
}

void fake_hal_de_pin(UART_HandleTypeDef *huart, const GPIO_TypeDef *port, uint16_t pin, bool active_low)
{
    fake_uart_t *f = uart_of(huart);
    f->de_port = port;
    f->de_pin = pin;
    f->de_low = active_low;
}

static bool de_active(const fake_uart_t *f, uint64_t t)
{
    return trace_at(f->gpio_de, f->gpio_de_n, t) || trace_at(f->hw_de, f->hw_de_n, t);
}

/* ---- the line ----------------------------------------------------------------------------- */

static void line_add(fake_uart_t *f, uint64_t start, uint8_t byte, uint8_t flags, bool own)
{
    size_t i = f->qn;
    if (f->qn >= LINE_MAX) {
        fail("fake: more than %lu characters waiting on the line", (unsigned long)LINE_MAX);
    }
    while ((i > 0u) && (f->q[i - 1u].start > start)) {
        f->q[i] = f->q[i - 1u];
        i--;
    }
    f->q[i].start = start;
    f->q[i].byte = byte;
    f->q[i].flags = flags;
    f->q[i].own = own;
    f->qn++;
    if (start + FAKE_CHAR > f->line_end) {
        f->line_end = start + FAKE_CHAR;
    }
}

static bool usart_on(const fake_uart_t *f, uint32_t bit)
{
    return ((f->u->CR1 & USART_CR1_UE) != 0u) && ((f->u->CR1 & bit) != 0u);
}

/* The receiver, mid stop bit of c. */
static void receive(fake_uart_t *f, const line_char_t *c)
{
    uint32_t err = 0u;

    if (!usart_on(f, USART_CR1_RE)) {
        return; /* nobody listening */
    }
    if (f->deaf && (c->own || de_active(f, c->start))) {
        return; /* the transceiver's receiver is off while it drives */
    }
    f->idle_at = c->start + 2u * FAKE_CHAR; /* one idle character after this one's stop bit */
    if (((c->flags & FAKE_OVERRUN) != 0u) || f->rdr_full) {
        f->st |= ST_ORE; /* the byte is lost behind the full data register */
        return;
    }
    err |= (((c->flags & FAKE_NOISE) != 0u) && ((f->u->CR3 & USART_CR3_ONEBIT) == 0u)) ? ST_NE : 0u;
    err |= ((c->flags & FAKE_NOISE_START) != 0u) ? ST_NE : 0u; /* one-bit sampling is for data bits only */
    err |= ((c->flags & FAKE_FRAMING) != 0u) ? ST_FE : 0u;
    err |= ((c->flags & FAKE_PARITY) != 0u) ? ST_PE : 0u;
    f->st |= err;
#if defined(J288_STUB_ISR_USART)
    if ((err != 0u) && ((f->u->CR3 & USART_CR3_DDRE) == 0u)) {
        return; /* RM0440/RM0433, DDRE = 0: the flagged byte is not given to the DMA */
    }
#endif
    f->rdr = c->byte;
    f->rdr_full = true;
    f->st |= ST_RXNE;
    f->idle_armed = true;
    f->heard++;
}

/* IDLE: the line idle for a character after the last one, once per RXNE. */
static void idle_due(fake_uart_t *f)
{
    f->idle_at = FAKE_NEVER;
    if ((f->qn > 0u) && (f->q[0].start < now_t)) {
        return; /* a character is on the wire: not idle */
    }
    if (f->idle_armed && usart_on(f, USART_CR1_RE)) {
        f->st |= ST_IDLE;
        f->idle_armed = false;
        f->idles++;
    }
}

/* ---- the transmitter ------------------------------------------------------------------------ */

static uint32_t de_ticks(const fake_uart_t *f, uint32_t field_shift)
{
#if defined(J288_STUB_ISR_USART)
    uint32_t samples = (f->u->CR1 >> field_shift) & 0x1Fu; /* in sample times */
    uint32_t per_bit = ((f->u->CR1 & USART_CR1_OVER8) != 0u) ? 8u : 16u;
    return (samples * FAKE_BIT + per_bit - 1u) / per_bit;
#else
    (void)f;
    (void)field_shift;
    return 0u;
#endif
}

static bool hw_de_mode(const fake_uart_t *f)
{
#if defined(J288_STUB_ISR_USART)
    return (f->u->CR3 & USART_CR3_DEM) != 0u;
#else
    (void)f;
    return false;
#endif
}

/* The data register's byte moves into the shift register (with hardware DE, after DEAT). */
static void shift_start(fake_uart_t *f)
{
    uint64_t start = now_t;
    if (f->shifting || !f->tdr_full) {
        return;
    }
    if (hw_de_mode(f) && !f->hwde) {
        f->hwde = true;
        trace_add(f->hw_de, &f->hw_de_n, true);
        start += de_ticks(f, 21u);
    }
    f->hwde_off_at = FAKE_NEVER;
    f->shifting = true;
    f->shift_start = start;
    f->shift_end = start + FAKE_CHAR;
    f->tdr_full = false;
    f->st |= ST_TXE;
    if (f->started == 0u) {
        f->first_start = start;
    }
    line_add(f, start, f->tdr, (f->started < FRAME_MAX) ? f->echo_flags[f->started] : 0u, true);
    f->started++;
}

static void shift_done(fake_uart_t *f)
{
    f->shifting = false;
    f->sent++;
    if (f->tdr_full) {
        shift_start(f);
        return;
    }
    f->st |= ST_TC; /* the shift register and the data register are both empty */
    if (f->hwde) {
        f->hwde_off_at = now_t + de_ticks(f, 16u);
    }
    if ((f->sent == f->programmed) && (f->last_end == FAKE_NEVER)) {
        f->last_end = now_t;
        if (f->reply_armed) {
            f->reply_armed = false;
            f->reply_start = now_t + f->reply_delay;
            for (size_t i = 0; i < f->reply_len; i++) {
                line_add(f, f->reply_start + (uint64_t)i * FAKE_CHAR, f->reply[i], f->reply_flags[i], false);
            }
        }
    }
}

/* One transfer of a stream: its count down by one, the half and complete flags raised as it
 * crosses them. Returns whether the count reached 0. */
static bool stream_count_down(fake_uart_t *f, bool rx)
{
    dma_regs_t *s = rx ? &f->rxs : &f->txs;
    uint32_t size = rx ? f->rx.size : f->tx.size;
    D_CNT(s)--;
    if (D_CNT(s) == size / 2u) {
        stream_flag_set(f, rx, D_HT);
    }
    if (D_CNT(s) == 0u) {
        stream_flag_set(f, rx, D_TC);
        return true;
    }
    return false;
}

/* The TX stream writes the next byte into the data register. */
static void tx_fill(fake_uart_t *f)
{
    dma_regs_t *s = &f->txs;
    uint32_t index;
    f->tx_fill_at = FAKE_NEVER;
    if (!f->tx.on || f->tx.stopping || f->tdr_full || (D_CNT(s) == 0u) ||
        ((f->u->CR3 & USART_CR3_DMAT) == 0u) || !usart_on(f, USART_CR1_TE)) {
        return;
    }
    index = f->tx.size - D_CNT(s);
    f->tdr = ((const uint8_t *)D_MEM(s))[index];
    if (index < FRAME_MAX) {
        f->frame[index] = f->tdr;
        f->frame_len = index + 1u;
    }
    f->tdr_full = true;
    f->st &= ~ST_TXE;
#if defined(J288_STUB_ISR_USART)
    f->st &= ~ST_TC; /* a write to TDR clears TC */
#else
    if (f->f4_tc_armed) { /* an SR read, then this DR write */
        f->st &= ~ST_TC;
        f->f4_tc_armed = false;
    }
#endif
    if (stream_count_down(f, false)) {
#if !defined(J288_STUB_CHANNELS)
        f->tx.on = false; /* a stream ends its transfer; a channel stays enabled */
#endif
    }
    shift_start(f);
}

/* ---- the receive stream ----------------------------------------------------------------------- */

static void rx_take(fake_uart_t *f)
{
    dma_regs_t *s = &f->rxs;
    f->rx_take_at = FAKE_NEVER;
    if (!f->rdr_full || !f->rx.on || f->rx.stopping || (D_CNT(s) == 0u) ||
        ((f->u->CR3 & USART_CR3_DMAR) == 0u)) {
        return;
    }
    ((uint8_t *)D_MEM(s))[f->rx.size - D_CNT(s)] = f->rdr;
    f->rdr_full = false;
    f->st &= ~ST_RXNE;
#if !defined(J288_STUB_ISR_USART)
    f->st &= ~f->f4_armed; /* the DMA's DR read ends an SR-then-DR sequence */
    f->f4_armed = 0u;
#endif
    if (stream_count_down(f, true)) {
        if ((D_CR(s) & D_CIRC) != 0u) {
            D_CNT(s) = f->rx.size;
        } else {
            f->rx.on = false;
        }
    }
}

/* New work for the DMA: a free data register to fill, a received byte to store. */
static void kick(fake_uart_t *f)
{
    if ((f->tx_fill_at == FAKE_NEVER) && f->tx.on && !f->tx.stopping && !f->tdr_full &&
        (D_CNT(&f->txs) != 0u) && ((f->u->CR3 & USART_CR3_DMAT) != 0u) && usart_on(f, USART_CR1_TE)) {
        uint32_t index = f->tx.size - D_CNT(&f->txs);
        f->tx_fill_at = now_t + 1u + ((index < FRAME_MAX) ? f->tx_stall[index] : 0u);
    }
    if ((f->rx_take_at == FAKE_NEVER) && f->rdr_full && f->rx.on && !f->rx.stopping &&
        (D_CNT(&f->rxs) != 0u) && ((f->u->CR3 & USART_CR3_DMAR) != 0u)) {
        f->rx_take_at = now_t + f->rx_delay;
    }
}

/* ---- time ------------------------------------------------------------------------------------- */

static uint64_t min64(uint64_t a, uint64_t b) { return (a < b) ? a : b; }

static uint64_t next_event(const fake_uart_t *f)
{
    uint64_t e = min64(f->tx_fill_at, f->rx_take_at);
    e = min64(e, f->idle_at);
    e = min64(e, f->hwde_off_at);
    if (f->shifting) {
        e = min64(e, f->shift_end);
    }
    if (f->qn > 0u) {
        e = min64(e, f->q[0].start + RX_AT);
    }
    if (f->tx.stopping) {
        e = min64(e, f->tx.off_at);
    }
    if (f->rx.stopping) {
        e = min64(e, f->rx.off_at);
    }
    return e;
}

static uint64_t next_hw_event(void)
{
    uint64_t e = FAKE_NEVER;
    for (size_t i = 0; i < n_uarts; i++) {
        e = min64(e, next_event(&uarts[i]));
    }
    return e;
}

static void process(fake_uart_t *f)
{
    bool any;
    do {
        any = false;
        if (f->tx.stopping && (f->tx.off_at <= now_t)) {
            f->tx.stopping = false;
            f->tx.on = false;
            any = true;
        }
        if (f->rx.stopping && (f->rx.off_at <= now_t)) {
            f->rx.stopping = false;
            f->rx.on = false;
            any = true;
        }
        if (f->tx_fill_at <= now_t) {
            tx_fill(f);
            any = true;
        }
        if (f->shifting && (f->shift_end <= now_t)) {
            shift_done(f);
            any = true;
        }
        if ((f->qn > 0u) && (f->q[0].start + RX_AT <= now_t)) {
            line_char_t c = f->q[0];
            memmove(&f->q[0], &f->q[1], (f->qn - 1u) * sizeof f->q[0]);
            f->qn--;
            receive(f, &c);
            any = true;
        }
        if (f->rx_take_at <= now_t) {
            rx_take(f);
            any = true;
        }
        if (f->idle_at <= now_t) {
            idle_due(f);
            any = true;
        }
        if (f->hwde_off_at <= now_t) {
            f->hwde_off_at = FAKE_NEVER;
            f->hwde = false;
            trace_add(f->hw_de, &f->hw_de_n, false);
            any = true;
        }
        kick(f);
    } while (any);
    mirror(f); /* what the hardware wrote is not the CPU's */
}

static void process_all(void)
{
    for (size_t i = 0; i < n_uarts; i++) {
        process(&uarts[i]);
    }
}

/* The hardware runs up to t. */
static void advance(uint64_t t)
{
    for (;;) {
        uint64_t e = next_hw_event();
        if (e > t) {
            break;
        }
        if (e > now_t) {
            now_t = e;
        }
        process_all();
    }
    if (t > now_t) {
        now_t = t;
    }
}

uint64_t fake_hal_time(void) { return now_t; }
uint32_t fake_hal_now_us(void) { return (uint32_t)(1000u + now_t / FAKE_TICKS_PER_US); }
unsigned long fake_hal_accesses(void) { return accesses; }

/* ---- the NVIC --------------------------------------------------------------------------------- */

static uint32_t cause(const fake_uart_t *f, fake_irq_t k)
{
    if (k == FAKE_IRQ_UART) {
        uint32_t cr1 = f->u->CR1, cr3 = f->u->CR3, c = 0u;
        c |= ((cr1 & USART_CR1_IDLEIE) != 0u) ? (f->st & ST_IDLE) : 0u;
        c |= ((cr1 & USART_CR1_TCIE) != 0u) ? (f->st & ST_TC) : 0u;
        c |= ((cr1 & USART_CR1_TXEIE) != 0u) ? (f->st & ST_TXE) : 0u;
        c |= ((cr1 & USART_CR1_RXNEIE) != 0u) ? (f->st & (ST_RXNE | ST_ORE)) : 0u;
        c |= ((cr1 & USART_CR1_PEIE) != 0u) ? (f->st & ST_PE) : 0u;
        c |= ((cr3 & USART_CR3_EIE) != 0u) ? (f->st & (ST_FE | ST_NE | ST_ORE)) : 0u;
        return c;
    }
    return D_CAUSE(stream_flags((fake_uart_t *)f, true), D_CR(&f->rxs));
}

static bool masked(const fake_uart_t *f)
{
    return (primask != 0u) || ((basepri != 0u) && (((uint32_t)f->prio << 4) >= basepri));
}

static void nvic_update(void)
{
    for (size_t i = 0; i < n_uarts; i++) {
        fake_uart_t *f = &uarts[i];
        for (unsigned k = 0; k < FAKE_IRQ_COUNT; k++) {
            irq_t *q = &f->irq[k];
            if (!q->pending && !q->active && (cause(f, (fake_irq_t)k) != 0u)) {
                q->pending = true;
                q->ready_at = now_t + q->latency;
            }
        }
    }
}

static const char *irq_name(fake_irq_t k) { return (k == FAKE_IRQ_UART) ? "UART" : "RX DMA"; }

/* One interrupt entry, and what the silicon does after it: a cause still set pends again. */
static void take(fake_uart_t *f, fake_irq_t k)
{
    irq_t *q = &f->irq[k];
    uint32_t before, after;
    q->pending = false;
    q->active = true;
    q->entries++;
    before = cause(f, k);
    in_isr++;
    now_t += 2u; /* exception entry */
    if (k == FAKE_IRQ_UART) {
        fake_app_uart_irq(f->huart);
    } else {
        fake_app_dma_rx_irq(f->huart);
    }
    in_isr--;
    q->active = false;
    sync_writes();
    advance(now_t);
    after = cause(f, k);
    if ((after & before) != 0u) {
        if (++q->storm >= STORM_LIMIT) {
            q->storm = 0u;
            fail("interrupt storm: the %s interrupt of USART%u was entered %u times in a row, each time "
                 "returning with its cause 0x%lx still set (status 0x%lx, CR1 0x%lx)",
                 irq_name(k), (unsigned)(f - uarts) + 1u, STORM_LIMIT, (unsigned long)after,
                 (unsigned long)f->st, (unsigned long)f->u->CR1);
        }
    } else {
        q->storm = 0u;
    }
    nvic_update();
    mirror_all();
}

static bool ready(const fake_uart_t *f, fake_irq_t k)
{
    const irq_t *q = &f->irq[k];
    return q->pending && !q->active && (q->ready_at <= now_t);
}

/* Take the first interrupt that is due, if any may be taken now. */
static bool dispatch_one(void)
{
    if ((in_isr != 0) || irq_hold || failed) {
        return false;
    }
    for (size_t i = 0; i < n_uarts; i++) {
        fake_uart_t *f = &uarts[i];
        fake_irq_t first = f->uart_first ? FAKE_IRQ_UART : FAKE_IRQ_DMA_RX;
        fake_irq_t second = f->uart_first ? FAKE_IRQ_DMA_RX : FAKE_IRQ_UART;
        if (masked(f)) {
            continue;
        }
        if (ready(f, first)) {
            take(f, first);
            return true;
        }
        if (ready(f, second)) {
            take(f, second);
            return true;
        }
    }
    return false;
}

/* When the next interrupt that could be taken is due (FAKE_NEVER: none). */
static uint64_t next_irq_due(void)
{
    uint64_t e = FAKE_NEVER;
    if ((in_isr != 0) || irq_hold) {
        return e;
    }
    for (size_t i = 0; i < n_uarts; i++) {
        const fake_uart_t *f = &uarts[i];
        if (masked(f)) {
            continue;
        }
        for (unsigned k = 0; k < FAKE_IRQ_COUNT; k++) {
            if (f->irq[k].pending && !f->irq[k].active) {
                e = min64(e, f->irq[k].ready_at);
            }
        }
    }
    return e;
}

/* Returns whether an interrupt was taken. */
static bool dispatch_all(void)
{
    bool any = false;
    nvic_update();
    while (dispatch_one()) {
        any = true;
    }
    return any;
}

void fake_hal_run(uint64_t ticks)
{
    uint64_t target = now_t + ticks;
    sync_writes();
    for (;;) {
        uint64_t e;
        nvic_update();
        if (dispatch_one()) {
            continue;
        }
        e = min64(next_hw_event(), next_irq_due());
        if (e <= now_t) {
            process_all(); /* due now, nothing to take: let the hardware move */
            e = min64(next_hw_event(), next_irq_due());
            if (e <= now_t) {
                e = now_t + 1u;
            }
        }
        if (e > target) {
            advance(target);
            break;
        }
        advance(e);
    }
    nvic_update();
    dispatch_all();
    mirror_all();
}

void fake_hal_run_us(uint32_t us) { fake_hal_run((uint64_t)us * FAKE_TICKS_PER_US); }

/* ---- CPU writes, found where a register differs from what the hardware last put there ------ */

static void stream_cr_write(fake_uart_t *f, dma_regs_t *s, dma_regs_t *sh, dstream_t *d, bool rx)
{
    uint32_t old = D_CR(sh), now = D_CR(s);
    bool en_hw = d->on || d->stopping;

    if (en_hw && (((old ^ now) & ~(uint32_t)(D_EN | D_IE)) != 0u)) {
        fail("fake: USART%lu's %s stream configuration written (CR 0x%lx) while its EN bit reads 1",
             (unsigned long)(f - uarts) + 1u, rx ? "RX" : "TX", (unsigned long)now);
    }
    if (!en_hw && ((now & D_EN) != 0u)) {
#if !defined(J288_STUB_CHANNELS)
        if (stream_flags(f, rx) != 0u) { /* RM0090: flags must be clear before EN is set */
            D_CR(s) = now & ~(uint32_t)D_EN;
            f->refused++;
            return;
        }
#endif
        d->on = true;
        d->size = D_CNT(s);
        if (!rx) {
            f->tx_fill_at = FAKE_NEVER; /* a stall of an earlier transfer is over */
            if (require_dmb && !f->dmb_since_tx_en) {
                fail("fake: USART%lu's TX stream enabled with no __DMB() since its last enable",
                     (unsigned long)(f - uarts) + 1u);
            }
            f->dmb_since_tx_en = false;
            f->programmed = D_CNT(s);
            f->started = 0u;
            f->sent = 0u;
            f->frame_len = 0u;
            f->first_start = FAKE_NEVER;
            f->last_end = FAKE_NEVER;
            f->reply_start = FAKE_NEVER;
        }
    } else if (en_hw && ((now & D_EN) == 0u)) {
#if defined(J288_STUB_CHANNELS)
        d->on = false; /* a channel stops at once */
#else
        if (!d->stopping) { /* a stream finishes its current transfer: EN reads 1 meanwhile */
            d->stopping = true;
            d->off_at = now_t + stop_delay;
        }
        D_CR(s) = now | D_EN;
#endif
    }
}

static void stream_write(fake_uart_t *f, dma_regs_t *s, dma_regs_t *sh, dstream_t *d, bool rx)
{
    bool en_hw = d->on || d->stopping;
    bool cfg_changed = (D_CNT(s) != D_CNT(sh)) || (D_MEM(s) != D_MEM(sh)) || (D_PAR(s) != D_PAR(sh));
#if !defined(J288_STUB_CHANNELS)
    cfg_changed = cfg_changed || (s->FCR != sh->FCR);
#endif
    if (en_hw && cfg_changed) {
        fail("fake: USART%lu's %s stream's count, addresses or FIFO written while its EN bit reads 1",
             (unsigned long)(f - uarts) + 1u, rx ? "RX" : "TX");
    }
    if (D_CR(s) != D_CR(sh)) {
        stream_cr_write(f, s, sh, d, rx);
    }
}

static void usart_cr1_write(fake_uart_t *f, uint32_t old, uint32_t now)
{
#if defined(J288_STUB_ISR_USART)
    if (((old & now & USART_CR1_UE) != 0u) && (((old ^ now) & CR1_LOCKED) != 0u)) {
        fail("fake: USART%lu CR1 bits 0x%lx that need UE=0 written while UE=1", (unsigned long)(f - uarts) + 1u,
             (unsigned long)((old ^ now) & CR1_LOCKED));
    }
#endif
    if (((old & USART_CR1_UE) != 0u) && ((now & USART_CR1_UE) == 0u)) {
        /* UE=0: the transmitter and receiver stop; the G4/H7 reset their status flags. */
        f->rdr_full = false;
        f->tdr_full = false;
        f->shifting = false;
        f->tx_fill_at = FAKE_NEVER;
        f->rx_take_at = FAKE_NEVER;
        f->idle_at = FAKE_NEVER;
        f->idle_armed = false;
#if defined(J288_STUB_ISR_USART)
        f->st = ST_TXE | ST_TC;
#endif
        if (f->hwde) {
            f->hwde = false;
            trace_add(f->hw_de, &f->hw_de_n, false);
        }
    }
#if defined(J288_STUB_ISR_USART)
    if (((old & USART_CR1_TE) != 0u) && ((now & USART_CR1_TE) == 0u) && !f->shifting) {
        f->st |= ST_TC; /* TE reset with no transmission going on: TC at once */
    }
#endif
}

static void usart_cr3_write(fake_uart_t *f, uint32_t old, uint32_t now)
{
#if defined(J288_STUB_ISR_USART)
    if (((f->u->CR1 & USART_CR1_UE) != 0u) && (((old ^ now) & CR3_LOCKED) != 0u)) {
        fail("fake: USART%lu CR3 bits 0x%lx that need UE=0 written while UE=1", (unsigned long)(f - uarts) + 1u,
             (unsigned long)((old ^ now) & CR3_LOCKED));
    }
#else
    (void)f;
    (void)old;
    (void)now;
#endif
}

static void sync_uart(fake_uart_t *f)
{
    USART_TypeDef *u = f->u;
    if (u->CR1 != f->su.CR1) {
        usart_cr1_write(f, f->su.CR1, u->CR1);
    }
    if (u->CR3 != f->su.CR3) {
        usart_cr3_write(f, f->su.CR3, u->CR3);
    }
#if defined(J288_STUB_ISR_USART)
    if (u->ICR != 0u) {
        f->st &= ~(u->ICR & (ST_PE | ST_FE | ST_NE | ST_ORE | ST_IDLE | ST_TC));
        u->ICR = 0u;
    }
#else
    if (u->SR != f->su.SR) { /* rc_w0: a 0 written clears TC or RXNE; the rest is read-only */
        f->st &= ~(~u->SR & f->su.SR & (ST_TC | ST_RXNE));
    }
#endif
    stream_write(f, &f->txs, &f->stx, &f->tx, false);
    stream_write(f, &f->rxs, &f->srx, &f->rx, true);
#if defined(J288_STUB_CHANNELS)
    if (f->dma.IFCR != 0u) {
        uint32_t c = f->dma.IFCR;
        for (unsigned ch = 0; ch < 8u; ch++) { /* GIFn clears the channel's four flags */
            if ((c & (DMA_ISR_GIF1 << (4u * ch))) != 0u) {
                c |= (uint32_t)D_ALL << (4u * ch);
            }
        }
        f->dfl[0] &= ~c;
        f->dma.IFCR = 0u;
    }
#else
    f->dfl[0] &= ~f->dma.LIFCR;
    f->dfl[1] &= ~f->dma.HIFCR;
    f->dma.LIFCR = 0u;
    f->dma.HIFCR = 0u;
#endif
    kick(f);
}

static void sync_writes(void)
{
    for (size_t i = 0; i < n_uarts; i++) {
        sync_uart(&uarts[i]);
        mirror(&uarts[i]); /* taken: the registers are the hardware's again */
    }
#if __DCACHE_PRESENT
    stub_mpu.RBAR = mpu_rbar[stub_mpu.RNR & 15u]; /* the region RNR selects */
    stub_mpu.RASR = mpu_rasr[stub_mpu.RNR & 15u];
#endif
}

/* The registers as the hardware shows them. */
static void mirror(fake_uart_t *f)
{
#if defined(J288_STUB_CHANNELS)
    uint32_t isr = f->dfl[0];
    for (unsigned ch = 0; ch < 8u; ch++) {
        if ((isr & ((uint32_t)(D_TC | D_HT | D_TE) << (4u * ch))) != 0u) {
            isr |= DMA_ISR_GIF1 << (4u * ch);
        }
    }
    f->dfl[0] = isr;
    f->dma.ISR = isr;
#else
    f->dma.LISR = f->dfl[0];
    f->dma.HISR = f->dfl[1];
#endif
    U_STATUS(f->u) = f->st;
#if defined(J288_STUB_ISR_USART)
    f->u->RDR = f->rdr;
#else
    f->u->DR = f->rdr;
#endif
    D_CR(&f->txs) = (f->tx.on || f->tx.stopping) ? (D_CR(&f->txs) | D_EN) : (D_CR(&f->txs) & ~(uint32_t)D_EN);
    D_CR(&f->rxs) = (f->rx.on || f->rx.stopping) ? (D_CR(&f->rxs) | D_EN) : (D_CR(&f->rxs) & ~(uint32_t)D_EN);
    f->su = *f->u;
    f->stx = f->txs;
    f->srx = f->rxs;
    f->sdma = f->dma;
}

static void mirror_all(void)
{
    for (size_t i = 0; i < n_uarts; i++) {
        mirror(&uarts[i]);
    }
}

/* ---- the CPU's accesses ------------------------------------------------------------------------- */

/* A register access (or a HAL call) of the code under test: a tick of CPU time passes, the
 * hardware catches up, and at thread level a due interrupt is taken first. */
static void cpu_access(void)
{
    accesses++;
    if ((release_at != 0u) && (accesses >= release_at)) {
        release_at = 0u;
        irq_hold = false;
    }
    sync_writes();
    advance(now_t + 1u);
    if ((in_isr == 0) && dispatch_all()) {
        sync_writes();
    }
}

/* Whether addr is one of the fake's registers (a USART, a stream, a flag block). */
bool fake_hal_is_register(const volatile void *addr)
{
    const volatile uint8_t *a = (const volatile uint8_t *)addr;
    for (size_t i = 0; i < n_uarts; i++) {
        const fake_uart_t *f = &uarts[i];
        if (((a >= (const volatile uint8_t *)f->u) && (a < (const volatile uint8_t *)(f->u + 1))) ||
            ((a >= (const volatile uint8_t *)&f->txs) && (a < (const volatile uint8_t *)(&f->txs + 1))) ||
            ((a >= (const volatile uint8_t *)&f->rxs) && (a < (const volatile uint8_t *)(&f->rxs + 1))) ||
            ((a >= (const volatile uint8_t *)&f->dma) && (a < (const volatile uint8_t *)(&f->dma + 1)))) {
            return true;
        }
    }
    return false;
}

/* A point between two instructions of the code under test that touch no register (memory the
 * CPU owns): no time passes, but a due interrupt may be taken there. */
void fake_hal_cpu_point(void)
{
    accesses++;
    if ((release_at != 0u) && (accesses >= release_at)) {
        release_at = 0u;
        irq_hold = false;
    }
    if ((in_isr == 0) && (n_uarts > 0u)) {
        sync_writes();
        if (dispatch_all()) {
            sync_writes();
        }
    }
}

void stub_reg_touch(const volatile void *reg)
{
    cpu_access();
#if !defined(J288_STUB_ISR_USART)
    for (size_t i = 0; i < n_uarts; i++) { /* an SR read arms the SR-then-DR/DR-write sequences */
        fake_uart_t *f = &uarts[i];
        if (reg == (const volatile void *)&f->u->SR) {
            f->f4_armed = f->st & (ST_IDLE | ST_ERRORS);
            f->f4_tc_armed = (f->st & ST_TC) != 0u;
        }
    }
#else
    (void)reg;
#endif
}

#if !defined(J288_STUB_ISR_USART)
static fake_uart_t *uart_of_usart(const USART_TypeDef *u)
{
    for (size_t i = 0; i < n_uarts; i++) {
        if (uarts[i].u == u) {
            return &uarts[i];
        }
    }
    return NULL;
}

void stub_usart_sr_clear(USART_TypeDef *u, uint32_t bits)
{
    fake_uart_t *f = uart_of_usart(u);
    cpu_access();
    if (f != NULL) {
        f->st &= ~(bits & (ST_TC | ST_RXNE)); /* rc_w0; the rest of SR is read-only */
        nvic_update();
    }
    mirror_all();
}

/* DR read: ends an SR-then-DR sequence; a byte still waiting for the DMA is taken (lost). */
uint32_t stub_usart_dr_read(USART_TypeDef *u)
{
    fake_uart_t *f = uart_of_usart(u);
    uint32_t v = 0u;
    cpu_access();
    if (f != NULL) {
        if (f->rdr_full) {
            f->stolen++;
            f->rdr_full = false;
            f->st &= ~ST_RXNE;
            f->rx_take_at = FAKE_NEVER;
        }
        f->st &= ~f->f4_armed;
        f->f4_armed = 0u;
        v = f->rdr;
        nvic_update();
    }
    mirror_all();
    return v;
}
#endif

/* ---- setup ------------------------------------------------------------------------------------- */

void fake_hal_reset(void)
{
    memset(call_log, 0, sizeof call_log);
    log_len = 0u;
    memset(counts, 0, sizeof counts);
    for (size_t i = 0; i < FAKE_UARTS; i++) {
        memset(&uarts[i], 0, UART_RESET_SIZE);
    }
    memset(stub_usart, 0, sizeof stub_usart);
    memset(pins, 0, sizeof pins);
    n_uarts = 0u;
    now_t = 0u;
    accesses = 0u;
    in_isr = 0;
    irq_hold = false;
    release_at = 0u;
    stop_delay = 3u;
    fail_hook = NULL;
    failed = false;
    primask = 0u;
    basepri = 0u;
    irq_disables = 0u;
    basepri_unmasked = 0u;
    dmb_count = 0u;
    require_dmb = false;
    hook_tim = NULL;
    tim_accesses = 0u;
    crc_reg = 0xFFFFFFFFu;
    crc_unclocked = false;
#if __DCACHE_PRESENT
    memset(&stub_scb, 0, sizeof stub_scb);
    memset(&stub_mpu, 0, sizeof stub_mpu);
    memset(mpu_rbar, 0, sizeof mpu_rbar);
    memset(mpu_rasr, 0, sizeof mpu_rasr);
    stub_mpu.TYPE = 16u << MPU_TYPE_DREGION_Pos;
#endif
}

#if defined(J288_STUB_DMAMUX)
/* USART3's ids are ST's too (RM0440: 28/29, RM0433: 45/46); the stub does not name them. */
#if defined(J288_STUB_G4)
#define REQ_USART3_RX 28u
#else
#define REQ_USART3_RX 45u
#endif
static const uint32_t k_req_rx[3] = {DMA_REQUEST_USART1_RX, DMA_REQUEST_USART2_RX, REQ_USART3_RX};
static const uint32_t k_req_tx[3] = {DMA_REQUEST_USART1_TX, DMA_REQUEST_USART2_TX, REQ_USART3_RX + 1u};
#endif

bool fake_hal_uart_setup(UART_HandleTypeDef *huart)
{
    fake_uart_t *f;
    for (size_t i = 0; i < n_uarts; i++) {
        if (uarts[i].huart == huart) {
            return true;
        }
    }
    if (n_uarts >= FAKE_UARTS) {
        return false;
    }
    f = &uarts[n_uarts];
    memset(f, 0, UART_RESET_SIZE);
    f->huart = huart;
    f->u = &stub_usart[n_uarts];
    memset(f->u, 0, sizeof *f->u);
    n_uarts++;
    huart->Instance = f->u;
    huart->hdmatx = &f->htx;
    huart->hdmarx = &f->hrx;
    huart->gState = HAL_UART_STATE_READY;
    huart->RxState = HAL_UART_STATE_READY;
    /* HAL_HalfDuplex_Init: single-wire mode, both directions, the USART on. */
    f->u->CR1 = USART_CR1_UE | USART_CR1_TE | USART_CR1_RE;
    f->u->CR3 = USART_CR3_HDSEL;
    f->st = ST_TXE | ST_TC;
    /* HAL_DMA_Init: byte to byte, memory increment; TX normal, RX circular (as CubeMX sets). */
    D_CR(&f->txs) = D_M2P;
#if defined(J288_STUB_CHANNELS)
    D_CR(&f->txs) |= DMA_CCR_MINC;
    D_CR(&f->rxs) = DMA_CCR_MINC | DMA_CCR_CIRC;
#else
    D_CR(&f->txs) |= DMA_SxCR_MINC;
    D_CR(&f->rxs) = DMA_SxCR_MINC | DMA_SxCR_CIRC;
#endif
    f->htx.Instance = &f->txs;
    f->hrx.Instance = &f->rxs;
    f->htx.Parent = huart;
    f->hrx.Parent = huart;
    f->htx.State = HAL_DMA_STATE_READY;
    f->hrx.State = HAL_DMA_STATE_READY;
    f->htx.Init.Direction = DMA_MEMORY_TO_PERIPH;
    f->hrx.Init.Direction = DMA_PERIPH_TO_MEMORY;
    f->htx.Init.Mode = DMA_NORMAL;
    f->hrx.Init.Mode = DMA_CIRCULAR;
#if defined(J288_STUB_CHANNELS)
    f->htx.DmaBaseAddress = &f->dma;
    f->hrx.DmaBaseAddress = &f->dma;
    f->htx.ChannelIndex = TX_SHIFT;
    f->hrx.ChannelIndex = RX_SHIFT;
#else
    f->htx.StreamBaseAddress = (uintptr_t)&f->dma.HISR;
    f->htx.StreamIndex = TX_SHIFT;
    f->hrx.StreamBaseAddress = (uintptr_t)&f->dma.LISR;
    f->hrx.StreamIndex = RX_SHIFT;
#endif
#if defined(J288_STUB_DMAMUX)
    f->mux_tx.CCR = k_req_tx[n_uarts - 1u];
    f->mux_rx.CCR = k_req_rx[n_uarts - 1u];
    f->htx.DMAmuxChannel = &f->mux_tx;
    f->hrx.DMAmuxChannel = &f->mux_rx;
    f->htx.Init.Request = k_req_tx[n_uarts - 1u];
    f->hrx.Init.Request = k_req_rx[n_uarts - 1u];
#endif
    f->tx_fill_at = FAKE_NEVER;
    f->rx_take_at = FAKE_NEVER;
    f->idle_at = FAKE_NEVER;
    f->hwde_off_at = FAKE_NEVER;
    f->first_start = FAKE_NEVER;
    f->last_end = FAKE_NEVER;
    f->reply_start = FAKE_NEVER;
    f->rx_delay = 2u;
    f->prio = 5u;
#if defined(J288_STUB_G4)
    f->uart_first = false; /* DMA1_Channel2 is vector 12, USART1 37 */
#else
    f->uart_first = true; /* USART1 37, DMA2_Stream2 58 */
#endif
    mirror(f);
    return true;
}

USART_TypeDef *fake_hal_usart(const UART_HandleTypeDef *huart) { return uart_of(huart)->u; }
dma_regs_t *fake_hal_rx_stream(const UART_HandleTypeDef *huart) { return &uart_of(huart)->rxs; }
dma_regs_t *fake_hal_tx_stream(const UART_HandleTypeDef *huart) { return &uart_of(huart)->txs; }
uint32_t fake_hal_rx_flags(const UART_HandleTypeDef *huart) { return stream_flags(uart_of(huart), true); }

/* ---- the line, from the test ---------------------------------------------------------------- */

void fake_hal_line_put(UART_HandleTypeDef *huart, const uint8_t *data, size_t len, const uint8_t *flags,
                       uint32_t gap_ticks)
{
    fake_uart_t *f = uart_of(huart);
    uint64_t t = (f->line_end > now_t) ? f->line_end : now_t;
    sync_writes();
    for (size_t i = 0; i < len; i++) {
        line_add(f, t, data[i], (flags != NULL) ? flags[i] : 0u, false);
        t += FAKE_CHAR + gap_ticks;
    }
}

void fake_hal_line_put_after(UART_HandleTypeDef *huart, uint64_t delay_ticks, const uint8_t *data, size_t len)
{
    fake_uart_t *f = uart_of(huart);
    uint64_t t = now_t + delay_ticks;
    sync_writes();
    for (size_t i = 0; i < len; i++) {
        line_add(f, t, data[i], 0u, false);
        t += FAKE_CHAR;
    }
}

void fake_hal_set_reg(volatile uint32_t *reg, uint32_t value)
{
    sync_writes();
    *reg = value;
    mirror_all(); /* taken as it is: what the HAL's initialisation left */
}

size_t fake_hal_rx_bytes(UART_HandleTypeDef *huart, const uint8_t *data, size_t len)
{
    fake_uart_t *f = uart_of(huart);
    unsigned before = f->heard;
    fake_hal_line_put(huart, data, len, NULL, 0u);
    fake_hal_run(f->line_end - now_t + f->rx_delay + 1u);
    return (size_t)(f->heard - before);
}

bool fake_hal_rx_flagged(UART_HandleTypeDef *huart, uint8_t byte, unsigned flags)
{
    fake_uart_t *f = uart_of(huart);
    unsigned before = f->heard;
    uint8_t fl = (uint8_t)flags;
    fake_hal_line_put(huart, &byte, 1u, &fl, 0u);
    fake_hal_run(f->line_end - now_t + f->rx_delay + 1u);
    return f->heard != before;
}

bool fake_hal_line_idle(UART_HandleTypeDef *huart)
{
    fake_uart_t *f = uart_of(huart);
    unsigned before = f->idles;
    uint64_t busy = f->line_end;
    if (f->shifting && (f->shift_end > busy)) {
        busy = f->shift_end;
    }
    fake_hal_run(((busy > now_t) ? busy - now_t : 0u) + 2u * FAKE_CHAR + 1u);
    return f->idles != before;
}

void fake_hal_reply_after_tx(UART_HandleTypeDef *huart, const uint8_t *data, size_t len, uint32_t delay_ticks,
                             const uint8_t *flags)
{
    fake_uart_t *f = uart_of(huart);
    f->reply_len = (len < FRAME_MAX) ? len : FRAME_MAX;
    memcpy(f->reply, data, f->reply_len);
    for (size_t i = 0; i < f->reply_len; i++) {
        f->reply_flags[i] = (flags != NULL) ? flags[i] : 0u;
    }
    f->reply_delay = delay_ticks;
    f->reply_armed = true;
}

void fake_hal_echo_flags(UART_HandleTypeDef *huart, size_t index, unsigned flags)
{
    if (index < FRAME_MAX) {
        uart_of(huart)->echo_flags[index] = (uint8_t)flags;
    }
}

void fake_hal_line_deaf(UART_HandleTypeDef *huart, bool deaf) { uart_of(huart)->deaf = deaf; }
void fake_hal_rx_dma_delay(UART_HandleTypeDef *huart, uint32_t ticks) { uart_of(huart)->rx_delay = ticks; }
void fake_hal_dma_stop_delay(uint32_t ticks) { stop_delay = ticks; }

void fake_hal_tx_stall(UART_HandleTypeDef *huart, size_t index, uint32_t ticks)
{
    if (index < FRAME_MAX) {
        uart_of(huart)->tx_stall[index] = ticks;
    }
}

void fake_hal_dma_rx_error(UART_HandleTypeDef *huart, unsigned how)
{
    fake_uart_t *f = uart_of(huart);
    uint32_t bits = D_TE;
    sync_writes();
#if !defined(J288_STUB_CHANNELS)
    bits |= ((how & FAKE_DMA_ALSO_DME) != 0u) ? D_DME : 0u;
#endif
    f->rx.on = false; /* a transfer error disables the stream / channel */
#if defined(J288_STUB_CHANNELS)
    (void)how;
    f->rx.stopping = false; /* a channel stops at once */
#else
    f->rx.stopping = (how & FAKE_DMA_STUCK) != 0u; /* ... or its EN bit keeps reading 1 */
#endif
    f->rx.off_at = now_t + 100000u;
    f->rx_take_at = FAKE_NEVER;
    stream_flag_set(f, true, bits);
    mirror(f);
    fake_hal_run(0u);
}

unsigned fake_hal_bytes_stolen(const UART_HandleTypeDef *huart) { return uart_of(huart)->stolen; }
unsigned fake_hal_en_refused(const UART_HandleTypeDef *huart) { return uart_of(huart)->refused; }

/* ---- our transmit, from the test ------------------------------------------------------------- */

bool fake_hal_tx_busy(const UART_HandleTypeDef *huart)
{
    const fake_uart_t *f = uart_of(huart);
    sync_writes();
    return (f->programmed > 0u) && (f->last_end == FAKE_NEVER) && (f->tx.on || f->tdr_full || f->shifting);
}

bool fake_hal_tx_complete(UART_HandleTypeDef *huart) { return fake_hal_tx_complete_ex(huart, true); }

bool fake_hal_tx_complete_ex(UART_HandleTypeDef *huart, bool then_idle)
{
    fake_uart_t *f = uart_of(huart);
    sync_writes();
    if (!fake_hal_tx_busy(huart)) {
        return false;
    }
    for (unsigned i = 0; (i < 100000u) && (f->last_end == FAKE_NEVER); i++) {
        fake_hal_run(FAKE_BIT);
    }
    if (f->last_end == FAKE_NEVER) {
        return false;
    }
    if (then_idle) {
        (void)fake_hal_line_idle(huart);
    }
    return true;
}

const uint8_t *fake_hal_tx_data(const UART_HandleTypeDef *huart, size_t *len)
{
    const fake_uart_t *f = uart_of(huart);
    if (len != NULL) {
        *len = f->frame_len;
    }
    return f->frame;
}

fake_hal_tx_info_t fake_hal_tx_info(const UART_HandleTypeDef *huart)
{
    const fake_uart_t *f = uart_of(huart);
    sync_writes();
    fake_hal_tx_info_t i;
    i.first_start = f->first_start;
    i.last_end = f->last_end;
    i.reply_start = f->reply_start;
    i.sent = f->sent;
    return i;
}

/* ---- interrupts, from the test ---------------------------------------------------------------- */

void fake_hal_irq_latency(UART_HandleTypeDef *huart, fake_irq_t irq, uint32_t ticks)
{
    uart_of(huart)->irq[irq].latency = ticks;
}
void fake_hal_irq_priority(UART_HandleTypeDef *huart, uint8_t prio) { uart_of(huart)->prio = prio; }
void fake_hal_irq_uart_first(UART_HandleTypeDef *huart, bool uart_first) { uart_of(huart)->uart_first = uart_first; }

void fake_hal_irq_hold(bool hold)
{
    irq_hold = hold;
    release_at = 0u;
}

void fake_hal_irq_release_at(unsigned long n)
{
    irq_hold = true;
    release_at = accesses + n + 1u;
}

bool fake_hal_irq_service(UART_HandleTypeDef *huart, bool uart)
{
    fake_uart_t *f = uart_of(huart);
    fake_irq_t k = uart ? FAKE_IRQ_UART : FAKE_IRQ_DMA_RX;
    sync_writes();
    nvic_update();
    if (!f->irq[k].pending) {
        return false;
    }
    take(f, k);
    return true;
}

bool fake_hal_irq_pending(UART_HandleTypeDef *huart, bool uart)
{
    fake_uart_t *f = uart_of(huart);
    sync_writes();
    nvic_update();
    return f->irq[uart ? FAKE_IRQ_UART : FAKE_IRQ_DMA_RX].pending;
}

unsigned fake_hal_irq_entries(const UART_HandleTypeDef *huart, fake_irq_t irq)
{
    return uart_of(huart)->irq[irq].entries;
}

/* ---- timers ---------------------------------------------------------------------------- */

HAL_StatusTypeDef HAL_TIM_Base_Start(TIM_HandleTypeDef *htim)
{
    htim->Instance->CR1 |= 1u;
    return HAL_OK;
}

void HAL_TIM_IRQHandler(TIM_HandleTypeDef *htim) { (void)htim; }

#define TIM_CC_BITS (TIM_FLAG_CC1 | TIM_FLAG_CC2 | TIM_FLAG_CC3 | TIM_FLAG_CC4)

/* Software-generated events (EGR, written directly by the port) raise their flags. */
static void tim_take_egr(TIM_TypeDef *tim)
{
    tim->SR |= tim->EGR & TIM_CC_BITS;
    tim->EGR = 0u;
}

/* One counter tick: the counter wraps after ARR, and each channel whose compare value it
 * reaches raises its flag, whatever the interrupt enables say. */
static void tim_tick(TIM_TypeDef *tim)
{
    tim->CNT = (tim->CNT >= tim->ARR) ? 0u : tim->CNT + 1u;
    tim->SR |= (tim->CNT == tim->CCR1) ? TIM_FLAG_CC1 : 0u;
    tim->SR |= (tim->CNT == tim->CCR2) ? TIM_FLAG_CC2 : 0u;
    tim->SR |= (tim->CNT == tim->CCR3) ? TIM_FLAG_CC3 : 0u;
    tim->SR |= (tim->CNT == tim->CCR4) ? TIM_FLAG_CC4 : 0u;
}

static void tim_advance(TIM_TypeDef *tim, uint32_t ticks)
{
    tim_take_egr(tim);
    for (uint32_t i = 0; i < ticks; i++) {
        tim_tick(tim);
    }
}

static void tim_access(TIM_TypeDef *tim)
{
    tim_take_egr(tim);
    if ((tim == hook_tim) && (hook_countdown-- == 0u)) {
        hook_tim = NULL;
        tim_advance(tim, hook_ticks);
    }
    tim_accesses++;
}

uint32_t stub_tim_read(TIM_TypeDef *tim, volatile uint32_t *reg)
{
    cpu_access();
    tim_access(tim);
    return *reg;
}

void stub_tim_write(TIM_TypeDef *tim, volatile uint32_t *reg, uint32_t value)
{
    cpu_access();
    tim_access(tim);
    if (reg == &tim->SR) {
        *reg &= value; /* rc_w0: writing 1 leaves a flag as it is */
    } else {
        *reg = value;
    }
}

void fake_hal_tim_advance_at(TIM_HandleTypeDef *htim, unsigned access, uint32_t ticks)
{
    hook_tim = htim->Instance;
    hook_countdown = access;
    hook_ticks = ticks;
}

unsigned fake_hal_tim_accesses(void) { return tim_accesses; }

/* What HAL_TIM_IRQHandler does for the compare channels: each flag raised with its
 * interrupt enabled is cleared and reported. */
static unsigned tim_irq(TIM_HandleTypeDef *htim)
{
    unsigned fired = 0u;
    tim_take_egr(htim->Instance);
    for (uint32_t n = 0; n < 4u; n++) {
        uint32_t bit = 2u << n;
        if (((htim->Instance->SR & bit) != 0u) && ((htim->Instance->DIER & bit) != 0u)) {
            htim->Instance->SR &= ~bit;
            htim->Channel = (HAL_TIM_ActiveChannel)(1u << n);
            in_isr++;
            HAL_TIM_OC_DelayElapsedCallback(htim);
            in_isr--;
            htim->Channel = HAL_TIM_ACTIVE_CHANNEL_CLEARED;
            fired++;
        }
    }
    return fired;
}

unsigned fake_hal_tim_run(TIM_HandleTypeDef *htim, uint32_t ticks)
{
    unsigned fired = tim_irq(htim);
    for (uint32_t i = 0; i < ticks; i++) {
        tim_tick(htim->Instance);
        fired += tim_irq(htim);
    }
    return fired;
}

bool fake_hal_tim_fire(TIM_HandleTypeDef *htim, uint32_t ch)
{
    uint32_t bit = 1u << (ch / 4u + 1u); /* TIM_IT_CCn */
    HAL_TIM_ActiveChannel active = (HAL_TIM_ActiveChannel)(1u << (ch / 4u));
    if ((htim->Instance->DIER & bit) == 0u) {
        return false;
    }
    htim->Channel = active;
    in_isr++;
    HAL_TIM_OC_DelayElapsedCallback(htim);
    in_isr--;
    htim->Channel = HAL_TIM_ACTIVE_CHANNEL_CLEARED;
    return true;
}

/* ---- GPIO ------------------------------------------------------------------------------ */

void HAL_GPIO_WritePin(GPIO_TypeDef *GPIOx, uint16_t GPIO_Pin, GPIO_PinState PinState)
{
    cpu_access();
    record(FAKE_GPIO_WRITE, GPIOx, (uint32_t)PinState);
    for (size_t i = 0; i < n_uarts; i++) {
        fake_uart_t *f = &uarts[i];
        if ((f->de_port == GPIOx) && (f->de_pin == GPIO_Pin)) {
            trace_add(f->gpio_de, &f->gpio_de_n, (PinState == GPIO_PIN_SET) != f->de_low);
        }
    }
    for (size_t i = 0; i < FAKE_PINS; i++) {
        if ((pins[i].port == NULL) || ((pins[i].port == GPIOx) && (pins[i].pin == GPIO_Pin))) {
            pins[i].port = GPIOx;
            pins[i].pin = GPIO_Pin;
            pins[i].level = (PinState == GPIO_PIN_SET) ? 1 : 0;
            break;
        }
    }
    mirror_all();
}

GPIO_PinState HAL_GPIO_ReadPin(GPIO_TypeDef *GPIOx, uint16_t GPIO_Pin)
{
    return (fake_hal_gpio_level(GPIOx, GPIO_Pin) == 1) ? GPIO_PIN_SET : GPIO_PIN_RESET;
}

int fake_hal_gpio_level(const GPIO_TypeDef *port, uint16_t pin)
{
    for (size_t i = 0; i < FAKE_PINS; i++) {
        if ((pins[i].port == port) && (pins[i].pin == pin)) {
            return pins[i].level;
        }
    }
    return -1;
}

/* ---- CRC unit: computed here bit by bit, independently of the library --------------------- */

static uint32_t crc_feed(uint32_t crc, uint32_t poly, uint32_t value, unsigned bits)
{
    crc ^= value << (32u - bits);
    for (unsigned b = 0; b < bits; b++) {
        crc = ((crc & 0x80000000u) != 0u) ? ((crc << 1) ^ poly) : (crc << 1);
    }
    return crc;
}

void fake_hal_crc_unclocked(bool off) { crc_unclocked = off; }

#if defined(J288_STUB_F4)
/* The F4's unit: polynomial 0x04C11DB7, reset to all ones, 32-bit words. */
static uint32_t crc_run(const CRC_HandleTypeDef *hcrc, const uint32_t *buf, uint32_t n)
{
    (void)hcrc;
    if (crc_unclocked) {
        return 0u; /* a peripheral without its clock reads as zeros */
    }
    for (uint32_t i = 0; i < n; i++) {
        crc_reg = crc_feed(crc_reg, 0x04C11DB7u, buf[i], 32u);
    }
    return crc_reg;
}
static uint32_t crc_initial(const CRC_HandleTypeDef *hcrc)
{
    (void)hcrc;
    return 0xFFFFFFFFu;
}
#else
static uint32_t reverse32(uint32_t v)
{
    uint32_t r = 0u;
    for (int b = 0; b < 32; b++) {
        r = (r << 1) | ((v >> b) & 1u);
    }
    return r;
}

/* The configurable unit as its handle sets it: polynomial, initial value, input format, output
 * reversal (input reversal and shorter polynomials are not modelled). */
static uint32_t crc_run(const CRC_HandleTypeDef *hcrc, const uint32_t *buf, uint32_t n)
{
    uint32_t poly = (hcrc->Init.DefaultPolynomialUse == DEFAULT_POLYNOMIAL_ENABLE) ? DEFAULT_CRC32_POLY
                                                                                   : hcrc->Init.GeneratingPolynomial;
    const uint8_t *bytes = (const uint8_t *)buf; /* how the HAL reads a non-word format */
    if (crc_unclocked) {
        return 0u;
    }
    for (uint32_t i = 0; i < n; i++) {
        switch (hcrc->InputDataFormat) {
        case CRC_INPUTDATA_FORMAT_WORDS: crc_reg = crc_feed(crc_reg, poly, buf[i], 32u); break;
        case CRC_INPUTDATA_FORMAT_HALFWORDS:
            crc_reg = crc_feed(crc_reg, poly, (uint32_t)bytes[2u * i] << 8 | bytes[2u * i + 1u], 16u);
            break;
        case CRC_INPUTDATA_FORMAT_BYTES: crc_reg = crc_feed(crc_reg, poly, bytes[i], 8u); break;
        default: return 0u; /* the HAL computes nothing for an undefined format */
        }
    }
    return (hcrc->Init.OutputDataInversionMode == CRC_OUTPUTDATA_INVERSION_DISABLE) ? crc_reg : reverse32(crc_reg);
}
static uint32_t crc_initial(const CRC_HandleTypeDef *hcrc)
{
    return (hcrc->Init.DefaultInitValueUse == DEFAULT_INIT_VALUE_ENABLE) ? DEFAULT_CRC_INITVALUE : hcrc->Init.InitValue;
}
#endif

uint32_t HAL_CRC_Calculate(CRC_HandleTypeDef *hcrc, uint32_t pBuffer[], uint32_t BufferLength)
{
    record(FAKE_CRC_CALCULATE, hcrc, BufferLength);
    crc_reg = crc_initial(hcrc);
    return crc_run(hcrc, pBuffer, BufferLength);
}

uint32_t HAL_CRC_Accumulate(CRC_HandleTypeDef *hcrc, uint32_t pBuffer[], uint32_t BufferLength)
{
    record(FAKE_CRC_ACCUMULATE, hcrc, BufferLength);
    return crc_run(hcrc, pBuffer, BufferLength);
}

/* ---- system and core ------------------------------------------------------------------- */

HAL_StatusTypeDef HAL_Init(void) { return HAL_OK; }
uint32_t HAL_GetTick(void) { return 0u; }

uint32_t __get_PRIMASK(void) { return primask; }
void __set_PRIMASK(uint32_t priMask)
{
    primask = priMask & 1u;
    if ((primask == 0u) && (in_isr == 0)) {
        cpu_access(); /* a pending interrupt is taken as soon as it is unmasked */
        mirror_all();
    }
}
void __disable_irq(void)
{
    primask = 1u;
    irq_disables++;
}
void __enable_irq(void) { __set_PRIMASK(0u); }
uint32_t fake_hal_primask(void) { return primask; }
uint32_t __get_BASEPRI(void) { return basepri; }
void __set_BASEPRI(uint32_t basePri)
{
    basepri = basePri & 0xFFu;
    if (in_isr == 0) {
        cpu_access();
        mirror_all();
    }
}
void __set_BASEPRI_MAX(uint32_t basePri)
{
    basePri &= 0xFFu;
#if defined(__CM7_REV) && (__CM7_REV < 0x0101U)
    if (primask == 0u) {
        basepri_unmasked++; /* erratum 837070: the mask may not hold for the next instruction */
    }
#endif
    if ((basePri != 0u) && ((basepri == 0u) || (basePri < basepri))) {
        basepri = basePri;
    }
}
uint32_t fake_hal_basepri(void) { return basepri; }
unsigned fake_hal_irq_disables(void) { return irq_disables; }
unsigned fake_hal_basepri_raised_unmasked(void) { return basepri_unmasked; }

void __DMB(void)
{
    dmb_count++;
    for (size_t i = 0; i < n_uarts; i++) {
        uarts[i].dmb_since_tx_en = true;
    }
}
void __DSB(void) { __DMB(); }
void __ISB(void) {}
unsigned fake_hal_dmb_count(void) { return dmb_count; }
void fake_hal_require_dmb(bool require) { require_dmb = require; }

#if __DCACHE_PRESENT
void SCB_CleanDCache_by_Addr(volatile void *addr, int32_t dsize)
{
    record(FAKE_CACHE_CLEAN, (const void *)addr, (uint32_t)dsize);
}

void SCB_InvalidateDCache_by_Addr(volatile void *addr, int32_t dsize)
{
    record(FAKE_CACHE_INVALIDATE, (const void *)addr, (uint32_t)dsize);
}

void fake_hal_dcache(bool on)
{
    stub_scb.CCR = on ? (stub_scb.CCR | SCB_CCR_DC_Msk) : (stub_scb.CCR & ~SCB_CCR_DC_Msk);
}

void fake_hal_mpu_region(unsigned n, uintptr_t base, unsigned size_log2, uint32_t attrs)
{
    mpu_rbar[n & 15u] = (uint32_t)base & (uint32_t)MPU_RBAR_ADDR_Msk;
    mpu_rasr[n & 15u] = attrs | (((uint32_t)size_log2 - 1u) << MPU_RASR_SIZE_Pos) | MPU_RASR_ENABLE_Msk;
}

void fake_hal_mpu_enable(bool on) { stub_mpu.CTRL = on ? MPU_CTRL_ENABLE_Msk : 0u; }
#else
void fake_hal_dcache(bool on) { (void)on; }
void fake_hal_mpu_region(unsigned n, uintptr_t base, unsigned size_log2, uint32_t attrs)
{
    (void)n;
    (void)base;
    (void)size_log2;
    (void)attrs;
}
void fake_hal_mpu_enable(bool on) { (void)on; }
#endif
