/* Host-side fake of the HAL slice the STM32 port uses; see fake_hal.h. */
#include "fake_hal.h"

#include <string.h>

#define FAKE_UARTS 4u
#define FAKE_PINS 16u

typedef struct {
    const UART_HandleTypeDef *huart;
    bool te, re;
    bool tx_busy;
    uint8_t tx[64];
    size_t tx_len;
    bool dmat, dmar; /* the UART's DMA requests (CR3) */
    uint8_t *rx_buf; /* armed reception, NULL when none */
    uint16_t rx_size;
    uint16_t rx_fill;
    bool half_done;
} fake_uart_t;

typedef struct {
    const GPIO_TypeDef *port;
    uint16_t pin;
    int level;
} fake_pin_t;

static fake_hal_call_t call_log[FAKE_HAL_LOG_SIZE];
static size_t log_len;
static unsigned counts[FAKE_FN_COUNT];
static bool fail_next[FAKE_FN_COUNT];
static fake_uart_t uarts[FAKE_UARTS];
static fake_pin_t pins[FAKE_PINS];
static uint32_t primask;
static unsigned irq_disables;
static uint32_t crc_reg = 0xFFFFFFFFu;
static bool crc_unclocked;
static bool rx_circular;
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
    memset(fail_next, 0, sizeof fail_next);
    memset(uarts, 0, sizeof uarts);
    memset(pins, 0, sizeof pins);
    primask = 0u;
    irq_disables = 0u;
    hook_tim = NULL;
    tim_accesses = 0u;
    crc_reg = 0xFFFFFFFFu;
    crc_unclocked = false;
    rx_circular = false;
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

/* A call of fn: logged; true when the test scripted it to fail (once, by fake_hal_fail_next). */
static bool call_fails(fake_hal_fn_t fn, const void *handle, uint32_t arg)
{
    bool f = fail_next[fn];
    record(fn, handle, arg);
    fail_next[fn] = false;
    return f;
}

size_t fake_hal_log_len(void) { return log_len; }
const fake_hal_call_t *fake_hal_log_at(size_t i) { return (i < log_len) ? &call_log[i] : NULL; }
void fake_hal_log_clear(void) { log_len = 0u; }
unsigned fake_hal_count(fake_hal_fn_t fn) { return counts[fn]; }
void fake_hal_fail_next(fake_hal_fn_t fn) { fail_next[fn] = true; }

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
    for (size_t i = 0; i < FAKE_UARTS; i++) {
        if (uarts[i].huart == NULL) {
            uarts[i].huart = huart;
            return &uarts[i];
        }
    }
    return &uarts[FAKE_UARTS - 1u]; /* tests use fewer UARTs than this */
}

/* ---- UART ------------------------------------------------------------------------------ */

/* The DMA handles linked to huart are ready after init, as HAL_DMA_Init leaves them. */
static void dma_set_state(DMA_HandleTypeDef *hdma, HAL_DMA_StateTypeDef st)
{
    if (hdma != NULL) {
        hdma->State = st;
    }
}

/* The F4 HAL starts the stream with HAL_DMA_Start_IT and ignores its result, which is
 * HAL_BUSY when the stream's handle is not READY (a transfer left running): the UART call
 * then returns HAL_OK and nothing moves. */
static bool dma_start(DMA_HandleTypeDef *hdma)
{
    if ((hdma != NULL) && (hdma->State != HAL_DMA_STATE_READY)) {
        return false;
    }
    dma_set_state(hdma, HAL_DMA_STATE_BUSY);
    return true;
}

HAL_DMA_StateTypeDef HAL_DMA_GetState(DMA_HandleTypeDef *hdma) { return hdma->State; }

HAL_StatusTypeDef HAL_DMA_Abort(DMA_HandleTypeDef *hdma)
{
    record(FAKE_DMA_ABORT, hdma, 0u);
    if (hdma->State != HAL_DMA_STATE_BUSY) {
        return HAL_ERROR; /* no transfer to abort */
    }
    hdma->State = HAL_DMA_STATE_READY;
    return HAL_OK;
}

HAL_StatusTypeDef HAL_HalfDuplex_Init(UART_HandleTypeDef *huart)
{
    dma_set_state(huart->hdmatx, HAL_DMA_STATE_READY);
    dma_set_state(huart->hdmarx, HAL_DMA_STATE_READY);
    huart->gState = HAL_UART_STATE_READY;
    huart->RxState = HAL_UART_STATE_READY;
    huart->ErrorCode = HAL_UART_ERROR_NONE;
    return HAL_OK;
}

