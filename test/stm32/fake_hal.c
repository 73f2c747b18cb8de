/* Host-side fake of the HAL slice the STM32 port uses; see fake_hal.h. */
#include "fake_hal.h"

#include <string.h>

#define FAKE_UARTS 4u
#define FAKE_PINS 16u

/* ---- the register models ---------------------------------------------------------------- */
#if defined(J288_STUB_G4)
#define U_STATUS(u) ((u)->ISR)
#define U_DATA(u) ((u)->RDR)
#define U_RXNE USART_ISR_RXNE_RXFNE
#define U_IDLE USART_ISR_IDLE
#define U_TC USART_ISR_TC
#define U_PE USART_ISR_PE
#define U_FE USART_ISR_FE
#define U_NE USART_ISR_NE
#define U_ORE USART_ISR_ORE
#define D_CTRL(s) ((s)->CCR)
#define D_COUNT(s) ((s)->CNDTR)
#define D_MEM(s) ((s)->CMAR)
#define D_EN DMA_CCR_EN
#define D_CIRC DMA_CCR_CIRC
#define D_HTIE DMA_CCR_HTIE
#define D_TCIE DMA_CCR_TCIE
#define D_TEIE DMA_CCR_TEIE
#define D_HT DMA_ISR_HTIF1
#define D_TC DMA_ISR_TCIF1
#define D_TE DMA_ISR_TEIF1
#define D_ALL (DMA_ISR_GIF1 | DMA_ISR_HTIF1 | DMA_ISR_TCIF1 | DMA_ISR_TEIF1)
#else
#define U_STATUS(u) ((u)->SR)
#define U_DATA(u) ((u)->DR)
#define U_RXNE USART_SR_RXNE
#define U_IDLE USART_SR_IDLE
#define U_TC USART_SR_TC
#define U_PE USART_SR_PE
#define U_FE USART_SR_FE
#define U_NE USART_SR_NE
#define U_ORE USART_SR_ORE
#define D_CTRL(s) ((s)->CR)
#define D_COUNT(s) ((s)->NDTR)
#define D_MEM(s) ((s)->M0AR)
#define D_EN DMA_SxCR_EN
#define D_CIRC DMA_SxCR_CIRC
#define D_HTIE DMA_SxCR_HTIE
#define D_TCIE DMA_SxCR_TCIE
#define D_TEIE DMA_SxCR_TEIE
#define D_HT DMA_LISR_HTIF0
#define D_TC DMA_LISR_TCIF0
#define D_TE DMA_LISR_TEIF0
#define D_ALL (DMA_LISR_FEIF0 | DMA_LISR_DMEIF0 | DMA_LISR_TEIF0 | DMA_LISR_HTIF0 | DMA_LISR_TCIF0)
#endif
#define U_ERRORS (U_PE | U_FE | U_NE | U_ORE)

typedef struct {
    UART_HandleTypeDef *huart;
    USART_TypeDef usart;
    J288_STUB_DMA_INSTANCE tx_stream, rx_stream;
    DMA_HandleTypeDef htx, hrx;
    DMA_TypeDef flags; /* both streams' flags: RX at shift 16 (low), TX at 22 (high) */
    uint8_t tx[64];
    size_t tx_len;
    bool deaf;
    bool lag;
    bool rx_since_idle;
    bool rx_running; /* the RX stream seen enabled: rx_size is its length */
    uint32_t rx_size;
    unsigned stolen;
} fake_uart_t;

typedef struct {
    const GPIO_TypeDef *port;
    uint16_t pin;
    int level;
} fake_pin_t;

static fake_hal_call_t call_log[FAKE_HAL_LOG_SIZE];
static size_t log_len;
static unsigned counts[FAKE_FN_COUNT];
static fake_uart_t uarts[FAKE_UARTS];
static fake_pin_t pins[FAKE_PINS];
static uint32_t primask;
static uint32_t basepri;
static unsigned irq_disables;
static bool irq_hold;
static uint32_t crc_reg = 0xFFFFFFFFu;
static bool crc_unclocked;
/* The counter-advance hook of fake_hal_tim_advance_at(). */
static TIM_TypeDef *hook_tim;
static unsigned hook_countdown;
static uint32_t hook_ticks;
static unsigned tim_accesses;

