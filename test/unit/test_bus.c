/* The bus engine against the scripted fake port: every path, exact bytes, states, stats. */
#include "unity.h"

#include "fake_port.h"
#include "j288/j288.h"
#include "worked_cmd.h"

#include <string.h>

void setUp(void) {}
void tearDown(void) {}

/* The spec's worked frames: FOC servo 3, watchdog on, pos 5215, k_pos 1280, k_spd 12800, and
 * the reply of servo 3 (FOC, 36 C, 41 C, 24.0 V, torque 1280, speed -41, pos 5215, OutPos
 * 1000). */
static const uint8_t WORKED_CMD3[J288_CMD_LEN] = {0xfe, 0xee, 0x93, 0x00, 0x00, 0x00, 0x00,
                                                  0x00, 0x5f, 0x14, 0x00, 0x00, 0x00, 0x05,
                                                  0x00, 0x32, 0xa6, 0x4b, 0x30, 0x3f};
static const uint8_t WORKED_REPLY3[J288_REPLY_LEN] = {
    0xfc, 0xee, 0x13, 0x24, 0x29, 0x30, 0x00, 0x05, 0xd7, 0xff, 0x5f, 0x14, 0x00,
    0x00, 0x00, 0x00, 0x00, 0x00, 0xe8, 0x03, 0x00, 0x00, 0x49, 0xc2, 0x3b, 0xee};
static const uint8_t WORKED_LOCK0[J288_CMD_LEN] = {
    0xfe, 0xee, 0x80, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0x1d, 0x99, 0xfb, 0x6e};

#define US        1000u
#define TX_END_NS 33333u /* 20 bytes at 6 Mbps */
#define REPLY_NS  43333u /* 26 bytes at 6 Mbps */
#define BUDGET_US 147u   /* 77 wire + 50 turnaround + 20 margin */

static fake_port_t fp;
static j288_bus_t bus;

static struct {
    int calls;
    j288_txn_t txn;
    void *user;
    j288_bus_state_t state_in_cb;
} cb;

static void on_done(void *user, const j288_txn_t *txn)
{
    cb.calls++;
    cb.txn = *txn;
    cb.user = user;
    cb.state_in_cb = j288_bus_state(&bus);
}

static j288_cmd_raw_t lock_cmd(uint8_t id)
{
    j288_cmd_raw_t c;
    memset(&c, 0, sizeof c);
    c.id = id;
    c.watchdog = true;
    return c;
}

/* The emergency stop's frame: broadcast lock with the watchdog bit 0 (a stop leaves no
 * watchdog to trip, and clears a trip). */
static j288_cmd_raw_t stop_cmd(void)
{
    j288_cmd_raw_t c = lock_cmd(J288_BROADCAST_ID);
    c.watchdog = false;
    return c;
}

static j288_reply_raw_t reply_for(uint8_t id, int32_t pos)
{
    j288_reply_raw_t r;
    memset(&r, 0, sizeof r);
    r.id = id;
    r.status = 1u;
    r.case_temp_c = 30;
    r.voltage_raw = 48u;
    r.pos = pos;
    r.out_pos = 100u;
    return r;
}

static void setup_cfg(const j288_bus_config_t *cfg)
{
    memset(&cb, 0, sizeof cb);
    fake_port_init(&fp);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_init(&bus, &fp.ops, &fp, cfg));
    fake_port_attach(&fp, &bus);
    fp.poll_fn = fake_port_poll_bus;
    fp.poll_user = &bus;
}

static void setup(void)
{
    setup_cfg(NULL);
}

static void submit_ok(const j288_cmd_raw_t *cmd)
{
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_submit(&bus, cmd, fake_port_now_us(&fp), on_done, &cb));
}

static void assert_frame(uint32_t i, const uint8_t *want)
{
    const fake_frame_t *f = fake_port_frame(&fp, i);
    TEST_ASSERT_NOT_NULL(f);
    TEST_ASSERT_EQUAL_UINT(J288_CMD_LEN, f->len);
    TEST_ASSERT_EQUAL_HEX8_ARRAY(want, f->data, J288_CMD_LEN);
}

static void assert_frame_cmd(uint32_t i, const j288_cmd_raw_t *cmd)
{
    uint8_t want[J288_CMD_LEN];
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_cmd_encode(cmd, want, NULL));
    assert_frame(i, want);
}

/* Every accepted submit is ok, failed or aborted once it is called back; pending is the one
 * in flight or queued (0 or 1). */
static void assert_stats_add_up(uint32_t pending)
{
    const j288_bus_stats_t *st = j288_bus_stats(&bus);
    TEST_ASSERT_EQUAL_UINT32(st->transactions, st->ok + st->failed + st->aborted + pending);
}

/* ---- init and configuration */

static void test_init_rejections(void)
{
    j288_bus_config_t cfg;
    j288_port_t ops;

    fake_port_init(&fp);
    ops = fp.ops;
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_bus_init(NULL, &ops, &fp, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_bus_init(&bus, NULL, &fp, NULL));
    ops.start_tx = NULL;
    TEST_ASSERT_EQUAL_INT(J288_ERR_PORT_OPS, j288_bus_init(&bus, &ops, &fp, NULL));
    ops = fp.ops;
    ops.now_us = NULL;
    TEST_ASSERT_EQUAL_INT(J288_ERR_PORT_OPS, j288_bus_init(&bus, &ops, &fp, NULL));
    ops = fp.ops;
    ops.unlock = NULL;
    TEST_ASSERT_EQUAL_INT(J288_ERR_PORT_OPS, j288_bus_init(&bus, &ops, &fp, NULL));
    ops = fp.ops;
    ops.lock = NULL;
    TEST_ASSERT_EQUAL_INT(J288_ERR_PORT_OPS, j288_bus_init(&bus, &ops, &fp, NULL));

    memset(&cfg, 0, sizeof cfg);
    cfg.retries = (uint8_t)(J288_CONFIG_MAX_RETRIES + 1u);
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, j288_bus_init(&bus, &fp.ops, &fp, &cfg));
    memset(&cfg, 0, sizeof cfg);
    cfg.baud = 9599u;
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, j288_bus_init(&bus, &fp.ops, &fp, &cfg));
    memset(&cfg, 0, sizeof cfg);
    cfg.margin_us = 60000001u;
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, j288_bus_init(&bus, &fp.ops, &fp, &cfg));
    memset(&cfg, 0, sizeof cfg);
    cfg.turnaround_us = 60000001u;
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, j288_bus_init(&bus, &fp.ops, &fp, &cfg));
    memset(&cfg, 0, sizeof cfg);
    cfg.guard_us = 60000001u;
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_CONFIG, j288_bus_init(&bus, &fp.ops, &fp, &cfg));
    cfg.guard_us = 60000000u; /* the limit itself is fine */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_init(&bus, &fp.ops, &fp, &cfg));

    /* Only the two required ops: fine. */
    memset(&ops, 0, sizeof ops);
    ops.start_tx = fp.ops.start_tx;
    ops.now_us = fp.ops.now_us;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_init(&bus, &ops, &fp, NULL));
    TEST_ASSERT_EQUAL_INT(J288_BUS_IDLE, j288_bus_state(&bus));
    /* Nothing was sent by any of this. */
    TEST_ASSERT_EQUAL_UINT32(0u, fp.nframes);
}

static void test_reply_budget_and_wire_time(void)
{
    j288_bus_config_t cfg;
    TEST_ASSERT_EQUAL_UINT32(77u, j288_wire_time_us(6000000u, 46u));
    TEST_ASSERT_EQUAL_UINT32(34u, j288_wire_time_us(6000000u, 20u));
    TEST_ASSERT_EQUAL_UINT32(3994u, j288_wire_time_us(115200u, 46u));
    TEST_ASSERT_EQUAL_UINT32(77u, j288_wire_time_us(0u, 46u));
    setup();
    TEST_ASSERT_EQUAL_UINT32(BUDGET_US, j288_bus_reply_budget_us(&bus));
    memset(&cfg, 0, sizeof cfg);
    cfg.baud = 1000000u;
    cfg.turnaround_us = 100u;
    cfg.margin_us = 3000u;
    setup_cfg(&cfg);
    TEST_ASSERT_EQUAL_UINT32(460u + 100u + 3000u, j288_bus_reply_budget_us(&bus));
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_reply_budget_us(NULL));
}

/* j288_bus_config(): the configuration as given, defaults filled in (the host reads its
 * retries through it, not through the bus's fields). */
static void test_config_accessor(void)
{
    j288_bus_config_t cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.retries = 2u;
    cfg.margin_us = 3000u;
    setup_cfg(&cfg);
    TEST_ASSERT_NOT_NULL(j288_bus_config(&bus));
    TEST_ASSERT_EQUAL_UINT8(2u, j288_bus_config(&bus)->retries);
    TEST_ASSERT_EQUAL_UINT32(3000u, j288_bus_config(&bus)->margin_us);
    TEST_ASSERT_EQUAL_UINT32(6000000u, j288_bus_config(&bus)->baud); /* 0: the default */
    TEST_ASSERT_NULL(j288_bus_config(NULL));
}

/* j288_wire_time_us() divides without a division: exact against 64-bit arithmetic (modulo
 * 2^32 where the result does not fit), at the edges and at random. */
static uint32_t wire_time_ref(uint32_t baud, uint32_t nbytes)
{
    uint64_t b = (baud == 0u) ? 6000000u : baud;
    return (uint32_t)(((uint64_t)nbytes * 10000000u + b - 1u) / b);
}

static void test_wire_time_exact(void)
{
    static const uint32_t bauds[] = {0u, 1u, 2u, 3u, 7u, 9600u, 115200u, 1000000u, 6000000u,
                                     9999999u, 10000000u, 10000001u, 0x7FFFFFFFu, 0x80000000u,
                                     0x80000001u, 0xFFFFFFFEu, 0xFFFFFFFFu};
    static const uint32_t counts[] = {0u, 1u, 2u, 20u, 26u, 46u, 429u, 430u, 65535u,
                                      0x7FFFFFFFu, 0x80000000u, 0xFFFFFFFFu};
    uint32_t x = 0x12345678u;
    size_t i, j;
    for (i = 0u; i < sizeof bauds / sizeof bauds[0]; i++) {
        for (j = 0u; j < sizeof counts / sizeof counts[0]; j++) {
            TEST_ASSERT_EQUAL_UINT32(wire_time_ref(bauds[i], counts[j]),
                                     j288_wire_time_us(bauds[i], counts[j]));
        }
    }
    for (i = 0u; i < 20000u; i++) {
        uint32_t b, n;
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        b = x >> (x & 31u);
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        n = x >> (x & 31u);
        TEST_ASSERT_EQUAL_UINT32(wire_time_ref(b, n), j288_wire_time_us(b, n));
    }
}

/* A configured guard is the gap between a reply and the next transmit. */
static void test_configured_guard(void)
{
    j288_bus_config_t cfg;
    j288_cmd_raw_t cmd = lock_cmd(3u);
    j288_reply_raw_t r = reply_for(3u, 31);
    memset(&cfg, 0, sizeof cfg);
    cfg.guard_us = 40u;
    setup_cfg(&cfg);
    fake_port_add_servo(&fp, 3u, &r);
    submit_ok(&cmd);
    fake_port_run_until(&fp, 87u * US); /* reply taken at 86 us */
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.result);
    submit_ok(&cmd); /* queued behind the guard */
    fake_port_run_until(&fp, 125u * US);
    TEST_ASSERT_EQUAL_UINT32(1u, fp.nframes);
    TEST_ASSERT_EQUAL_INT(J288_BUS_GUARD, j288_bus_state(&bus));
    fake_port_run_until(&fp, 126u * US);
    TEST_ASSERT_EQUAL_UINT32(2u, fp.nframes);
    TEST_ASSERT_EQUAL_UINT32(86u + 40u, fake_port_frame(&fp, 1u)->start_us);
}

/* ---- the normal transaction, step by step */

static void test_normal_transaction(void)
{
    j288_cmd_raw_t cmd = worked_cmd();
    setup();
    fake_port_rx_at(&fp, TX_END_NS + 10u * US + REPLY_NS, WORKED_REPLY3, J288_REPLY_LEN);
    fake_port_idle_at(&fp, TX_END_NS + 10u * US + REPLY_NS + 1667u);

    submit_ok(&cmd);
    TEST_ASSERT_EQUAL_INT(J288_BUS_TX, j288_bus_state(&bus));
    TEST_ASSERT_EQUAL_UINT32(1u, fp.nframes);
    assert_frame(0u, WORKED_CMD3);
    TEST_ASSERT_EQUAL_INT(J288_DIR_TX, fp.dir);
    TEST_ASSERT_EQUAL_INT(J288_ERR_BUSY, j288_bus_submit(&bus, &cmd, 0u, on_done, &cb));

    fake_port_run_until(&fp, TX_END_NS);
    TEST_ASSERT_EQUAL_INT(J288_BUS_WAIT_REPLY, j288_bus_state(&bus));
    TEST_ASSERT_EQUAL_INT(J288_DIR_RX, fp.dir);
    TEST_ASSERT_EQUAL_UINT32(1u, fp.start_rx_calls);
    TEST_ASSERT_EQUAL_INT(0, cb.calls);

    fake_port_run_until(&fp, TX_END_NS + 10u * US + REPLY_NS);
    TEST_ASSERT_EQUAL_INT(1, cb.calls);
    TEST_ASSERT_EQUAL_PTR(&cb, cb.user);
    TEST_ASSERT_EQUAL_INT(J288_BUS_GUARD, cb.state_in_cb);
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT8(3u, cb.txn.id);
    TEST_ASSERT_EQUAL_UINT8(1u, cb.txn.attempts);
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.attempt_result[0]);
    TEST_ASSERT_EQUAL_UINT32(0u, cb.txn.start_us);
    TEST_ASSERT_EQUAL_UINT32(86u, cb.txn.latency_us);
    TEST_ASSERT_EQUAL_UINT8(3u, cb.txn.reply.id);
    TEST_ASSERT_EQUAL_UINT8(1u, cb.txn.reply.status);
    TEST_ASSERT_EQUAL_INT8(36, cb.txn.reply.case_temp_c);
    TEST_ASSERT_EQUAL_UINT8(41u, cb.txn.reply.winding_temp_c);
    TEST_ASSERT_EQUAL_UINT8(48u, cb.txn.reply.voltage_raw);
    TEST_ASSERT_EQUAL_INT16(1280, cb.txn.reply.torque);
    TEST_ASSERT_EQUAL_INT16(-41, cb.txn.reply.speed);
    TEST_ASSERT_EQUAL_INT32(5215, cb.txn.reply.pos);
    TEST_ASSERT_EQUAL_UINT16(1000u, cb.txn.reply.out_pos);

    fake_port_run_for(&fp, 10u * US);
    TEST_ASSERT_EQUAL_INT(J288_BUS_IDLE, j288_bus_state(&bus));
    TEST_ASSERT_EQUAL_INT(1, cb.calls);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->transactions);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->attempts);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->ok);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_stats(&bus)->stale_bytes);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_parser_stats(&bus)->frames);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_parser_stats(&bus)->truncated);
    TEST_ASSERT_EQUAL_UINT32(1u, fp.nframes);
    assert_stats_add_up(0u);
}

