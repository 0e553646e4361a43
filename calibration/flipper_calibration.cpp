#include "pinball/calibration/flipper_calibration.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <vector>
#include <stdexcept>

#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>

#include "pinball/core/format.h"
#include "pinball/core/statistics.h"

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
    throw std::runtime_error("flipper calibration: no marker within " + format_number(tolerance_m * 1e3) +
                             " mm of " + what);
  }
  return *best;
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

double flipper_angle(table::Side side, const Vec2& pivot, const Vec2& tip) {
  const Vec2 d = tip - pivot;
  return side == table::Side::kLeft ? std::atan2(d.y(), d.x()) : std::atan2(d.y(), -d.x());
}

FlipperCalibration calibrate_flipper_markers(const table::Flipper& f, std::span<const Vec2> down, std::span<const Vec2> up,
                                             double tolerance_m) {
  const std::string name = "flipper '" + f.name + "'";
  const Vec2 pivot_down = nearest(down, f.pivot, tolerance_m, "the pivot of " + name + " (flippers down)");
  const Vec2 tip_down =
      nearest(down, table::flipper_tip(f, f.theta_min_rad), tolerance_m, "the tip of " + name + " (flippers down)");
  const Vec2 pivot_up = nearest(up, f.pivot, tolerance_m, "the pivot of " + name + " (flippers up)");
  const Vec2 tip_up =
      nearest(up, table::flipper_tip(f, f.theta_max_rad), tolerance_m, "the tip of " + name + " (flippers up)");
  // One rigid blade on one pivot: its two sightings must agree, or the camera or a marker moved
  // between the pictures (averaging them would place the pivot between two places it never was).
  const auto check_agree = [&](double down_m, double up_m, const char* what) {
    if (std::abs(down_m - up_m) <= kMarkerAgreement_m) return;
    throw std::runtime_error("flipper calibration: " + name + ": " + what + " differs by " +
                             format_number(std::abs(down_m - up_m) * 1e3, 3) + " mm between the down and up pictures " +
                             "(at most " + format_number(kMarkerAgreement_m * 1e3) +
                             " mm): the camera or a marker moved; take both pictures again");
  };
  check_agree(0.0, (pivot_up - pivot_down).norm(), "the pivot marker's place");
  check_agree((tip_down - pivot_down).norm(), (tip_up - pivot_up).norm(), "the blade's length (pivot to tip marker)");
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
  cv::Point2d c(su / a, sv / a);
  const double mu20 = suu / a - c.x * c.x, mu02 = svv / a - c.y * c.y, mu11 = suv / a - c.x * c.y;
  const double angle = 0.5 * std::atan2(2.0 * mu11, mu20 - mu02);
  cv::Point2d d(std::cos(angle), std::sin(angle));
  // The blob's principal axis is only a start: the centre line comes from the long edges.
  const double reach = std::hypot(box.width, box.height) + 4.0;
  double e_plus = edge_along(c, d, sample(diff_, c), reach);
  double e_minus = edge_along(c, -d, sample(diff_, c), reach);
  if (e_plus < 0.0 || e_minus < 0.0) return false;
  double width_px = 0.0;
  for (int pass = 0; pass < 2; ++pass) {
    c += 0.5 * (e_plus - e_minus) * d;  // the middle of the blade along its axis
    if (!fit_centre_line(c, d, 0.5 * (e_plus + e_minus), width_px)) return false;
    e_plus = edge_along(c, d, sample(diff_, c), reach);
    e_minus = edge_along(c, -d, sample(diff_, c), reach);
    if (e_plus < 0.0 || e_minus < 0.0) return false;
  }
  // Either end may be the tip. The pivot's end is no clean circle: where the
  // blade lies in every frame it is part of the background.
  double s_plus = e_plus, s_minus = e_minus;
  const bool plus_ok = fit_end(c, d, width_px, reach, s_plus);
  const bool minus_ok = fit_end(c, -d, width_px, reach, s_minus);
  if (!plus_ok && !minus_ok) return false;
  Sighting s;
  s.t_s = t_s;
  s.centre_px = c;
  s.axis = d;
  s.end_plus_px = c + e_plus * d;
  s.end_minus_px = c - e_minus * d;
  s.tip_plus_px = c + s_plus * d;
  s.tip_minus_px = c - s_minus * d;
  s.tip_plus_ok = plus_ok;
  s.tip_minus_ok = minus_ok;
  sightings_.push_back(s);
  return true;
}

bool TipTracker::fit_centre_line(cv::Point2d& c, cv::Point2d& d, double half_length_px, double& width_px) const {
  // Stations 1 px apart along the axis, a blade width clear of the rounded
  // ends: at each the two half-contrast edges across the axis; their midpoint
  // is on the centre line. A straight line through the midpoints (offset
  // across the axis against position along it) corrects c and d.
  const cv::Point2d n(-d.y, d.x);
  const double guess = width_px > 0.0 ? width_px : 4.0;
  const double clear = std::max(1.5, guess);
  double s0 = 0, s1 = 0, s2 = 0, so = 0, sso = 0;
  std::vector<double> widths;
  for (double s = -half_length_px + clear; s <= half_length_px - clear + 1e-9; s += 1.0) {
    const cv::Point2d at = c + s * d;
    const double level = sample(diff_, at);
    const double w1 = edge_along(at, n, level, 3.0 * guess + 6.0);
    const double w2 = edge_along(at, -n, level, 3.0 * guess + 6.0);
    if (w1 <= 0.0 || w2 <= 0.0) continue;
    const double off = 0.5 * (w1 - w2);
    s0 += 1.0;
    s1 += s;
    s2 += s * s;
    so += off;
    sso += s * off;
    widths.push_back(w1 + w2);
  }
  if (s0 < 3.0) return false;
  const double det = s0 * s2 - s1 * s1;
  if (!(det > 1e-9)) return false;
  const double slope = (s0 * sso - s1 * so) / det;
  const double offset = (so - slope * s1) / s0;
  c += offset * n;
  d = d + slope * n;
  d *= 1.0 / cv::norm(d);
  width_px = median(widths);
  return true;
}

