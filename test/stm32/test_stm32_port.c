/*
 * The STM32 HAL port driven through full transactions with the real bus engine, against the
 * fake HAL (test/stm32/fake_hal.c). The test plays the application (it defines the HAL's weak
 * callbacks and forwards them to the port, as a CubeMX project does) and the hardware (it
 * completes transmits, delivers bytes, idles the line, raises errors, fires the timer).
 * Built with J288_STM32_DCACHE=1 and J288_STM32_RX_BUF_SIZE=32 so that the cache maintenance
 * is exercised and a 26-byte reply crosses the half-transfer point.
 */
#include "unity.h"

#include <stdio.h>
#include <string.h>

#include "fake_hal.h"
#include "j288/j288.h"
#include "j288_stm32.h"
#include "worked_cmd.h"

/* ---- the application side: HAL callbacks forwarded to the port ------------------------- */

void HAL_UART_TxCpltCallback(UART_HandleTypeDef *huart) { (void)j288_stm32_on_tx_cplt(huart); }
void HAL_UARTEx_RxEventCallback(UART_HandleTypeDef *huart, uint16_t Size)
{
    (void)j288_stm32_on_rx_event(huart, Size);
}
void HAL_UART_ErrorCallback(UART_HandleTypeDef *huart) { (void)j288_stm32_on_error(huart); }
void HAL_TIM_OC_DelayElapsedCallback(TIM_HandleTypeDef *htim) { (void)j288_stm32_on_timer(htim); }

/* ---- fixtures ------------------------------------------------------------------------- */

/* The spec's worked frames (bytes from the independent generator). */
static const uint8_t k_cmd_foc3[J288_CMD_LEN] = {0xfe, 0xee, 0x93, 0x00, 0x00, 0x00, 0x00,
                                                 0x00, 0x5f, 0x14, 0x00, 0x00, 0x00, 0x05,
                                                 0x00, 0x32, 0xa6, 0x4b, 0x30, 0x3f};
static const uint8_t k_reply3[J288_REPLY_LEN] = {
    0xfc, 0xee, 0x13, 0x24, 0x29, 0x30, 0x00, 0x05, 0xd7, 0xff, 0x5f, 0x14, 0x00,
    0x00, 0x00, 0x00, 0x00, 0x00, 0xe8, 0x03, 0x00, 0x00, 0x49, 0xc2, 0x3b, 0xee};
/* The emergency stop: broadcast lock, watchdog bit 0 (id 15 | status 0 << 4 | 0 << 7). */
static const uint8_t k_lock_broadcast_head[3] = {0xfe, 0xee, 0x0f};

static USART_TypeDef usart1_regs, usart2_regs;
static UART_HandleTypeDef huart1, huart2, huart_other;
static DMA_HandleTypeDef hdma1_tx, hdma1_rx, hdma2_tx, hdma2_rx;
static TIM_TypeDef tim2_regs;
static TIM_HandleTypeDef htim2;
static CRC_TypeDef crc_regs;
static CRC_HandleTypeDef hcrc;
static GPIO_TypeDef gpioa;
#define DE_PIN ((uint16_t)0x0100u)

J288_STM32_DMA_BUFFER(dma1);
J288_STM32_DMA_BUFFER(dma2);
static j288_stm32_t port1, port2;

static uint32_t fake_now;
static uint32_t clock_us(void) { return fake_now; }

static int done_count;
static j288_txn_t last_txn;
static void on_done(void *user, const j288_txn_t *txn)
{
    (void)user;
    done_count++;
    last_txn = *txn;
}

static j288_stm32_config_t base_config(UART_HandleTypeDef *h, j288_stm32_dma_t *dma)
{
    j288_stm32_config_t c;
    memset(&c, 0, sizeof c);
    c.huart = h;
    c.dma = dma;
    c.now_us = clock_us;
    c.hcrc = &hcrc;
    return c;
}

void setUp(void)
{
    fake_hal_reset();
    memset(&huart1, 0, sizeof huart1);
    memset(&huart2, 0, sizeof huart2);
    memset(&huart_other, 0, sizeof huart_other);
    memset(&tim2_regs, 0, sizeof tim2_regs);
    memset(&htim2, 0, sizeof htim2);
    huart1.Instance = &usart1_regs;
    huart2.Instance = &usart2_regs;
    huart_other.Instance = &usart2_regs;
    huart1.hdmatx = &hdma1_tx;
    huart1.hdmarx = &hdma1_rx;
    huart2.hdmatx = &hdma2_tx;
    huart2.hdmarx = &hdma2_rx;
    (void)HAL_HalfDuplex_Init(&huart1);
    (void)HAL_HalfDuplex_Init(&huart2);
    (void)HAL_HalfDuplex_Init(&huart_other);
    htim2.Instance = &tim2_regs;
    tim2_regs.ARR = 0xFFFFFFFFu;
    memset(&hcrc, 0, sizeof hcrc);
    hcrc.Instance = &crc_regs;
    hcrc.InputDataFormat = CRC_INPUTDATA_FORMAT_WORDS; /* what CubeMX sets: the reset unit */
    fake_now = 1000u;
    done_count = 0;
    memset(&last_txn, 0, sizeof last_txn);
}

void tearDown(void)
{
    j288_stm32_deinit(&port1);
    j288_stm32_deinit(&port2);
}

static void init_port1(const j288_bus_config_t *bus_cfg, bool timer, bool de)
{
    j288_stm32_config_t c = base_config(&huart1, &dma1);
    if (timer) {
        c.htim = &htim2;
        c.tim_channel = TIM_CHANNEL_1;
    }
    if (de) {
        c.de_port = &gpioa;
        c.de_pin = DE_PIN;
    }
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_stm32_init(&port1, &c, bus_cfg));
}

/* Submit foc3 on port1 and complete its transmit. */
static void send_foc3(void)
{
    j288_cmd_raw_t cmd = worked_cmd();
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_submit(j288_stm32_bus(&port1), &cmd, fake_now, on_done, NULL));
    j288_bus_poll(j288_stm32_bus(&port1), fake_now);
    TEST_ASSERT_TRUE(fake_hal_tx_busy(&huart1));
    fake_now += 40u;
    TEST_ASSERT_TRUE(fake_hal_tx_complete(&huart1));
}

static void poll1(void) { j288_bus_poll(j288_stm32_bus(&port1), fake_now); }

/* ---- init ----------------------------------------------------------------------------- */

