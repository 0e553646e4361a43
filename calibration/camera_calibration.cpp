#include "pinball/calibration/camera_calibration.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include <Eigen/Dense>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "pinball/core/format.h"
#include "pinball/core/read_archive.h"

namespace pinball::calibration {
namespace {

// Twice the area of triangle abc over the square of its longest side: 0 for
// collinear points, about 0.87 for an equilateral triangle; scale-free.
double triangle_shape(const Vec2& a, const Vec2& b, const Vec2& c) {
  const double longest = std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
  if (!(longest > 0.0)) return 0.0;
  return std::abs(cross(b - a, c - a)) / longest;
}

// A triple whose shape is below this is "nearly collinear" (about 1 degree).
constexpr double kCollinear = 0.02;

// The worst triangle of a quadruple: how well four points define a homography.
double quad_shape(const std::array<Vec2, 4>& q) {
  return std::min({triangle_shape(q[0], q[1], q[2]), triangle_shape(q[0], q[1], q[3]), triangle_shape(q[0], q[2], q[3]),
                   triangle_shape(q[1], q[2], q[3])});
}

// Homography mapping four board points to four image points (DLT, double).
bool homography_from_4(const std::array<Vec2, 4>& b, const std::array<cv::Point2d, 4>& uv, cv::Matx33d& h) {
  Eigen::Matrix<double, 8, 8> a;
  Eigen::Matrix<double, 8, 1> r;
  for (int i = 0; i < 4; ++i) {
    const double x = b[i].x(), y = b[i].y(), u = uv[i].x, v = uv[i].y;
    a.row(2 * i) << x, y, 1.0, 0.0, 0.0, 0.0, -u * x, -u * y;
    a.row(2 * i + 1) << 0.0, 0.0, 0.0, x, y, 1.0, -v * x, -v * y;
    r(2 * i) = u;
    r(2 * i + 1) = v;
  }
  Eigen::FullPivLU<Eigen::Matrix<double, 8, 8>> lu(a);
  if (!lu.isInvertible()) return false;
  const Eigen::Matrix<double, 8, 1> s = lu.solve(r);
  h = cv::Matx33d(s(0), s(1), s(2), s(3), s(4), s(5), s(6), s(7), 1.0);
  return std::isfinite(s.sum());
}

bool project(const cv::Matx33d& h, const Vec2& p, cv::Point2d& uv, double& w) {
  const cv::Vec3d q = h * cv::Vec3d(p.x(), p.y(), 1.0);
  w = q[2];
  if (!(std::abs(w) > 1e-12)) return false;
  uv = {q[0] / w, q[1] / w};
  return true;
}

// Layout -> detection assignment for homography h (−1: unmatched); returns the
// matched count and the sum of squared distances.
int assign(const cv::Matx33d& h, std::span<const Vec2> layout, std::span<const DetectedMarker> det, double tol_px,
           double w_sign, std::vector<int>& out, double& sse) {
  out.assign(layout.size(), -1);
  sse = 0.0;
  int count = 0;
  for (std::size_t j = 0; j < layout.size(); ++j) {
    cv::Point2d uv;
    double w = 0.0;
    if (!project(h, layout[j], uv, w) || w * w_sign <= 0.0) continue;  // behind the camera
    int best = -1;
    double best_d2 = tol_px * tol_px;
    for (std::size_t i = 0; i < det.size(); ++i) {
      const cv::Point2d d = det[i].uv_px - uv;
      const double d2 = d.dot(d);
      if (d2 <= best_d2) {
        best_d2 = d2;
        best = static_cast<int>(i);
      }
    }
    if (best < 0 || std::find(out.begin(), out.end(), best) != out.end()) continue;
    out[j] = best;
    sse += best_d2;
    ++count;
  }
  return count;
}

}  // namespace

std::vector<DetectedMarker> detect_markers(const cv::Mat& gray, const MarkerDetectorConfig& c) {
  if (gray.empty() || gray.type() != CV_8UC1) throw std::invalid_argument("detect_markers: the image must be 8-bit gray");
  cv::Mat binary, labels, stats, centroids;
  cv::threshold(gray, binary, c.threshold, 255, cv::THRESH_BINARY);
  const int n = cv::connectedComponentsWithStats(binary, labels, stats, centroids, 8, CV_32S);
  std::vector<DetectedMarker> out;
  for (int k = 1; k < n; ++k) {
    const double area = stats.at<int>(k, cv::CC_STAT_AREA);
    if (area < c.min_area_px || area > c.max_area_px) continue;
    const cv::Rect box(stats.at<int>(k, cv::CC_STAT_LEFT), stats.at<int>(k, cv::CC_STAT_TOP),
                       stats.at<int>(k, cv::CC_STAT_WIDTH), stats.at<int>(k, cv::CC_STAT_HEIGHT));
    // Second moments of the blob: a disc seen through a homography is an ellipse.
    double su = 0.0, sv = 0.0, suu = 0.0, svv = 0.0, suv = 0.0, sum_gray = 0.0;
    for (int v = box.y; v < box.y + box.height; ++v) {
      const int* row = labels.ptr<int>(v);
      const std::uint8_t* g = gray.ptr<std::uint8_t>(v);
      for (int u = box.x; u < box.x + box.width; ++u) {
        if (row[u] != k) continue;
        su += u;
        sv += v;
        suu += static_cast<double>(u) * u;
        svv += static_cast<double>(v) * v;
        suv += static_cast<double>(u) * v;
        sum_gray += g[u];
      }
    }
    const double cu = su / area, cv_ = sv / area;
    const double mu20 = suu / area - cu * cu + 1.0 / 12.0;
    const double mu02 = svv / area - cv_ * cv_ + 1.0 / 12.0;
    const double mu11 = suv / area - cu * cv_;
    const double half = 0.5 * (mu20 + mu02);
    const double root = std::sqrt(0.25 * (mu20 - mu02) * (mu20 - mu02) + mu11 * mu11);
    const double l1 = half + root;
    const double l2 = std::max(half - root, 1e-9);
    if (std::sqrt(l1 / l2) > c.max_elongation) continue;
    if (area / (4.0 * std::numbers::pi * std::sqrt(l1 * l2)) < c.min_fill) continue;
    // Surround: a band just outside the blob (the sticker's dark ring).
    const double r = 2.0 * std::sqrt(l1);  // semi-major axis of the moment ellipse (px)
    const double band0 = r + 1.0, band1 = r + std::max(2.0, 0.4 * r);
    const cv::Rect outer = cv::Rect(cv::Point(static_cast<int>(std::floor(cu - band1)), static_cast<int>(std::floor(cv_ - band1))),
                                    cv::Point(static_cast<int>(std::ceil(cu + band1)) + 1,
                                              static_cast<int>(std::ceil(cv_ + band1)) + 1)) &
                           cv::Rect(0, 0, gray.cols, gray.rows);
    double ring_sum = 0.0;
    int ring_n = 0;
    for (int v = outer.y; v < outer.y + outer.height; ++v) {
      const std::uint8_t* g = gray.ptr<std::uint8_t>(v);
      for (int u = outer.x; u < outer.x + outer.width; ++u) {
        const double d = std::hypot(u - cu, v - cv_);
        if (d < band0 || d > band1) continue;
        ring_sum += g[u];
        ++ring_n;
      }
    }
    if (ring_n == 0) continue;
    const double surround = ring_sum / ring_n;
    const double contrast = sum_gray / area - surround;
    if (contrast < c.min_ring_contrast) continue;
    // Sub-pixel centre: weights ramp from a quarter to three quarters of the
    // contrast, so the anti-aliased rim counts symmetrically on every side.
    const double lo = surround + 0.25 * contrast, hi = surround + 0.75 * contrast;
    double sw = 0.0, swu = 0.0, swv = 0.0;
    for (int v = outer.y; v < outer.y + outer.height; ++v) {
      const std::uint8_t* g = gray.ptr<std::uint8_t>(v);
      for (int u = outer.x; u < outer.x + outer.width; ++u) {
        if (std::hypot(u - cu, v - cv_) > band0) continue;
        const double w = std::clamp((g[u] - lo) / (hi - lo), 0.0, 1.0);
        sw += w;
        swu += w * u;
        swv += w * v;
      }
    }
    if (!(sw > 0.0)) continue;
    out.push_back({cv::Point2d(swu / sw, swv / sw), area, contrast});
  }
  std::sort(out.begin(), out.end(), [](const DetectedMarker& a, const DetectedMarker& b) { return a.contrast > b.contrast; });
  if (static_cast<int>(out.size()) > c.max_markers) out.resize(static_cast<std::size_t>(std::max(c.max_markers, 0)));
  return out;
}

void check_marker_layout(std::span<const Vec2> p, double min_separation_m, std::span<const int> source_lines) {
  const std::size_t n = p.size();
  if (n < 4) {
    throw std::invalid_argument("marker layout: " + std::to_string(n) + " markers; a homography needs at least 4");
  }
  if (n > static_cast<std::size_t>(kMaxLayoutMarkers)) {
    throw std::invalid_argument("marker layout: " + std::to_string(n) + " markers; at most " +
                                std::to_string(kMaxLayoutMarkers) +
                                " (the detector keeps as many, and matching tries every four of them)");
  }
  // "markers 1 and 4" (from 1), or "the markers of lines 2 and 5" of a file.
  const bool by_line = source_lines.size() == n;
  const auto number = [&](std::size_t i) {
    return std::to_string(by_line ? source_lines[i] : static_cast<int>(i + 1));
  };
  const std::string some = by_line ? "the markers of lines " : "markers ";
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(p[i].x()) || !std::isfinite(p[i].y())) {
      throw std::invalid_argument("marker layout: " + std::string(by_line ? "the marker of line " : "marker ") +
                                  number(i) + " is not finite");
    }
    for (std::size_t j = i + 1; j < n; ++j) {
      if ((p[i] - p[j]).norm() < min_separation_m) {
        throw std::invalid_argument("marker layout: " + some + number(i) + " and " + number(j) +
                                    " coincide (closer than " + format_number(min_separation_m * 1e3) + " mm)");
      }
    }
  }
  // Four markers with no three on a line, or the homography is not determined.
  std::array<std::size_t, 3> worst{0, 1, 2};
  double worst_shape = 1e300;
  for (std::size_t a = 0; a < n; ++a) {
    for (std::size_t b = a + 1; b < n; ++b) {
      for (std::size_t c = b + 1; c < n; ++c) {
        const double s = triangle_shape(p[a], p[b], p[c]);
        if (s < worst_shape) {
          worst_shape = s;
          worst = {a, b, c};
        }
        if (s < kCollinear) continue;
        for (std::size_t d = c + 1; d < n; ++d) {
          if (quad_shape({p[a], p[b], p[c], p[d]}) >= kCollinear) return;
        }
      }
    }
  }
  std::ostringstream msg;
  msg << "marker layout: no four markers without three (nearly) collinear";
  if (n == 4 || worst_shape < kCollinear) {
    msg << " (" << some << number(worst[0]) << ", " << number(worst[1]) << ", " << number(worst[2])
        << " are collinear)";
  }
  throw std::invalid_argument(msg.str());
}

