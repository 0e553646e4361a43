/* The driver board: PROTOCOL.md's firmware rules (the portable core,
 * firmware_interface/core/board.c) wired to the STM32F446's CAN, timers and pins.
 *
 * Start-up order, safest first:
 *   1. coils off: the gate pins driven low (they float until then; the
 *      board's gate pull-downs hold them, coils.c);
 *   2. the reset cause, kept in the reset record;
 *   3. clocks (180 MHz, or the 16 MHz HSI fallback);
 *   4. the microsecond timer, then PWM at 0 % on every coil, the switches;
 *   5. the IWDG: from here a stalled loop resets the MCU within 19 ms;
 *   6. CAN, and the core (out of session, every driver off).
 *
 * The loop is the core's own pass (pbfw_board_service, firmware_interface/core/
 * service.c) over this board's drivers, then the IWDG refresh: one
 * iteration takes a few microseconds idle, under 1 ms with 16 frames to
 * handle (docs/results.md). It does not sleep: the core's deadlines are met
 * by polling the clock, so a pulse ends at most one iteration after its
 * deadline. */

#include <stddef.h>

#include "drivers.h"
#include "pinball/firmware/core/hal.h"
#include "registers.h"
#include "startup.h"

#ifndef PINBALL_FW_MAJOR
#define PINBALL_FW_MAJOR 1
#endif
#ifndef PINBALL_FW_MINOR
#define PINBALL_FW_MINOR 0
#endif

#define STATUS_PERIOD_NS 10000000 /* rule 12: 10 ms */
#define RX_FRAMES_PER_PASS 16u /* the RX ring's size (can.c) */

/* The platform's own health, which the protocol has no field for: read it
 * with a debugger (symbol g_board_state) on the bench. */
typedef struct board_state {
  clock_tree clock;       /* the clock tree in force */
  uint32_t reset_causes;  /* RCC_CSR reset flags at this boot */
  bool can_acknowledged;  /* bxCAN followed its mode changes at init */
  uint8_t board_id;       /* straps or PINBALL_BOARD_ID */
  uint32_t output_clamps; /* coil commands the output stage had to limit (0 expected) */
  uint32_t loops;         /* main loop iterations (wraps) */
  uint32_t max_loop_ns;   /* longest iteration since boot */
} board_state;

/* tools/qemu-boot-test.sh reads these three over QEMU's monitor. */
_Static_assert(offsetof(board_state, output_clamps) == 24, "qemu-boot-test.sh reads output_clamps at 24");
_Static_assert(offsetof(board_state, loops) == 28, "qemu-boot-test.sh reads loops at 28");
_Static_assert(offsetof(board_state, max_loop_ns) == 32, "qemu-boot-test.sh reads max_loop_ns at 32");

board_state g_board_state;
static pbfw_board board;

/* The core's output stage (coils_apply). The change is applied now: at_ns
 * is when the rule says it happened, earlier than now only when the loop was
 * late, and the hardware cannot go back. */
static void set_coil(void* context, unsigned driver, pbfw_coil_state state, uint8_t duty_pct,
                     pbfw_time_ns at_ns) {
  (void)context;
  (void)at_ns;
  if (!coils_apply(driver, state, duty_pct)) ++g_board_state.output_clamps;
}

/* The HAL's functions: the drivers as the core's loop calls them. */
static pbfw_time_ns hal_now_ns(void* context) {
  (void)context;
  return time_ns();
}
static bool hal_receive(void* context, pbfw_frame* frame) {
  (void)context;
  return can_receive(frame);
}
static bool hal_send(void* context, const pbfw_frame* frame) {
  (void)context;
  return can_send(frame);
}
static uint8_t hal_end_of_stroke(void* context) {
  (void)context;
  return eos_read();
}

/* Counts the boot in the reset record; a power-on or brown-out reset (or a
 * record that was never written) starts it again. */
static void record_reset(uint32_t causes) {
  if ((causes & (RCC_CSR_PORRSTF | RCC_CSR_BORRSTF)) || g_reset_record.magic != RESET_RECORD_MAGIC) {
    g_reset_record.magic = RESET_RECORD_MAGIC;
    g_reset_record.boots = 0u;
    g_reset_record.iwdg_resets = 0u;
  }
  ++g_reset_record.boots;
  /* The protocol has no message for "I was reset by my watchdog"; the host
   * sees the restart as a Status without its configured bits and starts a
   * new session (PROTOCOL.md, handshake step 5). The count is kept here for
   * the bench. */
  if (causes & RCC_CSR_IWDGRSTF) ++g_reset_record.iwdg_resets;
}

int main(void) {
  coils_safe();
  g_board_state.reset_causes = reset_cause_take();
  record_reset(g_board_state.reset_causes);
  g_board_state.clock = clock_init();
  time_init(&g_board_state.clock);
  coils_start_pwm(&g_board_state.clock);
  eos_init();
  g_board_state.board_id = board_id_read();
  iwdg_start();
  g_board_state.can_acknowledged = can_init(&g_board_state.clock);

  const pbfw_board_options options = {
      .board_id = g_board_state.board_id,
      .driver_count = COIL_COUNT,
      .status_period_ns = STATUS_PERIOD_NS,
      .fw_major = PINBALL_FW_MAJOR,
      .fw_minor = PINBALL_FW_MINOR,
      .set_coil = set_coil,
      .set_coil_context = NULL,
  };
  if (pbfw_board_init(&board, &options) != PBFW_INIT_OK) Default_Handler(); /* constant options: never */

  /* The core's hardware seam (pinball/firmware/core/hal.h) on this board. */
  const pbfw_hal hal = {
      .context = NULL,
      .now_ns = hal_now_ns,
      .receive = hal_receive,
      .send = hal_send,
      .end_of_stroke = hal_end_of_stroke,
  };
  pbfw_time_ns loop_start = time_ns();
  for (;;) {
    /* One pass of the core's loop: the clock once, at most
     * RX_FRAMES_PER_PASS frames (so a flooded bus cannot hold off the
     * timers or the IWDG refresh), the switches, the timers, then replies
     * into the TX mailboxes while one is free. */
    (void)pbfw_board_service(&board, &hal, RX_FRAMES_PER_PASS);
    can_poll();

    /* The core has been serviced: only now does the IWDG hear from us. */
    iwdg_refresh();

    const pbfw_time_ns now = time_ns();
    const pbfw_time_ns took = now - loop_start; /* < 19 ms, or the IWDG would have reset us */
    if (took > (pbfw_time_ns)g_board_state.max_loop_ns) g_board_state.max_loop_ns = (uint32_t)took;
    loop_start = now;
    ++g_board_state.loops;
  }
}
