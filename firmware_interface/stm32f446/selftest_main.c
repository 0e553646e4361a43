/* The QEMU self-test image: the board's start-up code, clock, timer and PWM
 * drivers and the real core (firmware_interface/core/), driven through a scripted
 * session instead of CAN (QEMU models no bxCAN). It checks the coil outputs
 * the hardware would produce, read back from TIM3/TIM4's compare registers,
 * against PROTOCOL.md's rules, then measures the instructions the frame
 * handler and the timer tick execute on their longest paths.
 *
 *   qemu-system-arm -M netduinoplus2 -nographic -icount shift=0 \
 *       -semihosting-config enable=on,target=native \
 *       -kernel pinball_driver_board_selftest.elf
 *
 * Output goes over semihosting; the exit code is the number of failed
 * checks (0: all passed). With -icount shift=0, QEMU's virtual clock moves
 * 1 ns per instruction and its STM32F2xx timer model counts that clock
 * divided by TIM2's prescaler, so TIM2 at prescaler 0 counts instructions.
 *
 * Three parts:
 *   1. rules: a scripted session on scripted time (exact deadlines);
 *   2. time: TIM2 through time.c, its 32-bit wrap, a live session on it;
 *   3. instruction counts of pbfw_board_on_frame and pbfw_board_advance on
 *      their worst paths (8 drivers expiring in one call, a full outbox). */

#include <stddef.h>

#include "drivers.h"
#include "pinball/firmware/core/hal.h"
#include "registers.h"
#include "semihosting.h"

#define MS ((pbfw_time_ns)1000000)
#define BOARD_ID 0u
#define MAX_EVENTS 64u
#define MAX_REPLIES 64u

/* The stack's ends, from the linker script. */
extern uint32_t _sstack[], _estack[]; /* NOLINT(bugprone-reserved-identifier): stm32f446.ld's names */

/* ---------------------------------------------------------------- checks */

static uint32_t checks;
static uint32_t failures;

static void report(bool ok, const char* what, const char* detail_name, int64_t expected, int64_t got) {
  ++checks;
  text_line l;
  line_start(&l);
  line_text(&l, ok ? "ok   " : "FAIL ");
  line_text(&l, what);
  if (!ok && detail_name != NULL) {
    line_text(&l, " (");
    line_text(&l, detail_name);
    line_text(&l, ": expected ");
    line_i64(&l, expected);
    line_text(&l, ", got ");
    line_i64(&l, got);
    line_text(&l, ")");
  }
  line_write(&l);
  if (!ok) ++failures;
}

static void check(bool ok, const char* what) { report(ok, what, NULL, 0, 0); }

static void check_eq(const char* what, int64_t expected, int64_t got) {
  report(expected == got, what, "value", expected, got);
}

static void heading(const char* text) {
  text_line l;
  line_start(&l);
  line_text(&l, "== ");
  line_text(&l, text);
  line_write(&l);
}

/* ------------------------------------------------- the board under test */

static pbfw_board board;
static pbfw_time_ns now; /* scripted time, ns */

/* What the core asked of the output stage, in order. */
typedef struct coil_event {
  unsigned driver;
  pbfw_coil_state state;
  uint8_t duty_pct;
  pbfw_time_ns at_ns;
} coil_event;
static coil_event events[MAX_EVENTS];
static unsigned event_count;
static uint32_t output_clamps;

/* The output stage as main.c wires it, and a log of every call. */
static void set_coil_logged(void* context, unsigned d, pbfw_coil_state state, uint8_t duty_pct,
                            pbfw_time_ns at_ns) {
  (void)context;
  if (!coils_apply(d, state, duty_pct)) ++output_clamps;
  if (event_count < MAX_EVENTS) {
    coil_event e = {d, state, duty_pct, at_ns};
    events[event_count++] = e;
  }
}

/* The output stage exactly as main.c wires it (no log): for the counts. */
static void set_coil_plain(void* context, unsigned d, pbfw_coil_state state, uint8_t duty_pct,
                           pbfw_time_ns at_ns) {
  (void)context;
  (void)at_ns;
  if (!coils_apply(d, state, duty_pct)) ++output_clamps;
}

/* The board's replies since the last step, decoded. */
static pbfw_message replies[MAX_REPLIES];
static unsigned reply_count;
static uint32_t undecodable_replies;

static void drain(pbfw_board* b) {
  pbfw_frame f;
  while (pbfw_board_pop_tx(b, &f)) {
    pbfw_message m;
    if (pbfw_decode(&f, &m, NULL) != PBFW_DECODE_OK) {
      ++undecodable_replies;
      continue;
    }
    if (reply_count < MAX_REPLIES) replies[reply_count++] = m;
  }
}

/* The board's options, as main.c gives them, with the output stage `set_coil`. */
static pbfw_board_options board_options(pbfw_set_coil_fn set_coil) {
  const pbfw_board_options options = {
      .board_id = BOARD_ID,
      .driver_count = COIL_COUNT,
      .status_period_ns = 10 * MS,
      .fw_major = 1,
      .fw_minor = 0,
      .set_coil = set_coil,
      .set_coil_context = NULL,
  };
  return options;
}

