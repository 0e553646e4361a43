#include "pinball/vision/ball_detector.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

#include "pinball/core/check.h"

namespace pinball::vision {
namespace {

// A pixel coordinate as an int for cv::Rect, clamped first: a prediction from
// an extreme homography or a wild velocity must not overflow the cast (UBSan's
// float-cast-overflow); the rectangles are cut to the image afterwards.
int pixel_index(double v) {
  constexpr double kFar = 1e6;
  return static_cast<int>(std::isfinite(v) ? std::clamp(v, -kFar, kFar) : 0.0);
}

// Second moments of a uniform stadium of radius 1 and length k (k = L / r), per unit area.
double stadium_major(double k) {
  return (k * k * k / 6.0 + std::numbers::pi * k * k / 4.0 + 4.0 * k / 3.0 + std::numbers::pi / 4.0) /
         (std::numbers::pi + 2.0 * k);
}
double stadium_minor(double k) { return (2.0 * k / 3.0 + std::numbers::pi / 4.0) / (std::numbers::pi + 2.0 * k); }

// The stadium (radius r, straight length L) with major and minor variances l1 >= l2.
void fit_stadium(double l1, double l2, double& r, double& length) {
  const double target = l1 / l2;
  double lo = 0.0;
  double hi = 40.0;
  for (int i = 0; i < 40; ++i) {  // l1/l2 grows with k
    const double mid = 0.5 * (lo + hi);
    if (stadium_major(mid) / stadium_minor(mid) < target) {
      lo = mid;
    } else {
      hi = mid;
    }
  }
  const double k = 0.5 * (lo + hi);
  r = std::sqrt(l2 / stadium_minor(k));
  length = k * r;
}

// A ball cut loose by the opening keeps nearly all its area; less is a ball
// partly eaten by the opening or a lump of something else.
constexpr double kMinSeparatedAreaRatio = 0.85;
// Blobs opened are at most this many balls' area: a ball and a flipper make
// about 3; a glare patch or a lit insert many more, and opening those would
// cost a whole-frame search's time for nothing.
constexpr double kMaxSplitAreaRatio = 8.0;

}  // namespace

const char* to_string(DetectionMiss miss) {
  switch (miss) {
    case DetectionMiss::kNone: return "none";
    case DetectionMiss::kBadFrame: return "bad_frame";
    case DetectionMiss::kNoBackground: return "no_background";
    case DetectionMiss::kNoBlob: return "no_blob";
    case DetectionMiss::kWrongSize: return "wrong_size";
    case DetectionMiss::kWrongShape: return "wrong_shape";
    case DetectionMiss::kOccluded: return "occluded";
    case DetectionMiss::kCut: return "cut";
  }
  return "unknown";
}

BallDetector::BallDetector(const CameraHomography& homography, cv::Size frame_size, const BallDetectorConfig& config)
    : homography_(homography), size_(frame_size), config_(config), background_(frame_size) {
  const BallDetectorConfig& c = config_;
  check_input(std::isfinite(c.ball_radius_m) && c.ball_radius_m > 0.0, "ball detector", "ball_radius_m must be > 0");
  check_input(c.threshold >= 1 && c.threshold <= 254, "ball detector", "threshold must be in [1, 254]");
  check_input(c.min_area_ratio > 0.0 && c.min_area_ratio < 1.0 && c.max_area_ratio > 1.0, "ball detector",
          "area ratios need 0 < min_area_ratio < 1 < max_area_ratio");
  check_input(c.max_elongation > 1.0, "ball detector", "max_elongation must be > 1");
  check_input(c.max_model_error > 0.0 && c.radius_tolerance > 0.0 && c.radius_tolerance < 1.0, "ball detector",
          "max_model_error must be > 0 and radius_tolerance in (0, 1)");
  check_input(c.min_fill > 0.0 && c.min_fill <= 1.0, "ball detector", "min_fill must be in (0, 1]");
  check_input(c.weight_floor_fraction >= 0.0 && c.weight_floor_fraction < 1.0, "ball detector", "weight_floor_fraction must be in [0, 1)");
  check_input(c.weight_saturation > 0.0 && c.weight_saturation <= 1.0, "ball detector", "weight_saturation must be in (0, 1]");
  check_input(c.roi_radius_factor >= 1.5, "ball detector", "roi_radius_factor must be >= 1.5");
  check_input(c.occluder_margin_px >= 0 && c.edge_margin_px >= 0, "ball detector", "margins must be >= 0");
  check_input(c.background_rate >= 0.0 && c.background_rate <= 1.0 && c.background_every >= 1, "ball detector",
          "background_rate must be in [0, 1] and background_every >= 1");
  diff_ = cv::Mat::zeros(size_, CV_8U);
  binary_ = cv::Mat::zeros(size_, CV_8U);
  stack_.resize(static_cast<std::size_t>(size_.width) * static_cast<std::size_t>(size_.height));
  halo_ = cv::Mat::zeros(size_, CV_8U);
  check_input(std::isfinite(c.separation_radius_fraction) && c.separation_radius_fraction >= 0.0 &&
              c.separation_radius_fraction < 1.0, "ball detector",
          "separation_radius_fraction must be in [0, 1)");
  check_input(c.max_separated_elongation >= 1.0, "ball detector", "max_separated_elongation must be >= 1");
  check_input(std::isfinite(c.latency_s) && c.latency_s >= 0.0 && c.latency_s <= 1.0, "ball detector",
              "latency_s must be in [0, 1] s");
  check_input(std::isfinite(c.row_time_s) && c.row_time_s >= 0.0 && c.row_time_s <= 1e-3, "ball detector",
              "row_time_s must be in [0, 0.001] s");
  check_input(c.dejitter_frames >= 0 && c.dejitter_frames <= FrameDejitter::kMaxWindow, "ball detector",
              "dejitter_frames must be in [0, " + std::to_string(FrameDejitter::kMaxWindow) + "]");
  if (c.lens) {
    check_input(c.lens->width_px == size_.width && c.lens->height_px == size_.height, "ball detector",
                "the lens was calibrated on " + std::to_string(c.lens->width_px) + "x" +
                    std::to_string(c.lens->height_px) + " images but the frames are " + std::to_string(size_.width) +
                    "x" + std::to_string(size_.height));
    undistorter_.emplace(*c.lens);
  }
  if (c.dejitter_frames > 0) dejitter_.emplace(c.frame_period_s, c.dejitter_frames);
  // The smallest ball the image holds, over a grid (half its area: the scale varies smoothly between
  // grid points). A blob under min_area_ratio of it is a speck anywhere, found without the ball's
  // expected size at its centre: through a lens that costs an undistortion, and 2 % salt noise took
  // 3.3 ms a frame instead of 0.4.
  double least_ball_px2 = std::numeric_limits<double>::infinity();
  for (int gv = 0; gv <= 12; ++gv) {
    for (int gu = 0; gu <= 16; ++gu) {
      const double r = expected_radius_px({(size_.width - 1) * gu / 16.0, (size_.height - 1) * gv / 12.0});
      if (std::isfinite(r) && r > 0.0) least_ball_px2 = std::min(least_ball_px2, std::numbers::pi * r * r);
    }
  }
  speck_area_px2_ = std::isfinite(least_ball_px2) ? 0.5 * c.min_area_ratio * least_ball_px2 : 0.0;
  split_label_ = cv::Mat::zeros(size_, CV_8U);
  split_core_ = cv::Mat::zeros(size_, CV_8U);
  split_run_ = cv::Mat::zeros(size_, CV_16S);
}

void BallDetector::set_occluder_mask(const cv::Mat& mask) {
  if (mask.empty()) {
    occluder_.release();
    return;
  }
  check_input(mask.type() == CV_8UC1 && mask.size() == size_, "ball detector", "the occluder mask must be 8-bit gray of the frame size");
  cv::Mat nonzero;
  cv::threshold(mask, nonzero, 0, 255, cv::THRESH_BINARY);
  const int m = config_.occluder_margin_px;
  if (m > 0) {
    cv::dilate(nonzero, occluder_, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * m + 1, 2 * m + 1)));
  } else {
    occluder_ = nonzero;
  }
}

