#include "pinball/simlab/sim_camera_source.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include <opencv2/calib3d.hpp>
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
// `convex`: fillConvexPoly; a convex outline seen through a lens may bend in, so fillPoly.
void polygon_patch(const std::vector<cv::Point2d>& uv_px, double value, cv::Size size, cv::Rect& roi, cv::Mat& patch,
                   bool convex) {
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
  if (convex) {
    cv::fillConvexPoly(patch, fixed, cv::Scalar(value), cv::LINE_AA, 4);
  } else {
    const std::vector<std::vector<cv::Point>> polygons{fixed};
    cv::fillPoly(patch, polygons, cv::Scalar(value), cv::LINE_AA, 4);
  }
  if (roi.area() == 0) return;
  patch = patch(cv::Rect(roi.x - box.x, roi.y - box.y, roi.width, roi.height)).clone();
}

}  // namespace

SimCameraRealism SimCameraRealism::typical(int width_px, int height_px) {
  SimCameraRealism r;
  r.lens = vision::typical_wide_lens(width_px, height_px);
  // A CMOS sensor read out row by row in about 4.8 ms (480 rows), inside the 5 ms frame period at 200 fps.
  r.row_time_s = 4.8e-3 / height_px;
  // The sensor's own crystal-clocked frame timing: a few microseconds.
  r.frame_jitter_s = 5e-6;
  // Row 0's mid-exposure to the host's stamp: the rest of the readout (~4 ms), USB3 transfer of
  // 300 kB and the driver's hand-over (~2 ms), then the host's wake-up (exponential, mean 1 ms).
  r.latency_min_s = 0.007;
  r.latency_jitter_mean_s = 0.001;
  // Incandescent general illumination on 50 Hz mains: ±8 % at 100 Hz, less than a lamp's own
  // swing because the room's light is mixed in.
  r.flicker_hz = 100.0;
  r.flicker_amplitude = 0.08;
  // Auto-exposure off, but the sensor warms and the room light changes: 2 % over tens of seconds.
  r.gain_drift_sigma = 0.02;
  r.gain_drift_time_s = 30.0;
  return r;
}

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
  const SimCameraRealism& r = c.realism;
  if (r.lens) {
    check_input(vision::check_intrinsics(*r.lens), "sim camera lens");
    check_input(r.lens->width_px == c.width_px && r.lens->height_px == c.height_px, "sim camera",
                "the lens's image size must be the camera's");
  }
  check_input(std::isfinite(r.row_time_s) && r.row_time_s >= 0.0 && r.row_time_s * c.height_px <= 1.0 / c.fps,
              "sim camera", "row_time_s must be >= 0 and read the frame out within one frame period");
  check_input(std::isfinite(r.frame_jitter_s) && r.frame_jitter_s >= 0.0 && r.frame_jitter_s <= 0.1 / c.fps,
              "sim camera", "frame_jitter_s must be in [0, a tenth of the frame period]");
  check_input(std::isfinite(r.latency_min_s) && r.latency_min_s >= 0.0 && r.latency_min_s <= 1.0 &&
                  std::isfinite(r.latency_jitter_mean_s) && r.latency_jitter_mean_s >= 0.0 &&
                  r.latency_jitter_mean_s <= 1.0,
              "sim camera", "latency_min_s and latency_jitter_mean_s must be in [0, 1] s");
  check_input(std::isfinite(r.flicker_hz) && r.flicker_hz > 0.0 && r.flicker_amplitude >= 0.0 &&
                  r.flicker_amplitude < 1.0,
              "sim camera", "flicker_hz must be > 0 and flicker_amplitude in [0, 1)");
  check_input(std::isfinite(r.gain_drift_sigma) && r.gain_drift_sigma >= 0.0 && r.gain_drift_sigma <= 0.5 &&
                  std::isfinite(r.gain_drift_time_s) && r.gain_drift_time_s > 0.0,
              "sim camera", "gain_drift_sigma must be in [0, 0.5] and gain_drift_time_s > 0");
  for (const table::Flipper& f : board.flippers) flipper_theta_.push_back(f.theta_min_rad);
  flipper_history_.assign(kHistory * flipper_theta_.size(), 0.0);
  period_s_ = 1.0 / c.fps;
  // Its own stream: switching realism on leaves the scene, lamps and noise as they were.
  timing_rng_ = Rng(c.seed ^ 0x5DEECE66DULL);
  if (r.flicker_amplitude > 0.0) flicker_phase_rad_ = timing_rng_.uniform(0.0, 2.0 * std::numbers::pi);
  schedule_next_frame(c.first_exposure_s);
  if (r.lens) build_lens_map();
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
  const SimCameraRealism& r = config_.realism;
  if (r.lens) s << ", lens k1 " << r.lens->k1 << " k2 " << r.lens->k2;
  if (r.row_time_s > 0.0) s << ", rolling shutter " << r.row_time_s * 1e6 << " us/row";
  if (r.latency_mean_s() > 0.0) s << ", latency " << r.latency_mean_s() * 1e3 << " ms";
  if (r.flicker_amplitude > 0.0) s << ", flicker " << r.flicker_amplitude * 100.0 << " % at " << r.flicker_hz << " Hz";
  if (r.gain_drift_sigma > 0.0) s << ", gain drift " << r.gain_drift_sigma * 100.0 << " %";
  return s.str();
}

