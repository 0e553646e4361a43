#include "pinball/calibration/camera_calibration.h"

#include <cstdio>
#include <fstream>
#include <stdexcept>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "common/error_text.h"
#include "common/temp_path.h"
#include "pinball/core/rng.h"
#include "pinball/simlab/sim_camera_source.h"
#include "pinball/table/board_loader.h"
#include "pinball/vision/camera_homography.h"

namespace pinball::calibration {
namespace {

table::Board table() {
  table::Board b;
  b.width_m = 0.51;
  b.height_m = 1.07;
  return b;
}

// Detections at the layout's true image positions (shuffled, with extras and noise).
std::vector<DetectedMarker> seen(const vision::CameraHomography& h, const std::vector<Vec2>& layout, double noise_px,
                                 std::uint64_t seed) {
  Rng rng(seed);
  std::vector<DetectedMarker> out;
  for (const Vec2& p : layout) {
    const cv::Point2d uv = h.image_from_board(p);
    out.push_back({uv + cv::Point2d(noise_px * rng.normal(), noise_px * rng.normal()), 50.0, 200.0});
  }
  std::reverse(out.begin(), out.end());
  out.push_back({cv::Point2d(320.5, 100.25), 40.0, 150.0});  // a stray bright blob
  return out;
}

TEST(CameraCalibration, RecoversTheHomographyFromExactMarkers) {
  const table::Board b = table();
  const vision::CameraHomography truth = vision::CameraHomography::default_view(b, cv::Size(640, 480));
  const std::vector<Vec2> layout = default_marker_layout(b);
  const HomographyFit fit = fit_homography(seen(truth, layout, 0.0, 1), layout, cv::Size(640, 480));
  EXPECT_EQ(fit.calibration.markers_used, 7);
  EXPECT_LT(fit.calibration.reprojection_rms_px, 1e-4);  // cv::findHomography works partly in float
  const vision::CameraHomography h(fit.calibration.image_from_board);
  for (const Vec2& p : {Vec2{0.1, 0.2}, Vec2{0.4, 0.9}, Vec2{0.25, 0.5}}) {
    EXPECT_LT((h.board_from_image(truth.image_from_board(p)) - p).norm(), 1e-7);
  }
}

TEST(CameraCalibration, NoisyMarkersGiveSubMillimetreHomography) {
  const table::Board b = table();
  const vision::CameraHomography truth = vision::CameraHomography::default_view(b, cv::Size(640, 480));
  const std::vector<Vec2> layout = default_marker_layout(b);
  const HomographyFit fit = fit_homography(seen(truth, layout, 0.2, 7), layout, cv::Size(640, 480));
  EXPECT_EQ(fit.calibration.markers_used, 7);
  EXPECT_GT(fit.calibration.reprojection_rms_px, 0.02);
  EXPECT_LT(fit.calibration.reprojection_rms_px, 0.5);
  const vision::CameraHomography h(fit.calibration.image_from_board);
  for (const Vec2& p : {Vec2{0.05, 0.05}, Vec2{0.45, 1.0}, Vec2{0.25, 0.5}}) {
    EXPECT_LT((h.board_from_image(truth.image_from_board(p)) - p).norm(), 1e-3);
  }
}

TEST(CameraCalibration, DegenerateLayoutsAreRefused) {
  const std::vector<Vec2> three{{0.0, 0.0}, {0.3, 0.0}, {0.0, 0.5}};
  EXPECT_THROW(check_marker_layout(three), std::invalid_argument);
  const std::vector<Vec2> collinear{{0.0, 0.0}, {0.1, 0.1}, {0.2, 0.2}, {0.4, 0.0}};
  try {
    check_marker_layout(collinear);
    FAIL() << "collinear triple accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("collinear"), std::string::npos) << e.what();
  }
  const std::vector<Vec2> line{{0.0, 0.0}, {0.1, 0.1}, {0.2, 0.2}, {0.3, 0.3001}, {0.4, 0.4}};
  EXPECT_THROW(check_marker_layout(line), std::invalid_argument);
  const std::vector<Vec2> coincide{{0.0, 0.0}, {0.3, 0.0}, {0.0, 0.5}, {0.3, 0.5}, {0.3005, 0.5}};
  try {
    check_marker_layout(coincide);
    FAIL() << "coincident markers accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("coincide"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(check_marker_layout(default_marker_layout(table())));
}

// The message must name what to fix: the layout, or the spots that are no marker.
std::string fit_error(const std::vector<DetectedMarker>& det, const std::vector<Vec2>& layout) {
  return pinball::testing::error_text([&] { fit_homography(det, layout, cv::Size(640, 480)); });
}

TEST(CameraCalibration, ALayoutFileOffTheBoardOrDegenerateIsRefusedNamingTheFile) {
  const std::string path = pinball::testing::temp_path("camera_calibration", "layout.csv");
  table::Board board = table();
  board.source = "lab.board";
  auto read = [&](const std::string& text) {
    std::ofstream(path) << text;
    return pinball::testing::error_text([&] { read_marker_layout_csv(path, board); });
  };
  std::string layout = "x,y\n";
  for (const Vec2& p : default_marker_layout(board)) {
    layout += std::to_string(p.x()) + "," + std::to_string(p.y()) + "\n";
  }
  EXPECT_EQ(read(layout), "no error");
  // The same layout in millimetres: it had been fitted, and failed with no word of the file.
  EXPECT_EQ(read("x,y\n51,100\n"),
            path + ":2: marker (51, 100) m is over 5 cm off the 0.51 x 1.07 m playfield of lab.board "
                   "(positions are in metres, board frame)");
  EXPECT_EQ(read("x,y\n0.1,0.1\n0.1,0.1\n0.3,0.5\n0.2,0.9\n"),
            path + ": marker layout: the markers of lines 2 and 3 coincide (closer than 10 mm)");
  // 250 markers: every four of them were built and sorted (3 GB, then std::bad_alloc).
  std::string many = "x,y\n";
  for (int i = 0; i < 25; ++i) many += std::to_string(0.02 + 0.019 * i) + "," + std::to_string(0.1 + 0.035 * i) + "\n";
  EXPECT_EQ(read(many), path + ": marker layout: 25 markers; at most 24 (the detector keeps as many, and matching "
                               "tries every four of them)");
  // A third column or a number with a tail was read as x,y and the rest dropped.
  EXPECT_EQ(read("x,y\n0.0408,0.0535abc\n"), path + ":2: expected two numbers x,y (m), got '0.0408,0.0535abc'");
  EXPECT_EQ(read("x,y\n0.0408,0.0535,5\n"), path + ":2: expected two numbers x,y (m), got '0.0408,0.0535,5'");
  EXPECT_EQ(read("x,y\n# comment\n0.1,0.1\n0.4,0.1 \n0.1,0.9\n0.1,0.5\n"),
            path + ": marker layout: no four markers without three (nearly) collinear (the markers of lines 3, 5, 6 "
                   "are collinear)");
  std::remove(path.c_str());
}

TEST(CameraCalibration, SymmetricLayoutIsNamedAsTheCause) {
  const table::Board b = table();
  const vision::CameraHomography truth = vision::CameraHomography::default_view(b, cv::Size(640, 480));
  // A rectangle with its centre: a half turn maps it onto itself.
  const std::vector<Vec2> layout{{0.05, 0.05}, {0.45, 0.05}, {0.45, 1.0}, {0.05, 1.0}, {0.25, 0.525}};
  const std::string e = fit_error(seen(truth, layout, 0.0, 1), layout);
  EXPECT_NE(e.find("the layout is (nearly) symmetric"), std::string::npos) << e;
}

TEST(CameraCalibration, StraySpotsThatMatchAsWellAreNamedNotTheLayout) {
  const table::Board b = table();
  const vision::CameraHomography truth = vision::CameraHomography::default_view(b, cv::Size(640, 480));
  const std::vector<Vec2> layout = default_marker_layout(b);
  // Five markers seen, and five reflections where a shifted camera would see them:
  // two sets of spots, each a good view of five markers.
  const cv::Matx33d shift(1, 0, 37.3, 0, 1, 21.9, 0, 0, 1);
  const vision::CameraHomography ghost(shift * truth.image_from_board_matrix());
  std::vector<DetectedMarker> det;
  for (std::size_t i = 0; i < 5; ++i) {
    det.push_back({truth.image_from_board(layout[i]), 50.0, 200.0});
    det.push_back({ghost.image_from_board(layout[i]), 50.0, 200.0});
  }
  const std::string e = fit_error(det, layout);
  EXPECT_NE(e.find("two sets of spots"), std::string::npos) << e;
  EXPECT_NE(e.find("10 spots detected for 7 markers"), std::string::npos) << e;
  EXPECT_EQ(e.find("symmetric"), std::string::npos) << e;
}

TEST(CameraCalibration, TooFewDetectionsIsAnError) {
  const table::Board b = table();
  const vision::CameraHomography truth = vision::CameraHomography::default_view(b, cv::Size(640, 480));
  const std::vector<Vec2> layout = default_marker_layout(b);
  std::vector<DetectedMarker> det = seen(truth, layout, 0.0, 1);
  det.resize(3);
  EXPECT_THROW(fit_homography(det, layout, cv::Size(640, 480)), std::runtime_error);
}

TEST(CameraCalibration, DetectsDrawnMarkersWithSubpixelCentres) {
  cv::Mat img(200, 300, CV_8U, cv::Scalar(40));
  const cv::Point2d centre(120.3, 80.7);
  cv::circle(img, cv::Point(static_cast<int>(centre.x * 16), static_cast<int>(centre.y * 16)), 12 * 16, cv::Scalar(10),
             cv::FILLED, cv::LINE_AA, 4);
  cv::circle(img, cv::Point(static_cast<int>(centre.x * 16), static_cast<int>(centre.y * 16)), 6 * 16, cv::Scalar(245),
             cv::FILLED, cv::LINE_AA, 4);
  cv::rectangle(img, cv::Rect(200, 50, 60, 8), cv::Scalar(250), cv::FILLED);  // bright, but a bar
  const std::vector<DetectedMarker> m = detect_markers(img);
  ASSERT_EQ(m.size(), 1u);
  EXPECT_NEAR(m[0].uv_px.x, centre.x, 0.1);
  EXPECT_NEAR(m[0].uv_px.y, centre.y, 0.1);
  EXPECT_THROW(detect_markers(cv::Mat(10, 10, CV_8UC3)), std::invalid_argument);
}

TEST(CameraCalibration, ThroughALensTheHomographyIsFittedOnUndistortedMarkers) {
  const table::Board b = table::load_board(std::string(PINBALL_SOURCE_DIR) + "/boards/mit1993.board");
  simlab::SimCameraConfig c;
  c.realism.lens = vision::typical_wide_lens();
  simlab::SimCameraSource camera(b, c);
  const std::vector<Vec2> layout = default_marker_layout(b);
  camera.set_markers(layout);
  vision::Frame frame;
  camera.render({}, 0.0, frame);
  // The board error of a fitted homography against the camera's true (ideal-image) one.
  const auto worst_error_m = [&](const HomographyFit& fit) {
    const vision::CameraHomography h(fit.calibration.image_from_board);
    double worst = 0.0;
    for (int i = 0; i <= 10; ++i) {
      for (int k = 0; k <= 20; ++k) {
        const Vec2 p{b.width_m * i / 10.0, b.height_m * k / 20.0};
        worst = std::max(worst, (h.board_from_image(camera.homography().image_from_board(p)) - p).norm());
      }
    }
    return worst;
  };
  const HomographyFit with_lens = calibrate_camera(frame.gray, layout, {}, {}, c.realism.lens);
  EXPECT_LT(with_lens.calibration.reprojection_rms_px, 0.3);
  EXPECT_LT(worst_error_m(with_lens), 0.001);
  // Without it the homography cannot absorb the distortion: pixels of residual, centimetres off at the edges.
  HomographyFitConfig loose;
  loose.ransac_threshold_px = 50.0;
  loose.match_tolerance_px = 40.0;
  const HomographyFit without = calibrate_camera(frame.gray, layout, {}, loose);
  EXPECT_GT(without.calibration.reprojection_rms_px, 1.0);
  EXPECT_GT(worst_error_m(without), 0.005);
  // A lens of other images than this one is refused.
  EXPECT_THROW(calibrate_camera(frame.gray, layout, {}, {}, vision::typical_wide_lens(1280, 960)),
               std::invalid_argument);
}

}  // namespace
}  // namespace pinball::calibration