static void test_init_rejects_bad_config(void)
{
    j288_stm32_config_t c = base_config(&huart1, &dma1);
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_stm32_init(NULL, &c, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_stm32_init(&port1, NULL, NULL));
    c.dma = NULL;
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_stm32_init(&port1, &c, NULL));
    c = base_config(NULL, &dma1);
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_stm32_init(&port1, &c, NULL));

    /* no tick at all: neither now_us nor a 32-bit timer */
    c = base_config(&huart1, &dma1);
    c.now_us = NULL;
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, j288_stm32_init(&port1, &c, NULL));
    c.htim = &htim2;
    c.tim_channel = TIM_CHANNEL_1;
    tim2_regs.ARR = 0xFFFFu; /* a 16-bit timer cannot be the tick */
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, j288_stm32_init(&port1, &c, NULL));
    tim2_regs.ARR = 0xFFFFFFFFu;
    c.tim_channel = 3u; /* not a TIM_CHANNEL_n */
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, j288_stm32_init(&port1, &c, NULL));
    c.tim_channel = TIM_CHANNEL_2;
    tim2_regs.CNT = 777u;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_stm32_init(&port1, &c, NULL));
    TEST_ASSERT_EQUAL_UINT32(777u, j288_stm32_now_us(&port1)); /* the timer is the tick */

    /* one bus per UART */
    c = base_config(&huart1, &dma2);
    TEST_ASSERT_EQUAL_INT(J288_ERR_BUSY, j288_stm32_init(&port2, &c, NULL));
}

static void test_init_leaves_line_receiving_de_inactive(void)
{
    init_port1(NULL, false, true);
    TEST_ASSERT_TRUE(fake_hal_receiver_on(&huart1));
    TEST_ASSERT_FALSE(fake_hal_transmitter_on(&huart1));
    TEST_ASSERT_EQUAL_INT(0, fake_hal_gpio_level(&gpioa, DE_PIN));
}

static void test_registry_is_bounded(void)
{
    static j288_stm32_t extra[J288_STM32_MAX_BUSES + 1u];
    static UART_HandleTypeDef uarts[J288_STM32_MAX_BUSES + 1u];
    static j288_stm32_dma_t J288_STM32_DMA_ALIGN bufs[J288_STM32_MAX_BUSES + 1u];
    static DMA_HandleTypeDef streams[2u * (J288_STM32_MAX_BUSES + 1u)];
    for (size_t i = 0; i <= J288_STM32_MAX_BUSES; i++) {
        j288_stm32_config_t c = base_config(&uarts[i], &bufs[i]);
        uarts[i].Instance = &usart1_regs;
        uarts[i].hdmatx = &streams[2u * i];
        uarts[i].hdmarx = &streams[2u * i + 1u];
        (void)HAL_HalfDuplex_Init(&uarts[i]);
        TEST_ASSERT_EQUAL_INT(i < J288_STM32_MAX_BUSES ? J288_OK : J288_ERR_BUSY,
                              j288_stm32_init(&extra[i], &c, NULL));
    }
    for (size_t i = 0; i <= J288_STM32_MAX_BUSES; i++) {
        j288_stm32_deinit(&extra[i]);
    }
    TEST_ASSERT_FALSE(j288_stm32_on_tx_cplt(&uarts[0]));
}

/* ---- transactions ---------------------------------------------------------------------- */

static void test_full_transaction_call_order_and_bytes(void)
{
    size_t len = 0;
    long abort_i, tx_i, de_on, clean_i, dma_i, de_off, rx_i, arm_i;
    init_port1(NULL, false, true);
    fake_hal_log_clear();

    j288_cmd_raw_t cmd = worked_cmd();
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_submit(j288_stm32_bus(&port1), &cmd, fake_now, on_done, NULL));
    poll1();

    /* the worked frame, byte for byte, sent from the DMA buffer */
    const uint8_t *sent = fake_hal_tx_data(&huart1, &len);
    TEST_ASSERT_EQUAL_UINT32((uint32_t)(J288_CMD_LEN), (uint32_t)len);
    TEST_ASSERT_EQUAL_HEX8_ARRAY(k_cmd_foc3, sent, J288_CMD_LEN);
    TEST_ASSERT_TRUE(huart1.pTxBuffPtr == dma1.tx);
    TEST_ASSERT_TRUE(fake_hal_transmitter_on(&huart1));
    TEST_ASSERT_FALSE(fake_hal_receiver_on(&huart1));
    TEST_ASSERT_EQUAL_INT(1, fake_hal_gpio_level(&gpioa, DE_PIN));

    /* abort stale reception -> transmitter on -> DE -> cache clean -> DMA */
    abort_i = fake_hal_log_find(FAKE_ABORT_RECEIVE, &huart1, 0);
    tx_i = fake_hal_log_find(FAKE_HALFDUPLEX_TX, &huart1, 0);
    de_on = fake_hal_log_find(FAKE_GPIO_WRITE, &gpioa, 0);
    clean_i = fake_hal_log_find(FAKE_CACHE_CLEAN, dma1.tx, 0);
    dma_i = fake_hal_log_find(FAKE_TRANSMIT_DMA, &huart1, 0);
    TEST_ASSERT_TRUE(abort_i >= 0 && abort_i < tx_i);
    TEST_ASSERT_TRUE(tx_i < de_on && de_on < dma_i);
    TEST_ASSERT_TRUE(clean_i >= 0 && clean_i < dma_i);
    TEST_ASSERT_EQUAL_UINT32(0u, fake_hal_log_at((size_t)clean_i)->arg % J288_STM32_DCACHE_LINE);
    TEST_ASSERT_EQUAL_INT(-1, fake_hal_log_find(FAKE_RECEIVE_TO_IDLE_DMA, &huart1, 0));

    /* transmit complete: DE off, receiver on, reception armed into the DMA buffer */
    fake_now += 40u;
    TEST_ASSERT_TRUE(fake_hal_tx_complete(&huart1));
    de_off = fake_hal_log_find(FAKE_GPIO_WRITE, &gpioa, (size_t)dma_i);
    rx_i = fake_hal_log_find(FAKE_HALFDUPLEX_RX, &huart1, (size_t)dma_i);
    arm_i = fake_hal_log_find(FAKE_RECEIVE_TO_IDLE_DMA, &huart1, (size_t)dma_i);
    TEST_ASSERT_TRUE(de_off >= 0 && rx_i >= 0 && arm_i > rx_i);
    TEST_ASSERT_EQUAL_INT(0, fake_hal_gpio_level(&gpioa, DE_PIN));
    TEST_ASSERT_TRUE(fake_hal_rx_armed(&huart1));
    TEST_ASSERT_TRUE(huart1.pRxBuffPtr == dma1.rx);
    TEST_ASSERT_EQUAL_UINT16(J288_STM32_RX_BUF_SIZE, huart1.RxXferSize);

    /* the reply: half-transfer event at 16 bytes, then idle at 26 */
    fake_now += 60u;
    TEST_ASSERT_EQUAL_UINT32((uint32_t)(J288_REPLY_LEN), (uint32_t)fake_hal_rx_bytes(&huart1, k_reply3, J288_REPLY_LEN));
    TEST_ASSERT_TRUE(fake_hal_rx_idle(&huart1));
    TEST_ASSERT_EQUAL_UINT32(2u, j288_stm32_stats(&port1)->rx_events);
    TEST_ASSERT_EQUAL_UINT32(J288_REPLY_LEN, j288_stm32_stats(&port1)->rx_bytes);
    TEST_ASSERT_TRUE(fake_hal_count(FAKE_CACHE_INVALIDATE) >= 2u);
    poll1();
    fake_now += 10u;
    poll1();

    TEST_ASSERT_EQUAL_INT(1, done_count);
    TEST_ASSERT_EQUAL_INT(J288_OK, last_txn.result);
    TEST_ASSERT_EQUAL_UINT8(3u, last_txn.reply.id);
    TEST_ASSERT_EQUAL_INT32(5215, last_txn.reply.pos);
    TEST_ASSERT_EQUAL_INT16(-41, last_txn.reply.speed);
    TEST_ASSERT_EQUAL_UINT16(1000u, last_txn.reply.out_pos);
    /* frames were checked on the CRC unit (command and reply), with the lock released */
    TEST_ASSERT_TRUE(fake_hal_count(FAKE_CRC_CALCULATE) >= 2u);
    TEST_ASSERT_EQUAL_UINT32(0u, fake_hal_primask());
}

