/*
 * stm32_hal_stub.h - the slice of the STM32Cube HAL (and CMSIS) that port/stm32_hal uses, for
 * three families: the F4 (the default, -DJ288_STUB_F4: USART SR/DR, DMA streams), the G4
 * (-DJ288_STUB_G4: USART ISR/ICR, DMA channels, DMAMUX) and the H7 (-DJ288_STUB_H7: USART
 * ISR/ICR, DMA streams, DMAMUX, a Cortex-M7 with its data cache).
 *
 * Written for this project, not taken from ST: it declares only the types, constants, macros
 * and functions that j288_stm32.c (and the example's link check) name, with the HAL's own
 * names and signatures, so that the port source compiles unchanged against this stub and
 * against the real STM32Cube HAL. Every constant that ST defines carries ST's value for the
 * family it stands for (test/stm32/stub_matches_st.sh compares them with ST's headers where
 * scripts/fetch-st.sh has fetched them). Register blocks are laid out as the silicon's, except
 * that DMA address registers hold a host pointer (uintptr_t); handles list only the fields
 * the port and the tests use.
 *
 * Implementations: test/stm32/fake_hal.c (the host tests' model of the silicon: with
 * J288_STUB_FAKE, every register access the port makes goes through it) and stm32_hal_stub.c
 * (do-nothing bodies so that the firmware example links).
 */
#ifndef J288_STM32_HAL_STUB_H
#define J288_STM32_HAL_STUB_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(J288_STUB_G4) + defined(J288_STUB_H7) + defined(J288_STUB_F4) > 1
#error "stm32_hal_stub.h: one of J288_STUB_F4, J288_STUB_G4, J288_STUB_H7"
#endif
#if !defined(J288_STUB_G4) && !defined(J288_STUB_H7) && !defined(J288_STUB_F4)
#define J288_STUB_F4
#endif

/* What the family has, in the stub's own words (ST's headers say it with the names below). */
#if defined(J288_STUB_F4)
#define STM32F4
#define J288_STUB_FAMILY "F4"
#elif defined(J288_STUB_G4)
#define STM32G4
#define J288_STUB_FAMILY "G4"
#define J288_STUB_ISR_USART 1
#define J288_STUB_CHANNELS 1
#define J288_STUB_DMAMUX 1
#else
#define STM32H7
#define J288_STUB_FAMILY "H7"
#define J288_STUB_ISR_USART 1
#define J288_STUB_DMAMUX 1
#endif

/* The host tests watch every register access (J288_STUB_FAKE): the port's J288_STM32_REG()
 * hands the register to the fake before each access, which brings the simulated hardware up to
 * that moment (and may take an interrupt there, as the silicon would between two
 * instructions). Elsewhere (the link check) the accesses are plain. */
#if defined(J288_STUB_FAKE)
void stub_reg_touch(const volatile void *reg);
#define J288_STM32_REG(reg) (*(stub_reg_touch(&(reg)), &(reg)))
#endif

/* ---- common ---------------------------------------------------------------------------- */
typedef enum { HAL_OK = 0x00u, HAL_ERROR = 0x01u, HAL_BUSY = 0x02u, HAL_TIMEOUT = 0x03u } HAL_StatusTypeDef;

/* ---- CMSIS core ------------------------------------------------------------------------- */
#define __NVIC_PRIO_BITS 4U
#define __MPU_PRESENT 1U
#if defined(J288_STUB_H7)
#define __CORTEX_M 7U
#ifndef __CM7_REV
#define __CM7_REV 0x0101U /* r1p1 */
#endif
#ifndef __DCACHE_PRESENT
#define __DCACHE_PRESENT 1U
#endif
#else
#define __CORTEX_M 4U
#define __CM4_REV 0x0001U
#endif
/* Cache maintenance exists only on a core with a data cache (CMSIS: the device header sets
 * __DCACHE_PRESENT, core_cm7.h declares the functions). -D__DCACHE_PRESENT=1U or 0U overrides
 * the family's (test/stm32/dcache_needs_a_cache.sh builds both). */