cv::Point2d SimCameraSource::image_from_board(const Vec2& p_board) const {
  const cv::Point2d ideal = homography_.image_from_board(p_board);
  return config_.realism.lens ? vision::distort_pixel(*config_.realism.lens, ideal) : ideal;
}

Vec2 SimCameraSource::board_at_pixel(int u, int v) const {
  if (ideal_map_.empty()) return homography_.board_from_image(cv::Point2d(u, v));
  const cv::Vec2f ideal = ideal_map_.at<cv::Vec2f>(v, u);
  return homography_.board_from_image(cv::Point2d(ideal[0], ideal[1]));
}

void SimCameraSource::build_lens_map() {
  const vision::CameraIntrinsics& lens = *config_.realism.lens;
  std::vector<cv::Point2d> pixels;
  pixels.reserve(static_cast<std::size_t>(config_.width_px) * static_cast<std::size_t>(config_.height_px));
  for (int v = 0; v < config_.height_px; ++v) {
    for (int u = 0; u < config_.width_px; ++u) pixels.emplace_back(u, v);
  }
  std::vector<cv::Point2d> ideal;
  const cv::Matx33d k = vision::camera_matrix(lens);
  cv::undistortPoints(pixels, ideal, k, vision::distortion_coefficients(lens), cv::noArray(), k,
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 50, 1e-6));
  ideal_map_.create(config_.height_px, config_.width_px, CV_32FC2);
  for (int v = 0; v < config_.height_px; ++v) {
    auto* row = ideal_map_.ptr<cv::Vec2f>(v);
    for (int u = 0; u < config_.width_px; ++u) {
      const cv::Point2d& q = ideal[static_cast<std::size_t>(v) * static_cast<std::size_t>(config_.width_px) +
                                   static_cast<std::size_t>(u)];
      row[u] = cv::Vec2f(static_cast<float>(q.x), static_cast<float>(q.y));
    }
  }
}

