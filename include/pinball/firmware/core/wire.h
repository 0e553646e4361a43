#ifndef PINBALL_FIRMWARE_CORE_WIRE_H
#define PINBALL_FIRMWARE_CORE_WIRE_H
/* The driver-board CAN protocol (firmware_interface/PROTOCOL.md) on the wire,
 * in portable C11: ids, kinds, limits, CRC-8, and the one decoder and encoder
 * of every message. The board firmware (firmware/), the reference board that
 * the simulator runs (VirtualDriverBoard) and the host's codec (codec.cpp)
 * all decode and encode through these functions, so a range check cannot
 * differ between them.
 *
 * No heap, no floating point, no library calls: it builds for a Cortex-M4
 * with nothing but a compiler. */

#include <stdbool.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ---- protocol constants (protocol.h holds the same values for C++ and
 * static_asserts that they agree) ---- */
#define PBFW_PROTOCOL_VERSION 2u
#define PBFW_MAX_FRAME_BYTES 8u
#define PBFW_MAX_DRIVERS 8u
#define PBFW_MAX_BOARDS 16u
#define PBFW_BITRATE_BPS 500000u
#define PBFW_ID_BASE 0x100u
#define PBFW_ID_MASK 0x700u
#define PBFW_ABS_MAX_PULSE_MS 100u
#define PBFW_ABS_MAX_HOLD_DUTY_PCT 50u
#define PBFW_ABS_MAX_HOLD_MS 10000u
#define PBFW_MIN_WATCHDOG_MS 10u
#define PBFW_MAX_WATCHDOG_MS 1000u
#define PBFW_DEFAULT_WATCHDOG_MS 100u
#define PBFW_BOARD_DRIVER 0xFFu       /* Fault.driver: the whole board */
#define PBFW_SEQ_REFERENCE_LAG 16384u /* rule 9: 2^14 */
#define PBFW_MAX_FAULT_CODE 9u

/* Message kinds: the id's middle nibble. */
typedef enum pbfw_kind {
  PBFW_RELEASE_ALL = 0x0,
  PBFW_RELEASE = 0x1,
  PBFW_FIRE = 0x2,
  PBFW_HEARTBEAT = 0x3,
  PBFW_CONFIGURE = 0x4,
  PBFW_HELLO = 0x5,
  PBFW_FAULT = 0x8,
  PBFW_STATUS = 0x9,
  PBFW_HELLO_ACK = 0xA
} pbfw_kind;

typedef enum pbfw_coil_state { PBFW_COIL_OFF = 0, PBFW_COIL_PULSE = 1, PBFW_COIL_HOLD = 2 } pbfw_coil_state;

typedef enum pbfw_fire_mode { PBFW_PULSE_ONLY = 0, PBFW_PULSE_HOLD = 1 } pbfw_fire_mode;

typedef enum pbfw_fault_code {
  PBFW_FAULT_WATCHDOG_EXPIRED = 1,
  PBFW_FAULT_HOLD_CAP_REACHED = 2,
  PBFW_FAULT_PULSE_CLAMPED = 3,
  PBFW_FAULT_BAD_FRAME = 4,
  PBFW_FAULT_VERSION_MISMATCH = 5,
  PBFW_FAULT_NOT_CONFIGURED = 6,
  PBFW_FAULT_NOT_ARMED = 7,
  PBFW_FAULT_STALE = 8,
  PBFW_FAULT_LOCKED = 9
} pbfw_fault_code;

/* Status.faults bits. */
#define PBFW_FAULT_BIT_WATCHDOG 0x01u
#define PBFW_FAULT_BIT_HOLD_CAP 0x02u
#define PBFW_FAULT_BIT_PULSE_CLAMP 0x04u
#define PBFW_FAULT_BIT_BAD_FRAME 0x08u
#define PBFW_FAULT_BIT_VERSION 0x10u
#define PBFW_FAULT_BIT_REFUSED 0x20u
#define PBFW_FAULT_BIT_RESERVED 0x40u
#define PBFW_FAULT_BIT_ARMED 0x80u

/* Why a frame was rejected (the values are the Fault 4 detail). */
typedef enum pbfw_decode_error {
  PBFW_DECODE_OK = 0,
  PBFW_DECODE_ERROR_FRAME = 1,   /* a controller error frame, not a message */
  PBFW_DECODE_FOREIGN_ID = 2,    /* not one of our ids */
  PBFW_DECODE_UNKNOWN_KIND = 3,  /* our id range but no such kind */
  PBFW_DECODE_WRONG_LENGTH = 4,  /* length differs from the kind's fixed length */
  PBFW_DECODE_BAD_CHECKSUM = 5,  /* CRC-8 mismatch */
  PBFW_DECODE_OUT_OF_RANGE = 6,  /* a field outside its range */
  PBFW_DECODE_WRONG_VERSION = 7  /* protocol version differs */
} pbfw_decode_error;

