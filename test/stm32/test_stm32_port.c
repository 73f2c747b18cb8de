/*
 * The STM32 port driven through full transactions with the real bus engine, against the fake
 * HAL (test/stm32/fake_hal.c): the USART and DMA registers of the F4 (test_stm32_port) or of
 * the G4 (test_stm32_port_g4, -DJ288_STUB_G4). The test plays the application (its IRQ
 * handlers call the port's entries) and the hardware (it completes transmits, puts bytes on
 * the line, idles it, raises line flags, fires the timer). Built with J288_STM32_DCACHE=1 and
 * J288_STM32_RX_BUF_SIZE=64 so that the cache maintenance is exercised and a transaction's 46
 * bytes (echo and reply) cross the half, complete and wrap points; received bytes are watched
 * on their way to the bus (J288_STM32_RX_SINK=test_rx_sink).
 */
#include "unity.h"

#include <stddef.h>
#include <stdio.h>
#include <string.h>

#include "fake_hal.h"
#include "j288/j288.h"
#include "j288_stm32.h"
#include "worked_cmd.h"

/* ---- fixtures ------------------------------------------------------------------------- */

/* The spec's worked frames (bytes from the independent generator). */
static const uint8_t k_cmd_foc3[J288_CMD_LEN] = {0xfe, 0xee, 0x93, 0x00, 0x00, 0x00, 0x00,
                                                 0x00, 0x5f, 0x14, 0x00, 0x00, 0x00, 0x05,
                                                 0x00, 0x32, 0xa6, 0x4b, 0x30, 0x3f};
static const uint8_t k_reply3[J288_REPLY_LEN] = {
    0xfc, 0xee, 0x13, 0x24, 0x29, 0x30, 0x00, 0x05, 0xd7, 0xff, 0x5f, 0x14, 0x00,
    0x00, 0x00, 0x00, 0x00, 0x00, 0xe8, 0x03, 0x00, 0x00, 0x49, 0xc2, 0x3b, 0xee};
/* Broadcast lock, the watchdog bit 0 (the stop clears a trip rather than arming one). */
static const uint8_t k_lock_broadcast_head[3] = {0xfe, 0xee, 0x0f};

static UART_HandleTypeDef huart1, huart2;
static TIM_TypeDef tim2_regs;
static TIM_HandleTypeDef htim2;
static CRC_TypeDef crc_regs;
static CRC_HandleTypeDef hcrc;
static GPIO_TypeDef gpioa;
#define DE_PIN ((uint16_t)0x0100u)
#define TX_PIN ((uint16_t)0x0200u)

J288_STM32_DMA_BUFFER(dma1);
J288_STM32_DMA_BUFFER(dma2);
static j288_stm32_t port1, port2;

/* ---- the application side: IRQ handlers call the port --------------------------------- */

static j288_stm32_t *port_of(const UART_HandleTypeDef *h) { return (h == &huart1) ? &port1 : &port2; }
void fake_app_uart_irq(UART_HandleTypeDef *huart) { j288_stm32_on_uart_irq(port_of(huart)); }
void fake_app_dma_rx_irq(UART_HandleTypeDef *huart) { j288_stm32_on_dma_rx_irq(port_of(huart)); }
void HAL_TIM_OC_DelayElapsedCallback(TIM_HandleTypeDef *htim) { (void)j288_stm32_on_timer(htim); }

/* Every byte the port hands to a bus, in order. */
#define SINK_SIZE 512u
static uint8_t sink[SINK_SIZE];
static size_t sink_len;
static unsigned sink_calls;
void test_rx_sink(j288_bus_t *bus, const uint8_t *data, size_t len);
void test_rx_sink(j288_bus_t *bus, const uint8_t *data, size_t len)
{
    for (size_t i = 0; (i < len) && (sink_len < SINK_SIZE); i++) {
        sink[sink_len++] = data[i];
    }
    sink_calls++;
    j288_bus_on_rx(bus, data, len);
}

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
    memset(&tim2_regs, 0, sizeof tim2_regs);
    memset(&htim2, 0, sizeof htim2);
    memset(&gpioa, 0, sizeof gpioa);
    fake_hal_uart_setup(&huart1);
    fake_hal_uart_setup(&huart2);
    htim2.Instance = &tim2_regs;
    tim2_regs.ARR = 0xFFFFFFFFu;
    memset(&hcrc, 0, sizeof hcrc);
    hcrc.Instance = &crc_regs;
    hcrc.InputDataFormat = CRC_INPUTDATA_FORMAT_WORDS; /* what CubeMX sets: the reset unit */
    fake_now = 1000u;
    done_count = 0;
    memset(&last_txn, 0, sizeof last_txn);
    sink_len = 0u;
    sink_calls = 0u;
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

static void poll1(void) { j288_bus_poll(j288_stm32_bus(&port1), fake_now); }

/* A bus that advances in its interrupts: the only kind the timer serves (a polled bus looks at
 * the clock when polled). */
static const j288_bus_config_t *isr_bus(void)
{
    static j288_bus_config_t bc;
    memset(&bc, 0, sizeof bc);
    bc.advance_in_isr = true;
    return &bc;
}