#ifndef __DCACHE_PRESENT
#define __DCACHE_PRESENT 0U
#endif

/* Static inline in CMSIS; plain functions here (the fake keeps the masks). */
uint32_t __get_PRIMASK(void);
void __set_PRIMASK(uint32_t priMask);
void __disable_irq(void);
void __enable_irq(void);
uint32_t __get_BASEPRI(void);
void __set_BASEPRI(uint32_t basePri);
void __set_BASEPRI_MAX(uint32_t basePri);
void __DMB(void);
void __DSB(void);
void __ISB(void);

#if __DCACHE_PRESENT
void SCB_CleanDCache_by_Addr(volatile void *addr, int32_t dsize);
void SCB_InvalidateDCache_by_Addr(volatile void *addr, int32_t dsize);
/* The registers that say whether the D-cache is on and what the MPU makes of an address. */
typedef struct {
    volatile uint32_t CPUID;
    volatile uint32_t ICSR;
    volatile uint32_t VTOR;
    volatile uint32_t AIRCR;
    volatile uint32_t SCR;
    volatile uint32_t CCR;
} SCB_Type;
typedef struct {
    volatile uint32_t TYPE;
    volatile uint32_t CTRL;
    volatile uint32_t RNR;
    volatile uint32_t RBAR;
    volatile uint32_t RASR;
} MPU_Type;
extern SCB_Type stub_scb;
extern MPU_Type stub_mpu;
#define SCB (&stub_scb)
#define MPU (&stub_mpu)
#define SCB_CCR_DC_Pos 16U
#define SCB_CCR_DC_Msk (1U << SCB_CCR_DC_Pos)
#define MPU_TYPE_DREGION_Pos 8U
#define MPU_TYPE_DREGION_Msk (0xFFU << MPU_TYPE_DREGION_Pos)
#define MPU_CTRL_ENABLE_Msk 1U
#define MPU_CTRL_PRIVDEFENA_Msk (1U << 2U)
#define MPU_RBAR_ADDR_Msk (0x7FFFFFFU << 5U)
#define MPU_RASR_ENABLE_Msk 1U
#define MPU_RASR_SIZE_Pos 1U
#define MPU_RASR_SIZE_Msk (0x1FU << MPU_RASR_SIZE_Pos)
#define MPU_RASR_SRD_Pos 8U
#define MPU_RASR_SRD_Msk (0xFFU << MPU_RASR_SRD_Pos)
#define MPU_RASR_B_Msk (1U << 16U)
#define MPU_RASR_C_Msk (1U << 17U)
#define MPU_RASR_S_Msk (1U << 18U)
#define MPU_RASR_TEX_Pos 19U
#define MPU_RASR_TEX_Msk (0x7U << MPU_RASR_TEX_Pos)
#endif

/* ---- GPIO ------------------------------------------------------------------------------ */
typedef struct {
    volatile uint32_t MODER;
    volatile uint32_t OTYPER;
    volatile uint32_t OSPEEDR;
    volatile uint32_t PUPDR;
    volatile uint32_t IDR;
    volatile uint32_t ODR;
    volatile uint32_t BSRR;
    volatile uint32_t LCKR;
    volatile uint32_t AFR[2];
} GPIO_TypeDef;

typedef enum { GPIO_PIN_RESET = 0u, GPIO_PIN_SET } GPIO_PinState;

void HAL_GPIO_WritePin(GPIO_TypeDef *GPIOx, uint16_t GPIO_Pin, GPIO_PinState PinState);
GPIO_PinState HAL_GPIO_ReadPin(GPIO_TypeDef *GPIOx, uint16_t GPIO_Pin);

