#ifndef PINBALL_FIRMWARE_CORE_BOARD_H
#define PINBALL_FIRMWARE_CORE_BOARD_H
/* The solenoid driver board's firmware rules (PROTOCOL.md, "Firmware rules",
 * 1..13), implemented once in portable C11. The same code runs on the STM32
 * board (firmware_interface/stm32f446/), in the simulator and in every host test
 * (VirtualDriverBoard wraps it).
 *
 * Fixed-size state, no heap, no floating point, deterministic: the caller
 * owns a pbfw_board, hands it frames and the time in nanoseconds, and the
 * board drives its coils through one callback (the HAL's output stage) and
 * queues its replies in an outbox the caller drains onto the bus.
 *
 * Time is a signed 64-bit count of nanoseconds from any origin that never
 * goes backwards (an earlier time is taken as the last one). It does not wrap
 * in practice (292 years), so deadlines compare with a plain `<=`. The board's
 * 1 MHz timer multiplies by 1000; nanoseconds let the simulator's clock (double
 * seconds) pass through without moving a coil's edge by a measurable amount. */

#include "pinball/firmware/core/wire.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef int64_t pbfw_time_ns;

/* Nanoseconds per millisecond: the protocol speaks in ms, the core in ns. */
#define PBFW_NS_PER_MS ((pbfw_time_ns)1000000)

/* Outgoing frames the board can queue between two drains. */
#define PBFW_OUTBOX_SIZE 32u

/* The output stage: called for every change of a coil's drive, at the exact
 * time the rule says it happens (which may be earlier than the call's `now`
 * when the caller was late: rule 13). duty_pct is 100 in a pulse, the hold
 * duty in a hold, 0 when off. Must not call back into the board. */
typedef void (*pbfw_set_coil_fn)(void* context, unsigned driver, pbfw_coil_state state, uint8_t duty_pct,
                                 pbfw_time_ns at_ns);

typedef struct pbfw_board_options {
  uint8_t board_id;           /* 0..15: the id's low nibble */
  uint8_t driver_count;       /* drivers fitted, 1..8 */
  pbfw_time_ns status_period_ns; /* Status period (rule 12: 10 ms = 10 000 000) */
  uint8_t fw_major, fw_minor; /* reported in HelloAck */
  pbfw_set_coil_fn set_coil;  /* the output stage; may be NULL in tests that only read the state */
  void* set_coil_context;
} pbfw_board_options;

/* What the board counted since pbfw_board_init (64-bit: they never wrap). */
typedef struct pbfw_board_counters {
  uint64_t frames;                 /* frames offered */
  uint64_t bad_frames;             /* failed to decode */
  uint64_t bad_checksum;           /* of which CRC mismatches */
  uint64_t version_mismatch;       /* of which wrong protocol version */
  uint64_t foreign;                /* another board's, or a board->host kind */
  uint64_t hellos;                 /* sessions started */
  uint64_t fires_accepted;         /* Fires that energised a coil */
  uint64_t refused_not_configured; /* commands before Hello / Configure */
  uint64_t refused_not_armed;      /* Fire while the watchdog was not alive */
  uint64_t refused_recycle;        /* Fire within the recycle time */
  uint64_t refused_busy;           /* Fire on a driver already on */
  uint64_t refused_locked;         /* Fire on a driver locked by its hold cap */
  uint64_t stale;                  /* Fire / Heartbeat whose seq was not newer */
  uint64_t pulse_clamps;           /* pulses shortened to the cap */
  uint64_t hold_cap_trips;         /* holds ended by the cap */
  uint64_t watchdog_trips;         /* all-off because heartbeats stopped */
  uint64_t tx_dropped;             /* replies lost to a full outbox */
} pbfw_board_counters;

