#pragma once
// Between the tracker's and the controller's plain structs and their LCM
// messages: fills every field with its documented unit and sign, and checks
// received messages field by field (a decoded message can still carry NaN or
// an out-of-range code; such a message is malformed).

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>
#include <span>

#include "pinball_lcm/lcmt_pinball_daemon_stats.hpp"
#include "pinball_lcm/lcmt_pinball_driver_status.hpp"
#include "pinball_lcm/lcmt_pinball_flipper_command.hpp"
#include "pinball_lcm/lcmt_pinball_game_event.hpp"
#include "pinball_lcm/lcmt_pinball_observation.hpp"
#include "pinball_lcm/lcmt_pinball_projection.hpp"
#include "pinball/firmware/driver_bus.h"
#include "pinball/track/observation.h"
#include "pinball/track/tracker.h"

namespace pinball::bus {

/// An observation message: `utime` the ball's exposure date (the frame's
/// stamp when not found), `delivered_utime` the frame's stamp. `found` false
/// leaves the position fields zero.
pinball_lcm::lcmt_pinball_observation to_lcm_observation(std::int64_t utime, std::int64_t delivered_utime,
                                                          std::int64_t seq, bool found,
                                                          const track::Observation& observation, double u_px,
                                                          double v_px, const track::ContactSensors& contacts);

/// The layout a PINBALL_OBSERVATION message was recorded in.
enum class ObservationLayout {
  kMalformed,       ///< neither layout decodes the whole message
  kCurrent,         ///< lcmt_pinball_observation
  kBeforeDelivery,  ///< lcmt_pinball_observation_v1 (logs from before 2026-12-03): no delivery stamp
};

/// Decodes a PINBALL_OBSERVATION message of either layout into the current
/// one; an old message is delivered at its own utime (latency unknown: 0).
/// The message must fill `size` exactly.
ObservationLayout decode_observation(const void* data, std::size_t size, pinball_lcm::lcmt_pinball_observation& out);

/// A projection message from one tracker update.
pinball_lcm::lcmt_pinball_projection to_lcm_projection(std::int64_t utime, std::int64_t seq,
                                                        std::int64_t observation_seq,
                                                        const track::TrackerOutput& output);

/// A driver status message from the host's view of the link: session state,
/// the coils the board's last Status reported on, and the bus's counters.
pinball_lcm::lcmt_pinball_driver_status to_lcm_driver_status(std::int64_t utime, std::int64_t seq,
                                                              firmware::BusState state,
                                                              const firmware::BoardView& board,
                                                              const firmware::DriverBusCounters& counters);

/// A flipper command message; `cause` is one of the message's CAUSE_ codes.
pinball_lcm::lcmt_pinball_flipper_command to_lcm_flipper_command(std::int64_t utime, std::int64_t seq,
                                                                  std::int64_t projection_seq, int flipper,
                                                                  bool energize, std::int8_t cause);

/// A game event message; `kind` is one of the message's KIND_ codes.
pinball_lcm::lcmt_pinball_game_event to_lcm_game_event(std::int64_t utime, std::int64_t seq, std::int8_t kind,
                                                        int ball, double points, double ball_time_s);

/// One stage of the latency table, as PINBALL_STATS carries it.
struct StageLatency {
  const char* name = "";  ///< e.g. "capture->detection"
  std::uint64_t count = 0;
  double p50_us = 0.0;
  double p99_us = 0.0;
  double max_us = 0.0;
};

/// The counters PINBALL_STATS carries beside the latencies.
struct DaemonStatsCounts {
  std::uint64_t frames = 0, frames_dropped = 0, detections = 0, projections = 0, commands = 0, camera_stalls = 0,
                malformed_messages = 0, ring_overflows = 0;
  std::uint64_t can_log_written = 0, can_log_dropped = 0;    ///< the CAN log's frames (0, 0 when none)
  std::uint64_t lcm_published = 0, lcm_publish_failed = 0;  ///< LCM messages published and refused
};

/// A daemon statistics message.
pinball_lcm::lcmt_pinball_daemon_stats to_lcm_daemon_stats(std::int64_t utime, std::int64_t seq,
                                                            std::span<const StageLatency> stages,
                                                            const DaemonStatsCounts& counts);

/// What is wrong with a decoded observation message ("seq below 0", "a found
/// ball's position is not finite"), or nullptr when it is well formed. A
/// static string: the receiving threads call it and allocate nothing.
const char* observation_fault(const pinball_lcm::lcmt_pinball_observation& m);

/// The observation inside a message: t_s the exposure date, latency_s the
/// delivery stamp less it (never below 0); false when the message is malformed
/// (observation_fault names why).
bool from_lcm_observation(const pinball_lcm::lcmt_pinball_observation& m, bool& found, track::Observation& out,
                          track::ContactSensors& contacts);

/// What is wrong with a decoded flipper command ("flipper outside -1..1"), or
/// nullptr when it is well formed. A static string, as observation_fault.
const char* flipper_command_fault(const pinball_lcm::lcmt_pinball_flipper_command& m);

/// A received flipper command is well formed (flipper -1..1, cause 0..5).
bool valid_flipper_command(const pinball_lcm::lcmt_pinball_flipper_command& m);

/// A message's LCM encoding (fingerprint and fields), for logs, tests and
/// benches; the daemon's bus encodes into its own buffer instead (no allocation).
template <class T>
std::vector<std::uint8_t> encode_message(const T& m) {
  std::vector<std::uint8_t> data(static_cast<std::size_t>(m.getEncodedSize()));
  m.encode(data.data(), 0, static_cast<int>(data.size()));
  return data;
}

/// The utime of an encoded pinball message without decoding it: every type in
/// src/bus/lcmtypes starts with `int64_t utime`, which LCM encodes big-endian
/// right after its 8-byte type fingerprint. Empty when the bytes are too short.
std::optional<std::int64_t> encoded_utime(const void* data, std::size_t size);

/// The projection a message carries (check it with valid_projection first):
/// the inverse of to_lcm_projection, for what reads projections back (the view).
track::TrajectoryProjection from_lcm_projection(const pinball_lcm::lcmt_pinball_projection& m);

/// A received projection is well formed: every number finite, flipper -1..1,
/// and a valid one has speed, d and t_impact >= 0 and h, angle in range.
bool valid_projection(const pinball_lcm::lcmt_pinball_projection& m);

}  // namespace pinball::bus