std::vector<Vec2> default_marker_layout(const table::Board& board) {
  // Fractions of the table; no reflection or rotation maps this set onto itself.
  static constexpr std::array<std::array<double, 2>, 7> kFractions{
      {{0.08, 0.05}, {0.93, 0.07}, {0.06, 0.95}, {0.90, 0.93}, {0.55, 0.30}, {0.25, 0.62}, {0.72, 0.70}}};
  std::vector<Vec2> out;
  for (const auto& f : kFractions) out.emplace_back(f[0] * board.width_m, f[1] * board.height_m);
  return out;
}

std::vector<Vec2> read_marker_layout_csv(const std::string& path, const table::Board& board) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::string line;
  int line_no = 0;
  std::vector<Vec2> out;
  std::vector<int> lines;  // each marker's line, for the layout check's messages
  bool header = false;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    if (!header) {
      if (line != "x,y") throw std::runtime_error(path + ":" + std::to_string(line_no) + ": header must be x,y");
      header = true;
      continue;
    }
    std::istringstream s(line);
    double x = 0.0, y = 0.0;
    char comma = 0;
    // Nothing after y: '0.0535abc' or a third column is no marker position.
    if (!(s >> x >> comma >> y) || comma != ',' || !std::isfinite(x) || !std::isfinite(y) || !(s >> std::ws).eof()) {
      throw std::runtime_error(path + ":" + std::to_string(line_no) + ": expected two numbers x,y (m), got " +
                               quote_value(line));
    }
    // Markers sit on the playfield or its rim; farther off is a unit or a file mistaken.
    if (!table::near_playfield(board, Vec2(x, y))) {
      throw std::runtime_error(path + ":" + std::to_string(line_no) + ": marker (" + format_number(x) + ", " +
                               format_number(y) + ") m is " + table::off_playfield_text(board) +
                               " (positions are in metres, board frame)");
    }
    out.emplace_back(x, y);
    lines.push_back(line_no);
  }
  if (!header) throw std::runtime_error(path + ":1: header must be x,y");
  try {
    check_marker_layout(out, 0.01, lines);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
  return out;
}

