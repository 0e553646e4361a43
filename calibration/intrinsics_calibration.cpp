#include "pinball/calibration/intrinsics_calibration.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "charuco_board.h"
#include "pinball/plot/draw.h"
#include "pinball/plot/ticks.h"

namespace pinball::calibration {
namespace {

std::string size_text(const cv::Size& s) { return std::to_string(s.width) + "x" + std::to_string(s.height); }

std::string number(const char* format, double x) {
  char buf[48];
  std::snprintf(buf, sizeof buf, format, x);
  return buf;
}

// The distance between the nearest two corners (px): a square's side where the board looks smallest.
double nearest_spacing(const std::vector<cv::Point2f>& corners) {
  double nearest = 1e9;
  for (std::size_t i = 0; i < corners.size(); ++i) {
    for (std::size_t k = i + 1; k < corners.size(); ++k) nearest = std::min(nearest, cv::norm(corners[i] - corners[k]));
  }
  return nearest;
}

// Refines corners in place to the saddle point of the gray levels, in a window of half side `half` px.
void refine(const cv::Mat& gray, std::vector<cv::Point2f>& corners, int half) {
  cv::cornerSubPix(gray, corners, cv::Size(half, half), cv::Size(-1, -1),
                   cv::TermCriteria(cv::TermCriteria::EPS | cv::TermCriteria::COUNT, 100, 1e-4));
}

TargetDetection detect_chessboard(const cv::Mat& gray, const TargetSpec& t) {
  TargetDetection d;
  const cv::Size pattern(t.squares_x - 1, t.squares_y - 1);
  std::vector<cv::Point2f> corners;
  // FAST_CHECK gives up quickly on an image without a chessboard.
  const int flags = cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_FAST_CHECK;
  if (!cv::findChessboardCorners(gray, pattern, corners, flags)) {
    d.why = "target not found";
    return d;
  }
  // A window large enough to gather the corner's edges, well short of the next corner.
  refine(gray, corners, std::clamp(static_cast<int>(0.35 * nearest_spacing(corners)), 2, 10));
  for (std::size_t i = 0; i < corners.size(); ++i) {
    d.corners_px.emplace_back(corners[i].x, corners[i].y);
    d.ids.push_back(static_cast<int>(i));
  }
  return d;
}

// Whether grid points are (nearly) on one line: no fit can use them.
bool collinear(const std::vector<cv::Point3d>& points) {
  cv::Mat m(static_cast<int>(points.size()), 2, CV_64F);
  for (int i = 0; i < m.rows; ++i) {
    m.at<double>(i, 0) = points[static_cast<std::size_t>(i)].x;
    m.at<double>(i, 1) = points[static_cast<std::size_t>(i)].y;
  }
  cv::PCA pca(m, cv::noArray(), cv::PCA::DATA_AS_ROW);
  const double spread = std::sqrt(std::max(0.0, pca.eigenvalues.at<double>(1)));
  return spread < 1e-3 * std::sqrt(std::max(1e-30, pca.eigenvalues.at<double>(0)));
}

TargetDetection detect_charuco(const cv::Mat& gray, const TargetSpec& t, const IntrinsicsFitConfig& config) {
  TargetDetection d;
  const cv::Ptr<cv::aruco::CharucoBoard> board = detail::make_charuco_board(t);
  std::vector<std::vector<cv::Point2f>> marker_corners, rejected;
  std::vector<int> marker_ids;
  cv::aruco::detectMarkers(gray, board->dictionary, marker_corners, marker_ids,
                           cv::aruco::DetectorParameters::create(), rejected);
  // Markers the first pass missed, where the board says they must be.
  if (!marker_ids.empty()) {
    cv::aruco::refineDetectedMarkers(gray, board, marker_corners, marker_ids, rejected);
  }
  std::vector<cv::Point2f> corners;
  std::vector<int> ids;
  if (!marker_ids.empty()) {
    // Without a camera matrix: each corner from the homography of its neighbouring markers, then cornerSubPix.
    cv::aruco::interpolateCornersCharuco(marker_corners, marker_ids, gray, board, corners, ids);
  }
  if (corners.empty()) {
    d.why = "target not found";
    return d;
  }
  if (static_cast<int>(corners.size()) < config.min_corners) {
    d.why = "only " + std::to_string(corners.size()) + " ChArUco corners";
    return d;
  }
  // OpenCV 4.6 returns every corner half a pixel right and down: its
  // refinement shifts the corners by half a pixel into cornerSubPix's
  // convention and back out, though cornerSubPix works in image coordinates
  // (opencv/opencv_contrib#3024; undone later by opencv/opencv#28380).
  // Refine them again, in a window clear of the markers: its half side is
  // the white squares' margin around a marker, (square - marker) / 2, at the
  // scale of the nearest two corners.
  const double margin = (t.square_m - t.marker_m) / (2.0 * t.square_m);
  refine(gray, corners, std::clamp(static_cast<int>(margin * nearest_spacing(corners)), 2, 10));
  const std::vector<cv::Point3d> all = target_points_m(t);
  std::vector<cv::Point3d> seen;
  for (const int id : ids) seen.push_back(all[static_cast<std::size_t>(id)]);
  if (collinear(seen)) {
    d.why = "the " + std::to_string(corners.size()) + " ChArUco corners found lie on one line";
    return d;
  }
  for (std::size_t i = 0; i < corners.size(); ++i) d.corners_px.emplace_back(corners[i].x, corners[i].y);
  d.ids = ids;
  return d;
}

// One image that shows the target, in the fit.
struct View {
  std::size_t image = 0;                 // index into the inputs
  std::vector<cv::Point3f> object_m;     // corners on the target (m)
  std::vector<cv::Point2f> image_px;     // where they were seen (px)
};

struct LensFit {
  cv::Matx33d k;
  cv::Mat d;
  std::vector<std::vector<cv::Point2d>> reprojected_px;  // per view
  std::vector<double> rms_px;                            // per view
  double rms_px_all = 0.0;
};

// cv::calibrateCamera's flags: none at first. Every pinhole parameter is
// fitted (fx and fy apart: a sensor's pixels need not be square; the principal
// point free: a lens is never centred exactly) and all five coefficients k1 k2
// p1 p2 k3 of the file's lens model, from the views' homographies (no
// intrinsic guess). Then k3 stays only where the views determine it: when
// |k3| is under kK3Significance of its standard error (calibrateCamera's
// stdDeviationsIntrinsics), the fit is repeated with CALIB_FIX_K3 (k3 = 0).
// A k3 the views do not pin down fits their corners no better but bends the
// model where no corner was seen; a k3 the lens has and the fit lacks bends
// it the other way. Measured on simulated chessboard views, 8 seeds each,
// the largest distortion error over the image (over the whole sensor):
//   the simulated lens (k3 = 0), 12 views: k3 free 0.61 px (2.2), this rule
//     0.30 px (0.51), the same as k3 fixed;
//   a lens with k1 -0.32, k2 0.14, k3 -0.03, 12 views: fixed 0.50 px (4.1),
//     free 0.28 px (1.3), this rule 0.35 px (3.2: one seed's k3 was under
//     3 standard errors); 20 views: fixed 0.46 px (4.0), free and this rule
//     0.17 px (1.0).
// 3 standard errors, not 2: at 2 one of 16 fits of the k3 = 0 lens kept a k3
// of -0.022 and was 0.61 px off (2.2 over the sensor).
constexpr int kCalibrationFlags = 0;
constexpr double kK3Significance = 3.0;

LensFit fit_lens(const std::vector<View>& views, const cv::Size& size) {
  std::vector<std::vector<cv::Point3f>> object;
  std::vector<std::vector<cv::Point2f>> image;
  for (const View& v : views) {
    object.push_back(v.object_m);
    image.push_back(v.image_px);
  }
  cv::Mat k, d, sd_intrinsics, sd_extrinsics, per_view;
  std::vector<cv::Mat> rvecs, tvecs;
  const cv::TermCriteria criteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 200, 1e-15);
  try {
    cv::calibrateCamera(object, image, size, k, d, rvecs, tvecs, sd_intrinsics, sd_extrinsics, per_view,
                        kCalibrationFlags, criteria);
    // k3 only where the views determine it (sd_intrinsics: fx fy cx cy k1 k2 p1 p2 k3 ...).
    const double k3 = d.at<double>(0, 4), sd_k3 = sd_intrinsics.at<double>(8, 0);
    if (!(std::abs(k3) >= kK3Significance * sd_k3)) {
      cv::calibrateCamera(object, image, size, k, d, rvecs, tvecs, kCalibrationFlags | cv::CALIB_FIX_K3, criteria);
    }
  } catch (const cv::Exception& e) {
    throw std::runtime_error("intrinsics: cv::calibrateCamera failed (" + e.err +
                             "): the views do not determine the lens; take more, tilted ones");
  }
  LensFit f;
  f.k = cv::Matx33d(k);
  f.d = d.clone();
  double sum2 = 0.0;
  std::size_t n = 0;
  for (std::size_t i = 0; i < views.size(); ++i) {
    std::vector<cv::Point2f> projected;
    cv::projectPoints(views[i].object_m, rvecs[i], tvecs[i], k, d, projected);
    double view2 = 0.0;
    std::vector<cv::Point2d> out;
    for (std::size_t p = 0; p < projected.size(); ++p) {
      const cv::Point2d e = cv::Point2d(projected[p]) - cv::Point2d(views[i].image_px[p]);
      view2 += e.dot(e);
      out.emplace_back(projected[p].x, projected[p].y);
    }
    sum2 += view2;
    n += projected.size();
    f.rms_px.push_back(std::sqrt(view2 / static_cast<double>(projected.size())));
    f.reprojected_px.push_back(std::move(out));
  }
  f.rms_px_all = std::sqrt(sum2 / static_cast<double>(n));
  return f;
}

std::string rejected_list(const std::vector<ImageResult>& images) {
  std::string out;
  for (const ImageResult& r : images) {
    if (r.rejection.empty()) continue;
    out += (out.empty() ? "" : ", ") + r.name + " " + r.rejection;
  }
  return out;
}

}  // namespace

