/* The protocol's wire format: CRC, lengths, the one decoder and encoder. */
#include "pinball/firmware/core/wire.h"

#include <stddef.h>

static uint16_t get_le16(const uint8_t* p) { return (uint16_t)(p[0] | (p[1] << 8)); }

static void put_le16(uint8_t* p, uint16_t v) {
  p[0] = (uint8_t)(v & 0xFFu);
  p[1] = (uint8_t)(v >> 8);
}

/* CRC-8, polynomial 0x2F (AUTOSAR), one table lookup per byte: the bitwise
 * loop was two thirds of the board's worst timer tick (docs/results.md).
 * kCrc8[i] is the CRC register after feeding byte i into a zero register;
 * core_wire_test.cpp checks the table against the bitwise definition. */
static const uint8_t kCrc8[256] = {
    0x00, 0x2F, 0x5E, 0x71, 0xBC, 0x93, 0xE2, 0xCD, 0x57, 0x78, 0x09, 0x26,
    0xEB, 0xC4, 0xB5, 0x9A, 0xAE, 0x81, 0xF0, 0xDF, 0x12, 0x3D, 0x4C, 0x63,
    0xF9, 0xD6, 0xA7, 0x88, 0x45, 0x6A, 0x1B, 0x34, 0x73, 0x5C, 0x2D, 0x02,
    0xCF, 0xE0, 0x91, 0xBE, 0x24, 0x0B, 0x7A, 0x55, 0x98, 0xB7, 0xC6, 0xE9,
    0xDD, 0xF2, 0x83, 0xAC, 0x61, 0x4E, 0x3F, 0x10, 0x8A, 0xA5, 0xD4, 0xFB,
    0x36, 0x19, 0x68, 0x47, 0xE6, 0xC9, 0xB8, 0x97, 0x5A, 0x75, 0x04, 0x2B,
    0xB1, 0x9E, 0xEF, 0xC0, 0x0D, 0x22, 0x53, 0x7C, 0x48, 0x67, 0x16, 0x39,
    0xF4, 0xDB, 0xAA, 0x85, 0x1F, 0x30, 0x41, 0x6E, 0xA3, 0x8C, 0xFD, 0xD2,
    0x95, 0xBA, 0xCB, 0xE4, 0x29, 0x06, 0x77, 0x58, 0xC2, 0xED, 0x9C, 0xB3,
    0x7E, 0x51, 0x20, 0x0F, 0x3B, 0x14, 0x65, 0x4A, 0x87, 0xA8, 0xD9, 0xF6,
    0x6C, 0x43, 0x32, 0x1D, 0xD0, 0xFF, 0x8E, 0xA1, 0xE3, 0xCC, 0xBD, 0x92,
    0x5F, 0x70, 0x01, 0x2E, 0xB4, 0x9B, 0xEA, 0xC5, 0x08, 0x27, 0x56, 0x79,
    0x4D, 0x62, 0x13, 0x3C, 0xF1, 0xDE, 0xAF, 0x80, 0x1A, 0x35, 0x44, 0x6B,
    0xA6, 0x89, 0xF8, 0xD7, 0x90, 0xBF, 0xCE, 0xE1, 0x2C, 0x03, 0x72, 0x5D,
    0xC7, 0xE8, 0x99, 0xB6, 0x7B, 0x54, 0x25, 0x0A, 0x3E, 0x11, 0x60, 0x4F,
    0x82, 0xAD, 0xDC, 0xF3, 0x69, 0x46, 0x37, 0x18, 0xD5, 0xFA, 0x8B, 0xA4,
    0x05, 0x2A, 0x5B, 0x74, 0xB9, 0x96, 0xE7, 0xC8, 0x52, 0x7D, 0x0C, 0x23,
    0xEE, 0xC1, 0xB0, 0x9F, 0xAB, 0x84, 0xF5, 0xDA, 0x17, 0x38, 0x49, 0x66,
    0xFC, 0xD3, 0xA2, 0x8D, 0x40, 0x6F, 0x1E, 0x31, 0x76, 0x59, 0x28, 0x07,
    0xCA, 0xE5, 0x94, 0xBB, 0x21, 0x0E, 0x7F, 0x50, 0x9D, 0xB2, 0xC3, 0xEC,
    0xD8, 0xF7, 0x86, 0xA9, 0x64, 0x4B, 0x3A, 0x15, 0x8F, 0xA0, 0xD1, 0xFE,
    0x33, 0x1C, 0x6D, 0x42,
};

