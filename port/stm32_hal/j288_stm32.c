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
typedef char j288_stm32_rx_whole_lines[(J288_STM32_RX_BUF_SIZE % J288_STM32_DCACHE_LINE) == 0u ? 1 : -1];
typedef char j288_stm32_rx_fits_hal[(J288_STM32_RX_BUF_SIZE <= 0xFFFFu) ? 1 : -1];

/* The callbacks carry only a HAL handle; this table maps it back to the bus. Written only by
 * init/deinit in thread context, read by the ISRs: a slot is filled before it is published,
 * and a pointer store is atomic on Cortex-M. */
static j288_stm32_t *volatile registry[J288_STM32_MAX_BUSES];

static j288_stm32_t *find_uart(const UART_HandleTypeDef *huart)
{
    for (size_t i = 0; i < J288_STM32_MAX_BUSES; i++) {
        j288_stm32_t *p = registry[i];
        if ((p != NULL) && (huart != NULL) && (p->cfg.huart == huart)) {
            return p;
        }
    }
    return NULL;
}

/* Counts a failure; returns whether the call succeeded. */
static bool hal_ok(j288_stm32_t *p, HAL_StatusTypeDef st)
{
    if (st != HAL_OK) {
        p->stats.hal_failures++;
        return false;
    }
    return true;
}

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

/* A transfer that never completed (a stalled stream, a lost TC or DMA interrupt) leaves the
 * UART BUSY_TX and the stream's handle BUSY. The next HAL_UART_Transmit_DMA would then fail,
 * or on the F4, whose HAL ignores HAL_DMA_Start_IT's result, return HAL_OK and send nothing;
 * the same goes for a reception. So a path left busy is aborted first: the UART's abort, and
 * the stream's own when the UART's did not reach it (the HAL aborts the stream only while
 * the UART's DMA request bit is set). Returns whether the stream is ready. */
static bool stream_ready(j288_stm32_t *p, j288_dir_t dir)
{
    UART_HandleTypeDef *h = p->cfg.huart;
    DMA_HandleTypeDef *hdma = (dir == J288_DIR_TX) ? h->hdmatx : h->hdmarx;
    bool uart_busy = (dir == J288_DIR_TX) && (h->gState != HAL_UART_STATE_READY);

    if (!uart_busy && (HAL_DMA_GetState(hdma) == HAL_DMA_STATE_READY)) {
        return true;
    }
    p->stats.dma_resets++;
    (void)hal_ok(p, (dir == J288_DIR_TX) ? HAL_UART_AbortTransmit(h) : HAL_UART_AbortReceive(h));
    if (HAL_DMA_GetState(hdma) != HAL_DMA_STATE_READY) {
        (void)hal_ok(p, HAL_DMA_Abort(hdma));
    }
    return HAL_DMA_GetState(hdma) == HAL_DMA_STATE_READY;
}

static bool tx_path_ready(j288_stm32_t *p)
{
    UART_HandleTypeDef *h = p->cfg.huart;
    return stream_ready(p, J288_DIR_TX) && (h->gState == HAL_UART_STATE_READY);
}

/* Single-wire mode: the transmitter and receiver share the pin, so the receiver is switched
 * off while we talk (no echo: init refuses config.echo) and the reception still armed from
 * the last transaction is abandoned first: anything it would still deliver is stale. A HAL
 * failure here cannot be returned (set_dir has no result): the following start_tx refuses,
 * so the attempt fails as J288_ERR_PORT; on the way to receive it is reported as a line
 * error (J288_LINE_DMA), so the attempt fails as J288_ERR_LINE instead of timing out
 * silently. */
static void op_set_dir(void *ctx, j288_dir_t dir)
{
    j288_stm32_t *p = ctx;
    p->dir = (uint8_t)dir;
    if (dir == J288_DIR_TX) {
        bool ok = hal_ok(p, HAL_UART_AbortReceive(p->cfg.huart));
        ok = ok && hal_ok(p, HAL_HalfDuplex_EnableTransmitter(p->cfg.huart));
        p->tx_refused = !ok;
        de_write(p, ok);
    } else {
        de_write(p, false);
        if (!hal_ok(p, HAL_HalfDuplex_EnableReceiver(p->cfg.huart))) {
            j288_bus_on_error(&p->bus, J288_LINE_DMA);
        }
    }
}

