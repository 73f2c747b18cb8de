/*
 * Instructions per transaction that the STM32 port adds on top of lib/, HAL calls included,
 * on Cortex-M4 under QEMU (-icount shift=0: SysTick counts instructions once calibrated on a
 * loop of known length). Built against ST's real STM32F4 HAL (`make bench-stm32-hal`, after
 * scripts/fetch-st.sh): the port, the HAL's UART and DMA drivers and the library run as on an
 * F446, on peripherals played in RAM (QEMU's mps2 board has no STM32 USART or DMA): the HAL
 * reaches its registers through the handles' Instance pointers, so RAM register blocks laid
 * out as the silicon's (a DMA controller on a 1 KiB boundary, its streams at their offsets)
 * serve. The bench raises the hardware's flags and calls the HAL's interrupt handlers where
 * the NVIC would; those few stores are counted with the port. The reply stays in the DMA
 * buffer between transactions (the DMA's writes cost the CPU nothing on silicon).
 *
 * Rows, per transaction (submit, poll, transmit, TX complete, turn to receive, 26-byte reply
 * ended by an idle line, poll, guard): lib/ alone behind a port whose operations do nothing
 * (the floor any port starts from), then the STM32 port with its receive stream in normal
 * mode (re-armed after every idle line) and in circular mode. Frame CRCs in software (the
 * CRC unit's path is measured by `make bench-target`).
 */
#include <stdio.h>
#include <string.h>

#include "j288/j288.h"
#include "j288_stm32.h"
#include "worked_cmd.h"

#define SYST_CSR (*(volatile uint32_t *)0xE000E010u)
#define SYST_RVR (*(volatile uint32_t *)0xE000E014u)
#define SYST_CVR (*(volatile uint32_t *)0xE000E018u)
#define ITERATIONS 200u
#define CAL_LOOPS 100000u

/* The spec's worked reply of servo 3. */
static const uint8_t k_reply3[J288_REPLY_LEN] = {
    0xfc, 0xee, 0x13, 0x24, 0x29, 0x30, 0x00, 0x05, 0xd7, 0xff, 0x5f, 0x14, 0x00,
    0x00, 0x00, 0x00, 0x00, 0x00, 0xe8, 0x03, 0x00, 0x00, 0x49, 0xc2, 0x3b, 0xee};

static uint32_t clock_us = 1000u;
static uint32_t done_ok;

/* Per-phase SysTick ticks: 0 submit and transmit start, 1 transmit complete and turn to
 * receive, 2 the reply and the idle line, 3 the polls that finish and end the guard. */
#define PHASES 4u
static uint32_t phase_ticks[PHASES];
static uint32_t phase_t;
/* The simulated DMA's and line's own work (copying bytes into the buffer, counting down) is
 * not the CPU's on silicon: it is timed and taken out of the figures. */
static uint32_t excluded_ticks;
static uint32_t excluded_at_begin;
static void phase_begin(void)
{
    phase_t = SYST_CVR;
    excluded_at_begin = excluded_ticks;
}
static void phase_end(unsigned i)
{
    uint32_t t = SYST_CVR;
    uint32_t excluded = excluded_ticks;
    phase_ticks[i] += ((phase_t - t) & 0x00FFFFFFu) - (excluded - excluded_at_begin);
    excluded_at_begin = excluded;
    phase_t = t;
}

static void systick_start(void)
{
    SYST_CSR = 0u;
    SYST_RVR = 0x00FFFFFFu;
    SYST_CVR = 0u;
    SYST_CSR = 5u; /* enable, processor clock, no interrupt */
}
static uint32_t systick_now(void) { return SYST_CVR; }
static uint32_t ticks_between(uint32_t a, uint32_t b) { return (a - b) & 0x00FFFFFFu; }

/* Instructions per SysTick tick, x1000, from a two-instruction loop. */
static uint32_t calibrate(void)
{
    uint32_t n = CAL_LOOPS;
    uint32_t t0 = systick_now();
    __asm volatile(".syntax unified\n1: subs %0, %0, #1\n\tbne 1b" : "+l"(n) : : "cc");
    return (uint32_t)((2ull * CAL_LOOPS * 1000u) / ticks_between(t0, systick_now()));
}

static uint32_t per_txn(uint32_t ticks, uint32_t ipt_milli)
{
    return (uint32_t)(((uint64_t)ticks * ipt_milli / 1000u + ITERATIONS / 2u) / ITERATIONS);
}

static void on_done(void *user, const j288_txn_t *txn)
{
    (void)user;
    done_ok += (txn->result == J288_OK) ? 1u : 0u;
}

/* ---- lib/ alone: a port whose operations do nothing ------------------------------------- */

static j288_bus_t plain_bus;