uint8_t pbfw_crc8(uint32_t id, const uint8_t* bytes, unsigned n) {
  uint8_t crc = 0xFFu;
  crc = kCrc8[crc ^ (uint8_t)(id & 0xFFu)];
  crc = kCrc8[crc ^ (uint8_t)((id >> 8) & 0x07u)];
  for (unsigned i = 0; i < n; ++i) crc = kCrc8[crc ^ bytes[i]];
  return (uint8_t)(crc ^ 0xFFu);
}

int pbfw_frame_length(unsigned kind) {
  switch (kind) {
    case PBFW_RELEASE_ALL: return 3;
    case PBFW_RELEASE: return 4;
    case PBFW_FIRE: return 6;
    case PBFW_HEARTBEAT: return 4;
    case PBFW_CONFIGURE: return 8;
    case PBFW_HELLO: return 4;
    case PBFW_FAULT: return 7;
    case PBFW_STATUS: return 8;
    case PBFW_HELLO_ACK: return 5;
    default: return -1;
  }
}

const char* pbfw_validate_config(const pbfw_driver_config* c) {
  if (c->max_pulse_ms < 1 || c->max_pulse_ms > PBFW_ABS_MAX_PULSE_MS) return "max_pulse_ms outside 1..kAbsMaxPulseMs (100)";
  if (c->pulse_ms < 1 || c->pulse_ms > c->max_pulse_ms) return "pulse_ms outside 1..max_pulse_ms";
  if (c->hold_duty_pct > PBFW_ABS_MAX_HOLD_DUTY_PCT) return "hold_duty_pct above kAbsMaxHoldDutyPct (50)";
  if (c->max_hold_ms < 1 || c->max_hold_ms > PBFW_ABS_MAX_HOLD_MS) return "max_hold_ms outside 1..kAbsMaxHoldMs (10000)";
  return NULL;
}

static pbfw_decode_error fail(pbfw_decode_error e, const char* why, const char** reason) {
  if (reason != NULL) *reason = why;
  return e;
}