void SimCameraSource::schedule_next_frame(double nominal_start_s) {
  const SimCameraRealism& r = config_.realism;
  next_nominal_s_ = nominal_start_s;
  next_start_s_ = nominal_start_s + (r.frame_jitter_s > 0.0 ? r.frame_jitter_s * timing_rng_.normal() : 0.0);
  next_latency_s_ = r.latency_min_s;
  if (r.latency_jitter_mean_s > 0.0) next_latency_s_ -= r.latency_jitter_mean_s * std::log1p(-timing_rng_.uniform01());
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

  const double outside = std::clamp(18.0 * config_.floor_gain + config_.floor_offset, 0.0, 255.0);
  if (ideal_map_.empty()) {
    const cv::Matx33d image_from_render = homography_.image_from_board_matrix() * r_from_b.inv();
    cv::warpPerspective(gray, floor_, cv::Mat(image_from_render), size, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
                        cv::Scalar(outside));
    return;
  }
  // Through the lens: each frame pixel samples the drawing where its ideal pixel's board point lies.
  cv::Mat map(size, CV_32FC2);
  for (int v = 0; v < size.height; ++v) {
    auto* row = map.ptr<cv::Vec2f>(v);
    for (int u = 0; u < size.width; ++u) {
      const Vec2 b = board_at_pixel(u, v);
      const cv::Vec3d q = r_from_b * cv::Vec3d(b.x(), b.y(), 1.0);
      row[u] = cv::Vec2f(static_cast<float>(q[0] / q[2]), static_cast<float>(q[1] / q[2]));
    }
  }
  cv::remap(gray, floor_, map, cv::noArray(), cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(outside));
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
    for (const Vec2& p : outline) uv.push_back(image_from_board(p));
    Patch lamp;
    polygon_patch(uv, config_.lamp_delta_gray, size, lamp.roi, lamp.values, !config_.realism.lens);
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
    // Each edge in pieces, so that a lens bends it.
    std::vector<cv::Point2d> uv;
    const std::size_t corners = p.polygon_board.size();
    for (std::size_t i = 0; i < corners; ++i) {
      const Vec2& a = p.polygon_board[i];
      const Vec2& b = p.polygon_board[(i + 1) % corners];
      for (int k = 0; k < 8; ++k) uv.push_back(image_from_board(a + (k / 8.0) * (b - a)));
    }
    Patch plastic;
    polygon_patch(uv, 255.0 * p.opacity, size, plastic.roi, plastic.values, !config_.realism.lens);
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
  const cv::Point2d c = image_from_board(g.centre_board);
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
      const Vec2 q = board_at_pixel(glare_.roi.x + u, glare_.roi.y + v);
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
    const cv::Point2d a = image_from_board(f.pivot);
    const cv::Point2d b = image_from_board(table::flipper_tip(f, flipper_theta_[i]));
    const int width_px = std::max(1, static_cast<int>(std::lround(config_.flipper_width_m * homography_.px_per_m_at(f.pivot))));
    cv::line(image, fixed(a), fixed(b), cv::Scalar(config_.flipper_gray), width_px, cv::LINE_AA, kShift);
  }
}