static HAL_StatusTypeDef half_duplex_enable(UART_HandleTypeDef *huart, bool transmitter)
{
    fake_uart_t *u = uart_of(huart);
    if (call_fails(transmitter ? FAKE_HALFDUPLEX_TX : FAKE_HALFDUPLEX_RX, huart, 0u)) {
        return HAL_ERROR;
    }
    u->te = transmitter;
    u->re = !transmitter;
    huart->gState = HAL_UART_STATE_READY; /* as ST's HAL does, whatever the transmit's state */
    return HAL_OK;
}

HAL_StatusTypeDef HAL_HalfDuplex_EnableTransmitter(UART_HandleTypeDef *huart)
{
    return half_duplex_enable(huart, true);
}

HAL_StatusTypeDef HAL_HalfDuplex_EnableReceiver(UART_HandleTypeDef *huart)
{
    return half_duplex_enable(huart, false);
}

HAL_StatusTypeDef HAL_UART_Transmit_DMA(UART_HandleTypeDef *huart, const uint8_t *pData, uint16_t Size)
{
    fake_uart_t *u = uart_of(huart);
    if (call_fails(FAKE_TRANSMIT_DMA, huart, Size) || (pData == NULL) || (Size == 0u) ||
        (huart->gState != HAL_UART_STATE_READY)) {
        return (huart->gState != HAL_UART_STATE_READY) ? HAL_BUSY : HAL_ERROR;
    }
    huart->pTxBuffPtr = pData;
    huart->TxXferSize = Size;
    huart->gState = HAL_UART_STATE_BUSY_TX;
    u->dmat = true; /* set after the stream start, whatever its result */
    if (!dma_start(huart->hdmatx)) {
        u->tx_busy = false; /* no transfer that will ever complete: a stalled one never does */
        return HAL_OK;      /* the F4 HAL's silent failure: nothing goes out, ever */
    }
    u->tx_len = (Size <= sizeof u->tx) ? Size : sizeof u->tx;
    memcpy(u->tx, pData, u->tx_len);
    u->tx_busy = true;
    return HAL_OK;
}

HAL_StatusTypeDef HAL_UARTEx_ReceiveToIdle_DMA(UART_HandleTypeDef *huart, uint8_t *pData, uint16_t Size)
{
    fake_uart_t *u = uart_of(huart);
    if (call_fails(FAKE_RECEIVE_TO_IDLE_DMA, huart, Size) || (pData == NULL) || (Size == 0u)) {
        return HAL_ERROR;
    }
    if (huart->RxState != HAL_UART_STATE_READY) {
        return HAL_BUSY;
    }
    huart->pRxBuffPtr = pData;
    huart->RxXferSize = Size;
    huart->RxState = HAL_UART_STATE_BUSY_RX;
    huart->ErrorCode = HAL_UART_ERROR_NONE;
    u->dmar = true;
    if (!dma_start(huart->hdmarx)) {
        return HAL_OK; /* as above: the reception never receives */
    }
    u->rx_buf = pData;
    u->rx_size = Size;
    u->rx_fill = 0u;
    u->half_done = false;
    return HAL_OK;
}

HAL_StatusTypeDef HAL_UART_AbortReceive(UART_HandleTypeDef *huart)
{
    fake_uart_t *u = uart_of(huart);
    if (call_fails(FAKE_ABORT_RECEIVE, huart, 0u)) {
        return HAL_ERROR;
    }
    u->rx_buf = NULL;
    if (u->dmar) { /* the HAL aborts the stream only when the UART's DMA request is on */
        u->dmar = false;
        dma_set_state(huart->hdmarx, HAL_DMA_STATE_READY);
    }
    huart->RxState = HAL_UART_STATE_READY;
    return HAL_OK;
}

HAL_StatusTypeDef HAL_UART_AbortTransmit(UART_HandleTypeDef *huart)
{
    fake_uart_t *u = uart_of(huart);
    if (call_fails(FAKE_ABORT_TRANSMIT, huart, 0u)) {
        return HAL_ERROR;
    }
    u->tx_busy = false;
    if (u->dmat) {
        u->dmat = false;
        dma_set_state(huart->hdmatx, HAL_DMA_STATE_READY);
    }
    huart->gState = HAL_UART_STATE_READY;
    return HAL_OK;
}

