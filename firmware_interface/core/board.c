/* The firmware rules of PROTOCOL.md; rule numbers in comments refer to its
 * "Firmware rules (the board MUST)". */
#include "pinball/firmware/core/board.h"

#include <stddef.h>

static pbfw_driver* driver_at(pbfw_board* b, unsigned d) { return &b->drivers[d]; }

pbfw_init_error pbfw_board_init(pbfw_board* b, const pbfw_board_options* options) {
  if (options->board_id >= PBFW_MAX_BOARDS) return PBFW_INIT_BAD_BOARD_ID;
  if (options->driver_count < 1 || options->driver_count > PBFW_MAX_DRIVERS) return PBFW_INIT_BAD_DRIVER_COUNT;
  if (options->status_period_ns <= 0) return PBFW_INIT_BAD_STATUS_PERIOD;
  const pbfw_board zero = {0};
  *b = zero;
  b->options = *options;
  b->watchdog_ms = PBFW_DEFAULT_WATCHDOG_MS;
  b->watchdog_ns = (pbfw_time_ns)PBFW_DEFAULT_WATCHDOG_MS * PBFW_NS_PER_MS;
  return PBFW_INIT_OK;
}

static void set_output(pbfw_board* b, unsigned d, pbfw_coil_state state, uint8_t duty_pct, pbfw_time_ns t) {
  pbfw_driver* drv = driver_at(b, d);
  drv->state = (uint8_t)state;
  drv->duty_pct = duty_pct;
  drv->since_ns = t;
  if (state == PBFW_COIL_OFF) drv->off_since_ns = t;
  else drv->has_been_on = true;
  if (b->options.set_coil != NULL) b->options.set_coil(b->options.set_coil_context, d, state, duty_pct, t);
}

static void all_off(pbfw_board* b, pbfw_time_ns t) {
  for (unsigned d = 0; d < b->options.driver_count; ++d) {
    if (b->drivers[d].state != PBFW_COIL_OFF) set_output(b, d, PBFW_COIL_OFF, 0, t);
  }
}

static void push_tx(pbfw_board* b, const pbfw_message* m) {
  if (b->out_count >= PBFW_OUTBOX_SIZE) {
    ++b->counters.tx_dropped;
    return;
  }
  pbfw_message sealed = *m;
  sealed.board = b->options.board_id;
  pbfw_encode(&sealed, &b->outbox[(b->out_head + b->out_count) % PBFW_OUTBOX_SIZE]);
  ++b->out_count;
}

bool pbfw_board_peek_tx(const pbfw_board* b, pbfw_frame* out) {
  if (b->out_count == 0) return false;
  *out = b->outbox[b->out_head];
  return true;
}

bool pbfw_board_pop_tx(pbfw_board* b, pbfw_frame* out) {
  if (!pbfw_board_peek_tx(b, out)) return false;
  b->out_head = (uint8_t)((b->out_head + 1u) % PBFW_OUTBOX_SIZE);
  --b->out_count;
  return true;
}

static void fault(pbfw_board* b, pbfw_fault_code code, uint8_t driver, uint16_t detail, uint8_t bit) {
  b->fault_bits |= bit;
  ++b->fault_count;
  pbfw_message m;
  m.kind = PBFW_FAULT;
  m.u.fault.code = (uint8_t)code;
  m.u.fault.driver = driver;
  m.u.fault.detail = detail;
  m.u.fault.count = b->fault_count;
  push_tx(b, &m);
}

pbfw_status pbfw_board_status(const pbfw_board* b) {
  pbfw_status s = {0};
  for (unsigned d = 0; d < b->options.driver_count; ++d) {
    const pbfw_driver* drv = &b->drivers[d];
    s.coil_states |= (uint16_t)((unsigned)drv->state << (2u * d));
    if (drv->eos) s.end_of_stroke |= (uint8_t)(1u << d);
    if (drv->configured) s.configured |= (uint8_t)(1u << d);
  }
  s.faults = (uint8_t)(b->fault_bits | (b->armed ? PBFW_FAULT_BIT_ARMED : 0u));
  s.last_seq = b->last_seq;
  return s;
}

static void push_status(pbfw_board* b) {
  pbfw_message m;
  m.kind = PBFW_STATUS;
  m.u.status = pbfw_board_status(b);
  push_tx(b, &m);
}

void pbfw_board_set_end_of_stroke(pbfw_board* b, unsigned d, bool closed) {
  if (d < b->options.driver_count) b->drivers[d].eos = closed;
}