double BallDetector::expected_radius_px(const cv::Point2d& uv_px) const {
  if (!undistorter_) return config_.ball_radius_m * homography_.px_per_m_at(homography_.board_from_image(uv_px));
  // Through the lens: the ideal image's scale times the lens's local area magnification there.
  const cv::Point2d ideal = undistorter_->ideal_from_distorted(uv_px);
  const CameraIntrinsics& lens = undistorter_->intrinsics();
  const cv::Point2d d0 = distort_pixel(lens, ideal);
  const cv::Point2d du = distort_pixel(lens, ideal + cv::Point2d(1.0, 0.0)) - d0;
  const cv::Point2d dv = distort_pixel(lens, ideal + cv::Point2d(0.0, 1.0)) - d0;
  const double magnification = std::sqrt(std::abs(du.x * dv.y - du.y * dv.x));
  return config_.ball_radius_m * homography_.px_per_m_at(homography_.board_from_image(ideal)) * magnification;
}

void BallDetector::fill_blob(int u, int v, const cv::Rect& region, Blob& blob) {
  const int w = size_.width;
  const int margin = std::max(2, config_.edge_margin_px);
  const int ru0 = region.x, rv0 = region.y, ru1 = region.x + region.width - 1, rv1 = region.y + region.height - 1;
  // Breadth first with a queue that keeps every pixel: afterwards stack_[0, area) is the blob.
  std::int32_t* queue = stack_.data();
  std::size_t head = 0;
  std::size_t tail = 0;
  std::uint8_t* bin = binary_.data;
  const std::uint8_t* occ = occluder_.empty() ? nullptr : occluder_.data;
  bin[v * w + u] = 0;
  queue[tail++] = v * w + u;
  blob.u0 = blob.u1 = u;
  blob.v0 = blob.v1 = v;
  while (head < tail) {
    const std::int32_t i = queue[head++];
    const int pu = i % w;
    const int pv = i / w;
    const double du = pu;
    const double dv = pv;
    blob.su += du;
    blob.sv += dv;
    blob.suu += du * du;
    blob.svv += dv * dv;
    blob.suv += du * dv;
    blob.u0 = std::min(blob.u0, pu);
    blob.u1 = std::max(blob.u1, pu);
    blob.v0 = std::min(blob.v0, pv);
    blob.v1 = std::max(blob.v1, pv);
    if (occ != nullptr && occ[i] != 0) blob.occluded = true;
    const int nu0 = std::max(pu - 1, ru0), nu1 = std::min(pu + 1, ru1);
    const int nv0 = std::max(pv - 1, rv0), nv1 = std::min(pv + 1, rv1);
    for (int nv = nv0; nv <= nv1; ++nv) {
      std::uint8_t* row = bin + nv * w;
      for (int nu = nu0; nu <= nu1; ++nu) {
        if (row[nu] == 0) continue;
        row[nu] = 0;
        queue[tail++] = nv * w + nu;
      }
    }
  }
  blob.area = static_cast<double>(tail);
  blob.at_region_edge = blob.u0 - ru0 < margin || ru1 - blob.u1 < margin || blob.v0 - rv0 < margin ||
                        rv1 - blob.v1 < margin;
}