void fake_hal_reset(void)
{
    memset(call_log, 0, sizeof call_log);
    log_len = 0u;
    memset(counts, 0, sizeof counts);
    memset(uarts, 0, sizeof uarts);
    memset(pins, 0, sizeof pins);
    primask = 0u;
    basepri = 0u;
    irq_disables = 0u;
    irq_hold = false;
    hook_tim = NULL;
    tim_accesses = 0u;
    crc_reg = 0xFFFFFFFFu;
    crc_unclocked = false;
}

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

static fake_uart_t *uart_of(const UART_HandleTypeDef *huart)
{
    for (size_t i = 0; i < FAKE_UARTS; i++) {
        if (uarts[i].huart == huart) {
            return &uarts[i];
        }
    }
    return &uarts[FAKE_UARTS - 1u]; /* tests set up fewer UARTs than this */
}

void fake_hal_uart_setup(UART_HandleTypeDef *huart)
{
    fake_uart_t *f = NULL;
    for (size_t i = 0; (i < FAKE_UARTS) && (f == NULL); i++) {
        if ((uarts[i].huart == NULL) || (uarts[i].huart == huart)) {
            f = &uarts[i];
        }
    }
    if (f == NULL) {
        return;
    }
    memset(f, 0, sizeof *f);
    f->huart = huart;
    huart->Instance = &f->usart;
    huart->hdmatx = &f->htx;
    huart->hdmarx = &f->hrx;
    huart->gState = HAL_UART_STATE_READY;
    huart->RxState = HAL_UART_STATE_READY;
    f->usart.CR1 = USART_CR1_UE | USART_CR1_TE | USART_CR1_RE;
    f->usart.CR3 = USART_CR3_HDSEL;
    U_STATUS(&f->usart) = U_TC; /* TC is up after reset */
    f->htx.Instance = &f->tx_stream;
    f->hrx.Instance = &f->rx_stream;
    f->htx.Parent = huart;
    f->hrx.Parent = huart;
    f->htx.State = HAL_DMA_STATE_READY;
    f->hrx.State = HAL_DMA_STATE_READY;
    f->hrx.Init.Mode = DMA_NORMAL;
#if defined(J288_STUB_G4)
    f->htx.DmaBaseAddress = &f->flags;
    f->hrx.DmaBaseAddress = &f->flags;
    f->htx.ChannelIndex = 0u;  /* channel 1 */
    f->hrx.ChannelIndex = 4u;  /* channel 2 */
#else
    f->htx.StreamBaseAddress = (uintptr_t)&f->flags.HISR;
    f->htx.StreamIndex = 22u; /* stream 7: HISR */
    f->hrx.StreamBaseAddress = (uintptr_t)&f->flags.LISR;
    f->hrx.StreamIndex = 16u; /* stream 2: LISR */
#endif
}

/* The flag register and shift of a stream, as the silicon lays them out. */
static volatile uint32_t *flag_reg(fake_uart_t *f, bool rx)
{
#if defined(J288_STUB_G4)
    (void)rx;
    return &f->flags.ISR;
#else
    return rx ? &f->flags.LISR : &f->flags.HISR;
#endif
}
static uint32_t flag_shift(fake_uart_t *f, bool rx)
{
#if defined(J288_STUB_G4)
    return rx ? f->hrx.ChannelIndex : f->htx.ChannelIndex;
#else
    return rx ? f->hrx.StreamIndex : f->htx.StreamIndex;
#endif
}

