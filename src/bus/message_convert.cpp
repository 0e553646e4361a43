#include "pinball/bus/message_convert.h"

#include <cmath>

#include "pinball/core/utime.h"

namespace pinball::bus {

pinball_lcm::lcmt_pinball_observation to_lcm_observation(std::int64_t utime, std::int64_t seq, bool found,
                                                          const track::Observation& observation, double u_px,
                                                          double v_px, const track::ContactSensors& contacts) {
  pinball_lcm::lcmt_pinball_observation m{};
  m.utime = utime;
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
  return m;
}

bool from_lcm_observation(const pinball_lcm::lcmt_pinball_observation& m, bool& found, track::Observation& out,
                          track::ContactSensors& contacts) {
  if (m.utime < 0 || m.seq < 0) return false;
  found = m.found;
  contacts.left = m.contact_left;
  contacts.right = m.contact_right;
  out.t_s = from_utime(m.utime);
  if (!found) return true;
  if (!std::isfinite(m.x_m) || !std::isfinite(m.y_m) || !(m.confidence >= 0.0 && m.confidence <= 1.0)) return false;
  out.p_board = Vec2(m.x_m, m.y_m);
  out.confidence = m.confidence;
  return true;
}

bool valid_flipper_command(const pinball_lcm::lcmt_pinball_flipper_command& m) {
  return m.utime >= 0 && m.flipper >= -1 && m.flipper <= 1 && m.cause >= 0 && m.cause <= 5;
}

}  // namespace pinball::bus