/* ---- USART ------------------------------------------------------------------------------ */
#if defined(J288_STUB_ISR_USART)
typedef struct {
    volatile uint32_t CR1;
    volatile uint32_t CR2;
    volatile uint32_t CR3;
    volatile uint32_t BRR;
    volatile uint32_t GTPR;
    volatile uint32_t RTOR;
    volatile uint32_t RQR;
    volatile uint32_t ISR;
    volatile uint32_t ICR;
    volatile uint32_t RDR;
    volatile uint32_t TDR;
    volatile uint32_t PRESC;
} USART_TypeDef;
#define USART_ISR_PE 0x00000001U
#define USART_ISR_FE 0x00000002U
#define USART_ISR_NE 0x00000004U
#define USART_ISR_ORE 0x00000008U
#define USART_ISR_IDLE 0x00000010U
#define USART_ISR_RXNE_RXFNE 0x00000020U
#define USART_ISR_TC 0x00000040U
#define USART_ISR_TXE_TXFNF 0x00000080U
#define USART_ISR_BUSY 0x00010000U
#define USART_ICR_PECF 0x00000001U
#define USART_ICR_FECF 0x00000002U
#define USART_ICR_NECF 0x00000004U
#define USART_ICR_ORECF 0x00000008U
#define USART_ICR_IDLECF 0x00000010U
#define USART_ICR_TCCF 0x00000040U
#define USART_CR1_UE 0x00000001U
#define USART_CR1_M0 0x00001000U
#define USART_CR1_OVER8 0x00008000U
#define USART_CR1_DEDT 0x001F0000U
#define USART_CR1_DEAT 0x03E00000U
#define USART_CR1_M1 0x10000000U
#define USART_CR1_FIFOEN 0x20000000U
#define USART_CR3_OVRDIS 0x00001000U
#define USART_CR3_DDRE 0x00002000U
#define USART_CR3_DEM 0x00004000U
#define USART_CR3_DEP 0x00008000U
#else
typedef struct {
    volatile uint32_t SR;
    volatile uint32_t DR;
    volatile uint32_t BRR;
    volatile uint32_t CR1;
    volatile uint32_t CR2;
    volatile uint32_t CR3;
    volatile uint32_t GTPR;
} USART_TypeDef;
#define USART_SR_PE 0x00000001U
#define USART_SR_FE 0x00000002U
#define USART_SR_NE 0x00000004U
#define USART_SR_ORE 0x00000008U
#define USART_SR_IDLE 0x00000010U
#define USART_SR_RXNE 0x00000020U
#define USART_SR_TC 0x00000040U
#define USART_SR_TXE 0x00000080U
#define USART_CR1_UE 0x00002000U
#define USART_CR1_M 0x00001000U
#define USART_CR1_OVER8 0x00008000U
/* The F4's two accesses with side effects, each one call the fake sees whole: SR's rc_w0 write
 * (a 1 leaves a flag alone) and the DR read that ends the SR-then-DR sequence clearing IDLE,
 * NE, FE and ORE. */
void stub_usart_sr_clear(USART_TypeDef *u, uint32_t bits);
uint32_t stub_usart_dr_read(USART_TypeDef *u);
#define J288_STM32_SR_CLEAR(u, bits) stub_usart_sr_clear((u), (bits))
#define J288_STM32_DR_READ(u) stub_usart_dr_read(u)
#endif
#define USART_CR1_RE 0x00000004U
#define USART_CR1_TE 0x00000008U
#define USART_CR1_IDLEIE 0x00000010U
#define USART_CR1_RXNEIE 0x00000020U
#define USART_CR1_TCIE 0x00000040U
#define USART_CR1_TXEIE 0x00000080U
#define USART_CR1_PEIE 0x00000100U
#define USART_CR1_PCE 0x00000400U
#define USART_CR3_EIE 0x00000001U
#define USART_CR3_HDSEL 0x00000008U
#define USART_CR3_DMAR 0x00000040U
#define USART_CR3_DMAT 0x00000080U
#define USART_CR3_ONEBIT 0x00000800U

