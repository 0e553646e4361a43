#include "pinball/calibration/calibration_figure.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include <opencv2/imgproc.hpp>

#include "pinball/core/format.h"
#include "pinball/plot/chart.h"
#include "pinball/plot/draw.h"

namespace pinball::calibration {
namespace {

constexpr double kScale = 2.0;       // figures enlarge the camera image this much
constexpr double kZoom = 2.0;        // each flipper's inset enlarges the figure this much again
constexpr double kInsetSpan = 1.35;  // an inset shows this many flipper lengths around the pivot

// Roles, each one palette colour in every calibration figure.
const cv::Scalar kDetected = plot::palette_colour(5), kInlier = plot::palette_colour(2),
                 kOutlier = plot::palette_colour(1), kTips = plot::palette_colour(5),
                 kMarkerless = plot::palette_colour(4), kMarkers = plot::palette_colour(2);

cv::Point2d at(const cv::Point2d& uv_px) { return uv_px * kScale; }

cv::Mat enlarged_bgr(const cv::Mat& gray) {
  cv::Mat big, bgr;
  cv::resize(gray, big, cv::Size(), kScale, kScale, cv::INTER_LINEAR);
  cv::cvtColor(big, bgr, cv::COLOR_GRAY2BGR);
  return bgr;
}

std::vector<cv::Point2d> arc(const vision::CameraHomography& h, const Vec2& c, double r, double a0, double a1) {
  std::vector<cv::Point2d> poly;
  const int n = 64;
  for (int k = 0; k <= n; ++k) {
    const double a = a0 + (a1 - a0) * k / n;
    poly.push_back(at(h.image_from_board(c + r * Vec2{std::cos(a), std::sin(a)})));
  }
  return poly;
}

// Direction angle (standard, from +x) of a flipper at elevation theta.
double direction_angle(table::Side side, double theta) { return side == table::Side::kLeft ? theta : M_PI - theta; }

std::string deg(double rad) { return format_number(rad * 180.0 / M_PI, 4); }

std::string describe(const char* method, const FlipperCalibration& f) {
  return f.name + " " + method + ": pivot (" + format_number(f.pivot_m.x(), 4) + ", " +
         format_number(f.pivot_m.y(), 4) + ") m, length " + format_number(f.length_m, 4) + " m, theta " +
         deg(f.theta_min_rad) + ".." + deg(f.theta_max_rad) + " deg";
}

// A zoomed crop of the figure around one flipper, with a scale bar at the
// local scale and its name.
cv::Mat flipper_inset(const cv::Mat& figure, const vision::CameraHomography& h, const FlipperCalibration& f) {
  const cv::Point2d pivot = at(h.image_from_board(f.pivot_m));
  const cv::Point2d step = at(h.image_from_board(f.pivot_m + Vec2{0.01, 0.0})) - pivot;
  const double px_per_m = std::hypot(step.x, step.y) / 0.01;  // the figure's scale at the pivot
  const int half = std::max(20, static_cast<int>(std::lround(kInsetSpan * f.length_m * px_per_m)));
  const cv::Rect want(cvRound(pivot.x) - half, cvRound(pivot.y) - half, 2 * half, 2 * half);
  const cv::Rect crop = want & cv::Rect(0, 0, figure.cols, figure.rows);
  if (crop.area() <= 0) return {};
  cv::Mat zoomed;
  cv::resize(figure(crop), zoomed, cv::Size(), kZoom, kZoom, cv::INTER_CUBIC);
  // Below the crop, on white: its name and a scale bar at the local scale.
  cv::Mat caption(66, zoomed.cols, CV_8UC3, cv::Scalar(255, 255, 255));
  plot::put_text(caption, f.name + ", x" + format_number(kScale * kZoom) + " the camera image", cv::Point(4, 16),
                 plot::kLabelScale, cv::Scalar(0, 0, 0));
  cv::Mat bar_area = caption(cv::Rect(0, 20, caption.cols, caption.rows - 20));
  plot::draw_scale_bar(bar_area, px_per_m * kZoom, plot::Corner::kBottomLeft);
  const std::vector<cv::Mat> parts{zoomed, caption};
  return plot::place(parts, false, 0);
}

}  // namespace

cv::Mat draw_camera_figure(const cv::Mat& gray, const HomographyFit& fit) {
  cv::Mat img = enlarged_bgr(gray);
  const vision::CameraHomography h(fit.calibration.image_from_board);
  for (const MarkerMatch& m : fit.matches) {
    cv::circle(img, cv::Point(at(m.uv_px)), 9, kDetected, 1, cv::LINE_AA);
    const cv::Point2d p = at(h.image_from_board(m.board));
    const cv::Scalar c = m.inlier ? kInlier : kOutlier;
    plot::draw_marker(img, p, plot::Marker::kCross, c, 14);
    plot::put_text(img, std::to_string(m.layout_index), cv::Point(p) + cv::Point(8, -8), 0.45, c);
  }
  char text[160];
  std::snprintf(text, sizeof text, "%d markers detected, %d used; reprojection rms %s px, max %s px (camera pixels)",
                fit.detections, fit.calibration.markers_used,
                format_number(fit.calibration.reprojection_rms_px).c_str(),
                format_number(fit.calibration.reprojection_max_px).c_str());
  const std::vector<std::string> notes{
      text, "the camera image enlarged x" + format_number(kScale) + "; numbers: the layout's marker index"};
  const std::vector<plot::LegendEntry> legend{
      plot::marker_entry("marker detected", kDetected, plot::Marker::kCircle),
      plot::marker_entry("layout through the fit: inlier", kInlier, plot::Marker::kCross),
      plot::marker_entry("layout through the fit: outlier", kOutlier, plot::Marker::kCross)};
  return plot::annotated_picture(img, legend, "Camera homography from markers - pinball calibrate camera", notes);
}

cv::Mat draw_flipper_figure(const cv::Mat& gray, const vision::CameraHomography& h,
                            std::span<const FlipperFigureItem> flippers) {
  cv::Mat img = enlarged_bgr(gray);
  std::vector<std::string> notes;
  bool any_sweep = false, any_markerless = false, any_markers = false;
  for (const FlipperFigureItem& item : flippers) {
    if (item.sweep) {
      any_sweep = true;
      for (const Vec2& t : item.sweep->tips_board) {
        plot::draw_marker(img, at(h.image_from_board(t)), plot::Marker::kDot, kTips, 3);
      }
    }
    if (const FlipperCalibration* f = item.markerless) {
      any_markerless = true;
      const double a0 = direction_angle(f->side, f->theta_min_rad), a1 = direction_angle(f->side, f->theta_max_rad);
      plot::draw_polyline(img, arc(h, f->pivot_m, f->length_m, 0.0, 2.0 * M_PI), kMarkerless, 1,
                          plot::LineStyle::kDashed);
      plot::draw_polyline(img, arc(h, f->pivot_m, f->length_m, a0, a1), kMarkerless, 2, plot::LineStyle::kSolid);
      plot::draw_marker(img, at(h.image_from_board(f->pivot_m)), plot::Marker::kCross, kMarkerless, 12);
      notes.push_back(describe("markerless", *f));
    }
    if (const FlipperCalibration* f = item.markers) {
      any_markers = true;
      const std::vector<cv::Point2d> blade{at(h.image_from_board(f->pivot_m)), at(h.image_from_board(f->tip_m))};
      plot::draw_marker(img, blade[0], plot::Marker::kTiltedCross, kMarkers, 12);
      plot::draw_polyline(img, blade, kMarkers, 1, plot::LineStyle::kSolid);
      notes.push_back(describe("markers", *f));
    }
  }
  std::vector<plot::LegendEntry> legend;
  if (any_sweep) legend.push_back(plot::marker_entry("blade tip seen (sweep)", kTips, plot::Marker::kDot));
  if (any_markerless) {
    legend.push_back(plot::line_entry("circle fitted to the tips", kMarkerless, plot::LineStyle::kDashed));
    legend.push_back(plot::line_entry("arc between the stops", kMarkerless));
    legend.push_back(plot::marker_entry("pivot (markerless)", kMarkerless, plot::Marker::kCross));
  }
  if (any_markers) {
    legend.push_back(plot::line_entry("pivot and tip at rest (markers)", kMarkers, plot::LineStyle::kSolid,
                                      plot::Marker::kTiltedCross));
  }
  // Below the whole view, one zoomed inset per flipper.
  std::vector<cv::Mat> insets;
  for (const FlipperFigureItem& item : flippers) {
    const FlipperCalibration* f = item.markerless ? item.markerless : item.markers;
    if (f == nullptr || !(f->length_m > 0.0)) continue;
    cv::Mat inset = flipper_inset(img, h, *f);
    if (!inset.empty()) insets.push_back(inset);
  }
  cv::Mat picture = img;
  if (!insets.empty()) {
    const std::vector<cv::Mat> parts{img, plot::place(insets, true)};
    picture = plot::place(parts, false);
  }
  return plot::annotated_picture(picture, legend, "Flipper pivots, lengths and stops - pinball calibrate flippers",
                                 notes);
}

cv::Mat draw_gravity_figure(std::span<const GravityRoll> rolls, const GravityCalibration& result) {
  const GravityEstimate& e = result.estimate;
  plot::Figure figure;
  const double half = 0.5 * (e.ci_high_mps2 - e.ci_low_mps2);
  figure.title =
      "Gravity along the table: g = " + format_mean_ci(e.g_mps2, half, 4) + " m/s^2 - pinball calibrate gravity";
  figure.notes = {format_number(100.0 * e.confidence) + " % interval [" + format_number(e.ci_low_mps2, 5) + ", " +
                      format_number(e.ci_high_mps2, 5) + "] m/s^2 (Student's t over rolls); " +
                      std::to_string(e.rolls_used) + " rolls used, " + std::to_string(e.rolls_rejected) + " left out",
                  "points: observations; lines: the parabola fitted to each roll's part used; grey dashed: left out"};
  figure.share_x = true;
  figure.panel_size = {960, 380};
  plot::Panel data, residuals;
  data.x.label = residuals.x.label = "time from the start of the recording (s)";
  data.y.label = "y - y(rest) (m)";
  residuals.y.label = "residual (mm)";
  residuals.references.push_back(
      {.vertical = false, .at = 0.0, .colour = cv::Scalar(60, 60, 60), .line = plot::LineStyle::kSolid, .label = ""});
  for (std::size_t i = 0; i < rolls.size() && i < result.rolls.size(); ++i) {
    const GravityRoll& r = rolls[i];
    const RollFit& f = result.rolls[i];
    if (r.observations.empty()) continue;
    const bool left_out = !f.usable || f.outlier;
    const cv::Scalar colour = left_out ? plot::muted_colour() : plot::palette_colour(static_cast<int>(i));
    std::string label = "roll " + std::to_string(i + 1);
    if (!f.usable) {
      label += " (left out: " + f.why + ")";
    } else {
      label += ": " + format_number(f.accel_mps2, 4) + " m/s^2" + (f.outlier ? " (left out: outlier)" : "");
    }
    const double t0 = r.observations.front().t_s, y0 = r.observations.front().p_board.y();
    plot::Series points{.label = "", .colour = colour, .line = plot::LineStyle::kNone, .marker = plot::Marker::kDot};
    for (const track::Observation& o : r.observations) {
      points.x.push_back(o.t_s - t0);
      points.y.push_back(o.p_board.y() - y0);
    }
    data.series.push_back(std::move(points));
    if (!f.usable) {
      // In the legend all the same, so that every roll is accounted for.
      data.series.push_back({.label = label, .colour = colour, .line = plot::LineStyle::kDashed});
      continue;
    }
    const auto parabola = [&](double t) {
      const double tau = t - f.t0_s;
      return f.c0 + tau * (f.c1 + tau * f.c2);
    };
    plot::Series curve{
        .label = label, .colour = colour, .line = left_out ? plot::LineStyle::kDashed : plot::LineStyle::kSolid};
    const double ta = r.observations[f.first].t_s, tb = r.observations[f.last].t_s;
    for (int k = 0; k <= 60; ++k) {
      const double t = ta + (tb - ta) * k / 60.0;
      curve.x.push_back(t - t0);
      curve.y.push_back(parabola(t) - y0);
    }
    data.series.push_back(std::move(curve));
    plot::Series off{.label = "", .colour = colour, .line = plot::LineStyle::kNone, .marker = plot::Marker::kDot};
    for (std::size_t k = f.first; k <= f.last && k < r.observations.size(); ++k) {
      const track::Observation& o = r.observations[k];
      off.x.push_back(o.t_s - t0);
      off.y.push_back(1e3 * (o.p_board.y() - parabola(o.t_s)));
    }
    residuals.series.push_back(std::move(off));
  }
  figure.panels = {data, residuals};
  return plot::render(figure);
}

}  // namespace pinball::calibration