static int op_start_tx(void *ctx, const uint8_t *data, size_t len)
{
    j288_stm32_t *p = ctx;
    if ((data == NULL) || (len == 0u) || (len > J288_STM32_TX_BUF_SIZE)) {
        return J288_ERR_BAD_ARG;
    }
    if (p->tx_refused || !tx_path_ready(p)) {
        return J288_ERR_PORT; /* counted in hal_failures where it failed */
    }
    /* Copy into the DMA buffer: the bus object may sit where the DMA cannot read. */
    memcpy(p->cfg.dma->tx, data, len);
    cache_clean(p->cfg.dma->tx, J288_STM32_TX_BUF_SIZE);
    p->stats.tx_frames++;
    if (!hal_ok(p, HAL_UART_Transmit_DMA(p->cfg.huart, p->cfg.dma->tx, (uint16_t)len))) {
        return J288_ERR_PORT;
    }
    return J288_OK;
}

static void rx_arm(j288_stm32_t *p)
{
    UART_HandleTypeDef *h = p->cfg.huart;
    /* As for transmit: a stream left busy would make the F4 HAL "start" a reception that
     * never receives; a stream that cannot be made ready is the line error reported below. */
    bool ready = stream_ready(p, J288_DIR_RX);

    p->rx_pos = 0u;
    /* Drop cached copies before the DMA writes, so that no dirty line is evicted on top of
     * received bytes later. */
    cache_invalidate(p->cfg.dma->rx, J288_STM32_RX_BUF_SIZE);
    if (!ready ||
        !hal_ok(p, HAL_UARTEx_ReceiveToIdle_DMA(h, p->cfg.dma->rx, (uint16_t)J288_STM32_RX_BUF_SIZE))) {
        j288_bus_on_error(&p->bus, J288_LINE_DMA);
    }
}

