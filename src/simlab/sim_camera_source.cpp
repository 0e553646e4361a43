#include "pinball/simlab/sim_camera_source.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "pinball/core/check.h"
#include "pinball/sim/renderer.h"

namespace pinball::simlab {
namespace {

// The renderer's playfield colour (BGR) as gray, to tell the table's art from its obstacles.
std::uint8_t playfield_gray() {
  cv::Mat bgr(1, 1, CV_8UC3, cv::Scalar(46, 34, 26));
  cv::Mat gray;
  cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
  return gray.at<std::uint8_t>(0, 0);
}

// Board (m) -> drawing (px) of sim::render_board for `options` as a 3x3 matrix, and its inverse.
cv::Matx33d render_from_board(const table::Board& board, const sim::RenderOptions& o) {
  return {o.px_per_m, 0.0, static_cast<double>(o.margin_px), 0.0, -o.px_per_m,
          o.margin_px + board.height_m * o.px_per_m, 0.0, 0.0, 1.0};
}

// An anti-aliased filled convex polygon (image points) as a patch: the patch's
// place in an image of `size` and its 8-bit values (`value` inside). Empty
// roi when the polygon is off the image.
void polygon_patch(const std::vector<cv::Point2d>& uv_px, double value, cv::Size size, cv::Rect& roi, cv::Mat& patch) {
  double u0 = 1e300, v0 = 1e300, u1 = -1e300, v1 = -1e300;
  for (const cv::Point2d& p : uv_px) {
    u0 = std::min(u0, p.x);
    v0 = std::min(v0, p.y);
    u1 = std::max(u1, p.x);
    v1 = std::max(v1, p.y);
  }
  const cv::Rect box(cv::Point(static_cast<int>(std::floor(u0)) - 1, static_cast<int>(std::floor(v0)) - 1),
                     cv::Point(static_cast<int>(std::ceil(u1)) + 2, static_cast<int>(std::ceil(v1)) + 2));
  roi = box & cv::Rect(0, 0, size.width, size.height);
  patch = cv::Mat::zeros(box.size(), CV_8U);
  std::vector<cv::Point> fixed;
  for (const cv::Point2d& p : uv_px) {
    fixed.emplace_back(static_cast<int>(std::lround((p.x - box.x) * 16.0)),
                       static_cast<int>(std::lround((p.y - box.y) * 16.0)));
  }
  cv::fillConvexPoly(patch, fixed, cv::Scalar(value), cv::LINE_AA, 4);
  if (roi.area() == 0) return;
  patch = patch(cv::Rect(roi.x - box.x, roi.y - box.y, roi.width, roi.height)).clone();
}

}  // namespace

std::vector<SimPlastic> SimCameraConfig::default_plastics() {
  // Fractions of a 0.51 x 1.07 m table; upper left and right mid, where
  // plastics over lanes and bumpers usually sit.
  SimPlastic a;
  a.polygon_board = {Vec2{0.07, 0.80}, Vec2{0.17, 0.78}, Vec2{0.19, 0.86}, Vec2{0.09, 0.89}};
  a.gray = 95.0;
  SimPlastic b;
  b.polygon_board = {Vec2{0.33, 0.50}, Vec2{0.42, 0.52}, Vec2{0.40, 0.60}, Vec2{0.32, 0.57}};
  b.gray = 140.0;
  return {a, b};
}

SimCameraSource::SimCameraSource(const table::Board& board, const SimCameraConfig& config)
    : board_(board),
      config_(config),
      homography_(vision::CameraHomography::default_view(board, cv::Size(std::max(config.width_px, 1),
                                                                 std::max(config.height_px, 1)),
                                                 config.view)),
      rng_(config.seed) {
  const SimCameraConfig& c = config_;
  check_input(c.width_px >= 32 && c.height_px >= 32 && c.width_px <= 8192 && c.height_px <= 8192, "sim camera",
          "width_px and height_px must be in [32, 8192]");
  check_input(std::isfinite(c.fps) && c.fps > 0.0, "sim camera", "fps must be > 0");
  check_input(std::isfinite(c.lens_height_m) && c.lens_height_m > 0.1, "sim camera", "lens_height_m must be > 0.1 m");
  check_input(std::isfinite(c.exposure_s) && c.exposure_s >= 0.0 && c.exposure_s <= 1.0 / c.fps, "sim camera",
          "exposure_s must be in [0, 1/fps]");
  check_input(std::isfinite(c.first_exposure_s), "sim camera", "first_exposure_s must be finite");
  check_input(c.supersample >= 1 && c.supersample <= 4, "sim camera", "supersample must be in [1, 4]");
  check_input(std::isfinite(c.floor_gain) && c.floor_gain >= 0.0 && std::isfinite(c.floor_offset), "sim camera",
          "floor_gain must be >= 0 and floor_offset finite");
  check_input(c.clutter_shapes >= 0 && std::isfinite(c.clutter_contrast), "sim camera", "clutter_shapes must be >= 0");
  check_input(c.ball_gray >= 0.0 && c.ball_gray <= 255.0 && c.highlight_gray >= 0.0 && c.highlight_gray <= 255.0, "sim camera",
          "ball_gray and highlight_gray must be in [0, 255]");
  check_input(c.ball_limb_darkening >= 0.0 && c.ball_limb_darkening <= 1.0, "sim camera", "ball_limb_darkening must be in [0, 1]");
  check_input(std::isfinite(c.highlight_sigma) && c.highlight_sigma > 0.0, "sim camera", "highlight_sigma must be > 0");
  check_input(c.lamps >= 0 && c.lamp_delta_gray >= 0.0 && c.lamp_delta_gray <= 255.0, "sim camera", "lamps must be >= 0, lamp_delta_gray in [0, 255]");
  check_input(c.lamp_toggle_probability >= 0.0 && c.lamp_toggle_probability <= 1.0, "sim camera",
          "lamp_toggle_probability must be in [0, 1]");
  check_input(c.glare.toggle_probability >= 0.0 && c.glare.toggle_probability <= 1.0 && c.glare.sigma_m > 0.0 &&
              c.glare.peak_gray >= 0.0 && c.glare.peak_gray <= 255.0, "sim camera",
          "glare needs sigma_m > 0, peak_gray in [0, 255], toggle_probability in [0, 1]");
  check_input(std::isfinite(c.noise_sigma) && c.noise_sigma >= 0.0 && c.noise_sigma <= 40.0, "sim camera",
          "noise_sigma must be in [0, 40]");
  for (const SimPlastic& p : c.plastics) {
    check_input(p.polygon_board.size() >= 3 && p.opacity >= 0.0 && p.opacity <= 1.0 && p.gray >= 0.0 && p.gray <= 255.0, "sim camera",
            "a plastic needs >= 3 vertices, opacity in [0, 1] and gray in [0, 255]");
  }
  check_input(c.flipper_gray >= 0.0 && c.flipper_gray <= 255.0 && c.flipper_width_m > 0.0, "sim camera",
          "flipper_gray must be in [0, 255] and flipper_width_m > 0");
  check_input(c.marker_radius_m > 0.0 && c.marker_ring_m >= c.marker_radius_m && c.marker_gray >= 0.0 &&
              c.marker_gray <= 255.0 && c.marker_ring_gray >= 0.0 && c.marker_ring_gray <= 255.0, "sim camera",
          "markers need 0 < marker_radius_m <= marker_ring_m and grays in [0, 255]");
  for (const table::Flipper& f : board.flippers) flipper_theta_.push_back(f.theta_min_rad);
  period_s_ = 1.0 / c.fps;
  next_exposure_s_ = c.first_exposure_s;
  build_floor();
  build_lamps();
  build_plastics();
  build_glare();
  build_noise();
}

std::string SimCameraSource::describe() const {
  std::ostringstream s;
  s << "simulated camera " << config_.width_px << "x" << config_.height_px << " at " << config_.fps << " fps, exposure "
    << config_.exposure_s * 1e3 << " ms, seed " << config_.seed;
  return s.str();
}

void SimCameraSource::build_floor() {
  const cv::Size size(config_.width_px, config_.height_px);
  sim::RenderOptions ro;
  ro.px_per_m = homography_.px_per_m_at(Vec2{0.5 * board_.width_m, 0.5 * board_.height_m}) * config_.supersample;
  ro.margin_px = 12 * config_.supersample;
  ro.draw_hud = false;
  // Flippers move: they are drawn per frame at their angle, not into the floor.
  table::Board without_flippers = board_;
  without_flippers.flippers.clear();
  const cv::Mat drawing = sim::render_board(without_flippers, nullptr, ro);
  cv::Mat gray;
  cv::cvtColor(drawing, gray, cv::COLOR_BGR2GRAY);

  // Playfield art: random shapes on the bare playfield only, under the obstacles.
  const std::uint8_t field = playfield_gray();
  cv::Mat art_mask;
  cv::compare(gray, cv::Scalar(field), art_mask, cv::CMP_EQ);
  cv::Mat art = gray.clone();
  const cv::Matx33d r_from_b = render_from_board(board_, ro);
  auto to_render = [&](const Vec2& p) {
    const cv::Vec3d q = r_from_b * cv::Vec3d(p.x(), p.y(), 1.0);
    return cv::Point(static_cast<int>(std::lround(q[0])), static_cast<int>(std::lround(q[1])));
  };
  for (int i = 0; i < config_.clutter_shapes; ++i) {
    const Vec2 p{rng_.uniform(0.0, board_.width_m), rng_.uniform(0.0, board_.height_m)};
    const double size_m = rng_.uniform(0.01, 0.06);
    const double value = std::clamp(field + rng_.uniform(-1.0, 1.0) * config_.clutter_contrast, 0.0, 255.0);
    const int kind = static_cast<int>(rng_.next_u64() % 3);
    const int px = std::max(1, static_cast<int>(std::lround(size_m * ro.px_per_m)));
    if (kind == 0) {
      cv::circle(art, to_render(p), px, cv::Scalar(value), cv::FILLED, cv::LINE_AA);
    } else if (kind == 1) {
      const Vec2 q = p + Vec2{rng_.uniform(-1.0, 1.0), rng_.uniform(-1.0, 1.0)} * size_m;
      cv::rectangle(art, to_render(p), to_render(q), cv::Scalar(value), cv::FILLED, cv::LINE_AA);
    } else {
      const Vec2 q = p + Vec2{rng_.uniform(-1.0, 1.0), rng_.uniform(-1.0, 1.0)} * 2.0 * size_m;
      cv::line(art, to_render(p), to_render(q), cv::Scalar(value), std::max(1, px / 6), cv::LINE_AA);
    }
  }
  art.copyTo(gray, art_mask);
  gray.convertTo(gray, CV_8U, config_.floor_gain, config_.floor_offset);
  if (config_.supersample > 1) cv::GaussianBlur(gray, gray, cv::Size(0, 0), 0.45 * config_.supersample);

  const cv::Matx33d image_from_render = homography_.image_from_board_matrix() * r_from_b.inv();
  const double outside = std::clamp(18.0 * config_.floor_gain + config_.floor_offset, 0.0, 255.0);
  cv::warpPerspective(gray, floor_, cv::Mat(image_from_render), size, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
                      cv::Scalar(outside));
}

void SimCameraSource::build_lamps() {
  const cv::Size size(config_.width_px, config_.height_px);
  for (int i = 0; i < config_.lamps; ++i) {
    const Vec2 c{rng_.uniform(0.06, board_.width_m - 0.06), rng_.uniform(0.15, board_.height_m - 0.06)};
    std::vector<Vec2> outline;
    if (i % 2 == 0) {  // a small round lamp, 6 mm radius
      for (int k = 0; k < 16; ++k) {
        const double a = 2.0 * std::numbers::pi * k / 16.0;
        outline.push_back(c + 0.006 * Vec2{std::cos(a), std::sin(a)});
      }
    } else {  // an arrow insert, 46 x 13 mm, pointing anywhere
      const double a = rng_.uniform(0.0, 2.0 * std::numbers::pi);
      const Vec2 d{std::cos(a), std::sin(a)};
      const Vec2 n{-d.y(), d.x()};
      outline = {c - 0.023 * d - 0.0065 * n, c + 0.013 * d - 0.0065 * n, c + 0.023 * d, c + 0.013 * d + 0.0065 * n,
                 c - 0.023 * d + 0.0065 * n};
    }
    std::vector<cv::Point2d> uv;
    for (const Vec2& p : outline) uv.push_back(homography_.image_from_board(p));
    Patch lamp;
    polygon_patch(uv, config_.lamp_delta_gray, size, lamp.roi, lamp.values);
    if (lamp.roi.area() == 0) continue;
    // Unlit, an insert is a little brighter than the playfield around it.
    cv::Mat unlit;
    lamp.values.convertTo(unlit, CV_8U, 0.15);
    cv::Mat target = floor_(lamp.roi);
    cv::add(target, unlit, target);
    lamps_.push_back(lamp);
    lamp_on_.push_back(static_cast<std::uint8_t>(rng_.uniform01() < 0.5 ? 1 : 0));
  }
}

void SimCameraSource::build_plastics() {
  const cv::Size size(config_.width_px, config_.height_px);
  occluder_mask_ = cv::Mat::zeros(size, CV_8U);
  for (const SimPlastic& p : config_.plastics) {
    std::vector<cv::Point2d> uv;
    for (const Vec2& q : p.polygon_board) uv.push_back(homography_.image_from_board(q));
    Patch plastic;
    polygon_patch(uv, 255.0 * p.opacity, size, plastic.roi, plastic.values);
    if (plastic.roi.area() == 0) continue;
    cv::Mat mask = occluder_mask_(plastic.roi);
    cv::Mat covered;
    cv::threshold(plastic.values, covered, 0, 255, cv::THRESH_BINARY);
    cv::max(mask, covered, mask);
    plastics_.push_back(plastic);
    plastic_gray_.push_back(p.gray);
  }
}

void SimCameraSource::build_glare() {
  const SimGlare& g = config_.glare;
  if (!g.enabled) return;
  const cv::Size size(config_.width_px, config_.height_px);
  const cv::Point2d c = homography_.image_from_board(g.centre_board);
  const double reach_px = 3.0 * g.sigma_m * homography_.px_per_m_at(g.centre_board) * 1.2;
  const cv::Rect box(cv::Point(static_cast<int>(std::floor(c.x - reach_px)), static_cast<int>(std::floor(c.y - reach_px))),
                     cv::Point(static_cast<int>(std::ceil(c.x + reach_px)) + 1,
                               static_cast<int>(std::ceil(c.y + reach_px)) + 1));
  glare_.roi = box & cv::Rect(0, 0, size.width, size.height);
  if (glare_.roi.area() == 0) return;
  glare_.values = cv::Mat::zeros(glare_.roi.size(), CV_8U);
  for (int v = 0; v < glare_.roi.height; ++v) {
    auto* row = glare_.values.ptr<std::uint8_t>(v);
    for (int u = 0; u < glare_.roi.width; ++u) {
      const Vec2 q = homography_.board_from_image(cv::Point2d(glare_.roi.x + u, glare_.roi.y + v));
      const double r2 = (q - g.centre_board).squaredNorm() / (g.sigma_m * g.sigma_m);
      row[u] = cv::saturate_cast<std::uint8_t>(g.peak_gray * std::exp(-0.5 * r2));
    }
  }
  glare_ready_ = true;
  glare_on_ = true;
}

void SimCameraSource::build_noise() {
  if (!(config_.noise_sigma > 0.0)) return;
  const std::size_t pixels = static_cast<std::size_t>(config_.width_px) * static_cast<std::size_t>(config_.height_px);
  noise_span_ = static_cast<std::size_t>(config_.width_px) * 97 + 13;
  noise_pos_.assign(pixels + noise_span_, 0);
  noise_neg_.assign(pixels + noise_span_, 0);
  for (std::size_t i = 0; i < noise_pos_.size(); ++i) {
    const double n = std::clamp(std::round(config_.noise_sigma * rng_.normal()), -127.0, 127.0);
    if (n > 0) noise_pos_[i] = static_cast<std::uint8_t>(n);
    if (n < 0) noise_neg_[i] = static_cast<std::uint8_t>(-n);
  }
}

void SimCameraSource::observe(const sim::GameState& state) {
  for (std::size_t i = 0; i < flipper_theta_.size() && i < state.flippers.size(); ++i) {
    flipper_theta_[i] = state.flippers[i].theta_rad;
  }
  // A ball that hops is nearer the lens: seen from above the playfield's
  // centre it moves out along the line from the centre and grows.
  const double lens_above_ball = config_.lens_height_m - board_.ball.radius_m;
  ball_scale_ = lens_above_ball / std::max(lens_above_ball - state.ball.height_m, 0.05 * lens_above_ball);
  const Vec2 centre(0.5 * board_.width_m, 0.5 * board_.height_m);
  observe_ball(state.time_s, centre + ball_scale_ * (state.ball.position_m - centre), state.ball_in_play);
}

void SimCameraSource::draw_flippers(cv::Mat& image) const {
  // Sub-pixel end points (shift 4: 1/16 px), so a flipper's image moves
  // smoothly with its angle as a real one does; calibration measures its tip.
  constexpr int kShift = 4;
  constexpr double kScale = 1 << kShift;
  const auto fixed = [&](const cv::Point2d& p) {
    return cv::Point(static_cast<int>(std::lround(p.x * kScale)), static_cast<int>(std::lround(p.y * kScale)));
  };
  for (std::size_t i = 0; i < flipper_theta_.size(); ++i) {
    const table::Flipper& f = board_.flippers[i];
    const cv::Point2d a = homography_.image_from_board(f.pivot);
    const cv::Point2d b = homography_.image_from_board(table::flipper_tip(f, flipper_theta_[i]));
    const int width_px = std::max(1, static_cast<int>(std::lround(config_.flipper_width_m * homography_.px_per_m_at(f.pivot))));
    cv::line(image, fixed(a), fixed(b), cv::Scalar(config_.flipper_gray), width_px, cv::LINE_AA, kShift);
  }
}

void SimCameraSource::set_flipper_angles(std::span<const double> theta_rad) {
  for (std::size_t i = 0; i < flipper_theta_.size() && i < theta_rad.size(); ++i) flipper_theta_[i] = theta_rad[i];
}

void SimCameraSource::set_markers(std::span<const Vec2> centres_board) {
  markers_.clear();
  marker_gray_.clear();
  const cv::Size size(config_.width_px, config_.height_px);
  for (const Vec2& c : centres_board) {
    for (const auto& [radius, gray] : {std::pair{config_.marker_ring_m, config_.marker_ring_gray},
                                       std::pair{config_.marker_radius_m, config_.marker_gray}}) {
      std::vector<cv::Point2d> uv;
      for (int k = 0; k < 64; ++k) {
        const double a = 2.0 * std::numbers::pi * k / 64.0;
        uv.push_back(homography_.image_from_board(c + radius * Vec2{std::cos(a), std::sin(a)}));
      }
      Patch disc;
      polygon_patch(uv, 255.0, size, disc.roi, disc.values);
      if (disc.roi.area() == 0) continue;
      markers_.push_back(disc);
      marker_gray_.push_back(gray);
    }
  }
}

void SimCameraSource::observe_ball(double t_s, const Vec2& p_board, bool in_play) {
  if (history_size_ > 0) {
    const Sample& newest = history_[(history_head_ + history_size_ - 1) % kHistory];
    if (!(t_s > newest.t_s)) return;  // time must increase; a repeated time adds nothing
  }
  const Sample s{t_s, p_board, in_play};
  if (history_size_ < kHistory) {
    history_[(history_head_ + history_size_) % kHistory] = s;
    ++history_size_;
  } else {
    history_[history_head_] = s;
    history_head_ = (history_head_ + 1) % kHistory;
  }
}

void SimCameraSource::reset(double t_s) {
  history_size_ = 0;
  history_head_ = 0;
  next_exposure_s_ = t_s;
}

bool SimCameraSource::sample_at(double t_s, Vec2& p, bool& in_play) const {
  if (history_size_ == 0) return false;
  auto at = [&](std::size_t i) -> const Sample& { return history_[(history_head_ + i) % kHistory]; };
  if (t_s <= at(0).t_s) {
    p = at(0).p;
    in_play = at(0).in_play;
    return true;
  }
  std::size_t lo = 0;
  std::size_t hi = history_size_ - 1;
  if (t_s >= at(hi).t_s) {
    p = at(hi).p;
    in_play = at(hi).in_play;
    return true;
  }
  while (hi - lo > 1) {  // at(lo).t < t <= at(hi).t
    const std::size_t mid = (lo + hi) / 2;
    if (at(mid).t_s < t_s) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  const Sample& a = at(lo);
  const Sample& b = at(hi);
  in_play = b.in_play;
  if (a.in_play && b.in_play) {
    const double f = (t_s - a.t_s) / (b.t_s - a.t_s);
    p = a.p + f * (b.p - a.p);
  } else {
    p = b.p;
  }
  return true;
}

bool SimCameraSource::read(vision::Frame& out) {
  if (history_size_ == 0) return false;
  const double newest = history_[(history_head_ + history_size_ - 1) % kHistory].t_s;
  const double oldest = history_[history_head_].t_s;
  while (true) {
    const double start = next_exposure_s_;
    const double end = start + config_.exposure_s;
    if (newest < end) return false;
    if (start < oldest && history_size_ == kHistory) {  // its exposure left the history: lost
      ++counters_.dropped;
      ++sequence_;
      next_exposure_s_ += period_s_;
      continue;
    }
    // Path samples at the middles of n equal slices of the exposure.
    Vec2 p0, p1;
    bool in0 = false, in1 = false;
    sample_at(start, p0, in0);
    sample_at(end, p1, in1);
    const double blur_px = cv::norm(homography_.image_from_board(p1) - homography_.image_from_board(p0));
    const int n = std::clamp(static_cast<int>(std::ceil(blur_px / 0.25)) + 1, 2, static_cast<int>(kMaxPath));
    std::size_t present = 0;
    for (int k = 0; k < n; ++k) {
      Vec2 p;
      bool in_play = false;
      sample_at(start + (k + 0.5) / n * config_.exposure_s, p, in_play);
      if (in_play) path_[present++] = p;
    }
    const double t_mid = start + 0.5 * config_.exposure_s;
    compose(std::span<const Vec2>(path_.data(), present), n, t_mid, out);
    Vec2 p_mid;
    bool in_mid = false;
    sample_at(t_mid, p_mid, in_mid);
    truth_.p_board_mid = p_mid;
    truth_.uv_px_mid = homography_.image_from_board(p_mid);
    out.driver_t_s = start;
    next_exposure_s_ += period_s_;
    return true;
  }
}

void SimCameraSource::render(std::span<const Vec2> path_board, double t_mid_s, vision::Frame& out) {
  const std::size_t n = std::min(path_board.size(), kMaxPath);
  compose(path_board.first(n), static_cast<int>(n), t_mid_s, out);
  if (n > 0) {
    Vec2 mean = Vec2::Zero();
    for (std::size_t i = 0; i < n; ++i) mean += path_board[i];
    truth_.p_board_mid = mean / static_cast<double>(n);
    truth_.uv_px_mid = homography_.image_from_board(truth_.p_board_mid);
  }
  out.driver_t_s = t_mid_s - 0.5 * config_.exposure_s;
}

// Paints `gray` over `image` inside the patch, the patch's values being the opacity (255: opaque).
void SimCameraSource::blend(const Patch& p, double gray, cv::Mat& image) {
  for (int v = 0; v < p.roi.height; ++v) {
    auto* row = image.ptr<std::uint8_t>(p.roi.y + v) + p.roi.x;
    const auto* alpha = p.values.ptr<std::uint8_t>(v);
    for (int u = 0; u < p.roi.width; ++u) {
      if (alpha[u] == 0) continue;
      const double a = alpha[u] / 255.0;
      row[u] = cv::saturate_cast<std::uint8_t>(row[u] + a * (gray - row[u]));
    }
  }
}

void SimCameraSource::advance_effects() {
  if (lamps_blinking_ && config_.lamp_toggle_probability > 0.0) {
    for (std::uint8_t& on : lamp_on_) {
      if (rng_.uniform01() < config_.lamp_toggle_probability) on = static_cast<std::uint8_t>(on ^ 1U);
    }
  }
  if (glare_ready_ && config_.glare.toggle_probability > 0.0 && rng_.uniform01() < config_.glare.toggle_probability) {
    glare_on_ = !glare_on_;
  }
}

void SimCameraSource::compose(std::span<const Vec2> path_board, int path_total, double t_mid_s, vision::Frame& out) {
  advance_effects();
  floor_.copyTo(out.gray);  // reuses out.gray's buffer when it already has this size
  cv::Mat& image = out.gray;
  truth_ = FrameTruth{};
  for (std::size_t i = 0; i < lamps_.size(); ++i) {
    if (lamp_on_[i] == 0) continue;
    cv::Mat target = image(lamps_[i].roi);
    cv::add(target, lamps_[i].values, target);
    ++truth_.lamps_lit;
  }
  draw_flippers(image);
  truth_.ball_present = !path_board.empty();
  truth_.ball_whole_exposure = !path_board.empty() && static_cast<int>(path_board.size()) == path_total;
  if (!path_board.empty()) draw_ball(path_board, path_total, image);
  for (std::size_t i = 0; i < plastics_.size(); ++i) blend(plastics_[i], plastic_gray_[i], image);
  for (std::size_t i = 0; i < markers_.size(); ++i) blend(markers_[i], marker_gray_[i], image);
  truth_.glare_on = glare_ready_ && glare_on_;
  if (truth_.glare_on) {
    cv::Mat target = image(glare_.roi);
    cv::add(target, glare_.values, target);
    if (truth_.ball_present) {
      const double reach = 3.0 * config_.glare.sigma_m + board_.ball.radius_m;
      for (const Vec2& p : path_board) {
        if ((p - config_.glare.centre_board).norm() < reach) truth_.in_glare = true;
      }
    }
  }
  if (noise_span_ > 0) {
    const std::size_t offset = static_cast<std::size_t>(rng_.next_u64() % noise_span_);
    const cv::Mat pos(image.rows, image.cols, CV_8U, noise_pos_.data() + offset);
    const cv::Mat neg(image.rows, image.cols, CV_8U, noise_neg_.data() + offset);
    cv::add(image, pos, image);
    cv::subtract(image, neg, image);
  }
  out.t_s = t_mid_s;
  out.sequence = sequence_++;
  ++counters_.frames;
}

void SimCameraSource::draw_ball(std::span<const Vec2> path_board, int path_total, cv::Mat& image) {
  const double r_m = board_.ball.radius_m * ball_scale_;
  // Image-space box around every path position.
  double u0 = 1e300, v0 = 1e300, u1 = -1e300, v1 = -1e300, r_px = 0.0;
  for (const Vec2& p : path_board) {
    const cv::Point2d c = homography_.image_from_board(p);
    const double r = r_m * homography_.px_per_m_at(p);
    r_px = std::max(r_px, r);
    u0 = std::min(u0, c.x - r);
    v0 = std::min(v0, c.y - r);
    u1 = std::max(u1, c.x + r);
    v1 = std::max(v1, c.y + r);
  }
  truth_.blur_px = cv::norm(homography_.image_from_board(path_board.back()) -
                            homography_.image_from_board(path_board.front()));
  const cv::Rect box = cv::Rect(cv::Point(static_cast<int>(std::floor(u0)) - 2, static_cast<int>(std::floor(v0)) - 2),
                                cv::Point(static_cast<int>(std::ceil(u1)) + 3, static_cast<int>(std::ceil(v1)) + 3)) &
                       cv::Rect(0, 0, image.cols, image.rows);
  const Vec2 mid = path_board[path_board.size() / 2];
  const double scale = homography_.px_per_m_at(mid);  // px per m, for the edge's anti-aliasing width
  truth_.radius_px = r_m * scale;
  const SimCameraConfig& c = config_;
  const Vec2 highlight = c.highlight_offset * r_m;
  const double inv_2s2 = 1.0 / (2.0 * c.highlight_sigma * c.highlight_sigma * r_m * r_m);
  const double rim_gray = c.ball_gray * (1.0 - c.ball_limb_darkening);
  const double inv_n = 1.0 / path_total;
  double covered = 0.0;
  double hidden = 0.0;
  for (int v = box.y; v < box.y + box.height; ++v) {
    auto* row = image.ptr<std::uint8_t>(v);
    const auto* occluded = occluder_mask_.ptr<std::uint8_t>(v);
    for (int u = box.x; u < box.x + box.width; ++u) {
      const Vec2 q = homography_.board_from_image(cv::Point2d(u, v));
      const double under = row[u];
      double acc = 0.0;
      double coverage = 0.0;
      for (const Vec2& p : path_board) {
        const Vec2 d = q - p;
        const double dist_m = d.norm();
        const double cov = std::clamp(r_m * scale - dist_m * scale + 0.5, 0.0, 1.0);
        if (cov <= 0.0) continue;
        double gray = rim_gray;
        const double rho2 = dist_m * dist_m / (r_m * r_m);
        if (rho2 < 1.0) {
          gray = c.ball_gray * (1.0 - c.ball_limb_darkening * (1.0 - std::sqrt(1.0 - rho2)));
          gray += (c.highlight_gray - gray) * std::exp(-(d - highlight).squaredNorm() * inv_2s2);
        }
        acc += cov * (gray - under);
        coverage += cov;
      }
      if (coverage <= 0.0) continue;
      row[u] = cv::saturate_cast<std::uint8_t>(under + acc * inv_n);
      covered += coverage;
      if (occluded[u] != 0) hidden += coverage;
    }
  }
  truth_.occluded_fraction = covered > 0.0 ? hidden / covered : 0.0;
}

}  // namespace pinball::simlab