static void test_reply_split_by_a_gap_is_heard_whole(void)
{
    init_port1(NULL, false, false);
    send_foc3();
    /* 10 bytes, the line idles (reception ends and is re-armed), then the other 16 */
    TEST_ASSERT_EQUAL_UINT32((uint32_t)(10u), (uint32_t)fake_hal_rx_bytes(&huart1, k_reply3, 10u));
    TEST_ASSERT_TRUE(fake_hal_rx_idle(&huart1));
    TEST_ASSERT_TRUE(fake_hal_rx_armed(&huart1));
    TEST_ASSERT_EQUAL_UINT32((uint32_t)(16u), (uint32_t)fake_hal_rx_bytes(&huart1, &k_reply3[10], 16u));
    TEST_ASSERT_TRUE(fake_hal_rx_idle(&huart1));
    poll1();
    TEST_ASSERT_EQUAL_INT(1, done_count);
    TEST_ASSERT_EQUAL_INT(J288_OK, last_txn.result);
    TEST_ASSERT_EQUAL_INT32(5215, last_txn.reply.pos);
}

static void test_reply_one_byte_per_event(void)
{
    /* an RxEvent per byte (e.g. a tiny buffer): each event's size is a fill level, so the
     * port hands over only the new byte each time */
    init_port1(NULL, false, false);
    send_foc3();
    for (uint16_t i = 0; i < J288_REPLY_LEN; i++) {
        dma1.rx[i] = k_reply3[i];
        huart1.RxState = (i + 1u < J288_REPLY_LEN) ? HAL_UART_STATE_BUSY_RX : HAL_UART_STATE_READY;
        TEST_ASSERT_TRUE(j288_stm32_on_rx_event(&huart1, (uint16_t)(i + 1u)));
    }
    TEST_ASSERT_EQUAL_UINT32(J288_REPLY_LEN, j288_stm32_stats(&port1)->rx_bytes);
    poll1();
    TEST_ASSERT_EQUAL_INT(1, done_count);
    TEST_ASSERT_EQUAL_INT(J288_OK, last_txn.result);
}

static void test_bogus_event_size_is_clamped(void)
{
    init_port1(NULL, false, false);
    send_foc3();
    huart1.RxState = HAL_UART_STATE_READY;
    TEST_ASSERT_TRUE(j288_stm32_on_rx_event(&huart1, 0xFFFFu));
    TEST_ASSERT_EQUAL_UINT32(J288_STM32_RX_BUF_SIZE, j288_stm32_stats(&port1)->rx_bytes);
}

static void test_error_mid_frame_fails_with_line_error(void)
{
    j288_bus_config_t bc;
    memset(&bc, 0, sizeof bc);
    init_port1(&bc, false, false);
    send_foc3();
    TEST_ASSERT_EQUAL_UINT32((uint32_t)(12u), (uint32_t)fake_hal_rx_bytes(&huart1, k_reply3, 12u));
    fake_hal_rx_error(&huart1, HAL_UART_ERROR_FE | HAL_UART_ERROR_NE);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_stm32_stats(&port1)->line_errors);
    TEST_ASSERT_TRUE(fake_hal_rx_armed(&huart1)); /* listening again */
    poll1();
    fake_now += j288_bus_reply_budget_us(j288_stm32_bus(&port1)) + 10u;
    poll1();
    TEST_ASSERT_EQUAL_INT(1, done_count);
    TEST_ASSERT_EQUAL_INT(J288_ERR_LINE, last_txn.result);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(j288_stm32_bus(&port1))->line_errors);
}

static void test_timeout_from_timer_channel(void)
{
    uint32_t budget;
    init_port1(NULL, true, false);
    tim2_regs.CNT = 5000u;
    send_foc3();
    budget = j288_bus_reply_budget_us(j288_stm32_bus(&port1));
    /* the compare channel is armed a deadline ahead of the counter */
    TEST_ASSERT_TRUE((tim2_regs.DIER & TIM_IT_CC1) != 0u);
    TEST_ASSERT_TRUE(tim2_regs.CCR1 > 5000u && tim2_regs.CCR1 <= 5000u + budget + 1u);
    /* another channel's interrupt is not ours */
    TEST_ASSERT_FALSE(fake_hal_tim_fire(&htim2, TIM_CHANNEL_2));
    fake_now += budget + 5u;
    TEST_ASSERT_TRUE(fake_hal_tim_fire(&htim2, TIM_CHANNEL_1));
    TEST_ASSERT_EQUAL_UINT32(1u, j288_stm32_stats(&port1)->timer_events);
    poll1();
    TEST_ASSERT_EQUAL_INT(1, done_count);
    TEST_ASSERT_EQUAL_INT(J288_ERR_TIMEOUT, last_txn.result);
}

