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
    crc_reg = 0xFFFFFFFFu;
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

static bool take_failure(fake_hal_fn_t fn)
{
    bool f = fail_next[fn];
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

HAL_StatusTypeDef HAL_HalfDuplex_Init(UART_HandleTypeDef *huart)
{
    huart->gState = HAL_UART_STATE_READY;
    huart->RxState = HAL_UART_STATE_READY;
    huart->ErrorCode = HAL_UART_ERROR_NONE;
    return HAL_OK;
}

HAL_StatusTypeDef HAL_HalfDuplex_EnableTransmitter(UART_HandleTypeDef *huart)
{
    fake_uart_t *u = uart_of(huart);
    record(FAKE_HALFDUPLEX_TX, huart, 0u);
    if (take_failure(FAKE_HALFDUPLEX_TX)) {
        return HAL_ERROR;
    }
    u->te = true;
    u->re = false;
    return HAL_OK;
}

HAL_StatusTypeDef HAL_HalfDuplex_EnableReceiver(UART_HandleTypeDef *huart)
{
    fake_uart_t *u = uart_of(huart);
    record(FAKE_HALFDUPLEX_RX, huart, 0u);
    if (take_failure(FAKE_HALFDUPLEX_RX)) {
        return HAL_ERROR;
    }
    u->te = false;
    u->re = true;
    return HAL_OK;
}

HAL_StatusTypeDef HAL_UART_Transmit_DMA(UART_HandleTypeDef *huart, const uint8_t *pData, uint16_t Size)
{
    fake_uart_t *u = uart_of(huart);
    record(FAKE_TRANSMIT_DMA, huart, Size);
    if (take_failure(FAKE_TRANSMIT_DMA) || (pData == NULL) || (Size == 0u) ||
        (huart->gState != HAL_UART_STATE_READY)) {
        return (huart->gState != HAL_UART_STATE_READY) ? HAL_BUSY : HAL_ERROR;
    }
    u->tx_len = (Size <= sizeof u->tx) ? Size : sizeof u->tx;
    memcpy(u->tx, pData, u->tx_len);
    u->tx_busy = true;
    huart->pTxBuffPtr = pData;
    huart->TxXferSize = Size;
    huart->gState = HAL_UART_STATE_BUSY_TX;
    return HAL_OK;
}

HAL_StatusTypeDef HAL_UARTEx_ReceiveToIdle_DMA(UART_HandleTypeDef *huart, uint8_t *pData, uint16_t Size)
{
    fake_uart_t *u = uart_of(huart);
    record(FAKE_RECEIVE_TO_IDLE_DMA, huart, Size);
    if (take_failure(FAKE_RECEIVE_TO_IDLE_DMA) || (pData == NULL) || (Size == 0u)) {
        return HAL_ERROR;
    }
    if (huart->RxState != HAL_UART_STATE_READY) {
        return HAL_BUSY;
    }
    u->rx_buf = pData;
    u->rx_size = Size;
    u->rx_fill = 0u;
    u->half_done = false;
    huart->pRxBuffPtr = pData;
    huart->RxXferSize = Size;
    huart->RxState = HAL_UART_STATE_BUSY_RX;
    huart->ErrorCode = HAL_UART_ERROR_NONE;
    return HAL_OK;
}

HAL_StatusTypeDef HAL_UART_AbortReceive(UART_HandleTypeDef *huart)
{
    fake_uart_t *u = uart_of(huart);
    record(FAKE_ABORT_RECEIVE, huart, 0u);
    u->rx_buf = NULL;
    huart->RxState = HAL_UART_STATE_READY;
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
    huart->gState = HAL_UART_STATE_READY; /* the HAL is ready again before the callback */
    HAL_UART_TxCpltCallback(huart);
    return true;
}

/* Reception over: the HAL marks the handle ready, then reports the fill level. */
static void rx_end(UART_HandleTypeDef *huart, fake_uart_t *u)
{
    uint16_t fill = u->rx_fill;
    u->rx_buf = NULL;
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
        if (u->rx_fill == u->rx_size) {
            rx_end(huart, u); /* buffer full (DMA transfer complete) */
        } else if (!u->half_done && (u->rx_fill == (uint16_t)(u->rx_size / 2u))) {
            u->half_done = true; /* half transfer: reception goes on */
            HAL_UARTEx_RxEventCallback(huart, u->rx_fill);
        }
    }
    return stored;
}

bool fake_hal_rx_idle(UART_HandleTypeDef *huart)
{
    fake_uart_t *u = uart_of(huart);
    if ((u->rx_buf == NULL) || (u->rx_fill == 0u)) {
        return false; /* the HAL reports idle only inside a reception that has data */
    }
    rx_end(huart, u);
    return true;
}

void fake_hal_rx_error(UART_HandleTypeDef *huart, uint32_t error_code)
{
    fake_uart_t *u = uart_of(huart);
    u->rx_buf = NULL; /* DMA mode: the HAL treats the error as blocking and aborts */
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

static uint32_t crc_feed(uint32_t crc, uint32_t word)
{
    crc ^= word;
    for (int b = 0; b < 32; b++) {
        crc = ((crc & 0x80000000u) != 0u) ? ((crc << 1) ^ 0x04C11DB7u) : (crc << 1);
    }
    return crc;
}

uint32_t HAL_CRC_Calculate(CRC_HandleTypeDef *hcrc, uint32_t pBuffer[], uint32_t BufferLength)
{
    record(FAKE_CRC_CALCULATE, hcrc, BufferLength);
    crc_reg = 0xFFFFFFFFu;
    for (uint32_t i = 0; i < BufferLength; i++) {
        crc_reg = crc_feed(crc_reg, pBuffer[i]);
    }
    return crc_reg;
}

uint32_t HAL_CRC_Accumulate(CRC_HandleTypeDef *hcrc, uint32_t pBuffer[], uint32_t BufferLength)
{
    record(FAKE_CRC_ACCUMULATE, hcrc, BufferLength);
    for (uint32_t i = 0; i < BufferLength; i++) {
        crc_reg = crc_feed(crc_reg, pBuffer[i]);
    }
    return crc_reg;
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