static int nop_start_tx(void *ctx, const uint8_t *data, size_t len)
{
    (void)ctx;
    (void)data;
    (void)len;
    return 0;
}
static uint32_t nop_now_us(void *ctx)
{
    (void)ctx;
    return clock_us;
}
static void nop_dir(void *ctx, j288_dir_t dir)
{
    (void)ctx;
    (void)dir;
}
static void nop_ctx(void *ctx) { (void)ctx; }
static void nop_arm(void *ctx, uint32_t t)
{
    (void)ctx;
    (void)t;
}

static const j288_port_t nop_port = {
    .start_tx = nop_start_tx,
    .now_us = nop_now_us,
    .start_rx = nop_ctx,
    .set_dir = nop_dir,
    .arm_timeout = nop_arm,
    .lock = nop_ctx,
    .unlock = nop_ctx,
};

static void plain_transaction(void)
{
    j288_cmd_raw_t cmd = worked_cmd();
    phase_begin();
    (void)j288_bus_submit(&plain_bus, &cmd, clock_us, on_done, NULL);
    j288_bus_poll(&plain_bus, clock_us);
    phase_end(0u);
    j288_bus_on_tx_done(&plain_bus);
    phase_end(1u);
    j288_bus_on_rx(&plain_bus, k_reply3, J288_REPLY_LEN);
    j288_bus_on_rx_idle(&plain_bus);
    phase_end(2u);
    clock_us += 100u;
    j288_bus_poll(&plain_bus, clock_us);
    clock_us += 10u;
    j288_bus_poll(&plain_bus, clock_us);
    phase_end(3u);
}

/* ---- the STM32 port on the real HAL, peripherals in RAM --------------------------------- */

#if defined(STM32G4)
/* DMA1 channels 1 (TX) and 2 (RX), their flags in one ISR/IFCR pair. HAL_DMA_Init would find
 * the flags from the channel's fixed address and program the DMAMUX at its own: the fields it
 * fills in are set here instead. */
static DMA_Channel_TypeDef tx_ch, rx_ch;
static DMA_TypeDef dma1_regs;
#define RX_COUNT (rx_ch.CNDTR)
#define TX_COUNT (tx_ch.CNDTR)
#define DMA_FLAGS (dma1_regs.ISR)
#define DMA_FLAGS_CLEARED (dma1_regs.IFCR)
#define F_HT DMA_ISR_HTIF1
#define F_TC DMA_ISR_TCIF1
#define RX_SHIFT 4u /* channel 2 */
#define UART_STATUS (usart1_regs.ISR)
#define S_TC USART_ISR_TC
#define S_IDLE USART_ISR_IDLE
#define FAMILY "G4"
#else
/* DMA2 as the HAL addresses it: LISR, HISR, LIFCR, HIFCR, then 8 streams of 0x18 bytes from
 * offset 0x10; the HAL finds a stream's flags from the stream's address. */
static uint32_t dma2_block[0x100u / 4u] __attribute__((aligned(1024)));
#define DMA2_STREAM(n) ((DMA_Stream_TypeDef *)(void *)((uint8_t *)dma2_block + 0x10u + 0x18u * (n)))
#define TX_STREAM DMA2_STREAM(7u)
#define RX_COUNT (DMA2_STREAM(2u)->NDTR)
#define TX_COUNT (TX_STREAM->NDTR)
#define DMA_FLAGS (dma2_block[0])         /* LISR */
#define DMA_FLAGS_CLEARED (dma2_block[2]) /* LIFCR */
#define F_HT DMA_LISR_HTIF0
#define F_TC DMA_LISR_TCIF0
#define RX_SHIFT 16u /* stream 2's flags in LISR */
#define UART_STATUS (usart1_regs.SR)
#define S_TC USART_SR_TC
#define S_IDLE USART_SR_IDLE
#define FAMILY "F4"
#endif

static USART_TypeDef usart1_regs;
static TIM_TypeDef tim2_regs;
static UART_HandleTypeDef huart1;
static DMA_HandleTypeDef hdma_tx, hdma_rx;
static TIM_HandleTypeDef htim2;
J288_STM32_DMA_BUFFER(bus_dma);
static j288_stm32_t port;

static uint32_t bench_now_us(void) { return clock_us; }

static uint32_t pause_t;
static void pause_begin(void) { pause_t = SYST_CVR; }
static void pause_end(void) { excluded_ticks += (pause_t - SYST_CVR) & 0x00FFFFFFu; }