/* Submit foc3 on port1 and let its transmit finish (the echo comes back on the line). */
static void send_foc3(void)
{
    j288_cmd_raw_t cmd = worked_cmd();
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_submit(j288_stm32_bus(&port1), &cmd, fake_now, on_done, NULL));
    poll1();
    TEST_ASSERT_TRUE(fake_hal_tx_busy(&huart1));
    fake_now += 40u;
    TEST_ASSERT_TRUE(fake_hal_tx_complete(&huart1));
}

/* Past the deadline, polled: the transaction ends. */
static void finish(void)
{
    poll1();
    fake_now += j288_bus_reply_budget_us(j288_stm32_bus(&port1)) + 10u;
    poll1();
}

static void reply_whole(void)
{
    TEST_ASSERT_EQUAL_UINT32((uint32_t)J288_REPLY_LEN,
                             (uint32_t)fake_hal_rx_bytes(&huart1, k_reply3, J288_REPLY_LEN));
    TEST_ASSERT_TRUE(fake_hal_line_idle(&huart1));
}

static void assert_reply_ok(void)
{
    TEST_ASSERT_EQUAL_INT(1, done_count);
    TEST_ASSERT_EQUAL_INT(J288_OK, last_txn.result);
    TEST_ASSERT_EQUAL_UINT8(3u, last_txn.reply.id);
    TEST_ASSERT_EQUAL_INT32(5215, last_txn.reply.pos);
}

/* After a failed transaction: past its guard, the next one is heard whole. */
static void next_transaction_is_heard_whole(void)
{
    fake_now += 3u * j288_bus_reply_budget_us(j288_stm32_bus(&port1)) + 10u;
    poll1();
    done_count = 0;
    send_foc3();
    reply_whole();
    finish();
    assert_reply_ok();
}

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

static void test_init_rejects_echo_on_a_deaf_line(void)
{
    j288_bus_config_t bc;
    j288_stm32_config_t c = base_config(&huart1, &dma1);
    memset(&bc, 0, sizeof bc);
    bc.echo = true;
    c.deaf_while_transmitting = true;
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, j288_stm32_init(&port1, &c, &bc));
    c.deaf_while_transmitting = false;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_stm32_init(&port1, &c, &bc));
}

/* The UART as the port runs it: both directions and DMA requests on, one-bit sampling, no
 * error interrupt, the idle-line interrupt; the RX stream circular and running, before any
 * transaction; DE inactive. */
static void test_init_takes_the_line(void)
{
    USART_TypeDef *u = fake_hal_usart(&huart1);
    init_port1(NULL, false, true);
    TEST_ASSERT_TRUE((u->CR1 & (USART_CR1_UE | USART_CR1_TE | USART_CR1_RE | USART_CR1_IDLEIE)) ==
                     (USART_CR1_UE | USART_CR1_TE | USART_CR1_RE | USART_CR1_IDLEIE));
    TEST_ASSERT_TRUE((u->CR3 & (USART_CR3_ONEBIT | USART_CR3_DMAR | USART_CR3_DMAT)) ==
                     (USART_CR3_ONEBIT | USART_CR3_DMAR | USART_CR3_DMAT));
    TEST_ASSERT_TRUE((u->CR3 & (USART_CR3_EIE | USART_CR3_HDSEL)) == USART_CR3_HDSEL);
#if defined(J288_STUB_G4)
    TEST_ASSERT_TRUE((fake_hal_rx_stream(&huart1)->CCR & (DMA_CCR_EN | DMA_CCR_CIRC)) == (DMA_CCR_EN | DMA_CCR_CIRC));
    TEST_ASSERT_EQUAL_UINT32(J288_STM32_RX_BUF_SIZE, fake_hal_rx_stream(&huart1)->CNDTR);
#else
    TEST_ASSERT_TRUE((fake_hal_rx_stream(&huart1)->CR & (DMA_SxCR_EN | DMA_SxCR_CIRC)) == (DMA_SxCR_EN | DMA_SxCR_CIRC));
    TEST_ASSERT_EQUAL_UINT32(J288_STM32_RX_BUF_SIZE, fake_hal_rx_stream(&huart1)->NDTR);
#endif
    TEST_ASSERT_EQUAL_INT(0, fake_hal_gpio_level(&gpioa, DE_PIN));
}

/* A stream in FIFO mode (CubeMX offers it) counts a byte in NDTR when it leaves the UART,
 * but writes it to memory only at the FIFO's threshold: the port, reading positions from the
 * counter, would hand the bus stale bytes. Init puts the RX stream in direct mode. */
static void test_init_puts_the_rx_stream_in_direct_mode(void)
{
#if defined(J288_STUB_G4)
    TEST_IGNORE_MESSAGE("DMA channels have no FIFO");
#else
    fake_hal_rx_stream(&huart1)->FCR = DMA_SxFCR_DMDIS | 0x1u; /* FIFO mode, threshold 1/2 */
    init_port1(NULL, false, true);
    TEST_ASSERT_EQUAL_HEX32(0u, fake_hal_rx_stream(&huart1)->FCR & DMA_SxFCR_DMDIS);
#endif
}

