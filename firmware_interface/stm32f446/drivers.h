#ifndef PINBALL_FIRMWARE_STM32F446_DRIVERS_H
#define PINBALL_FIRMWARE_STM32F446_DRIVERS_H
/* The driver board's drivers on the STM32F446: one small function set per
 * peripheral, each in its own file (clock.c, time.c, coils.c, eos.c,
 * board_id.c, can.c, iwdg.c). main.c only wires them to the portable core:
 * the output stage (set_coil) and the core's HAL (pinball/firmware/core/
 * hal.h: clock, CAN receive and send, switches). Nothing here allocates,
 * and every wait on hardware is bounded. */

#include <stdbool.h>
#include <stdint.h>

#include "pinball/firmware/core/board.h"

/* ---- clock.c: the clock tree ---- */

/* Where the system clock came from. */
typedef enum clock_source {
  CLOCK_HSI_16MHZ = 0,     /* internal RC: the reset clock, and the fallback */
  CLOCK_HSE_PLL_180MHZ = 1 /* 8 MHz from the ST-LINK's MCO (HSE bypass) through the PLL */
} clock_source;

/* The step of the HSE/PLL bring-up that timed out (CLOCK_STEP_NONE: none). */
typedef enum clock_step {
  CLOCK_STEP_NONE = 0,
  CLOCK_STEP_HSE_READY,
  CLOCK_STEP_OVERDRIVE_READY,
  CLOCK_STEP_OVERDRIVE_SWITCH,
  CLOCK_STEP_PLL_READY,
  CLOCK_STEP_FLASH_LATENCY,
  CLOCK_STEP_SWITCH
} clock_step;

/* The clock tree in force. */
typedef struct clock_tree {
  clock_source source;
  clock_step failed_step; /* why source is CLOCK_HSI_16MHZ, when it is */
  uint32_t sysclk_hz;     /* core and AHB clock, Hz */
  uint32_t apb1_hz;       /* PCLK1 (bxCAN), Hz */
  uint32_t
      apb1_timer_hz; /* TIM2..TIM5 kernel clock, Hz: PCLK1 x2 when APB1 is divided (RM0390, RCC "Clocks") */
} clock_tree;

/* Brings the core to 180 MHz from the 8 MHz HSE bypass, or leaves it on the
 * 16 MHz HSI when any step does not complete in time. Returns the tree. */
clock_tree clock_init(void);

/* ---- time.c: the monotonic clock (TIM2, 1 us resolution) ---- */

/* Starts TIM2 as a free-running 32-bit counter at 1 MHz. */
void time_init(const clock_tree* clock);

/* Time since time_init in the core's unit, nanoseconds (int64), in steps of
 * 1000 (TIM2 counts microseconds). TIM2's 32-bit count is extended in
 * software: correct as long as two calls are less than 2^32 us (71 min)
 * apart, which the main loop (and the IWDG behind it) guarantees.
 * Main-loop context only (not reentrant). */
pbfw_time_ns time_ns(void);

/* TIM2's raw count (1 MHz; the self-test reads it for instruction counts). */
uint32_t time_raw_count(void);

/* ---- coils.c: the 8 gate outputs ---- */

#define COIL_COUNT 8u

/* First thing after reset: every coil pin a push-pull output driven low. */
void coils_safe(void);

/* Starts the PWM timers (TIM3, TIM4) at 0 % duty and hands the pins to them. */
void coils_start_pwm(const clock_tree* clock);

/* Sets driver d's duty: 0 off, 1..99 PWM, 100 fully on. */
void coils_set_duty(unsigned d, uint8_t duty_pct);

/* The core's output stage (pbfw_set_coil_fn without the time): the state
 * decides the duty, 100 % in a pulse, 0 when off; a hold gets duty_pct,
 * limited once more to the absolute cap (50 %). Returns false when it had
 * to limit it, which the core never asks for. */
bool coils_apply(unsigned d, pbfw_coil_state state, uint8_t duty_pct);

/* The duty driver d's timer channel produces now, read back from its CCR. */
uint8_t coils_duty(unsigned d);

/* From any context, even a fault: every coil pin back to a plain output
 * driven low, without trusting the timers. */
void coils_emergency_off(void);

/* ---- eos.c: the 8 end-of-stroke switches ---- */

void eos_init(void);

/* Bit d set when driver d's switch is closed (switches pull to ground). */
uint8_t eos_read(void);

/* ---- board_id.c: the board id straps ---- */

/* The board id, 0..15: PINBALL_BOARD_ID when the build fixes it, else the
 * four straps (a jumper to ground sets its bit). */
uint8_t board_id_read(void);

/* ---- iwdg.c: the independent watchdog and the reset cause ---- */

/* The reset causes RCC_CSR latched (RCC_CSR_*RSTF bits), read once and cleared. */
uint32_t reset_cause_take(void);

/* The IWDG's timeout at the LSI's nominal 32 kHz (6.8..18.8 ms over the
 * LSI's 17..47 kHz range; iwdg.c says why). */
#define IWDG_TIMEOUT_MS 10u

/* Starts the IWDG: it resets the MCU when iwdg_refresh is not called for
 * IWDG_TIMEOUT_MS. Nothing can stop it but a reset. */
void iwdg_start(void);
void iwdg_refresh(void);

/* ---- can.c: bxCAN1 ---- */

/* What the CAN driver counted (each wraps at 2^32). */
typedef struct can_counters {
  uint32_t rx_frames;     /* frames taken from FIFO 0 */
  uint32_t rx_overruns;   /* frames lost: hardware FIFO 0 overrun */
  uint32_t rx_ring_full;  /* frames lost: software ring full */
  uint32_t tx_frames;     /* frames handed to a mailbox */
  uint32_t bus_errors;    /* error frames seen (LEC changes) */
  uint32_t bus_off;       /* bus-off entries (left by ABOM) */
  uint32_t error_passive; /* error-passive entries */
  uint32_t init_timeouts; /* INAK did not follow INRQ in time */
} can_counters;

/* Configures bxCAN1 on PA11/PA12 at 500 kbit/s from the APB1 clock, one
 * filter for the protocol's ids, FIFO 0 by interrupt. False when the
 * controller did not acknowledge a mode change in time (counted; it keeps
 * trying on its own). */
bool can_init(const clock_tree* clock);

/* Takes the oldest received frame; false when none. Main loop only. */
bool can_receive(pbfw_frame* out);

/* Puts a frame into a free TX mailbox; false when all three are busy (the
 * caller keeps it and offers it again). Main loop only. */
bool can_send(const pbfw_frame* frame);

/* Once a main-loop pass: lets an error interrupt that fired on bus-off or
 * error passive fire again once the condition has cleared. */
void can_poll(void);

/* A copy of the counters. */
can_counters can_get_counters(void);

#endif /* PINBALL_FIRMWARE_STM32F446_DRIVERS_H */