static void test_timer_on_16_bit_counter_wraps(void)
{
    init_port1(NULL, true, false);
    tim2_regs.ARR = 0xFFFFu;
    tim2_regs.CNT = 0xFFF0u;
    send_foc3();
    TEST_ASSERT_TRUE((tim2_regs.DIER & TIM_IT_CC1) != 0u);
    TEST_ASSERT_TRUE(tim2_regs.CCR1 < 0x0200u); /* wrapped past 0xFFFF, not beyond ARR */
}

/* A 16-bit timer cannot hold a reply budget over 65.5 ms: the compare goes ARR ticks ahead,
 * fires early, and the port must re-arm it for the rest instead of waking the bus (which
 * would not re-arm it, and with advance_in_isr and no polling the transaction would never
 * end). */
static void test_16_bit_timer_long_budget_rearms_until_deadline(void)
{
    j288_bus_config_t bc;
    uint32_t start, budget;
    memset(&bc, 0, sizeof bc);
    bc.advance_in_isr = true;
    bc.margin_us = 100000u;
    init_port1(&bc, true, false);
    tim2_regs.ARR = 0xFFFFu;
    tim2_regs.CNT = 0x1234u;
    start = fake_now;
    send_foc3();
    budget = j288_bus_reply_budget_us(j288_stm32_bus(&port1));
    TEST_ASSERT_TRUE(budget > 0xFFFFu);
    TEST_ASSERT_EQUAL_HEX32(0x1233u, tim2_regs.CCR1); /* capped at a full period */

    /* the capped compare fires after 65.5 ms: early, so re-armed for the remainder */
    fake_now = start + 0xFFFFu;
    tim2_regs.CNT = 0x1233u;
    TEST_ASSERT_TRUE(fake_hal_tim_fire(&htim2, TIM_CHANNEL_1));
    TEST_ASSERT_EQUAL_INT(0, done_count);
    TEST_ASSERT_TRUE((tim2_regs.DIER & TIM_IT_CC1) != 0u);
    TEST_ASSERT_EQUAL_HEX32((0x1233u + (start + budget - fake_now)) & 0xFFFFu, tim2_regs.CCR1);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_stm32_stats(&port1)->timer_rearms);

    /* no polling at all: the re-armed compare alone ends the transaction */
    fake_now += 1000000u;
    TEST_ASSERT_TRUE(fake_hal_tim_fire(&htim2, TIM_CHANNEL_1));
    TEST_ASSERT_EQUAL_INT(1, done_count);
    TEST_ASSERT_EQUAL_INT(J288_ERR_TIMEOUT, last_txn.result);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_stm32_stats(&port1)->timer_rearms);
}

static void test_advance_in_isr_timeout_ends_in_timer_interrupt(void)
{
    j288_bus_config_t bc;
    memset(&bc, 0, sizeof bc);
    bc.advance_in_isr = true;
    init_port1(&bc, true, false);
    send_foc3();
    fake_now += j288_bus_reply_budget_us(j288_stm32_bus(&port1)) + 5u;
    TEST_ASSERT_TRUE(fake_hal_tim_fire(&htim2, TIM_CHANNEL_1));
    TEST_ASSERT_EQUAL_INT(1, done_count);
    TEST_ASSERT_EQUAL_INT(J288_ERR_TIMEOUT, last_txn.result);
}

static void test_transmit_dma_failure_is_a_port_error(void)
{
    j288_cmd_raw_t cmd = worked_cmd();
    init_port1(NULL, false, false);
    fake_hal_fail_next(FAKE_TRANSMIT_DMA);
    (void)j288_bus_submit(j288_stm32_bus(&port1), &cmd, fake_now, on_done, NULL);
    poll1();
    fake_now += 1000u;
    poll1();
    TEST_ASSERT_EQUAL_INT(1, done_count);
    TEST_ASSERT_EQUAL_INT(J288_ERR_PORT, last_txn.result);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_stm32_stats(&port1)->hal_failures);
}

static void test_receive_arm_failure_is_reported(void)
{
    init_port1(NULL, false, false);
    fake_hal_fail_next(FAKE_RECEIVE_TO_IDLE_DMA);
    send_foc3();
    TEST_ASSERT_EQUAL_UINT32(1u, j288_stm32_stats(&port1)->hal_failures);
    poll1();
    fake_now += j288_bus_reply_budget_us(j288_stm32_bus(&port1)) + 10u;
    poll1();
    TEST_ASSERT_EQUAL_INT(1, done_count);
    TEST_ASSERT_EQUAL_INT(J288_ERR_LINE, last_txn.result);
}

static void test_bytes_during_transmit_are_not_heard(void)
{
    j288_cmd_raw_t cmd = worked_cmd();
    init_port1(NULL, false, false);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_submit(j288_stm32_bus(&port1), &cmd, fake_now, on_done, NULL));
    poll1();
    /* single-wire: the receiver is off while we transmit */
    TEST_ASSERT_EQUAL_UINT32((uint32_t)(0u), (uint32_t)fake_hal_rx_bytes(&huart1, k_reply3, J288_REPLY_LEN));
}

static void test_two_buses_route_by_handle(void)
{
    j288_cmd_raw_t cmd = worked_cmd();
    j288_stm32_config_t c2 = base_config(&huart2, &dma2);
    init_port1(NULL, false, false);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_stm32_init(&port2, &c2, NULL));

    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_submit(j288_stm32_bus(&port1), &cmd, fake_now, on_done, NULL));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_submit(j288_stm32_bus(&port2), &cmd, fake_now, on_done, NULL));
    j288_bus_poll(j288_stm32_bus(&port1), fake_now);
    j288_bus_poll(j288_stm32_bus(&port2), fake_now);
    TEST_ASSERT_TRUE(huart2.pTxBuffPtr == dma2.tx);
    fake_now += 40u;
    TEST_ASSERT_TRUE(fake_hal_tx_complete(&huart2));
    TEST_ASSERT_TRUE(fake_hal_tx_complete(&huart1));
    TEST_ASSERT_TRUE(huart2.pRxBuffPtr == dma2.rx);

    /* bus 2 gets the reply; bus 1 gets nothing and times out */
    (void)fake_hal_rx_bytes(&huart2, k_reply3, J288_REPLY_LEN);
    TEST_ASSERT_TRUE(fake_hal_rx_idle(&huart2));
    j288_bus_poll(j288_stm32_bus(&port2), fake_now);
    TEST_ASSERT_EQUAL_INT(1, done_count);
    TEST_ASSERT_EQUAL_INT(J288_OK, last_txn.result);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_stm32_stats(&port1)->rx_bytes);
    fake_now += j288_bus_reply_budget_us(j288_stm32_bus(&port1)) + 10u;
    poll1();
    TEST_ASSERT_EQUAL_INT(2, done_count);
    TEST_ASSERT_EQUAL_INT(J288_ERR_TIMEOUT, last_txn.result);

    /* a UART that is no bus of ours is left alone */
    TEST_ASSERT_FALSE(j288_stm32_on_tx_cplt(&huart_other));
    TEST_ASSERT_FALSE(j288_stm32_on_rx_event(&huart_other, 3u));
    TEST_ASSERT_FALSE(j288_stm32_on_error(&huart_other));
    TEST_ASSERT_FALSE(j288_stm32_on_tx_cplt(NULL));
}