static void op_start_rx(void *ctx)
{
    rx_arm(ctx);
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

/* Thread-context sections of the bus against its own interrupts: PRIMASK, saved so that a
 * caller which already masked stays masked. */
static void op_lock(void *ctx)
{
    j288_stm32_t *p = ctx;
    uint32_t saved = __get_PRIMASK();
    __disable_irq();
    p->lock_saved = saved;
}

static void op_unlock(void *ctx)
{
    const j288_stm32_t *p = ctx;
    __set_PRIMASK(p->lock_saved);
}

/* The one operations table. Each bus gets a copy (j288_stm32_t.ops) without the optional
 * operations its configuration lacks: no timer, no arm_timeout (the application polls); no
 * CRC unit, no crc32 (the library's compile-time backend). */
static const j288_port_t port_ops = {
    .start_tx = op_start_tx,
    .now_us = op_now_us,
    .start_rx = op_start_rx,
    .set_dir = op_set_dir,
    .arm_timeout = op_arm_timeout,
#if J288_STM32_HW_CRC
    .crc32 = op_crc32,
#endif
    .lock = op_lock,
    .unlock = op_unlock,
};

static void pick_ops(j288_stm32_t *p)
{
    p->ops = port_ops;
    if (p->cfg.htim == NULL) {
        p->ops.arm_timeout = NULL;
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

static int check_config(const j288_stm32_config_t *cfg, const j288_bus_config_t *bus_cfg)
{
    if ((cfg->huart == NULL) || (cfg->dma == NULL)) {
        return J288_ERR_NULL;
    }
    if ((cfg->huart->hdmatx == NULL) || (cfg->huart->hdmarx == NULL)) {
        return J288_ERR_BAD_CONFIG; /* the UART has no DMA streams linked */
    }
    if ((bus_cfg != NULL) && bus_cfg->echo) {
        return J288_ERR_BAD_CONFIG; /* the receiver is off while we transmit */
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
    pick_ops(p);
    rc = j288_bus_init(&p->bus, &p->ops, p, bus_cfg);
    if (rc != J288_OK) {
        return rc;
    }
    if (cfg->htim != NULL) {
        __HAL_TIM_DISABLE_IT(cfg->htim, channel_it(cfg->tim_channel));
    }
    p->dir = (uint8_t)J288_DIR_RX;
    de_write(p, false);
    if (!hal_ok(p, HAL_HalfDuplex_EnableReceiver(cfg->huart))) {
        return J288_ERR_PORT;
    }
    registry[free_slot] = p;
    return J288_OK;
}

void j288_stm32_deinit(j288_stm32_t *p)
{
    for (size_t i = 0; i < J288_STM32_MAX_BUSES; i++) {
        if ((p != NULL) && (registry[i] == p)) {
            registry[i] = NULL;
            if (p->cfg.htim != NULL) {
                __HAL_TIM_DISABLE_IT(p->cfg.htim, channel_it(p->cfg.tim_channel));
            }
            /* A command still on the wire is cut short rather than left to finish after
             * the transceiver has been released. */
            (void)HAL_UART_AbortTransmit(p->cfg.huart);
            (void)HAL_UART_AbortReceive(p->cfg.huart);
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

/* ---- callbacks -------------------------------------------------------------------------- */

bool j288_stm32_on_tx_cplt(UART_HandleTypeDef *huart)
{
    j288_stm32_t *p = find_uart(huart);
    if (p == NULL) {
        return false;
    }
    /* TxCplt comes on the UART's transmission-complete flag: the stop bit of the last byte
     * is out, so the bus may turn the line around now (it calls set_dir and start_rx). */
    j288_bus_on_tx_done(&p->bus);
    return true;
}

/* Hand the bus the bytes at [from, to) of the receive buffer. */
static void rx_deliver(j288_stm32_t *p, uint16_t from, uint16_t to)
{
    cache_invalidate(p->cfg.dma->rx, J288_STM32_RX_BUF_SIZE);
    j288_bus_on_rx(&p->bus, &p->cfg.dma->rx[from], (size_t)(to - from));
    p->stats.rx_bytes += (uint32_t)(to - from);
}

/* ReceiveToIdle reports the fill level of the buffer, not a delta: half-transfer, idle and
 * full events each give the position reached in the buffer so far.
 * Normal-mode stream: the reception ends at an idle line or a full buffer (the HAL's RxState
 * is then no longer BUSY_RX) and is re-armed at once in receive direction; a byte arriving
 * during that re-arm (a few microseconds after the idle flag) is lost, and its reply is then
 * TRUNCATED at the deadline.
 * Circular-mode stream (recommended): the reception never ends, an idle line only reports
 * the position, and the buffer wraps after a full event; a pause inside a reply loses
 * nothing. Either way an idle line never ends the transaction (j288_bus_on_rx_idle is a
 * no-op): the bus keeps a frame in progress until the deadline. */
bool j288_stm32_on_rx_event(UART_HandleTypeDef *huart, uint16_t size)
{
    j288_stm32_t *p = find_uart(huart);
    uint16_t pos;
    bool ended;

    if (p == NULL) {
        return false;
    }
    p->stats.rx_events++;
    ended = huart->RxState != HAL_UART_STATE_BUSY_RX;
    pos = p->rx_pos;
    if (size > J288_STM32_RX_BUF_SIZE) {
        size = (uint16_t)J288_STM32_RX_BUF_SIZE; /* never trust a count beyond the buffer */
    }
    if (size < pos) { /* circular: wrapped without a full event (a missed interrupt) */
        rx_deliver(p, pos, (uint16_t)J288_STM32_RX_BUF_SIZE);
        pos = 0u;
    }
    if (size > pos) {
        rx_deliver(p, pos, size);
    }
    p->rx_pos = (size < J288_STM32_RX_BUF_SIZE) ? size : 0u; /* full: a circular stream wraps */
    if (ended) {
        if (size < J288_STM32_RX_BUF_SIZE) {
            j288_bus_on_rx_idle(&p->bus);
        }
        if (p->dir == (uint8_t)J288_DIR_RX) {
            rx_arm(p);
        }
    }
    return true;
}

static uint32_t line_flags(uint32_t hal_error)
{
    uint32_t f = 0u;
    f |= ((hal_error & HAL_UART_ERROR_PE) != 0u) ? J288_LINE_PARITY : 0u;
    f |= ((hal_error & HAL_UART_ERROR_NE) != 0u) ? J288_LINE_NOISE : 0u;
    f |= ((hal_error & HAL_UART_ERROR_FE) != 0u) ? J288_LINE_FRAMING : 0u;
    f |= ((hal_error & HAL_UART_ERROR_ORE) != 0u) ? J288_LINE_OVERRUN : 0u;
    f |= ((hal_error & HAL_UART_ERROR_DMA) != 0u) ? J288_LINE_DMA : 0u;
    return (f != 0u) ? f : J288_LINE_NOISE; /* an error without a known bit is still one */
}

/* In DMA mode the HAL treats receive errors as blocking: it has aborted the reception before
 * this callback, and the bytes of the broken frame are not delivered. Report the error, then
 * listen again if we are in receive direction. */
bool j288_stm32_on_error(UART_HandleTypeDef *huart)
{
    j288_stm32_t *p = find_uart(huart);
    if (p == NULL) {
        return false;
    }
    p->stats.line_errors++;
    j288_bus_on_error(&p->bus, line_flags(huart->ErrorCode));
    if ((p->dir == (uint8_t)J288_DIR_RX) && (huart->RxState != HAL_UART_STATE_BUSY_RX)) {
        rx_arm(p);
    }
    return true;
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