RangeViolation check_intrinsics_fit_config(const IntrinsicsFitConfig& c) {
  if (c.min_images < 3) return {"min_images", "must be >= 3"};
  if (!std::isfinite(c.max_image_rms_px) || !(c.max_image_rms_px > 0.0)) return {"max_image_rms_px", "must be > 0 px"};
  if (c.min_corners < 6) return {"min_corners", "must be >= 6"};
  return {};
}

TargetDetection detect_target(const cv::Mat& gray, const TargetSpec& target, const IntrinsicsFitConfig& config) {
  check_input(check_target(target), "target");
  check_input(check_intrinsics_fit_config(config), "intrinsics fit");
  check_input(!gray.empty() && gray.type() == CV_8UC1, "detect_target", "expected an 8-bit gray image");
  return target.kind == TargetKind::kChessboard ? detect_chessboard(gray, target) : detect_charuco(gray, target, config);
}

IntrinsicsFit calibrate_intrinsics(std::span<const TargetImage> images, const TargetSpec& target,
                                   const IntrinsicsFitConfig& config,
                                   const std::function<void(std::size_t searched)>& searched) {
  check_input(check_target(target), "target");
  check_input(check_intrinsics_fit_config(config), "intrinsics fit");
  if (images.empty()) throw std::runtime_error("intrinsics: no images");
  // Every image 8-bit gray and of the first one's size, before any work.
  const cv::Size size = images[0].gray.size();
  for (const TargetImage& im : images) {
    if (im.gray.empty()) throw std::runtime_error(im.name + ": empty image");
    if (im.gray.type() != CV_8UC1) {
      throw std::runtime_error(im.name + ": not an 8-bit gray image (" + std::to_string(im.gray.channels()) +
                               " channels, " + std::to_string(8 * im.gray.elemSize1()) + "-bit)");
    }
    if (im.gray.size() != size) {
      throw std::runtime_error(im.name + ": " + size_text(im.gray.size()) + ", but " + images[0].name + " is " +
                               size_text(size));
    }
  }
  IntrinsicsFit fit;
  const std::vector<cv::Point3d> points = target_points_m(target);
  std::vector<View> views;
  for (std::size_t i = 0; i < images.size(); ++i) {
    ImageResult r;
    r.name = images[i].name;
    const TargetDetection d = detect_target(images[i].gray, target, config);
    r.corners = static_cast<int>(d.corners_px.size());
    r.corners_px = d.corners_px;
    r.rejection = d.why;
    if (d.why.empty()) {
      View v;
      v.image = i;
      for (std::size_t p = 0; p < d.ids.size(); ++p) {
        const cv::Point3d& o = points[static_cast<std::size_t>(d.ids[p])];
        v.object_m.emplace_back(static_cast<float>(o.x), static_cast<float>(o.y), 0.0f);
        v.image_px.emplace_back(static_cast<float>(d.corners_px[p].x), static_cast<float>(d.corners_px[p].y));
      }
      views.push_back(std::move(v));
    }
    fit.images.push_back(std::move(r));
    if (searched) searched(i + 1);
  }
  const auto too_few = [&](const char* what) {
    throw std::runtime_error("intrinsics: only " + std::to_string(views.size()) + " of " +
                             std::to_string(images.size()) + " images " + what + "; at least " +
                             std::to_string(config.min_images) + " needed (rejected: " + rejected_list(fit.images) +
                             ")");
  };
  if (static_cast<int>(views.size()) < config.min_images) too_few("show the target");
  // Fit, leave out the worst image while it is poor, fit again.
  LensFit lens = fit_lens(views, size);
  for (;;) {
    const std::size_t worst = static_cast<std::size_t>(
        std::max_element(lens.rms_px.begin(), lens.rms_px.end()) - lens.rms_px.begin());
    if (lens.rms_px[worst] <= config.max_image_rms_px) break;
    ImageResult& r = fit.images[views[worst].image];
    r.rejection = "reprojection " + number("%.3g", lens.rms_px[worst]) + " px > " +
                  number("%g", config.max_image_rms_px) + " px";
    r.reprojection_rms_px = lens.rms_px[worst];
    r.reprojected_px = lens.reprojected_px[worst];
    views.erase(views.begin() + static_cast<std::ptrdiff_t>(worst));
    if (static_cast<int>(views.size()) < config.min_images) {
      too_few(("fit within " + number("%g", config.max_image_rms_px) + " px").c_str());
    }
    lens = fit_lens(views, size);
  }
  for (std::size_t v = 0; v < views.size(); ++v) {
    ImageResult& r = fit.images[views[v].image];
    r.used = true;
    r.reprojection_rms_px = lens.rms_px[v];
    r.reprojected_px = lens.reprojected_px[v];
  }
  IntrinsicsCalibration& c = fit.calibration;
  c.lens = vision::intrinsics_from_opencv(lens.k, lens.d, size);
  if (const RangeViolation v = vision::check_intrinsics(c.lens)) {
    throw std::runtime_error("intrinsics: the fitted lens is out of range (" + v.key + " " + v.rule +
                             "): the views do not pin it down; take more, tilted, reaching the image corners");
  }
  c.target = target.describe();
  c.images_used = static_cast<int>(views.size());
  c.images_rejected = static_cast<int>(images.size() - views.size());
  c.reprojection_rms_px = lens.rms_px_all;
  return fit;
}