static int port_setup(void)
{
    j288_stm32_config_t pc;
    static const DMA_HandleTypeDef zero_dma;

    memset(&usart1_regs, 0, sizeof usart1_regs);
    memset(&huart1, 0, sizeof huart1);
    hdma_tx = zero_dma;
    hdma_rx = zero_dma;
#if defined(STM32G4)
    memset(&dma1_regs, 0, sizeof dma1_regs);
    hdma_tx.Instance = &tx_ch;
    hdma_tx.DmaBaseAddress = &dma1_regs;
    hdma_tx.ChannelIndex = 0u;
    hdma_rx.Instance = &rx_ch;
    hdma_rx.DmaBaseAddress = &dma1_regs;
    hdma_rx.ChannelIndex = RX_SHIFT;
    tx_ch.CCR = DMA_CCR_DIR | DMA_CCR_MINC; /* what HAL_DMA_Init writes: memory to peripheral */
    rx_ch.CCR = DMA_CCR_MINC;
#else
    memset(dma2_block, 0, sizeof dma2_block);
    hdma_tx.Instance = DMA2_STREAM(7u);
    hdma_tx.Init.Channel = DMA_CHANNEL_4;
    hdma_tx.Init.Direction = DMA_MEMORY_TO_PERIPH;
    hdma_tx.Init.MemInc = DMA_MINC_ENABLE;
    hdma_tx.Init.Mode = DMA_NORMAL;
    hdma_rx.Instance = DMA2_STREAM(2u);
    hdma_rx.Init.Channel = DMA_CHANNEL_4;
    hdma_rx.Init.Direction = DMA_PERIPH_TO_MEMORY;
    hdma_rx.Init.MemInc = DMA_MINC_ENABLE;
    hdma_rx.Init.Mode = DMA_CIRCULAR;
    if ((HAL_DMA_Init(&hdma_tx) != HAL_OK) || (HAL_DMA_Init(&hdma_rx) != HAL_OK)) {
        return -1;
    }
#endif
    /* What HAL_HalfDuplex_Init leaves (its clock and baud setup needs the RCC, which is not
     * here): the handle ready, the UART on in half-duplex mode, the streams linked. */
    huart1.Instance = &usart1_regs;
    huart1.Init.BaudRate = 6000000u;
    huart1.Init.Mode = UART_MODE_TX_RX;
    huart1.Init.OverSampling = UART_OVERSAMPLING_8;
    huart1.hdmatx = &hdma_tx;
    huart1.hdmarx = &hdma_rx;
    hdma_tx.Parent = &huart1;
    hdma_rx.Parent = &huart1;
    huart1.gState = HAL_UART_STATE_READY;
    huart1.RxState = HAL_UART_STATE_READY;
    usart1_regs.CR1 = USART_CR1_UE | USART_CR1_TE | USART_CR1_RE;
    usart1_regs.CR3 = USART_CR3_HDSEL;

    htim2.Instance = &tim2_regs;
    tim2_regs.ARR = 0xFFFFFFFFu;

    memset(&pc, 0, sizeof pc);
    pc.huart = &huart1;
    pc.dma = &bus_dma;
    pc.now_us = bench_now_us;
    pc.htim = &htim2;
    pc.tim_channel = TIM_CHANNEL_1;
    pc.irq_priority = 5u;
    j288_stm32_deinit(&port);
    return j288_stm32_init(&port, &pc, NULL);
}

/* The simulation runs paused (its time excluded); the port's entries run counted. The G4's
 * flags the port clears through ICR go afterwards, as the silicon clears them. */
static void port_uart_irq(void)
{
    pause_end();
    j288_stm32_on_uart_irq(&port);
    pause_begin();
#if defined(STM32G4)
    usart1_regs.ISR &= ~usart1_regs.ICR;
    usart1_regs.ICR = 0u;
#endif
}

/* n bytes arrive on the line and go to the RX stream's buffer; the stream counts down and
 * raises its half and complete flags, whose interrupt is taken at once (and the flags the
 * port cleared through LIFCR go, as the silicon clears them). Called paused. */
static void line_receive(const uint8_t *src, uint32_t n)
{
    while (n > 0u) {
        uint32_t pos = J288_STM32_RX_BUF_SIZE - RX_COUNT;
        uint32_t to_flag = ((pos < J288_STM32_RX_BUF_SIZE / 2u) ? J288_STM32_RX_BUF_SIZE / 2u : J288_STM32_RX_BUF_SIZE) - pos;
        uint32_t chunk = (n < to_flag) ? n : to_flag;
        memcpy(&bus_dma.rx[pos], src, chunk);
        src += chunk;
        n -= chunk;
        RX_COUNT -= chunk;
        if (chunk == to_flag) {
            DMA_FLAGS |= ((RX_COUNT == 0u) ? F_TC : F_HT) << RX_SHIFT;
            RX_COUNT = (RX_COUNT == 0u) ? J288_STM32_RX_BUF_SIZE : RX_COUNT;
            pause_end();
            j288_stm32_on_dma_rx_irq(&port);
            pause_begin();
            DMA_FLAGS &= ~DMA_FLAGS_CLEARED;
            DMA_FLAGS_CLEARED = 0u;
        }
    }
}

