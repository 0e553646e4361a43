#include "pinball/calibration/latency_calibration.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>

#include "pinball/core/check.h"
#include "pinball/core/least_squares_line.h"
#include "pinball/core/running_stats.h"
#include "pinball/core/statistics.h"
#include "pinball/vision/frame_dejitter.h"

namespace pinball::calibration {
namespace {

double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// The region's pixels as flat lists (offsets into the roi), for the per-frame sums.
struct RegionPixels {
  std::vector<int> row;       // row in the roi
  std::vector<int> col;       // column in the roi
  std::vector<double> angle;  // rad from the down stop
  std::vector<double> area;   // m²
  std::vector<int> ref_row;   // the reference pixels: row and column in the roi
  std::vector<int> ref_col;
};

RegionPixels region_pixels(const FlipperRegion& region) {
  RegionPixels p;
  for (int r = 0; r < region.roi.height; ++r) {
    const auto* m = region.mask.ptr<std::uint8_t>(r);
    for (int c = 0; c < region.roi.width; ++c) {
      if (m[c] == 0) continue;
      p.row.push_back(r);
      p.col.push_back(c);
      p.angle.push_back(region.angle_rad.at<double>(r, c));
      p.area.push_back(region.area_m2.at<double>(r, c));
    }
  }
  if (region.reference.empty()) return p;
  for (int r = 0; r < region.roi.height; ++r) {
    const auto* m = region.reference.ptr<std::uint8_t>(r);
    for (int c = 0; c < region.roi.width; ++c) {
      if (m[c] == 0) continue;
      p.ref_row.push_back(r);
      p.ref_col.push_back(c);
    }
  }
  return p;
}

// Each row's brightness in `frame` relative to the rest image, from the
// reference pixels (flicker under a rolling shutter, gain drift): the ratio
// of the row sums, smoothed as a quadratic in the row (a constant with fewer
// than 8 rows to fit, 1 without a reference). `rest_ref_row` holds the rest
// image's reference sum per roi row, `count` its pixels.
void row_gains(const cv::Mat& frame, const RegionPixels& px, const std::vector<double>& rest_ref_row,
               const std::vector<int>& count, std::vector<double>& frame_row, std::vector<double>& gain) {
  std::fill(frame_row.begin(), frame_row.end(), 0.0);
  for (std::size_t i = 0; i < px.ref_row.size(); ++i) {
    frame_row[static_cast<std::size_t>(px.ref_row[i])] += frame.at<std::uint8_t>(px.ref_row[i], px.ref_col[i]);
  }
  const auto rows = static_cast<int>(gain.size());
  const double mid = 0.5 * (rows - 1), half = std::max(1.0, 0.5 * (rows - 1));
  Eigen::Matrix3d a = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  double sum_frame = 0.0, sum_rest = 0.0;
  int fitted = 0;
  for (int r = 0; r < rows; ++r) {
    const auto k = static_cast<std::size_t>(r);
    sum_frame += frame_row[k];
    sum_rest += rest_ref_row[k];
    if (count[k] < 4 || rest_ref_row[k] <= 0.0) continue;
    const double x = (r - mid) / half;
    const Eigen::Vector3d basis(1.0, x, x * x);
    a += count[k] * basis * basis.transpose();
    b += count[k] * basis * (frame_row[k] / rest_ref_row[k]);
    ++fitted;
  }
  const double constant = sum_rest > 0.0 ? sum_frame / sum_rest : 1.0;
  if (fitted < 8) {
    std::fill(gain.begin(), gain.end(), constant);
    return;
  }
  const Eigen::Vector3d c = a.ldlt().solve(b);
  for (int r = 0; r < rows; ++r) {
    const double x = (r - mid) / half;
    const double g = c[0] + c[1] * x + c[2] * x * x;
    gain[static_cast<std::size_t>(r)] = g > 0.05 ? g : constant;
  }
}

// The frame's pixels inside the roi: the frame itself when it is the crop.
cv::Mat roi_of(const cv::Mat& gray, const FlipperRegion& region) {
  if (gray.size() == region.roi.size()) return gray;
  return gray(region.roi);
}

// A frame's motion metric Σ (frame / its row's gain − rest) · weight over the
// region, and the same sum with each pixel's image row as a factor (where the
// change is: which rows' exposure times the metric reflects).
struct Metric {
  double m = 0.0;       // the metric
  double row_m = 0.0;   // Σ change · weight · row (px)
};

Metric motion_metric(const cv::Mat& frame, const std::vector<double>& rest, const std::vector<double>& weight,
                     const std::vector<double>& gain, const RegionPixels& px, int first_row) {
  Metric s;
  for (std::size_t i = 0; i < weight.size(); ++i) {
    const double change =
        (frame.at<std::uint8_t>(px.row[i], px.col[i]) / gain[static_cast<std::size_t>(px.row[i])] - rest[i]) * weight[i];
    s.m += change;
    s.row_m += change * (first_row + px.row[i]);
  }
  return s;
}

void check_options(const LatencyOptions& o) {
  const char* ctx = "latency calibration";
  check_input(std::isfinite(o.frame_period_s) && o.frame_period_s > 0.0 && o.frame_period_s <= 1.0, ctx,
              "frame_period_s must be in (0, 1] s");
  check_input(std::isfinite(o.row_time_s) && o.row_time_s >= 0.0 && o.row_time_s <= 0.001, ctx,
              "row_time_s must be in [0, 0.001] s");
  check_input(std::isfinite(o.actuation_delay_s) && o.actuation_delay_s >= 0.0 && o.actuation_delay_s <= 1.0, ctx,
              "actuation_delay_s must be in [0, 1] s");
  check_input(o.dejitter_frames >= 1 && o.dejitter_frames <= vision::FrameDejitter::kMaxWindow, ctx,
              "dejitter_frames must be in [1, " + std::to_string(vision::FrameDejitter::kMaxWindow) + "]");
  check_input(o.rest_frames >= 2 && o.rest_frames <= 1000, ctx, "rest_frames must be in [2, 1000]");
  check_input(std::isfinite(o.window_s) && o.window_s > 0.0 && o.window_s <= 10.0, ctx, "window_s must be in (0, 10] s");
  check_input(o.fit_low > 0.0 && o.fit_low < o.fit_high && o.fit_high < 1.0, ctx,
              "fit_low and fit_high must satisfy 0 < fit_low < fit_high < 1");
  check_input(o.min_fit_frames >= 2, ctx, "min_fit_frames must be >= 2");
  check_input(std::isfinite(o.max_fit_rms) && o.max_fit_rms > 0.0, ctx, "max_fit_rms must be > 0");
  check_input(std::isfinite(o.min_motion_sigmas) && o.min_motion_sigmas > 0.0, ctx, "min_motion_sigmas must be > 0");
}

}  // namespace

const char* to_string(LatencyRejection rejection) {
  switch (rejection) {
    case LatencyRejection::kNone: return "used";
    case LatencyRejection::kClockNotSettled: return "frame clock not settled";
    case LatencyRejection::kFramesDropped: return "frames dropped around it";
    case LatencyRejection::kNoMotion: return "no motion seen";
    case LatencyRejection::kTooFewFitFrames: return "too few frames in the fit window";
    case LatencyRejection::kFitResidual: return "fit residual too large";
  }
  return "?";
}

CameraTiming LatencyEstimate::camera_timing() const {
  CameraTiming t;
  t.latency_s = latency_s;
  t.latency_spread_s = spread_s;
  t.row_time_s = row_time_s;
  t.events_used = events_used;
  return t;
}

FlipperRegion flipper_region(const table::Flipper& flipper, const ImageFromBoard& image_from_board, cv::Size image_size,
                             const FlipperRegionOptions& options) {
  const char* ctx = "flipper region";
  check_input(std::isfinite(flipper.length_m) && flipper.length_m > 0.0, ctx, "the flipper needs a length > 0");
  const double sweep = std::abs(flipper.theta_max_rad - flipper.theta_min_rad);
  check_input(std::isfinite(sweep) && sweep > 1e-3 && sweep < std::numbers::pi, ctx,
              "the flipper's stops must differ by (0.001, pi) rad");
  check_input(std::isfinite(options.half_width_m) && options.half_width_m > 0.0 && options.half_width_m < flipper.length_m,
              ctx, "half_width_m must be in (0, the flipper's length)");
  check_input(std::isfinite(options.sample_step_m) && options.sample_step_m > 0.0 &&
                  options.sample_step_m <= options.half_width_m,
              ctx, "sample_step_m must be in (0, half_width_m]");
  check_input(options.reference_margin_px >= 0 && options.reference_margin_px <= 200 &&
                  options.reference_guard_px >= 0 && options.reference_guard_px < options.reference_margin_px + 1,
              ctx, "reference_margin_px must be in [0, 200] and reference_guard_px in [0, reference_margin_px]");
  check_input(image_size.width > 0 && image_size.height > 0, ctx, "the image size must be > 0");
  check_input(static_cast<bool>(image_from_board), ctx, "no board-to-image mapping");

  const Vec2 down = table::flipper_direction(flipper, flipper.theta_min_rad);
  const Vec2 up = table::flipper_direction(flipper, flipper.theta_max_rad);
  const double sense = cross(down, up) >= 0.0 ? 1.0 : -1.0;  // +1: the stroke turns counter-clockwise
  const double h = options.half_width_m;
  const double reach = flipper.length_m + h;

  // Per-pixel sums over board samples: count, polar angle, board point.
  const cv::Rect frame(0, 0, image_size.width, image_size.height);
  cv::Mat count = cv::Mat::zeros(image_size, CV_32S);
  cv::Mat angle_sum = cv::Mat::zeros(image_size, CV_64F);
  cv::Mat x_sum = cv::Mat::zeros(image_size, CV_64F);
  cv::Mat y_sum = cv::Mat::zeros(image_size, CV_64F);
  const int steps = static_cast<int>(std::ceil(2.0 * reach / options.sample_step_m));
  int outside = 0;
  for (int i = 0; i <= steps; ++i) {
    for (int k = 0; k <= steps; ++k) {
      const Vec2 u{-reach + i * options.sample_step_m, -reach + k * options.sample_step_m};
      const double rho = u.norm();
      if (rho < h || rho > reach) continue;
      const double phi = sense * std::atan2(cross(down, u), down.dot(u));  // from the down stop, towards up
      double distance = 0.0;
      if (phi < 0.0 || phi > sweep) {
        // Beyond a stop: the nearer stop's bat (by angle) is the nearest part of the sweep.
        const double past_up = phi > sweep ? phi - sweep : phi + 2.0 * std::numbers::pi - sweep;
        const double before_down = phi < 0.0 ? -phi : 2.0 * std::numbers::pi - phi;
        const Vec2 stop = past_up < before_down ? up : down;
        distance = distance_point_segment(u, Vec2::Zero(), flipper.length_m * stop);
      } else {
        distance = std::max(0.0, rho - flipper.length_m);
      }
      if (distance > h) continue;
      const Vec2 p = flipper.pivot + u;
      const cv::Point2d px = image_from_board(p);
      const cv::Point pixel(static_cast<int>(std::lround(px.x)), static_cast<int>(std::lround(px.y)));
      if (!std::isfinite(px.x) || !std::isfinite(px.y) || !frame.contains(pixel)) {
        ++outside;
        continue;
      }
      ++count.at<int>(pixel);
      angle_sum.at<double>(pixel) += phi;
      x_sum.at<double>(pixel) += p.x();
      y_sum.at<double>(pixel) += p.y();
    }
  }
  check_input(outside == 0, ctx, "the flipper's region is not wholly inside the image");

  FlipperRegion region;
  region.sweep_rad = sweep;
  cv::Mat mask;
  cv::compare(count, 0, mask, cv::CMP_GT);
  const cv::Rect box = cv::boundingRect(mask);
  check_input(box.area() > 0, ctx, "the flipper's region covers no pixel");
  const int margin = options.reference_margin_px;
  region.roi = cv::Rect(box.x - margin, box.y, box.width + 2 * margin, box.height) & frame;
  region.mask = mask(region.roi).clone();
  // The reference: the rest of the roi, clear of the region by the guard.
  cv::Mat near;
  const int g = options.reference_guard_px;
  cv::dilate(region.mask, near, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * g + 1, 2 * g + 1)));
  cv::bitwise_not(near, region.reference);
  region.reference_pixels = cv::countNonZero(region.reference);
  region.angle_rad = cv::Mat::zeros(region.roi.size(), CV_64F);
  region.area_m2 = cv::Mat::zeros(region.roi.size(), CV_64F);
  double row_sum = 0.0;
  const double e = 1e-4;  // finite-difference step for the mapping's Jacobian (m)
  for (int r = 0; r < region.roi.height; ++r) {
    for (int c = 0; c < region.roi.width; ++c) {
      if (region.mask.at<std::uint8_t>(r, c) == 0) continue;
      const cv::Point pixel(region.roi.x + c, region.roi.y + r);
      const double n = count.at<int>(pixel);
      region.angle_rad.at<double>(r, c) = angle_sum.at<double>(pixel) / n;
      const Vec2 p{x_sum.at<double>(pixel) / n, y_sum.at<double>(pixel) / n};
      const cv::Point2d o = image_from_board(p);
      const cv::Point2d dx = (image_from_board(p + Vec2{e, 0.0}) - o) / e;
      const cv::Point2d dy = (image_from_board(p + Vec2{0.0, e}) - o) / e;
      const double det = std::abs(dx.x * dy.y - dx.y * dy.x);  // px² per m²
      region.area_m2.at<double>(r, c) = det > 0.0 ? 1.0 / det : 0.0;
      row_sum += pixel.y;
      ++region.pixels;
    }
  }
  region.mean_row_px = row_sum / region.pixels;
  return region;
}