static void test_worked_lock_frame_through_bus(void)
{
    j288_cmd_raw_t cmd = lock_cmd(0u);
    setup();
    submit_ok(&cmd);
    assert_frame(0u, WORKED_LOCK0);
}

static void run_chunked(uint8_t chunk)
{
    j288_cmd_raw_t cmd = lock_cmd(2u);
    j288_reply_raw_t r = reply_for(2u, -77);
    setup();
    fake_port_add_servo(&fp, 2u, &r);
    fp.servo[2].chunk = chunk;
    submit_ok(&cmd);
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 1000u * US));
    TEST_ASSERT_EQUAL_INT(1, cb.calls);
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.result);
    TEST_ASSERT_EQUAL_INT32(-77, cb.txn.reply.pos);
    TEST_ASSERT_EQUAL_UINT32(86u, cb.txn.latency_us);
    TEST_ASSERT_EQUAL_UINT32(1u, fp.servo[2].commands);
    assert_frame_cmd(0u, &cmd);
}

static void test_reply_in_many_chunks(void)
{
    run_chunked(1u);
    run_chunked(3u);
    run_chunked(7u);
    run_chunked(25u);
}

static void test_reply_as_one_chunk_with_following_noise_is_stale(void)
{
    static const uint8_t noise[3] = {0x11, 0x22, 0x33};
    j288_cmd_raw_t cmd = worked_cmd();
    uint8_t both[J288_REPLY_LEN + 3u];
    setup();
    memcpy(both, WORKED_REPLY3, J288_REPLY_LEN);
    memcpy(&both[J288_REPLY_LEN], noise, 3u);
    fake_port_rx_at(&fp, 90u * US, both, sizeof both);
    submit_ok(&cmd);
    fake_port_run_until(&fp, 100u * US);
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT32(3u, j288_bus_stats(&bus)->stale_bytes);
}

/* ---- echo */

static void test_echo_present(void)
{
    j288_bus_config_t cfg;
    j288_cmd_raw_t cmd = lock_cmd(4u);
    j288_reply_raw_t r = reply_for(4u, 4444);
    memset(&cfg, 0, sizeof cfg);
    cfg.echo = true;
    setup_cfg(&cfg);
    fp.echo = true;
    fp.echo_delay_ns = 3u * US; /* the echo trails the transmit: ECHO state is visible */
    fake_port_add_servo(&fp, 4u, &r);
    submit_ok(&cmd);
    TEST_ASSERT_EQUAL_UINT32(1u, fp.start_rx_calls); /* listening before the transmit */
    fake_port_run_until(&fp, TX_END_NS);
    TEST_ASSERT_EQUAL_INT(J288_BUS_ECHO, j288_bus_state(&bus));
    fake_port_run_until(&fp, TX_END_NS + 3u * US);
    TEST_ASSERT_EQUAL_INT(J288_BUS_WAIT_REPLY, j288_bus_state(&bus));
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 1000u * US));
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.result);
    TEST_ASSERT_EQUAL_INT32(4444, cb.txn.reply.pos);
    TEST_ASSERT_EQUAL_UINT32(1u, fp.start_rx_calls); /* not re-armed at tx done */
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_stats(&bus)->stale_bytes);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_stats(&bus)->collisions);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_parser_stats(&bus)->garbage_bytes);
}

static void test_echo_mismatch_is_collision(void)
{
    j288_bus_config_t cfg;
    j288_cmd_raw_t cmd = lock_cmd(4u);
    j288_reply_raw_t r = reply_for(4u, 4444);
    memset(&cfg, 0, sizeof cfg);
    cfg.echo = true;
    setup_cfg(&cfg);
    fp.echo = true;
    fp.echo_flip_at = 7;
    fake_port_add_servo(&fp, 4u, &r);
    submit_ok(&cmd);
    fake_port_run_until(&fp, TX_END_NS);
    TEST_ASSERT_EQUAL_INT(1, cb.calls); /* ends as soon as our transmit is over */
    TEST_ASSERT_EQUAL_INT(J288_ERR_COLLISION, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT32(33u, cb.txn.latency_us);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->collisions);
    TEST_ASSERT_EQUAL_INT(J288_BUS_GUARD, j288_bus_state(&bus));
    /* The servo's reply falls into the long guard (to a budget after the attempt's
     * deadline, not after the collision): stale, not a result. */
    fake_port_run_until(&fp, 2u * BUDGET_US * US - 1u);
    TEST_ASSERT_EQUAL_INT(J288_BUS_GUARD, j288_bus_state(&bus));
    fake_port_run_until(&fp, 2u * BUDGET_US * US);
    TEST_ASSERT_EQUAL_INT(J288_BUS_IDLE, j288_bus_state(&bus));
    /* the rest of our own echo after the mismatch (12 bytes) and the reply */
    TEST_ASSERT_EQUAL_UINT32(12u + J288_REPLY_LEN, j288_bus_stats(&bus)->stale_bytes);
    TEST_ASSERT_EQUAL_INT(1, cb.calls);
}

static void test_echo_missing_is_collision_at_deadline(void)
{
    j288_bus_config_t cfg;
    j288_cmd_raw_t cmd = lock_cmd(4u);
    memset(&cfg, 0, sizeof cfg);
    cfg.echo = true;
    setup_cfg(&cfg); /* the fake does not echo */
    submit_ok(&cmd);
    fake_port_run_until(&fp, (BUDGET_US - 1u) * US);
    TEST_ASSERT_EQUAL_INT(J288_BUS_ECHO, j288_bus_state(&bus));
    fake_port_run_until(&fp, BUDGET_US * US);
    TEST_ASSERT_EQUAL_INT(J288_ERR_COLLISION, cb.txn.result);
}

/* ---- failures */

static void test_no_reply_times_out_exactly(void)
{
    j288_cmd_raw_t cmd = lock_cmd(9u);
    setup();
    submit_ok(&cmd);
    fake_port_run_until(&fp, (BUDGET_US - 1u) * US + 999u);
    TEST_ASSERT_EQUAL_INT(0, cb.calls);
    TEST_ASSERT_EQUAL_INT(J288_BUS_WAIT_REPLY, j288_bus_state(&bus));
    fake_port_run_until(&fp, BUDGET_US * US);
    TEST_ASSERT_EQUAL_INT(1, cb.calls);
    TEST_ASSERT_EQUAL_INT(J288_ERR_TIMEOUT, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT32(BUDGET_US, cb.txn.latency_us);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->timeouts);
    /* After a failure the guard is the whole reply budget. */
    fake_port_run_until(&fp, 2u * BUDGET_US * US - 1u);
    TEST_ASSERT_EQUAL_INT(J288_BUS_GUARD, j288_bus_state(&bus));
    fake_port_run_until(&fp, 2u * BUDGET_US * US);
    TEST_ASSERT_EQUAL_INT(J288_BUS_IDLE, j288_bus_state(&bus));
}

static void test_submit_in_guard_waits_for_guard(void)
{
    j288_cmd_raw_t cmd = lock_cmd(9u);
    setup();
    submit_ok(&cmd);
    fake_port_run_until(&fp, BUDGET_US * US + 5u * US);
    TEST_ASSERT_EQUAL_INT(J288_BUS_GUARD, j288_bus_state(&bus));
    submit_ok(&cmd); /* accepted, queued behind the guard */
    TEST_ASSERT_EQUAL_INT(J288_ERR_BUSY, j288_bus_submit(&bus, &cmd, 0u, on_done, &cb));
    TEST_ASSERT_EQUAL_UINT32(1u, fp.nframes);
    fake_port_run_until(&fp, 2u * BUDGET_US * US);
    TEST_ASSERT_EQUAL_UINT32(2u, fp.nframes);
    TEST_ASSERT_EQUAL_UINT32(2u * BUDGET_US, fake_port_frame(&fp, 1u)->start_us);
    TEST_ASSERT_EQUAL_INT(J288_BUS_TX, j288_bus_state(&bus));
}

static void test_late_reply_in_guard_is_stale(void)
{
    j288_cmd_raw_t cmd = lock_cmd(3u);
    j288_reply_raw_t r = reply_for(3u, 111);
    setup();
    fake_port_add_servo(&fp, 3u, &r);
    fp.servo[3].extra_delay_ns = 120u * US; /* reply ends at ~207 us: after the 147 us deadline */
    submit_ok(&cmd);
    fake_port_run_until(&fp, 200u * US);
    TEST_ASSERT_EQUAL_INT(J288_ERR_TIMEOUT, cb.txn.result);
    /* Submitted now: queued; the late bytes arrive in the guard. */
    fp.servo[3].extra_delay_ns = 0u;
    fp.servo[3].reply.pos = 222;
    submit_ok(&cmd);
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 2000u * US));
    TEST_ASSERT_EQUAL_INT(2, cb.calls);
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.result);
    TEST_ASSERT_EQUAL_INT32(222, cb.txn.reply.pos); /* the fresh reply, not the late one */
    TEST_ASSERT_EQUAL_UINT32(J288_REPLY_LEN, j288_bus_stats(&bus)->stale_bytes);
    TEST_ASSERT_EQUAL_UINT32(2u * BUDGET_US, fake_port_frame(&fp, 1u)->start_us);
}

static void test_late_reply_during_next_transaction_not_credited(void)
{
    j288_cmd_raw_t c3 = lock_cmd(3u);
    j288_cmd_raw_t c4 = lock_cmd(4u);
    j288_reply_raw_t r3 = reply_for(3u, 333);
    j288_reply_raw_t r4 = reply_for(4u, 444);
    uint8_t late[J288_REPLY_LEN];
    setup();
    fake_port_add_servo(&fp, 4u, &r4);
    fp.servo[4].turnaround_ns = 60u * US;
    submit_ok(&c3); /* servo 3 stays silent... */
    fake_port_run_until(&fp, BUDGET_US * US);
    TEST_ASSERT_EQUAL_INT(J288_ERR_TIMEOUT, cb.txn.result);
    submit_ok(&c4); /* starts at 294 us */
    /* ...and answers very late, inside servo 4's reply window. */
    fake_port_encode_reply(&r3, late);
    fake_port_rx_paced(&fp, (2u * BUDGET_US + 34u + 5u) * US, late, J288_REPLY_LEN);
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 2000u * US));
    TEST_ASSERT_EQUAL_INT(2, cb.calls);
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT8(4u, cb.txn.id);
    TEST_ASSERT_EQUAL_UINT8(4u, cb.txn.reply.id);
    TEST_ASSERT_EQUAL_INT32(444, cb.txn.reply.pos);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->wrong_id);
    TEST_ASSERT_EQUAL_UINT32(2u, j288_bus_parser_stats(&bus)->frames);
}

static void test_late_reply_during_next_transmit_is_stale(void)
{
    j288_cmd_raw_t c3 = lock_cmd(3u);
    uint8_t late[J288_REPLY_LEN];
    j288_reply_raw_t r3 = reply_for(3u, 333);
    setup();
    submit_ok(&c3);
    fake_port_run_until(&fp, 2u * BUDGET_US * US);
    TEST_ASSERT_EQUAL_INT(J288_ERR_TIMEOUT, cb.txn.result);
    TEST_ASSERT_EQUAL_INT(J288_BUS_IDLE, j288_bus_state(&bus));
    submit_ok(&c3);
    /* The old reply lands while our next command is still on the wire. */
    fake_port_encode_reply(&r3, late);
    fake_port_rx_at(&fp, 2u * BUDGET_US * US + 20u * US, late, J288_REPLY_LEN);
    fake_port_run_until(&fp, 3u * BUDGET_US * US);
    TEST_ASSERT_EQUAL_INT(2, cb.calls);
    TEST_ASSERT_EQUAL_INT(J288_ERR_TIMEOUT, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT32(J288_REPLY_LEN, j288_bus_stats(&bus)->stale_bytes);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_parser_stats(&bus)->frames);
}

static void test_bytes_before_tx_done_in_same_poll_are_stale(void)
{
    /* Poll only once after both the stale bytes and tx done were recorded. */
    j288_cmd_raw_t c3 = lock_cmd(3u);
    uint8_t early[J288_REPLY_LEN];
    j288_reply_raw_t r3 = reply_for(3u, 333);
    setup();
    fp.poll_fn = NULL;
    submit_ok(&c3);
    fake_port_encode_reply(&r3, early);
    fake_port_rx_at(&fp, 10u * US, early, J288_REPLY_LEN);
    fake_port_rx_at(&fp, 60u * US, WORKED_REPLY3, 5u); /* after tx done: reply window */
    fake_port_run_until(&fp, 100u * US);
    j288_bus_poll(&bus, fake_port_now_us(&fp));
    TEST_ASSERT_EQUAL_UINT32(J288_REPLY_LEN, j288_bus_stats(&bus)->stale_bytes);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_parser_stats(&bus)->frames);
    TEST_ASSERT_EQUAL_UINT32(5u, j288_parser_pending(&bus.parser));
}