static void init_board(pbfw_board* b, pbfw_set_coil_fn set_coil) {
  const pbfw_board_options options = board_options(set_coil);
  const pbfw_init_error e = pbfw_board_init(b, &options);
  check_eq("pbfw_board_init accepts the board's options", PBFW_INIT_OK, e);
}

/* A new step: forget the previous step's events and replies. */
static void step(const char* name) {
  heading(name);
  event_count = 0u;
  reply_count = 0u;
}

static void deliver(const pbfw_frame* f) {
  pbfw_board_on_frame(&board, f, now);
  drain(&board);
}

static pbfw_frame encode(pbfw_message m) {
  m.board = BOARD_ID;
  pbfw_frame f = {0};
  pbfw_encode(&m, &f);
  return f;
}

static pbfw_frame hello_frame(uint8_t version, uint16_t watchdog_ms) {
  pbfw_message m = {.kind = PBFW_HELLO};
  m.u.hello.version = version;
  m.u.hello.watchdog_ms = watchdog_ms;
  return encode(m);
}

static pbfw_frame configure_frame(uint8_t d, uint8_t pulse_ms, uint8_t hold_pct, uint8_t max_pulse_ms,
                                  uint8_t recycle_ms, uint16_t max_hold_ms) {
  pbfw_message m = {.kind = PBFW_CONFIGURE};
  m.u.configure.driver = d;
  m.u.configure.config.pulse_ms = pulse_ms;
  m.u.configure.config.hold_duty_pct = hold_pct;
  m.u.configure.config.max_pulse_ms = max_pulse_ms;
  m.u.configure.config.recycle_ms = recycle_ms;
  m.u.configure.config.max_hold_ms = max_hold_ms;
  return encode(m);
}

static pbfw_frame heartbeat_frame(uint16_t seq) {
  pbfw_message m = {.kind = PBFW_HEARTBEAT};
  m.u.heartbeat.version = PBFW_PROTOCOL_VERSION;
  m.u.heartbeat.seq = seq;
  return encode(m);
}

static pbfw_frame fire_frame(uint8_t d, pbfw_fire_mode mode, uint8_t pulse_ms, uint16_t seq) {
  pbfw_message m = {.kind = PBFW_FIRE};
  m.u.fire.driver = d;
  m.u.fire.mode = (uint8_t)mode;
  m.u.fire.pulse_ms = pulse_ms;
  m.u.fire.seq = seq;
  return encode(m);
}

static pbfw_frame release_frame(uint8_t d, uint16_t seq) {
  pbfw_message m = {.kind = PBFW_RELEASE};
  m.u.release.driver = d;
  m.u.release.seq = seq;
  return encode(m);
}

static pbfw_frame release_all_frame(uint16_t seq) {
  pbfw_message m = {.kind = PBFW_RELEASE_ALL};
  m.u.release_all.seq = seq;
  return encode(m);
}

static void hello(uint8_t version, uint16_t watchdog_ms) {
  const pbfw_frame f = hello_frame(version, watchdog_ms);
  deliver(&f);
}
static void configure(uint8_t d, uint8_t pulse_ms, uint8_t hold_pct, uint8_t max_pulse_ms, uint8_t recycle_ms,
                      uint16_t max_hold_ms) {
  const pbfw_frame f = configure_frame(d, pulse_ms, hold_pct, max_pulse_ms, recycle_ms, max_hold_ms);
  deliver(&f);
}
static void heartbeat(uint16_t seq) {
  const pbfw_frame f = heartbeat_frame(seq);
  deliver(&f);
}
static void fire(uint8_t d, pbfw_fire_mode mode, uint8_t pulse_ms, uint16_t seq) {
  const pbfw_frame f = fire_frame(d, mode, pulse_ms, seq);
  deliver(&f);
}
static void advance_to(pbfw_time_ns t) {
  now = t;
  pbfw_board_advance(&board, now);
  drain(&board);
}

/* The number of replies of `kind` (and, for a Fault, of `code`) this step. */
static unsigned count_replies(pbfw_kind kind, unsigned code) {
  unsigned n = 0u;
  for (unsigned i = 0; i < reply_count; ++i) {
    if (replies[i].kind != kind) continue;
    if (kind == PBFW_FAULT && replies[i].u.fault.code != code) continue;
    ++n;
  }
  return n;
}

static const pbfw_message* last_reply(pbfw_kind kind) {
  for (unsigned i = reply_count; i > 0u; --i) {
    if (replies[i - 1u].kind == kind) return &replies[i - 1u];
  }
  return NULL;
}

static void check_fault(const char* what, pbfw_fault_code code, int64_t detail) {
  const pbfw_message* m = last_reply(PBFW_FAULT);
  check(m != NULL && m->u.fault.code == code, what);
  if (m != NULL && m->u.fault.code == code) check_eq("  its detail", detail, m->u.fault.detail);
}

static bool has_event(unsigned d, pbfw_coil_state state, uint8_t duty, pbfw_time_ns at) {
  for (unsigned i = 0; i < event_count; ++i) {
    const coil_event* e = &events[i];
    if (e->driver == d && e->state == state && e->duty_pct == duty && e->at_ns == at) return true;
  }
  return false;
}

/* The duty each coil output should show now. */
static uint8_t expected_duty[COIL_COUNT];