void LatencyRecording::add_frame(const FlipperRegion& region, const cv::Mat& gray, double t_s, std::uint64_t sequence) {
  check_input(gray.type() == CV_8UC1, "latency recording", "frames must be 8-bit gray");
  check_input((cv::Rect(0, 0, gray.cols, gray.rows) & region.roi) == region.roi, "latency recording",
              "the frame does not hold the flipper's region");
  frames.push_back({gray(region.roi).clone(), t_s, sequence});
}

double estimate_frame_period_s(const LatencyRecording& recording, double nominal_period_s, int window) {
  check_input(std::isfinite(nominal_period_s) && nominal_period_s > 0.0, "frame period", "nominal_period_s must be > 0");
  check_input(window >= 2, "frame period", "window must be >= 2");
  const std::vector<LatencyFrame>& f = recording.frames;
  const auto w = static_cast<std::size_t>(window);
  if (f.size() < 2 * w) return nominal_period_s;
  double period = nominal_period_s;
  // The envelope's lowest point in each end window, on the current period; twice, as the period moves it.
  for (int pass = 0; pass < 3; ++pass) {
    const auto lowest = [&](std::size_t from) {
      std::size_t best = from;
      double best_offset = 1e300;
      for (std::size_t k = from; k < from + w; ++k) {
        const double offset = f[k].t_s - static_cast<double>(f[k].sequence - f[0].sequence) * period;
        if (offset < best_offset) {
          best_offset = offset;
          best = k;
        }
      }
      return std::pair{best, best_offset};
    };
    const auto [a, offset_a] = lowest(0);
    const auto [b, offset_b] = lowest(f.size() - w);
    if (f[b].sequence <= f[a].sequence) return nominal_period_s;
    period += (offset_b - offset_a) / static_cast<double>(f[b].sequence - f[a].sequence);
  }
  return period;
}