static void test_estop_broadcasts_lock_without_waiting(void)
{
    size_t len = 0;
    init_port1(NULL, false, false);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_estop(j288_stm32_bus(&port1), fake_now));
    poll1();
    const uint8_t *sent = fake_hal_tx_data(&huart1, &len);
    TEST_ASSERT_EQUAL_UINT32((uint32_t)(J288_CMD_LEN), (uint32_t)len);
    TEST_ASSERT_EQUAL_HEX8_ARRAY(k_lock_broadcast_head, sent, 3u);
    fake_now += 40u;
    TEST_ASSERT_TRUE(fake_hal_tx_complete(&huart1));
    for (int i = 0; i < 3; i++) {
        fake_now += 10u;
        poll1();
    }
    TEST_ASSERT_TRUE(j288_bus_is_idle(j288_stm32_bus(&port1)));
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(j288_stm32_bus(&port1))->estops);
}

static void test_scheduler_sweep_over_port(void)
{
    static j288_sched_t sched;
    j288_cmd_raw_t cmd = worked_cmd();
    init_port1(NULL, false, false);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_init(&sched, j288_stm32_bus(&port1), NULL));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_enable(&sched, 3u, true));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_set_cmd(&sched, &cmd));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_sched_start_sweep(&sched, fake_now));
    j288_sched_poll(&sched, fake_now);
    TEST_ASSERT_EQUAL_HEX8_ARRAY(k_cmd_foc3, fake_hal_tx_data(&huart1, NULL), J288_CMD_LEN);
    fake_now += 40u;
    TEST_ASSERT_TRUE(fake_hal_tx_complete(&huart1));
    (void)fake_hal_rx_bytes(&huart1, k_reply3, J288_REPLY_LEN);
    TEST_ASSERT_TRUE(fake_hal_rx_idle(&huart1));
    for (int i = 0; i < 5; i++) {
        fake_now += 5u;
        j288_sched_poll(&sched, fake_now);
    }
    TEST_ASSERT_EQUAL_UINT32(1u, j288_sched_sweeps(&sched));
    TEST_ASSERT_TRUE(j288_sched_slot(&sched, 3u)->has_reply);
    TEST_ASSERT_EQUAL_INT32(5215, j288_sched_slot(&sched, 3u)->reply.pos);
}

/* ---- CRC unit --------------------------------------------------------------------------- */

static void test_hw_crc_matches_worked_frames_at_any_alignment(void)
{
    uint8_t buf[J288_REPLY_LEN + 3u];
    for (size_t off = 0; off < 4u; off++) {
        memcpy(&buf[off], k_reply3, J288_REPLY_LEN);
        /* reply: bytes 2..21 (5 words), CRC at 22 */
        TEST_ASSERT_EQUAL_HEX32(j288_get_u32le(&k_reply3[22]), j288_stm32_crc32(&hcrc, &buf[off + 2u], 5u));
        memcpy(&buf[off], k_cmd_foc3, J288_CMD_LEN);
        TEST_ASSERT_EQUAL_HEX32(j288_get_u32le(&k_cmd_foc3[16]), j288_stm32_crc32(&hcrc, &buf[off], 4u));
    }
    TEST_ASSERT_EQUAL_UINT32(0u, fake_hal_primask());
    TEST_ASSERT_EQUAL_UINT(8u, fake_hal_irq_disables()); /* locked once per CRC */
}

static void test_hw_crc_long_input_chunks_and_matches_software(void)
{
    uint8_t data[4u * 21u];
    for (size_t i = 0; i < sizeof data; i++) {
        data[i] = (uint8_t)(i * 37u + 5u);
    }
    TEST_ASSERT_EQUAL_HEX32(j288_crc32_update_bitwise(J288_CRC32_INIT, data, 21u),
                            j288_stm32_crc32(&hcrc, data, 21u));
    TEST_ASSERT_EQUAL_UINT(1u, fake_hal_count(FAKE_CRC_CALCULATE));
    TEST_ASSERT_EQUAL_UINT(2u, fake_hal_count(FAKE_CRC_ACCUMULATE));
    TEST_ASSERT_EQUAL_HEX32(J288_CRC32_INIT, j288_stm32_crc32(&hcrc, NULL, 0u));
}

static void test_default_crc_falls_back_to_software_until_attached(void)
{
    j288_stm32_crc_attach(NULL);
    TEST_ASSERT_EQUAL_HEX32(j288_get_u32le(&k_cmd_foc3[16]), j288_stm32_crc32_default(k_cmd_foc3, 4u));
    TEST_ASSERT_EQUAL_UINT(0u, fake_hal_count(FAKE_CRC_CALCULATE));
    j288_stm32_crc_attach(&hcrc);
    TEST_ASSERT_EQUAL_HEX32(j288_get_u32le(&k_cmd_foc3[16]), j288_stm32_crc32_default(k_cmd_foc3, 4u));
    TEST_ASSERT_EQUAL_UINT(1u, fake_hal_count(FAKE_CRC_CALCULATE));
    j288_stm32_crc_attach(NULL);
}

static void test_bus_lock_masks_and_restores(void)
{
    init_port1(NULL, false, false);
    /* the port's lock pair: masked inside, the previous state restored after */
    j288_stm32_bus(&port1)->port->lock(&port1);
    TEST_ASSERT_EQUAL_UINT32(1u, fake_hal_primask());
    j288_stm32_bus(&port1)->port->unlock(&port1);
    TEST_ASSERT_EQUAL_UINT32(0u, fake_hal_primask());
}


/* ---- silicon races and HAL failures ----------------------------------------------------- */

/* The timer is the tick (now_us NULL), so that the counter the test runs is the port's clock. */
static void init_port1_timer_tick(const j288_bus_config_t *bus_cfg)
{
    j288_stm32_config_t c = base_config(&huart1, &dma1);
    c.now_us = NULL;
    c.htim = &htim2;
    c.tim_channel = TIM_CHANNEL_1;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_stm32_init(&port1, &c, bus_cfg));
}

static uint32_t timeouts_delivered(void)
{
    const j288_stm32_stats_t *st = j288_stm32_stats(&port1);
    return st->timer_events - st->timer_rearms;
}