pbfw_decode_error pbfw_decode(const pbfw_frame* f, pbfw_message* out, const char** reason) {
  if (reason != NULL) *reason = "";
  if (f->error) return fail(PBFW_DECODE_ERROR_FRAME, "controller error frame", reason);
  if (f->id > 0x7FFu || (f->id & PBFW_ID_MASK) != PBFW_ID_BASE) {
    return fail(PBFW_DECODE_FOREIGN_ID, "id outside 0x100..0x1FF", reason);
  }
  const unsigned kind = (f->id >> 4) & 0x0Fu;
  const int expected = pbfw_frame_length(kind);
  if (expected < 0) return fail(PBFW_DECODE_UNKNOWN_KIND, "unknown message kind", reason);
  if (f->len != expected) return fail(PBFW_DECODE_WRONG_LENGTH, "length differs from the kind's length", reason);
  if (pbfw_crc8(f->id, f->data, f->len - 1u) != f->data[f->len - 1u]) {
    return fail(PBFW_DECODE_BAD_CHECKSUM, "CRC-8 mismatch", reason);
  }
  const uint8_t* d = f->data;
  pbfw_message m;
  m.board = (uint8_t)(f->id & 0x0Fu);
  m.kind = (pbfw_kind)kind;
  switch (m.kind) {
    case PBFW_HELLO:
      if (d[0] != PBFW_PROTOCOL_VERSION) return fail(PBFW_DECODE_WRONG_VERSION, "Hello: protocol version differs", reason);
      m.u.hello.version = d[0];
      m.u.hello.watchdog_ms = get_le16(d + 1);
      if (m.u.hello.watchdog_ms < PBFW_MIN_WATCHDOG_MS || m.u.hello.watchdog_ms > PBFW_MAX_WATCHDOG_MS) {
        return fail(PBFW_DECODE_OUT_OF_RANGE, "Hello: watchdog_ms outside 10..1000", reason);
      }
      break;
    case PBFW_HELLO_ACK:
      if (d[0] != PBFW_PROTOCOL_VERSION) return fail(PBFW_DECODE_WRONG_VERSION, "HelloAck: protocol version differs", reason);
      if (d[1] < 1 || d[1] > PBFW_MAX_DRIVERS) return fail(PBFW_DECODE_OUT_OF_RANGE, "HelloAck: driver_count outside 1..8", reason);
      m.u.hello_ack.version = d[0];
      m.u.hello_ack.driver_count = d[1];
      m.u.hello_ack.fw_major = d[2];
      m.u.hello_ack.fw_minor = d[3];
      break;
    case PBFW_CONFIGURE:
      if (d[0] >= PBFW_MAX_DRIVERS) return fail(PBFW_DECODE_OUT_OF_RANGE, "Configure: driver >= 8", reason);
      m.u.configure.driver = d[0];
      m.u.configure.config.pulse_ms = d[1];
      m.u.configure.config.hold_duty_pct = d[2];
      m.u.configure.config.max_pulse_ms = d[3];
      m.u.configure.config.recycle_ms = d[4];
      m.u.configure.config.max_hold_ms = get_le16(d + 5);
      if (pbfw_validate_config(&m.u.configure.config) != NULL) {
        return fail(PBFW_DECODE_OUT_OF_RANGE, "Configure: timing or cap out of range", reason);
      }
      break;
    case PBFW_FIRE:
      if (d[0] >= PBFW_MAX_DRIVERS) return fail(PBFW_DECODE_OUT_OF_RANGE, "Fire: driver >= 8", reason);
      if (d[1] > 1) return fail(PBFW_DECODE_OUT_OF_RANGE, "Fire: mode not 0 or 1", reason);
      if (d[2] > PBFW_ABS_MAX_PULSE_MS) return fail(PBFW_DECODE_OUT_OF_RANGE, "Fire: pulse_ms above 100", reason);
      m.u.fire.driver = d[0];
      m.u.fire.mode = d[1];
      m.u.fire.pulse_ms = d[2];
      m.u.fire.seq = get_le16(d + 3);
      break;
    case PBFW_RELEASE:
      if (d[0] >= PBFW_MAX_DRIVERS) return fail(PBFW_DECODE_OUT_OF_RANGE, "Release: driver >= 8", reason);
      m.u.release.driver = d[0];
      m.u.release.seq = get_le16(d + 1);
      break;
    case PBFW_RELEASE_ALL:
      m.u.release_all.seq = get_le16(d);
      break;
    case PBFW_HEARTBEAT:
      if (d[0] != PBFW_PROTOCOL_VERSION) return fail(PBFW_DECODE_WRONG_VERSION, "Heartbeat: protocol version differs", reason);
      m.u.heartbeat.version = d[0];
      m.u.heartbeat.seq = get_le16(d + 1);
      break;
    case PBFW_STATUS: {
      const uint16_t states = get_le16(d);
      for (unsigned i = 0; i < PBFW_MAX_DRIVERS; ++i) {
        if (((states >> (2u * i)) & 3u) == 3u) return fail(PBFW_DECODE_OUT_OF_RANGE, "Status: coil state 3 is undefined", reason);
      }
      if (d[4] & PBFW_FAULT_BIT_RESERVED) return fail(PBFW_DECODE_OUT_OF_RANGE, "Status: reserved fault bit 6 set", reason);
      m.u.status.coil_states = states;
      m.u.status.end_of_stroke = d[2];
      m.u.status.configured = d[3];
      m.u.status.faults = d[4];
      m.u.status.last_seq = get_le16(d + 5);
      break;
    }
    case PBFW_FAULT:
      if (d[0] < 1 || d[0] > PBFW_MAX_FAULT_CODE) return fail(PBFW_DECODE_OUT_OF_RANGE, "Fault: unknown fault code", reason);
      if (d[1] >= PBFW_MAX_DRIVERS && d[1] != PBFW_BOARD_DRIVER) {
        return fail(PBFW_DECODE_OUT_OF_RANGE, "Fault: driver neither 0..7 nor 0xFF", reason);
      }
      m.u.fault.code = d[0];
      m.u.fault.driver = d[1];
      m.u.fault.detail = get_le16(d + 2);
      m.u.fault.count = get_le16(d + 4);
      break;
    default:
      return fail(PBFW_DECODE_UNKNOWN_KIND, "unknown message kind", reason);
  }
  if (out != NULL) *out = m;
  return PBFW_DECODE_OK;
}