bool TipTracker::fit_end(const cv::Point2d& c, const cv::Point2d& d, double width_px, double reach_px,
                         double& s_px) const {
  // The rounded end is a circle centred on the centre line: half-contrast
  // edges along rays from a point near its centre, within 60° of the axis
  // (farther round, the blade's straight sides take over), give points
  // (a, b) in axis coordinates about that point, and (a − δ)² + b² = r² is
  // linear in δ and r² − δ². s_px comes in as the end (edge along the axis)
  // and goes out as the centre of the end's circle.
  const cv::Point2d n(-d.y, d.x);
  double s = s_px - 0.5 * width_px;
  constexpr int kRays = 17;
  constexpr double kSpan = 60.0 * std::numbers::pi / 180.0;
  for (int pass = 0; pass < 2; ++pass) {
    const cv::Point2d q = c + s * d;
    const double level = sample(diff_, q);
    Eigen::Matrix2d ata = Eigen::Matrix2d::Zero();
    Eigen::Vector2d atb = Eigen::Vector2d::Zero();
    int used = 0;
    for (int k = 0; k < kRays; ++k) {
      const double phi = -kSpan + 2.0 * kSpan * k / (kRays - 1);
      const cv::Point2d u = std::cos(phi) * d + std::sin(phi) * n;
      const double rho = edge_along(q, u, level, std::min(reach_px, 2.0 * width_px + 4.0));
      if (rho <= 0.0) continue;
      const double ax = rho * std::cos(phi), bx = rho * std::sin(phi);
      const Eigen::Vector2d row(2.0 * ax, 1.0);
      ata += row * row.transpose();
      atb += row * (ax * ax + bx * bx);
      ++used;
    }
    if (used < 5) return false;
    const Eigen::Vector2d x = ata.ldlt().solve(atb);
    if (!x.allFinite() || std::abs(x(0)) > width_px) return false;
    s += x(0);
  }
  s_px = s;
  return true;
}

SweepTrack TipTracker::finish() const {
  if (sightings_.size() < 10) {
    throw std::runtime_error("flipper sweep: the blade was seen in " + std::to_string(sightings_.size()) + " of " +
                             std::to_string(measured_) + " frames; at least 10 needed");
  }
  SweepTrack track;
  track.frames = measured_;
  std::vector<Line2> lines;
  for (const Sighting& s : sightings_) {
    // Two points of the image line, mapped: lines stay lines under a homography.
    const Vec2 p0 = to_board(homography_, s.centre_px - 8.0 * s.axis);
    const Vec2 p1 = to_board(homography_, s.centre_px + 8.0 * s.axis);
    lines.push_back({0.5 * (p0 + p1), (p1 - p0).normalized()});
  }
  LinesMeet meet;
  try {
    meet = meet_lines(lines, options_.circle);
  } catch (const std::invalid_argument&) {
    throw std::runtime_error("flipper sweep: the blade never turned; sweep it from stop to stop");
  }
  for (std::size_t i = 0; i < sightings_.size(); ++i) {
    const Sighting& s = sightings_[i];
    // The tip is the end away from the pivot; a frame whose tip end was no circle is left out.
    const bool use_plus = (to_board(homography_, s.end_plus_px) - meet.point).norm() >
                          (to_board(homography_, s.end_minus_px) - meet.point).norm();
    if (!(use_plus ? s.tip_plus_ok : s.tip_minus_ok)) continue;
    track.t_s.push_back(s.t_s);
    track.tips_board.push_back(to_board(homography_, use_plus ? s.tip_plus_px : s.tip_minus_px));
    Line2 l = lines[i];
    if (l.direction.dot(track.tips_board.back() - meet.point) < 0.0) l.direction = -l.direction;
    track.blades_board.push_back(l);
  }
  if (track.tips_board.size() < 10) {
    throw std::runtime_error("flipper sweep: the blade's tip was found in " + std::to_string(track.tips_board.size()) +
                             " of " + std::to_string(measured_) + " frames; at least 10 needed");
  }
  track.meet = meet;
  return track;
}

FlipperCalibration flipper_from_sweep_track(SweepTrack& track, const table::Flipper& nominal, const SweepOptions& options) {
  if (track.blades_board.empty()) {
    track.circle = fit_circle(track.tips_board, options.circle);
  } else {
    // The pivot is where the blade's centre lines meet; the length is the tips' median distance from it.
    track.meet = meet_lines(track.blades_board, options.circle);
    std::vector<double> r;
    for (const Vec2& t : track.tips_board) r.push_back((t - track.meet.point).norm());
    const double length = median(r);
    double ss = 0.0;
    for (const double x : r) ss += (x - length) * (x - length);
    track.circle.centre = track.meet.point;
    track.circle.radius = length;
    track.circle.rms = std::sqrt(ss / static_cast<double>(r.size()));
    track.circle.points = static_cast<int>(r.size());
  }
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
  c.theta_min_rad = median(down);
  c.theta_max_rad = median(up);
  table::Flipper f = nominal;
  f.pivot = c.pivot_m;
  f.length_m = c.length_m;
  c.tip_m = table::flipper_tip(f, c.theta_min_rad);
  return c;
}

FlipperCalibration calibrate_flipper_sweep(const FrameSourceFactory& open, const vision::CameraHomography& homography,
                                           const table::Flipper& nominal, const SweepOptions& options, SweepTrack* track) {
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