cv::Point2d BallDetector::weighted_centroid(const Blob& blob, bool opened) {
  // Weights only on the blob and a 2 px halo around it (the anti-aliased rim
  // below the threshold), never on a neighbouring blob.
  constexpr int kHalo = 2;
  const cv::Rect box = cv::Rect(cv::Point(blob.u0 - kHalo, blob.v0 - kHalo),
                                cv::Point(blob.u1 + kHalo + 1, blob.v1 + kHalo + 1)) &
                       cv::Rect(0, 0, size_.width, size_.height);
  const int w = size_.width;
  const auto n = static_cast<std::size_t>(blob.area);
  int peak = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const std::int32_t i = stack_[k];
    peak = std::max(peak, static_cast<int>(diff_.data[i]));
    const int pu = i % w;
    const int pv = i / w;
    for (int v = std::max(pv - kHalo, box.y); v <= std::min(pv + kHalo, box.y + box.height - 1); ++v) {
      std::uint8_t* row = halo_.ptr<std::uint8_t>(v);
      for (int u = std::max(pu - kHalo, box.x); u <= std::min(pu + kHalo, box.x + box.width - 1); ++u) {
        row[u] = std::max<std::uint8_t>(row[u], 1);
      }
    }
  }
  if (opened) {
    // The rim is what lies below the threshold; foreground around the opened
    // blob belongs to the thin object the opening cut away.
    for (std::size_t k = 0; k < n; ++k) halo_.data[stack_[k]] = 2;
  }
  const double floor = config_.weight_floor_fraction * config_.threshold;
  const double cap = std::max({config_.weight_saturation * peak, static_cast<double>(config_.threshold), floor + 1.0});
  const double inv = 1.0 / (cap - floor);
  double sw = 0.0, su = 0.0, sv = 0.0;
  for (int v = box.y; v < box.y + box.height; ++v) {
    const std::uint8_t* row = diff_.ptr<std::uint8_t>(v);
    std::uint8_t* in = halo_.ptr<std::uint8_t>(v);
    for (int u = box.x; u < box.x + box.width; ++u) {
      if (in[u] == 0) continue;
      const bool removed = opened && in[u] == 1 && row[u] > config_.threshold;
      in[u] = 0;
      if (removed) continue;
      const double wgt = std::min(1.0, (row[u] - floor) * inv);
      if (wgt <= 0.0) continue;
      sw += wgt;
      su += wgt * u;
      sv += wgt * v;
    }
  }
  if (!(sw > 0.0)) return {blob.su / blob.area, blob.sv / blob.area};
  return {su / sw, sv / sw};
}