/* When driver d's current state ends by itself; false when it does not. */
static bool driver_deadline(const pbfw_driver* drv, pbfw_time_ns* at) {
  if (drv->state == PBFW_COIL_PULSE) {
    *at = drv->pulse_end_ns;
    return true;
  }
  if (drv->state == PBFW_COIL_HOLD) {
    *at = drv->hold_end_ns;
    return true;
  }
  return false;
}

static uint8_t min_u8(uint8_t a, uint8_t b) { return a < b ? a : b; }
static uint16_t min_u16(uint16_t a, uint16_t b) { return a < b ? a : b; }

/* Driver d's pulse or hold reached its end at t. */
static void expire_driver(pbfw_board* b, unsigned d, pbfw_time_ns t) {
  pbfw_driver* drv = driver_at(b, d);
  if (drv->state == PBFW_COIL_PULSE) {
    const uint8_t duty = min_u8(drv->config.hold_duty_pct, PBFW_ABS_MAX_HOLD_DUTY_PCT); /* rule 6: never above 50 % */
    if (drv->hold_after_pulse && duty > 0) {
      drv->hold_end_ns = t + (pbfw_time_ns)min_u16(drv->config.max_hold_ms, PBFW_ABS_MAX_HOLD_MS) * PBFW_NS_PER_MS;
      set_output(b, d, PBFW_COIL_HOLD, duty, t);
    } else {
      set_output(b, d, PBFW_COIL_OFF, 0, t);
    }
    return;
  }
  /* Rule 6: the hold cap ends the hold whatever the host says and locks the driver. */
  ++b->counters.hold_cap_trips;
  drv->locked = true;
  set_output(b, d, PBFW_COIL_OFF, 0, t);
  fault(b, PBFW_FAULT_HOLD_CAP_REACHED, (uint8_t)d, drv->config.max_hold_ms, PBFW_FAULT_BIT_HOLD_CAP);
}

void pbfw_board_advance(pbfw_board* b, pbfw_time_ns now) {
  if (!b->started) {
    b->started = true;
    b->now_ns = now;
    b->next_status_ns = now;
  }
  if (now < b->now_ns) now = b->now_ns;
  /* Rule 13: apply every timer that expired up to now, earliest first, each
   * at its own deadline. On a tie the watchdog goes first (all off), then the
   * lowest driver. */
  for (;;) {
    pbfw_time_ns t = now;
    int which = -2; /* -1: watchdog, >= 0: driver */
    if (b->armed && b->last_heartbeat_ns + b->watchdog_ns <= t) {
      t = b->last_heartbeat_ns + b->watchdog_ns;
      which = -1;
    }
    for (unsigned d = 0; d < b->options.driver_count; ++d) {
      pbfw_time_ns end;
      if (!driver_deadline(&b->drivers[d], &end)) continue;
      if (end < t || (end <= t && which == -2)) {
        t = end;
        which = (int)d;
      }
    }
    if (which == -2) break;
    if (which == -1) {
      /* Rule 4: heartbeats stopped: every driver off at the deadline. */
      b->armed = false;
      ++b->counters.watchdog_trips;
      all_off(b, t);
      fault(b, PBFW_FAULT_WATCHDOG_EXPIRED, PBFW_BOARD_DRIVER, b->watchdog_ms,
            PBFW_FAULT_BIT_WATCHDOG);
      continue;
    }
    expire_driver(b, (unsigned)which, t);
  }
  b->now_ns = now;
  /* Rule 12: Status every period; the fault bits are what happened since the last one. */
  if (now >= b->next_status_ns) {
    push_status(b);
    b->fault_bits = 0;
    b->next_status_ns += b->options.status_period_ns;
    if (b->next_status_ns <= now) b->next_status_ns = now + b->options.status_period_ns;
  }
}

pbfw_time_ns pbfw_board_next_deadline(const pbfw_board* b) {
  pbfw_time_ns next = b->started ? b->next_status_ns : b->now_ns;
  if (b->armed && b->last_heartbeat_ns + b->watchdog_ns < next) next = b->last_heartbeat_ns + b->watchdog_ns;
  for (unsigned d = 0; d < b->options.driver_count; ++d) {
    pbfw_time_ns end;
    if (driver_deadline(&b->drivers[d], &end) && end < next) next = end;
  }
  return next;
}

/* Rule 9: the session's newest seq, and every driver's reference kept within
 * 2^14 of it so that heartbeats alone never make a later Fire look old. */