/* ---- DMA: streams (F4, H7) or channels (G4), and the G4's and H7's DMAMUX ---------------- */
/* Address registers hold a host pointer here (they are 32 bits on the silicon). */
#define J288_STM32_DMA_ADDR(a) ((uintptr_t)(a))
#if defined(J288_STUB_CHANNELS)
typedef struct {
    volatile uint32_t CCR;
    volatile uint32_t CNDTR;
    volatile uintptr_t CPAR;
    volatile uintptr_t CMAR;
} DMA_Channel_TypeDef;
typedef struct {
    volatile uint32_t ISR;
    volatile uint32_t IFCR;
} DMA_TypeDef;
#define DMA_CCR_EN 0x00000001U
#define DMA_CCR_TCIE 0x00000002U
#define DMA_CCR_HTIE 0x00000004U
#define DMA_CCR_TEIE 0x00000008U
#define DMA_CCR_DIR 0x00000010U
#define DMA_CCR_CIRC 0x00000020U
#define DMA_CCR_PINC 0x00000040U
#define DMA_CCR_MINC 0x00000080U
#define DMA_CCR_PSIZE 0x00000300U
#define DMA_CCR_MSIZE 0x00000C00U
#define DMA_CCR_MEM2MEM 0x00004000U
#define DMA_ISR_GIF1 0x00000001U
#define DMA_ISR_TCIF1 0x00000002U
#define DMA_ISR_HTIF1 0x00000004U
#define DMA_ISR_TEIF1 0x00000008U
#define DMA_CIRCULAR 0x00000020U
#define DMA_MEMORY_TO_PERIPH 0x00000010U
#define J288_STUB_DMA_INSTANCE DMA_Channel_TypeDef
#else
typedef struct {
    volatile uint32_t CR;
    volatile uint32_t NDTR;
    volatile uintptr_t PAR;
    volatile uintptr_t M0AR;
    volatile uintptr_t M1AR;
    volatile uint32_t FCR;
} DMA_Stream_TypeDef;
typedef struct {
    volatile uint32_t LISR;
    volatile uint32_t HISR;
    volatile uint32_t LIFCR;
    volatile uint32_t HIFCR;
} DMA_TypeDef;
#define DMA_SxCR_EN 0x00000001U
#define DMA_SxCR_DMEIE 0x00000002U
#define DMA_SxCR_TEIE 0x00000004U
#define DMA_SxCR_HTIE 0x00000008U
#define DMA_SxCR_TCIE 0x00000010U
#define DMA_SxCR_PFCTRL 0x00000020U
#define DMA_SxCR_DIR 0x000000C0U
#define DMA_SxCR_DIR_0 0x00000040U
#define DMA_SxCR_CIRC 0x00000100U
#define DMA_SxCR_PINC 0x00000200U
#define DMA_SxCR_MINC 0x00000400U
#define DMA_SxCR_PSIZE 0x00001800U
#define DMA_SxCR_MSIZE 0x00006000U
#define DMA_SxCR_DBM 0x00040000U
#define DMA_SxFCR_DMDIS 0x00000004U /* FIFO mode (direct mode disabled) */
#define DMA_SxFCR_FEIE 0x00000080U
/* Stream 0's flags in LISR; the HAL's StreamIndex shifts them to the stream's. */
#define DMA_LISR_FEIF0 0x00000001U
#define DMA_LISR_DMEIF0 0x00000004U
#define DMA_LISR_TEIF0 0x00000008U
#define DMA_LISR_HTIF0 0x00000010U
#define DMA_LISR_TCIF0 0x00000020U
#define DMA_CIRCULAR 0x00000100U
#define DMA_MEMORY_TO_PERIPH 0x00000040U
#define J288_STUB_DMA_INSTANCE DMA_Stream_TypeDef
#endif
#define DMA_NORMAL 0x00000000U
#define DMA_PERIPH_TO_MEMORY 0x00000000U

#if defined(J288_STUB_DMAMUX)
typedef struct {
    volatile uint32_t CCR;
} DMAMUX_Channel_TypeDef;
typedef struct {
    volatile uint32_t CSR;
    volatile uint32_t CFR;
} DMAMUX_ChannelStatus_TypeDef;
#define DMAMUX_CxCR_DMAREQ_ID 0x000000FFU
#if defined(J288_STUB_G4)
#define DMA_REQUEST_USART1_RX 24U
#define DMA_REQUEST_USART1_TX 25U
#define DMA_REQUEST_USART2_RX 26U
#define DMA_REQUEST_USART2_TX 27U
#else
#define DMA_REQUEST_USART1_RX 41U
#define DMA_REQUEST_USART1_TX 42U
#define DMA_REQUEST_USART2_RX 43U
#define DMA_REQUEST_USART2_TX 44U
#endif
#endif