/* The outputs as the hardware produces them (TIM3/TIM4 CCR, read back)
 * against what the rules say, and against the core's own state. */
static void check_outputs(const char* what) {
  const pbfw_status s = pbfw_board_status(&board);
  bool ok = true;
  for (unsigned d = 0; d < COIL_COUNT; ++d) {
    const uint8_t hw = coils_duty(d);
    const unsigned core_state = (s.coil_states >> (2u * d)) & 3u;
    const uint8_t core_duty = core_state == PBFW_COIL_PULSE  ? 100u
                              : core_state == PBFW_COIL_HOLD ? board.drivers[d].duty_pct
                                                             : 0u;
    if (hw == expected_duty[d] && hw == core_duty) continue;
    text_line l;
    line_start(&l);
    line_text(&l, "     driver ");
    line_u32(&l, d);
    line_text(&l, ": PWM compare register ");
    line_u32(&l, hw);
    line_text(&l, " %, the rules say ");
    line_u32(&l, expected_duty[d]);
    line_text(&l, " %, the core's state says ");
    line_u32(&l, core_duty);
    line_text(&l, " %");
    line_write(&l);
    ok = false;
  }
  check(ok, what);
}

/* ------------------------------------------------ part 1: the rules */

static void rules(void) {
  const pbfw_time_ns t0 = 1000 * MS; /* any origin */
  now = t0;
  init_board(&board, set_coil_logged);
  for (unsigned d = 0; d < COIL_COUNT; ++d) expected_duty[d] = 0u;

  step("power-up: every coil off, a Status (rules 1, 12)");
  advance_to(t0);
  check_eq("one Status", 1, count_replies(PBFW_STATUS, 0));
  check_outputs("every output at 0 %");

  step("Fire before Hello is refused (rule 2)");
  fire(0, PBFW_PULSE_HOLD, 0, 1);
  check_fault("Fault 6 not configured", PBFW_FAULT_NOT_CONFIGURED, PBFW_FIRE);
  check_eq("no coil switched", 0, event_count);
  check_outputs("every output at 0 %");

  step("Hello of protocol 1 is refused (Fault 5)");
  hello(1, 100);
  check_fault("Fault 5 version mismatch", PBFW_FAULT_VERSION_MISMATCH, 1);
  check_eq("no HelloAck", 0, count_replies(PBFW_HELLO_ACK, 0));

  step("Hello v2, watchdog 100 ms: HelloAck and Status (handshake 1-2)");
  hello(PBFW_PROTOCOL_VERSION, 100);
  const pbfw_message* ack = last_reply(PBFW_HELLO_ACK);
  check(ack != NULL, "a HelloAck");
  if (ack != NULL) {
    check_eq("  its version", PBFW_PROTOCOL_VERSION, ack->u.hello_ack.version);
    check_eq("  its driver count", COIL_COUNT, ack->u.hello_ack.driver_count);
  }
  check_eq("a Status after it", 1, count_replies(PBFW_STATUS, 0));

  step("Configure drivers 0 and 5: a Status each (rule 12)");
  configure(0, 30, 25, 40, 10, 5000); /* pulse 30 ms, hold 25 %, caps 40 ms / 5 s, recycle 10 ms */
  configure(5, 20, 0, 20, 10, 1000);  /* pulse only */
  const pbfw_message* st = last_reply(PBFW_STATUS);
  check_eq("two Status", 2, count_replies(PBFW_STATUS, 0));
  check_eq("configured bits", 0x21, st != NULL ? st->u.status.configured : -1);

  step("Fire before the first Heartbeat is refused (rule 3)");
  fire(0, PBFW_PULSE_HOLD, 0, 10);
  check_fault("Fault 7 not armed", PBFW_FAULT_NOT_ARMED, 0);
  check_outputs("every output at 0 %");

  step("Heartbeat arms the watchdog");
  now = t0 + 5 * MS;
  heartbeat(11);
  advance_to(t0 + 10 * MS);
  st = last_reply(PBFW_STATUS);
  check(st != NULL && (st->u.status.faults & PBFW_FAULT_BIT_ARMED) != 0u, "Status shows armed");

  step("Fire driver 0, pulse then hold: 100 % now (rule 5)");
  const pbfw_time_ns tf = t0 + 20 * MS;
  now = tf;
  heartbeat(12);
  fire(0, PBFW_PULSE_HOLD, 0, 13);
  check(has_event(0, PBFW_COIL_PULSE, 100, tf), "set_coil(0, pulse, 100 %) at the Fire");
  expected_duty[0] = 100u;
  check_outputs("driver 0 at 100 %, the rest at 0 %");

  step("the pulse lasts the configured 30 ms, then the hold at 25 % (rules 5, 6)");
  advance_to(tf + 30 * MS - 1);
  check_eq("no change 1 ns before the deadline", 0, event_count);
  check_outputs("driver 0 still at 100 %");
  advance_to(tf + 30 * MS);
  check(has_event(0, PBFW_COIL_HOLD, 25, tf + 30 * MS), "set_coil(0, hold, 25 %) at exactly 30 ms");
  expected_duty[0] = 25u;
  check_outputs("driver 0 at 25 %");

  step("a stale Fire is ignored and reported (rule 9)");
  now = tf + 31 * MS;
  fire(0, PBFW_PULSE_HOLD, 0, 13);
  check_fault("Fault 8 stale", PBFW_FAULT_STALE, 13);
  check_eq("no coil switched", 0, event_count);
  check_outputs("driver 0 still at 25 %");

  step("a corrupted frame changes nothing (rule 11)");
  pbfw_frame bad = fire_frame(5, PBFW_PULSE_ONLY, 0, 14);
  bad.data[bad.len - 1u] ^= 0x01u; /* one bit of the CRC */
  deliver(&bad);
  check_fault("Fault 4 bad frame, CRC", PBFW_FAULT_BAD_FRAME, PBFW_DECODE_BAD_CHECKSUM);
  pbfw_frame short_frame = fire_frame(5, PBFW_PULSE_ONLY, 0, 14);
  short_frame.len = 5u;
  deliver(&short_frame);
  check_fault("Fault 4 bad frame, length", PBFW_FAULT_BAD_FRAME, PBFW_DECODE_WRONG_LENGTH);
  check_eq("no coil switched", 0, event_count);
  check_outputs("driver 5 still at 0 %");

  step("a pulse asked longer than max_pulse_ms is clamped and reported (rule 5)");
  const pbfw_time_ns t5 = tf + 35 * MS;
  now = t5;
  heartbeat(15);
  fire(5, PBFW_PULSE_ONLY, 50, 16);
  check_fault("Fault 3 pulse clamped", PBFW_FAULT_PULSE_CLAMPED, 50);
  expected_duty[5] = 100u;
  check_outputs("driver 5 at 100 %");
  advance_to(t5 + 20 * MS);
  check(has_event(5, PBFW_COIL_OFF, 0, t5 + 20 * MS), "driver 5 off after max_pulse_ms (20 ms), not 50");
  expected_duty[5] = 0u;
  check_outputs("driver 5 at 0 %");

  step("no Fire within recycle_ms of the last off (rule 8)");
  now = t5 + 25 * MS;
  const uint64_t recycled_before = board.counters.refused_recycle;
  fire(5, PBFW_PULSE_ONLY, 0, 17);
  check_eq("refused (counted)", 1, (int64_t)(board.counters.refused_recycle - recycled_before));
  check_outputs("driver 5 still at 0 %");
  now = t5 + 30 * MS;
  fire(5, PBFW_PULSE_ONLY, 0, 18);
  check(has_event(5, PBFW_COIL_PULSE, 100, t5 + 30 * MS), "accepted at exactly recycle_ms");
  expected_duty[5] = 100u;
  check_outputs("driver 5 at 100 %");

  step("a late main loop: the pulse still ends at its own deadline (rule 13)");
  advance_to(t5 + 70 * MS); /* the pulse (20 ms) ended at t5 + 50 ms */
  check(has_event(5, PBFW_COIL_OFF, 0, t5 + 50 * MS),
        "set_coil(5, off) stamped at the deadline, not at the late call");
  expected_duty[5] = 0u;
  check_outputs("driver 5 at 0 %");

  step("a repeated Fire on an energised coil is ignored (rule 7)");
  const uint64_t busy_before = board.counters.refused_busy;
  fire(0, PBFW_PULSE_HOLD, 0, 19);
  check_eq("refused (counted)", 1, (int64_t)(board.counters.refused_busy - busy_before));
  check_eq("no coil switched", 0, event_count);
  check_outputs("driver 0 still at 25 %");

  step("a replayed Heartbeat does not feed the watchdog (rule 4)");
  now = t5 + 80 * MS;
  heartbeat(15); /* the last one again */
  advance_to(t5 + 100 * MS - 1);
  check_eq("still on 1 ns before the deadline", 0, event_count);
  check_outputs("driver 0 still at 25 %");

  step("heartbeats stop: every coil off at the watchdog deadline (rule 4)");
  advance_to(t5 + 130 * MS); /* late again */
  check(has_event(0, PBFW_COIL_OFF, 0, t5 + 100 * MS),
        "set_coil(0, off) at exactly 100 ms after the last Heartbeat");
  check_fault("Fault 1 watchdog", PBFW_FAULT_WATCHDOG_EXPIRED, 100);
  expected_duty[0] = 0u;
  check_outputs("every output at 0 %");
  st = last_reply(PBFW_STATUS);
  check(st != NULL && (st->u.status.faults & PBFW_FAULT_BIT_WATCHDOG) &&
            !(st->u.status.faults & PBFW_FAULT_BIT_ARMED),
        "Status: watchdog bit set, armed bit clear");

  step("Fire after the watchdog expired is refused (rule 3)");
  fire(0, PBFW_PULSE_HOLD, 0, 20);
  check_fault("Fault 7 not armed", PBFW_FAULT_NOT_ARMED, 0);
  check_outputs("every output at 0 %");

  step("the hold cap ends the hold and locks the driver (rule 6)");
  const pbfw_time_ns th = t5 + 140 * MS;
  now = th;
  heartbeat(21);
  configure(0, 30, 25, 40, 0, 50); /* hold cap 50 ms */
  fire(0, PBFW_PULSE_HOLD, 0, 22);
  expected_duty[0] = 100u;
  check_outputs("driver 0 at 100 %");
  now = th + 20 * MS;
  heartbeat(23);
  advance_to(th + 30 * MS);
  expected_duty[0] = 25u;
  check_outputs("driver 0 at 25 %");
  now = th + 40 * MS;
  heartbeat(24);
  now = th + 60 * MS;
  heartbeat(25);
  event_count = 0u;
  advance_to(th + 80 * MS);
  check(has_event(0, PBFW_COIL_OFF, 0, th + 80 * MS), "set_coil(0, off) at exactly 30 + 50 ms");
  check_fault("Fault 2 hold cap", PBFW_FAULT_HOLD_CAP_REACHED, 50);
  expected_duty[0] = 0u;
  check_outputs("driver 0 at 0 %");
  now = th + 85 * MS;
  fire(0, PBFW_PULSE_HOLD, 0, 26);
  check_fault("a locked driver refuses Fire: Fault 9", PBFW_FAULT_LOCKED, 0);
  check_outputs("driver 0 still at 0 %");
  const pbfw_frame rel = release_frame(0, 27);
  deliver(&rel);
  fire(0, PBFW_PULSE_HOLD, 0, 28);
  check(has_event(0, PBFW_COIL_PULSE, 100, th + 85 * MS), "after Release it fires again");
  expected_duty[0] = 100u;
  check_outputs("driver 0 at 100 %");

  step("Hello switches every coil off (rule 1)");
  hello(PBFW_PROTOCOL_VERSION, 100);
  check(has_event(0, PBFW_COIL_OFF, 0, th + 85 * MS), "set_coil(0, off) on Hello");
  expected_duty[0] = 0u;
  check_outputs("every output at 0 %");

  step("ReleaseAll is obeyed whatever its seq (rule 10)");
  now = th + 90 * MS;
  configure(0, 30, 25, 40, 0, 5000);
  heartbeat(40);
  fire(0, PBFW_PULSE_HOLD, 0, 41);
  expected_duty[0] = 100u;
  check_outputs("driver 0 at 100 %");
  const pbfw_frame all = release_all_frame(3); /* far older than 41 */
  deliver(&all);
  check(has_event(0, PBFW_COIL_OFF, 0, th + 90 * MS), "set_coil(0, off) on an old ReleaseAll");
  expected_duty[0] = 0u;
  check_outputs("every output at 0 %");

  step("the output stage never had to limit a duty");
  check_eq("coils_apply clamps", 0, output_clamps);
  check_eq("undecodable replies from the board", 0, undecodable_replies);
}