static void test_registry_is_bounded(void)
{
    static j288_stm32_t extra[J288_STM32_MAX_BUSES + 1u];
    static UART_HandleTypeDef uarts[J288_STM32_MAX_BUSES + 1u];
    static j288_stm32_dma_t bufs[J288_STM32_MAX_BUSES + 1u];
    fake_hal_reset();
    for (size_t i = 0; i <= J288_STM32_MAX_BUSES; i++) {
        j288_stm32_config_t c = base_config(&uarts[i], &bufs[i]);
        fake_hal_uart_setup(&uarts[i]);
        if (i == J288_STM32_MAX_BUSES) {
            uarts[i] = uarts[0]; /* the fake has as many UARTs as the registry: share one */
            uarts[i].Instance = uarts[1].Instance;
        }
        TEST_ASSERT_EQUAL_INT(i < J288_STM32_MAX_BUSES ? J288_OK : J288_ERR_BUSY,
                              j288_stm32_init(&extra[i], &c, NULL));
    }
    for (size_t i = 0; i <= J288_STM32_MAX_BUSES; i++) {
        j288_stm32_deinit(&extra[i]);
    }
    j288_stm32_on_uart_irq(&extra[0]); /* unregistered: nothing happens */
    TEST_ASSERT_EQUAL_UINT32(0u, j288_stm32_stats(&extra[0])->rx_events);
}

/* Fault 4: a DMA buffer in RAM the DMA cannot reach is refused, by family (test_stm32_port:
 * F4, _g4: G4, _h7: H7); the type carries the cache-line alignment. */
static void test_init_refuses_buffers_the_dma_cannot_reach(void)
{
    j288_stm32_config_t c = base_config(&huart1, &dma1);
    struct after_a_char {
        char c;
        j288_stm32_dma_t d;
    };
    TEST_ASSERT_EQUAL_UINT32(0u, (uint32_t)(offsetof(struct after_a_char, d) % J288_STM32_DCACHE_LINE));
#if defined(STM32H7)
    static const uintptr_t unreachable[] = {0x00000020u, 0x0003FFE0u,  /* ITCM */
                                            0x20000000u, 0x2001FFE0u}; /* DTCM */
#elif defined(STM32F4)
    static const uintptr_t unreachable[] = {0x10000000u, 0x1000FFE0u}; /* CCM data RAM */
#endif
#if defined(STM32G4)
    c.dma = (j288_stm32_dma_t *)(uintptr_t)0x10000000u; /* the G4's CCM SRAM is reachable */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_stm32_init(&port1, &c, NULL));
    j288_stm32_deinit(&port1);
#else
    for (size_t i = 0; i < sizeof unreachable / sizeof unreachable[0]; i++) {
        c.dma = (j288_stm32_dma_t *)unreachable[i];
        TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, j288_stm32_init(&port1, &c, NULL));
    }
#endif
    /* not on a cache line, with the D-cache in use */
    c.dma = (j288_stm32_dma_t *)(void *)&dma2.rx[1];
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, j288_stm32_init(&port1, &c, NULL));
    c.dma = &dma1;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_stm32_init(&port1, &c, NULL));
}

static void test_init_rejects_uart_without_dma_streams(void)
{
    j288_stm32_config_t c = base_config(&huart1, &dma1);
    DMA_HandleTypeDef *rx = huart1.hdmarx, *tx = huart1.hdmatx;
    huart1.hdmarx = NULL;
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, j288_stm32_init(&port1, &c, NULL));
    huart1.hdmarx = rx;
    huart1.hdmatx = NULL;
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, j288_stm32_init(&port1, &c, NULL));
    huart1.hdmatx = tx;
}

/* ---- the pin and the lock ----------------------------------------------------------------- */

static void test_tx_pin_drive_option(void)
{
    j288_stm32_config_t c = base_config(&huart1, &dma1);
    c.tx_port = &gpioa;
    c.tx_pin = TX_PIN;
    gpioa.OTYPER = 0x0001u;
    c.tx_drive = J288_STM32_PIN_OPEN_DRAIN;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_stm32_init(&port1, &c, NULL));
    TEST_ASSERT_EQUAL_HEX32(0x0001u | TX_PIN, gpioa.OTYPER);
    j288_stm32_deinit(&port1);
    c.tx_drive = J288_STM32_PIN_PUSH_PULL;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_stm32_init(&port1, &c, NULL));
    TEST_ASSERT_EQUAL_HEX32(0x0001u, gpioa.OTYPER);
    j288_stm32_deinit(&port1);
    gpioa.OTYPER = TX_PIN;
    c.tx_drive = J288_STM32_PIN_AS_CONFIGURED;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_stm32_init(&port1, &c, NULL));
    TEST_ASSERT_EQUAL_HEX32(TX_PIN, gpioa.OTYPER);
}

/* With the bus's priority given, the lock raises BASEPRI to it (other interrupts keep running)
 * and never lowers a mask already held; without, it masks all (PRIMASK). */