typedef enum {
    HAL_DMA_STATE_RESET = 0x00u,
    HAL_DMA_STATE_READY = 0x01u,
    HAL_DMA_STATE_BUSY = 0x02u,
    HAL_DMA_STATE_TIMEOUT = 0x03u,
    HAL_DMA_STATE_ERROR = 0x04u,
    HAL_DMA_STATE_ABORT = 0x05u
} HAL_DMA_StateTypeDef;

typedef struct {
#if defined(J288_STUB_DMAMUX)
    uint32_t Request;
#else
    uint32_t Channel;
#endif
    uint32_t Direction;
    uint32_t Mode;
} DMA_InitTypeDef;

/* The fields HAL_DMA_Init fills in that the port reads: where the stream's or channel's
 * flags live, and (G4, H7) its DMAMUX channel. The H7's Instance may be a BDMA channel. */
typedef struct __DMA_HandleTypeDef {
#if defined(J288_STUB_H7)
    void *Instance;
#else
    J288_STUB_DMA_INSTANCE *Instance;
#endif
    DMA_InitTypeDef Init;
    void *Parent;
    volatile HAL_DMA_StateTypeDef State;
#if defined(J288_STUB_CHANNELS)
    DMA_TypeDef *DmaBaseAddress;
    uint32_t ChannelIndex;
#else
    uintptr_t StreamBaseAddress; /* uint32_t in the HAL: a host address here */
    uint32_t StreamIndex;
#endif
#if defined(J288_STUB_DMAMUX)
    DMAMUX_Channel_TypeDef *DMAmuxChannel;
    DMAMUX_ChannelStatus_TypeDef *DMAmuxChannelStatus;
    uint32_t DMAmuxChannelStatusMask;
#endif
} DMA_HandleTypeDef;

#if defined(J288_STUB_H7)
/* The H7's D3-domain BDMA (LPUART1's): channels the port does not drive. */
typedef struct {
    volatile uint32_t CCR;
    volatile uint32_t CNDTR;
    volatile uint32_t CPAR;
    volatile uint32_t CM0AR;
    volatile uint32_t CM1AR;
} BDMA_Channel_TypeDef;
extern BDMA_Channel_TypeDef stub_bdma_channel[8];
#define BDMA_Channel0 (&stub_bdma_channel[0])
#define BDMA_Channel7 (&stub_bdma_channel[7])
#define IS_BDMA_CHANNEL_INSTANCE(INSTANCE)                                                     \
    (((const void *)(INSTANCE) >= (const void *)BDMA_Channel0) &&                                \
     ((const void *)(INSTANCE) <= (const void *)BDMA_Channel7))
#endif

void HAL_DMA_IRQHandler(DMA_HandleTypeDef *hdma);
HAL_DMA_StateTypeDef HAL_DMA_GetState(DMA_HandleTypeDef *hdma);
HAL_StatusTypeDef HAL_DMA_Abort(DMA_HandleTypeDef *hdma);

/* ---- UART handle -------------------------------------------------------------------------- */
typedef struct {
    uint32_t BaudRate;
    uint32_t WordLength;
    uint32_t StopBits;
    uint32_t Parity;
    uint32_t Mode;
    uint32_t HwFlowCtl;
    uint32_t OverSampling;
} UART_InitTypeDef;

/* The HAL keeps transmit and receive states apart (gState, RxState). */
typedef uint32_t HAL_UART_StateTypeDef;
#define HAL_UART_STATE_RESET 0x00000000U
#define HAL_UART_STATE_READY 0x00000020U
#define HAL_UART_STATE_BUSY 0x00000024U
#define HAL_UART_STATE_BUSY_TX 0x00000021U
#define HAL_UART_STATE_BUSY_RX 0x00000022U
#define HAL_UART_STATE_ERROR 0x000000E0U

