#include "pinball/simlab/sim_target_view.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include "pinball/core/rng.h"

namespace pinball::simlab {
namespace {

constexpr double kRadPerDeg = std::numbers::pi / 180.0;

void check_lens_and_target(const vision::CameraIntrinsics& lens, const calibration::TargetSpec& target) {
  check_input(vision::check_intrinsics(lens), "lens");
  check_input(calibration::check_target(target), "target");
}

// The sheet's outline: the squares and a half-square border (target frame, m).
std::vector<cv::Point3d> sheet_outline(const calibration::TargetSpec& t, int per_edge) {
  const double m = 0.5 * t.square_m;
  const double x0 = -m, y0 = -m, x1 = t.squares_x * t.square_m + m, y1 = t.squares_y * t.square_m + m;
  std::vector<cv::Point3d> out;
  for (int i = 0; i < per_edge; ++i) {
    const double f = double(i) / per_edge;
    out.emplace_back(x0 + f * (x1 - x0), y0, 0.0);
    out.emplace_back(x1, y0 + f * (y1 - y0), 0.0);
    out.emplace_back(x1 - f * (x1 - x0), y1, 0.0);
    out.emplace_back(x0, y1 - f * (y1 - y0), 0.0);
  }
  return out;
}

// Whether every outline point lies in front of the camera and inside the image, `margin_px` clear of its edges.
bool in_view(const std::vector<cv::Point3d>& outline, const cv::Matx33d& r, const cv::Vec3d& t,
             const vision::CameraIntrinsics& lens, double margin_px) {
  for (const cv::Point3d& p : outline) {
    const cv::Vec3d c = r * cv::Vec3d(p.x, p.y, p.z) + t;
    if (c[2] <= 1e-3) return false;
    const cv::Point2d ideal(lens.fx_px * c[0] / c[2] + lens.cx_px, lens.fy_px * c[1] / c[2] + lens.cy_px);
    // Far outside, the polynomial model folds back: refuse before distorting.
    if (std::abs(ideal.x - lens.cx_px) > 2.0 * lens.width_px || std::abs(ideal.y - lens.cy_px) > 2.0 * lens.height_px) {
      return false;
    }
    const cv::Point2d seen = vision::distort_pixel(lens, ideal);
    if (seen.x < margin_px || seen.y < margin_px || seen.x > lens.width_px - 1 - margin_px ||
        seen.y > lens.height_px - 1 - margin_px) {
      return false;
    }
  }
  return true;
}

}  // namespace

std::vector<calibration::TargetImage> simulated_target_images(const vision::CameraIntrinsics& lens,
                                                              const calibration::TargetSpec& target, int views,
                                                              std::uint64_t seed) {
  const std::vector<TargetPose> poses = default_target_poses(target, lens, views, seed);
  std::vector<calibration::TargetImage> images;
  for (std::size_t i = 0; i < poses.size(); ++i) {
    char name[48];
    std::snprintf(name, sizeof name, "sim_view_%02zu.png", i + 1);
    images.push_back({name, render_target_view(lens, target, poses[i], {}, ball_seed(seed, i))});
  }
  return images;
}

std::vector<TargetPose> default_target_poses(const calibration::TargetSpec& target,
                                             const vision::CameraIntrinsics& lens, int views, std::uint64_t seed) {
  check_lens_and_target(lens, target);
  check_input(views >= 1 && views <= 10000, "default_target_poses", "views must be in [1, 10000]");
  // Where the target is pushed towards: the middle, the corners, the edges (fractions of the image).
  constexpr std::array<std::array<double, 2>, 9> kAnchors{{{0.5, 0.5},
                                                           {0.0, 0.0},
                                                           {1.0, 0.0},
                                                           {1.0, 1.0},
                                                           {0.0, 1.0},
                                                           {0.5, 0.0},
                                                           {1.0, 0.5},
                                                           {0.5, 1.0},
                                                           {0.0, 0.5}}};
  Rng rng(seed);
  const double width_m = target.squares_x * target.square_m, height_m = target.squares_y * target.square_m;
  const cv::Vec3d centre(0.5 * width_m, 0.5 * height_m, 0.0);
  const std::vector<cv::Point3d> outline = sheet_outline(target, 16);
  // The pose with the target's centre seen at (ax, ay) (fractions of the image).
  const auto placed = [&](const cv::Matx33d& r, double fill, double ax, double ay) {
    const double depth_m = width_m * lens.fx_px / (fill * lens.width_px);
    const cv::Point2d ideal =
        vision::ideal_from_distorted_newton(lens, {ax * (lens.width_px - 1), ay * (lens.height_px - 1)});
    const cv::Vec3d ray((ideal.x - lens.cx_px) / lens.fx_px, (ideal.y - lens.cy_px) / lens.fy_px, 1.0);
    return cv::Vec3d(depth_m * ray - r * centre);
  };
  std::vector<TargetPose> poses;
  for (int v = 0; v < views; ++v) {
    const auto& anchor = kAnchors[static_cast<std::size_t>(v) % kAnchors.size()];
    const double tilt = rng.uniform(12.0, 35.0) * kRadPerDeg, axis = rng.uniform(0.0, 2.0 * std::numbers::pi);
    // Square to the image's edges in a corner (else its corner cannot reach the image's), turned elsewhere.
    const bool corner = anchor[0] != 0.5 && anchor[1] != 0.5;
    const double turn = rng.uniform(-1.0, 1.0) * (corner ? 3.0 : 20.0) * kRadPerDeg;
    double fill = rng.uniform(0.4, 0.6);  // the squares' width over the image's
    const double cx = 0.5 + rng.uniform(-0.05, 0.05), cy = 0.5 + rng.uniform(-0.05, 0.05);
    cv::Matx33d tilt_r, turn_r;
    cv::Rodrigues(cv::Vec3d(tilt * std::cos(axis), tilt * std::sin(axis), 0.0), tilt_r);
    cv::Rodrigues(cv::Vec3d(0.0, 0.0, turn), turn_r);
    const cv::Matx33d r = tilt_r * turn_r;
    // Small enough to be seen whole near the middle, then as far towards the anchor as it stays in view.
    while (fill > 0.1 && !in_view(outline, r, placed(r, fill, cx, cy), lens, 4.0)) fill *= 0.95;
    // Then move it towards the anchor while it stays in view: diagonally, or
    // along x or y alone (along an edge it touches), in halving steps; so a
    // corner view ends in the corner against both edges.
    double ax = cx, ay = cy;
    const auto toward = [](double from, double to, double step) {
      return std::abs(to - from) <= step ? to - from : std::copysign(step, to - from);
    };
    for (double step = 0.2; step > 1e-3;) {
      const double dx = toward(ax, anchor[0], step), dy = toward(ay, anchor[1], step);
      bool moved = false;
      for (const auto& [mx, my] : {std::pair{dx, dy}, std::pair{dx, 0.0}, std::pair{0.0, dy}}) {
        if ((mx != 0.0 || my != 0.0) && in_view(outline, r, placed(r, fill, ax + mx, ay + my), lens, 4.0)) {
          ax += mx;
          ay += my;
          moved = true;
          break;
        }
      }
      if (!moved) step *= 0.5;
    }
    cv::Vec3d rvec;
    cv::Rodrigues(r, rvec);
    poses.push_back({rvec, placed(r, fill, ax, ay)});
  }
  return poses;
}

RangeViolation check_target_view_options(const TargetViewOptions& o) {
  const auto gray = [](double g) { return std::isfinite(g) && g >= 0.0 && g <= 255.0; };
  if (!std::isfinite(o.noise_sigma) || o.noise_sigma < 0.0 || o.noise_sigma > 50.0) {
    return {"noise_sigma", "must be in [0, 50] gray levels"};
  }
  if (!std::isfinite(o.blur_sigma_px) || o.blur_sigma_px < 0.0 || o.blur_sigma_px > 50.0) {
    return {"blur_sigma_px", "must be in [0, 50] px"};
  }
  if (o.supersample < 1 || o.supersample > 8) return {"supersample", "must be in [1, 8]"};
  if (!gray(o.paper_gray)) return {"paper_gray", "must be in [0, 255]"};
  if (!gray(o.ink_gray)) return {"ink_gray", "must be in [0, 255]"};
  if (!gray(o.background_gray)) return {"background_gray", "must be in [0, 255]"};
  return {};
}

cv::Mat render_target_view(const vision::CameraIntrinsics& lens, const calibration::TargetSpec& target,
                           const TargetPose& pose, const TargetViewOptions& o, std::uint64_t seed) {
  check_lens_and_target(lens, target);
  check_input(check_target_view_options(o), "target view");
  const calibration::TargetPattern pattern(target);
  cv::Matx33d r;
  cv::Rodrigues(pose.rvec, r);
  // The camera in the target frame: centre o, and each ray's direction R^T d.
  const cv::Matx33d rt = r.t();
  const cv::Vec3d o_t = -(rt * pose.tvec_m);
  const double border = 0.5 * target.square_m;
  const double x_lo = -border, y_lo = -border, x_hi = pattern.width_m() + border, y_hi = pattern.height_m() + border;

  const int w = lens.width_px, h = lens.height_px, s = o.supersample;
  // What the ray through the normalised ideal point (x, y) meets: 0 background, 1 paper, 2 ink.
  const auto what = [&](double x, double y) -> std::uint8_t {
    const cv::Vec3d d = rt * cv::Vec3d(x, y, 1.0);
    if (std::abs(d[2]) < 1e-12) return 0;
    const double along = -o_t[2] / d[2];
    if (!(along > 0.0)) return 0;
    const double px = o_t[0] + along * d[0], py = o_t[1] + along * d[1];
    if (!(px >= x_lo && px <= x_hi && py >= y_lo && py <= y_hi)) return 0;
    return pattern.ink(px, py) ? 2 : 1;
  };
  const std::array<double, 3> gray{o.background_gray, o.paper_gray, o.ink_gray};

  // First the pixels' corners (u - 0.5, v - 0.5): their ideal points and what they see.
  cv::Mat ideal(h + 1, w + 1, CV_64FC2);
  cv::Mat seen(h + 1, w + 1, CV_8UC1);
  for (int v = 0; v <= h; ++v) {
    const double yd = (v - 0.5 - lens.cy_px) / lens.fy_px;
    double x = (-0.5 - lens.cx_px) / lens.fx_px, y = yd;  // Newton starts from the previous corner's solution
    auto* ip = ideal.ptr<cv::Vec2d>(v);
    auto* sp = seen.ptr<std::uint8_t>(v);
    for (int u = 0; u <= w; ++u) {
      vision::undistort_normalised(lens, (u - 0.5 - lens.cx_px) / lens.fx_px, yd, x, y);
      ip[u] = {x, y};
      sp[u] = what(x, y);
    }
  }
  // A pixel whose corners all see one thing, and whose neighbours' do too, is
  // that thing's gray. The others (an edge crosses them, or a corner of the
  // pattern may poke in) are sampled s x s times on an "n-rooks" pattern: one
  // sample in each cell of an s x s grid, shifted within it so that no two
  // share a column or a row of the finer s² x s² grid; an edge near the
  // pixel grid's axes is then resolved to 1/s² px, not 1/s, and the corners a
  // detector finds follow the true edges, not the sampling's steps.
  cv::Mat mixed(h, w, CV_8UC1);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const std::uint8_t c = seen.at<std::uint8_t>(v, u);
      mixed.at<std::uint8_t>(v, u) = c != seen.at<std::uint8_t>(v, u + 1) || c != seen.at<std::uint8_t>(v + 1, u) ||
                                             c != seen.at<std::uint8_t>(v + 1, u + 1)
                                         ? 255
                                         : 0;
    }
  }
  cv::dilate(mixed, mixed, cv::Mat());
  std::vector<cv::Point2d> offsets;  // within the pixel, from its top-left corner
  for (int j = 0; j < s; ++j) {
    for (int i = 0; i < s; ++i) offsets.emplace_back((i + (j + 0.5) / s) / s, (j + (i + 0.5) / s) / s);
  }
  cv::Mat sum(h, w, CV_64F);
  for (int v = 0; v < h; ++v) {
    auto* row = sum.ptr<double>(v);
    for (int u = 0; u < w; ++u) {
      if (!mixed.at<std::uint8_t>(v, u)) {
        row[u] = gray[seen.at<std::uint8_t>(v, u)];
        continue;
      }
      // Newton from the ideal points of the pixel's corners, interpolated.
      const cv::Vec2d c00 = ideal.at<cv::Vec2d>(v, u), c10 = ideal.at<cv::Vec2d>(v, u + 1);
      const cv::Vec2d c01 = ideal.at<cv::Vec2d>(v + 1, u), c11 = ideal.at<cv::Vec2d>(v + 1, u + 1);
      double total = 0.0;
      for (const cv::Point2d& off : offsets) {
        const cv::Vec2d start =
            (1 - off.y) * ((1 - off.x) * c00 + off.x * c10) + off.y * ((1 - off.x) * c01 + off.x * c11);
        double x = start[0], y = start[1];
        vision::undistort_normalised(lens, (u - 0.5 + off.x - lens.cx_px) / lens.fx_px,
                                     (v - 0.5 + off.y - lens.cy_px) / lens.fy_px, x, y);
        total += gray[what(x, y)];
      }
      row[u] = total / static_cast<double>(offsets.size());
    }
  }
  if (o.blur_sigma_px > 0.0) cv::GaussianBlur(sum, sum, cv::Size(0, 0), o.blur_sigma_px, o.blur_sigma_px, cv::BORDER_REPLICATE);
  Rng rng(seed);
  cv::Mat out(h, w, CV_8UC1);
  for (int v = 0; v < h; ++v) {
    const double* in = sum.ptr<double>(v);
    auto* px = out.ptr<std::uint8_t>(v);
    for (int u = 0; u < w; ++u) {
      const double g = in[u] + (o.noise_sigma > 0.0 ? o.noise_sigma * rng.normal() : 0.0);
      px[u] = static_cast<std::uint8_t>(std::clamp(std::lround(g), 0L, 255L));
    }
  }
  return out;
}

}  // namespace pinball::simlab