LatencyEstimate measure_latency(const LatencyRecording& recording, const FlipperRegion& region,
                                const LatencyOptions& o) {
  check_options(o);
  check_input(region.pixels > 0 && !region.mask.empty(), "latency calibration", "empty flipper region");
  const std::vector<LatencyFrame>& frames = recording.frames;
  for (const LatencyFrame& f : frames) {
    check_input(f.gray.type() == CV_8UC1 && (f.gray.size() == region.roi.size() ||
                                            (cv::Rect(0, 0, f.gray.cols, f.gray.rows) & region.roi) == region.roi),
                "latency calibration", "every frame must be 8-bit gray holding the flipper's region");
  }
  const RegionPixels px = region_pixels(region);

  // Date the frames by the camera's clock; a frame is settled once the
  // envelope has seen dejitter_frames frames since it last restarted.
  vision::FrameDejitter dejitter(o.frame_period_s, o.dejitter_frames);
  std::vector<double> stamp(frames.size());
  std::vector<char> settled(frames.size(), 0);
  std::uint64_t run = 0;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const bool restart = k == 0 || frames[k].sequence <= frames[k - 1].sequence ||
                         frames[k].sequence - frames[k - 1].sequence > static_cast<std::uint64_t>(o.dejitter_frames);
    run = restart ? 1 : run + (frames[k].sequence - frames[k - 1].sequence);
    stamp[k] = dejitter.steady_stamp(frames[k].sequence, frames[k].t_s);
    settled[k] = run >= static_cast<std::uint64_t>(o.dejitter_frames) ? 1 : 0;
  }

  LatencyEstimate est;
  est.row_time_s = o.row_time_s;
  std::vector<double> rest(px.angle.size()), weight(px.angle.size());
  const auto rows = static_cast<std::size_t>(region.roi.height);
  std::vector<double> rest_ref_row(rows), frame_row(rows), gain(rows, 1.0);
  std::vector<int> ref_count(rows, 0);
  for (const int r : px.ref_row) ++ref_count[static_cast<std::size_t>(r)];
  std::vector<double> used_latencies;
  for (const double command : recording.command_t_s) {
    LatencyEvent ev;
    ev.command_t_s = command;
    // Frames stamped up to the command show the flipper at rest; those of the window show it move.
    // (A linear search: the dates need not be quite sorted when the stamps jitter by more than a period.)
    const auto first_stamped_after = [&](double t_s) {
      return static_cast<std::size_t>(
          std::find_if(stamp.begin(), stamp.end(), [t_s](double s) { return s > t_s; }) - stamp.begin());
    };
    const std::size_t first_after = first_stamped_after(command);
    const std::size_t window_end = std::max(first_after, first_stamped_after(command + o.window_s));
    const auto rest_n = static_cast<std::size_t>(o.rest_frames);
    const auto reject = [&](LatencyRejection why) {
      ev.rejection = why;
      est.events.push_back(ev);
    };
    if (first_after < rest_n || window_end >= frames.size()) {
      reject(first_after < rest_n ? LatencyRejection::kClockNotSettled : LatencyRejection::kFramesDropped);
      continue;
    }
    const std::size_t first_rest = first_after - rest_n;
    if (!settled[first_rest]) {
      reject(LatencyRejection::kClockNotSettled);
      continue;
    }
    bool gap = false;
    for (std::size_t k = first_rest + 1; k <= window_end; ++k) gap |= frames[k].sequence != frames[k - 1].sequence + 1;
    if (gap) {
      reject(LatencyRejection::kFramesDropped);
      continue;
    }

    // The rest image, and weights that a uniform change of brightness leaves at zero.
    std::fill(rest.begin(), rest.end(), 0.0);
    std::fill(rest_ref_row.begin(), rest_ref_row.end(), 0.0);
    for (std::size_t k = first_rest; k < first_after; ++k) {
      const cv::Mat g = roi_of(frames[k].gray, region);
      for (std::size_t i = 0; i < rest.size(); ++i) rest[i] += g.at<std::uint8_t>(px.row[i], px.col[i]);
      for (std::size_t i = 0; i < px.ref_row.size(); ++i) {
        rest_ref_row[static_cast<std::size_t>(px.ref_row[i])] += g.at<std::uint8_t>(px.ref_row[i], px.ref_col[i]);
      }
    }
    for (double& s : rest_ref_row) s /= static_cast<double>(rest_n);
    // A frame's metric, its rows' brightness matched to the rest image's first.
    const auto metric_of = [&](std::size_t k) {
      const cv::Mat g = roi_of(frames[k].gray, region);
      row_gains(g, px, rest_ref_row, ref_count, frame_row, gain);
      return motion_metric(g, rest, weight, gain, px, region.roi.y);
    };
    double moment = 0.0, mass = 0.0;
    for (std::size_t i = 0; i < rest.size(); ++i) {
      rest[i] /= static_cast<double>(rest_n);
      moment += rest[i] * px.area[i] * px.angle[i];
      mass += rest[i] * px.area[i];
    }
    const double mean_angle = mass > 0.0 ? moment / mass : 0.0;
    for (std::size_t i = 0; i < weight.size(); ++i) weight[i] = px.area[i] * (px.angle[i] - mean_angle);

    RunningStats noise;
    for (std::size_t k = first_rest; k < first_after; ++k) noise.add(metric_of(k).m);
    std::vector<double> metric, row_metric;
    for (std::size_t k = first_after; k < window_end; ++k) {
      const Metric s = metric_of(k);
      metric.push_back(s.m);
      row_metric.push_back(s.row_m);
    }
    // The full stroke: the median of the frames above half the largest change (the flipper held up).
    double peak = 0.0;
    for (const double m : metric) {
      if (std::abs(m) > std::abs(peak)) peak = m;
    }
    std::vector<double> held;
    for (const double m : metric) {
      if (peak != 0.0 && m / peak >= 0.5) held.push_back(m);
    }
    const double full = held.empty() ? 0.0 : median(held);
    const double sigma = std::max(noise.stddev(), 1e-12 * std::abs(full));
    ev.stroke_sigmas = full != 0.0 ? std::abs(full) / sigma : 0.0;
    if (full == 0.0 || ev.stroke_sigmas < o.min_motion_sigmas) {
      reject(LatencyRejection::kNoMotion);
      continue;
    }
    // The rising frames: the contiguous run at or above fit_low just before
    // the first frame past fit_high.
    std::size_t high = metric.size();
    for (std::size_t k = 0; k < metric.size(); ++k) {
      if (metric[k] / full > o.fit_high) {
        high = k;
        break;
      }
    }
    // Each fit frame's time: its stamp, plus the row time for the rows whose
    // change made its metric between the frames either side of it (where
    // the bat's edges were then), less the command's time.
    std::vector<std::size_t> fit;
    for (std::size_t k = high; k-- > 0;) {
      if (metric[k] / full < o.fit_low) break;
      fit.push_back(k);
    }
    ev.fit_frames = static_cast<int>(fit.size());
    if (high == metric.size() || ev.fit_frames < o.min_fit_frames) {
      reject(high == metric.size() ? LatencyRejection::kNoMotion : LatencyRejection::kTooFewFitFrames);
      continue;
    }
    std::vector<std::pair<double, double>> xy;  // (time since the command, √fraction)
    std::vector<double> fraction;
    double row_sum = 0.0;
    for (const std::size_t k : fit) {
      const std::size_t after = std::min(k + 1, metric.size() - 1);
      const double dm = metric[after] - (k > 0 ? metric[k - 1] : 0.0);
      const double drow = row_metric[after] - (k > 0 ? row_metric[k - 1] : 0.0);
      const double row = dm != 0.0 ? std::clamp(drow / dm, static_cast<double>(region.roi.y),
                                                static_cast<double>(region.roi.y + region.roi.height - 1))
                                   : region.mean_row_px;
      row_sum += row;
      fraction.push_back(metric[k] / full);
      xy.emplace_back(stamp[first_after + k] - command + row * o.row_time_s, std::sqrt(fraction.back()));
    }
    ev.motion_row_px = row_sum / static_cast<double>(fit.size());
    LineFit line = fit_line(xy);
    // A frame shows the angle averaged over its exposure: (t − t_move)² + e²/12
    // in units of the line's slope, which lifts the early points: take it off.
    for (int pass = 0; pass < 2 && o.exposure_s > 0.0 && line.slope > 0.0; ++pass) {
      const double lift = line.slope * line.slope * o.exposure_s * o.exposure_s / 12.0;
      for (std::size_t i = 0; i < xy.size(); ++i) xy[i].second = std::sqrt(std::max(fraction[i] - lift, 0.0));
      line = fit_line(xy);
    }
    double ss = 0.0;
    for (const auto& [x, y] : xy) ss += (y - line.intercept - line.slope * x) * (y - line.intercept - line.slope * x);
    ev.fit_rms = std::sqrt(ss / static_cast<double>(xy.size()));
    if (!(line.slope > 0.0) || ev.fit_rms > o.max_fit_rms) {
      reject(LatencyRejection::kFitResidual);
      continue;
    }
    const double start = -line.intercept / line.slope;  // row 0's time of the motion's start, less the command's
    ev.motion_stamp_s = command + start;
    ev.latency_s = start - o.actuation_delay_s;
    used_latencies.push_back(ev.latency_s);
    est.events.push_back(ev);
  }

  est.events_used = static_cast<int>(used_latencies.size());
  est.events_rejected = static_cast<int>(est.events.size()) - est.events_used;
  if (est.events_used < 3) {
    std::string why = "latency: only " + std::to_string(est.events_used) + " of " +
                      std::to_string(est.events.size()) + " events usable";
    std::string list;
    for (std::size_t i = 0; i < est.events.size(); ++i) {
      if (est.events[i].used()) continue;
      list += (list.empty() ? "" : ", ") + std::string("event ") + std::to_string(i + 1) + ": " +
              to_string(est.events[i].rejection);
    }
    // The one cause a setting cures: the stroke's start is over within a frame or two.
    const bool short_of_frames = std::any_of(est.events.begin(), est.events.end(), [](const LatencyEvent& ev) {
      return ev.rejection == LatencyRejection::kTooFewFitFrames;
    });
    const std::string hint = short_of_frames ? "; too few frames in the fit window: the flipper's stroke starts within "
                                               "fewer frames than the fit needs at this frame rate: run the camera "
                                               "faster (--fps)"
                                             : "";
    throw std::runtime_error(why + (list.empty() ? "" : " (" + list + ")") + hint);
  }
  for (const LatencyEvent& ev : est.events) {
    if (ev.used()) est.motion_row_px += ev.motion_row_px / est.events_used;
  }
  est.latency_s = median(used_latencies);
  RunningStats spread;
  for (const double l : used_latencies) spread.add(l);
  est.spread_s = spread.stddev();
  return est;
}

}  // namespace pinball::calibration