typedef struct __UART_HandleTypeDef {
    USART_TypeDef *Instance;
    UART_InitTypeDef Init;
    const uint8_t *pTxBuffPtr;
    uint16_t TxXferSize;
    uint8_t *pRxBuffPtr;
    uint16_t RxXferSize;
    DMA_HandleTypeDef *hdmatx;
    DMA_HandleTypeDef *hdmarx;
    volatile HAL_UART_StateTypeDef gState;
    volatile HAL_UART_StateTypeDef RxState;
    volatile uint32_t ErrorCode;
} UART_HandleTypeDef;

HAL_StatusTypeDef HAL_HalfDuplex_Init(UART_HandleTypeDef *huart);
void HAL_UART_IRQHandler(UART_HandleTypeDef *huart);

/* ---- timers ---------------------------------------------------------------------------- */
typedef struct {
    volatile uint32_t CR1;
    volatile uint32_t CR2;
    volatile uint32_t SMCR;
    volatile uint32_t DIER;
    volatile uint32_t SR;
    volatile uint32_t EGR;
    volatile uint32_t CCMR1;
    volatile uint32_t CCMR2;
    volatile uint32_t CCER;
    volatile uint32_t CNT;
    volatile uint32_t PSC;
    volatile uint32_t ARR;
    volatile uint32_t RCR;
    volatile uint32_t CCR1;
    volatile uint32_t CCR2;
    volatile uint32_t CCR3;
    volatile uint32_t CCR4;
} TIM_TypeDef;

typedef struct {
    uint32_t Prescaler;
    uint32_t CounterMode;
    uint32_t Period;
    uint32_t ClockDivision;
    uint32_t AutoReloadPreload;
} TIM_Base_InitTypeDef;

typedef enum {
    HAL_TIM_ACTIVE_CHANNEL_1 = 0x01u,
    HAL_TIM_ACTIVE_CHANNEL_2 = 0x02u,
    HAL_TIM_ACTIVE_CHANNEL_3 = 0x04u,
    HAL_TIM_ACTIVE_CHANNEL_4 = 0x08u,
    HAL_TIM_ACTIVE_CHANNEL_CLEARED = 0x00u
} HAL_TIM_ActiveChannel;

typedef struct __TIM_HandleTypeDef {
    TIM_TypeDef *Instance;
    TIM_Base_InitTypeDef Init;
    HAL_TIM_ActiveChannel Channel;
} TIM_HandleTypeDef;

#define TIM_CHANNEL_1 0x00000000U
#define TIM_CHANNEL_2 0x00000004U
#define TIM_CHANNEL_3 0x00000008U
#define TIM_CHANNEL_4 0x0000000CU

/* Capture/compare interrupt enables (DIER) and flags (SR): bit n for channel n. */
#define TIM_IT_CC1 0x00000002U
#define TIM_IT_CC2 0x00000004U
#define TIM_IT_CC3 0x00000008U
#define TIM_IT_CC4 0x00000010U
#define TIM_FLAG_CC1 0x00000002U
#define TIM_FLAG_CC2 0x00000004U
#define TIM_FLAG_CC3 0x00000008U
#define TIM_FLAG_CC4 0x00000010U
/* Software event generation (EGR): bit n makes channel n's compare flag rise at once. */
#define TIM_EGR_CC1G 0x00000002U
#define TIM_EGR_CC2G 0x00000004U
#define TIM_EGR_CC3G 0x00000008U
#define TIM_EGR_CC4G 0x00000010U
/* Output compare preload: a new compare value waits for the next update event. */
#define TIM_CCMR1_OC1PE 0x00000008U
#define TIM_CCMR1_OC2PE 0x00000800U
#define TIM_CCMR2_OC3PE 0x00000008U
#define TIM_CCMR2_OC4PE 0x00000800U