/* Clears written by the CPU take effect (ICR on the G4; the DMA's IFCR). */
static void sync(fake_uart_t *f)
{
#if defined(J288_STUB_G4)
    U_STATUS(&f->usart) &= ~f->usart.ICR;
    f->usart.ICR = 0u;
    f->flags.ISR &= ~f->flags.IFCR;
    f->flags.IFCR = 0u;
#else
    f->flags.LISR &= ~f->flags.LIFCR;
    f->flags.LIFCR = 0u;
    f->flags.HISR &= ~f->flags.HIFCR;
    f->flags.HIFCR = 0u;
#endif
    if ((D_CTRL(&f->rx_stream) & D_EN) == 0u) {
        f->rx_running = false;
    } else if (!f->rx_running) {
        f->rx_running = true;
        f->rx_size = D_COUNT(&f->rx_stream);
    }
}

/* The RX stream takes the byte waiting in the data register. */
static void dma_rx_take(fake_uart_t *f)
{
    J288_STUB_DMA_INSTANCE *s = &f->rx_stream;
    volatile uint32_t *fl = flag_reg(f, true);
    uint32_t sh = flag_shift(f, true);
    uint8_t *mem = (uint8_t *)D_MEM(s);

    sync(f);
    if (((U_STATUS(&f->usart) & U_RXNE) == 0u) || ((f->usart.CR3 & USART_CR3_DMAR) == 0u) ||
        !f->rx_running || (D_COUNT(s) == 0u)) {
        return;
    }
    mem[f->rx_size - D_COUNT(s)] = (uint8_t)U_DATA(&f->usart);
    U_STATUS(&f->usart) &= ~U_RXNE;
    D_COUNT(s)--;
    if (D_COUNT(s) == f->rx_size / 2u) {
        *fl |= (uint32_t)D_HT << sh;
    }
    if (D_COUNT(s) == 0u) {
        *fl |= (uint32_t)D_TC << sh;
        if ((D_CTRL(s) & D_CIRC) != 0u) {
            D_COUNT(s) = f->rx_size;
        } else {
            D_CTRL(s) &= ~(uint32_t)D_EN;
        }
    }
}

static bool uart_irq_pending(fake_uart_t *f)
{
    uint32_t st = U_STATUS(&f->usart);
    uint32_t cr1 = f->usart.CR1;
    return (((st & U_IDLE) != 0u) && ((cr1 & USART_CR1_IDLEIE) != 0u)) ||
           (((st & U_TC) != 0u) && ((cr1 & USART_CR1_TCIE) != 0u)) ||
           (((st & (U_FE | U_NE | U_ORE)) != 0u) && ((f->usart.CR3 & USART_CR3_EIE) != 0u));
}

static bool dma_irq_pending(fake_uart_t *f)
{
    uint32_t fl = (*flag_reg(f, true) >> flag_shift(f, true));
    uint32_t cr = D_CTRL(&f->rx_stream);
    return (((fl & D_HT) != 0u) && ((cr & D_HTIE) != 0u)) ||
           (((fl & D_TC) != 0u) && ((cr & D_TCIE) != 0u)) ||
           (((fl & D_TE) != 0u) && ((cr & D_TEIE) != 0u));
}

/* One handler, if its interrupt is pending; the DMA catches up afterwards. */
static bool service(fake_uart_t *f, bool uart)
{
    bool pending;
    sync(f);
    pending = uart ? uart_irq_pending(f) : dma_irq_pending(f);
    if (pending) {
        if (uart) {
            fake_app_uart_irq(f->huart);
        } else {
            fake_app_dma_rx_irq(f->huart);
        }
    }
    dma_rx_take(f);
    return pending;
}

/* The NVIC: pending interrupts are taken until none is (the UART's first, its vector being
 * the lower number on both families); a handler that leaves its flag up is taken again, a
 * bounded number of times. */
static void dispatch(fake_uart_t *f)
{
    for (unsigned n = 0; (n < 16u) && !irq_hold; n++) {
        if (!service(f, true) && !service(f, false)) {
            return;
        }
    }
}