/* ------------------------------------------------ part 2: TIM2 time */

/* The core's HAL for the live session: TIM2 time, frames from a script, and
 * a transmitter that, like the bxCAN's three mailboxes, takes at most three
 * frames a pass and checks that each is the next Status/Fault/HelloAck in
 * sequence (the outbox keeps what it refuses). */
#define SCRIPT_SIZE 8u
static pbfw_frame script[SCRIPT_SIZE];
static unsigned script_head, script_count;
static unsigned sent_this_pass;
static pbfw_time_ns last_pass_ns;
static uint32_t transmit_order_errors;
static uint16_t last_fault_count;

static void script_frame(pbfw_frame f) {
  if (script_count < SCRIPT_SIZE) script[(script_head + script_count++) % SCRIPT_SIZE] = f;
}

static pbfw_time_ns live_now(void* context) {
  (void)context;
  sent_this_pass = 0u; /* a pass reads the clock once, first */
  last_pass_ns = time_ns();
  return last_pass_ns;
}

static bool live_receive(void* context, pbfw_frame* f) {
  (void)context;
  if (script_count == 0u) return false;
  *f = script[script_head];
  script_head = (script_head + 1u) % SCRIPT_SIZE;
  --script_count;
  return true;
}

static bool live_send(void* context, const pbfw_frame* f) {
  (void)context;
  if (sent_this_pass == 3u) return false;
  ++sent_this_pass;
  pbfw_message m;
  if (pbfw_decode(f, &m, NULL) != PBFW_DECODE_OK) {
    ++transmit_order_errors;
    return true;
  }
  if (m.kind == PBFW_FAULT) {
    if (m.u.fault.count != (uint16_t)(last_fault_count + 1u)) ++transmit_order_errors;
    last_fault_count = m.u.fault.count;
  }
  if (reply_count < MAX_REPLIES) replies[reply_count++] = m;
  return true;
}

