/* board.h - the board bring-up that STM32CubeMX generates in a real project (handles,
 * MX_*_Init, interrupt handlers); here written by hand against the HAL stub. */
#ifndef J288_EXAMPLE_BOARD_H
#define J288_EXAMPLE_BOARD_H

#include "main.h"

#define ESTOP_GPIO_PORT GPIOC
#define ESTOP_PIN ((uint16_t)0x2000u) /* PC13 */

extern UART_HandleTypeDef huart1;
extern DMA_HandleTypeDef hdma_usart1_tx;
extern DMA_HandleTypeDef hdma_usart1_rx;
extern TIM_HandleTypeDef htim2;
extern CRC_HandleTypeDef hcrc;

void board_init(void);
void board_fatal(void);

#endif /* J288_EXAMPLE_BOARD_H */