/* Arming a deadline a few ticks away while the counter runs: wherever between two register
 * accesses the counter passes the new compare value, the timeout must still come, and soon
 * (not one timer period later, which is 71 minutes on a 32-bit timer at 1 MHz). */
static void test_timer_arm_races_the_counter_at_every_access(void)
{
    const j288_port_t *ops;
    init_port1_timer_tick(NULL);
    ops = j288_stm32_bus(&port1)->port;
    for (uint32_t delay = 1u; delay <= 3u; delay++) {
        for (uint32_t run = 1u; run <= 4u; run++) {
            for (unsigned access = 0u; access < 24u; access++) {
                char msg[64];
                uint32_t before = timeouts_delivered();
                tim2_regs.CNT = 5000u;
                tim2_regs.SR = 0u;
                fake_hal_tim_advance_at(&htim2, access, run);
                ops->arm_timeout(&port1, 5000u + delay);
                (void)fake_hal_tim_run(&htim2, delay + run + 2u);
                snprintf(msg, sizeof msg, "delay %u, %u ticks before access %u", (unsigned)delay,
                         (unsigned)run, access);
                TEST_ASSERT_EQUAL_UINT32_MESSAGE(before + 1u, timeouts_delivered(), msg);
            }
        }
    }
}

static void test_timer_deadline_already_passed_fires_at_once(void)
{
    init_port1_timer_tick(NULL);
    tim2_regs.CNT = 5000u;
    j288_stm32_bus(&port1)->port->arm_timeout(&port1, 4990u);
    TEST_ASSERT_EQUAL_UINT(1u, fake_hal_tim_run(&htim2, 0u));
    TEST_ASSERT_EQUAL_UINT32(1u, timeouts_delivered());
}

/* A CRC handle in another configuration would fail every frame as "bad CRC" with no hint. */
static void test_init_rejects_crc_unit_not_in_the_servo_configuration(void)
{
    j288_stm32_config_t c = base_config(&huart1, &dma1);
    static const uint32_t bad_formats[] = {CRC_INPUTDATA_FORMAT_UNDEFINED, CRC_INPUTDATA_FORMAT_BYTES,
                                           CRC_INPUTDATA_FORMAT_HALFWORDS};
    for (size_t i = 0; i < sizeof bad_formats / sizeof bad_formats[0]; i++) {
        hcrc.InputDataFormat = bad_formats[i];
        TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, j288_stm32_init(&port1, &c, NULL));
    }
    hcrc.InputDataFormat = CRC_INPUTDATA_FORMAT_WORDS;
    hcrc.Init.OutputDataInversionMode = CRC_OUTPUTDATA_INVERSION_ENABLE;
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, j288_stm32_init(&port1, &c, NULL));
    hcrc.Init.OutputDataInversionMode = CRC_OUTPUTDATA_INVERSION_DISABLE;
    hcrc.Init.InputDataInversionMode = CRC_INPUTDATA_INVERSION_BYTE;
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, j288_stm32_init(&port1, &c, NULL));
    hcrc.Init.InputDataInversionMode = CRC_INPUTDATA_INVERSION_NONE;
    hcrc.Init.DefaultPolynomialUse = DEFAULT_POLYNOMIAL_DISABLE;
    hcrc.Init.GeneratingPolynomial = 0x1EDC6F41u; /* CRC-32C */
    hcrc.Init.CRCLength = CRC_POLYLENGTH_32B;
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, j288_stm32_init(&port1, &c, NULL));
    hcrc.Init.DefaultPolynomialUse = DEFAULT_POLYNOMIAL_ENABLE;
    hcrc.Init.DefaultInitValueUse = DEFAULT_INIT_VALUE_DISABLE;
    hcrc.Init.InitValue = 0u;
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, j288_stm32_init(&port1, &c, NULL));

    /* the same CRC spelled out instead of by default is fine */
    hcrc.Init.InitValue = 0xFFFFFFFFu;
    hcrc.Init.DefaultPolynomialUse = DEFAULT_POLYNOMIAL_DISABLE;
    hcrc.Init.GeneratingPolynomial = 0x04C11DB7u;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_stm32_init(&port1, &c, NULL));
}

/* The handle may be right and the unit still not: e.g. its clock never enabled (the F4's
 * handle has no fields to check). A known-answer check at init catches it. */
static void test_init_rejects_crc_unit_that_computes_wrong(void)
{
    j288_stm32_config_t c = base_config(&huart1, &dma1);
    fake_hal_crc_unclocked(true);
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, j288_stm32_init(&port1, &c, NULL));
    fake_hal_crc_unclocked(false);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_stm32_init(&port1, &c, NULL));
}

static void test_init_fails_when_the_line_cannot_receive(void)
{
    j288_stm32_config_t c = base_config(&huart1, &dma1);
    fake_hal_fail_next(FAKE_HALFDUPLEX_RX);
    TEST_ASSERT_EQUAL_INT(J288_ERR_PORT, j288_stm32_init(&port1, &c, NULL));
    TEST_ASSERT_FALSE(j288_stm32_on_tx_cplt(&huart1)); /* not registered */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_stm32_init(&port1, &c, NULL));
}

static void test_init_rejects_uart_without_dma_streams(void)
{
    j288_stm32_config_t c = base_config(&huart1, &dma1);
    huart1.hdmarx = NULL;
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, j288_stm32_init(&port1, &c, NULL));
    huart1.hdmarx = &hdma1_rx;
    huart1.hdmatx = NULL;
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, j288_stm32_init(&port1, &c, NULL));
}

/* Reply to the transaction in flight on port1 and finish it. */
static void reply_and_finish(void)
{
    TEST_ASSERT_EQUAL_UINT32((uint32_t)J288_REPLY_LEN,
                             (uint32_t)fake_hal_rx_bytes(&huart1, k_reply3, J288_REPLY_LEN));
    TEST_ASSERT_TRUE(fake_hal_rx_idle(&huart1));
    poll1();
    fake_now += 10u;
    poll1();
}

/* Past a failed attempt and its guard. */
static void wait_out_failure(void)
{
    fake_now += 3u * j288_bus_reply_budget_us(j288_stm32_bus(&port1)) + 10u;
    poll1();
    fake_now += 3u * j288_bus_reply_budget_us(j288_stm32_bus(&port1)) + 10u;
    poll1();
}

/* A transmit whose completion never comes (DMA stalled) fails its transaction; the next one
 * must not find the UART still busy transmitting. */