void HAL_UART_IRQHandler(UART_HandleTypeDef *huart) { (void)huart; }

const uint8_t *fake_hal_tx_data(const UART_HandleTypeDef *huart, size_t *len)
{
    fake_uart_t *u = uart_of(huart);
    if (len != NULL) {
        *len = u->tx_len;
    }
    return u->tx;
}

bool fake_hal_tx_busy(const UART_HandleTypeDef *huart) { return uart_of(huart)->tx_busy; }
bool fake_hal_rx_armed(const UART_HandleTypeDef *huart) { return uart_of(huart)->rx_buf != NULL; }
bool fake_hal_receiver_on(const UART_HandleTypeDef *huart) { return uart_of(huart)->re; }
bool fake_hal_transmitter_on(const UART_HandleTypeDef *huart) { return uart_of(huart)->te; }

bool fake_hal_tx_complete(UART_HandleTypeDef *huart)
{
    fake_uart_t *u = uart_of(huart);
    if (!u->tx_busy) {
        return false;
    }
    u->tx_busy = false;
    u->dmat = false;
    dma_set_state(huart->hdmatx, HAL_DMA_STATE_READY);
    huart->gState = HAL_UART_STATE_READY; /* the HAL is ready again before the callback */
    HAL_UART_TxCpltCallback(huart);
    return true;
}

/* Reception over: the HAL marks the handle ready, then reports the fill level. */
static void rx_end(UART_HandleTypeDef *huart, fake_uart_t *u)
{
    uint16_t fill = u->rx_fill;
    u->rx_buf = NULL;
    u->dmar = false;
    dma_set_state(huart->hdmarx, HAL_DMA_STATE_READY);
    huart->RxState = HAL_UART_STATE_READY;
    HAL_UARTEx_RxEventCallback(huart, fill);
}

size_t fake_hal_rx_bytes(UART_HandleTypeDef *huart, const uint8_t *data, size_t len)
{
    fake_uart_t *u = uart_of(huart);
    size_t stored = 0u;
    for (size_t i = 0; i < len; i++) {
        if ((u->rx_buf == NULL) || !u->re) {
            continue; /* nobody listening: the byte is lost */
        }
        u->rx_buf[u->rx_fill++] = data[i];
        stored++;
        if ((u->rx_fill == u->rx_size) && rx_circular) {
            u->rx_fill = 0u; /* the stream wraps and goes on */
            u->half_done = false;
            HAL_UARTEx_RxEventCallback(huart, u->rx_size);
        } else if (u->rx_fill == u->rx_size) {
            rx_end(huart, u); /* buffer full (DMA transfer complete) */
        } else if (!u->half_done && (u->rx_fill == (uint16_t)(u->rx_size / 2u))) {
            u->half_done = true; /* half transfer: reception goes on */
            HAL_UARTEx_RxEventCallback(huart, u->rx_fill);
        }
    }
    return stored;
}

void fake_hal_rx_circular(bool on) { rx_circular = on; }

bool fake_hal_rx_idle(UART_HandleTypeDef *huart)
{
    fake_uart_t *u = uart_of(huart);
    if ((u->rx_buf == NULL) || (u->rx_fill == 0u)) {
        return false; /* the HAL reports idle only inside a reception that has data */
    }
    if (rx_circular) {
        HAL_UARTEx_RxEventCallback(huart, u->rx_fill); /* the reception goes on */
        return true;
    }
    rx_end(huart, u);
    return true;
}

void fake_hal_rx_error(UART_HandleTypeDef *huart, uint32_t error_code)
{
    fake_uart_t *u = uart_of(huart);
    u->rx_buf = NULL; /* DMA mode: the HAL treats the error as blocking and aborts */
    u->dmar = false;
    dma_set_state(huart->hdmarx, HAL_DMA_STATE_READY);
    huart->RxState = HAL_UART_STATE_READY;
    huart->ErrorCode = error_code;
    HAL_UART_ErrorCallback(huart);
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
unsigned fake_hal_irq_disables(void) { return irq_disables; }

void SCB_CleanDCache_by_Addr(volatile void *addr, int32_t dsize)
{
    record(FAKE_CACHE_CLEAN, (const void *)addr, (uint32_t)dsize);
}

void SCB_InvalidateDCache_by_Addr(volatile void *addr, int32_t dsize)
{
    record(FAKE_CACHE_INVALIDATE, (const void *)addr, (uint32_t)dsize);
}