void fake_hal_irq_hold(bool hold) { irq_hold = hold; }
bool fake_hal_irq_service(UART_HandleTypeDef *huart, bool uart) { return service(uart_of(huart), uart); }
bool fake_hal_irq_pending(UART_HandleTypeDef *huart, bool uart)
{
    fake_uart_t *f = uart_of(huart);
    sync(f);
    return uart ? uart_irq_pending(f) : dma_irq_pending(f);
}

void fake_hal_line_deaf(UART_HandleTypeDef *huart, bool deaf) { uart_of(huart)->deaf = deaf; }
void fake_hal_dma_lag(UART_HandleTypeDef *huart, bool lag) { uart_of(huart)->lag = lag; }
unsigned fake_hal_bytes_stolen(const UART_HandleTypeDef *huart) { return uart_of(huart)->stolen; }
USART_TypeDef *fake_hal_usart(const UART_HandleTypeDef *huart) { return &uart_of(huart)->usart; }
J288_STUB_DMA_INSTANCE *fake_hal_rx_stream(const UART_HandleTypeDef *huart) { return &uart_of(huart)->rx_stream; }
J288_STUB_DMA_INSTANCE *fake_hal_tx_stream(const UART_HandleTypeDef *huart) { return &uart_of(huart)->tx_stream; }

/* A byte at the receiver. */
static bool receive(fake_uart_t *f, uint8_t byte, unsigned flags)
{
    USART_TypeDef *u = &f->usart;
    uint32_t err = 0u;

    dma_rx_take(f); /* a lagging stream has caught up within a byte's time */
    if (((u->CR1 & USART_CR1_UE) == 0u) || ((u->CR1 & USART_CR1_RE) == 0u)) {
        return false; /* nobody listening */
    }
    f->rx_since_idle = true;
    if (((flags & FAKE_OVERRUN) != 0u) || ((U_STATUS(u) & U_RXNE) != 0u)) {
        U_STATUS(u) |= U_ORE; /* the byte is lost behind the full data register */
        return false;
    }
    err |= (((flags & FAKE_NOISE) != 0u) && ((u->CR3 & USART_CR3_ONEBIT) == 0u)) ? U_NE : 0u;
    err |= ((flags & FAKE_FRAMING) != 0u) ? U_FE : 0u;
    err |= ((flags & FAKE_PARITY) != 0u) ? U_PE : 0u;
    U_STATUS(u) |= err;
#if defined(J288_STUB_G4)
    if ((err != 0u) && ((u->CR3 & USART_CR3_DDRE) == 0u)) {
        return false; /* RM0440: the flagged byte is not handed to the DMA, RXNE stays 0 */
    }
#endif
    U_DATA(u) = byte;
    U_STATUS(u) |= U_RXNE;
    if (!f->lag) {
        dma_rx_take(f);
    }
    return true;
}

size_t fake_hal_rx_bytes(UART_HandleTypeDef *huart, const uint8_t *data, size_t len)
{
    fake_uart_t *f = uart_of(huart);
    size_t taken = 0u;
    for (size_t i = 0; i < len; i++) {
        taken += receive(f, data[i], 0u) ? 1u : 0u;
        dispatch(f);
    }
    return taken;
}

bool fake_hal_rx_flagged(UART_HandleTypeDef *huart, uint8_t byte, unsigned flags)
{
    fake_uart_t *f = uart_of(huart);
    bool taken = receive(f, byte, flags);
    dispatch(f);
    return taken;
}

bool fake_hal_line_idle(UART_HandleTypeDef *huart)
{
    fake_uart_t *f = uart_of(huart);
    sync(f);
    if (!f->rx_since_idle) {
        return false;
    }
    f->rx_since_idle = false;
    U_STATUS(&f->usart) |= U_IDLE;
    dispatch(f);
    return true;
}

void fake_hal_dma_rx_error(UART_HandleTypeDef *huart)
{
    fake_uart_t *f = uart_of(huart);
    sync(f);
    D_CTRL(&f->rx_stream) &= ~(uint32_t)D_EN;
    *flag_reg(f, true) |= (uint32_t)D_TE << flag_shift(f, true);
    dispatch(f);
}