static uint8_t live_end_of_stroke(void* context) {
  (void)context;
  return 0u;
}

static const pbfw_hal live_hal = {
    .context = NULL,
    .now_ns = live_now,
    .receive = live_receive,
    .send = live_send,
    .end_of_stroke = live_end_of_stroke,
};


static void live_time(void) {
  step("TIM2: time_ns is monotonic across the 32-bit counter's wrap");
  TIM2->CNT = 0xFFFFF000u; /* 4096 us before the wrap */
  (void)time_ns();         /* takes the jump */
  const pbfw_time_ns before = time_ns();
  for (uint32_t i = 0; i < 100000000u && time_raw_count() >= 0xFFFFF000u; ++i) {
  }
  const pbfw_time_ns after = time_ns();
  check(time_raw_count() < 0xFFFFF000u, "the counter wrapped");
  check(after > before, "time went on across the wrap");
  check(after - before < 20 * MS, "by less than 20 ms (no 2^32 us jump)");

  step("a live session through the core's main-loop pass on TIM2 time: pulse 30 ms, hold cap 20 ms");
  init_board(&board, set_coil_logged);
  script_frame(hello_frame(PBFW_PROTOCOL_VERSION, 100));
  script_frame(configure_frame(2, 30, 40, 40, 10, 20));
  script_frame(heartbeat_frame(1));
  (void)pbfw_board_service(&board, &live_hal, 16);
  check(last_reply(PBFW_HELLO_ACK) != NULL, "HelloAck through the pass");
  script_frame(fire_frame(2, PBFW_PULSE_HOLD, 0, 2));
  const pbfw_time_ns fired = time_ns();
  (void)pbfw_board_service(&board, &live_hal, 16);
  check_eq("driver 2 at 100 % after the pass that took the Fire", 100, coils_duty(2));
  uint16_t seq = 3;
  pbfw_time_ns last_heartbeat = fired;
  pbfw_time_ns hold_seen = 0;
  pbfw_time_ns off_seen = 0;
  pbfw_time_ns longest_pass = 0;
  pbfw_time_ns previous = fired;
  for (uint32_t i = 0; i < 1000000u && off_seen == 0 && previous - fired < 500 * MS; ++i) {
    if (previous - last_heartbeat >= 20 * MS) {
      script_frame(heartbeat_frame(seq++));
      last_heartbeat = previous;
    }
    (void)pbfw_board_service(&board, &live_hal, 16);
    const pbfw_time_ns t = time_ns(); /* the pass's outputs are in place by now */
    if (t - previous > longest_pass) longest_pass = t - previous;
    previous = t;
    const uint8_t duty = coils_duty(2);
    if (duty == 40u && hold_seen == 0) hold_seen = t;
    if (duty == 0u && hold_seen != 0) off_seen = t;
  }
  check(hold_seen != 0 && off_seen != 0, "the hold began and ended");
  check(hold_seen - fired >= 30 * MS, "hold not before 30 ms of TIM2 time");
  check(hold_seen - fired <= 30 * MS + 2 * longest_pass, "hold within a pass of 30 ms");
  check(off_seen - fired >= 50 * MS, "off not before 30 + 20 ms");
  check(off_seen - fired <= 50 * MS + 2 * longest_pass, "off within a pass of 50 ms");
  check_eq("every reply taken by the transmitter, in order, 3 a pass at most", 0, transmit_order_errors);
  check_eq("no reply lost to the busy transmitter", 0, (int64_t)board.counters.tx_dropped);
  text_line l;
  line_start(&l);
  line_text(&l, "     measured on TIM2: hold after ");
  line_i64(&l, hold_seen - fired);
  line_text(&l, " ns, off after ");
  line_i64(&l, off_seen - fired);
  line_text(&l, " ns, longest pass ");
  line_i64(&l, longest_pass);
  line_text(&l, " ns");
  line_write(&l);
}

