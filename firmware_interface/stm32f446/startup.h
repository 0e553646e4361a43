#ifndef PINBALL_FIRMWARE_STM32F446_STARTUP_H
#define PINBALL_FIRMWARE_STM32F446_STARTUP_H
/* What survives a reset: a record in .noinit (stm32f446.ld), which
 * Reset_Handler neither copies nor zeroes. Valid once its magic is set; a
 * power-up finds garbage there and starts it again. */

#include <stdint.h>

#define RESET_RECORD_MAGIC 0x50424657u /* "PBFW" */

typedef struct reset_record {
  uint32_t magic;       /* RESET_RECORD_MAGIC once initialised */
  uint32_t boots;       /* resets since the last power-up */
  uint32_t iwdg_resets; /* of which the IWDG caused (main.c counts them) */
} reset_record;

extern reset_record g_reset_record;

/* The handler every unexpected exception lands in: coils off, then waits for
 * the IWDG. */
void Default_Handler(void);

#endif /* PINBALL_FIRMWARE_STM32F446_STARTUP_H */
