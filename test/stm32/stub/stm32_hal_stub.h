/*
 * stm32_hal_stub.h - the slice of the STM32Cube HAL (and CMSIS core) that port/stm32_hal uses.
 *
 * Written for this project, not taken from ST: it declares only the types, constants, macros
 * and functions that j288_stm32.c names, with the HAL's own names and signatures, so that the
 * port source compiles unchanged against this stub (host tests, the link-only firmware
 * example) and against the real STM32Cube HAL. Register structures list only the registers
 * the port touches; their layout is NOT the silicon's, so nothing built on this stub can drive
 * real hardware. Constants that the port passes back to the HAL (channel numbers, flag bits)
 * carry the values the HAL uses, so a mistake shows up the same way in both builds.
 *
 * Implementations: test/stm32/fake_hal.c (a host-side fake that records calls and fires the
 * HAL's callbacks) and stm32_hal_stub.c (do-nothing bodies so that firmware links).
 */
#ifndef J288_STM32_HAL_STUB_H
#define J288_STM32_HAL_STUB_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ---- common ---------------------------------------------------------------------------- */
typedef enum { HAL_OK = 0x00u, HAL_ERROR = 0x01u, HAL_BUSY = 0x02u, HAL_TIMEOUT = 0x03u } HAL_StatusTypeDef;

/* ---- GPIO ------------------------------------------------------------------------------ */
typedef struct {
    volatile uint32_t OTYPER;
    volatile uint32_t ODR;
    volatile uint32_t BSRR;
} GPIO_TypeDef;

typedef enum { GPIO_PIN_RESET = 0u, GPIO_PIN_SET } GPIO_PinState;

void HAL_GPIO_WritePin(GPIO_TypeDef *GPIOx, uint16_t GPIO_Pin, GPIO_PinState PinState);
GPIO_PinState HAL_GPIO_ReadPin(GPIO_TypeDef *GPIOx, uint16_t GPIO_Pin);

/* ---- DMA and USART registers: two families -------------------------------------------- */
/* The port drives each transaction through the registers. Two register models cover ST's
 * families: the F4's (USART SR/DR, DMA streams with NDTR and flags in LISR/HISR), the default,
 * and the G4's (USART ISR/ICR/RDR/TDR, DMA channels with CNDTR and flags in ISR/IFCR), with
 * -DJ288_STUB_G4. Bit values are the silicon's (RM0390, RM0440); the layouts are not. */
/* Address registers hold a host pointer here (they are 32 bits on the silicon). */
#define J288_STM32_DMA_ADDR(a) ((uintptr_t)(a))
#if defined(J288_STUB_G4)
#define STM32G4
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
#define DMA_CCR_EN 0x00000001u
#define DMA_CCR_TCIE 0x00000002u
#define DMA_CCR_HTIE 0x00000004u
#define DMA_CCR_TEIE 0x00000008u
#define DMA_CCR_CIRC 0x00000020u
#define DMA_ISR_GIF1 0x00000001u
#define DMA_ISR_TCIF1 0x00000002u
#define DMA_ISR_HTIF1 0x00000004u
#define DMA_ISR_TEIF1 0x00000008u
#define J288_STUB_DMA_INSTANCE DMA_Channel_TypeDef

typedef struct {
    volatile uint32_t CR1;
    volatile uint32_t CR2;
    volatile uint32_t CR3;
    volatile uint32_t BRR;
    volatile uint32_t ISR;
    volatile uint32_t ICR;
    volatile uint32_t RDR;
    volatile uint32_t TDR;
} USART_TypeDef;
#define USART_ISR_PE 0x00000001u
#define USART_ISR_FE 0x00000002u
#define USART_ISR_NE 0x00000004u
#define USART_ISR_ORE 0x00000008u
#define USART_ISR_IDLE 0x00000010u
#define USART_ISR_RXNE_RXFNE 0x00000020u
#define USART_ISR_TC 0x00000040u
#define USART_ICR_PECF 0x00000001u
#define USART_ICR_FECF 0x00000002u
#define USART_ICR_NECF 0x00000004u
#define USART_ICR_ORECF 0x00000008u
#define USART_ICR_IDLECF 0x00000010u
#define USART_ICR_TCCF 0x00000040u
#define USART_CR1_UE 0x00000001u
#define USART_CR3_OVRDIS 0x00001000u
#define USART_CR3_DDRE 0x00002000u
#else
/* -DJ288_STUB_H7: the same registers under the H7's name (its DMA1/2 are streams as the F4's),
 * for what the port decides by family rather than by register model (reachable RAM). */