/* ---------------------------------------- part 3: instruction counts */

/* Entry points the trace tool (tools/wcet_trace.py) finds by name: every
 * instruction between a call of wcet_begin and the next call of wcet_end is
 * one window. */
__attribute__((noinline)) void wcet_begin(void) { __asm__ volatile("" ::: "memory"); }
__attribute__((noinline)) void wcet_end(void) { __asm__ volatile("" ::: "memory"); }

typedef enum operation { OP_NONE, OP_FRAME, OP_ADVANCE, OP_SERVICE } operation;

/* The HAL for the counts: a fixed time, no frames, a transmitter that
 * takes everything, and the switches read from the pins as main.c does. */
static pbfw_time_ns measure_time;
static pbfw_time_ns measure_now(void* context) {
  (void)context;
  return measure_time;
}
static bool measure_receive(void* context, pbfw_frame* f) {
  (void)context;
  (void)f;
  return false;
}
static bool measure_send(void* context, const pbfw_frame* f) {
  (void)context;
  (void)f;
  return true;
}
static uint8_t measure_end_of_stroke(void* context) {
  (void)context;
  return eos_read();
}
static const pbfw_hal measure_hal = {
    .context = NULL,
    .now_ns = measure_now,
    .receive = measure_receive,
    .send = measure_send,
    .end_of_stroke = measure_end_of_stroke,
};

static uint32_t window_overhead;
static bool counts_are_instructions;

/* TIM2 ticks (instructions under -icount shift=0 at prescaler 0) of one
 * call, less the harness's own. */
static uint32_t measure(pbfw_board* b, operation op, const pbfw_frame* frame, pbfw_time_ns t) {
  wcet_begin();
  const uint32_t start = time_raw_count();
  if (op == OP_FRAME) pbfw_board_on_frame(b, frame, t);
  if (op == OP_ADVANCE) pbfw_board_advance(b, t);
  if (op == OP_SERVICE) (void)pbfw_board_service(b, &measure_hal, 16);
  const uint32_t end = time_raw_count();
  wcet_end();
  const uint32_t ticks = end - start;
  return ticks > window_overhead ? ticks - window_overhead : 0u;
}

static void print_count(const char* name, uint32_t instructions) {
  text_line l;
  line_start(&l);
  line_text(&l, "icount ");
  line_text(&l, name);
  line_text(&l, " ");
  line_u32(&l, instructions);
  line_write(&l);
}

