#include "pinball/calibration/calibration_file.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

#include "pinball/core/data_path.h"
#include "pinball/core/format.h"
#include "pinball/core/text_file.h"
#include "pinball/core/utc_date.h"
#include "pinball/core/yaml_read_archive.h"

namespace pinball::calibration {
namespace {

void emit_vec2(YAML::Emitter& e, const char* key, const Vec2& v, const char* comment) {
  e << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginSeq << v.x() << v.y() << YAML::EndSeq;
  if (comment) e << YAML::Comment(comment);
}

// The checks a type cannot express, after reading.
void check_flipper(const FlipperCalibration& f, const std::string& p, const YamlReadArchive& r) {
  if (!(f.length_m > 0.0)) r.fail(p + ".length_m", "must be > 0");
  if (!(f.theta_max_rad > f.theta_min_rad)) r.fail(p + ".theta_max_rad", "must be above theta_min_rad");
}

void check_calibration(const Calibration& c, const YamlReadArchive& r) {
  if (c.camera) {
    const CameraCalibration& k = *c.camera;
    if (!(std::abs(cv::determinant(k.image_from_board)) > 0.0)) r.fail("camera.image_from_board", "singular matrix");
    if (k.image_width_px <= 0 || k.image_height_px <= 0) r.fail("camera.image_width_px", "image size must be > 0");
  }
  if (c.intrinsics) {
    const vision::CameraIntrinsics& lens = c.intrinsics->lens;
    if (const RangeViolation v = vision::check_intrinsics(lens)) r.fail("intrinsics.lens." + v.key, v.rule);
    if (c.camera && (lens.width_px != c.camera->image_width_px || lens.height_px != c.camera->image_height_px)) {
      r.fail("intrinsics.lens.width_px", "the lens was calibrated on " + std::to_string(lens.width_px) + "x" +
                                             std::to_string(lens.height_px) + " images but the camera section's are " +
                                             std::to_string(c.camera->image_width_px) + "x" +
                                             std::to_string(c.camera->image_height_px));
    }
  }
  if (c.camera_timing) {
    const CameraTiming& t = *c.camera_timing;
    if (!std::isfinite(t.latency_s) || t.latency_s < 0.0 || t.latency_s > 1.0) {
      r.fail("camera_timing.latency_s", "must be in [0, 1] s");
    }
    if (!std::isfinite(t.latency_spread_s) || t.latency_spread_s < 0.0) {
      r.fail("camera_timing.latency_spread_s", "must be >= 0 s");
    }
    if (!std::isfinite(t.row_time_s) || t.row_time_s < 0.0 || t.row_time_s > 1e-3) {
      r.fail("camera_timing.row_time_s", "must be in [0, 0.001] s");
    }
    if (t.events_used < 0) r.fail("camera_timing.events_used", "must be >= 0");
  }
  for (std::size_t i = 0; i < c.flippers.size(); ++i) {
    check_flipper(c.flippers[i], "flippers[" + std::to_string(i) + "]", r);
  }
  if (c.gravity) {
    const GravityEstimate& g = *c.gravity;
    if (!(g.g_mps2 > 0.0 && g.g_mps2 <= table::kMaxGravity_mps2)) {
      r.fail("gravity.g_mps2", "must be in (0, " + format_exact(table::kMaxGravity_mps2) +
                                   "] m/s^2, as a board's g along the table");
    }
    if (!(g.ci_low_mps2 <= g.g_mps2 && g.g_mps2 <= g.ci_high_mps2)) {
      r.fail("gravity.ci_low_mps2", "the interval must hold g_mps2");
    }
  }
}


}  // namespace

const char* to_string(FlipperMethod method) {
  return method == FlipperMethod::kMarkers ? "markers" : "markerless";
}

std::string calibration_to_yaml(const Calibration& c) {
  YAML::Emitter e;
  e.SetDoublePrecision(17);
  e << YAML::Comment("pinball calibration file (docs/calibration.md): SI units, board frame (m, +y up the table)");
  e << YAML::BeginMap;
  e << YAML::Key << "version" << YAML::Value << c.version;
  e << YAML::Key << "date" << YAML::Value << (c.date.empty() ? utc_now_iso8601() : c.date) << YAML::Comment("UTC");
  e << YAML::Key << "board" << YAML::Value << c.board << YAML::Comment("the board file it calibrates");
  if (c.camera) {
    const CameraCalibration& k = *c.camera;
    e << YAML::Key << "camera" << YAML::Value << YAML::BeginMap;
    e << YAML::Key << "image_width_px" << YAML::Value << k.image_width_px;
    e << YAML::Key << "image_height_px" << YAML::Value << k.image_height_px;
    e << YAML::Key << "image_from_board" << YAML::Value << YAML::BeginSeq;
    for (int i = 0; i < 3; ++i) {
      e << YAML::Flow << YAML::BeginSeq << k.image_from_board(i, 0) << k.image_from_board(i, 1)
        << k.image_from_board(i, 2) << YAML::EndSeq;
    }
    e << YAML::EndSeq << YAML::Comment("homography: board (x m, y m, 1) -> image (u px, v px, w)");
    e << YAML::Key << "markers_used" << YAML::Value << k.markers_used;
    e << YAML::Key << "reprojection_rms_px" << YAML::Value << k.reprojection_rms_px;
    e << YAML::Key << "reprojection_max_px" << YAML::Value << k.reprojection_max_px;
    e << YAML::EndMap;
  }
  if (c.intrinsics) {
    const IntrinsicsCalibration& in = *c.intrinsics;
    const vision::CameraIntrinsics& l = in.lens;
    e << YAML::Key << "intrinsics" << YAML::Value << YAML::BeginMap;
    e << YAML::Key << "lens" << YAML::Value << YAML::BeginMap;
    e << YAML::Key << "width_px" << YAML::Value << l.width_px;
    e << YAML::Key << "height_px" << YAML::Value << l.height_px;
    e << YAML::Key << "fx_px" << YAML::Value << l.fx_px;
    e << YAML::Key << "fy_px" << YAML::Value << l.fy_px;
    e << YAML::Key << "cx_px" << YAML::Value << l.cx_px;
    e << YAML::Key << "cy_px" << YAML::Value << l.cy_px;
    e << YAML::Key << "k1" << YAML::Value << l.k1 << YAML::Comment("radial, OpenCV's model");
    e << YAML::Key << "k2" << YAML::Value << l.k2;
    e << YAML::Key << "k3" << YAML::Value << l.k3;
    e << YAML::Key << "p1" << YAML::Value << l.p1 << YAML::Comment("tangential");
    e << YAML::Key << "p2" << YAML::Value << l.p2;
    e << YAML::EndMap;
    e << YAML::Key << "target" << YAML::Value << in.target;
    e << YAML::Key << "images_used" << YAML::Value << in.images_used;
    e << YAML::Key << "images_rejected" << YAML::Value << in.images_rejected;
    e << YAML::Key << "reprojection_rms_px" << YAML::Value << in.reprojection_rms_px;
    e << YAML::EndMap;
  }
  if (c.camera_timing) {
    const CameraTiming& t = *c.camera_timing;
    e << YAML::Key << "camera_timing" << YAML::Value << YAML::BeginMap;
    e << YAML::Key << "latency_s" << YAML::Value << t.latency_s << YAML::Comment("frame stamp minus row 0's mid-exposure");
    e << YAML::Key << "latency_spread_s" << YAML::Value << t.latency_spread_s;
    e << YAML::Key << "row_time_s" << YAML::Value << t.row_time_s << YAML::Comment("rolling shutter; 0: global");
    e << YAML::Key << "events_used" << YAML::Value << t.events_used << YAML::Comment("0: configured, not measured");
    e << YAML::EndMap;
  }
  if (!c.flippers.empty()) {
    e << YAML::Key << "flippers" << YAML::Value << YAML::BeginSeq;
    for (const FlipperCalibration& f : c.flippers) {
      e << YAML::BeginMap;
      e << YAML::Key << "name" << YAML::Value << f.name;
      e << YAML::Key << "side" << YAML::Value << (f.side == table::Side::kLeft ? "left" : "right");
      e << YAML::Key << "method" << YAML::Value << to_string(f.method);
      emit_vec2(e, "pivot_m", f.pivot_m, nullptr);
      emit_vec2(e, "tip_m", f.tip_m, "tip at rest (theta_min)");
      e << YAML::Key << "length_m" << YAML::Value << f.length_m;
      e << YAML::Key << "theta_min_rad" << YAML::Value << f.theta_min_rad << YAML::Comment("down stop");
      e << YAML::Key << "theta_max_rad" << YAML::Value << f.theta_max_rad << YAML::Comment("up stop");
      e << YAML::Key << "fit_rms_m" << YAML::Value << f.fit_rms_m;
      e << YAML::Key << "points" << YAML::Value << f.points;
      if (f.disagreement) {
        const FlipperDisagreement& d = *f.disagreement;
        e << YAML::Key << "disagreement" << YAML::Value << YAML::BeginMap;
        e << YAML::Key << "pivot_m" << YAML::Value << d.pivot_m;
        e << YAML::Key << "tip_m" << YAML::Value << d.tip_m;
        e << YAML::Key << "length_m" << YAML::Value << d.length_m;
        e << YAML::Key << "theta_min_rad" << YAML::Value << d.theta_min_rad;
        e << YAML::Key << "theta_max_rad" << YAML::Value << d.theta_max_rad;
        e << YAML::EndMap << YAML::Comment("this method minus the other");
      }
      e << YAML::EndMap;
    }
    e << YAML::EndSeq;
  }
  if (c.gravity) {
    const GravityEstimate& g = *c.gravity;
    e << YAML::Key << "gravity" << YAML::Value << YAML::BeginMap;
    e << YAML::Key << "g_mps2" << YAML::Value << g.g_mps2 << YAML::Comment("rolling ball, along -y");
    e << YAML::Key << "ci_low_mps2" << YAML::Value << g.ci_low_mps2;
    e << YAML::Key << "ci_high_mps2" << YAML::Value << g.ci_high_mps2;
    e << YAML::Key << "confidence" << YAML::Value << g.confidence;
    e << YAML::Key << "rolls_used" << YAML::Value << g.rolls_used;
    e << YAML::Key << "rolls_rejected" << YAML::Value << g.rolls_rejected;
    e << YAML::Key << "per_roll_mps2" << YAML::Value << YAML::Flow << g.per_roll_mps2;
    e << YAML::EndMap;
  }
  e << YAML::EndMap;
  return std::string(e.c_str()) + "\n";
}

void write_calibration(const Calibration& calibration, const std::string& path) {
  write_text_file(path, calibration_to_yaml(calibration));  // a lab's measurements: never half a file
}

Calibration parse_calibration(const std::string& text, const std::string& name) {
  const YAML::Node root = load_yaml(text, name);
  require_yaml_version(root, name, kCalibrationFileVersion, "a calibration file");
  // Every key is required and no other is allowed (a misspelt key must not
  // pass unseen); sections and `disagreement` are optional. A repeated key is
  // refused by the reader.
  YamlReadArchive r(name, {.refuse_unknown_keys = true, .require_every_key = true});
  Calibration c;
  r.read(root, "", &c);
  check_calibration(c, r);
  return c;
}

Calibration read_calibration(const std::string& path) { return parse_calibration(read_text_file(path), path); }

track::FlipperGeometry flipper_geometry_from_calibration(const Calibration& c, const std::string& name) {
  const FlipperCalibration* left = nullptr;
  const FlipperCalibration* right = nullptr;
  for (const FlipperCalibration& f : c.flippers) {
    const FlipperCalibration*& slot = f.side == table::Side::kLeft ? left : right;
    if (slot) throw std::runtime_error(name + ":flippers: more than one " + (f.side == table::Side::kLeft ? "left" : "right") + " flipper");
    slot = &f;
  }
  if (!left || !right) throw std::runtime_error(name + ":flippers: missing (the tracker needs a left and a right flipper)");
  try {
    return track::make_flipper_geometry({left->pivot_m, left->tip_m}, {right->pivot_m, right->tip_m});
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(name + ":flippers: " + e.what());
  }
}

void apply_calibration(const Calibration& c, const std::string& name, track::TrackerConfig& config,
                       track::FlipperGeometry& geometry) {
  if (c.gravity) config.g_mps2 = c.gravity->g_mps2;
  if (c.flippers.empty()) return;
  geometry = flipper_geometry_from_calibration(c, name);
  double length = 0.0, pivot_y = 0.0;
  for (const FlipperCalibration& f : c.flippers) {
    length = std::max(length, f.length_m);
    pivot_y = std::max(pivot_y, f.pivot_m.y());
  }
  // The same rules default_tracker_config applies to the board's flippers.
  config.window_distance_m = 0.5 * length;
  config.rolling_epsilon_m = 0.1 * length;
  config.critical_y_m = pivot_y + 0.35;
}

vision::CameraHomography camera_homography(const Calibration& c, const std::string& name) {
  if (!c.camera) throw std::runtime_error(name + ":camera: missing");
  try {
    return vision::CameraHomography(c.camera->image_from_board);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(name + ":camera.image_from_board: " + e.what());
  }
}

void check_calibration_matches_board(const Calibration& c, const std::string& name, const table::Board& board) {
  // The table it was measured on: another board's file (not this one, nor a copy of it) means another
  // table's camera, flippers and gravity. A recorded board no longer found cannot be compared.
  const std::string recorded = c.board.empty() ? "" : find_data_file(c.board);
  std::error_code ec;
  if (!recorded.empty() && !board.source.empty() && std::filesystem::is_regular_file(recorded, ec) &&
      std::filesystem::is_regular_file(board.source, ec) && !same_file(recorded, board.source) &&
      !same_contents(recorded, board.source)) {
    throw KeyError(name, "board", "is " + c.board + ", not the board " + board.source +
                                      ": a calibration of another table (its camera, flippers and gravity are that "
                                      "table's)");
  }
  for (std::size_t i = 0; i < c.flippers.size(); ++i) {
    const FlipperCalibration& f = c.flippers[i];
    const std::string key = "flippers[" + std::to_string(i) + "]";
    const auto on_board = std::find_if(board.flippers.begin(), board.flippers.end(),
                                       [&](const table::Flipper& b) { return b.name == f.name; });
    if (on_board == board.flippers.end()) {
      std::string names;
      for (const table::Flipper& b : board.flippers) names += (names.empty() ? "" : ", ") + b.name;
      throw KeyError(name, key + ".name", "'" + f.name + "' is not a flipper of the board " + board.source +
                                              " (its flippers: " + (names.empty() ? "none" : names) + ")");
    }
    if (on_board->side != f.side) {
      throw KeyError(name, key + ".side", std::string(table::side_name(f.side)) + ", but the board's '" + f.name +
                                              "' is a " + std::string(table::side_name(on_board->side)) + " flipper");
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (c.flippers[j].name == f.name) throw KeyError(name, key + ".name", "'" + f.name + "' is calibrated twice");
    }
  }
}

void apply_calibration(const Calibration& c, const std::string& name, table::Board& board) {
  check_calibration_matches_board(c, name, board);
  for (const FlipperCalibration& f : c.flippers) {
    table::Flipper* target = nullptr;
    for (table::Flipper& b : board.flippers) {
      if (b.name == f.name) target = &b;
    }
    target->pivot = f.pivot_m;
    target->length_m = f.length_m;
    target->theta_min_rad = f.theta_min_rad;
    target->theta_max_rad = f.theta_max_rad;
  }
  if (c.gravity) board.gravity_mps2 = c.gravity->g_mps2;
}

}  // namespace pinball::calibration