void SimCameraSource::draw_flippers_exposed(double start_s, cv::Mat& image) {
  constexpr int kShift = 4;
  constexpr double kScale = 1 << kShift;
  constexpr int kCoarse = 17;     // instants that find where the flipper is during the frame
  constexpr int kMaxInstants = 96;
  const double row_time = config_.realism.row_time_s;
  const double exposure = config_.exposure_s;
  const cv::Rect frame_rect(0, 0, image.cols, image.rows);
  for (std::size_t i = 0; i < flipper_theta_.size(); ++i) {
    const table::Flipper& f = board_.flippers[i];
    const cv::Point2d pivot = image_from_board(f.pivot);
    const int width_px = std::max(1, static_cast<int>(std::lround(config_.flipper_width_m * homography_.px_per_m_at(f.pivot))));
    // Coarse pass over the whole frame's exposure: does it move, and which rows can it cover?
    const double frame_span = (image.rows - 1) * row_time + exposure;
    double lo_rad = 1e300, hi_rad = -1e300;
    double u0 = pivot.x, u1 = pivot.x, v0 = pivot.y, v1 = pivot.y;
    for (int k = 0; k < kCoarse; ++k) {
      const double theta = flipper_angle_at(i, start_s + frame_span * k / (kCoarse - 1));
      lo_rad = std::min(lo_rad, theta);
      hi_rad = std::max(hi_rad, theta);
      const cv::Point2d tip = image_from_board(table::flipper_tip(f, theta));
      u0 = std::min(u0, tip.x);
      u1 = std::max(u1, tip.x);
      v0 = std::min(v0, tip.y);
      v1 = std::max(v1, tip.y);
    }
    if (hi_rad == lo_rad || frame_span <= 0.0) {  // still during the frame: one sharp drawing
      const cv::Point2d tip = image_from_board(table::flipper_tip(f, lo_rad));
      cv::line(image, cv::Point(static_cast<int>(std::lround(pivot.x * kScale)), static_cast<int>(std::lround(pivot.y * kScale))),
               cv::Point(static_cast<int>(std::lround(tip.x * kScale)), static_cast<int>(std::lround(tip.y * kScale))),
               cv::Scalar(config_.flipper_gray), width_px, cv::LINE_AA, kShift);
      continue;
    }
    const int reach = width_px + 3;
    const cv::Rect box = cv::Rect(cv::Point(static_cast<int>(std::floor(u0)) - reach, static_cast<int>(std::floor(v0)) - reach),
                                  cv::Point(static_cast<int>(std::ceil(u1)) + reach + 1,
                                            static_cast<int>(std::ceil(v1)) + reach + 1)) &
                         frame_rect;
    if (box.area() == 0) continue;
    // Instants evenly over the exposures of the box's rows, fine enough that
    // the tip moves about a quarter pixel from one to the next.
    const double t_first = start_s + box.y * row_time;
    const double span = (box.height - 1) * row_time + exposure;
    const double sweep_px = (hi_rad - lo_rad) * f.length_m * homography_.px_per_m_at(f.pivot);
    const int instants = std::clamp(static_cast<int>(std::ceil(sweep_px / 0.25)) + 2, 2, kMaxInstants);
    const double step = span / (instants - 1);
    flipper_instant_.resize(static_cast<std::size_t>(instants));
    for (int j = 0; j < instants; ++j) flipper_instant_[static_cast<std::size_t>(j)] = flipper_angle_at(i, t_first + j * step);
    // Row r of the box averages the instants inside its own exposure (the nearest one when it has none).
    flipper_sum_.create(box.size(), CV_16U);
    flipper_sum_.setTo(0);
    flipper_sample_.create(box.size(), CV_8U);
    flipper_row_count_.assign(static_cast<std::size_t>(box.height), 0);
    const auto first_instant = [&](int r) {
      return std::clamp(static_cast<int>(std::ceil((r * row_time) / step - 1e-9)), 0, instants - 1);
    };
    const auto last_instant = [&](int r) {
      const int j = std::clamp(static_cast<int>(std::floor((r * row_time + exposure) / step + 1e-9)), 0, instants - 1);
      return std::max(j, first_instant(r));
    };
    for (int j = 0; j < instants; ++j) {
      flipper_sample_.setTo(0);
      const cv::Point2d tip = image_from_board(table::flipper_tip(f, flipper_instant_[static_cast<std::size_t>(j)]));
      const auto fixed = [&](const cv::Point2d& p) {
        return cv::Point(static_cast<int>(std::lround((p.x - box.x) * kScale)), static_cast<int>(std::lround((p.y - box.y) * kScale)));
      };
      cv::line(flipper_sample_, fixed(pivot), fixed(tip), cv::Scalar(255), width_px, cv::LINE_AA, kShift);
      for (int r = 0; r < box.height; ++r) {
        if (j < first_instant(r) || j > last_instant(r)) continue;
        const auto* from = flipper_sample_.ptr<std::uint8_t>(r);
        auto* to = flipper_sum_.ptr<std::uint16_t>(r);
        for (int u = 0; u < box.width; ++u) to[u] = static_cast<std::uint16_t>(to[u] + from[u]);
        ++flipper_row_count_[static_cast<std::size_t>(r)];
      }
    }
    for (int r = 0; r < box.height; ++r) {
      const double scale = 1.0 / (255.0 * std::max(flipper_row_count_[static_cast<std::size_t>(r)], 1));
      const auto* sum = flipper_sum_.ptr<std::uint16_t>(r);
      auto* row = image.ptr<std::uint8_t>(box.y + r) + box.x;
      for (int u = 0; u < box.width; ++u) {
        if (sum[u] == 0) continue;
        const double a = sum[u] * scale;
        row[u] = cv::saturate_cast<std::uint8_t>(row[u] + a * (config_.flipper_gray - row[u]));
      }
    }
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
        uv.push_back(image_from_board(c + radius * Vec2{std::cos(a), std::sin(a)}));
      }
      Patch disc;
      polygon_patch(uv, 255.0, size, disc.roi, disc.values, !config_.realism.lens);
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
  std::size_t slot = history_head_;
  if (history_size_ < kHistory) {
    slot = (history_head_ + history_size_) % kHistory;
    ++history_size_;
  } else {
    history_head_ = (history_head_ + 1) % kHistory;
  }
  history_[slot] = s;
  std::copy(flipper_theta_.begin(), flipper_theta_.end(),
            flipper_history_.begin() + static_cast<std::ptrdiff_t>(slot * flipper_theta_.size()));
}

void SimCameraSource::reset(double t_s) {
  history_size_ = 0;
  history_head_ = 0;
  schedule_next_frame(t_s);
}

