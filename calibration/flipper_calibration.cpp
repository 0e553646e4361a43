#include "pinball/calibration/flipper_calibration.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>

namespace pinball::calibration {
namespace {

// Nearest of `points` to `target` within tolerance; throws naming what is missing.
Vec2 nearest(std::span<const Vec2> points, const Vec2& target, double tolerance_m, const std::string& what) {
  const Vec2* best = nullptr;
  double best_d = tolerance_m;
  for (const Vec2& p : points) {
    const double d = (p - target).norm();
    if (d <= best_d) {
      best_d = d;
      best = &p;
    }
  }
  if (!best) {
    throw std::runtime_error("flipper calibration: no marker within " + std::to_string(tolerance_m * 1e3) +
                             " mm of " + what);
  }
  return *best;
}

double median_of(std::vector<double> v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

double quantile(std::vector<double> v, double q) {
  const std::size_t k = std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

// Bilinear sample of an 8-bit image; 0 outside.
double sample(const cv::Mat& img, const cv::Point2d& p) {
  const int u = static_cast<int>(std::floor(p.x)), v = static_cast<int>(std::floor(p.y));
  if (u < 0 || v < 0 || u + 1 >= img.cols || v + 1 >= img.rows) return 0.0;
  const double fu = p.x - u, fv = p.y - v;
  const std::uint8_t* r0 = img.ptr<std::uint8_t>(v);
  const std::uint8_t* r1 = img.ptr<std::uint8_t>(v + 1);
  return (1 - fv) * ((1 - fu) * r0[u] + fu * r0[u + 1]) + fv * ((1 - fu) * r1[u] + fu * r1[u + 1]);
}

Vec2 to_board(const vision::CameraHomography& h, const cv::Point2d& p) { return h.board_from_image(p); }

}  // namespace

double flipper_angle(sim::Side side, const Vec2& pivot, const Vec2& tip) {
  const Vec2 d = tip - pivot;
  return side == sim::Side::kLeft ? std::atan2(d.y(), d.x()) : std::atan2(d.y(), -d.x());
}

FlipperCalibration calibrate_flipper_markers(const sim::Flipper& f, std::span<const Vec2> down, std::span<const Vec2> up,
                                             double tolerance_m) {
  const std::string name = "flipper '" + f.name + "'";
  const Vec2 pivot_down = nearest(down, f.pivot, tolerance_m, name + "'s pivot (flippers down)");
  const Vec2 tip_down = nearest(down, sim::flipper_tip(f, f.theta_min_rad), tolerance_m, name + "'s tip (flippers down)");
  const Vec2 pivot_up = nearest(up, f.pivot, tolerance_m, name + "'s pivot (flippers up)");
  const Vec2 tip_up = nearest(up, sim::flipper_tip(f, f.theta_max_rad), tolerance_m, name + "'s tip (flippers up)");
  FlipperCalibration c;
  c.name = f.name;
  c.side = f.side;
  c.method = FlipperMethod::kMarkers;
  c.pivot_m = 0.5 * (pivot_down + pivot_up);
  c.tip_m = tip_down;
  c.length_m = 0.5 * ((tip_down - c.pivot_m).norm() + (tip_up - c.pivot_m).norm());
  c.theta_min_rad = flipper_angle(f.side, c.pivot_m, tip_down);
  c.theta_max_rad = flipper_angle(f.side, c.pivot_m, tip_up);
  c.points = 4;
  if (!(c.length_m > 0.0) || !(c.theta_max_rad > c.theta_min_rad)) {
    throw std::runtime_error("flipper calibration: " + name + ": the up tip is not above the down tip");
  }
  return c;
}

TipTracker::TipTracker(cv::Size size, const vision::CameraHomography& homography, const SweepOptions& options)
    : size_(size), homography_(homography), options_(options) {
  if (size.width < 8 || size.height < 8) throw std::invalid_argument("tip tracker: frame size too small");
  if (options.threshold < 1 || options.threshold > 254) throw std::invalid_argument("tip tracker: threshold must be in [1, 254]");
  background_ = cv::Mat(size, CV_8U, cv::Scalar(255));
}

void TipTracker::learn(const cv::Mat& gray) {
  if (gray.type() != CV_8UC1 || gray.size() != size_) throw std::invalid_argument("tip tracker: frame is not 8-bit gray of the video's size");
  cv::min(background_, gray, background_);
  ++learned_;
}

double TipTracker::edge_along(const cv::Point2d& from, const cv::Point2d& dir, double level, double max_px) const {
  // First fall below half of `level`, then again at half of the level just inside that edge.
  constexpr double kStep = 0.25;
  double half = 0.5 * level;
  double s_edge = -1.0;
  for (int pass = 0; pass < 2; ++pass) {
    double prev = sample(diff_, from);
    s_edge = -1.0;
    for (double s = kStep; s <= max_px; s += kStep) {
      const double val = sample(diff_, from + s * dir);
      if (val < half) {
        s_edge = s - kStep + kStep * (prev - half) / std::max(prev - val, 1e-9);
        break;
      }
      prev = val;
    }
    if (s_edge < 0.0) return -1.0;
    const double inside = sample(diff_, from + std::max(0.0, s_edge - 2.0) * dir);
    half = 0.5 * inside;
  }
  return s_edge;
}

bool TipTracker::measure(const cv::Mat& gray, double t_s) {
  if (gray.type() != CV_8UC1 || gray.size() != size_) throw std::invalid_argument("tip tracker: frame is not 8-bit gray of the video's size");
  if (learned_ == 0) throw std::logic_error("tip tracker: measure() before learn()");
  ++measured_;
  cv::subtract(gray, background_, diff_);
  cv::threshold(diff_, binary_, options_.threshold, 255, cv::THRESH_BINARY);
  const int n = cv::connectedComponentsWithStats(binary_, labels_, stats_, centroids_, 8, CV_32S);
  int best = -1;
  int best_area = options_.min_area_px - 1;
  for (int k = 1; k < n; ++k) {
    const int area = stats_.at<int>(k, cv::CC_STAT_AREA);
    if (area > best_area) {
      best_area = area;
      best = k;
    }
  }
  if (best < 0) return false;
  const cv::Rect box(stats_.at<int>(best, cv::CC_STAT_LEFT), stats_.at<int>(best, cv::CC_STAT_TOP),
                     stats_.at<int>(best, cv::CC_STAT_WIDTH), stats_.at<int>(best, cv::CC_STAT_HEIGHT));
  double su = 0, sv = 0, suu = 0, svv = 0, suv = 0;
  for (int v = box.y; v < box.y + box.height; ++v) {
    const int* row = labels_.ptr<int>(v);
    for (int u = box.x; u < box.x + box.width; ++u) {
      if (row[u] != best) continue;
      su += u;
      sv += v;
      suu += static_cast<double>(u) * u;
      svv += static_cast<double>(v) * v;
      suv += static_cast<double>(u) * v;
    }
  }
  const double a = best_area;
  const cv::Point2d c(su / a, sv / a);
  const double mu20 = suu / a - c.x * c.x, mu02 = svv / a - c.y * c.y, mu11 = suv / a - c.x * c.y;
  const double angle = 0.5 * std::atan2(2.0 * mu11, mu20 - mu02);
  const cv::Point2d d(std::cos(angle), std::sin(angle));
  const cv::Point2d nrm(-d.y, d.x);
  const double level = sample(diff_, c);
  const double reach = std::hypot(box.width, box.height) + 4.0;
  const double e_plus = edge_along(c, d, level, reach);
  const double e_minus = edge_along(c, -d, level, reach);
  // Blade width: the half-contrast edges across the axis, a little either side of the centre.
  std::vector<double> widths;
  for (const double s : {-2.0, 0.0, 2.0}) {
    const cv::Point2d at = c + s * d;
    const double l = sample(diff_, at);
    const double w1 = edge_along(at, nrm, l, 30.0);
    const double w2 = edge_along(at, -nrm, l, 30.0);
    if (w1 > 0.0 && w2 > 0.0) widths.push_back(w1 + w2);
  }
  if (e_plus < 0.0 || e_minus < 0.0 || widths.empty()) return false;
  Sighting s;
  s.t_s = t_s;
  s.centre_px = c;
  s.axis = d;
  s.end_plus_px = c + e_plus * d;
  s.end_minus_px = c - e_minus * d;
  s.width_px = median_of(widths);
  sightings_.push_back(s);
  return true;
}

SweepTrack TipTracker::finish() const {
  if (sightings_.size() < 10) {
    throw std::runtime_error("flipper sweep: the blade was seen in " + std::to_string(sightings_.size()) + " of " +
                             std::to_string(measured_) + " frames; at least 10 needed");
  }
  // Where the blade axes meet: least squares over the lines (centre, axis).
  Eigen::Matrix2d a = Eigen::Matrix2d::Zero();
  Eigen::Vector2d b = Eigen::Vector2d::Zero();
  for (const Sighting& s : sightings_) {
    const Eigen::Vector2d d(s.axis.x, s.axis.y);
    const Eigen::Matrix2d p = Eigen::Matrix2d::Identity() - d * d.transpose();
    a += p;
    b += p * Eigen::Vector2d(s.centre_px.x, s.centre_px.y);
  }
  const Eigen::JacobiSVD<Eigen::Matrix2d> svd(a);
  if (!(svd.singularValues()(1) > 1e-3 * svd.singularValues()(0))) {
    throw std::runtime_error("flipper sweep: the blade never turned; sweep it from stop to stop");
  }
  const Eigen::Vector2d apex = a.ldlt().solve(b);
  const cv::Point2d apex_px(apex.x(), apex.y());
  SweepTrack track;
  track.frames = measured_;
  track.rough_pivot_board = to_board(homography_, apex_px);
  for (const Sighting& s : sightings_) {
    // The tip end is the one away from the pivot; its rounded cap is half a blade wide.
    const bool plus = cv::norm(s.end_plus_px - apex_px) > cv::norm(s.end_minus_px - apex_px);
    const cv::Point2d end_px = plus ? s.end_plus_px : s.end_minus_px;
    const Vec2 end = to_board(homography_, end_px);
    const Vec2 centre = to_board(homography_, s.centre_px);
    const Vec2 out = (end - centre).normalized();
    const double half_width_m = 0.5 * s.width_px / homography_.px_per_m_at(end);
    track.t_s.push_back(s.t_s);
    track.tips_board.push_back(end - half_width_m * out);
  }
  return track;
}

FlipperCalibration flipper_from_sweep_track(SweepTrack& track, const sim::Flipper& nominal, const SweepOptions& options) {
  track.circle = fit_circle(track.tips_board, options.circle);
  FlipperCalibration c;
  c.name = nominal.name;
  c.side = nominal.side;
  c.method = FlipperMethod::kMarkerless;
  c.pivot_m = track.circle.centre;
  c.length_m = track.circle.radius;
  c.fit_rms_m = track.circle.rms;
  c.points = track.circle.points;
  std::vector<double> theta;
  for (const Vec2& t : track.tips_board) theta.push_back(flipper_angle(nominal.side, c.pivot_m, t));
  const double lo = quantile(theta, 0.05) + options.stop_band_rad;
  const double hi = quantile(theta, 0.95) - options.stop_band_rad;
  std::vector<double> down, up;
  for (const double t : theta) {
    if (t <= lo) down.push_back(t);
    if (t >= hi) up.push_back(t);
  }
  if (down.empty() || up.empty() || !(hi > lo)) {
    throw std::runtime_error("flipper sweep: '" + nominal.name + "' turned less than twice the stop band");
  }
  c.theta_min_rad = median_of(down);
  c.theta_max_rad = median_of(up);
  sim::Flipper f = nominal;
  f.pivot = c.pivot_m;
  f.length_m = c.length_m;
  c.tip_m = sim::flipper_tip(f, c.theta_min_rad);
  return c;
}

FlipperCalibration calibrate_flipper_sweep(const FrameSourceFactory& open, const vision::CameraHomography& homography,
                                           const sim::Flipper& nominal, const SweepOptions& options, SweepTrack* track) {
  vision::Frame frame;
  std::unique_ptr<vision::FrameSource> first = open();
  TipTracker tracker(first->frame_size(), homography, options);
  while (first->read(frame)) tracker.learn(frame.gray);
  first.reset();
  std::unique_ptr<vision::FrameSource> second = open();
  while (second->read(frame)) tracker.measure(frame.gray, frame.t_s);
  SweepTrack t = tracker.finish();
  FlipperCalibration c = flipper_from_sweep_track(t, nominal, options);
  if (track) *track = std::move(t);
  return c;
}

FlipperDisagreement compare_flippers(const FlipperCalibration& a, const FlipperCalibration& b) {
  FlipperDisagreement d;
  d.pivot_m = (a.pivot_m - b.pivot_m).norm();
  d.tip_m = (a.tip_m - b.tip_m).norm();
  d.length_m = a.length_m - b.length_m;
  d.theta_min_rad = a.theta_min_rad - b.theta_min_rad;
  d.theta_max_rad = a.theta_max_rad - b.theta_max_rad;
  return d;
}

}  // namespace pinball::calibration