static void test_bus_lock_masks_only_the_bus_interrupts(void)
{
    const j288_port_t *ops;
    j288_stm32_config_t c = base_config(&huart1, &dma1);
#if defined(__ARM_ARCH_6M__) || defined(__ARM_ARCH_8M_BASE__)
    TEST_IGNORE_MESSAGE("no BASEPRI on this core: the lock is PRIMASK (test_bus_lock_without_priority)");
#endif
    c.irq_priority = 5u;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_stm32_init(&port1, &c, NULL));
    ops = j288_stm32_bus(&port1)->port;
    ops->lock(&port1);
    TEST_ASSERT_EQUAL_UINT32(5u << (8u - __NVIC_PRIO_BITS), fake_hal_basepri());
    TEST_ASSERT_EQUAL_UINT32(0u, fake_hal_primask());
    ops->unlock(&port1);
    TEST_ASSERT_EQUAL_UINT32(0u, fake_hal_basepri());
    __set_BASEPRI(2u << (8u - __NVIC_PRIO_BITS)); /* a caller already masking more */
    ops->lock(&port1);
    TEST_ASSERT_EQUAL_UINT32(2u << (8u - __NVIC_PRIO_BITS), fake_hal_basepri());
    ops->unlock(&port1);
    TEST_ASSERT_EQUAL_UINT32(2u << (8u - __NVIC_PRIO_BITS), fake_hal_basepri());
    __set_BASEPRI(0u);
}

/* A priority the NVIC cannot hold (its top __NVIC_PRIO_BITS bits) is refused at init: shifted
 * into BASEPRI it would keep only its low bits, and 1 << __NVIC_PRIO_BITS would write 0, a
 * lock that masks nothing. */
static void test_init_rejects_a_priority_the_nvic_cannot_hold(void)
{
    j288_stm32_config_t c = base_config(&huart1, &dma1);
    c.irq_priority = (uint8_t)(1u << __NVIC_PRIO_BITS);
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, j288_stm32_init(&port1, &c, NULL));
    c.irq_priority = 0xFFu;
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, j288_stm32_init(&port1, &c, NULL));
    c.irq_priority = (uint8_t)((1u << __NVIC_PRIO_BITS) - 1u); /* the least urgent: fine */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_stm32_init(&port1, &c, NULL));
}

static void test_bus_lock_without_priority_masks_all(void)
{
    const j288_port_t *ops;
    j288_stm32_config_t c = base_config(&huart1, &dma1);
    c.irq_priority = 0u;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_stm32_init(&port1, &c, NULL));
    ops = j288_stm32_bus(&port1)->port;
    ops->lock(&port1);
    TEST_ASSERT_EQUAL_UINT32(1u, fake_hal_primask());
    ops->unlock(&port1);
    TEST_ASSERT_EQUAL_UINT32(0u, fake_hal_primask());
}

/* ---- transactions ---------------------------------------------------------------------- */

static void test_full_transaction_registers_and_bytes(void)
{
    size_t len = 0;
    const j288_stm32_stats_t *st;
    init_port1(NULL, false, true);
    fake_hal_log_clear();

    j288_cmd_raw_t cmd = worked_cmd();
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_submit(j288_stm32_bus(&port1), &cmd, fake_now, on_done, NULL));
    poll1();
    TEST_ASSERT_TRUE(fake_hal_tx_busy(&huart1));
    TEST_ASSERT_EQUAL_INT(1, fake_hal_gpio_level(&gpioa, DE_PIN));
    /* with a DE pin to drop, transmit complete ends the transmit (not the echo's idle line) */
    TEST_ASSERT_TRUE((fake_hal_usart(&huart1)->CR1 & USART_CR1_TCIE) != 0u);
    TEST_ASSERT_TRUE(fake_hal_log_find(FAKE_CACHE_CLEAN, dma1.tx, 0) >= 0);

    /* the worked frame, byte for byte, from the DMA buffer; the echo skipped */
    fake_now += 40u;
    TEST_ASSERT_TRUE(fake_hal_tx_complete(&huart1));
    TEST_ASSERT_EQUAL_HEX8_ARRAY(k_cmd_foc3, fake_hal_tx_data(&huart1, &len), J288_CMD_LEN);
    TEST_ASSERT_EQUAL_UINT32((uint32_t)J288_CMD_LEN, (uint32_t)len);
    TEST_ASSERT_EQUAL_INT(0, fake_hal_gpio_level(&gpioa, DE_PIN));
    TEST_ASSERT_TRUE((fake_hal_usart(&huart1)->CR1 & USART_CR1_TCIE) == 0u);
    st = j288_stm32_stats(&port1);
    TEST_ASSERT_EQUAL_UINT32(J288_CMD_LEN, st->rx_skipped);

    reply_whole();
    TEST_ASSERT_EQUAL_UINT32(J288_REPLY_LEN, st->rx_bytes);
    TEST_ASSERT_EQUAL_HEX8_ARRAY(k_reply3, sink, J288_REPLY_LEN);
    TEST_ASSERT_TRUE(fake_hal_count(FAKE_CACHE_INVALIDATE) >= 1u);
    finish();
    assert_reply_ok();
    TEST_ASSERT_EQUAL_INT16(-41, last_txn.reply.speed);
    TEST_ASSERT_EQUAL_UINT16(1000u, last_txn.reply.out_pos);
    TEST_ASSERT_TRUE(fake_hal_count(FAKE_CRC_CALCULATE) >= 2u);
    TEST_ASSERT_EQUAL_UINT32(0u, fake_hal_primask());
}