#if defined(J288_STUB_H7)
#define STM32H7
#else
#define STM32F4
#endif
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
#define DMA_SxCR_EN 0x00000001u
#define DMA_SxCR_DMEIE 0x00000002u
#define DMA_SxCR_TEIE 0x00000004u
#define DMA_SxCR_HTIE 0x00000008u
#define DMA_SxCR_TCIE 0x00000010u
#define DMA_SxCR_CIRC 0x00000100u
#define DMA_SxFCR_DMDIS 0x00000004u /* FIFO mode (direct mode disabled) */
/* Stream 0's flags in LISR; the HAL's StreamIndex shifts them to the stream's. */
#define DMA_LISR_FEIF0 0x00000001u
#define DMA_LISR_DMEIF0 0x00000004u
#define DMA_LISR_TEIF0 0x00000008u
#define DMA_LISR_HTIF0 0x00000010u
#define DMA_LISR_TCIF0 0x00000020u
#define J288_STUB_DMA_INSTANCE DMA_Stream_TypeDef

typedef struct {
    volatile uint32_t SR;
    volatile uint32_t DR;
    volatile uint32_t BRR;
    volatile uint32_t CR1;
    volatile uint32_t CR2;
    volatile uint32_t CR3;
} USART_TypeDef;
#define USART_SR_PE 0x00000001u
#define USART_SR_FE 0x00000002u
#define USART_SR_NE 0x00000004u
#define USART_SR_ORE 0x00000008u
#define USART_SR_IDLE 0x00000010u
#define USART_SR_RXNE 0x00000020u
#define USART_SR_TC 0x00000040u
#define USART_CR1_UE 0x00002000u
/* The fake HAL sees the two accesses whose side effects the F4 defines: SR's rc_w0 write,
 * and the DR read that ends the SR-then-DR sequence clearing IDLE, NE, FE and ORE. */
void stub_usart_sr_clear(USART_TypeDef *u, uint32_t bits);
uint32_t stub_usart_dr_read(USART_TypeDef *u);
#define J288_STM32_SR_CLEAR(u, bits) stub_usart_sr_clear((u), (bits))
#define J288_STM32_DR_READ(u) stub_usart_dr_read(u)
#endif
#define USART_CR1_RE 0x00000004u
#define USART_CR1_TE 0x00000008u
#define USART_CR1_IDLEIE 0x00000010u
#define USART_CR1_TCIE 0x00000040u
#define USART_CR1_PEIE 0x00000100u
#define USART_CR3_EIE 0x00000001u
#define USART_CR3_HDSEL 0x00000008u
#define USART_CR3_DMAR 0x00000040u
#define USART_CR3_DMAT 0x00000080u
#define USART_CR3_ONEBIT 0x00000800u

typedef enum {
    HAL_DMA_STATE_RESET = 0x00u,
    HAL_DMA_STATE_READY = 0x01u,
    HAL_DMA_STATE_BUSY = 0x02u,
    HAL_DMA_STATE_TIMEOUT = 0x03u,
    HAL_DMA_STATE_ERROR = 0x04u,
    HAL_DMA_STATE_ABORT = 0x05u
} HAL_DMA_StateTypeDef;

#define DMA_NORMAL 0x00000000u
#define DMA_CIRCULAR 0x00000100u
typedef struct {
    uint32_t Mode;
} DMA_InitTypeDef;

/* The fields HAL_DMA_Init fills in that the port reads: where the stream's or channel's
 * flags live. */
typedef struct __DMA_HandleTypeDef {
    J288_STUB_DMA_INSTANCE *Instance;
    DMA_InitTypeDef Init;
    void *Parent;
    volatile HAL_DMA_StateTypeDef State;
#if defined(J288_STUB_G4)
    DMA_TypeDef *DmaBaseAddress;
    uint32_t ChannelIndex;
#else
    uintptr_t StreamBaseAddress;
    uint32_t StreamIndex;
#endif
} DMA_HandleTypeDef;