void pbfw_encode(const pbfw_message* m, pbfw_frame* out) {
  uint8_t* d = out->data;
  for (unsigned i = 0; i < PBFW_MAX_FRAME_BYTES; ++i) d[i] = 0;
  out->id = pbfw_make_id(m->kind, m->board);
  out->error = false;
  switch (m->kind) {
    case PBFW_HELLO:
      d[0] = m->u.hello.version;
      put_le16(d + 1, m->u.hello.watchdog_ms);
      break;
    case PBFW_HELLO_ACK:
      d[0] = m->u.hello_ack.version;
      d[1] = m->u.hello_ack.driver_count;
      d[2] = m->u.hello_ack.fw_major;
      d[3] = m->u.hello_ack.fw_minor;
      break;
    case PBFW_CONFIGURE:
      d[0] = m->u.configure.driver;
      d[1] = m->u.configure.config.pulse_ms;
      d[2] = m->u.configure.config.hold_duty_pct;
      d[3] = m->u.configure.config.max_pulse_ms;
      d[4] = m->u.configure.config.recycle_ms;
      put_le16(d + 5, m->u.configure.config.max_hold_ms);
      break;
    case PBFW_FIRE:
      d[0] = m->u.fire.driver;
      d[1] = m->u.fire.mode;
      d[2] = m->u.fire.pulse_ms;
      put_le16(d + 3, m->u.fire.seq);
      break;
    case PBFW_RELEASE:
      d[0] = m->u.release.driver;
      put_le16(d + 1, m->u.release.seq);
      break;
    case PBFW_RELEASE_ALL:
      put_le16(d, m->u.release_all.seq);
      break;
    case PBFW_HEARTBEAT:
      d[0] = m->u.heartbeat.version;
      put_le16(d + 1, m->u.heartbeat.seq);
      break;
    case PBFW_STATUS:
      put_le16(d, m->u.status.coil_states);
      d[2] = m->u.status.end_of_stroke;
      d[3] = m->u.status.configured;
      d[4] = m->u.status.faults;
      put_le16(d + 5, m->u.status.last_seq);
      break;
    case PBFW_FAULT:
      d[0] = m->u.fault.code;
      d[1] = m->u.fault.driver;
      put_le16(d + 2, m->u.fault.detail);
      put_le16(d + 4, m->u.fault.count);
      break;
  }
  const int len = pbfw_frame_length(m->kind);
  out->len = (uint8_t)(len > 0 ? len : 0);
  if (len > 0) d[len - 1] = pbfw_crc8(out->id, d, (unsigned)len - 1u);
}