/* A session with every driver configured and the watchdog armed, at t. */
static void session(pbfw_board* b, pbfw_time_ns t, uint16_t max_hold_ms) {
  const pbfw_board_options options = board_options(set_coil_plain);
  (void)pbfw_board_init(b, &options);
  pbfw_board_advance(b, t);
  const pbfw_frame h = hello_frame(PBFW_PROTOCOL_VERSION, 100);
  pbfw_board_on_frame(b, &h, t);
  for (uint8_t d = 0; d < COIL_COUNT; ++d) {
    const pbfw_frame c = configure_frame(d, 30, 25, 40, 0, max_hold_ms);
    pbfw_board_on_frame(b, &c, t);
  }
  const pbfw_frame hb = heartbeat_frame(1);
  pbfw_board_on_frame(b, &hb, t);
  drain(b);
}

static void fire_all(pbfw_board* b, pbfw_time_ns t, uint16_t first_seq) {
  for (uint8_t d = 0; d < COIL_COUNT; ++d) {
    const pbfw_frame f = fire_frame(d, PBFW_PULSE_HOLD, 0, (uint16_t)(first_seq + d));
    pbfw_board_on_frame(b, &f, t);
  }
  drain(b);
}

/* Fills the outbox with bad-frame Faults. */
static void fill_outbox(pbfw_board* b, pbfw_time_ns t) {
  pbfw_frame junk = heartbeat_frame(999);
  junk.data[junk.len - 1u] ^= 0xFFu;
  for (unsigned i = 0; i < PBFW_OUTBOX_SIZE; ++i) pbfw_board_on_frame(b, &junk, t);
}

static pbfw_board scratch;

static void instruction_counts(void) {
  step("instruction counts (valid under -icount shift=0)");
  /* TIM2 at prescaler 0 counts QEMU's virtual nanoseconds. */
  TIM2->PSC = 0u;
  TIM2->EGR = TIM_EGR_UG;
  (void)time_raw_count();
  window_overhead = 0u;
  window_overhead = measure(&scratch, OP_NONE, NULL, 0);
  /* Under -icount shift=0 the empty window is a fixed handful of
   * instructions; under real-time emulation it is thousands of ticks. */
  counts_are_instructions = window_overhead < 64u;
  print_count("harness_overhead", window_overhead);

  const pbfw_time_ns t = 5000 * MS;
  pbfw_frame f;

  session(&scratch, t, 5000);
  pbfw_board_advance(&scratch, t);
  const uint32_t advance_idle = measure(&scratch, OP_ADVANCE, NULL, t + 1);
  print_count("advance_nothing_due", advance_idle);
  const uint32_t advance_status = measure(&scratch, OP_ADVANCE, NULL, t + 10 * MS);
  print_count("advance_status_due", advance_status);
  drain(&scratch);
  /* One main-loop pass with nothing to do: the clock, no frame, the 8
   * switches, the timers, an empty outbox. */
  measure_time = t + 10 * MS + 1;
  const uint32_t service_idle = measure(&scratch, OP_SERVICE, NULL, 0);
  print_count("service_pass_idle", service_idle);

  f = fire_frame(0, PBFW_PULSE_HOLD, 0, 100);
  const uint32_t frame_fire = measure(&scratch, OP_FRAME, &f, t + 10 * MS);
  print_count("on_frame_fire", frame_fire);
  f = fire_frame(1, PBFW_PULSE_HOLD, 60, 101);
  const uint32_t frame_fire_clamped = measure(&scratch, OP_FRAME, &f, t + 10 * MS);
  print_count("on_frame_fire_clamped", frame_fire_clamped);
  f = fire_frame(2, PBFW_PULSE_HOLD, 0, 102);
  f.data[f.len - 1u] ^= 0x80u;
  const uint32_t frame_bad_crc = measure(&scratch, OP_FRAME, &f, t + 10 * MS);
  print_count("on_frame_bad_crc", frame_bad_crc);
  f = heartbeat_frame(103);
  const uint32_t frame_heartbeat = measure(&scratch, OP_FRAME, &f, t + 10 * MS);
  print_count("on_frame_heartbeat", frame_heartbeat);
  f = configure_frame(3, 30, 25, 40, 0, 5000);
  const uint32_t frame_configure = measure(&scratch, OP_FRAME, &f, t + 10 * MS);
  print_count("on_frame_configure", frame_configure);
  drain(&scratch);

  /* Hello with all 8 coils on: 8 switched off, HelloAck and Status queued. */
  session(&scratch, t, 5000);
  fire_all(&scratch, t, 10);
  f = hello_frame(PBFW_PROTOCOL_VERSION, 100);
  const uint32_t frame_hello = measure(&scratch, OP_FRAME, &f, t + 1);
  print_count("on_frame_hello_8_on", frame_hello);
  drain(&scratch);

  /* 8 pulses ending in one advance, a Status due. */
  session(&scratch, t, 50);
  fire_all(&scratch, t, 10);
  const uint32_t advance_8_pulse = measure(&scratch, OP_ADVANCE, NULL, t + 30 * MS);
  print_count("advance_8_pulses_end_status", advance_8_pulse);
  drain(&scratch);
  /* 8 hold caps in one advance: 8 off, 8 Fault 2 and a Status. */
  f = heartbeat_frame(50);
  pbfw_board_on_frame(&scratch, &f, t + 60 * MS);
  drain(&scratch);
  const uint32_t advance_8_cap = measure(&scratch, OP_ADVANCE, NULL, t + 80 * MS);
  print_count("advance_8_hold_caps_status", advance_8_cap);
  drain(&scratch);

  /* The same with the outbox full: the replies are dropped and counted. */
  session(&scratch, t, 50);
  fire_all(&scratch, t, 10);
  pbfw_board_advance(&scratch, t + 30 * MS);
  f = heartbeat_frame(50);
  pbfw_board_on_frame(&scratch, &f, t + 60 * MS);
  drain(&scratch);
  fill_outbox(&scratch, t + 60 * MS);
  const uint32_t advance_8_cap_full = measure(&scratch, OP_ADVANCE, NULL, t + 80 * MS);
  print_count("advance_8_hold_caps_outbox_full", advance_8_cap_full);
  drain(&scratch);

  /* The watchdog with 8 coils held: all off, Fault 1, a Status. */
  session(&scratch, t, 5000);
  fire_all(&scratch, t, 10);
  pbfw_board_advance(&scratch, t + 30 * MS);
  drain(&scratch);
  const uint32_t advance_watchdog = measure(&scratch, OP_ADVANCE, NULL, t + 100 * MS);
  print_count("advance_watchdog_8_on_status", advance_watchdog);
  drain(&scratch);

  /* A Fire arriving as 8 pulses end: on_frame runs the timers first. */
  session(&scratch, t, 50);
  fire_all(&scratch, t, 10);
  f = fire_frame(0, PBFW_PULSE_HOLD, 0, 40);
  const uint32_t frame_fire_8_expire = measure(&scratch, OP_FRAME, &f, t + 30 * MS);
  print_count("on_frame_fire_as_8_pulses_end", frame_fire_8_expire);
  drain(&scratch);

  if (!counts_are_instructions) {
    heading("not under -icount shift=0: the counts above are TIM2 ticks of real time, no budget checked");
    return;
  }
  /* Budgets: about twice what -O2 and -Os measure today (docs/results.md),
   * so a change that makes either path grossly longer fails here. */
  check(frame_fire < 2000u, "on_frame(Fire) under 2000 instructions");
  check(frame_hello < 5500u, "on_frame(Hello, 8 on) under 5500 instructions");
  check(advance_idle < 300u, "advance with nothing due under 300 instructions");
  check(service_idle < 1000u, "an idle main-loop pass under 1000 instructions");
  check(advance_8_cap < 18000u, "advance with 8 hold caps under 18000 instructions");
  check(advance_watchdog < 5000u, "advance with the watchdog under 5000 instructions");
}