struct BallDetector::Best {
  bool have = false;
  Blob blob;
  cv::Point2d uv;
  double conf = 0.0;
  double elong = 0.0;
  double expected = 0.0;
  double model_error = 0.0;
  double r_fit = 0.0;
  bool opened = false;
  DetectionMiss worst = DetectionMiss::kNoBlob;
  double worst_closeness = 0.0;
};

bool BallDetector::search(const cv::Rect& region, bool region_is_roi, double t_s, Detection& out) {
  const cv::Mat frame = (*frame_)(region);
  const cv::Mat background = background_.image()(region);
  cv::Mat diff = diff_(region);
  cv::Mat binary = binary_(region);
  cv::absdiff(frame, background, diff);
  cv::threshold(diff, binary, config_.threshold, 255, cv::THRESH_BINARY);

  Best best;
  split_count_ = 0;
  scan(region, region, region_is_roi, false, out, best);
  // No blob passed: open the rejected ones big enough to hold a ball, which
  // cuts a ball loose from a flipper or rail it touches, and test the pieces.
  for (int k = 0; k < split_count_; ++k) {
    const auto label = static_cast<std::uint8_t>(k + 1);
    const cv::Rect& box = split_box_[static_cast<std::size_t>(k)];
    if (!best.have) {
      ++counters_.separations;
      open_split(label, box);  // also clears the candidate's labels
      scan(region, box, region_is_roi, true, out, best);
      continue;
    }
    for (int v = box.y; v < box.y + box.height; ++v) {
      std::uint8_t* row = split_label_.ptr<std::uint8_t>(v);
      for (int u = box.x; u < box.x + box.width; ++u) {
        if (row[u] == label) row[u] = 0;
      }
    }
  }
  if (!best.have) {
    if (!region_is_roi || out.miss == DetectionMiss::kNone) out.miss = best.worst;
    return false;
  }
  const cv::Point2d uv = best.uv;
  out.found = true;
  out.miss = DetectionMiss::kNone;
  out.uv_px = uv;
  out.area_px = best.blob.area;
  out.expected_area_px = best.expected;
  out.elongation = best.elong;
  out.model_error = best.model_error;
  out.radius_px = best.r_fit;
  out.from_roi = region_is_roi;
  out.separated = best.opened;
  if (undistorter_) {
    // The pixels' spread about the centroid (+ 1/12: a pixel's own extent), for the lens's second-order terms.
    const Blob& b = best.blob;
    const double mu = b.su / b.area, mv = b.sv / b.area;
    const cv::Matx22d cov(b.suu / b.area - mu * mu + 1.0 / 12.0, b.suv / b.area - mu * mv, b.suv / b.area - mu * mv,
                          b.svv / b.area - mv * mv + 1.0 / 12.0);
    out.uv_ideal_px = undistorter_->ideal_centroid(uv, cov);
  } else {
    out.uv_ideal_px = uv;
  }
  out.observation.t_s = t_s - config_.latency_s + uv.y * config_.row_time_s;
  out.observation.p_board = homography_.board_from_image(out.uv_ideal_px);
  out.observation.confidence = best.conf;
  return true;
}