static void note_seq(pbfw_board* b, uint16_t seq) {
  if (b->has_seq && !pbfw_seq_newer(seq, b->last_seq)) return;
  b->has_seq = true;
  b->last_seq = seq;
  const uint16_t floor = (uint16_t)(seq - PBFW_SEQ_REFERENCE_LAG);
  for (unsigned d = 0; d < b->options.driver_count; ++d) {
    pbfw_driver* drv = &b->drivers[d];
    if (drv->has_seq && pbfw_seq_newer(floor, drv->last_seq)) drv->last_seq = floor;
  }
}

static void on_hello(pbfw_board* b, const pbfw_hello* m, pbfw_time_ns now) {
  ++b->counters.hellos;
  all_off(b, now); /* rule 1 */
  /* A hold-cap lock survives the new session: only Release or ReleaseAll
   * acknowledge it (rule 6). */
  for (unsigned d = 0; d < PBFW_MAX_DRIVERS; ++d) {
    b->drivers[d].configured = false;
    b->drivers[d].has_seq = false;
  }
  b->session = true;
  b->armed = false;
  b->watchdog_ms = m->watchdog_ms;
  b->watchdog_ns = (pbfw_time_ns)m->watchdog_ms * PBFW_NS_PER_MS;
  b->has_hb_seq = false;
  b->has_seq = false;
  b->last_seq = 0;
  b->fault_count = 0;
  pbfw_message ack;
  ack.kind = PBFW_HELLO_ACK;
  ack.u.hello_ack.version = PBFW_PROTOCOL_VERSION;
  ack.u.hello_ack.driver_count = b->options.driver_count;
  ack.u.hello_ack.fw_major = b->options.fw_major;
  ack.u.hello_ack.fw_minor = b->options.fw_minor;
  push_tx(b, &ack);
  push_status(b); /* rule 12 */
}

static void on_configure(pbfw_board* b, const pbfw_configure* m, pbfw_time_ns now) {
  if (m->driver >= b->options.driver_count) {
    ++b->counters.refused_not_configured;
    fault(b, PBFW_FAULT_NOT_CONFIGURED, m->driver, PBFW_CONFIGURE, PBFW_FAULT_BIT_REFUSED);
    return;
  }
  pbfw_driver* drv = driver_at(b, m->driver);
  if (drv->state != PBFW_COIL_OFF) set_output(b, m->driver, PBFW_COIL_OFF, 0, now); /* rule 1 */
  drv->config = m->config;
  drv->configured = true; /* a hold-cap lock stays: only Release or ReleaseAll clear it (rule 6) */
  push_status(b);         /* rule 12 */
}

static void on_fire(pbfw_board* b, const pbfw_fire* m, pbfw_time_ns now) {
  if (m->driver >= b->options.driver_count || !b->drivers[m->driver].configured) { /* rule 2 */
    ++b->counters.refused_not_configured;
    fault(b, PBFW_FAULT_NOT_CONFIGURED, m->driver, PBFW_FIRE, PBFW_FAULT_BIT_REFUSED);
    return;
  }
  pbfw_driver* drv = driver_at(b, m->driver);
  if (drv->has_seq && !pbfw_seq_newer(m->seq, drv->last_seq)) { /* rule 9 */
    ++b->counters.stale;
    fault(b, PBFW_FAULT_STALE, m->driver, m->seq, PBFW_FAULT_BIT_REFUSED);
    return;
  }
  drv->has_seq = true;
  drv->last_seq = m->seq;
  note_seq(b, m->seq);
  if (!b->armed) { /* rule 3 */
    ++b->counters.refused_not_armed;
    fault(b, PBFW_FAULT_NOT_ARMED, m->driver, 0, PBFW_FAULT_BIT_REFUSED);
    return;
  }
  if (drv->locked) { /* rule 6 */
    ++b->counters.refused_locked;
    fault(b, PBFW_FAULT_LOCKED, m->driver, 0, PBFW_FAULT_BIT_REFUSED);
    return;
  }
  if (drv->state != PBFW_COIL_OFF) { /* rule 7: never restart a pulse on an energised coil */
    ++b->counters.refused_busy;
    return;
  }
  if (drv->has_been_on && now < drv->off_since_ns + (pbfw_time_ns)drv->config.recycle_ms * PBFW_NS_PER_MS) { /* rule 8 */
    ++b->counters.refused_recycle;
    return;
  }
  const uint8_t wanted = m->pulse_ms != 0 ? m->pulse_ms : drv->config.pulse_ms;
  const uint8_t cap = min_u8(drv->config.max_pulse_ms, PBFW_ABS_MAX_PULSE_MS);
  uint8_t pulse = wanted;
  if (wanted > cap) { /* rule 5 */
    pulse = cap;
    ++b->counters.pulse_clamps;
    fault(b, PBFW_FAULT_PULSE_CLAMPED, m->driver, wanted, PBFW_FAULT_BIT_PULSE_CLAMP);
  }
  ++b->counters.fires_accepted;
  drv->hold_after_pulse = m->mode == PBFW_PULSE_HOLD;
  drv->pulse_end_ns = now + (pbfw_time_ns)pulse * PBFW_NS_PER_MS;
  set_output(b, m->driver, PBFW_COIL_PULSE, 100, now);
}