const uint8_t *fake_hal_tx_data(const UART_HandleTypeDef *huart, size_t *len)
{
    fake_uart_t *f = uart_of(huart);
    if (fake_hal_tx_busy(huart)) { /* what the stream was loaded with */
        uint32_t n = D_COUNT(&f->tx_stream);
        f->tx_len = (n <= sizeof f->tx) ? n : sizeof f->tx;
        memcpy(f->tx, (const uint8_t *)D_MEM(&f->tx_stream), f->tx_len);
    }
    if (len != NULL) {
        *len = f->tx_len;
    }
    return f->tx;
}

bool fake_hal_tx_busy(const UART_HandleTypeDef *huart)
{
    fake_uart_t *f = uart_of(huart);
    return ((D_CTRL(&f->tx_stream) & D_EN) != 0u) && (D_COUNT(&f->tx_stream) != 0u) &&
           ((f->usart.CR3 & USART_CR3_DMAT) != 0u);
}

bool fake_hal_tx_complete(UART_HandleTypeDef *huart) { return fake_hal_tx_complete_ex(huart, true); }

bool fake_hal_tx_complete_ex(UART_HandleTypeDef *huart, bool then_idle)
{
    fake_uart_t *f = uart_of(huart);
    J288_STUB_DMA_INSTANCE *s = &f->tx_stream;
    const uint8_t *mem = (const uint8_t *)D_MEM(s);
    uint32_t n;

    sync(f);
    if (!fake_hal_tx_busy(huart) || ((f->usart.CR1 & USART_CR1_TE) == 0u)) {
        return false;
    }
    n = D_COUNT(s);
    f->tx_len = (n <= sizeof f->tx) ? n : sizeof f->tx;
    memcpy(f->tx, mem, f->tx_len);
    for (uint32_t i = 0; i < n; i++) {
        if (!f->deaf) {
            (void)receive(f, mem[i], 0u); /* the single wire: the receiver hears it */
            dispatch(f);
        }
    }
    D_COUNT(s) = 0u;
#if !defined(J288_STUB_G4)
    D_CTRL(s) &= ~(uint32_t)D_EN; /* a stream stops at the end; a channel stays enabled */
#endif
    *flag_reg(f, false) |= (uint32_t)D_TC << flag_shift(f, false);
    U_STATUS(&f->usart) |= U_TC;
    dispatch(f);
    if (then_idle) {
        (void)fake_hal_line_idle(huart);
    }
    return true;
}

#if !defined(J288_STUB_G4)
static fake_uart_t *uart_of_usart(const USART_TypeDef *u)
{
    for (size_t i = 0; i < FAKE_UARTS; i++) {
        if (&uarts[i].usart == u) {
            return &uarts[i];
        }
    }
    return NULL;
}

void stub_usart_sr_clear(USART_TypeDef *u, uint32_t bits) { u->SR &= ~bits; }

/* SR then DR: IDLE and the error flags go; a byte still waiting for the DMA goes with them. */
uint32_t stub_usart_dr_read(USART_TypeDef *u)
{
    fake_uart_t *f = uart_of_usart(u);
    if ((f != NULL) && ((u->SR & USART_SR_RXNE) != 0u)) {
        f->stolen++;
    }
    u->SR &= ~(uint32_t)(USART_SR_RXNE | USART_SR_IDLE | U_ERRORS);
    return u->DR;
}
#endif

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
    tim_access(tim);
    return *reg;
}

void stub_tim_write(TIM_TypeDef *tim, volatile uint32_t *reg, uint32_t value)
{
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
            HAL_TIM_OC_DelayElapsedCallback(htim);
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
    HAL_TIM_OC_DelayElapsedCallback(htim);
    htim->Channel = HAL_TIM_ACTIVE_CHANNEL_CLEARED;
    return true;
}