static void test_wrong_id_only(void)
{
    j288_cmd_raw_t cmd = lock_cmd(5u);
    j288_reply_raw_t r = reply_for(5u, 55);
    setup();
    fake_port_add_servo(&fp, 5u, &r);
    fp.servo[5].reply_id = 7;
    submit_ok(&cmd);
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 2000u * US));
    TEST_ASSERT_EQUAL_INT(1, cb.calls);
    TEST_ASSERT_EQUAL_INT(J288_ERR_WRONG_ID, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT32(BUDGET_US, cb.txn.latency_us); /* waits for the right one */
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->wrong_id);
}

static void test_two_servos_with_one_id(void)
{
    j288_cmd_raw_t c3 = lock_cmd(3u);
    j288_cmd_raw_t c4 = lock_cmd(4u);
    j288_reply_raw_t r3 = reply_for(3u, 300);
    j288_reply_raw_t r4 = reply_for(4u, 400);
    setup();
    fake_port_add_servo(&fp, 3u, &r3);
    fp.servo[3].twin = true; /* its twin answers 38 us after it */
    fp.servo[3].twin_gap_ns = 38u * US;
    fake_port_add_servo(&fp, 4u, &r4);
    fp.servo[4].turnaround_ns = 50u * US;
    submit_ok(&c3);
    fake_port_run_until(&fp, 87u * US);
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.result);
    TEST_ASSERT_EQUAL_INT32(300, cb.txn.reply.pos); /* the first answer */
    submit_ok(&c4);                                 /* in the 2 us guard: queued */
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 2000u * US));
    TEST_ASSERT_EQUAL_INT(2, cb.calls);
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.result);
    TEST_ASSERT_EQUAL_INT32(400, cb.txn.reply.pos); /* the twin's 1300 was not taken */
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->wrong_id);
}

static void test_corrupted_reply(void)
{
    j288_cmd_raw_t cmd = lock_cmd(6u);
    j288_reply_raw_t r = reply_for(6u, 66);
    setup();
    fake_port_add_servo(&fp, 6u, &r);
    fp.servo[6].corrupt = true;
    submit_ok(&cmd);
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 2000u * US));
    TEST_ASSERT_EQUAL_INT(J288_ERR_CRC, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT32(BUDGET_US, cb.txn.latency_us);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->crc_errors);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_parser_stats(&bus)->crc_errors);
}

static void test_truncated_reply_with_and_without_idle(void)
{
    j288_cmd_raw_t cmd = lock_cmd(6u);
    j288_reply_raw_t r = reply_for(6u, 66);
    int pass;
    for (pass = 0; pass < 2; pass++) {
        setup();
        fp.idle = (pass == 0);
        fake_port_add_servo(&fp, 6u, &r);
        fp.servo[6].truncate = true;
        submit_ok(&cmd);
        TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 2000u * US));
        TEST_ASSERT_EQUAL_INT(J288_ERR_TRUNCATED, cb.txn.result);
        TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->crc_errors);
        TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_parser_stats(&bus)->truncated);
    }
}

static void test_garbage_before_reply(void)
{
    j288_cmd_raw_t cmd = lock_cmd(8u);
    j288_reply_raw_t r = reply_for(8u, 88);
    setup();
    fake_port_add_servo(&fp, 8u, &r);
    fp.servo[8].garbage = 9u;
    fp.servo[8].chunk = 4u;
    submit_ok(&cmd);
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 2000u * US));
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.result);
    TEST_ASSERT_EQUAL_INT32(88, cb.txn.reply.pos);
    TEST_ASSERT_EQUAL_UINT32(86u + 15u, cb.txn.latency_us); /* 9 more byte times */
    TEST_ASSERT_EQUAL_UINT32(9u, j288_bus_parser_stats(&bus)->garbage_bytes);
}

static void test_broadcast_waits_for_no_reply(void)
{
    j288_cmd_raw_t cmd = lock_cmd(J288_BROADCAST_ID);
    j288_reply_raw_t r = reply_for(1u, 1);
    static const uint8_t noise[4] = {0xfc, 0xee, 0x01, 0x02};
    setup();
    fake_port_add_servo(&fp, 1u, &r);
    fake_port_add_servo(&fp, 2u, &r);
    fake_port_rx_at(&fp, 40u * US, noise, sizeof noise);
    submit_ok(&cmd);
    fake_port_run_until(&fp, TX_END_NS);
    TEST_ASSERT_EQUAL_INT(1, cb.calls);
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT8(J288_BROADCAST_ID, cb.txn.id);
    TEST_ASSERT_EQUAL_UINT32(33u, cb.txn.latency_us);
    TEST_ASSERT_EQUAL_UINT32(1u, fp.servo[1].commands);
    TEST_ASSERT_EQUAL_UINT32(1u, fp.servo[2].commands);
    TEST_ASSERT_EQUAL_UINT8(15u, fp.servo[2].last_cmd.id);
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 2000u * US));
    TEST_ASSERT_EQUAL_UINT32(4u, j288_bus_stats(&bus)->stale_bytes);
    TEST_ASSERT_EQUAL_INT(1, cb.calls);
}

/* ---- retries */

static void test_retries_keep_each_reason(void)
{
    j288_bus_config_t cfg;
    j288_cmd_raw_t cmd = lock_cmd(3u);
    j288_reply_raw_t r = reply_for(3u, 31);
    memset(&cfg, 0, sizeof cfg);
    cfg.retries = 3u;
    setup_cfg(&cfg);
    fp.start_tx_fail = 1; /* attempt 1: port error; 2: silent; 3: corrupt; 4: good */
    submit_ok(&cmd);
    TEST_ASSERT_EQUAL_UINT32(0u, fp.nframes);
    fake_port_run_until(&fp, 2u * BUDGET_US * US);
    TEST_ASSERT_EQUAL_UINT32(1u, fp.nframes);
    fake_port_run_until(&fp, 4u * BUDGET_US * US - 1u);
    TEST_ASSERT_EQUAL_INT(0, cb.calls);
    fake_port_add_servo(&fp, 3u, &r);
    fp.servo[3].corrupt = true;
    fake_port_run_until(&fp, 4u * BUDGET_US * US + 40u * US); /* servo heard attempt 3 */
    TEST_ASSERT_EQUAL_UINT32(2u, fp.nframes);
    fp.servo[3].corrupt = false;
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 5000u * US));
    TEST_ASSERT_EQUAL_INT(1, cb.calls);
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT8(4u, cb.txn.attempts);
    TEST_ASSERT_EQUAL_INT(J288_ERR_PORT, cb.txn.attempt_result[0]);
    TEST_ASSERT_EQUAL_INT(J288_ERR_TIMEOUT, cb.txn.attempt_result[1]);
    TEST_ASSERT_EQUAL_INT(J288_ERR_CRC, cb.txn.attempt_result[2]);
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.attempt_result[3]);
    TEST_ASSERT_EQUAL_UINT32(3u, fp.nframes);
    assert_frame_cmd(0u, &cmd);
    assert_frame_cmd(1u, &cmd);
    assert_frame_cmd(2u, &cmd);
    /* each retry a budget after the failed attempt's deadline (the port error at 0 too) */
    TEST_ASSERT_EQUAL_UINT32(2u * BUDGET_US, fake_port_frame(&fp, 0u)->start_us);
    TEST_ASSERT_EQUAL_UINT32(4u * BUDGET_US, fake_port_frame(&fp, 1u)->start_us);
    TEST_ASSERT_EQUAL_UINT32(6u * BUDGET_US, fake_port_frame(&fp, 2u)->start_us);
    TEST_ASSERT_EQUAL_UINT32(6u * BUDGET_US, cb.txn.start_us);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->transactions);
    TEST_ASSERT_EQUAL_UINT32(4u, j288_bus_stats(&bus)->attempts);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->port_errors);
}

static void test_retries_exhausted(void)
{
    j288_bus_config_t cfg;
    j288_cmd_raw_t cmd = lock_cmd(3u);
    memset(&cfg, 0, sizeof cfg);
    cfg.retries = 2u;
    setup_cfg(&cfg);
    submit_ok(&cmd);
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 5000u * US));
    TEST_ASSERT_EQUAL_INT(1, cb.calls);
    TEST_ASSERT_EQUAL_INT(J288_ERR_TIMEOUT, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT8(3u, cb.txn.attempts);
    TEST_ASSERT_EQUAL_UINT32(3u, fp.nframes);
    TEST_ASSERT_EQUAL_UINT32(3u, j288_bus_stats(&bus)->timeouts);
}

/* failed counts transactions (after all their retries), not attempts; aborted and ok not. */
static void test_failed_counts_transactions(void)
{
    j288_bus_config_t cfg;
    j288_cmd_raw_t cmd = lock_cmd(3u);
    j288_reply_raw_t r = reply_for(3u, 31);
    memset(&cfg, 0, sizeof cfg);
    cfg.retries = 2u;
    setup_cfg(&cfg);
    submit_ok(&cmd); /* nobody answers: 3 attempts, 1 failed transaction */
    assert_stats_add_up(1u);
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 5000u * US));
    TEST_ASSERT_EQUAL_INT(J288_ERR_TIMEOUT, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT32(3u, j288_bus_stats(&bus)->timeouts);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->failed);
    assert_stats_add_up(0u);

    fake_port_add_servo(&fp, 3u, &r); /* a success */
    submit_ok(&cmd);
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, fp.now_ns + 5000u * US));
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->failed);
    assert_stats_add_up(0u);

    submit_ok(&cmd); /* aborted by a stop: aborted, not failed */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_estop(&bus, fake_port_now_us(&fp)));
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, fp.now_ns + 5000u * US));
    TEST_ASSERT_EQUAL_INT(J288_ERR_ABORTED, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->failed);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->aborted);
    assert_stats_add_up(0u);

    fp.start_tx_fail = 3; /* port errors on every attempt: failed */
    submit_ok(&cmd);
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, fp.now_ns + 5000u * US));
    TEST_ASSERT_EQUAL_INT(J288_ERR_PORT, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT32(2u, j288_bus_stats(&bus)->failed);
    TEST_ASSERT_EQUAL_UINT32(4u, j288_bus_stats(&bus)->transactions);
    assert_stats_add_up(0u);
}

/* While a failed attempt waits to be re-sent: a submit is refused, an estop ends the
 * transaction (its attempts' reasons kept) and the stop goes out at once. */
static void test_estop_and_submit_while_waiting_to_retry(void)
{
    j288_bus_config_t cfg;
    j288_cmd_raw_t cmd = lock_cmd(3u);
    j288_cmd_raw_t stop = stop_cmd();
    memset(&cfg, 0, sizeof cfg);
    cfg.retries = 2u;
    setup_cfg(&cfg);
    submit_ok(&cmd);
    fake_port_run_until(&fp, 150u * US); /* attempt 1 timed out at 147; retry due at 294 */
    TEST_ASSERT_EQUAL_INT(J288_BUS_GUARD, j288_bus_state(&bus));
    TEST_ASSERT_EQUAL_INT(J288_ERR_BUSY, j288_bus_submit(&bus, &cmd, 150u, on_done, &cb));
    TEST_ASSERT_EQUAL_INT(0, cb.calls);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_estop(&bus, 150u));
    TEST_ASSERT_EQUAL_INT(1, cb.calls);
    TEST_ASSERT_EQUAL_INT(J288_ERR_ABORTED, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT8(1u, cb.txn.attempts);
    TEST_ASSERT_EQUAL_INT(J288_ERR_TIMEOUT, cb.txn.attempt_result[0]);
    TEST_ASSERT_EQUAL_UINT32(2u, fp.nframes);
    assert_frame_cmd(1u, &stop);
    TEST_ASSERT_EQUAL_UINT32(150u, fake_port_frame(&fp, 1u)->start_us);
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 5000u * US));
    TEST_ASSERT_EQUAL_UINT32(2u, fp.nframes); /* the retry never went out */
    assert_stats_add_up(0u);

    /* estop while the attempt is on the wire, which then fails: no retry either */
    setup_cfg(&cfg);
    submit_ok(&cmd);
    fake_port_run_until(&fp, 50u * US);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_estop(&bus, 50u));
    fake_port_run_until(&fp, BUDGET_US * US);
    TEST_ASSERT_EQUAL_INT(1, cb.calls);
    TEST_ASSERT_EQUAL_INT(J288_ERR_ABORTED, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT8(1u, cb.txn.attempts);
    TEST_ASSERT_EQUAL_INT(J288_ERR_TIMEOUT, cb.txn.attempt_result[0]);
    TEST_ASSERT_EQUAL_UINT32(2u, fp.nframes);
    assert_frame_cmd(1u, &stop);
    TEST_ASSERT_EQUAL_UINT32(BUDGET_US, fake_port_frame(&fp, 1u)->start_us);
}

/* A broadcast heard with a line error on the wire is a failed attempt: retried. */
static void test_broadcast_with_line_error_is_retried(void)
{
    j288_bus_config_t cfg;
    j288_cmd_raw_t cmd = lock_cmd(J288_BROADCAST_ID);
    memset(&cfg, 0, sizeof cfg);
    cfg.retries = 1u;
    setup_cfg(&cfg);
    fake_port_error_at(&fp, 10u * US, J288_LINE_NOISE);
    submit_ok(&cmd);
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 5000u * US));
    TEST_ASSERT_EQUAL_INT(1, cb.calls);
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT8(2u, cb.txn.attempts);
    TEST_ASSERT_EQUAL_INT(J288_ERR_LINE, cb.txn.attempt_result[0]);
    TEST_ASSERT_EQUAL_UINT32(2u, fp.nframes);
    /* ended at its tx done (33 us), re-sent a budget after its deadline */
    TEST_ASSERT_EQUAL_UINT32(2u * BUDGET_US, fake_port_frame(&fp, 1u)->start_us);
}