void BallDetector::scan(const cv::Rect& region, const cv::Rect& box, bool region_is_roi, bool opened, Detection& out,
                        Best& best) {
  const BallDetectorConfig& c = config_;
  const double log_span = std::max(-std::log(c.min_area_ratio), std::log(c.max_area_ratio));
  for (int v = box.y; v < box.y + box.height; ++v) {
    const std::uint8_t* row = binary_.ptr<std::uint8_t>(v);
    int u = box.x;
    const int end = box.x + box.width;
    while (u < end) {
      if (u + 8 <= end) {
        std::uint64_t word;
        std::memcpy(&word, row + u, sizeof word);
        if (word == 0) {
          u += 8;
          continue;
        }
      }
      if (row[u] == 0) {
        ++u;
        continue;
      }
      Blob blob;
      fill_blob(u, v, region, blob);
      ++u;
      ++out.blobs;
      if (blob.area < 3.0 && blob.area < speck_area_px2_) continue;  // a speck anywhere in the image
      const cv::Point2d centre{blob.su / blob.area, blob.sv / blob.area};
      const double r_px = expected_radius_px(centre);
      const double expected = std::numbers::pi * r_px * r_px;
      const double ratio = blob.area / expected;
      if (blob.area < 3.0 && ratio < c.min_area_ratio) continue;  // a speck of noise: not worth a reason
      DetectionMiss reason = DetectionMiss::kNone;
      double elong = 0.0;
      double fill = 0.0;
      double model_error = 0.0;
      double r_fit = 0.0;
      if (blob.occluded) {
        reason = DetectionMiss::kOccluded;
        ++counters_.rejected_occluded;
      } else if (blob.at_region_edge) {
        reason = DetectionMiss::kCut;
        if (!region_is_roi) ++counters_.rejected_edge;
      } else if (ratio < c.min_area_ratio || ratio > c.max_area_ratio) {
        reason = DetectionMiss::kWrongSize;
        ++counters_.rejected_size;
      } else {
        // Second moments; + 1/12 turns pixel sums into the continuous figure's variance.
        const double mu20 = blob.suu / blob.area - centre.x * centre.x + 1.0 / 12.0;
        const double mu02 = blob.svv / blob.area - centre.y * centre.y + 1.0 / 12.0;
        const double mu11 = blob.suv / blob.area - centre.x * centre.y;
        const double half = 0.5 * (mu20 + mu02);
        const double root = std::sqrt(0.25 * (mu20 - mu02) * (mu20 - mu02) + mu11 * mu11);
        const double l1 = half + root;
        const double l2 = std::max(half - root, 1e-9);
        elong = std::sqrt(l1 / l2);
        fill = blob.area / (4.0 * std::numbers::pi * std::sqrt(l1 * l2));
        // A ball blurred along a line is, above the threshold, close to a
        // stadium (a rectangle of length L capped by two half discs of radius
        // r). Fit r and L to the two second moments and compare the areas: a
        // ball merged with a lamp or the edge of a glare breaks the relation
        // even when its area and elongation look right.
        double length = 0.0;
        fit_stadium(l1, l2, r_fit, length);
        const double model_area = r_fit * r_fit * std::numbers::pi + 2.0 * r_fit * length;
        model_error = std::abs(blob.area / model_area - 1.0);
        const double r_ratio = r_fit / r_px;
        // A piece cut loose by the opening must be a whole ball: nearly all of
        // its area, its radius, and little blur (see max_separated_elongation).
        const double r_tol = opened ? 0.5 * c.radius_tolerance : c.radius_tolerance;
        if (elong > (opened ? c.max_separated_elongation : c.max_elongation) || fill < c.min_fill ||
            model_error > c.max_model_error || r_ratio < 1.0 - r_tol || r_ratio > 1.0 + r_tol ||
            (opened && ratio < kMinSeparatedAreaRatio)) {
          reason = DetectionMiss::kWrongShape;
          ++counters_.rejected_shape;
        }
      }
      if (reason != DetectionMiss::kNone) {
        if (!opened && ratio >= c.min_area_ratio && ratio <= kMaxSplitAreaRatio) add_split(blob);
        // The reason reported is the one of the blob closest to a ball's size.
        const double closeness = std::abs(std::log(ratio));
        if (best.worst == DetectionMiss::kNoBlob || closeness < best.worst_closeness) {
          best.worst = reason;
          best.worst_closeness = closeness;
        }
        continue;
      }
      const double conf = std::clamp(std::min(fill, 1.0) * (1.0 - 0.5 * (elong - 1.0) / (c.max_elongation - 1.0)) *
                                         (1.0 - 0.5 * std::abs(std::log(ratio)) / log_span),
                                     0.01, 1.0);
      if (!best.have || conf > best.conf) {
        best.have = true;
        best.blob = blob;
        best.uv = weighted_centroid(blob, opened);  // now, while stack_ holds this blob's pixels
        best.conf = conf;
        best.elong = elong;
        best.expected = expected;
        best.model_error = model_error;
        best.r_fit = r_fit;
        best.opened = opened;
      }
    }
  }
}