/* Many transactions: the circular buffer wraps again and again, every reply arrives whole;
 * without a DE pin the echo's idle line ends each transmit (no transmit-complete interrupt). */
static void test_many_transactions_across_the_wraps(void)
{
    init_port1(NULL, false, false);
    TEST_ASSERT_TRUE((fake_hal_usart(&huart1)->CR1 & USART_CR1_TCIE) == 0u);
    for (int i = 0; i < 20; i++) {
        done_count = 0;
        sink_len = 0u;
        send_foc3();
        reply_whole();
        poll1();
        fake_now += 10u;
        poll1();
        assert_reply_ok();
        TEST_ASSERT_EQUAL_HEX8_ARRAY(k_reply3, sink, J288_REPLY_LEN);
    }
    TEST_ASSERT_EQUAL_UINT32(20u * J288_REPLY_LEN, j288_stm32_stats(&port1)->rx_bytes);
}

/* With the bus's echo option the 20 echoed bytes go to the bus, which checks them. */
static void test_echo_option_checks_the_echo(void)
{
    j288_bus_config_t bc;
    memset(&bc, 0, sizeof bc);
    bc.echo = true;
    init_port1(&bc, false, false);
    send_foc3();
    TEST_ASSERT_EQUAL_HEX8_ARRAY(k_cmd_foc3, sink, J288_CMD_LEN);
    reply_whole();
    finish();
    assert_reply_ok();
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_stats(j288_stm32_bus(&port1))->collisions);
}

/* A deaf line (transceiver receiver off with DE): nothing to skip, nothing of the reply lost. */
static void test_deaf_line_skips_nothing(void)
{
    j288_stm32_config_t c = base_config(&huart1, &dma1);
    c.deaf_while_transmitting = true;
    fake_hal_line_deaf(&huart1, true);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_stm32_init(&port1, &c, NULL));
    send_foc3();
    TEST_ASSERT_EQUAL_UINT32(0u, j288_stm32_stats(&port1)->rx_skipped);
    reply_whole();
    finish();
    assert_reply_ok();
}

static void test_reply_split_by_a_gap_at_any_position_is_heard_whole(void)
{
    for (size_t cut = 1u; cut < J288_REPLY_LEN; cut++) {
        char msg[32];
        setUp();
        init_port1(NULL, false, false);
        send_foc3();
        (void)fake_hal_rx_bytes(&huart1, k_reply3, cut);
        TEST_ASSERT_TRUE(fake_hal_line_idle(&huart1));
        (void)fake_hal_rx_bytes(&huart1, &k_reply3[cut], J288_REPLY_LEN - cut);
        TEST_ASSERT_TRUE(fake_hal_line_idle(&huart1));
        finish();
        snprintf(msg, sizeof msg, "gap after byte %u", (unsigned)cut);
        TEST_ASSERT_EQUAL_INT_MESSAGE(J288_OK, last_txn.result, msg);
        tearDown();
    }
}

static void test_reply_stopping_at_a_gap_is_truncated_at_the_deadline(void)
{
    init_port1(NULL, false, false);
    send_foc3();
    (void)fake_hal_rx_bytes(&huart1, k_reply3, 12u);
    TEST_ASSERT_TRUE(fake_hal_line_idle(&huart1));
    finish();
    TEST_ASSERT_EQUAL_INT(1, done_count);
    TEST_ASSERT_EQUAL_INT(J288_ERR_TRUNCATED, last_txn.result);
}

/* Fault 1: no turnaround window. The reply starts 0, 1, 2, 5 or 10 us after our last stop bit
 * (a byte takes 1.67 us at 6 Mbps), and the interrupt that ends the transmit (the idle line
 * after the echo, or a later one) is taken before or after the reply's first bytes arrived,
 * with the DMA prompt or lagging: every byte reaches the bus. Bytes are timed in thirds of a
 * microsecond (a byte: 5). */
static void run_turnaround(unsigned delay_us, unsigned tc_latency_thirds, bool lag)
{
    j288_cmd_raw_t cmd = worked_cmd();
    unsigned first_done = 3u * delay_us + 5u; /* the reply's first byte complete */
    size_t before_tc = 0u;
    char msg[80];

    setUp();
    init_port1(NULL, false, false);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_submit(j288_stm32_bus(&port1), &cmd, fake_now, on_done, NULL));
    poll1();
    fake_hal_irq_hold(true); /* the interrupt that ends the transmit waits its latency */
    /* a frame of silence after the echo (2 us and more) raises IDLE */
    TEST_ASSERT_TRUE(fake_hal_tx_complete_ex(&huart1, delay_us >= 2u));
    fake_hal_dma_lag(&huart1, lag); /* reply bytes wait in DR while a handler runs */
    if (tc_latency_thirds >= first_done) {
        before_tc = 1u + (tc_latency_thirds - first_done) / 5u;
    }
    if (before_tc > J288_REPLY_LEN) {
        before_tc = J288_REPLY_LEN;
    }
    (void)fake_hal_rx_bytes(&huart1, k_reply3, before_tc);
    while (fake_hal_irq_service(&huart1, true) || fake_hal_irq_service(&huart1, false)) {
    }
    fake_hal_irq_hold(false);
    (void)fake_hal_rx_bytes(&huart1, &k_reply3[before_tc], J288_REPLY_LEN - before_tc);
    TEST_ASSERT_TRUE(fake_hal_line_idle(&huart1));
    finish();
    snprintf(msg, sizeof msg, "reply %u us after the stop bit, transmit end taken %u/3 us late%s", delay_us,
             tc_latency_thirds, lag ? ", DMA lagging" : "");
    TEST_ASSERT_EQUAL_INT_MESSAGE(J288_OK, last_txn.result, msg);
    TEST_ASSERT_EQUAL_UINT32_MESSAGE(J288_REPLY_LEN, j288_stm32_stats(&port1)->rx_bytes, msg);
    TEST_ASSERT_EQUAL_UINT_MESSAGE(0u, fake_hal_bytes_stolen(&huart1), msg);
    tearDown();
}

