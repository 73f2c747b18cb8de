/* The port template's interrupt glue drives a real bus: a reply split across the wrap of the
 * circular receive DMA buffer reaches the engine whole and in order. */
#include "unity.h"

#include "../../port/template/j288_port_template.c"

void setUp(void) {}
void tearDown(void) {}

static int calls;
static j288_txn_t last;

static void on_done(void *user, const j288_txn_t *txn)
{
    (void)user;
    calls++;
    last = *txn;
}

static void test_template_forwards_wrapped_dma(void)
{
    static j288_port_template_t port;
    j288_cmd_raw_t cmd;
    j288_reply_raw_t r;
    uint8_t frame[J288_REPLY_LEN];
    uint32_t start = J288_PORT_TEMPLATE_RX_DMA_SIZE - 10u;
    uint32_t i;

    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_port_template_init(NULL, NULL));
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_port_template_init(&port, NULL));
    memset(&cmd, 0, sizeof cmd);
    cmd.id = 2u;
    memset(&r, 0, sizeof r);
    r.id = 2u;
    r.pos = 4242;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_reply_encode(&r, frame, NULL));

    /* noise while idle moves the read position near the end of the buffer */
    j288_port_template_rx_event_isr(&port, start, true);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_submit(&port.bus, &cmd, 0u, on_done, NULL));
    j288_port_template_tx_complete_isr(&port);
    for (i = 0u; i < J288_REPLY_LEN; i++) {
        port.rx_dma[(start + i) % J288_PORT_TEMPLATE_RX_DMA_SIZE] = frame[i];
    }
    j288_port_template_rx_event_isr(&port, 0u, false); /* transfer complete: 10 bytes */
    j288_port_template_rx_event_isr(
        &port, (start + J288_REPLY_LEN) % J288_PORT_TEMPLATE_RX_DMA_SIZE, true);
    j288_bus_poll(&port.bus, 0u);
    TEST_ASSERT_EQUAL_INT(1, calls);
    TEST_ASSERT_EQUAL_INT(J288_OK, last.result);
    TEST_ASSERT_EQUAL_INT32(4242, last.reply.pos);
    TEST_ASSERT_EQUAL_UINT32(start, j288_bus_stats(&port.bus)->stale_bytes);

    /* errors and the timer reach the bus */
    j288_port_template_error_isr(&port, J288_LINE_FRAMING);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&port.bus)->line_errors);
    j288_port_template_timer_isr(&port);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_template_forwards_wrapped_dma);
    return UNITY_END();
}