/* Rule 10: switching off is always safe, obeyed whatever the seq or session. */
static void on_release(pbfw_board* b, unsigned d, uint16_t seq, pbfw_time_ns now) {
  pbfw_driver* drv = driver_at(b, d);
  if (!drv->has_seq || pbfw_seq_newer(seq, drv->last_seq)) {
    drv->has_seq = true;
    drv->last_seq = seq;
  }
  drv->locked = false;
  if (drv->state != PBFW_COIL_OFF) set_output(b, d, PBFW_COIL_OFF, 0, now);
}

static void on_heartbeat(pbfw_board* b, const pbfw_heartbeat* m, pbfw_time_ns now) {
  if (b->has_hb_seq && !pbfw_seq_newer(m->seq, b->hb_seq)) { /* rule 4: a replay feeds nothing */
    ++b->counters.stale;
    return;
  }
  b->has_hb_seq = true;
  b->hb_seq = m->seq;
  b->last_heartbeat_ns = now;
  b->armed = true;
  note_seq(b, m->seq);
}

static void handle(pbfw_board* b, const pbfw_message* m, pbfw_time_ns now) {
  switch (m->kind) {
    case PBFW_HELLO:
      on_hello(b, &m->u.hello, now);
      return;
    case PBFW_RELEASE:
      if (m->u.release.driver < b->options.driver_count) on_release(b, m->u.release.driver, m->u.release.seq, now);
      note_seq(b, m->u.release.seq);
      return;
    case PBFW_RELEASE_ALL:
      for (unsigned d = 0; d < b->options.driver_count; ++d) on_release(b, d, m->u.release_all.seq, now);
      note_seq(b, m->u.release_all.seq);
      return;
    case PBFW_HEARTBEAT:
    case PBFW_CONFIGURE:
    case PBFW_FIRE:
      if (!b->session) { /* rule 2 */
        ++b->counters.refused_not_configured;
        fault(b, PBFW_FAULT_NOT_CONFIGURED, PBFW_BOARD_DRIVER, (uint16_t)m->kind, PBFW_FAULT_BIT_REFUSED);
        return;
      }
      if (m->kind == PBFW_HEARTBEAT) on_heartbeat(b, &m->u.heartbeat, now);
      if (m->kind == PBFW_CONFIGURE) on_configure(b, &m->u.configure, now);
      if (m->kind == PBFW_FIRE) on_fire(b, &m->u.fire, now);
      return;
    default:
      ++b->counters.foreign; /* a board -> host message: not for us */
      return;
  }
}

void pbfw_board_on_frame(pbfw_board* b, const pbfw_frame* frame, pbfw_time_ns now) {
  pbfw_board_advance(b, now);
  now = b->now_ns;
  ++b->counters.frames;
  pbfw_message m;
  const pbfw_decode_error e = pbfw_decode(frame, &m, NULL);
  if (e != PBFW_DECODE_OK) {
    if (e == PBFW_DECODE_ERROR_FRAME || e == PBFW_DECODE_FOREIGN_ID) {
      ++b->counters.foreign;
      return;
    }
    /* Rule 11: counted and reported, no output changes. */
    ++b->counters.bad_frames;
    if (e == PBFW_DECODE_BAD_CHECKSUM) ++b->counters.bad_checksum;
    if ((frame->id & 0x0Fu) != b->options.board_id) return; /* someone else's garbage */
    if (e == PBFW_DECODE_WRONG_VERSION) {
      ++b->counters.version_mismatch;
      fault(b, PBFW_FAULT_VERSION_MISMATCH, PBFW_BOARD_DRIVER, frame->data[0], PBFW_FAULT_BIT_VERSION);
    } else {
      fault(b, PBFW_FAULT_BAD_FRAME, PBFW_BOARD_DRIVER, (uint16_t)e, PBFW_FAULT_BIT_BAD_FRAME);
    }
    return;
  }
  if (m.board != b->options.board_id) {
    ++b->counters.foreign;
    return;
  }
  handle(b, &m, now);
}