static void test_stalled_transmit_is_aborted_and_the_next_transaction_works(void)
{
    j288_cmd_raw_t cmd = worked_cmd();
    init_port1(NULL, false, false);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_submit(j288_stm32_bus(&port1), &cmd, fake_now, on_done, NULL));
    poll1();
    TEST_ASSERT_TRUE(fake_hal_tx_busy(&huart1)); /* ... and never completes */
    wait_out_failure();
    TEST_ASSERT_EQUAL_INT(1, done_count);
    TEST_ASSERT_TRUE(last_txn.result != J288_OK);

    send_foc3();
    reply_and_finish();
    TEST_ASSERT_EQUAL_INT(2, done_count);
    TEST_ASSERT_EQUAL_INT(J288_OK, last_txn.result);
}

/* The F4 HAL returns HAL_OK from HAL_UART_Transmit_DMA even when the stream did not start
 * (its handle left busy): the port must not wait for a transmit that never began. */
static void test_transmit_stream_left_busy_is_recovered(void)
{
    init_port1(NULL, false, false);
    hdma1_tx.State = HAL_DMA_STATE_BUSY;
    send_foc3(); /* asserts that the frame went out */
    reply_and_finish();
    TEST_ASSERT_EQUAL_INT(1, done_count);
    TEST_ASSERT_EQUAL_INT(J288_OK, last_txn.result);
}

static void test_receive_stream_left_busy_is_recovered(void)
{
    j288_cmd_raw_t cmd = worked_cmd();
    init_port1(NULL, false, false);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_submit(j288_stm32_bus(&port1), &cmd, fake_now, on_done, NULL));
    poll1();
    hdma1_rx.State = HAL_DMA_STATE_BUSY;
    fake_now += 40u;
    TEST_ASSERT_TRUE(fake_hal_tx_complete(&huart1));
    TEST_ASSERT_TRUE(fake_hal_rx_armed(&huart1));
    reply_and_finish();
    TEST_ASSERT_EQUAL_INT(1, done_count);
    TEST_ASSERT_EQUAL_INT(J288_OK, last_txn.result);
}

/* A HAL failure while turning the line to transmit: nothing is sent, the application sees
 * J288_ERR_PORT, and the next transaction works. */
static void test_turnaround_to_transmit_failure_is_a_port_error(void)
{
    static const fake_hal_fn_t fails[] = {FAKE_HALFDUPLEX_TX, FAKE_ABORT_RECEIVE};
    j288_bus_config_t bc;
    memset(&bc, 0, sizeof bc);
    init_port1(&bc, false, false);
    for (size_t i = 0; i < sizeof fails / sizeof fails[0]; i++) {
        j288_cmd_raw_t cmd = worked_cmd();
        unsigned sent = fake_hal_count(FAKE_TRANSMIT_DMA);
        int before = done_count;
        fake_hal_fail_next(fails[i]);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_submit(j288_stm32_bus(&port1), &cmd, fake_now, on_done, NULL));
        poll1();
        TEST_ASSERT_EQUAL_UINT(sent, fake_hal_count(FAKE_TRANSMIT_DMA));
        wait_out_failure();
        TEST_ASSERT_EQUAL_INT(before + 1, done_count);
        TEST_ASSERT_EQUAL_INT(J288_ERR_PORT, last_txn.result);

        send_foc3();
        reply_and_finish();
        TEST_ASSERT_EQUAL_INT(before + 2, done_count);
        TEST_ASSERT_EQUAL_INT(J288_OK, last_txn.result);
    }
    TEST_ASSERT_EQUAL_UINT32(2u, j288_stm32_stats(&port1)->hal_failures);
}

/* A HAL failure while turning the line to receive: the attempt fails as a line error (DMA
 * flag) at once rather than as a silent timeout, and the next transaction works. */
static void test_turnaround_to_receive_failure_is_a_line_error(void)
{
    j288_bus_config_t bc;
    memset(&bc, 0, sizeof bc);
    init_port1(&bc, false, false);
    fake_hal_fail_next(FAKE_HALFDUPLEX_RX);
    send_foc3();
    wait_out_failure();
    TEST_ASSERT_EQUAL_INT(1, done_count);
    TEST_ASSERT_EQUAL_INT(J288_ERR_LINE, last_txn.result);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_stm32_stats(&port1)->hal_failures);

    send_foc3();
    reply_and_finish();
    TEST_ASSERT_EQUAL_INT(2, done_count);
    TEST_ASSERT_EQUAL_INT(J288_OK, last_txn.result);
}

/* The receiver is off while we transmit, so no echo can come: the port refuses echo. */
/* Unregistering a bus whose command is still on the wire: the transfer stops, the
 * transceiver is released, and its completion no longer reaches the bus. */
static void test_deinit_during_a_transmit_stops_it_and_releases_the_line(void)
{
    j288_cmd_raw_t cmd = worked_cmd();
    init_port1(NULL, false, true);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_submit(j288_stm32_bus(&port1), &cmd, fake_now, on_done, NULL));
    TEST_ASSERT_TRUE(fake_hal_tx_busy(&huart1));
    TEST_ASSERT_EQUAL_INT(1, fake_hal_gpio_level(&gpioa, DE_PIN));
    j288_stm32_deinit(&port1);
    TEST_ASSERT_FALSE(fake_hal_tx_busy(&huart1));
    TEST_ASSERT_FALSE(fake_hal_rx_armed(&huart1));
    TEST_ASSERT_EQUAL_INT(0, fake_hal_gpio_level(&gpioa, DE_PIN));
    TEST_ASSERT_FALSE(j288_stm32_on_tx_cplt(&huart1));
    TEST_ASSERT_EQUAL_INT(0, done_count);
}

static void test_echo_is_refused(void)
{
    j288_stm32_config_t c = base_config(&huart1, &dma1);
    j288_bus_config_t bc;
    memset(&bc, 0, sizeof bc);
    bc.echo = true;
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, j288_stm32_init(&port1, &c, &bc));
    TEST_ASSERT_FALSE(j288_stm32_on_tx_cplt(&huart1)); /* not registered */
}

/* ---- pauses inside a reply ---------------------------------------------------------------- */

/* An idle line inside a reply (a servo or adapter pausing) ends the HAL's reception, not the
 * transaction: wherever the gap falls (before or after the half-transfer point, after the
 * first byte or before the last), the port re-arms and the reply is heard whole. */