/* ---- GPIO ------------------------------------------------------------------------------ */

void HAL_GPIO_WritePin(GPIO_TypeDef *GPIOx, uint16_t GPIO_Pin, GPIO_PinState PinState)
{
    record(FAKE_GPIO_WRITE, GPIOx, (uint32_t)PinState);
    for (size_t i = 0; i < FAKE_PINS; i++) {
        if ((pins[i].port == NULL) || ((pins[i].port == GPIOx) && (pins[i].pin == GPIO_Pin))) {
            pins[i].port = GPIOx;
            pins[i].pin = GPIO_Pin;
            pins[i].level = (PinState == GPIO_PIN_SET) ? 1 : 0;
            return;
        }
    }
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

/* The unit as its handle configures it (the configurable unit of the G4/H7; the reset
 * configuration is the servo's CRC): polynomial, initial value, input format and output
 * reversal. Input reversal and polynomial sizes other than 32 bits are not modelled. */
static uint32_t crc_feed(uint32_t crc, uint32_t poly, uint32_t value, unsigned bits)
{
    crc ^= value << (32u - bits);
    for (unsigned b = 0; b < bits; b++) {
        crc = ((crc & 0x80000000u) != 0u) ? ((crc << 1) ^ poly) : (crc << 1);
    }
    return crc;
}

static uint32_t reverse32(uint32_t v)
{
    uint32_t r = 0u;
    for (int b = 0; b < 32; b++) {
        r = (r << 1) | ((v >> b) & 1u);
    }
    return r;
}

void fake_hal_crc_unclocked(bool off) { crc_unclocked = off; }

static uint32_t crc_run(const CRC_HandleTypeDef *hcrc, const uint32_t *buf, uint32_t n)
{
    if (crc_unclocked) {
        return 0u; /* a peripheral without its clock reads as zeros */
    }
    uint32_t poly = (hcrc->Init.DefaultPolynomialUse == DEFAULT_POLYNOMIAL_ENABLE)
                        ? DEFAULT_CRC32_POLY
                        : hcrc->Init.GeneratingPolynomial;
    const uint8_t *bytes = (const uint8_t *)buf; /* how the HAL reads a non-word format */
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
    return (hcrc->Init.OutputDataInversionMode == CRC_OUTPUTDATA_INVERSION_DISABLE) ? crc_reg
                                                                                    : reverse32(crc_reg);
}

uint32_t HAL_CRC_Calculate(CRC_HandleTypeDef *hcrc, uint32_t pBuffer[], uint32_t BufferLength)
{
    record(FAKE_CRC_CALCULATE, hcrc, BufferLength);
    crc_reg = (hcrc->Init.DefaultInitValueUse == DEFAULT_INIT_VALUE_ENABLE) ? DEFAULT_CRC_INITVALUE
                                                                            : hcrc->Init.InitValue;
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
void __set_PRIMASK(uint32_t priMask) { primask = priMask; }
void __disable_irq(void)
{
    primask = 1u;
    irq_disables++;
}
uint32_t fake_hal_primask(void) { return primask; }
uint32_t __get_BASEPRI(void) { return basepri; }
void __set_BASEPRI(uint32_t basePri) { basepri = basePri & 0xFFu; }
void __set_BASEPRI_MAX(uint32_t basePri)
{
    basePri &= 0xFFu;
    if ((basePri != 0u) && ((basepri == 0u) || (basePri < basepri))) {
        basepri = basePri;
    }
}
uint32_t fake_hal_basepri(void) { return basepri; }
unsigned fake_hal_irq_disables(void) { return irq_disables; }

void SCB_CleanDCache_by_Addr(volatile void *addr, int32_t dsize)
{
    record(FAKE_CACHE_CLEAN, (const void *)addr, (uint32_t)dsize);
}

void SCB_InvalidateDCache_by_Addr(volatile void *addr, int32_t dsize)
{
    record(FAKE_CACHE_INVALIDATE, (const void *)addr, (uint32_t)dsize);
}