/* The TX stream sends its 20 bytes, which the single wire echoes to the receiver, then the
 * last stop bit goes out: TC, whose interrupt ends the transmit; a character later the line
 * idles (IDLE, a second interrupt) before the servo answers. */
static void hw_transmit_done(void)
{
    pause_begin();
    /* SR's bits are rc_w0: the port's clear of TC (a write of ~TC) left the others as they
     * were, which RAM does not do: put them back (and TC cleared). */
    UART_STATUS = 0u;
    line_receive(bus_dma.tx, TX_COUNT);
    TX_COUNT = 0u;
#if !defined(STM32G4)
    TX_STREAM->CR &= ~(uint32_t)DMA_SxCR_EN; /* a stream stops; a channel stays enabled */
#endif
    UART_STATUS = S_TC;
    if ((usart1_regs.CR1 & USART_CR1_TCIE) != 0u) {
        port_uart_irq();
    }
    UART_STATUS = S_TC | S_IDLE;
    port_uart_irq();
    UART_STATUS = S_TC; /* the F4's SR-then-DR read, the G4's ICR cleared IDLE */
    pause_end();
}

/* 26 bytes of reply, then the line idles. */
static void hw_reply_then_idle(void)
{
    pause_begin();
    line_receive(k_reply3, J288_REPLY_LEN);
    UART_STATUS = S_TC | S_IDLE;
    port_uart_irq();
    UART_STATUS = S_TC;
    pause_end();
}

static void port_transaction(void)
{
    j288_cmd_raw_t cmd = worked_cmd();
    j288_bus_t *bus = j288_stm32_bus(&port);
    phase_begin();
    (void)j288_bus_submit(bus, &cmd, clock_us, on_done, NULL);
    j288_bus_poll(bus, clock_us);
    phase_end(0u);
    hw_transmit_done();
    phase_end(1u);
    hw_reply_then_idle();
    phase_end(2u);
    clock_us += 100u;
    j288_bus_poll(bus, clock_us);
    clock_us += 10u;
    j288_bus_poll(bus, clock_us);
    phase_end(3u);
}

/* ---- the run ------------------------------------------------------------------------------ */

typedef struct {
    uint32_t total;
    uint32_t phase[PHASES];
} result_t;

static result_t run(void (*txn)(void), uint32_t ipt)
{
    result_t r;
    uint32_t t0, t1;
    txn(); /* warm: the first transaction, then measure */
    done_ok = 0u;
    memset(phase_ticks, 0, sizeof phase_ticks);
    excluded_ticks = 0u;
    t0 = systick_now();
    for (uint32_t i = 0; i < ITERATIONS; i++) {
        txn();
    }
    t1 = systick_now();
    r.total = (done_ok == ITERATIONS) ? per_txn(ticks_between(t0, t1) - excluded_ticks, ipt) : 0u;
    for (unsigned i = 0; i < PHASES; i++) {
        r.phase[i] = per_txn(phase_ticks[i], ipt);
    }
    return r;
}

static void print_row(const char *name, const result_t *r, const result_t *base)
{
    printf("| %s | %u", name, (unsigned)r->total);
    if (base == NULL) {
        printf(" | -");
    } else {
        printf(" | %u", (unsigned)(r->total - base->total));
    }
    for (unsigned i = 0; i < PHASES; i++) {
        printf(" | %u", (unsigned)r->phase[i]);
    }
    printf(" |\n");
}

int main(void)
{
    uint32_t ipt;
    result_t plain, regs;

    systick_start();
    ipt = calibrate();

    if (j288_bus_init(&plain_bus, &nop_port, NULL, NULL) != J288_OK) {
        return 1;
    }
    plain = run(plain_transaction, ipt);
    if (port_setup() != J288_OK) {
        printf("port setup failed\n");
        return 1;
    }
    regs = run(port_transaction, ipt);
    if ((plain.total == 0u) || (regs.total == 0u)) {
        printf("a transaction did not end J288_OK\n");
        return 1;
    }
    printf("bench: %u transactions each; %u.%03u instructions per SysTick tick\n",
           (unsigned)ITERATIONS, (unsigned)(ipt / 1000u), (unsigned)(ipt % 1000u));
    printf("| path | per transaction | added | submit + TX start | echo + TX complete + idle | "
           "reply + idle | polls to the end |\n");
    printf("|---|---:|---:|---:|---:|---:|---:|\n");
    print_row("lib/ alone (port operations empty)", &plain, NULL);
    print_row("STM32 port on " FAMILY " registers (HAL init)", &regs, &plain);
    printf("interrupt time per transaction (the port's entries and what the bus does in them): "
           "%u instructions\n", (unsigned)(regs.phase[1] + regs.phase[2]));
    return 0;
}