/* ---- line errors */

static void test_line_error_marks_attempt(void)
{
    j288_cmd_raw_t cmd = lock_cmd(3u);
    j288_reply_raw_t r = reply_for(3u, 31);
    setup();
    fake_port_error_at(&fp, 50u * US, J288_LINE_FRAMING);
    submit_ok(&cmd);
    fake_port_run_until(&fp, 400u * US);
    TEST_ASSERT_EQUAL_INT(J288_ERR_LINE, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->line_errors);

    /* A good reply after a line error still counts: its CRC vouches for it. */
    setup();
    fake_port_add_servo(&fp, 3u, &r);
    fake_port_error_at(&fp, 40u * US, J288_LINE_NOISE);
    submit_ok(&cmd);
    fake_port_run_until(&fp, 400u * US);
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.result);

    /* A line error while idle belongs to no transaction. */
    setup();
    fake_port_error_at(&fp, 1u * US, J288_LINE_OVERRUN);
    fake_port_run_until(&fp, 10u * US);
    fake_port_add_servo(&fp, 3u, &r);
    submit_ok(&cmd);
    fake_port_run_until(&fp, 400u * US);
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->line_errors);
}

static void test_line_gone_is_offline_without_retry(void)
{
    j288_bus_config_t cfg;
    j288_cmd_raw_t cmd = lock_cmd(3u);
    memset(&cfg, 0, sizeof cfg);
    cfg.retries = 3u;
    setup_cfg(&cfg);
    fake_port_error_at(&fp, 50u * US, J288_LINE_GONE);
    submit_ok(&cmd);
    fake_port_run_until(&fp, 50u * US);
    TEST_ASSERT_EQUAL_INT(1, cb.calls);
    TEST_ASSERT_EQUAL_INT(J288_ERR_OFFLINE, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT8(1u, cb.txn.attempts);
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 5000u * US));
    TEST_ASSERT_EQUAL_UINT32(1u, fp.nframes);

    /* gone while waiting to retry: ends there, nothing more is sent */
    setup_cfg(&cfg);
    fp.start_tx_fail = 1;
    fake_port_error_at(&fp, 50u * US, J288_LINE_GONE);
    submit_ok(&cmd);
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 5000u * US));
    TEST_ASSERT_EQUAL_INT(1, cb.calls);
    TEST_ASSERT_EQUAL_INT(J288_ERR_OFFLINE, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT8(1u, cb.txn.attempts);
    TEST_ASSERT_EQUAL_INT(J288_ERR_PORT, cb.txn.attempt_result[0]);
    TEST_ASSERT_EQUAL_UINT32(50u, cb.txn.latency_us);
    TEST_ASSERT_EQUAL_UINT32(0u, fp.nframes);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->failed);
}

/* ---- caller errors, busy, tx timeout */

static void test_submit_errors_send_nothing(void)
{
    j288_cmd_raw_t cmd = lock_cmd(3u);
    setup();
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_bus_submit(NULL, &cmd, 0u, NULL, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_bus_submit(&bus, NULL, 0u, NULL, NULL));
    cmd.id = 16u;
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_ID, j288_bus_submit(&bus, &cmd, 0u, NULL, NULL));
    cmd = lock_cmd(3u);
    cmd.status = 2u;
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_STATUS, j288_bus_submit(&bus, &cmd, 0u, NULL, NULL));
    cmd = lock_cmd(3u);
    cmd.kd = -1;
    TEST_ASSERT_EQUAL_INT(J288_ERR_NEG_GAIN, j288_bus_submit(&bus, &cmd, 0u, NULL, NULL));
    TEST_ASSERT_EQUAL_UINT32(0u, fp.nframes);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_stats(&bus)->transactions);
    TEST_ASSERT_EQUAL_INT(J288_BUS_IDLE, j288_bus_state(&bus));
    /* NULL-safe event calls and inspection */
    j288_bus_on_rx(NULL, NULL, 3u);
    j288_bus_on_rx(&bus, NULL, 3u);
    j288_bus_on_tx_done(NULL);
    j288_bus_on_rx_idle(NULL);
    j288_bus_on_error(NULL, 1u);
    j288_bus_on_timer(NULL);
    j288_bus_poll(NULL, 0u);
    j288_bus_on_rx(&bus, WORKED_REPLY3, 0u); /* an empty chunk records nothing */
    j288_bus_poll(&bus, 0u);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_stats(&bus)->stale_bytes);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_stats(&bus)->rx_overflows);
    TEST_ASSERT_NULL(j288_bus_stats(NULL));
    TEST_ASSERT_NULL(j288_bus_parser_stats(NULL));
    TEST_ASSERT_EQUAL_INT(J288_BUS_IDLE, j288_bus_state(NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_bus_transfer_blocking(NULL, &cmd, NULL));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_bus_estop(NULL, 0u));
    /* a NULL callback is fine */
    cmd = lock_cmd(3u);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_submit(&bus, &cmd, 0u, NULL, NULL));
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 5000u * US));
}

static void test_tx_done_never_comes(void)
{
    j288_cmd_raw_t cmd = lock_cmd(3u);
    setup();
    fp.txdone = FAKE_TXDONE_MANUAL;
    submit_ok(&cmd);
    fake_port_run_until(&fp, BUDGET_US * US);
    TEST_ASSERT_EQUAL_INT(J288_ERR_TX_TIMEOUT, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->timeouts);
}

static void test_tx_done_inline_os_style(void)
{
    j288_cmd_raw_t cmd = worked_cmd();
    j288_reply_raw_t r = reply_for(3u, 5);
    setup();
    fp.txdone = FAKE_TXDONE_INLINE;
    fake_port_add_servo(&fp, 3u, &r);
    fp.poll_fn = NULL;
    submit_ok(&cmd);
    /* Reported from inside start_tx: recorded, and the receiver was re-armed at once. */
    TEST_ASSERT_EQUAL_UINT32(1u, fp.start_rx_calls);
    TEST_ASSERT_EQUAL_INT(J288_DIR_RX, fp.dir);
    j288_bus_poll(&bus, fake_port_now_us(&fp));
    TEST_ASSERT_EQUAL_INT(J288_BUS_WAIT_REPLY, j288_bus_state(&bus));
    fp.poll_fn = fake_port_poll_bus;
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 5000u * US));
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.result);
}

static void test_rx_overflow_counted(void)
{
    uint8_t junk[100];
    setup();
    memset(junk, 0x42, sizeof junk);
    fp.poll_fn = NULL;
    j288_bus_on_rx(&bus, junk, sizeof junk);
    TEST_ASSERT_EQUAL_UINT32(100u - J288_CONFIG_RX_RING_SIZE, j288_bus_stats(&bus)->rx_overflows);
    j288_bus_poll(&bus, 0u);
    TEST_ASSERT_EQUAL_UINT32(J288_CONFIG_RX_RING_SIZE, j288_bus_stats(&bus)->stale_bytes);
}

static void test_port_crc_hook_is_used(void)
{
    j288_cmd_raw_t cmd = worked_cmd();
    j288_reply_raw_t r = reply_for(3u, 5);
    fake_port_init(&fp);
    fp.ops.crc32 = fake_port_crc32;
    memset(&cb, 0, sizeof cb);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_init(&bus, &fp.ops, &fp, NULL));
    fake_port_attach(&fp, &bus);
    fp.poll_fn = fake_port_poll_bus;
    fp.poll_user = &bus;
    fake_port_add_servo(&fp, 3u, &r);
    submit_ok(&cmd);
    TEST_ASSERT_EQUAL_UINT32(1u, fp.crc_calls); /* the command */
    assert_frame(0u, WORKED_CMD3);
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 5000u * US));
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT32(2u, fp.crc_calls); /* and the reply */
}

/* ---- emergency stop */

static void test_estop_while_busy(void)
{
    j288_cmd_raw_t cmd = lock_cmd(3u);
    j288_cmd_raw_t stop = stop_cmd();
    j288_reply_raw_t r = reply_for(3u, 31);
    setup();
    fake_port_add_servo(&fp, 3u, &r);
    submit_ok(&cmd);
    fake_port_run_until(&fp, 10u * US);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_estop(&bus, fake_port_now_us(&fp)));
    TEST_ASSERT_EQUAL_INT(J288_ERR_BUSY, j288_bus_submit(&bus, &cmd, 0u, on_done, &cb));
    TEST_ASSERT_EQUAL_UINT32(1u, fp.nframes); /* not cut mid-frame */
    fake_port_run_until(&fp, 87u * US);       /* the reply is taken: the line is free */
    TEST_ASSERT_EQUAL_INT(1, cb.calls);
    TEST_ASSERT_EQUAL_INT(J288_ERR_ABORTED, cb.txn.result);
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.attempt_result[0]);
    TEST_ASSERT_EQUAL_UINT32(2u, fp.nframes); /* the stop follows at once */
    assert_frame_cmd(1u, &stop);
    TEST_ASSERT_EQUAL_UINT32(86u, fake_port_frame(&fp, 1u)->start_us);
    TEST_ASSERT_EQUAL_UINT32(1u, fp.servo[3].commands); /* not yet heard */
    TEST_ASSERT_EQUAL_INT(J288_ERR_BUSY, j288_bus_submit(&bus, &cmd, 0u, on_done, &cb));
    fake_port_run_until(&fp, 87u * US + TX_END_NS);
    TEST_ASSERT_EQUAL_UINT32(2u, fp.servo[3].commands);
    TEST_ASSERT_EQUAL_UINT8(15u, fp.servo[3].last_cmd.id);
    TEST_ASSERT_EQUAL_UINT8(J288_MODE_LOCK, fp.servo[3].last_cmd.status);
    TEST_ASSERT_EQUAL_INT(1, cb.calls); /* the stop has no user callback */
    submit_ok(&cmd);                    /* accepted again */
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->estops);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->aborted);
    TEST_ASSERT_EQUAL_UINT32(2u, j288_bus_stats(&bus)->transactions);
    assert_stats_add_up(1u);
}

static void test_estop_idle_and_with_queued_work(void)
{
    j288_cmd_raw_t cmd = lock_cmd(3u);
    j288_cmd_raw_t stop = stop_cmd();
    setup();
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_estop(&bus, 0u));
    TEST_ASSERT_EQUAL_UINT32(1u, fp.nframes);
    assert_frame_cmd(0u, &stop);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_estop(&bus, 0u)); /* already on the wire: once */
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 5000u * US));
    TEST_ASSERT_EQUAL_UINT32(1u, fp.nframes);

    /* A submit queued behind a guard is dropped in favour of the stop. */
    submit_ok(&cmd);
    fake_port_run_until(&fp, fp.now_ns + BUDGET_US * US);
    TEST_ASSERT_EQUAL_INT(J288_ERR_TIMEOUT, cb.txn.result);
    submit_ok(&cmd); /* queued: guard */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_estop(&bus, fake_port_now_us(&fp)));
    TEST_ASSERT_EQUAL_INT(2, cb.calls);
    TEST_ASSERT_EQUAL_INT(J288_ERR_ABORTED, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT8(0u, cb.txn.attempts);
    TEST_ASSERT_EQUAL_UINT32(3u, fp.nframes);
    assert_frame_cmd(2u, &stop);
}

/* The stop frame is not a user transaction: it counts in estops only, never in ok or
 * aborted, whose sums must stay those of the transactions called back. */
static void test_estop_counts_in_estops_only(void)
{
    j288_cmd_raw_t cmd = lock_cmd(3u);
    j288_reply_raw_t r = reply_for(3u, 31);
    setup();
    fake_port_add_servo(&fp, 3u, &r);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_estop(&bus, 0u));
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 5000u * US));
    TEST_ASSERT_EQUAL_UINT32(1u, fp.nframes);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->estops);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->attempts);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_stats(&bus)->transactions);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_stats(&bus)->ok);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_stats(&bus)->aborted);

    /* a transaction aborted by a stop: aborted 1, ok still only the user's successes */
    submit_ok(&cmd);
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, fp.now_ns + 5000u * US));
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.result);
    submit_ok(&cmd);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_estop(&bus, fake_port_now_us(&fp)));
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, fp.now_ns + 5000u * US));
    TEST_ASSERT_EQUAL_INT(2, cb.calls);
    TEST_ASSERT_EQUAL_INT(J288_ERR_ABORTED, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT32(4u, fp.nframes);
    TEST_ASSERT_EQUAL_UINT32(2u, j288_bus_stats(&bus)->estops);
    TEST_ASSERT_EQUAL_UINT32(2u, j288_bus_stats(&bus)->transactions);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->ok);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->aborted);
}

/* A stop frame that did not get out is sent again (with the default retries 0): the lock
 * must reach the servos. Each failure kind, then a dead port (bounded), then a vanished
 * line (at once), then a request merged into a stop that then fails. */
static void test_estop_resent_after_port_error(void)
{
    j288_cmd_raw_t cmd = lock_cmd(3u);
    j288_cmd_raw_t stop = stop_cmd();
    setup();
    fp.start_tx_fail = 1;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_estop(&bus, 0u));
    TEST_ASSERT_EQUAL_UINT32(0u, fp.nframes);
    TEST_ASSERT_EQUAL_INT(J288_ERR_BUSY, j288_bus_submit(&bus, &cmd, 0u, on_done, &cb));
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 5000u * US));
    TEST_ASSERT_EQUAL_UINT32(1u, fp.nframes);
    assert_frame_cmd(0u, &stop);
    /* after the guard of a failed attempt: a budget after its deadline */
    TEST_ASSERT_EQUAL_UINT32(2u * BUDGET_US, fake_port_frame(&fp, 0u)->start_us);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->estops);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_stats(&bus)->estop_failures);
    TEST_ASSERT_EQUAL_UINT32(2u, j288_bus_stats(&bus)->attempts);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->port_errors);
    TEST_ASSERT_EQUAL_INT(0, cb.calls);
}