LensComparison compare_lenses(const vision::CameraIntrinsics& lens, const vision::CameraIntrinsics& reference) {
  check_input(vision::check_intrinsics(lens), "lens");
  check_input(vision::check_intrinsics(reference), "reference lens");
  check_input(lens.width_px == reference.width_px && lens.height_px == reference.height_px, "compare_lenses",
              "the lenses belong to images of different sizes");
  LensComparison c;
  c.fx_error_pct = (lens.fx_px / reference.fx_px - 1.0) * 100.0;
  c.fy_error_pct = (lens.fy_px / reference.fy_px - 1.0) * 100.0;
  c.principal_point_error_px = std::hypot(lens.cx_px - reference.cx_px, lens.cy_px - reference.cy_px);
  // Where each lens's distortion puts the ideal pixels of a grid over the
  // image, and those the reference lens images on a grid over the sensor.
  const vision::PointUndistorter undistort(reference);
  const auto error = [&](const cv::Point2d& ideal) {
    return cv::norm(vision::distort_pixel(lens, ideal) - vision::distort_pixel(reference, ideal));
  };
  constexpr int kSteps = 16;
  for (int i = 0; i <= kSteps; ++i) {
    for (int k = 0; k <= kSteps; ++k) {
      const cv::Point2d grid_px((reference.width_px - 1) * i / double(kSteps),
                                (reference.height_px - 1) * k / double(kSteps));
      c.distortion_max_error_px = std::max(c.distortion_max_error_px, error(grid_px));
      c.distortion_sensor_max_error_px =
          std::max(c.distortion_sensor_max_error_px, error(undistort.ideal_from_distorted(grid_px)));
    }
  }
  return c;
}