static void test_reply_at_any_delay_after_the_stop_bit_loses_no_byte(void)
{
    static const unsigned delays[] = {0u, 1u, 2u, 5u, 10u};
    for (size_t d = 0; d < sizeof delays / sizeof delays[0]; d++) {
        for (unsigned late = 0u; late <= 12u; late += 3u) {
            run_turnaround(delays[d], late, false);
            run_turnaround(delays[d], late, true);
        }
    }
}

/* Fault 2: the position comes from the stream's counter at every event, whatever the order
 * in which the half, complete and idle interrupts are taken and however late. A window of 80
 * bytes (more than the 64-byte buffer), an idle line after 10: each event is served 0 to 8
 * bytes after it was raised, the UART's or the stream's first when both wait; every byte
 * reaches the bus exactly once, in order. */
static void test_every_event_order_delivers_each_byte_once(void)
{
    uint8_t window[80];
    for (size_t i = 0; i < sizeof window; i++) {
        window[i] = (uint8_t)(0x40u + i);
    }
    for (unsigned pattern = 0u; pattern < 3u * 3u * 3u * 2u; pattern++) {
        unsigned lag_uart = (pattern % 3u) * 4u;
        unsigned lag_dma = ((pattern / 3u) % 3u) * 4u;
        unsigned lag_late = ((pattern / 9u) % 3u) * 4u;
        bool uart_first = (pattern / 27u) != 0u;
        unsigned uart_wait = 0u, dma_wait = 0u;
        char msg[64];

        setUp();
        init_port1(NULL, false, false);
        send_foc3(); /* echo skipped at transmit complete */
        sink_len = 0u;
        fake_hal_irq_hold(true);
        for (size_t i = 0; i < sizeof window; i++) {
            (void)fake_hal_rx_bytes(&huart1, &window[i], 1u);
            if (i == 9u) {
                (void)fake_hal_line_idle(&huart1);
            }
            uart_wait = fake_hal_irq_pending(&huart1, true) ? uart_wait + 1u : 0u;
            dma_wait = fake_hal_irq_pending(&huart1, false) ? dma_wait + 1u : 0u;
            /* the late event of the window: served later still */
            unsigned dma_lag = (i > 60u) ? lag_late : lag_dma;
            for (int k = 0; k < 2; k++) {
                bool uart = (k == 0) == uart_first;
                if (uart && (uart_wait > lag_uart)) {
                    (void)fake_hal_irq_service(&huart1, true);
                    uart_wait = 0u;
                }
                if (!uart && (dma_wait > dma_lag)) {
                    (void)fake_hal_irq_service(&huart1, false);
                    dma_wait = 0u;
                }
            }
        }
        (void)fake_hal_line_idle(&huart1);
        while (fake_hal_irq_service(&huart1, !uart_first) || fake_hal_irq_service(&huart1, uart_first)) {
        }
        fake_hal_irq_hold(false);
        snprintf(msg, sizeof msg, "pattern %u", pattern);
        TEST_ASSERT_EQUAL_UINT32_MESSAGE((uint32_t)sizeof window, (uint32_t)sink_len, msg);
        TEST_ASSERT_EQUAL_HEX8_ARRAY_MESSAGE(window, sink, sizeof window, msg);
        tearDown();
    }
}

/* Fault 3: line errors are left to the CRC. A noise flag at any byte of the reply: the byte is
 * kept, the reply is good. A framing error or an overrun at any byte: that byte is gone or
 * wrong, but nothing after it is lost: the next transaction is good. The counters say which. */
static void flagged_reply(size_t at, unsigned flag)
{
    (void)fake_hal_rx_bytes(&huart1, k_reply3, at);
    (void)fake_hal_rx_flagged(&huart1, k_reply3[at], flag);
    (void)fake_hal_rx_bytes(&huart1, &k_reply3[at + 1u], J288_REPLY_LEN - at - 1u);
    TEST_ASSERT_TRUE(fake_hal_line_idle(&huart1));
}

static void test_noise_at_any_byte_keeps_the_reply(void)
{
    for (size_t at = 0u; at < J288_REPLY_LEN; at++) {
        char msg[32];
        setUp();
        init_port1(NULL, false, false);
        send_foc3();
        flagged_reply(at, FAKE_NOISE);
        finish();
        snprintf(msg, sizeof msg, "noise at byte %u", (unsigned)at);
        TEST_ASSERT_EQUAL_INT_MESSAGE(J288_OK, last_txn.result, msg);
        TEST_ASSERT_EQUAL_UINT32_MESSAGE(J288_REPLY_LEN, j288_stm32_stats(&port1)->rx_bytes, msg);
        tearDown();
    }
}