static void test_estop_resent_after_collision(void)
{
    j288_bus_config_t cfg;
    j288_cmd_raw_t stop = stop_cmd();
    memset(&cfg, 0, sizeof cfg);
    cfg.echo = true;
    setup_cfg(&cfg);
    fp.echo = true;
    fp.echo_flip_at = 7;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_estop(&bus, 0u));
    fake_port_run_until(&fp, TX_END_NS);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->collisions);
    fp.echo_flip_at = -1;
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 5000u * US));
    TEST_ASSERT_EQUAL_UINT32(2u, fp.nframes);
    assert_frame_cmd(1u, &stop);
    TEST_ASSERT_EQUAL_UINT32(2u * BUDGET_US, fake_port_frame(&fp, 1u)->start_us);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->collisions);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->estops);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_stats(&bus)->estop_failures);
}

static void test_estop_resent_after_tx_timeout_and_line_error(void)
{
    j288_cmd_raw_t stop = stop_cmd();
    setup();
    fp.txdone = FAKE_TXDONE_MANUAL; /* the first transmit never completes */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_estop(&bus, 0u));
    fake_port_run_until(&fp, BUDGET_US * US);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->timeouts);
    fp.txdone = FAKE_TXDONE_TIMED;
    fp.tx_busy = false; /* the port gave that transmit up */
    /* the second is heard with a line error on the wire: sent a third time */
    fake_port_error_at(&fp, 2u * BUDGET_US * US + 10u * US, J288_LINE_FRAMING);
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 5000u * US));
    TEST_ASSERT_EQUAL_UINT32(3u, fp.nframes);
    assert_frame_cmd(1u, &stop);
    assert_frame_cmd(2u, &stop);
    TEST_ASSERT_EQUAL_UINT32(2u * BUDGET_US, fake_port_frame(&fp, 1u)->start_us);
    TEST_ASSERT_EQUAL_UINT32(4u * BUDGET_US, fake_port_frame(&fp, 2u)->start_us);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->estops);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_stats(&bus)->estop_failures);
    TEST_ASSERT_EQUAL_UINT32(3u, j288_bus_stats(&bus)->attempts);
    TEST_ASSERT_EQUAL_INT(0, fp.tx_overlap_errors);
}

static void test_estop_dead_port_gives_up_bounded(void)
{
    j288_cmd_raw_t cmd = lock_cmd(3u);
    setup();
    fp.start_tx_fail = 1000;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_estop(&bus, 0u));
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 50000u * US));
    TEST_ASSERT_EQUAL_UINT32(J288_ESTOP_ATTEMPTS, j288_bus_stats(&bus)->attempts);
    TEST_ASSERT_EQUAL_UINT32(J288_ESTOP_ATTEMPTS, j288_bus_stats(&bus)->port_errors);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->estops);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->estop_failures);
    TEST_ASSERT_EQUAL_INT(1000 - (int)J288_ESTOP_ATTEMPTS, fp.start_tx_fail);
    /* each re-send a budget after the failed attempt's deadline; idle as long after the last */
    TEST_ASSERT_EQUAL_UINT32(2u * J288_ESTOP_ATTEMPTS * BUDGET_US, fake_port_now_us(&fp));
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_stats(&bus)->transactions);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_stats(&bus)->failed);
    /* given up: the bus takes work again (and reports the port's error) */
    fp.start_tx_fail = 0;
    submit_ok(&cmd);
    TEST_ASSERT_EQUAL_UINT32(1u, fp.nframes);
}

static void test_estop_line_gone_ends_at_once(void)
{
    setup();
    fp.txdone = FAKE_TXDONE_MANUAL;
    fake_port_error_at(&fp, 20u * US, J288_LINE_GONE); /* during the transmit */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_estop(&bus, 0u));
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 5000u * US));
    TEST_ASSERT_EQUAL_UINT32(1u, fp.nframes);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->attempts);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->estop_failures);

    setup();
    fp.start_tx_fail = 1;
    fake_port_error_at(&fp, 50u * US, J288_LINE_GONE); /* while waiting to send again */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_estop(&bus, 0u));
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 5000u * US));
    TEST_ASSERT_EQUAL_UINT32(0u, fp.nframes);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->attempts);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->estop_failures);
}

static void test_estop_merged_into_failing_stop_starts_again(void)
{
    setup();
    fp.start_tx_fail = 1000;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_estop(&bus, 0u));
    fake_port_run_until(&fp, 100u * US);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_estop(&bus, 100u)); /* merged into the stop */
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->estops);
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 50000u * US));
    /* the first stop failed: the merged request was a stop of its own */
    TEST_ASSERT_EQUAL_UINT32(2u, j288_bus_stats(&bus)->estops);
    TEST_ASSERT_EQUAL_UINT32(2u, j288_bus_stats(&bus)->estop_failures);
    TEST_ASSERT_EQUAL_UINT32(2u * J288_ESTOP_ATTEMPTS, j288_bus_stats(&bus)->attempts);

    /* merged into a stop that then gets out: sent once */
    setup();
    fp.start_tx_fail = 1;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_estop(&bus, 0u));
    fake_port_run_until(&fp, 100u * US);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_estop(&bus, 100u));
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 50000u * US));
    TEST_ASSERT_EQUAL_UINT32(1u, fp.nframes);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->estops);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_stats(&bus)->estop_failures);
}

/* ---- advance in ISR */

static int chain_left;

static void on_done_chain(void *user, const j288_txn_t *txn)
{
    j288_cmd_raw_t next = lock_cmd((uint8_t)(txn->id + 1u));
    uint8_t id = txn->id;
    if (chain_left > 0) {
        chain_left--;
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_submit(&bus, &next, 0u, on_done_chain, user));
    }
    /* txn is still this transaction's, although the next one was submitted */
    TEST_ASSERT_EQUAL_UINT8(id, txn->id);
    on_done(user, txn);
}

static void test_advance_in_isr_chains_without_poll(void)
{
    j288_bus_config_t cfg;
    j288_cmd_raw_t cmd = lock_cmd(0u);
    uint8_t i;
    memset(&cfg, 0, sizeof cfg);
    cfg.advance_in_isr = true;
    setup_cfg(&cfg);
    fp.poll_fn = NULL; /* nobody polls: events and the timer drive everything */
    for (i = 0u; i < 5u; i++) {
        j288_reply_raw_t r = reply_for(i, 1000 + i);
        if (i != 2u) {
            fake_port_add_servo(&fp, i, &r); /* 2 is missing: a timeout via the timer */
        }
    }
    chain_left = 4;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_submit(&bus, &cmd, 0u, on_done_chain, &cb));
    TEST_ASSERT_EQUAL_UINT32(1u, fp.lock_calls);
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 5000u * US));
    TEST_ASSERT_EQUAL_INT(5, cb.calls);
    TEST_ASSERT_EQUAL_UINT32(5u, fp.nframes);
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.result);
    TEST_ASSERT_EQUAL_INT32(1004, cb.txn.reply.pos);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->timeouts);
    TEST_ASSERT_EQUAL_UINT32(4u, j288_bus_stats(&bus)->ok);
    TEST_ASSERT_EQUAL_INT(0, fp.lock_errors);
    TEST_ASSERT_EQUAL_INT(0, fp.lock_depth);
    TEST_ASSERT_EQUAL_INT(0, fp.tx_overlap_errors);
    /* back to back: frame 1 starts 2 us (guard) after reply 0 ended at 86.67 us */
    TEST_ASSERT_EQUAL_UINT32(88u, fake_port_frame(&fp, 1u)->start_us);
    TEST_ASSERT_TRUE(fp.timer_fires > 0u);
}

static void test_advance_in_isr_with_inline_tx_done(void)
{
    j288_bus_config_t cfg;
    j288_cmd_raw_t cmd = lock_cmd(0u);
    uint8_t i;
    memset(&cfg, 0, sizeof cfg);
    cfg.advance_in_isr = true;
    setup_cfg(&cfg);
    fp.poll_fn = NULL;
    fp.txdone = FAKE_TXDONE_INLINE; /* tx done re-enters the bus from inside start_tx */
    for (i = 0u; i < 4u; i++) {
        j288_reply_raw_t r = reply_for(i, 2000 + i);
        fake_port_add_servo(&fp, i, &r);
    }
    chain_left = 3;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_submit(&bus, &cmd, 0u, on_done_chain, &cb));
    TEST_ASSERT_EQUAL_INT(J288_BUS_WAIT_REPLY, j288_bus_state(&bus));
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 5000u * US));
    TEST_ASSERT_EQUAL_INT(4, cb.calls);
    TEST_ASSERT_EQUAL_INT32(2003, cb.txn.reply.pos);
    TEST_ASSERT_EQUAL_UINT32(4u, j288_bus_stats(&bus)->ok);
    TEST_ASSERT_EQUAL_UINT32(4u, fp.start_rx_calls);
    TEST_ASSERT_EQUAL_INT(0, fp.lock_errors);
}

/* Advanced in the event calls, with no timer to wake it: a transmit that completes after the
 * reply deadline ends the attempt there (TIMEOUT), as the general pass of the machine does; a
 * reply only waits while the deadline is ahead. */
static void test_isr_tx_done_after_deadline_times_out(void)
{
    j288_bus_config_t cfg;
    j288_cmd_raw_t cmd = lock_cmd(3u);
    memset(&cfg, 0, sizeof cfg);
    cfg.advance_in_isr = true;
    setup_cfg(&cfg);
    fp.ops.arm_timeout = NULL;
    fp.poll_fn = NULL;
    fp.txdone = FAKE_TXDONE_MANUAL;
    submit_ok(&cmd);
    fake_port_tx_done_at(&fp, (uint64_t)(BUDGET_US + 1u) * US);
    fake_port_run_until(&fp, (uint64_t)(BUDGET_US + 2u) * US);
    TEST_ASSERT_EQUAL_INT(1, cb.calls);
    TEST_ASSERT_EQUAL_INT(J288_ERR_TIMEOUT, cb.txn.result);
    TEST_ASSERT_EQUAL_INT(J288_BUS_GUARD, j288_bus_state(&bus));
}

/* ---- the event calls' fast paths (advance_in_isr): each case the general pass treats
 * differently from "the awaited transition" must still be treated that way. Events are
 * delivered by hand, as the interrupts would, with nobody polling. */

static void setup_isr_manual(bool echo)
{
    j288_bus_config_t cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.advance_in_isr = true;
    cfg.echo = echo;
    setup_cfg(&cfg);
    fp.poll_fn = NULL;
    fp.txdone = FAKE_TXDONE_MANUAL;
}

/* Transmit complete before its echo was heard whole: the echo is still awaited. */
static void test_isr_tx_done_before_echo_waits_for_echo(void)
{
    j288_cmd_raw_t cmd = worked_cmd();
    setup_isr_manual(true);
    submit_ok(&cmd);
    j288_bus_on_rx(&bus, WORKED_CMD3, 10u);
    j288_bus_on_tx_done(&bus);
    TEST_ASSERT_EQUAL_INT(J288_BUS_ECHO, j288_bus_state(&bus));
    j288_bus_on_rx(&bus, &WORKED_CMD3[10], 10u);
    TEST_ASSERT_EQUAL_INT(J288_BUS_WAIT_REPLY, j288_bus_state(&bus));
    j288_bus_on_rx(&bus, WORKED_REPLY3, J288_REPLY_LEN);
    TEST_ASSERT_EQUAL_INT(1, cb.calls);
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.result);
}

/* A transmit-complete nobody asked for (idle, or a second one in the guard) changes no state. */
static void test_isr_spurious_tx_done_changes_nothing(void)
{
    j288_cmd_raw_t cmd = worked_cmd();
    setup_isr_manual(false);
    j288_bus_on_tx_done(&bus);
    TEST_ASSERT_EQUAL_INT(J288_BUS_IDLE, j288_bus_state(&bus));
    submit_ok(&cmd);
    j288_bus_on_tx_done(&bus);
    j288_bus_on_rx(&bus, WORKED_REPLY3, J288_REPLY_LEN);
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.result);
    TEST_ASSERT_EQUAL_INT32(5215, cb.txn.reply.pos);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_parser_stats(&bus)->frames);
    TEST_ASSERT_EQUAL_INT(J288_BUS_GUARD, j288_bus_state(&bus));
    j288_bus_on_tx_done(&bus);
    TEST_ASSERT_EQUAL_INT(J288_BUS_GUARD, j288_bus_state(&bus));
    j288_bus_on_rx(&bus, WORKED_REPLY3, J288_REPLY_LEN);
    TEST_ASSERT_EQUAL_INT(1, cb.calls);
    TEST_ASSERT_EQUAL_UINT32(J288_REPLY_LEN, j288_bus_stats(&bus)->stale_bytes);
}

/* The stop is a broadcast: done at its transmit-complete, no reply awaited. */
static void test_isr_estop_ends_at_tx_done(void)
{
    setup_isr_manual(false);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_estop(&bus, 0u));
    TEST_ASSERT_EQUAL_INT(J288_BUS_TX, j288_bus_state(&bus));
    j288_bus_on_tx_done(&bus);
    TEST_ASSERT_EQUAL_INT(J288_BUS_GUARD, j288_bus_state(&bus));
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->estops);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_stats(&bus)->estop_failures);
    TEST_ASSERT_EQUAL_UINT32(1u, fp.nframes);
}