namespace {

// Roles, each one palette colour (pinball/plot/draw.h).
const cv::Scalar kFigureBackground(40, 40, 40), kText(240, 240, 240), kUsed = plot::palette_colour(2),
    kPoor = plot::palette_colour(3), kNotFound = plot::palette_colour(1), kArrow = plot::palette_colour(4);

void put(cv::Mat& img, const std::string& text, cv::Point at, double scale, const cv::Scalar& colour) {
  plot::put_text(img, text, at, scale, colour);
}

// The largest round gain (1, 2, 5, 10, ...) that draws `residual_px` (image px)
// at most `room_px` long on a thumbnail `scale` times the image's size.
double arrow_gain(double residual_px, double scale, double room_px) {
  if (!(residual_px * scale > 0.0)) return 1.0;
  return std::clamp(plot::round_at_most(room_px / (residual_px * scale)), 1.0, 5e5);
}

}  // namespace

cv::Mat draw_intrinsics_figure(const IntrinsicsFit& fit, std::span<const TargetImage> images) {
  check_input(images.size() == fit.images.size() && !images.empty(), "draw_intrinsics_figure",
              "needs the images the fit was made from, in the same order");
  constexpr int kColumns = 4, kThumbWidth = 320, kCaption = 40, kGap = 8, kTop = kGap;
  const cv::Size size = images[0].gray.size();
  const double scale = std::min(1.0, double(kThumbWidth) / size.width);
  const int tw = static_cast<int>(std::lround(size.width * scale)), th = static_cast<int>(std::lround(size.height * scale));
  const int n = static_cast<int>(images.size());
  const int columns = std::min(kColumns, n), rows = (n + kColumns - 1) / kColumns;
  const int width = std::max(kColumns * (kThumbWidth + kGap) + kGap, columns * (tw + kGap) + kGap);
  cv::Mat img(kTop + rows * (th + kCaption + kGap), width, CV_8UC3, kFigureBackground);

  // One scale for every arrow: the largest residual of a used image about 20 px long.
  double largest = 0.0;
  for (const ImageResult& r : fit.images) {
    if (!r.used) continue;
    for (std::size_t p = 0; p < r.reprojected_px.size(); ++p) {
      largest = std::max(largest, cv::norm(r.reprojected_px[p] - r.corners_px[p]));
    }
  }
  const double gain = arrow_gain(largest, scale, 20.0);

  const IntrinsicsCalibration& c = fit.calibration;
  const vision::CameraIntrinsics& l = c.lens;
  char line[256];
  std::vector<std::string> notes;
  std::snprintf(line, sizeof line, "%d of %zu images used, reprojection rms %.3f px; arrows: residual x%g",
                c.images_used, fit.images.size(), c.reprojection_rms_px, gain);
  notes.emplace_back(line);
  std::snprintf(line, sizeof line,
                "%dx%d: fx %.2f fy %.2f cx %.2f cy %.2f px; k1 %.4f k2 %.4f k3 %.4f p1 %.5f p2 %.5f", l.width_px,
                l.height_px, l.fx_px, l.fy_px, l.cx_px, l.cy_px, l.k1, l.k2, l.k3, l.p1, l.p2);
  notes.emplace_back(line);

  for (int i = 0; i < n; ++i) {
    const ImageResult& r = fit.images[static_cast<std::size_t>(i)];
    const cv::Point origin(kGap + (i % kColumns) * (tw + kGap), kTop + (i / kColumns) * (th + kCaption + kGap));
    cv::Mat thumb, bgr;
    const cv::Mat& gray = images[static_cast<std::size_t>(i)].gray;
    if (gray.size() == size && gray.type() == CV_8UC1) {
      cv::resize(gray, thumb, cv::Size(tw, th), 0, 0, cv::INTER_AREA);
      cv::cvtColor(thumb, bgr, cv::COLOR_GRAY2BGR);
      bgr.copyTo(img(cv::Rect(origin, cv::Size(tw, th))));
    }
    cv::Mat cell = img(cv::Rect(origin, cv::Size(tw, th)));
    const cv::Scalar colour = r.used ? kUsed : (r.reprojected_px.empty() ? kNotFound : kPoor);
    for (std::size_t p = 0; p < r.corners_px.size(); ++p) {
      const cv::Point2d at = r.corners_px[p] * scale;
      cv::circle(cell, cv::Point(cvRound(at.x), cvRound(at.y)), 2, colour, 1, cv::LINE_AA);
      if (p < r.reprojected_px.size()) {
        const cv::Point2d to = at + (r.reprojected_px[p] - r.corners_px[p]) * (gain * scale);
        cv::arrowedLine(cell, cv::Point(cvRound(at.x), cvRound(at.y)), cv::Point(cvRound(to.x), cvRound(to.y)), kArrow,
                        1, cv::LINE_AA, 0, 0.3);
      }
    }
    const cv::Point caption = origin + cv::Point(0, th + 15);
    std::string name = r.name;
    if (name.size() > 44) name = "..." + name.substr(name.size() - 41);
    put(img, name, caption, 0.42, kText);
    const std::string status =
        r.used ? std::to_string(r.corners) + " corners, rms " + number("%.3f", r.reprojection_rms_px) + " px"
               : "rejected: " + r.rejection;
    put(img, status, caption + cv::Point(0, 17), 0.42, colour);
  }
  const std::vector<plot::LegendEntry> legend{
      plot::marker_entry("corner, image used", kUsed, plot::Marker::kCircle),
      plot::marker_entry("corner, image fits poorly (left out)", kPoor, plot::Marker::kCircle),
      plot::marker_entry("image left out, target not found", kNotFound, plot::Marker::kCircle),
      plot::line_entry("reprojection residual, drawn x" + number("%g", gain), kArrow)};
  return plot::annotated_picture(img, legend, "Lens intrinsics from " + c.target + " - pinball calibrate intrinsics",
                                 notes);
}

}  // namespace pinball::calibration