/* ------------------------------------------------------ stack high-water */

#define STACK_PAINT 0xA5A5A5A5u

/* Stack positions as word indices from _sstack, as startup.c walks .data and
 * .bss: comparing pointers to two linker symbols is undefined in C. */
static uintptr_t stack_words_below(uintptr_t address) {
  return (address - (uintptr_t)_sstack) / sizeof(uint32_t);
}

/* Paints the unused stack below the current frame, 16 words clear of it. */
__attribute__((noinline)) static void paint_stack(void) {
  uintptr_t sp;
  __asm__ volatile("mov %0, sp" : "=r"(sp));
  const uintptr_t painted_words = stack_words_below(sp) - 16u;
  for (uintptr_t i = 0; i < painted_words; ++i) _sstack[i] = STACK_PAINT;
}

static uint32_t stack_used_bytes(void) {
  const uintptr_t stack_words = stack_words_below((uintptr_t)_estack);
  uintptr_t untouched_words = 0;
  while (untouched_words < stack_words && _sstack[untouched_words] == STACK_PAINT) ++untouched_words;
  return (uint32_t)((stack_words - untouched_words) * sizeof(uint32_t));
}

int main(void) {
  paint_stack();
  coils_safe();
  const clock_tree clock = clock_init();
  time_init(&clock);
  coils_start_pwm(&clock);

  heading("pinball driver board self-test (STM32F446 image, QEMU netduinoplus2)");
  text_line l;
  line_start(&l);
  line_text(&l, "clock: ");
  line_text(&l,
            clock.source == CLOCK_HSE_PLL_180MHZ ? "HSE/PLL 180 MHz" : "HSI 16 MHz fallback, failed step ");
  if (clock.source != CLOCK_HSE_PLL_180MHZ) line_u32(&l, (uint32_t)clock.failed_step);
  line_write(&l);

  rules();
  live_time();
  instruction_counts();

  line_start(&l);
  line_text(&l, "stack high-water ");
  line_u32(&l, stack_used_bytes());
  line_text(&l, " bytes of ");
  line_u32(&l, (uint32_t)((uintptr_t)_estack - (uintptr_t)_sstack));
  line_write(&l);
  line_start(&l);
  line_text(&l, failures == 0u ? "PASS " : "FAIL ");
  line_u32(&l, checks - failures);
  line_text(&l, "/");
  line_u32(&l, checks);
  line_text(&l, " checks");
  line_write(&l);
  semihosting_exit(failures > 255u ? 255u : failures);
}