/* A whole reply heard before our transmit completed belongs to nobody. */
static void test_isr_reply_before_tx_done_is_stale(void)
{
    j288_cmd_raw_t cmd = worked_cmd();
    setup_isr_manual(false);
    submit_ok(&cmd);
    j288_bus_on_rx(&bus, WORKED_REPLY3, J288_REPLY_LEN);
    TEST_ASSERT_EQUAL_INT(0, cb.calls);
    TEST_ASSERT_EQUAL_UINT32(J288_REPLY_LEN, j288_bus_stats(&bus)->stale_bytes);
    j288_bus_on_tx_done(&bus);
    TEST_ASSERT_EQUAL_INT(J288_BUS_WAIT_REPLY, j288_bus_state(&bus));
}

/* A reply and one more byte in one call: the reply is taken, the byte counted stale. */
static void test_isr_reply_with_trailing_byte(void)
{
    j288_cmd_raw_t cmd = worked_cmd();
    uint8_t rx[J288_REPLY_LEN + 1u];
    memcpy(rx, WORKED_REPLY3, J288_REPLY_LEN);
    rx[J288_REPLY_LEN] = 0x5au;
    setup_isr_manual(false);
    submit_ok(&cmd);
    j288_bus_on_tx_done(&bus);
    j288_bus_on_rx(&bus, rx, sizeof rx);
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->stale_bytes);
}

/* A partial frame held by the parser, then a whole reply in one call: the held head and the
 * new bytes make one bad frame first (the byte path's order), then the reply is found. */
static void test_isr_whole_reply_after_partial(void)
{
    j288_cmd_raw_t cmd = worked_cmd();
    setup_isr_manual(false);
    submit_ok(&cmd);
    j288_bus_on_tx_done(&bus);
    j288_bus_on_rx(&bus, WORKED_REPLY3, 10u);
    j288_bus_on_rx(&bus, WORKED_REPLY3, J288_REPLY_LEN);
    TEST_ASSERT_EQUAL_INT(1, cb.calls);
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->crc_errors);
}

/* The CRC does not cover the head: a frame with a wrong head but a good CRC is no reply. */
static void test_isr_reply_with_bad_head_refused(void)
{
    j288_cmd_raw_t cmd = worked_cmd();
    uint8_t rx[J288_REPLY_LEN];
    memcpy(rx, WORKED_REPLY3, J288_REPLY_LEN);
    rx[1] = 0xefu;
    setup_isr_manual(false);
    submit_ok(&cmd);
    j288_bus_on_tx_done(&bus);
    j288_bus_on_rx(&bus, rx, sizeof rx);
    TEST_ASSERT_EQUAL_INT(0, cb.calls);
    TEST_ASSERT_EQUAL_INT(J288_BUS_WAIT_REPLY, j288_bus_state(&bus));
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_parser_stats(&bus)->frames);
}

/* Whole replies that are not ours, each in one call: with a bad CRC (counted), from another
 * id (noted, the reply still awaited), then ours, taken and counted once by the parser. */
static void test_isr_whole_replies_wrong_id_bad_crc_then_ours(void)
{
    j288_cmd_raw_t cmd = worked_cmd();
    j288_reply_raw_t r7 = reply_for(7u, 7);
    uint8_t other[J288_REPLY_LEN], bad[J288_REPLY_LEN];
    fake_port_encode_reply(&r7, other);
    memcpy(bad, WORKED_REPLY3, J288_REPLY_LEN);
    bad[12] ^= 0x40u;
    setup_isr_manual(false);
    submit_ok(&cmd);
    j288_bus_on_tx_done(&bus);
    j288_bus_on_rx(&bus, bad, sizeof bad);
    TEST_ASSERT_EQUAL_INT(0, cb.calls);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->crc_errors);
    j288_bus_on_rx(&bus, other, sizeof other);
    TEST_ASSERT_EQUAL_INT(0, cb.calls);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->wrong_id);
    TEST_ASSERT_EQUAL_INT(J288_BUS_WAIT_REPLY, j288_bus_state(&bus));
    j288_bus_on_rx(&bus, WORKED_REPLY3, J288_REPLY_LEN);
    TEST_ASSERT_EQUAL_INT(1, cb.calls);
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.result);
    TEST_ASSERT_EQUAL_INT32(5215, cb.txn.reply.pos);
    TEST_ASSERT_EQUAL_UINT32(2u, j288_bus_parser_stats(&bus)->frames); /* id 7's and ours */
}

/* The first whole reply after the transmit, from another id: noted, not taken. */
static void test_isr_first_whole_reply_from_another_id(void)
{
    j288_cmd_raw_t cmd = worked_cmd();
    j288_reply_raw_t r7 = reply_for(7u, 7);
    uint8_t other[J288_REPLY_LEN];
    fake_port_encode_reply(&r7, other);
    setup_isr_manual(false);
    submit_ok(&cmd);
    j288_bus_on_tx_done(&bus);
    j288_bus_on_rx(&bus, other, sizeof other);
    TEST_ASSERT_EQUAL_INT(0, cb.calls);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->wrong_id);
    TEST_ASSERT_EQUAL_INT(J288_BUS_WAIT_REPLY, j288_bus_state(&bus));
}

/* A completion that hears 5 more bytes (put in the ring: the bus is advancing) and submits
 * the next command, which waits for the guard. */
static void on_done_noise_then_submit(void *user, const j288_txn_t *txn)
{
    j288_cmd_raw_t cmd = worked_cmd();
    on_done(user, txn);
    if (cb.calls == 1) {
        j288_bus_on_rx(&bus, WORKED_REPLY3, 5u);
        TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_submit(&bus, &cmd, fake_port_now_us(&fp),
                                                       on_done_noise_then_submit, user));
    }
}

/* The guard's timer starts the queued submit (the timer's fast path): bytes left in the ring
 * from the guard are counted stale, not taken as the new attempt's reply, and the next reply
 * is taken as usual. */
static void test_isr_guard_timer_starts_queued_after_stale_bytes(void)
{
    j288_cmd_raw_t cmd = worked_cmd();
    setup_isr_manual(false);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_submit(&bus, &cmd, fake_port_now_us(&fp),
                                                   on_done_noise_then_submit, &cb));
    j288_bus_on_tx_done(&bus);
    j288_bus_on_rx(&bus, WORKED_REPLY3, J288_REPLY_LEN);
    TEST_ASSERT_EQUAL_INT(1, cb.calls);
    TEST_ASSERT_EQUAL_INT(J288_BUS_GUARD, j288_bus_state(&bus));
    TEST_ASSERT_EQUAL_UINT32(1u, fp.nframes);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_stats(&bus)->stale_bytes);
    fp.now_ns += (uint64_t)J288_DEFAULT_GUARD_US * US;
    j288_bus_on_timer(&bus);
    TEST_ASSERT_EQUAL_INT(J288_BUS_TX, j288_bus_state(&bus));
    TEST_ASSERT_EQUAL_UINT32(2u, fp.nframes);
    TEST_ASSERT_EQUAL_UINT32(5u, j288_bus_stats(&bus)->stale_bytes);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_stats(&bus)->crc_errors);
    j288_bus_on_tx_done(&bus);
    TEST_ASSERT_EQUAL_INT(J288_BUS_WAIT_REPLY, j288_bus_state(&bus));
    j288_bus_on_rx(&bus, WORKED_REPLY3, J288_REPLY_LEN);
    TEST_ASSERT_EQUAL_INT(2, cb.calls);
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT32(2u, j288_bus_parser_stats(&bus)->frames);
    TEST_ASSERT_EQUAL_UINT32(2u, j288_bus_stats(&bus)->ok);
}

/* A retry waits for the guard after the failure; the guard's timer starts it (the general
 * pass: the timer's fast path only takes a queued submit), and its reply ends the transaction. */
static void test_isr_guard_timer_starts_retry(void)
{
    j288_bus_config_t cfg;
    j288_cmd_raw_t cmd = worked_cmd();
    memset(&cfg, 0, sizeof cfg);
    cfg.advance_in_isr = true;
    cfg.retries = 1u;
    setup_cfg(&cfg);
    fp.poll_fn = NULL;
    fp.txdone = FAKE_TXDONE_MANUAL;
    submit_ok(&cmd);
    j288_bus_on_tx_done(&bus);
    fp.now_ns = (uint64_t)BUDGET_US * US; /* the deadline, no reply */
    j288_bus_on_timer(&bus);
    TEST_ASSERT_EQUAL_INT(J288_BUS_GUARD, j288_bus_state(&bus));
    TEST_ASSERT_EQUAL_INT(0, cb.calls);
    fp.now_ns += (uint64_t)(BUDGET_US - 1u) * US; /* one microsecond before the guard's end */
    j288_bus_on_timer(&bus);
    TEST_ASSERT_EQUAL_UINT32(1u, fp.nframes);
    fp.now_ns += US;
    j288_bus_on_timer(&bus);
    TEST_ASSERT_EQUAL_INT(J288_BUS_TX, j288_bus_state(&bus));
    TEST_ASSERT_EQUAL_UINT32(2u, fp.nframes);
    j288_bus_on_tx_done(&bus);
    j288_bus_on_rx(&bus, WORKED_REPLY3, J288_REPLY_LEN);
    TEST_ASSERT_EQUAL_INT(1, cb.calls);
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT8(2u, cb.txn.attempts);
    TEST_ASSERT_EQUAL_INT(J288_ERR_TIMEOUT, cb.txn.attempt_result[0]);
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.attempt_result[1]);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->timeouts);
}

/* A stop requested while a reply is awaited: the reply, taken whole by the fast path, ends
 * the transaction J288_ERR_ABORTED (its attempt's own result kept), and the stop goes out. */
static void test_isr_reply_under_pending_estop_aborts(void)
{
    j288_cmd_raw_t cmd = worked_cmd();
    j288_cmd_raw_t stop = stop_cmd();
    setup_isr_manual(false);
    submit_ok(&cmd);
    j288_bus_on_tx_done(&bus);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_estop(&bus, fake_port_now_us(&fp)));
    TEST_ASSERT_EQUAL_INT(J288_BUS_WAIT_REPLY, j288_bus_state(&bus));
    j288_bus_on_rx(&bus, WORKED_REPLY3, J288_REPLY_LEN);
    TEST_ASSERT_EQUAL_INT(1, cb.calls);
    TEST_ASSERT_EQUAL_INT(J288_ERR_ABORTED, cb.txn.result);
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.attempt_result[0]);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->aborted);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_stats(&bus)->ok);
    TEST_ASSERT_EQUAL_INT(J288_BUS_TX, j288_bus_state(&bus));
    TEST_ASSERT_EQUAL_UINT32(2u, fp.nframes);
    assert_frame_cmd(1u, &stop);
}

/* Without advance_in_isr the event calls only record: the state moves at the next poll. */
static void test_poll_mode_tx_done_waits_for_poll(void)
{
    j288_cmd_raw_t cmd = worked_cmd();
    setup();
    fp.poll_fn = NULL;
    fp.txdone = FAKE_TXDONE_MANUAL;
    submit_ok(&cmd);
    j288_bus_on_tx_done(&bus);
    TEST_ASSERT_EQUAL_INT(J288_BUS_TX, j288_bus_state(&bus));
    j288_bus_poll(&bus, 0u);
    TEST_ASSERT_EQUAL_INT(J288_BUS_WAIT_REPLY, j288_bus_state(&bus));
}

static void test_failure_ranking(void)
{
    j288_cmd_raw_t cmd = lock_cmd(3u);
    uint8_t bad[J288_REPLY_LEN], other[J288_REPLY_LEN];
    j288_reply_raw_t r7 = reply_for(7u, 7);
    fake_port_encode_reply(&r7, other);
    memcpy(bad, other, sizeof bad);
    bad[12] ^= 0x40u;

    /* crc, then wrong id: wrong id */
    setup();
    fake_port_rx_at(&fp, 50u * US, bad, sizeof bad);
    fake_port_rx_at(&fp, 90u * US, other, sizeof other);
    submit_ok(&cmd);
    fake_port_run_until(&fp, 400u * US);
    TEST_ASSERT_EQUAL_INT(J288_ERR_WRONG_ID, cb.txn.result);

    /* wrong id, then a line error: still wrong id */
    setup();
    fake_port_rx_at(&fp, 50u * US, other, sizeof other);
    fake_port_error_at(&fp, 100u * US, J288_LINE_NOISE);
    submit_ok(&cmd);
    fake_port_run_until(&fp, 400u * US);
    TEST_ASSERT_EQUAL_INT(J288_ERR_WRONG_ID, cb.txn.result);

    /* crc, then a line error: line */
    setup();
    fake_port_rx_at(&fp, 50u * US, bad, sizeof bad);
    fake_port_error_at(&fp, 100u * US, J288_LINE_NOISE);
    submit_ok(&cmd);
    fake_port_run_until(&fp, 400u * US);
    TEST_ASSERT_EQUAL_INT(J288_ERR_LINE, cb.txn.result);

    /* line, then crc: line */
    setup();
    fake_port_error_at(&fp, 40u * US, J288_LINE_FRAMING);
    fake_port_rx_at(&fp, 50u * US, bad, sizeof bad);
    submit_ok(&cmd);
    fake_port_run_until(&fp, 400u * US);
    TEST_ASSERT_EQUAL_INT(J288_ERR_LINE, cb.txn.result);
}

static void test_noise_while_idle_is_not_echo(void)
{
    static const uint8_t noise[3] = {0xfe, 0xee, 0x01};
    j288_bus_config_t cfg;
    j288_cmd_raw_t cmd = lock_cmd(4u);
    j288_reply_raw_t r = reply_for(4u, 4);
    memset(&cfg, 0, sizeof cfg);
    cfg.echo = true;
    setup_cfg(&cfg);
    fp.echo = true;
    fake_port_add_servo(&fp, 4u, &r);
    j288_bus_on_rx(&bus, noise, sizeof noise); /* recorded, nobody polled since */
    submit_ok(&cmd);
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 5000u * US));
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT32(3u, j288_bus_stats(&bus)->stale_bytes);
}

