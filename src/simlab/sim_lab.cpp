#include "pinball/simlab/sim_lab.h"

#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "pinball/calibration/camera_calibration.h"
#include "pinball/core/rng.h"
#include "pinball/sim/game_state.h"
#include "pinball/sim/penetration.h"
#include "pinball/sim/model_world.h"

namespace pinball::simlab {
namespace {

simlab::SimCameraConfig camera_config(const SimLabOptions& o) {
  simlab::SimCameraConfig c = o.camera;
  c.seed = o.seed;
  return c;
}

// Frames of one flipper swept by hand, rendered on demand.
class SweepSource final : public vision::FrameSource {
 public:
  SweepSource(const SimLab& lab, std::size_t index)
      : lab_(lab), index_(index), camera_(lab.truth(), camera_config(lab.options())) {
    camera_.set_lamps_blinking(false);  // lamps steady in the lab (attract mode off)
    for (const table::Flipper& f : lab.truth().flippers) theta_.push_back(f.theta_min_rad);
    frames_ = static_cast<std::uint64_t>(std::floor(lab.sweep_duration_s() * camera_.fps()));
  }
  bool read(vision::Frame& out) override {
    if (next_ >= frames_) return false;
    const double t = static_cast<double>(next_++) / camera_.fps();
    theta_[index_] = lab_.sweep_angle(index_, t);
    camera_.set_flipper_angles(theta_);
    camera_.render({}, t, out);
    return true;
  }
  cv::Size frame_size() const override { return camera_.frame_size(); }
  double fps() const override { return camera_.fps(); }
  vision::FrameSourceCounters counters() const override { return camera_.counters(); }
  std::string describe() const override {
    std::ostringstream s;
    s << "simulated sweep of flipper " << index_ << ", " << camera_.describe();
    return s.str();
  }