void HAL_DMA_IRQHandler(DMA_HandleTypeDef *hdma);
HAL_DMA_StateTypeDef HAL_DMA_GetState(DMA_HandleTypeDef *hdma);
HAL_StatusTypeDef HAL_DMA_Abort(DMA_HandleTypeDef *hdma);

/* ---- UART ------------------------------------------------------------------------------ */
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
#define HAL_UART_STATE_RESET 0x00u
#define HAL_UART_STATE_READY 0x20u
#define HAL_UART_STATE_BUSY 0x24u
#define HAL_UART_STATE_BUSY_TX 0x21u
#define HAL_UART_STATE_BUSY_RX 0x22u
#define HAL_UART_STATE_ERROR 0xE0u

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
HAL_StatusTypeDef HAL_HalfDuplex_EnableTransmitter(UART_HandleTypeDef *huart);
HAL_StatusTypeDef HAL_HalfDuplex_EnableReceiver(UART_HandleTypeDef *huart);
HAL_StatusTypeDef HAL_UART_Transmit_DMA(UART_HandleTypeDef *huart, const uint8_t *pData, uint16_t Size);
HAL_StatusTypeDef HAL_UARTEx_ReceiveToIdle_DMA(UART_HandleTypeDef *huart, uint8_t *pData, uint16_t Size);
HAL_StatusTypeDef HAL_UART_AbortReceive(UART_HandleTypeDef *huart);
HAL_StatusTypeDef HAL_UART_AbortTransmit(UART_HandleTypeDef *huart);
void HAL_UART_IRQHandler(UART_HandleTypeDef *huart);

/* Weak in the HAL; the application defines them (the port never does). */
void HAL_UART_TxCpltCallback(UART_HandleTypeDef *huart);
void HAL_UARTEx_RxEventCallback(UART_HandleTypeDef *huart, uint16_t Size);
void HAL_UART_ErrorCallback(UART_HandleTypeDef *huart);