void BallDetector::add_split(const Blob& blob) {
  if (config_.separation_radius_fraction <= 0.0 || split_count_ >= kMaxSplits) return;
  const auto label = static_cast<std::uint8_t>(split_count_ + 1);
  const auto n = static_cast<std::size_t>(blob.area);
  for (std::size_t k = 0; k < n; ++k) split_label_.data[stack_[k]] = label;
  split_box_[static_cast<std::size_t>(split_count_)] =
      cv::Rect(cv::Point(blob.u0, blob.v0), cv::Point(blob.u1 + 1, blob.v1 + 1));
  ++split_count_;
}

void BallDetector::open_split(std::uint8_t label, const cv::Rect& box) {
  // Opening by a disc of radius rho, made of horizontal chords of half-width
  // chord[dy]: a pixel survives the erosion when, on every row dy away, the
  // candidate's run through it reaches chord[dy] to both sides; the dilation
  // sets a pixel when, on some row dy away, an eroded pixel lies within
  // chord[dy]. Both read per-row run lengths, so the cost is the box's area
  // times the disc's height. Pixels of other blobs in the box are not used.
  const cv::Point2d centre(box.x + 0.5 * box.width, box.y + 0.5 * box.height);
  const double rho = config_.separation_radius_fraction * expected_radius_px(centre);
  const int r = std::min(static_cast<int>(std::floor(rho)), kMaxSplitRadius);
  std::array<std::int16_t, 2 * kMaxSplitRadius + 1> chord{};
  for (int dy = -r; dy <= r; ++dy) {
    chord[static_cast<std::size_t>(dy + r)] =
        static_cast<std::int16_t>(std::floor(std::sqrt(std::max(0.0, rho * rho - dy * dy))));
  }
  const int u0 = box.x, u1 = box.x + box.width, v0 = box.y, v1 = box.y + box.height;
  constexpr std::int16_t kFar = 10000;
  // Half run lengths: 1 + how far the candidate extends to the nearer side.
  for (int v = v0; v < v1; ++v) {
    std::uint8_t* lab = split_label_.ptr<std::uint8_t>(v);
    auto* run = split_run_.ptr<std::int16_t>(v);
    std::int16_t n = 0;
    for (int u = u0; u < u1; ++u) {
      n = lab[u] == label ? static_cast<std::int16_t>(n + 1) : std::int16_t{0};
      run[u] = n;
    }
    n = 0;
    for (int u = u1 - 1; u >= u0; --u) {
      n = lab[u] == label ? static_cast<std::int16_t>(n + 1) : std::int16_t{0};
      run[u] = std::min(run[u], n);
      if (lab[u] == label) lab[u] = 0;
    }
  }
  // Erosion.
  for (int v = v0 + r; v < v1 - r; ++v) {
    std::uint8_t* core = split_core_.ptr<std::uint8_t>(v);
    for (int u = u0; u < u1; ++u) {
      bool in = true;
      for (int dy = -r; dy <= r && in; ++dy) {
        in = split_run_.ptr<std::int16_t>(v + dy)[u] > chord[static_cast<std::size_t>(dy + r)];
      }
      core[u] = in ? 1 : 0;
    }
  }
  // Horizontal distance to the nearest eroded pixel.
  for (int v = v0; v < v1; ++v) {
    const std::uint8_t* core = split_core_.ptr<std::uint8_t>(v);
    auto* run = split_run_.ptr<std::int16_t>(v);
    std::int16_t d = kFar;
    for (int u = u0; u < u1; ++u) {
      d = core[u] != 0 ? std::int16_t{0} : static_cast<std::int16_t>(std::min<int>(d + 1, kFar));
      run[u] = d;
    }
    d = kFar;
    for (int u = u1 - 1; u >= u0; --u) {
      d = core[u] != 0 ? std::int16_t{0} : static_cast<std::int16_t>(std::min<int>(d + 1, kFar));
      run[u] = std::min(run[u], d);
    }
  }
  // Dilation into the foreground; the erosion scratch is cleared afterwards.
  for (int v = v0; v < v1; ++v) {
    std::uint8_t* bin = binary_.ptr<std::uint8_t>(v);
    for (int u = u0; u < u1; ++u) {
      bool in = false;
      for (int dy = std::max(-r, v0 - v); dy <= std::min(r, v1 - 1 - v) && !in; ++dy) {
        in = split_run_.ptr<std::int16_t>(v + dy)[u] <= chord[static_cast<std::size_t>(dy + r)];
      }
      bin[u] = in ? 255 : 0;
    }
  }
  for (int v = v0; v < v1; ++v) std::memset(split_core_.ptr<std::uint8_t>(v) + u0, 0, static_cast<std::size_t>(box.width));
}