/* One classic CAN frame as the firmware sees it. */
typedef struct pbfw_frame {
  uint32_t id;                        /* 11-bit identifier */
  uint8_t len;                        /* data length, 0..8 */
  uint8_t data[PBFW_MAX_FRAME_BYTES]; /* payload; bytes past len are ignored */
  bool error;                         /* a controller error frame */
} pbfw_frame;

/* One driver's timings and caps (Configure). */
typedef struct pbfw_driver_config {
  uint8_t pulse_ms;      /* default full-power pulse, 1..max_pulse_ms */
  uint8_t hold_duty_pct; /* hold PWM duty, 0..50; 0 = no hold */
  uint8_t max_pulse_ms;  /* per-driver pulse cap, 1..100 */
  uint16_t max_hold_ms;  /* per-driver hold cap, 1..10000 */
  uint8_t recycle_ms;    /* off time before the next Fire */
} pbfw_driver_config;

typedef struct pbfw_hello { uint8_t version; uint16_t watchdog_ms; } pbfw_hello;
typedef struct pbfw_hello_ack { uint8_t version, driver_count, fw_major, fw_minor; } pbfw_hello_ack;
typedef struct pbfw_configure { uint8_t driver; pbfw_driver_config config; } pbfw_configure;
typedef struct pbfw_fire { uint8_t driver, mode, pulse_ms; uint16_t seq; } pbfw_fire;
typedef struct pbfw_release { uint8_t driver; uint16_t seq; } pbfw_release;
typedef struct pbfw_release_all { uint16_t seq; } pbfw_release_all;
typedef struct pbfw_heartbeat { uint8_t version; uint16_t seq; } pbfw_heartbeat;
typedef struct pbfw_status {
  uint16_t coil_states; /* 2 bits per driver */
  uint8_t end_of_stroke, configured, faults;
  uint16_t last_seq;
} pbfw_status;
typedef struct pbfw_fault { uint8_t code, driver; uint16_t detail, count; } pbfw_fault;

/* A decoded message: its board, its kind and the member of `u` that kind names. */
typedef struct pbfw_message {
  uint8_t board; /* 0..15 */
  pbfw_kind kind;
  union {
    pbfw_hello hello;
    pbfw_hello_ack hello_ack;
    pbfw_configure configure;
    pbfw_fire fire;
    pbfw_release release;
    pbfw_release_all release_all;
    pbfw_heartbeat heartbeat;
    pbfw_status status;
    pbfw_fault fault;
  } u;
} pbfw_message;

/* True when sequence number a is newer than b (RFC 1982 serial arithmetic). */
static inline bool pbfw_seq_newer(uint16_t a, uint16_t b) { return (int16_t)(uint16_t)(a - b) > 0; }

/* The 11-bit id of `kind` for board `board`. */
static inline uint32_t pbfw_make_id(pbfw_kind kind, uint8_t board) {
  return PBFW_ID_BASE | ((uint32_t)kind << 4) | (board & 0x0Fu);
}

/* CRC-8 (AUTOSAR 0x2F, init 0xFF, final xor 0xFF) over the id's low byte, the
 * id's bits 8..10, then `n` bytes. */
uint8_t pbfw_crc8(uint32_t id, const uint8_t* bytes, unsigned n);

/* Fixed data length of a kind, or -1 for an unknown kind. */
int pbfw_frame_length(unsigned kind);

/* Checks a driver configuration: NULL when valid, else the reason. */
const char* pbfw_validate_config(const pbfw_driver_config* config);

/* Decodes and validates one frame into *out. Returns PBFW_DECODE_OK or the
 * first failed check; *reason (when not NULL) gets a static string naming it. */
pbfw_decode_error pbfw_decode(const pbfw_frame* frame, pbfw_message* out, const char** reason);

/* Encodes `message` (its kind and member) for board message->board and seals
 * it with the CRC. Field values are encoded as given, valid or not, so tests
 * can build bad frames; the receiver rejects them. */
void pbfw_encode(const pbfw_message* message, pbfw_frame* out);

#ifdef __cplusplus
}
#endif

#endif /* PINBALL_FIRMWARE_CORE_WIRE_H */