static void test_framing_or_overrun_at_any_byte_loses_nothing_after(void)
{
    static const unsigned flags[] = {FAKE_FRAMING, FAKE_OVERRUN, FAKE_PARITY};
    for (size_t f = 0; f < sizeof flags / sizeof flags[0]; f++) {
        for (size_t at = 0u; at < J288_REPLY_LEN; at++) {
            char msg[48];
            const j288_stm32_stats_t *st;
            setUp();
            init_port1(NULL, false, false);
            send_foc3();
            flagged_reply(at, flags[f]);
            finish();
            snprintf(msg, sizeof msg, "flag %u at byte %u", flags[f], (unsigned)at);
            st = j288_stm32_stats(&port1);
            TEST_ASSERT_EQUAL_UINT32_MESSAGE(flags[f] == FAKE_FRAMING ? 1u : 0u, st->framing_errors, msg);
            TEST_ASSERT_EQUAL_UINT32_MESSAGE(flags[f] == FAKE_OVERRUN ? 1u : 0u, st->overruns, msg);
            TEST_ASSERT_EQUAL_UINT32_MESSAGE(flags[f] == FAKE_PARITY ? 1u : 0u, st->parity_errors, msg);
            TEST_ASSERT_EQUAL_UINT32_MESSAGE(0u, st->noise_errors, msg);
            TEST_ASSERT_TRUE_MESSAGE(j288_bus_stats(j288_stm32_bus(&port1))->line_errors >= 1u, msg);
            /* every byte after the flagged one reached the bus */
            TEST_ASSERT_TRUE_MESSAGE(sink_len >= J288_REPLY_LEN - at - 1u, msg);
            if (at + 1u < J288_REPLY_LEN) {
                TEST_ASSERT_EQUAL_HEX8_ARRAY_MESSAGE(&k_reply3[at + 1u], &sink[sink_len - (J288_REPLY_LEN - at - 1u)],
                                                     J288_REPLY_LEN - at - 1u, msg);
            }
            next_transaction_is_heard_whole();
            tearDown();
        }
    }
}

/* A transfer error stops the RX stream: it is restarted, reported, and the next reply heard. */
static void test_rx_stream_error_restarts_the_stream(void)
{
    init_port1(NULL, false, false);
    send_foc3();
    (void)fake_hal_rx_bytes(&huart1, k_reply3, 5u);
    fake_hal_dma_rx_error(&huart1);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_stm32_stats(&port1)->dma_errors);
    finish();
    TEST_ASSERT_EQUAL_INT(J288_ERR_LINE, last_txn.result);
    next_transaction_is_heard_whole();
}

/* A transmit whose completion never came (the stream left running): the next transmit stops
 * it at the register and goes out. */
static void test_stalled_transmit_is_stopped_and_the_next_transaction_works(void)
{
    j288_cmd_raw_t cmd = worked_cmd();
    init_port1(NULL, false, false);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_submit(j288_stm32_bus(&port1), &cmd, fake_now, on_done, NULL));
    poll1();
    TEST_ASSERT_TRUE(fake_hal_tx_busy(&huart1)); /* ... and its completion never comes */
    fake_now += 3u * j288_bus_reply_budget_us(j288_stm32_bus(&port1)) + 10u;
    poll1();
    TEST_ASSERT_EQUAL_INT(1, done_count);
    TEST_ASSERT_EQUAL_INT(J288_ERR_TX_TIMEOUT, last_txn.result);
    next_transaction_is_heard_whole();
    TEST_ASSERT_EQUAL_UINT32(1u, j288_stm32_stats(&port1)->dma_resets);
}

static void test_deinit_during_a_transmit_stops_it_and_releases_the_line(void)
{
    j288_cmd_raw_t cmd = worked_cmd();
    init_port1(NULL, false, true);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_submit(j288_stm32_bus(&port1), &cmd, fake_now, on_done, NULL));
    poll1();
    TEST_ASSERT_EQUAL_INT(1, fake_hal_gpio_level(&gpioa, DE_PIN));
    j288_stm32_deinit(&port1);
    TEST_ASSERT_FALSE(fake_hal_tx_busy(&huart1));
    TEST_ASSERT_EQUAL_INT(0, fake_hal_gpio_level(&gpioa, DE_PIN));
    TEST_ASSERT_TRUE((fake_hal_usart(&huart1)->CR3 & (USART_CR3_DMAR | USART_CR3_DMAT)) == 0u);
}