/* ---- timers ---------------------------------------------------------------------------- */
typedef struct {
    volatile uint32_t CR1;
    volatile uint32_t DIER;
    volatile uint32_t SR;
    volatile uint32_t EGR;
    volatile uint32_t CNT;
    volatile uint32_t PSC;
    volatile uint32_t ARR;
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

#define TIM_CHANNEL_1 0x00000000u
#define TIM_CHANNEL_2 0x00000004u
#define TIM_CHANNEL_3 0x00000008u
#define TIM_CHANNEL_4 0x0000000Cu

/* Capture/compare interrupt enables (DIER) and flags (SR): bit n for channel n. */
#define TIM_IT_CC1 0x00000002u
#define TIM_IT_CC2 0x00000004u
#define TIM_IT_CC3 0x00000008u
#define TIM_IT_CC4 0x00000010u
#define TIM_FLAG_CC1 0x00000002u
#define TIM_FLAG_CC2 0x00000004u
#define TIM_FLAG_CC3 0x00000008u
#define TIM_FLAG_CC4 0x00000010u

/* Software event generation (EGR): bit n makes channel n's compare flag rise at once. */
#define TIM_EGR_CC1G 0x00000002u
#define TIM_EGR_CC2G 0x00000004u
#define TIM_EGR_CC3G 0x00000008u
#define TIM_EGR_CC4G 0x00000010u

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
typedef struct {
    volatile uint32_t DR;
    volatile uint32_t IDR;
    volatile uint32_t CR;
} CRC_TypeDef;

/* The handle of the configurable unit (G4, H7, F7, L4...; the F4's has only Instance): the
 * port checks these fields at init. */
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

#define DEFAULT_CRC32_POLY 0x04C11DB7u
#define DEFAULT_CRC_INITVALUE 0xFFFFFFFFu
#define DEFAULT_POLYNOMIAL_ENABLE ((uint8_t)0x00u)
#define DEFAULT_POLYNOMIAL_DISABLE ((uint8_t)0x01u)
#define DEFAULT_INIT_VALUE_ENABLE ((uint8_t)0x00u)
#define DEFAULT_INIT_VALUE_DISABLE ((uint8_t)0x01u)
#define CRC_POLYLENGTH_32B 0x00000000u
#define CRC_POLYLENGTH_16B 0x00000008u
#define CRC_INPUTDATA_FORMAT_UNDEFINED 0x00000000u
#define CRC_INPUTDATA_FORMAT_BYTES 0x00000001u
#define CRC_INPUTDATA_FORMAT_HALFWORDS 0x00000002u
#define CRC_INPUTDATA_FORMAT_WORDS 0x00000003u
#define CRC_INPUTDATA_INVERSION_NONE 0x00000000u
#define CRC_INPUTDATA_INVERSION_BYTE 0x00000020u
#define CRC_OUTPUTDATA_INVERSION_DISABLE 0x00000000u
#define CRC_OUTPUTDATA_INVERSION_ENABLE 0x00000080u

/* Resets the unit to its initial value, feeds BufferLength units of InputDataFormat (words in
 * the servo's configuration), returns the result. */
HAL_StatusTypeDef HAL_CRC_Init(CRC_HandleTypeDef *hcrc);
uint32_t HAL_CRC_Calculate(CRC_HandleTypeDef *hcrc, uint32_t pBuffer[], uint32_t BufferLength);
/* Feeds BufferLength more words without resetting, returns the running result. */
uint32_t HAL_CRC_Accumulate(CRC_HandleTypeDef *hcrc, uint32_t pBuffer[], uint32_t BufferLength);

/* ---- system ---------------------------------------------------------------------------- */
/* Interrupt numbers and peripheral addresses of an STM32F4 (F405/407/446 share them): the
 * link check of the example (board_stub.c). */
typedef enum {
    TIM2_IRQn = 28,
    USART1_IRQn = 37,
    DMA2_Stream2_IRQn = 58,
    DMA2_Stream7_IRQn = 70
} IRQn_Type;

#define TIM2 ((TIM_TypeDef *)0x40000000u)
#define USART1 ((USART_TypeDef *)0x40011000u)
#define GPIOA ((GPIO_TypeDef *)0x40020000u)
#define GPIOC ((GPIO_TypeDef *)0x40020800u)
#define CRC ((CRC_TypeDef *)0x40023000u)
#define DMA2_Stream2 ((DMA_Stream_TypeDef *)0x40026440u)
#define DMA2_Stream7 ((DMA_Stream_TypeDef *)0x400264B8u)

#define UART_WORDLENGTH_8B 0x00000000u
#define UART_STOPBITS_1 0x00000000u
#define UART_PARITY_NONE 0x00000000u
#define UART_MODE_TX_RX 0x0000000Cu
#define UART_HWCONTROL_NONE 0x00000000u
#define UART_OVERSAMPLING_8 0x00008000u
#define TIM_COUNTERMODE_UP 0x00000000u
#define TIM_CLOCKDIVISION_DIV1 0x00000000u
#define TIM_AUTORELOAD_PRELOAD_DISABLE 0x00000000u

void HAL_NVIC_SetPriority(IRQn_Type IRQn, uint32_t PreemptPriority, uint32_t SubPriority);
void HAL_NVIC_EnableIRQ(IRQn_Type IRQn);
HAL_StatusTypeDef HAL_Init(void);
uint32_t HAL_GetTick(void);

/* ---- CMSIS core (static inline in CMSIS; plain functions here) -------------------------- */
uint32_t __get_PRIMASK(void);
void __set_PRIMASK(uint32_t priMask);
void __disable_irq(void);
/* BASEPRI (ARMv7-M and later): the lowest-urgency priority still taken, 0 = none masked;
 * __set_BASEPRI_MAX only ever raises the mask. Priorities sit in the top __NVIC_PRIO_BITS. */
#ifndef __NVIC_PRIO_BITS
#define __NVIC_PRIO_BITS 4U
#endif
uint32_t __get_BASEPRI(void);
void __set_BASEPRI(uint32_t basePri);
void __set_BASEPRI_MAX(uint32_t basePri);
/* Cache maintenance exists only on a core with a data cache (CMSIS: the device header sets
 * __DCACHE_PRESENT, core_cm7.h declares the functions). The stub models such a core unless
 * told otherwise with -D__DCACHE_PRESENT=0U, which models a Cortex-M4. */
#ifndef __DCACHE_PRESENT
#define __DCACHE_PRESENT 1U
#endif
#if __DCACHE_PRESENT
void SCB_CleanDCache_by_Addr(volatile void *addr, int32_t dsize);
void SCB_InvalidateDCache_by_Addr(volatile void *addr, int32_t dsize);
#endif

#ifdef __cplusplus
}
#endif

#endif /* J288_STM32_HAL_STUB_H */