HomographyFit fit_homography(std::span<const DetectedMarker> det, std::span<const Vec2> layout, cv::Size image_size,
                             const HomographyFitConfig& config) {
  check_marker_layout(layout);
  const int m = static_cast<int>(layout.size());
  if (m < 5) {
    throw std::runtime_error("camera calibration: " + std::to_string(m) +
                             " markers cannot be matched without knowing which is which; use at least 5");
  }
  const int nd = static_cast<int>(det.size());
  if (nd < config.min_markers) {
    throw std::runtime_error("camera calibration: " + std::to_string(nd) + " markers detected, at least " +
                             std::to_string(config.min_markers) + " needed");
  }
  // Base quadruples of the layout, best conditioned first: every ordered
  // choice of four detections for one of them is a hypothesis.
  std::vector<std::pair<double, std::array<int, 4>>> bases;
  for (int a = 0; a < m; ++a)
    for (int b = a + 1; b < m; ++b)
      for (int c = b + 1; c < m; ++c)
        for (int d = c + 1; d < m; ++d)
          bases.push_back({quad_shape({layout[a], layout[b], layout[c], layout[d]}), {a, b, c, d}});
  std::sort(bases.begin(), bases.end(), [](const auto& x, const auto& y) { return x.first > y.first; });
  bases.resize(std::min<std::size_t>(bases.size(), 3));

  std::vector<int> best, current, rival;
  int best_count = 0;
  double best_sse = 0.0;
  for (const auto& base : bases) {
    const std::array<Vec2, 4> b{layout[base.second[0]], layout[base.second[1]], layout[base.second[2]],
                                layout[base.second[3]]};
    for (int i0 = 0; i0 < nd; ++i0)
      for (int i1 = 0; i1 < nd; ++i1)
        for (int i2 = 0; i2 < nd; ++i2)
          for (int i3 = 0; i3 < nd; ++i3) {
            if (i0 == i1 || i0 == i2 || i0 == i3 || i1 == i2 || i1 == i3 || i2 == i3) continue;
            cv::Matx33d h;
            if (!homography_from_4(b, {det[i0].uv_px, det[i1].uv_px, det[i2].uv_px, det[i3].uv_px}, h)) continue;
            cv::Point2d uv;
            double w0 = 0.0;
            if (!project(h, b[0], uv, w0)) continue;
            double sse = 0.0;
            const int count = assign(h, layout, det, config.match_tolerance_px, w0 > 0.0 ? 1.0 : -1.0, current, sse);
            if (count < 4) continue;
            if (count > best_count) {
              best_count = count;
              best_sse = sse;
              best = current;
              rival.clear();
            } else if (count == best_count && current == best) {
              best_sse = std::min(best_sse, sse);
            } else if (count == best_count) {
              rival = current;  // as many markers agree with another assignment
              if (sse < best_sse) {
                std::swap(rival, best);
                best_sse = sse;
              }
            }
          }
  }
  if (best_count < config.min_markers) {
    throw std::runtime_error("camera calibration: only " + std::to_string(best_count) + " of " + std::to_string(m) +
                             " markers could be matched (" + std::to_string(nd) + " detected)");
  }
  if (!rival.empty()) {
    // The same spots matched two ways is the layout's symmetry; other spots
    // matched as well as the markers are something bright that is no marker.
    const auto spots = [](const std::vector<int>& assignment) {
      std::vector<int> s;
      for (int d : assignment)
        if (d >= 0) s.push_back(d);
      std::sort(s.begin(), s.end());
      return s;
    };
    const std::string count = std::to_string(best_count) + " markers each, " + std::to_string(nd) +
                              " spots detected for " + std::to_string(m) + " markers";
    if (spots(rival) != spots(best)) {
      throw std::runtime_error("camera calibration: two sets of spots match the layout equally well (" + count +
                               "); the spots that are no marker (reflections, lamps) need covering");
    }
    throw std::runtime_error("camera calibration: the markers match the layout in more than one way (" + count +
                             "); the layout is (nearly) symmetric");
  }

  HomographyFit fit;
  fit.detections = nd;
  std::vector<cv::Point2d> src, dst;
  std::vector<Vec2> matched;
  for (int j = 0; j < m; ++j) {
    if (best[j] < 0) continue;
    MarkerMatch mm;
    mm.layout_index = j;
    mm.detection_index = best[j];
    mm.board = layout[j];
    mm.uv_px = det[best[j]].uv_px;
    fit.matches.push_back(mm);
    src.emplace_back(layout[j].x(), layout[j].y());
    dst.push_back(mm.uv_px);
    matched.push_back(layout[j]);
  }
  check_marker_layout(matched);
  std::vector<unsigned char> mask;
  const cv::Mat h = cv::findHomography(src, dst, cv::RANSAC, config.ransac_threshold_px, mask);
  if (h.empty()) throw std::runtime_error("camera calibration: cv::findHomography found no homography");
  CameraCalibration& cal = fit.calibration;
  cal.image_from_board = cv::Matx33d(h.ptr<double>());
  cal.image_from_board *= 1.0 / cal.image_from_board(2, 2);
  cal.image_width_px = image_size.width;
  cal.image_height_px = image_size.height;
  double ss = 0.0;
  for (std::size_t k = 0; k < fit.matches.size(); ++k) {
    MarkerMatch& mm = fit.matches[k];
    cv::Point2d uv;
    double w = 0.0;
    project(cal.image_from_board, mm.board, uv, w);
    mm.residual_px = cv::norm(uv - mm.uv_px);
    mm.inlier = mask.empty() || mask[k] != 0;
    if (!mm.inlier) continue;
    ++cal.markers_used;
    ss += mm.residual_px * mm.residual_px;
    cal.reprojection_max_px = std::max(cal.reprojection_max_px, mm.residual_px);
  }
  if (cal.markers_used < config.min_markers) {
    throw std::runtime_error("camera calibration: only " + std::to_string(cal.markers_used) +
                             " markers agree with one homography");
  }
  cal.reprojection_rms_px = std::sqrt(ss / cal.markers_used);
  return fit;
}

void undistort_markers(std::vector<DetectedMarker>& markers, const vision::CameraIntrinsics& lens) {
  const vision::PointUndistorter undistorter(lens);
  for (DetectedMarker& m : markers) m.uv_px = undistorter.ideal_from_distorted(m.uv_px);
}

HomographyFit calibrate_camera(const cv::Mat& gray, std::span<const Vec2> layout, const MarkerDetectorConfig& detector,
                               const HomographyFitConfig& config, const std::optional<vision::CameraIntrinsics>& lens) {
  std::vector<DetectedMarker> det = detect_markers(gray, detector);
  if (lens) {
    check_input(lens->width_px == gray.cols && lens->height_px == gray.rows, "calibrate camera",
                "the lens was calibrated on " + std::to_string(lens->width_px) + "x" + std::to_string(lens->height_px) +
                    " images but this image is " + std::to_string(gray.cols) + "x" + std::to_string(gray.rows));
    undistort_markers(det, *lens);
  }
  return fit_homography(det, layout, gray.size(), config);
}

}  // namespace pinball::calibration