Detection BallDetector::detect(const Frame& frame, const cv::Point2d* predicted_uv_px) {
  Detection out;
  ++counters_.frames;
  if (frame.gray.type() != CV_8UC1 || frame.gray.size() != size_) {
    ++counters_.bad_frames;
    out.miss = DetectionMiss::kBadFrame;
    return out;
  }
  // Every frame feeds the steady clock, ball or not.
  const double stamp_s = dejitter_ ? dejitter_->steady_stamp(frame.sequence, frame.t_s) : frame.t_s;
  if (!background_.ready()) {
    out.miss = DetectionMiss::kNoBackground;
    return out;
  }
  frame_ = &frame.gray;
  const cv::Rect image(0, 0, size_.width, size_.height);
  bool found = false;
  bool have_prediction = false;
  cv::Point2d predicted;
  double motion_px = 0.0;
  if (predicted_uv_px != nullptr) {
    predicted = *predicted_uv_px;
    have_prediction = std::isfinite(predicted.x) && std::isfinite(predicted.y);
  } else if (track_frames_ > 0) {
    const double dt = frame.t_s - last_t_s_;
    const cv::Point2d step = track_frames_ > 1 && std::isfinite(dt) && dt > 0.0 && dt < 0.1 ? velocity_px_ * dt
                                                                                           : cv::Point2d{0.0, 0.0};
    predicted = last_uv_px_ + step;
    motion_px = cv::norm(step);
    have_prediction = true;
  }
  if (config_.use_roi && have_prediction && predicted.x >= 0.0 && predicted.y >= 0.0 && predicted.x < image.width &&
      predicted.y < image.height) {
    const double half = config_.roi_radius_factor * expected_radius_px(predicted) + motion_px + 2.0;
    const cv::Rect roi = cv::Rect(cv::Point(pixel_index(std::floor(predicted.x - half)),
                                            pixel_index(std::floor(predicted.y - half))),
                                  cv::Point(pixel_index(std::ceil(predicted.x + half)) + 1,
                                            pixel_index(std::ceil(predicted.y + half)) + 1)) &
                         image;
    if (roi.area() > 0) found = search(roi, roi != image, stamp_s, out);
  }
  if (!found) {
    ++counters_.full_searches;
    found = search(image, false, stamp_s, out);
  }
  if (found) {
    out.observation.latency_s = frame.t_s - out.observation.t_s;
    ++counters_.found;
    if (out.from_roi) ++counters_.found_in_roi;
    if (out.separated) ++counters_.found_separated;
    const double dt = frame.t_s - last_t_s_;
    if (track_frames_ > 0 && std::isfinite(dt) && dt > 0.0) velocity_px_ = (out.uv_px - last_uv_px_) * (1.0 / dt);
    last_uv_px_ = out.uv_px;
    last_t_s_ = frame.t_s;
    ++track_frames_;
  } else {
    track_frames_ = 0;
  }
  if (config_.background_rate > 0.0 && counters_.frames % static_cast<std::uint64_t>(config_.background_every) == 0) {
    cv::Rect exclude;
    if (found || have_prediction) {
      const cv::Point2d c = found ? out.uv_px : predicted;
      const double half = 2.5 * expected_radius_px(c) + motion_px + 4.0;
      exclude = cv::Rect(cv::Point(pixel_index(c.x - half), pixel_index(c.y - half)),
                         cv::Point(pixel_index(c.x + half) + 1, pixel_index(c.y + half) + 1));
    }
    background_.update(frame.gray, config_.background_rate, exclude);
  }
  frame_ = nullptr;
  return out;
}

}  // namespace pinball::vision