void SimCameraSource::bracket(double t_s, std::size_t& lo, std::size_t& hi, double& fraction) const {
  auto at = [&](std::size_t i) -> const Sample& { return history_[(history_head_ + i) % kHistory]; };
  lo = 0;
  hi = history_size_ - 1;
  fraction = 0.0;
  if (t_s <= at(0).t_s) {
    hi = 0;
    return;
  }
  if (t_s >= at(hi).t_s) {
    lo = hi;
    return;
  }
  while (hi - lo > 1) {  // at(lo).t < t <= at(hi).t
    const std::size_t mid = (lo + hi) / 2;
    if (at(mid).t_s < t_s) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  fraction = (t_s - at(lo).t_s) / (at(hi).t_s - at(lo).t_s);
}

bool SimCameraSource::sample_at(double t_s, Vec2& p, bool& in_play) const {
  if (history_size_ == 0) return false;
  std::size_t lo = 0, hi = 0;
  double f = 0.0;
  bracket(t_s, lo, hi, f);
  const Sample& a = history_[(history_head_ + lo) % kHistory];
  const Sample& b = history_[(history_head_ + hi) % kHistory];
  in_play = b.in_play;
  p = lo != hi && a.in_play && b.in_play ? Vec2(a.p + f * (b.p - a.p)) : b.p;
  return true;
}

double SimCameraSource::flipper_angle_at(std::size_t i, double t_s) const {
  if (history_size_ == 0) return flipper_theta_[i];
  std::size_t lo = 0, hi = 0;
  double f = 0.0;
  bracket(t_s, lo, hi, f);
  const std::size_t n = flipper_theta_.size();
  const double a = flipper_history_[((history_head_ + lo) % kHistory) * n + i];
  const double b = flipper_history_[((history_head_ + hi) % kHistory) * n + i];
  return a + f * (b - a);
}

std::span<const Vec2> SimCameraSource::BallPaths::row(int v) const {
  if (rows == 0) return common;
  if (v < first_row || v >= first_row + rows) return {};
  const auto k = static_cast<std::size_t>(v - first_row);
  return {row_paths + k * kMaxPath, static_cast<std::size_t>(row_counts[k])};
}

double SimCameraSource::ball_row(double start_s, Vec2& p_board) const {
  // The row whose exposure catches the ball's centre: a fixed point of
  // v = image row of the ball at that row's mid-exposure (the ball moves far
  // less than a row per row time, so it converges in a few steps).
  const SimCameraRealism& r = config_.realism;
  double v = 0.0;
  bool in_play = false;
  for (int it = 0; it < 6; ++it) {
    sample_at(start_s + v * r.row_time_s + 0.5 * config_.exposure_s, p_board, in_play);
    v = std::clamp(image_from_board(p_board).y, 0.0, config_.height_px - 1.0);
    if (r.row_time_s == 0.0) break;
  }
  return v;
}

SimCameraSource::BallPaths SimCameraSource::ball_paths(double start_s) {
  const double exposure = config_.exposure_s;
  Vec2 p0, p1;
  bool in0 = false, in1 = false;
  sample_at(start_s, p0, in0);
  sample_at(start_s + exposure, p1, in1);
  const double blur_px = cv::norm(image_from_board(p1) - image_from_board(p0));
  const int n = std::clamp(static_cast<int>(std::ceil(blur_px / 0.25)) + 1, 2, static_cast<int>(kMaxPath));
  BallPaths paths;
  paths.total = n;
  // Path samples at the middles of n equal slices of an exposure from t0.
  const auto fill = [&](double t0, Vec2* out) {
    int present = 0;
    for (int k = 0; k < n; ++k) {
      Vec2 p;
      bool in_play = false;
      sample_at(t0 + (k + 0.5) / n * exposure, p, in_play);
      if (in_play) out[present++] = p;
    }
    return present;
  };
  const double row_time = config_.realism.row_time_s;
  if (row_time == 0.0) {
    paths.common = std::span<const Vec2>(path_.data(), static_cast<std::size_t>(fill(start_s, path_.data())));
    return paths;
  }
  Vec2 p_centre;
  const double v_centre = ball_row(start_s, p_centre);
  const double radius_px = board_.ball.radius_m * ball_scale_ * homography_.px_per_m_at(p_centre);
  const double reach = radius_px + blur_px + 3.0;
  const int first = std::max(0, static_cast<int>(std::floor(v_centre - reach)));
  const int last = std::min(config_.height_px - 1, static_cast<int>(std::ceil(v_centre + reach)));
  paths.first_row = first;
  paths.rows = std::clamp(last - first + 1, 0, kMaxRows);
  paths.row_paths = row_path_.data();
  paths.row_counts = row_count_.data();
  for (int k = 0; k < paths.rows; ++k) {
    row_count_[static_cast<std::size_t>(k)] =
        fill(start_s + (first + k) * row_time, row_path_.data() + static_cast<std::size_t>(k) * kMaxPath);
  }
  paths.common = paths.row(static_cast<int>(std::lround(v_centre)));
  return paths;
}

bool SimCameraSource::read(vision::Frame& out) {
  if (history_size_ == 0) return false;
  const double newest = history_[(history_head_ + history_size_ - 1) % kHistory].t_s;
  const double oldest = history_[history_head_].t_s;
  const SimCameraRealism& r = config_.realism;
  while (true) {
    const double start = next_start_s_;
    const double readout_end = start + (config_.height_px - 1) * r.row_time_s + config_.exposure_s;
    const double row0_mid = start + 0.5 * config_.exposure_s;
    const double stamp = row0_mid + next_latency_s_;
    if (newest < std::max(readout_end, stamp)) return false;
    if (start < oldest && history_size_ == kHistory) {  // its exposure left the history: lost
      ++counters_.dropped;
      ++sequence_;
      schedule_next_frame(next_nominal_s_ + period_s_);
      continue;
    }
    compose(ball_paths(start), start, true, out);
    Vec2 p_ball;
    const double v_ball = ball_row(start, p_ball);
    truth_.t_row0_exposure_s = row0_mid;
    truth_.t_ball_exposure_s = row0_mid + v_ball * r.row_time_s;
    truth_.latency_s = stamp - row0_mid;
    truth_.p_board_mid = p_ball;
    truth_.uv_px_mid = image_from_board(p_ball);
    out.t_s = stamp;
    out.driver_t_s = start;
    schedule_next_frame(next_nominal_s_ + period_s_);
    return true;
  }
}

void SimCameraSource::render(std::span<const Vec2> path_board, double t_mid_s, vision::Frame& out) {
  BallPaths paths;
  paths.common = path_board.first(std::min(path_board.size(), kMaxPath));
  paths.total = std::max(1, static_cast<int>(paths.common.size()));
  const double start = t_mid_s - 0.5 * config_.exposure_s;
  compose(paths, start, false, out);
  if (!paths.common.empty()) {
    Vec2 mean = Vec2::Zero();
    for (const Vec2& p : paths.common) mean += p;
    truth_.p_board_mid = mean / static_cast<double>(paths.common.size());
    truth_.uv_px_mid = image_from_board(truth_.p_board_mid);
  }
  truth_.t_row0_exposure_s = truth_.t_ball_exposure_s = t_mid_s;
  out.t_s = t_mid_s;
  out.driver_t_s = start;
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

void SimCameraSource::apply_gain(double start_s, cv::Mat& image) {
  const SimCameraRealism& r = config_.realism;
  if (r.gain_drift_sigma > 0.0) {  // Ornstein–Uhlenbeck, stepped one frame period
    const double a = std::exp(-period_s_ / r.gain_drift_time_s);
    drift_ = a * drift_ + r.gain_drift_sigma * std::sqrt(1.0 - a * a) * timing_rng_.normal();
  }
  const double base = 1.0 + drift_;
  truth_.gain = base;
  if (r.flicker_amplitude <= 0.0) {
    if (base != 1.0) image.convertTo(image, -1, base);
    return;
  }
  // The light's brightness averaged over each row's exposure.
  const double w = 2.0 * std::numbers::pi * r.flicker_hz;
  const double exposure = config_.exposure_s;
  const auto row_gain = [&](double t0) {
    const double mean_cos = exposure > 0.0 ? (std::sin(w * (t0 + exposure) + flicker_phase_rad_) -
                                              std::sin(w * t0 + flicker_phase_rad_)) / (w * exposure)
                                           : std::cos(w * t0 + flicker_phase_rad_);
    return base * (1.0 + r.flicker_amplitude * mean_cos);
  };
  if (r.row_time_s == 0.0) {
    image.convertTo(image, -1, row_gain(start_s));
    return;
  }
  for (int v = 0; v < image.rows; ++v) {
    cv::Mat row = image.row(v);
    row.convertTo(row, -1, row_gain(start_s + v * r.row_time_s));
  }
}

void SimCameraSource::compose(const BallPaths& paths, double start_s, bool exposed, vision::Frame& out) {
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
  if (exposed) {
    draw_flippers_exposed(start_s, image);
  } else {
    draw_flippers(image);
  }
  const std::span<const Vec2> centre_path = paths.common;
  truth_.ball_present = !centre_path.empty();
  truth_.ball_whole_exposure = !centre_path.empty() && static_cast<int>(centre_path.size()) == paths.total;
  if (truth_.ball_present) draw_ball(paths, image);
  for (std::size_t i = 0; i < plastics_.size(); ++i) blend(plastics_[i], plastic_gray_[i], image);
  for (std::size_t i = 0; i < markers_.size(); ++i) blend(markers_[i], marker_gray_[i], image);
  truth_.glare_on = glare_ready_ && glare_on_;
  if (truth_.glare_on) {
    cv::Mat target = image(glare_.roi);
    cv::add(target, glare_.values, target);
    if (truth_.ball_present) {
      const double reach = 3.0 * config_.glare.sigma_m + board_.ball.radius_m;
      for (const Vec2& p : centre_path) {
        if ((p - config_.glare.centre_board).norm() < reach) truth_.in_glare = true;
      }
    }
  }
  apply_gain(start_s, image);
  if (noise_span_ > 0) {
    const std::size_t offset = static_cast<std::size_t>(rng_.next_u64() % noise_span_);
    const cv::Mat pos(image.rows, image.cols, CV_8U, noise_pos_.data() + offset);
    const cv::Mat neg(image.rows, image.cols, CV_8U, noise_neg_.data() + offset);
    cv::add(image, pos, image);
    cv::subtract(image, neg, image);
  }
  out.sequence = sequence_++;
  ++counters_.frames;
}

void SimCameraSource::draw_ball(const BallPaths& paths, cv::Mat& image) {
  const double r_m = board_.ball.radius_m * ball_scale_;
  // Image-space box around every path position of every row.
  double u0 = 1e300, v0 = 1e300, u1 = -1e300, v1 = -1e300;
  const auto extend = [&](std::span<const Vec2> path) {
    for (const Vec2& p : path) {
      const cv::Point2d c = image_from_board(p);
      const double r = r_m * homography_.px_per_m_at(p);
      u0 = std::min(u0, c.x - r);
      v0 = std::min(v0, c.y - r);
      u1 = std::max(u1, c.x + r);
      v1 = std::max(v1, c.y + r);
    }
  };
  if (paths.rows == 0) {
    extend(paths.common);
  } else {
    for (int v = paths.first_row; v < paths.first_row + paths.rows; ++v) extend(paths.row(v));
  }
  const std::span<const Vec2> centre_path = paths.common;
  truth_.blur_px = cv::norm(image_from_board(centre_path.back()) - image_from_board(centre_path.front()));
  cv::Rect box = cv::Rect(cv::Point(static_cast<int>(std::floor(u0)) - 2, static_cast<int>(std::floor(v0)) - 2),
                          cv::Point(static_cast<int>(std::ceil(u1)) + 3, static_cast<int>(std::ceil(v1)) + 3)) &
                 cv::Rect(0, 0, image.cols, image.rows);
  const Vec2 mid = centre_path[centre_path.size() / 2];
  const double scale = homography_.px_per_m_at(mid);  // px per m, for the edge's anti-aliasing width
  truth_.radius_px = r_m * scale;
  const SimCameraConfig& c = config_;
  const Vec2 highlight = c.highlight_offset * r_m;
  const double inv_2s2 = 1.0 / (2.0 * c.highlight_sigma * c.highlight_sigma * r_m * r_m);
  const double rim_gray = c.ball_gray * (1.0 - c.ball_limb_darkening);
  const double inv_n = 1.0 / paths.total;
  double covered = 0.0;
  double hidden = 0.0;
  for (int v = box.y; v < box.y + box.height; ++v) {
    const std::span<const Vec2> path_board = paths.row(v);
    if (path_board.empty()) continue;
    auto* row = image.ptr<std::uint8_t>(v);
    const auto* occluded = occluder_mask_.ptr<std::uint8_t>(v);
    for (int u = box.x; u < box.x + box.width; ++u) {
      const Vec2 q = board_at_pixel(u, v);
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
