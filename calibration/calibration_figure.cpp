#include "pinball/calibration/calibration_figure.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <opencv2/imgproc.hpp>

namespace pinball::calibration {
namespace {

constexpr double kScale = 2.0;  // figures enlarge the camera image this much

const cv::Scalar kYellow(0, 220, 255), kGreen(0, 200, 0), kRed(40, 40, 230), kCyan(230, 220, 0),
    kMagenta(220, 60, 220), kWhite(245, 245, 245);

cv::Point at(const cv::Point2d& uv_px) {
  return {static_cast<int>(std::lround(uv_px.x * kScale)), static_cast<int>(std::lround(uv_px.y * kScale))};
}

cv::Mat enlarged_bgr(const cv::Mat& gray) {
  cv::Mat big, bgr;
  cv::resize(gray, big, cv::Size(), kScale, kScale, cv::INTER_LINEAR);
  cv::cvtColor(big, bgr, cv::COLOR_GRAY2BGR);
  return bgr;
}

void label(cv::Mat& img, const std::string& text, int line) {
  cv::putText(img, text, cv::Point(8, 20 + 18 * line), cv::FONT_HERSHEY_SIMPLEX, 0.5, kWhite, 1, cv::LINE_AA);
}

void draw_arc(cv::Mat& img, const vision::CameraHomography& h, const Vec2& c, double r, double a0, double a1,
              const cv::Scalar& colour) {
  std::vector<cv::Point> poly;
  const int n = 64;
  for (int k = 0; k <= n; ++k) {
    const double a = a0 + (a1 - a0) * k / n;
    poly.push_back(at(h.image_from_board(c + r * Vec2{std::cos(a), std::sin(a)})));
  }
  cv::polylines(img, poly, false, colour, 1, cv::LINE_AA);
}

// Direction angle (standard, from +x) of a flipper at elevation theta.
double direction_angle(table::Side side, double theta) { return side == table::Side::kLeft ? theta : M_PI - theta; }

}  // namespace

cv::Mat draw_camera_figure(const cv::Mat& gray, const HomographyFit& fit) {
  cv::Mat img = enlarged_bgr(gray);
  const vision::CameraHomography h(fit.calibration.image_from_board);
  for (const MarkerMatch& m : fit.matches) {
    cv::circle(img, at(m.uv_px), 9, kYellow, 1, cv::LINE_AA);
    const cv::Point p = at(h.image_from_board(m.board));
    const cv::Scalar c = m.inlier ? kGreen : kRed;
    cv::drawMarker(img, p, c, cv::MARKER_CROSS, 14, 1, cv::LINE_AA);
    cv::putText(img, std::to_string(m.layout_index), p + cv::Point(8, -8), cv::FONT_HERSHEY_SIMPLEX, 0.45, c, 1,
                cv::LINE_AA);
  }
  char text[160];
  std::snprintf(text, sizeof text, "%d markers detected, %d used; reprojection rms %.3f px, max %.3f px",
                fit.detections, fit.calibration.markers_used, fit.calibration.reprojection_rms_px,
                fit.calibration.reprojection_max_px);
  label(img, text, 0);
  return img;
}

cv::Mat draw_flipper_figure(const cv::Mat& gray, const vision::CameraHomography& h,
                            std::span<const FlipperFigureItem> flippers) {
  cv::Mat img = enlarged_bgr(gray);
  int line = 0;
  for (const FlipperFigureItem& item : flippers) {
    if (item.sweep) {
      for (const Vec2& t : item.sweep->tips_board) cv::circle(img, at(h.image_from_board(t)), 1, kCyan, cv::FILLED);
    }
    if (const FlipperCalibration* f = item.markerless) {
      const double a0 = direction_angle(f->side, f->theta_min_rad), a1 = direction_angle(f->side, f->theta_max_rad);
      draw_arc(img, h, f->pivot_m, f->length_m, 0.0, 2.0 * M_PI, cv::Scalar(120, 40, 120));
      draw_arc(img, h, f->pivot_m, f->length_m, a0, a1, kMagenta);
      cv::drawMarker(img, at(h.image_from_board(f->pivot_m)), kMagenta, cv::MARKER_CROSS, 12, 1, cv::LINE_AA);
      char text[160];
      std::snprintf(text, sizeof text, "%s markerless: pivot (%.4f, %.4f) m, length %.4f m, theta %.2f..%.2f deg",
                    f->name.c_str(), f->pivot_m.x(), f->pivot_m.y(), f->length_m, f->theta_min_rad * 180 / M_PI,
                    f->theta_max_rad * 180 / M_PI);
      label(img, text, line++);
    }
    if (const FlipperCalibration* f = item.markers) {
      const cv::Point p = at(h.image_from_board(f->pivot_m));
      cv::drawMarker(img, p, kGreen, cv::MARKER_TILTED_CROSS, 12, 1, cv::LINE_AA);
      cv::line(img, p, at(h.image_from_board(f->tip_m)), kGreen, 1, cv::LINE_AA);
      char text[160];
      std::snprintf(text, sizeof text, "%s markers:    pivot (%.4f, %.4f) m, length %.4f m, theta %.2f..%.2f deg",
                    f->name.c_str(), f->pivot_m.x(), f->pivot_m.y(), f->length_m, f->theta_min_rad * 180 / M_PI,
                    f->theta_max_rad * 180 / M_PI);
      label(img, text, line++);
    }
  }
  return img;
}

cv::Mat draw_gravity_figure(std::span<const GravityRoll> rolls, const GravityCalibration& result) {
  const cv::Size size(960, 600);
  const int left = 70, right = 20, top = 50, bottom = 50;
  cv::Mat img(size, CV_8UC3, cv::Scalar(30, 30, 30));
  // Time from each roll's own start, y relative to where it rested: the rolls overlay.
  double t_max = 0.1, y_min = -0.01;
  for (const GravityRoll& r : rolls) {
    if (r.observations.empty()) continue;
    t_max = std::max(t_max, r.observations.back().t_s - r.observations.front().t_s);
    for (const track::Observation& o : r.observations) {
      y_min = std::min(y_min, o.p_board.y() - r.observations.front().p_board.y());
    }
  }
  const auto px = [&](double t, double dy) {
    return cv::Point(left + static_cast<int>((size.width - left - right) * t / t_max),
                     top + static_cast<int>((size.height - top - bottom) * (dy / y_min)));
  };
  cv::rectangle(img, px(0, 0), px(t_max, y_min), cv::Scalar(90, 90, 90), 1);
  for (std::size_t i = 0; i < rolls.size() && i < result.rolls.size(); ++i) {
    const GravityRoll& r = rolls[i];
    const RollFit& f = result.rolls[i];
    if (r.observations.empty()) continue;
    const double t0 = r.observations.front().t_s, y0 = r.observations.front().p_board.y();
    const cv::Scalar colour = !f.usable || f.outlier ? kRed : kCyan;
    for (const track::Observation& o : r.observations) {
      cv::circle(img, px(o.t_s - t0, o.p_board.y() - y0), 1, colour * 0.6, cv::FILLED);
    }
    if (!f.usable) continue;
    std::vector<cv::Point> curve;
    const double ta = r.observations[f.first].t_s, tb = r.observations[f.last].t_s;
    for (int k = 0; k <= 60; ++k) {
      const double t = ta + (tb - ta) * k / 60.0, tau = t - f.t0_s;
      curve.push_back(px(t - t0, f.c0 + tau * (f.c1 + tau * f.c2) - y0));
    }
    cv::polylines(img, curve, false, colour, 2, cv::LINE_AA);
  }
  const GravityEstimate& e = result.estimate;
  char text[200];
  std::snprintf(text, sizeof text, "g along the table %.5f m/s^2, %.0f%% interval [%.5f, %.5f]; %d rolls used, %d left out",
                e.g_mps2, 100.0 * e.confidence, e.ci_low_mps2, e.ci_high_mps2, e.rolls_used, e.rolls_rejected);
  label(img, text, 0);
  label(img, "y - y(rest) (m) against time from the start of each recording (s); lines: fitted parabolas", 1);
  char axis[64];
  std::snprintf(axis, sizeof axis, "%.2f s", t_max);
  cv::putText(img, axis, px(t_max, y_min) + cv::Point(-50, 20), cv::FONT_HERSHEY_SIMPLEX, 0.45, kWhite, 1);
  std::snprintf(axis, sizeof axis, "%.2f m", y_min);
  cv::putText(img, axis, px(0, y_min) + cv::Point(-65, 0), cv::FONT_HERSHEY_SIMPLEX, 0.45, kWhite, 1);
  return img;
}

}  // namespace pinball::calibration