 private:
  const SimLab& lab_;
  std::size_t index_;
  simlab::SimCameraSource camera_;
  std::vector<double> theta_;
  std::uint64_t frames_ = 0;
  std::uint64_t next_ = 0;
};

}  // namespace

SimLabOptions with_mounting_error(SimLabOptions options) {
  options.pivot_offset_m = Vec2{0.003, -0.002};
  options.length_offset_m = 0.002;
  options.theta_offset_rad = 0.012;
  return options;
}

SimLab::SimLab(const table::Board& nominal, const SimLabOptions& options)
    : nominal_(nominal), truth_(nominal), options_(options) {
  for (table::Flipper& f : truth_.flippers) {
    f.pivot += options.pivot_offset_m;
    f.length_m += options.length_offset_m;
    f.theta_min_rad += options.theta_offset_rad;
    f.theta_max_rad += options.theta_offset_rad;
  }
  camera_ = std::make_unique<simlab::SimCameraSource>(truth_, camera_config(options));
  camera_->set_lamps_blinking(false);
}

cv::Mat SimLab::marker_image(std::span<const Vec2> markers, bool flippers_up) {
  std::vector<double> theta;
  for (const table::Flipper& f : truth_.flippers) theta.push_back(flippers_up ? f.theta_max_rad : f.theta_min_rad);
  camera_->set_flipper_angles(theta);
  camera_->set_markers(markers);
  camera_->render({}, 0.0, frame_);
  camera_->set_markers({});
  return frame_.gray.clone();
}

cv::Mat SimLab::camera_image() {
  const std::vector<Vec2> layout = calibration::default_marker_layout(nominal_);
  return marker_image(layout, false);
}

cv::Mat SimLab::flipper_markers_image(bool flippers_up) {
  std::vector<Vec2> markers;
  for (const table::Flipper& f : truth_.flippers) {
    markers.push_back(f.pivot);
    markers.push_back(table::flipper_tip(f, flippers_up ? f.theta_max_rad : f.theta_min_rad));
  }
  return marker_image(markers, flippers_up);
}

double SimLab::sweep_duration_s() const {
  return options_.sweeps * 2.0 * (options_.sweep_rest_s + options_.sweep_move_s) + options_.sweep_rest_s;
}

double SimLab::sweep_angle(std::size_t index, double t_s) const {
  const table::Flipper& f = truth_.flippers.at(index);
  const double rest = options_.sweep_rest_s, move = options_.sweep_move_s;
  const double period = 2.0 * (rest + move);
  const double t = std::fmod(std::max(t_s, 0.0), period);
  // Rest down, move up, rest up, move down; a smooth (cosine) push by hand.
  double up = 0.0;
  if (t < rest) {
    up = 0.0;
  } else if (t < rest + move) {
    up = 0.5 - 0.5 * std::cos(std::numbers::pi * (t - rest) / move);
  } else if (t < 2.0 * rest + move) {
    up = 1.0;
  } else {
    up = 0.5 + 0.5 * std::cos(std::numbers::pi * (t - 2.0 * rest - move) / move);
  }
  return f.theta_min_rad + up * (f.theta_max_rad - f.theta_min_rad);
}

std::unique_ptr<vision::FrameSource> SimLab::sweep_video(std::size_t index) const {
  if (index >= truth_.flippers.size()) throw std::invalid_argument("sim lab: no flipper " + std::to_string(index));
  return std::make_unique<SweepSource>(*this, index);
}

std::vector<calibration::GravityRoll> SimLab::rolls(int count, std::uint64_t stream) const {
  Rng rng(options_.seed * 0x9E3779B97F4A7C15ull + stream + 1);
  const std::unique_ptr<sim::World> world = sim::make_model_world(truth_);
  const double r = truth_.ball.radius_m;
  constexpr std::uint32_t kContact = sim::StepEvents::kHitObstacle | sim::StepEvents::kHitFlipper |
                                     sim::StepEvents::kFlipperPush | sim::StepEvents::kSensor |
                                     sim::StepEvents::kBallLost;
  std::vector<calibration::GravityRoll> out;
  for (int attempt = 0; static_cast<int>(out.size()) < count; ++attempt) {
    if (attempt > 200 * std::max(count, 1)) throw std::runtime_error("sim lab: no free place to roll a ball from");
    const Vec2 p0{rng.uniform(0.15, 0.85) * truth_.width_m, rng.uniform(0.45, 0.92) * truth_.height_m};
    bool free = true;
    for (const table::Shape& s : truth_.shapes) free = free && sim::shape_penetration_m(s, p0, 2.0 * r) <= 0.0;
    for (const table::Sensor& s : truth_.sensors) free = free && sim::shape_penetration_m(s.shape, p0, 2.0 * r) <= 0.0;
    if (!free) continue;
    sim::GameState state = sim::make_game_state(truth_, options_.seed);
    state.ball.position_m = p0;
    state.ball.velocity_mps = Vec2::Zero();
    state.ball_in_play = true;
    track::CameraModel camera(options_.roll_camera, rng.next_u64());
    calibration::GravityRoll roll;
    std::ostringstream name;
    name << "sim roll " << out.size() << " from (" << p0.x() << ", " << p0.y() << ")";
    roll.source = name.str();
    track::Observation o;
    const double dt = world->dt_s();
    for (double t = 0.0; t < options_.roll_hold_s; t += dt) {
      camera.expose(t, p0);
      while (camera.deliver(t, o)) roll.observations.push_back(o);
    }
    state.time_s = options_.roll_hold_s;
    double contact_s = -1.0;
    Vec2 contact_p = p0;
    while (state.time_s < options_.roll_hold_s + 4.0) {
      const sim::StepEvents e = world->step(state);
      camera.expose(state.time_s, state.ball.position_m, state.ball_in_play);
      while (camera.deliver(state.time_s, o)) roll.observations.push_back(o);
      if (contact_s < 0.0 && (e.flags & kContact) != 0) {
        contact_s = state.time_s;
        contact_p = state.ball.position_m;
      }
      if (!state.ball_in_play || (contact_s >= 0.0 && state.time_s > contact_s + options_.roll_after_contact_s)) break;
    }
    if (contact_s < 0.0) contact_p = state.ball.position_m;
    if ((contact_p - p0).norm() < options_.roll_min_travel_m) continue;
    out.push_back(std::move(roll));
  }
  return out;
}

}  // namespace pinball::simlab