static void test_bytes_after_broadcast_in_same_poll(void)
{
    j288_cmd_raw_t cmd = lock_cmd(J288_BROADCAST_ID);
    setup();
    fp.poll_fn = NULL;
    submit_ok(&cmd);
    fake_port_rx_at(&fp, 50u * US, WORKED_REPLY3, J288_REPLY_LEN);
    fake_port_run_until(&fp, 100u * US);
    j288_bus_poll(&bus, fake_port_now_us(&fp));
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_stats(&bus)->wrong_id);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_parser_stats(&bus)->frames);
    TEST_ASSERT_EQUAL_UINT32(J288_REPLY_LEN, j288_bus_stats(&bus)->stale_bytes);
}

/* An echo that differs at byte 5: the attempt is a collision, and the 14 bytes after the
 * difference are stale whether the echo comes in one piece or byte by byte (they were once
 * compared and dropped uncounted when they came in the same piece). */
static void test_echo_mismatch_same_in_any_chunking(void)
{
    j288_bus_config_t cfg;
    j288_cmd_raw_t cmd = lock_cmd(4u);
    uint8_t echo[J288_CMD_LEN];
    int pass;
    for (pass = 0; pass < 2; pass++) {
        size_t i;
        memset(&cfg, 0, sizeof cfg);
        cfg.echo = true;
        setup_cfg(&cfg);
        fp.poll_fn = NULL;
        fp.txdone = FAKE_TXDONE_MANUAL;
        submit_ok(&cmd);
        memcpy(echo, fake_port_frame(&fp, 0u)->data, sizeof echo);
        echo[5] ^= 0x20u;
        if (pass == 0) {
            j288_bus_on_rx(&bus, echo, sizeof echo);
        } else {
            for (i = 0u; i < sizeof echo; i++) {
                j288_bus_on_rx(&bus, &echo[i], 1u);
                j288_bus_poll(&bus, 20u);
            }
        }
        j288_bus_on_tx_done(&bus);
        j288_bus_poll(&bus, 34u);
        TEST_ASSERT_EQUAL_INT(1, cb.calls);
        TEST_ASSERT_EQUAL_INT(J288_ERR_COLLISION, cb.txn.result);
        TEST_ASSERT_EQUAL_UINT32(14u, j288_bus_stats(&bus)->stale_bytes);
    }
}

/* ---- pauses inside a reply: the line goes idle, the frame goes on */

/* WORKED_REPLY3 in two parts with an idle line between them (split: bytes in the first part);
 * heard whole, in poll mode and with the bus advanced in the event calls. */
static void check_reply_split_by_pause(size_t split, bool isr)
{
    j288_bus_config_t cfg;
    j288_cmd_raw_t cmd = worked_cmd();
    memset(&cfg, 0, sizeof cfg);
    cfg.advance_in_isr = isr;
    setup_cfg(&cfg);
    submit_ok(&cmd);
    fake_port_idle_at(&fp, 40u * US); /* before the reply starts */
    fake_port_rx_at(&fp, 45u * US, WORKED_REPLY3, split);
    fake_port_idle_at(&fp, 47u * US);
    fake_port_rx_at(&fp, 90u * US, &WORKED_REPLY3[split], J288_REPLY_LEN - split);
    fake_port_idle_at(&fp, 92u * US);
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 2000u * US));
    TEST_ASSERT_EQUAL_INT(1, cb.calls);
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.result);
    TEST_ASSERT_EQUAL_INT32(5215, cb.txn.reply.pos);
    TEST_ASSERT_EQUAL_UINT32(90u, cb.txn.latency_us); /* taken when its last byte came */
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_parser_stats(&bus)->truncated);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_stats(&bus)->crc_errors);
}

static void test_pause_inside_head_keeps_frame(void)
{
    check_reply_split_by_pause(1u, false);
    check_reply_split_by_pause(1u, true);
}

static void test_pause_inside_payload_keeps_frame(void)
{
    check_reply_split_by_pause(15u, false);
    check_reply_split_by_pause(15u, true);
    check_reply_split_by_pause(J288_REPLY_LEN - 1u, true);
}

/* A pause before the reply starts changes nothing either. */
static void test_pause_before_reply(void)
{
    check_reply_split_by_pause(0u, false);
    check_reply_split_by_pause(0u, true);
}

/* A partial frame, a pause, then a corrupt whole frame: the pause does not cut the first, the
 * two make one bad frame and then the second, both CRC failures (nothing truncated). A corrupt
 * frame and then a partial one still held at the deadline: CRC outranks TRUNCATED, and the
 * bus counts both frames. */
static void test_crc_outranks_truncated(void)
{
    j288_cmd_raw_t cmd = worked_cmd();
    uint8_t bad[J288_REPLY_LEN];
    memcpy(bad, WORKED_REPLY3, sizeof bad);
    bad[12] ^= 0x01u;

    setup();
    submit_ok(&cmd);
    fake_port_rx_at(&fp, 45u * US, WORKED_REPLY3, 10u);
    fake_port_idle_at(&fp, 47u * US);
    fake_port_rx_at(&fp, 90u * US, bad, sizeof bad);
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 2000u * US));
    TEST_ASSERT_EQUAL_INT(J288_ERR_CRC, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT32(BUDGET_US, cb.txn.latency_us);
    TEST_ASSERT_EQUAL_UINT32(2u, j288_bus_parser_stats(&bus)->crc_errors);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_parser_stats(&bus)->truncated);
    TEST_ASSERT_EQUAL_UINT32(2u, j288_bus_stats(&bus)->crc_errors);

    setup();
    submit_ok(&cmd);
    fake_port_rx_at(&fp, 45u * US, bad, sizeof bad);
    fake_port_rx_at(&fp, 100u * US, WORKED_REPLY3, 7u);
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 2000u * US));
    TEST_ASSERT_EQUAL_INT(J288_ERR_CRC, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_parser_stats(&bus)->crc_errors);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_parser_stats(&bus)->truncated);
    TEST_ASSERT_EQUAL_UINT32(2u, j288_bus_stats(&bus)->crc_errors);
}

/* An attempt that ended early (a collision at its tx done, 33 us) is retried only a reply
 * budget after its deadline: the servo's late answer to it (at 250 us) falls into the guard
 * and is never taken as the retry's reply. */
static void test_late_reply_after_early_failure_dies_out(void)
{
    j288_bus_config_t cfg;
    j288_cmd_raw_t cmd = lock_cmd(4u);
    j288_reply_raw_t r = reply_for(4u, 4444);
    uint8_t late[J288_REPLY_LEN];
    memset(&cfg, 0, sizeof cfg);
    cfg.echo = true;
    cfg.retries = 1u;
    setup_cfg(&cfg);
    fp.echo = true;
    fp.echo_flip_at = 7;
    fake_port_encode_reply(&r, late);
    submit_ok(&cmd);
    fake_port_run_until(&fp, TX_END_NS + 1000u);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->collisions);
    fp.echo_flip_at = -1;
    fake_port_rx_at(&fp, 250u * US, late, sizeof late);
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 5000u * US));
    TEST_ASSERT_EQUAL_INT(1, cb.calls);
    TEST_ASSERT_EQUAL_INT(J288_ERR_TIMEOUT, cb.txn.result);
    TEST_ASSERT_EQUAL_INT(J288_ERR_COLLISION, cb.txn.attempt_result[0]);
    TEST_ASSERT_EQUAL_UINT32(2u, fp.nframes);
    TEST_ASSERT_EQUAL_UINT32(2u * BUDGET_US, fake_port_frame(&fp, 1u)->start_us);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_parser_stats(&bus)->frames);
    /* the rest of the corrupt echo (12 bytes) and the late reply */
    TEST_ASSERT_EQUAL_UINT32(12u + J288_REPLY_LEN, j288_bus_stats(&bus)->stale_bytes);
}

/* With the bus advanced in the event calls, on_rx takes its bytes in place; what a full ring
 * could not have held is lost and counted the same way as through the ring (poll mode). */
static void test_rx_overflow_same_in_isr_mode(void)
{
    uint8_t junk[100];
    j288_bus_config_t cfg;
    j288_cmd_raw_t cmd = worked_cmd();
    int pass;
    memset(junk, 0x42, sizeof junk);
    for (pass = 0; pass < 2; pass++) {
        memset(&cfg, 0, sizeof cfg);
        cfg.advance_in_isr = (pass == 1);
        setup_cfg(&cfg);
        fp.poll_fn = NULL;
        submit_ok(&cmd);
        fake_port_run_until(&fp, TX_END_NS);
        j288_bus_poll(&bus, fake_port_now_us(&fp));
        TEST_ASSERT_EQUAL_INT(J288_BUS_WAIT_REPLY, j288_bus_state(&bus));
        j288_bus_on_rx(&bus, junk, sizeof junk);
        j288_bus_poll(&bus, fake_port_now_us(&fp));
        TEST_ASSERT_EQUAL_UINT32(100u - J288_CONFIG_RX_RING_SIZE,
                                 j288_bus_stats(&bus)->rx_overflows);
        TEST_ASSERT_EQUAL_UINT32(J288_CONFIG_RX_RING_SIZE,
                                 j288_bus_parser_stats(&bus)->garbage_bytes);
        j288_bus_on_rx(&bus, WORKED_REPLY3, J288_REPLY_LEN);
        j288_bus_poll(&bus, fake_port_now_us(&fp));
        TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.result);
    }
}

/* Bytes reported from inside an advance (here by the completion callback of a timed-out
 * transaction, as a port may from inside one of its operations) wait in the ring; bytes
 * arriving later queue behind them instead of being taken in place first. */
static bool feed_in_callback;

static void on_done_feeds(void *user, const j288_txn_t *txn)
{
    on_done(user, txn);
    if (feed_in_callback) {
        feed_in_callback = false;
        j288_bus_on_rx(&bus, WORKED_REPLY3, 3u);
    }
}

static void test_rx_from_inside_an_advance_keeps_order(void)
{
    j288_bus_config_t cfg;
    j288_cmd_raw_t cmd = worked_cmd();
    memset(&cfg, 0, sizeof cfg);
    cfg.advance_in_isr = true;
    setup_cfg(&cfg);
    fp.poll_fn = NULL;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_submit(&bus, &cmd, 0u, on_done_feeds, &cb));
    feed_in_callback = true;
    fake_port_run_until(&fp, BUDGET_US * US); /* tx done, then the deadline */
    TEST_ASSERT_EQUAL_INT(1, cb.calls);
    TEST_ASSERT_EQUAL_INT(J288_ERR_TIMEOUT, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_stats(&bus)->stale_bytes); /* 3 bytes wait */
    j288_bus_on_rx(&bus, &WORKED_REPLY3[3], 5u); /* through the ring, behind them */
    TEST_ASSERT_EQUAL_UINT32(8u, j288_bus_stats(&bus)->stale_bytes);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_stats(&bus)->rx_overflows);
}

/* ---- time wrap-around */

static void test_time_wraps_at_2_pow_32(void)
{
    j288_cmd_raw_t cmd = lock_cmd(3u);
    j288_reply_raw_t r = reply_for(3u, 31);
    setup();
    fp.origin_us = 0xFFFFFFFFu - 40u; /* wraps inside the transaction */
    fake_port_add_servo(&fp, 3u, &r);
    submit_ok(&cmd);
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 5000u * US));
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT32(86u, cb.txn.latency_us);
    TEST_ASSERT_EQUAL_UINT32(0xFFFFFFFFu - 40u, cb.txn.start_us);

    setup();
    fp.origin_us = 0xFFFFFFFFu - 100u; /* deadline beyond the wrap */
    submit_ok(&cmd);
    fake_port_run_until(&fp, (BUDGET_US - 1u) * US);
    TEST_ASSERT_EQUAL_INT(0, cb.calls);
    fake_port_run_until(&fp, BUDGET_US * US);
    TEST_ASSERT_EQUAL_INT(1, cb.calls);
    TEST_ASSERT_EQUAL_INT(J288_ERR_TIMEOUT, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT32(BUDGET_US, cb.txn.latency_us);
}

/* ---- several buses */

static void test_several_buses_are_independent(void)
{
    static fake_port_t fp2;
    static j288_bus_t bus2;
    j288_cmd_raw_t cmd = lock_cmd(3u);
    j288_reply_raw_t r1 = reply_for(3u, 101);
    j288_reply_raw_t r2 = reply_for(3u, 202);
    struct {
        int calls;
        j288_txn_t txn;
        void *user;
        j288_bus_state_t s;
    } save;
    setup();
    fake_port_init(&fp2);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_init(&bus2, &fp2.ops, &fp2, NULL));
    fake_port_attach(&fp2, &bus2);
    fp2.poll_fn = fake_port_poll_bus;
    fp2.poll_user = &bus2;
    fake_port_add_servo(&fp, 3u, &r1);
    fake_port_add_servo(&fp2, 3u, &r2);
    fp2.servo[3].chunk = 2u;
    submit_ok(&cmd);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_submit(&bus2, &cmd, 0u, NULL, NULL));
    fake_port_run_until(&fp, 40u * US);
    fake_port_run_until(&fp2, 60u * US);
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 5000u * US));
    memcpy(&save, &cb, sizeof save);
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp2, 5000u * US));
    TEST_ASSERT_EQUAL_INT(1, save.calls);
    TEST_ASSERT_EQUAL_INT32(101, save.txn.reply.pos);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus2)->ok);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_parser_stats(&bus2)->frames);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_parser_stats(&bus)->frames);
    TEST_ASSERT_EQUAL_UINT32(0u, j288_bus_stats(&bus2)->stale_bytes);
}

/* ---- blocking helper */