static void test_reply_split_by_a_gap_at_any_position_is_heard_whole(void)
{
    init_port1(NULL, false, false);
    for (size_t split = 1u; split < J288_REPLY_LEN; split++) {
        int before = done_count;
        send_foc3();
        TEST_ASSERT_EQUAL_UINT32((uint32_t)split, (uint32_t)fake_hal_rx_bytes(&huart1, k_reply3, split));
        TEST_ASSERT_TRUE(fake_hal_rx_idle(&huart1));
        poll1();
        TEST_ASSERT_EQUAL_INT(before, done_count); /* the pause ended nothing */
        TEST_ASSERT_TRUE(fake_hal_rx_armed(&huart1));
        fake_now += 20u;
        TEST_ASSERT_EQUAL_UINT32((uint32_t)(J288_REPLY_LEN - split),
                                 (uint32_t)fake_hal_rx_bytes(&huart1, &k_reply3[split], J288_REPLY_LEN - split));
        TEST_ASSERT_TRUE(fake_hal_rx_idle(&huart1));
        poll1();
        TEST_ASSERT_EQUAL_INT(before + 1, done_count);
        TEST_ASSERT_EQUAL_INT(J288_OK, last_txn.result);
        TEST_ASSERT_EQUAL_INT32(5215, last_txn.reply.pos);
        fake_now += 10u;
        poll1(); /* the guard */
    }
}

/* With the receive stream in circular mode a pause only reports the position: nothing is
 * re-armed, and the reply is whole wherever it falls in the buffer, across the wrap too. */
static void test_circular_stream_hears_a_paused_reply_across_the_wrap(void)
{
    static const uint8_t noise[10] = {0};
    init_port1(NULL, false, false);
    fake_hal_rx_circular(true);
    for (size_t split = 1u; split < J288_REPLY_LEN; split++) {
        int before = done_count;
        unsigned arms;
        send_foc3();
        arms = fake_hal_count(FAKE_RECEIVE_TO_IDLE_DMA);
        /* line noise first, so that the reply crosses the end of the 32-byte buffer */
        TEST_ASSERT_EQUAL_UINT32(10u, (uint32_t)fake_hal_rx_bytes(&huart1, noise, sizeof noise));
        TEST_ASSERT_TRUE(fake_hal_rx_idle(&huart1));
        (void)fake_hal_rx_bytes(&huart1, k_reply3, split);
        (void)fake_hal_rx_idle(&huart1); /* no event when the pause falls right at the wrap */
        poll1();
        TEST_ASSERT_EQUAL_INT(before, done_count);
        (void)fake_hal_rx_bytes(&huart1, &k_reply3[split], J288_REPLY_LEN - split);
        (void)fake_hal_rx_idle(&huart1);
        TEST_ASSERT_EQUAL_UINT(arms, fake_hal_count(FAKE_RECEIVE_TO_IDLE_DMA)); /* no re-arm */
        poll1();
        TEST_ASSERT_EQUAL_INT(before + 1, done_count);
        TEST_ASSERT_EQUAL_INT(J288_OK, last_txn.result);
        TEST_ASSERT_EQUAL_INT32(5215, last_txn.reply.pos);
        fake_now += 10u;
        poll1();
    }
}

/* A reply that stops at a gap and never resumes is TRUNCATED at the deadline, not at the
 * idle line. */
static void test_reply_stopping_at_a_gap_is_truncated_at_the_deadline(void)
{
    uint32_t start = fake_now;
    init_port1(NULL, false, false);
    send_foc3();
    (void)fake_hal_rx_bytes(&huart1, k_reply3, 20u);
    TEST_ASSERT_TRUE(fake_hal_rx_idle(&huart1));
    poll1();
    TEST_ASSERT_EQUAL_INT(0, done_count);
    fake_now = start + j288_bus_reply_budget_us(j288_stm32_bus(&port1)) - 1u;
    poll1();
    TEST_ASSERT_EQUAL_INT(0, done_count);
    fake_now += 2u;
    poll1();
    TEST_ASSERT_EQUAL_INT(1, done_count);
    TEST_ASSERT_EQUAL_INT(J288_ERR_TRUNCATED, last_txn.result);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_init_rejects_bad_config);
    RUN_TEST(test_init_leaves_line_receiving_de_inactive);
    RUN_TEST(test_registry_is_bounded);
    RUN_TEST(test_full_transaction_call_order_and_bytes);
    RUN_TEST(test_reply_split_by_a_gap_is_heard_whole);
    RUN_TEST(test_reply_one_byte_per_event);
    RUN_TEST(test_bogus_event_size_is_clamped);
    RUN_TEST(test_error_mid_frame_fails_with_line_error);
    RUN_TEST(test_timeout_from_timer_channel);
    RUN_TEST(test_timer_on_16_bit_counter_wraps);
    RUN_TEST(test_advance_in_isr_timeout_ends_in_timer_interrupt);
    RUN_TEST(test_16_bit_timer_long_budget_rearms_until_deadline);
    RUN_TEST(test_transmit_dma_failure_is_a_port_error);
    RUN_TEST(test_receive_arm_failure_is_reported);
    RUN_TEST(test_bytes_during_transmit_are_not_heard);
    RUN_TEST(test_two_buses_route_by_handle);
    RUN_TEST(test_estop_broadcasts_lock_without_waiting);
    RUN_TEST(test_scheduler_sweep_over_port);
    RUN_TEST(test_hw_crc_matches_worked_frames_at_any_alignment);
    RUN_TEST(test_hw_crc_long_input_chunks_and_matches_software);
    RUN_TEST(test_default_crc_falls_back_to_software_until_attached);
    RUN_TEST(test_bus_lock_masks_and_restores);
    RUN_TEST(test_timer_arm_races_the_counter_at_every_access);
    RUN_TEST(test_timer_deadline_already_passed_fires_at_once);
    RUN_TEST(test_init_rejects_crc_unit_not_in_the_servo_configuration);
    RUN_TEST(test_init_rejects_crc_unit_that_computes_wrong);
    RUN_TEST(test_init_rejects_uart_without_dma_streams);
    RUN_TEST(test_init_fails_when_the_line_cannot_receive);
    RUN_TEST(test_stalled_transmit_is_aborted_and_the_next_transaction_works);
    RUN_TEST(test_transmit_stream_left_busy_is_recovered);
    RUN_TEST(test_receive_stream_left_busy_is_recovered);
    RUN_TEST(test_turnaround_to_transmit_failure_is_a_port_error);
    RUN_TEST(test_turnaround_to_receive_failure_is_a_line_error);
    RUN_TEST(test_deinit_during_a_transmit_stops_it_and_releases_the_line);
    RUN_TEST(test_echo_is_refused);
    RUN_TEST(test_reply_split_by_a_gap_at_any_position_is_heard_whole);
    RUN_TEST(test_reply_stopping_at_a_gap_is_truncated_at_the_deadline);
    RUN_TEST(test_circular_stream_hears_a_paused_reply_across_the_wrap);
    return UNITY_END();
}