/* The HAL's register macros, each register access made through stub_tim_read/stub_tim_write
 * (plain loads and stores in stm32_hal_stub.c) so that the fake HAL can let the counter run
 * between any two accesses, as the silicon's does. A read-modify-write is two accesses, as
 * on the silicon. */
uint32_t stub_tim_read(TIM_TypeDef *tim, volatile uint32_t *reg);
void stub_tim_write(TIM_TypeDef *tim, volatile uint32_t *reg, uint32_t value);
#define __HAL_TIM_GET_COUNTER(h) stub_tim_read((h)->Instance, &(h)->Instance->CNT)
#define __HAL_TIM_GET_AUTORELOAD(h) stub_tim_read((h)->Instance, &(h)->Instance->ARR)
#define __HAL_TIM_ENABLE_IT(h, it)                                                             \
    stub_tim_write((h)->Instance, &(h)->Instance->DIER,                                        \
                   stub_tim_read((h)->Instance, &(h)->Instance->DIER) | (it))
#define __HAL_TIM_DISABLE_IT(h, it)                                                            \
    stub_tim_write((h)->Instance, &(h)->Instance->DIER,                                        \
                   stub_tim_read((h)->Instance, &(h)->Instance->DIER) & ~(it))
/* SR bits are cleared by writing 0 (rc_w0), others written as 1 stay untouched. */
#define __HAL_TIM_CLEAR_FLAG(h, f) stub_tim_write((h)->Instance, &(h)->Instance->SR, ~(f))
#define __HAL_TIM_SET_COMPARE(h, ch, v)                                                        \
    stub_tim_write((h)->Instance,                                                              \
                   (ch) == TIM_CHANNEL_1   ? &(h)->Instance->CCR1                              \
                   : (ch) == TIM_CHANNEL_2 ? &(h)->Instance->CCR2                              \
                   : (ch) == TIM_CHANNEL_3 ? &(h)->Instance->CCR3                              \
                                           : &(h)->Instance->CCR4,                             \
                   (v))

HAL_StatusTypeDef HAL_TIM_Base_Init(TIM_HandleTypeDef *htim);
HAL_StatusTypeDef HAL_TIM_Base_Start(TIM_HandleTypeDef *htim);
void HAL_TIM_IRQHandler(TIM_HandleTypeDef *htim);
void HAL_TIM_OC_DelayElapsedCallback(TIM_HandleTypeDef *htim); /* weak in the HAL */

/* ---- CRC unit -------------------------------------------------------------------------- */
#if defined(J288_STUB_F4)
/* The F4's unit has one fixed configuration; its handle only names it. */
typedef struct {
    volatile uint32_t DR;
    volatile uint32_t IDR;
    volatile uint32_t CR;
} CRC_TypeDef;
typedef struct {
    CRC_TypeDef *Instance;
} CRC_HandleTypeDef;
#else
typedef struct {
    volatile uint32_t DR;
    volatile uint32_t IDR;
    volatile uint32_t CR;
    uint32_t RESERVED2;
    volatile uint32_t INIT;
    volatile uint32_t POL;
} CRC_TypeDef;
/* The configurable unit's handle (G4, H7, F7, L4...): the port checks these fields at init. */
typedef struct {
    uint8_t DefaultPolynomialUse;
    uint8_t DefaultInitValueUse;
    uint32_t GeneratingPolynomial;
    uint32_t CRCLength;
    uint32_t InitValue;
    uint32_t InputDataInversionMode;
    uint32_t OutputDataInversionMode;
} CRC_InitTypeDef;
typedef struct {
    CRC_TypeDef *Instance;
    CRC_InitTypeDef Init;
    uint32_t InputDataFormat;
} CRC_HandleTypeDef;
#define DEFAULT_CRC32_POLY 0x04C11DB7U
#define DEFAULT_CRC_INITVALUE 0xFFFFFFFFU
#define DEFAULT_POLYNOMIAL_ENABLE ((uint8_t)0x00U)
#define DEFAULT_POLYNOMIAL_DISABLE ((uint8_t)0x01U)
#define DEFAULT_INIT_VALUE_ENABLE ((uint8_t)0x00U)
#define DEFAULT_INIT_VALUE_DISABLE ((uint8_t)0x01U)
#define CRC_POLYLENGTH_32B 0x00000000U
#define CRC_POLYLENGTH_16B 0x00000008U
#define CRC_INPUTDATA_FORMAT_UNDEFINED 0x00000000U
#define CRC_INPUTDATA_FORMAT_BYTES 0x00000001U
#define CRC_INPUTDATA_FORMAT_HALFWORDS 0x00000002U
#define CRC_INPUTDATA_FORMAT_WORDS 0x00000003U
#define CRC_INPUTDATA_INVERSION_NONE 0x00000000U
#define CRC_INPUTDATA_INVERSION_BYTE 0x00000020U
#define CRC_OUTPUTDATA_INVERSION_DISABLE 0x00000000U
#define CRC_OUTPUTDATA_INVERSION_ENABLE 0x00000080U
#endif