static void test_transfer_blocking(void)
{
    j288_cmd_raw_t cmd = lock_cmd(3u);
    j288_reply_raw_t r = reply_for(3u, 77);
    j288_txn_t txn;
    setup();
    fp.poll_fn = NULL;
    fp.txdone = FAKE_TXDONE_INLINE;
    fake_port_add_servo(&fp, 3u, &r);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_transfer_blocking(&bus, &cmd, &txn));
    TEST_ASSERT_EQUAL_INT32(77, txn.reply.pos);
    TEST_ASSERT_EQUAL_UINT32(86u, txn.latency_us);
    TEST_ASSERT_TRUE(fp.wait_calls > 0u);
    /* back to back: the second waits out the guard, then works */
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_transfer_blocking(&bus, &cmd, NULL));
    TEST_ASSERT_EQUAL_UINT32(2u, fp.nframes);
    /* nobody answers */
    cmd.id = 9u;
    TEST_ASSERT_EQUAL_INT(J288_ERR_TIMEOUT, j288_bus_transfer_blocking(&bus, &cmd, &txn));
    TEST_ASSERT_EQUAL_UINT32(BUDGET_US, txn.latency_us);
    /* the device vanishes */
    fp.gone = true;
    cmd.id = 3u;
    TEST_ASSERT_EQUAL_INT(J288_ERR_OFFLINE, j288_bus_transfer_blocking(&bus, &cmd, &txn));
    fp.gone = false;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_transfer_blocking(&bus, &cmd, &txn));
    /* caller errors */
    cmd.id = 20u;
    TEST_ASSERT_EQUAL_INT(J288_ERR_BAD_ID, j288_bus_transfer_blocking(&bus, &cmd, &txn));
    TEST_ASSERT_EQUAL_INT(J288_ERR_NULL, j288_bus_transfer_blocking(&bus, NULL, &txn));
    fp.ops.wait = NULL;
    cmd.id = 3u;
    TEST_ASSERT_EQUAL_INT(J288_ERR_PORT_OPS, j288_bus_transfer_blocking(&bus, &cmd, &txn));
    /* 3 ok, a timeout and the vanished device failed; the refused calls count nowhere */
    TEST_ASSERT_EQUAL_UINT32(5u, j288_bus_stats(&bus)->transactions);
    TEST_ASSERT_EQUAL_UINT32(2u, j288_bus_stats(&bus)->failed);
    assert_stats_add_up(0u);
}

static int blocking_from_cb_rc;

static void on_done_try_blocking(void *user, const j288_txn_t *txn)
{
    j288_cmd_raw_t c = lock_cmd(1u);
    on_done(user, txn);
    blocking_from_cb_rc = j288_bus_transfer_blocking(&bus, &c, NULL);
}

static void test_transfer_blocking_edge_cases(void)
{
    j288_cmd_raw_t cmd = lock_cmd(3u);
    j288_txn_t txn;
    setup();
    fp.poll_fn = NULL;
    /* the device vanishes while the command is in flight (not queued behind a guard) */
    TEST_ASSERT_TRUE(j288_bus_is_idle(&bus));
    fp.gone = true;
    TEST_ASSERT_EQUAL_INT(J288_ERR_OFFLINE, j288_bus_transfer_blocking(&bus, &cmd, &txn));
    TEST_ASSERT_EQUAL_INT(J288_ERR_OFFLINE, txn.result);
    TEST_ASSERT_EQUAL_UINT8(1u, txn.attempts);
    TEST_ASSERT_EQUAL_UINT32(1u, fp.nframes);
    fp.gone = false;
    /* not from a completion callback */
    fp.poll_fn = fake_port_poll_bus;
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, fp.now_ns + 5000u * US));
    blocking_from_cb_rc = 0;
    TEST_ASSERT_EQUAL_INT(
        J288_OK, j288_bus_submit(&bus, &cmd, fake_port_now_us(&fp), on_done_try_blocking, &cb));
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, fp.now_ns + 5000u * US));
    TEST_ASSERT_EQUAL_INT(J288_ERR_BUSY, blocking_from_cb_rc);
    TEST_ASSERT_EQUAL_UINT32(2u, fp.nframes);
}

/* The device vanishes while the blocking call waits for the guard (its submit queued) or
 * for a retry: it ends J288_ERR_OFFLINE without sending anything more. */
static void test_transfer_blocking_gone_between_attempts(void)
{
    j288_bus_config_t cfg;
    j288_cmd_raw_t cmd = lock_cmd(3u);
    j288_reply_raw_t r = reply_for(3u, 77);
    j288_txn_t txn;
    memset(&cfg, 0, sizeof cfg);
    cfg.retries = 1u;
    setup_cfg(&cfg);
    fp.poll_fn = NULL;
    fake_port_add_servo(&fp, 3u, &r);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_transfer_blocking(&bus, &cmd, &txn));
    TEST_ASSERT_EQUAL_INT(J288_BUS_GUARD, j288_bus_state(&bus)); /* 2 us to go */
    fp.gone = true;
    TEST_ASSERT_EQUAL_INT(J288_ERR_OFFLINE, j288_bus_transfer_blocking(&bus, &cmd, &txn));
    TEST_ASSERT_EQUAL_INT(J288_ERR_OFFLINE, txn.result);
    TEST_ASSERT_EQUAL_UINT8(0u, txn.attempts);
    TEST_ASSERT_EQUAL_UINT32(1u, fp.nframes);
    fp.gone = false;

    fp.servo[3].present = false; /* attempt 1 times out; unplugged before the retry */
    fp.gone_after_ns = fp.now_ns + 200u * US;
    TEST_ASSERT_EQUAL_INT(J288_ERR_OFFLINE, j288_bus_transfer_blocking(&bus, &cmd, &txn));
    TEST_ASSERT_EQUAL_UINT8(1u, txn.attempts);
    TEST_ASSERT_EQUAL_INT(J288_ERR_TIMEOUT, txn.attempt_result[0]);
    TEST_ASSERT_EQUAL_UINT32(2u, fp.nframes);
    TEST_ASSERT_EQUAL_UINT32(1u, j288_bus_stats(&bus)->ok);
    TEST_ASSERT_EQUAL_UINT32(2u, j288_bus_stats(&bus)->failed);
    assert_stats_add_up(0u);
}

/* advance_in_isr on a port without lock/unlock (one interrupt priority, nothing to mask). */
static void test_advance_in_isr_without_lock_ops(void)
{
    j288_bus_config_t cfg;
    j288_cmd_raw_t cmd = lock_cmd(0u);
    j288_reply_raw_t r = reply_for(0u, 500);
    memset(&cb, 0, sizeof cb);
    memset(&cfg, 0, sizeof cfg);
    cfg.advance_in_isr = true;
    fake_port_init(&fp);
    fp.ops.lock = NULL;
    fp.ops.unlock = NULL;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_init(&bus, &fp.ops, &fp, &cfg));
    fake_port_attach(&fp, &bus);
    fake_port_add_servo(&fp, 0u, &r);
    submit_ok(&cmd);
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, 5000u * US));
    TEST_ASSERT_EQUAL_INT(J288_OK, cb.txn.result);
    TEST_ASSERT_EQUAL_INT32(500, cb.txn.reply.pos);
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_estop(&bus, fake_port_now_us(&fp)));
    TEST_ASSERT_TRUE(fake_port_run_until_idle(&fp, fp.now_ns + 5000u * US));
    TEST_ASSERT_EQUAL_UINT32(2u, fp.nframes);
    TEST_ASSERT_EQUAL_UINT32(0u, fp.lock_calls);
}

/* ---- poll mode without a timer op: the application's polls find the deadline */

static void test_poll_only_port(void)
{
    j288_cmd_raw_t cmd = lock_cmd(3u);
    memset(&cb, 0, sizeof cb);
    fake_port_init(&fp);
    fp.ops.arm_timeout = NULL;
    fp.ops.start_rx = NULL;
    fp.ops.set_dir = NULL;
    fp.ops.lock = NULL;
    fp.ops.unlock = NULL;
    TEST_ASSERT_EQUAL_INT(J288_OK, j288_bus_init(&bus, &fp.ops, &fp, NULL));
    fake_port_attach(&fp, &bus);
    fp.poll_fn = fake_port_poll_bus;
    fp.poll_user = &bus;
    submit_ok(&cmd);
    fake_port_run_until(&fp, 1000u * US); /* one late poll */
    TEST_ASSERT_EQUAL_INT(J288_ERR_TIMEOUT, cb.txn.result);
    TEST_ASSERT_EQUAL_UINT32(1000u, cb.txn.latency_us); /* seen when polled */
    TEST_ASSERT_EQUAL_UINT32(0u, fp.timer_arms);
    TEST_ASSERT_EQUAL_UINT32(0u, fp.start_rx_calls);
}

int main(void)
{
    UNITY_BEGIN();
    RUN_TEST(test_init_rejections);
    RUN_TEST(test_reply_budget_and_wire_time);
    RUN_TEST(test_config_accessor);
    RUN_TEST(test_wire_time_exact);
    RUN_TEST(test_configured_guard);
    RUN_TEST(test_normal_transaction);
    RUN_TEST(test_worked_lock_frame_through_bus);
    RUN_TEST(test_reply_in_many_chunks);
    RUN_TEST(test_reply_as_one_chunk_with_following_noise_is_stale);
    RUN_TEST(test_echo_present);
    RUN_TEST(test_echo_mismatch_is_collision);
    RUN_TEST(test_echo_missing_is_collision_at_deadline);
    RUN_TEST(test_no_reply_times_out_exactly);
    RUN_TEST(test_submit_in_guard_waits_for_guard);
    RUN_TEST(test_late_reply_in_guard_is_stale);
    RUN_TEST(test_late_reply_during_next_transaction_not_credited);
    RUN_TEST(test_late_reply_during_next_transmit_is_stale);
    RUN_TEST(test_bytes_before_tx_done_in_same_poll_are_stale);
    RUN_TEST(test_wrong_id_only);
    RUN_TEST(test_two_servos_with_one_id);
    RUN_TEST(test_corrupted_reply);
    RUN_TEST(test_truncated_reply_with_and_without_idle);
    RUN_TEST(test_garbage_before_reply);
    RUN_TEST(test_broadcast_waits_for_no_reply);
    RUN_TEST(test_retries_keep_each_reason);
    RUN_TEST(test_retries_exhausted);
    RUN_TEST(test_failed_counts_transactions);
    RUN_TEST(test_estop_and_submit_while_waiting_to_retry);
    RUN_TEST(test_broadcast_with_line_error_is_retried);
    RUN_TEST(test_line_error_marks_attempt);
    RUN_TEST(test_line_gone_is_offline_without_retry);
    RUN_TEST(test_submit_errors_send_nothing);
    RUN_TEST(test_tx_done_never_comes);
    RUN_TEST(test_tx_done_inline_os_style);
    RUN_TEST(test_rx_overflow_counted);
    RUN_TEST(test_port_crc_hook_is_used);
    RUN_TEST(test_estop_while_busy);
    RUN_TEST(test_estop_idle_and_with_queued_work);
    RUN_TEST(test_estop_counts_in_estops_only);
    RUN_TEST(test_estop_resent_after_port_error);
    RUN_TEST(test_estop_resent_after_collision);
    RUN_TEST(test_estop_resent_after_tx_timeout_and_line_error);
    RUN_TEST(test_estop_dead_port_gives_up_bounded);
    RUN_TEST(test_estop_line_gone_ends_at_once);
    RUN_TEST(test_estop_merged_into_failing_stop_starts_again);
    RUN_TEST(test_advance_in_isr_chains_without_poll);
    RUN_TEST(test_advance_in_isr_with_inline_tx_done);
    RUN_TEST(test_isr_tx_done_after_deadline_times_out);
    RUN_TEST(test_isr_tx_done_before_echo_waits_for_echo);
    RUN_TEST(test_isr_spurious_tx_done_changes_nothing);
    RUN_TEST(test_isr_estop_ends_at_tx_done);
    RUN_TEST(test_isr_reply_before_tx_done_is_stale);
    RUN_TEST(test_isr_reply_with_trailing_byte);
    RUN_TEST(test_isr_whole_reply_after_partial);
    RUN_TEST(test_isr_reply_with_bad_head_refused);
    RUN_TEST(test_isr_whole_replies_wrong_id_bad_crc_then_ours);
    RUN_TEST(test_isr_first_whole_reply_from_another_id);
    RUN_TEST(test_isr_guard_timer_starts_queued_after_stale_bytes);
    RUN_TEST(test_isr_guard_timer_starts_retry);
    RUN_TEST(test_isr_reply_under_pending_estop_aborts);
    RUN_TEST(test_poll_mode_tx_done_waits_for_poll);
    RUN_TEST(test_failure_ranking);
    RUN_TEST(test_noise_while_idle_is_not_echo);
    RUN_TEST(test_bytes_after_broadcast_in_same_poll);
    RUN_TEST(test_echo_mismatch_same_in_any_chunking);
    RUN_TEST(test_pause_inside_head_keeps_frame);
    RUN_TEST(test_pause_inside_payload_keeps_frame);
    RUN_TEST(test_pause_before_reply);
    RUN_TEST(test_crc_outranks_truncated);
    RUN_TEST(test_late_reply_after_early_failure_dies_out);
    RUN_TEST(test_rx_overflow_same_in_isr_mode);
    RUN_TEST(test_rx_from_inside_an_advance_keeps_order);
    RUN_TEST(test_time_wraps_at_2_pow_32);
    RUN_TEST(test_several_buses_are_independent);
    RUN_TEST(test_transfer_blocking);
    RUN_TEST(test_transfer_blocking_edge_cases);
    RUN_TEST(test_transfer_blocking_gone_between_attempts);
    RUN_TEST(test_advance_in_isr_without_lock_ops);
    RUN_TEST(test_poll_only_port);
    return UNITY_END();
}
