#include "pinball/bus/message_convert.h"

#include <algorithm>
#include <cmath>

#include "pinball/core/utime.h"
#include "pinball_lcm/lcmt_pinball_observation_v1.hpp"

namespace pinball::bus {

pinball_lcm::lcmt_pinball_observation to_lcm_observation(std::int64_t utime, std::int64_t delivered_utime,
                                                          std::int64_t seq, bool found,
                                                          const track::Observation& observation, double u_px,
                                                          double v_px, const track::ContactSensors& contacts) {
  pinball_lcm::lcmt_pinball_observation m{};
  m.utime = utime;
  m.delivered_utime = delivered_utime;
  m.seq = seq;
  m.found = found;
  if (found) {
    m.x_m = observation.p_board.x();
    m.y_m = observation.p_board.y();
    m.u_px = u_px;
    m.v_px = v_px;
    m.confidence = observation.confidence;
  }
  m.contact_left = contacts.left;
  m.contact_right = contacts.right;
  return m;
}

pinball_lcm::lcmt_pinball_projection to_lcm_projection(std::int64_t utime, std::int64_t seq,
                                                        std::int64_t observation_seq,
                                                        const track::TrackerOutput& output) {
  const track::TrajectoryProjection& p = output.projection;
  pinball_lcm::lcmt_pinball_projection m{};
  m.utime = utime;
  m.seq = seq;
  m.observation_seq = observation_seq;
  m.valid = p.valid;
  m.reason = static_cast<std::int8_t>(p.reason);
  m.flipper = static_cast<std::int8_t>(p.valid ? p.flipper : -1);
  m.hittable = p.hittable;
  m.rolling = p.rolling;
  if (p.valid) {
    m.speed_mps = p.speed_mps;
    m.angle_rad = p.angle_rad;
    m.h = p.h;
    m.d_m = p.d_m;
    m.t_impact_s = p.t_impact_s;
    m.impact_x_m = p.impact_point.x();
    m.impact_y_m = p.impact_point.y();
  }
  m.launched = output.launch.launched;
  m.lost = output.launch.lost;
  return m;
}

pinball_lcm::lcmt_pinball_driver_status to_lcm_driver_status(std::int64_t utime, std::int64_t seq,
                                                              firmware::BusState state,
                                                              const firmware::BoardView& board,
                                                              const firmware::DriverBusCounters& k) {
  pinball_lcm::lcmt_pinball_driver_status m{};
  m.utime = utime;
  m.seq = seq;
  m.bus_state = static_cast<std::int8_t>(state);
  m.board_valid = board.valid;
  for (int d = 0; board.valid && d < firmware::kMaxDrivers; ++d) {
    if (board.status.coil(d) != firmware::CoilState::kOff) m.coils_on = static_cast<std::int16_t>(m.coils_on | (1 << d));
  }
  m.frames_sent = static_cast<std::int64_t>(k.frames_sent);
  m.rx_frames = static_cast<std::int64_t>(k.rx_frames);
  m.rx_bad = static_cast<std::int64_t>(k.rx_bad);
  m.faults = static_cast<std::int64_t>(k.faults);
  m.bus_off = static_cast<std::int64_t>(k.bus_off);
  m.reconnects = static_cast<std::int64_t>(k.reconnects);
  m.tx_failures = static_cast<std::int64_t>(k.tx_failures);
  m.release_alls = static_cast<std::int64_t>(k.release_alls);
  m.watchdog_faults = static_cast<std::int64_t>(k.watchdog_faults);
  m.hold_cap_faults = static_cast<std::int64_t>(k.hold_cap_faults);
  m.release_retries = static_cast<std::int64_t>(k.release_retries);
  m.release_escalations = static_cast<std::int64_t>(k.release_escalations);
  m.liveness_stalls = static_cast<std::int64_t>(k.liveness_stalls);
  m.coils_dropped = static_cast<std::int64_t>(k.coils_dropped);
  return m;
}

pinball_lcm::lcmt_pinball_flipper_command to_lcm_flipper_command(std::int64_t utime, std::int64_t seq,
                                                                  std::int64_t projection_seq, int flipper,
                                                                  bool energize, std::int8_t cause) {
  pinball_lcm::lcmt_pinball_flipper_command m{};
  m.utime = utime;
  m.seq = seq;
  m.projection_seq = projection_seq;
  m.flipper = static_cast<std::int8_t>(flipper);
  m.energize = energize;
  m.cause = cause;
  return m;
}

pinball_lcm::lcmt_pinball_game_event to_lcm_game_event(std::int64_t utime, std::int64_t seq, std::int8_t kind,
                                                        int ball, double points, double ball_time_s) {
  pinball_lcm::lcmt_pinball_game_event m{};
  m.utime = utime;
  m.seq = seq;
  m.kind = kind;
  m.ball = ball;
  m.points = points;
  m.ball_time_s = ball_time_s;
  return m;
}

pinball_lcm::lcmt_pinball_daemon_stats to_lcm_daemon_stats(std::int64_t utime, std::int64_t seq,
                                                            std::span<const StageLatency> stages,
                                                            const DaemonStatsCounts& counts) {
  pinball_lcm::lcmt_pinball_daemon_stats m;
  m.utime = utime;
  m.seq = seq;
  m.num_stages = static_cast<std::int32_t>(stages.size());
  for (const StageLatency& s : stages) {
    m.stage.emplace_back(s.name);
    m.count.push_back(static_cast<std::int64_t>(s.count));
    m.p50_us.push_back(s.p50_us);
    m.p99_us.push_back(s.p99_us);
    m.max_us.push_back(s.max_us);
  }
  m.frames = static_cast<std::int64_t>(counts.frames);
  m.frames_dropped = static_cast<std::int64_t>(counts.frames_dropped);
  m.detections = static_cast<std::int64_t>(counts.detections);
  m.projections = static_cast<std::int64_t>(counts.projections);
  m.commands = static_cast<std::int64_t>(counts.commands);
  m.camera_stalls = static_cast<std::int64_t>(counts.camera_stalls);
  m.malformed_messages = static_cast<std::int64_t>(counts.malformed_messages);
  m.ring_overflows = static_cast<std::int64_t>(counts.ring_overflows);
  m.can_log_written = static_cast<std::int64_t>(counts.can_log_written);
  m.can_log_dropped = static_cast<std::int64_t>(counts.can_log_dropped);
  m.lcm_published = static_cast<std::int64_t>(counts.lcm_published);
  m.lcm_publish_failed = static_cast<std::int64_t>(counts.lcm_publish_failed);
  return m;
}

ObservationLayout decode_observation(const void* data, std::size_t size, pinball_lcm::lcmt_pinball_observation& out) {
  if (size > 0x7fffffffu) return ObservationLayout::kMalformed;
  const int n = static_cast<int>(size);
  if (out.decode(data, 0, n) == n) return ObservationLayout::kCurrent;
  pinball_lcm::lcmt_pinball_observation_v1 old{};
  if (old.decode(data, 0, n) != n) return ObservationLayout::kMalformed;
  out = pinball_lcm::lcmt_pinball_observation{};
  out.utime = old.utime;
  out.delivered_utime = old.utime;
  out.seq = old.seq;
  out.found = old.found;
  out.x_m = old.x_m;
  out.y_m = old.y_m;
  out.u_px = old.u_px;
  out.v_px = old.v_px;
  out.confidence = old.confidence;
  out.contact_left = old.contact_left;
  out.contact_right = old.contact_right;
  return ObservationLayout::kBeforeDelivery;
}

const char* observation_fault(const pinball_lcm::lcmt_pinball_observation& m) {
  if (m.utime < 0) return "utime below 0";
  if (m.delivered_utime < 0) return "delivered_utime below 0";
  if (m.seq < 0) return "seq below 0";
  if (!m.found) return nullptr;
  if (!std::isfinite(m.x_m) || !std::isfinite(m.y_m)) return "a found ball's position is not finite";
  if (!(m.confidence >= 0.0 && m.confidence <= 1.0)) return "a found ball's confidence is outside 0..1";
  return nullptr;
}

bool from_lcm_observation(const pinball_lcm::lcmt_pinball_observation& m, bool& found, track::Observation& out,
                          track::ContactSensors& contacts) {
  if (observation_fault(m) != nullptr) return false;
  found = m.found;
  contacts.left = m.contact_left;
  contacts.right = m.contact_right;
  out.t_s = from_utime(m.utime);
  out.latency_s = std::max(0.0, from_utime(m.delivered_utime) - out.t_s);
  if (!found) return true;
  out.p_board = Vec2(m.x_m, m.y_m);
  out.confidence = m.confidence;
  return true;
}

const char* flipper_command_fault(const pinball_lcm::lcmt_pinball_flipper_command& m) {
  using M = pinball_lcm::lcmt_pinball_flipper_command;
  if (m.utime < 0) return "utime below 0";
  if (m.flipper < -1 || m.flipper > 1) return "flipper outside -1..1 (-1 every flipper, 0 left, 1 right)";
  if (m.cause < M::CAUSE_PROJECTION || m.cause > M::CAUSE_BUS_FAULT) return "cause outside 0..5";
  return nullptr;
}

bool valid_flipper_command(const pinball_lcm::lcmt_pinball_flipper_command& m) {
  return flipper_command_fault(m) == nullptr;
}

track::TrajectoryProjection from_lcm_projection(const pinball_lcm::lcmt_pinball_projection& m) {
  track::TrajectoryProjection p;
  p.valid = m.valid;
  p.reason = static_cast<track::NoProjection>(m.reason);
  p.flipper = m.flipper;  // NOLINT(bugprone-signed-char-misuse): an int8 index, not a character
  p.speed_mps = m.speed_mps;
  p.angle_rad = m.angle_rad;
  p.h = m.h;
  p.d_m = m.d_m;
  p.t_impact_s = m.t_impact_s;
  p.impact_point = Vec2(m.impact_x_m, m.impact_y_m);
  p.hittable = m.hittable;
  p.rolling = m.rolling;
  return p;
}

bool valid_projection(const pinball_lcm::lcmt_pinball_projection& m) {
  const bool finite = std::isfinite(m.speed_mps) && std::isfinite(m.angle_rad) && std::isfinite(m.h) &&
                      std::isfinite(m.d_m) && std::isfinite(m.t_impact_s) && std::isfinite(m.impact_x_m) &&
                      std::isfinite(m.impact_y_m);
  if (m.utime < 0 || !finite || m.flipper < -1 || m.flipper > 1) return false;
  if (!m.valid) return m.reason >= 0 && m.reason <= static_cast<int>(track::NoProjection::kNumerical);
  return m.flipper >= 0 && m.speed_mps >= 0.0 && m.d_m >= 0.0 && m.t_impact_s >= 0.0 &&
         std::abs(m.angle_rad) <= 2.0 && std::abs(m.h) < 1e3;
}

std::optional<std::int64_t> encoded_utime(const void* data, std::size_t size) {
  constexpr std::size_t kFingerprintBytes = 8;
  if (data == nullptr || size < kFingerprintBytes + 8) return std::nullopt;
  const auto* p = static_cast<const unsigned char*>(data) + kFingerprintBytes;
  std::uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v = (v << 8) | p[i];
  return static_cast<std::int64_t>(v);
}

}  // namespace pinball::bus