/* One driver's state. */
typedef struct pbfw_driver {
  pbfw_driver_config config;
  bool configured;        /* configured in this session */
  bool hold_after_pulse;  /* the Fire asked for mode 1 */
  bool locked;            /* hold cap tripped: refuses Fire until Release */
  bool has_seq;           /* last_seq is meaningful */
  bool eos;               /* end-of-stroke switch closed */
  bool has_been_on;       /* off_since_ns is meaningful (recycle time) */
  uint8_t state;          /* pbfw_coil_state */
  uint8_t duty_pct;       /* 100 in a pulse, the hold duty in a hold */
  uint16_t last_seq;      /* the driver's sequence reference (rule 9) */
  pbfw_time_ns since_ns;     /* when the current state began */
  pbfw_time_ns pulse_end_ns; /* when the pulse ends */
  pbfw_time_ns hold_end_ns;  /* when the hold cap ends the hold */
  pbfw_time_ns off_since_ns; /* when the driver last went off */
} pbfw_driver;

/* The whole board. Treat as opaque: read it through the functions below. */
typedef struct pbfw_board {
  pbfw_board_options options;
  pbfw_driver drivers[PBFW_MAX_DRIVERS];
  bool started;     /* time has been set once */
  bool session;     /* a valid Hello arrived */
  bool armed;       /* heartbeats arrive in time */
  bool has_hb_seq;  /* hb_seq is meaningful */
  bool has_seq;     /* last_seq is meaningful */
  uint8_t fault_bits;
  uint16_t hb_seq;      /* newest Heartbeat seq */
  uint16_t last_seq;    /* newest seq accepted in the session */
  uint16_t fault_count; /* faults reported since Hello */
  uint16_t watchdog_ms; /* the session's heartbeat timeout, as Hello gave it */
  pbfw_time_ns watchdog_ns;
  pbfw_time_ns last_heartbeat_ns;
  pbfw_time_ns now_ns;
  pbfw_time_ns next_status_ns;
  pbfw_frame outbox[PBFW_OUTBOX_SIZE];
  uint8_t out_head, out_count;
  pbfw_board_counters counters;
} pbfw_board;

/* Why pbfw_board_init refused its options. */
typedef enum pbfw_init_error {
  PBFW_INIT_OK = 0,
  PBFW_INIT_BAD_BOARD_ID,     /* board_id > 15 */
  PBFW_INIT_BAD_DRIVER_COUNT, /* driver_count outside 1..8 */
  PBFW_INIT_BAD_STATUS_PERIOD /* status_period_ns <= 0 */
} pbfw_init_error;

/* Every driver off and unconfigured, out of session. Calls no callback: the
 * output stage is off at reset by the hardware's design (rule 1). */
pbfw_init_error pbfw_board_init(pbfw_board* board, const pbfw_board_options* options);

/* Handles one received frame at `now_ns` (runs the timers up to now first). */
void pbfw_board_on_frame(pbfw_board* board, const pbfw_frame* frame, pbfw_time_ns now_ns);

/* Runs every timer that expired up to `now_ns`, each at its own deadline and
 * earliest first (pulse end, hold cap, watchdog), then the Status period. */
void pbfw_board_advance(pbfw_board* board, pbfw_time_ns now_ns);

/* The earliest time at which pbfw_board_advance has something to do (a pulse
 * or hold ending, the watchdog, the next Status): a main loop may sleep until
 * then or until a frame arrives. */
pbfw_time_ns pbfw_board_next_deadline(const pbfw_board* board);

/* Copies the oldest queued reply without taking it; false when none. */
bool pbfw_board_peek_tx(const pbfw_board* board, pbfw_frame* out);

/* Takes the oldest queued reply (Status, Fault, HelloAck); false when none. */
bool pbfw_board_pop_tx(pbfw_board* board, pbfw_frame* out);

/* Sets driver d's end-of-stroke switch (reported in Status). */
void pbfw_board_set_end_of_stroke(pbfw_board* board, unsigned d, bool closed);

/* The Status the board would send now. */
pbfw_status pbfw_board_status(const pbfw_board* board);

#ifdef __cplusplus
}
#endif

#endif /* PINBALL_FIRMWARE_CORE_BOARD_H */