static void test_two_buses_route_by_port(void)
{
    j288_cmd_raw_t cmd = worked_cmd();
    j288_stm32_config_t c2 = base_config(&huart2, &dma2);
    init_port1(NULL, false, false);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_stm32_init(&port2, &c2, NULL));

    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_submit(j288_stm32_bus(&port1), &cmd, fake_now, on_done, NULL));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_submit(j288_stm32_bus(&port2), &cmd, fake_now, on_done, NULL));
    j288_bus_poll(j288_stm32_bus(&port1), fake_now);
    j288_bus_poll(j288_stm32_bus(&port2), fake_now);
    fake_now += 40u;
    TEST_ASSERT_TRUE(fake_hal_tx_complete(&huart2));
    TEST_ASSERT_TRUE(fake_hal_tx_complete(&huart1));

    /* bus 2 gets the reply; bus 1 gets nothing and times out */
    (void)fake_hal_rx_bytes(&huart2, k_reply3, J288_REPLY_LEN);
    TEST_ASSERT_TRUE(fake_hal_line_idle(&huart2));
    j288_bus_poll(j288_stm32_bus(&port2), fake_now);
    TEST_ASSERT_EQUAL_INT(1, done_count);
    TEST_ASSERT_EQUAL_INT(J288_OK, last_txn.result);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_stm32_stats(&port1)->rx_bytes);
    finish();
    TEST_ASSERT_EQUAL_INT(2, done_count);
    TEST_ASSERT_EQUAL_INT(J288_ERR_TIMEOUT, last_txn.result);
    j288_stm32_on_uart_irq(NULL);
    j288_stm32_on_dma_rx_irq(NULL);
}

/* ---- timer ---------------------------------------------------------------------------- */

static void test_timeout_from_timer_channel(void)
{
    uint32_t budget;
    init_port1(isr_bus(), true, false);
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
    TEST_ASSERT_EQUAL_INT(1, done_count);
    TEST_ASSERT_EQUAL_INT(J288_ERR_TIMEOUT, last_txn.result);
}

/* Polled, the bus needs no timer: the compare is never armed. */
static void test_polled_bus_leaves_the_timer_alone(void)
{
    init_port1(NULL, true, false);
    send_foc3();
    TEST_ASSERT_TRUE((tim2_regs.DIER & TIM_IT_CC1) == 0u);
    finish();
    TEST_ASSERT_EQUAL_INT(J288_ERR_TIMEOUT, last_txn.result);
}

static void test_timer_on_16_bit_counter_wraps(void)
{
    init_port1(isr_bus(), true, false);
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
    TEST_ASSERT_TRUE(fake_hal_line_idle(&huart1));
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
    init_port1_timer_tick(isr_bus());
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
    init_port1_timer_tick(isr_bus());
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


int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_init_rejects_bad_config);
    RUN_TEST(test_init_rejects_echo_on_a_deaf_line);
    RUN_TEST(test_init_takes_the_line);
    RUN_TEST(test_registry_is_bounded);
    RUN_TEST(test_init_puts_the_rx_stream_in_direct_mode);
    RUN_TEST(test_init_refuses_buffers_the_dma_cannot_reach);
    RUN_TEST(test_init_rejects_uart_without_dma_streams);
    RUN_TEST(test_tx_pin_drive_option);
    RUN_TEST(test_bus_lock_masks_only_the_bus_interrupts);
    RUN_TEST(test_bus_lock_without_priority_masks_all);
    RUN_TEST(test_init_rejects_a_priority_the_nvic_cannot_hold);
    RUN_TEST(test_full_transaction_registers_and_bytes);
    RUN_TEST(test_many_transactions_across_the_wraps);
    RUN_TEST(test_echo_option_checks_the_echo);
    RUN_TEST(test_deaf_line_skips_nothing);
    RUN_TEST(test_reply_split_by_a_gap_at_any_position_is_heard_whole);
    RUN_TEST(test_reply_stopping_at_a_gap_is_truncated_at_the_deadline);
    RUN_TEST(test_reply_at_any_delay_after_the_stop_bit_loses_no_byte);
    RUN_TEST(test_every_event_order_delivers_each_byte_once);
    RUN_TEST(test_noise_at_any_byte_keeps_the_reply);
    RUN_TEST(test_framing_or_overrun_at_any_byte_loses_nothing_after);
    RUN_TEST(test_rx_stream_error_restarts_the_stream);
    RUN_TEST(test_stalled_transmit_is_stopped_and_the_next_transaction_works);
    RUN_TEST(test_deinit_during_a_transmit_stops_it_and_releases_the_line);
    RUN_TEST(test_two_buses_route_by_port);
    RUN_TEST(test_timeout_from_timer_channel);
    RUN_TEST(test_polled_bus_leaves_the_timer_alone);
    RUN_TEST(test_timer_on_16_bit_counter_wraps);
    RUN_TEST(test_advance_in_isr_timeout_ends_in_timer_interrupt);
    RUN_TEST(test_16_bit_timer_long_budget_rearms_until_deadline);
    RUN_TEST(test_estop_broadcasts_lock_without_waiting);
    RUN_TEST(test_scheduler_sweep_over_port);
    RUN_TEST(test_hw_crc_matches_worked_frames_at_any_alignment);
    RUN_TEST(test_hw_crc_long_input_chunks_and_matches_software);
    RUN_TEST(test_default_crc_falls_back_to_software_until_attached);
    RUN_TEST(test_timer_arm_races_the_counter_at_every_access);
    RUN_TEST(test_timer_deadline_already_passed_fires_at_once);
    RUN_TEST(test_init_rejects_crc_unit_not_in_the_servo_configuration);
    RUN_TEST(test_init_rejects_crc_unit_that_computes_wrong);
    return UNITY_END();
}