/* Resets the unit to its initial value, feeds BufferLength units of InputDataFormat (words in
 * the servo's configuration), returns the result. */
HAL_StatusTypeDef HAL_CRC_Init(CRC_HandleTypeDef *hcrc);
uint32_t HAL_CRC_Calculate(CRC_HandleTypeDef *hcrc, uint32_t pBuffer[], uint32_t BufferLength);
/* Feeds BufferLength more words without resetting, returns the running result. */
uint32_t HAL_CRC_Accumulate(CRC_HandleTypeDef *hcrc, uint32_t pBuffer[], uint32_t BufferLength);

/* ---- the peripherals' names (what a device header gives) ----------------------------------- */
/* USART1..3 name the fake's first three UARTs in the host tests (fake_hal.c defines the
 * blocks); the link check (stm32_hal_stub.c) gives them RAM of their own. Which DMAMUX request
 * ids belong to which UART is decided by these names, as on the silicon; the stub names those
 * of USART1 and USART2 only, so that USART3 stands for a UART the port's table does not know. */
extern USART_TypeDef stub_usart[3];
#define USART1 (&stub_usart[0])
#define USART2 (&stub_usart[1])
#define USART3 (&stub_usart[2])

#if defined(J288_STUB_F4)
/* Interrupt numbers and peripheral addresses of an STM32F4 (F405/407/446 share them): the
 * link check of the example (board_stub.c). */
typedef enum {
    TIM2_IRQn = 28,
    USART1_IRQn = 37,
    DMA2_Stream2_IRQn = 58,
    DMA2_Stream7_IRQn = 70
} IRQn_Type;
#define TIM2 ((TIM_TypeDef *)0x40000000u)
#define GPIOA ((GPIO_TypeDef *)0x40020000u)
#define GPIOC ((GPIO_TypeDef *)0x40020800u)
#define CRC ((CRC_TypeDef *)0x40023000u)
#define DMA2_Stream2 ((DMA_Stream_TypeDef *)0x40026440u)
#define DMA2_Stream7 ((DMA_Stream_TypeDef *)0x400264B8u)
void HAL_NVIC_SetPriority(IRQn_Type IRQn, uint32_t PreemptPriority, uint32_t SubPriority);
void HAL_NVIC_EnableIRQ(IRQn_Type IRQn);
#endif

#define UART_WORDLENGTH_8B 0x00000000U
#define UART_STOPBITS_1 0x00000000U
#define UART_PARITY_NONE 0x00000000U
#define UART_MODE_TX_RX 0x0000000CU
#define UART_HWCONTROL_NONE 0x00000000U
#define UART_OVERSAMPLING_8 0x00008000U
#define TIM_COUNTERMODE_UP 0x00000000U
#define TIM_CLOCKDIVISION_DIV1 0x00000000U
#define TIM_AUTORELOAD_PRELOAD_DISABLE 0x00000000U

HAL_StatusTypeDef HAL_Init(void);
uint32_t HAL_GetTick(void);

#ifdef __cplusplus
}
#endif

#endif /* J288_STM32_HAL_STUB_H */
