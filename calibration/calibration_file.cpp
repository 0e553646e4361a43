#include "pinball/calibration/calibration_file.h"

#include <chrono>
#include <cmath>
#include <ctime>
#include <fstream>
#include <initializer_list>
#include <utility>
#include <sstream>
#include <stdexcept>

#include <yaml-cpp/yaml.h>

namespace pinball::calibration {
namespace {

std::string now_utc_iso8601() {
  const std::time_t t = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

void emit_vec2(YAML::Emitter& e, const char* key, const Vec2& v, const char* comment) {
  e << YAML::Key << key << YAML::Value << YAML::Flow << YAML::BeginSeq << v.x() << v.y() << YAML::EndSeq;
  if (comment) e << YAML::Comment(comment);
}

// Reads keys of one file, naming file:key in every error.
class Reader {
 public:
  explicit Reader(std::string name) : name_(std::move(name)) {}

  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw std::runtime_error(name_ + ":" + key + ": " + what);
  }
  YAML::Node need(const YAML::Node& parent, const std::string& path, const char* key) const {
    if (!parent.IsMap()) fail(path, "expected a mapping");
    const YAML::Node n = parent[key];
    if (!n) fail(join(path, key), "missing");
    return n;
  }
  double number(const YAML::Node& parent, const std::string& path, const char* key) const {
    const YAML::Node n = need(parent, path, key);
    double v = 0.0;
    if (!n.IsScalar() || !YAML::convert<double>::decode(n, v) || !std::isfinite(v)) {
      fail(join(path, key), "expected a finite number");
    }
    return v;
  }
  // Several finite numbers of one mapping, each into its field, in order (the first missing or bad one is named).
  void numbers_into(const YAML::Node& parent, const std::string& path,
                    std::initializer_list<std::pair<const char*, double*>> fields) const {
    for (const auto& [key, field] : fields) *field = number(parent, path, key);
  }
  int integer(const YAML::Node& parent, const std::string& path, const char* key) const {
    const YAML::Node n = need(parent, path, key);
    int v = 0;
    if (!n.IsScalar() || !YAML::convert<int>::decode(n, v)) fail(join(path, key), "expected an integer");
    return v;
  }
  std::string text(const YAML::Node& parent, const std::string& path, const char* key) const {
    const YAML::Node n = need(parent, path, key);
    if (!n.IsScalar()) fail(join(path, key), "expected text");
    return n.Scalar();
  }
  std::vector<double> numbers(const YAML::Node& n, const std::string& path, std::size_t size) const {
    if (!n.IsSequence() || (size > 0 && n.size() != size)) {
      fail(path, size > 0 ? "expected a list of " + std::to_string(size) + " numbers" : "expected a list of numbers");
    }
    std::vector<double> out;
    for (std::size_t i = 0; i < n.size(); ++i) {
      double v = 0.0;
      if (!n[i].IsScalar() || !YAML::convert<double>::decode(n[i], v) || !std::isfinite(v)) {
        fail(path + "[" + std::to_string(i) + "]", "expected a finite number");
      }
      out.push_back(v);
    }
    return out;
  }
  Vec2 vec2(const YAML::Node& parent, const std::string& path, const char* key) const {
    const std::vector<double> v = numbers(need(parent, path, key), join(path, key), 2);
    return {v[0], v[1]};
  }
  static std::string join(const std::string& path, const std::string& key) {
    return path.empty() ? key : path + "." + key;
  }
  const std::string& name() const { return name_; }

 private:
  std::string name_;
};

CameraCalibration read_camera(const Reader& r, const YAML::Node& n) {
  const std::string p = "camera";
  CameraCalibration c;
  c.image_width_px = r.integer(n, p, "image_width_px");
  c.image_height_px = r.integer(n, p, "image_height_px");
  const YAML::Node m = r.need(n, p, "image_from_board");
  if (!m.IsSequence() || m.size() != 3) r.fail(p + ".image_from_board", "expected 3 rows of 3 numbers");
  for (int i = 0; i < 3; ++i) {
    const std::vector<double> row = r.numbers(m[i], p + ".image_from_board[" + std::to_string(i) + "]", 3);
    for (int j = 0; j < 3; ++j) c.image_from_board(i, j) = row[static_cast<std::size_t>(j)];
  }
  if (!(std::abs(cv::determinant(c.image_from_board)) > 0.0)) r.fail(p + ".image_from_board", "singular matrix");
  c.markers_used = r.integer(n, p, "markers_used");
  c.reprojection_rms_px = r.number(n, p, "reprojection_rms_px");
  c.reprojection_max_px = r.number(n, p, "reprojection_max_px");
  if (c.image_width_px <= 0 || c.image_height_px <= 0) r.fail(p + ".image_width_px", "image size must be > 0");
  return c;
}

FlipperCalibration read_flipper(const Reader& r, const YAML::Node& n, const std::string& p) {
  FlipperCalibration f;
  f.name = r.text(n, p, "name");
  const std::string side = r.text(n, p, "side");
  if (side != "left" && side != "right") r.fail(p + ".side", "expected left or right");
  f.side = side == "left" ? table::Side::kLeft : table::Side::kRight;
  const std::string method = r.text(n, p, "method");
  if (method != "markers" && method != "markerless") r.fail(p + ".method", "expected markers or markerless");
  f.method = method == "markers" ? FlipperMethod::kMarkers : FlipperMethod::kMarkerless;
  f.pivot_m = r.vec2(n, p, "pivot_m");
  f.tip_m = r.vec2(n, p, "tip_m");
  r.numbers_into(n, p, {{"length_m", &f.length_m}, {"theta_min_rad", &f.theta_min_rad},
                        {"theta_max_rad", &f.theta_max_rad}, {"fit_rms_m", &f.fit_rms_m}});
  f.points = r.integer(n, p, "points");
  if (!(f.length_m > 0.0)) r.fail(p + ".length_m", "must be > 0");
  if (!(f.theta_max_rad > f.theta_min_rad)) r.fail(p + ".theta_max_rad", "must be above theta_min_rad");
  if (n["disagreement"]) {
    const std::string q = p + ".disagreement";
    const YAML::Node d = n["disagreement"];
    FlipperDisagreement g;
    r.numbers_into(d, q, {{"pivot_m", &g.pivot_m}, {"tip_m", &g.tip_m}, {"length_m", &g.length_m},
                          {"theta_min_rad", &g.theta_min_rad}, {"theta_max_rad", &g.theta_max_rad}});
    f.disagreement = g;
  }
  return f;
}

GravityEstimate read_gravity(const Reader& r, const YAML::Node& n) {
  const std::string p = "gravity";
  GravityEstimate g;
  r.numbers_into(n, p, {{"g_mps2", &g.g_mps2}, {"ci_low_mps2", &g.ci_low_mps2}, {"ci_high_mps2", &g.ci_high_mps2},
                        {"confidence", &g.confidence}});
  g.rolls_used = r.integer(n, p, "rolls_used");
  g.rolls_rejected = r.integer(n, p, "rolls_rejected");
  g.per_roll_mps2 = r.numbers(r.need(n, p, "per_roll_mps2"), p + ".per_roll_mps2", 0);
  if (!(g.g_mps2 > 0.0)) r.fail(p + ".g_mps2", "must be > 0");
  if (!(g.ci_low_mps2 <= g.g_mps2 && g.g_mps2 <= g.ci_high_mps2)) r.fail(p + ".ci_low_mps2", "the interval must hold g_mps2");
  return g;
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
  e << YAML::Key << "date" << YAML::Value << (c.date.empty() ? now_utc_iso8601() : c.date) << YAML::Comment("UTC");
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
  std::ofstream out(path);
  out << calibration_to_yaml(calibration);
  if (!out) throw std::runtime_error(path + ": cannot write");
}

Calibration parse_calibration(const std::string& text, const std::string& name) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw std::runtime_error(name + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  const Reader r(name);
  if (!root.IsMap()) r.fail("version", "missing (not a calibration file)");
  Calibration c;
  c.version = r.integer(root, "", "version");
  if (c.version != kCalibrationFileVersion) {
    r.fail("version", std::to_string(c.version) + " is not the supported version " +
                          std::to_string(kCalibrationFileVersion));
  }
  c.date = r.text(root, "", "date");
  c.board = r.text(root, "", "board");
  if (root["camera"]) c.camera = read_camera(r, root["camera"]);
  if (root["flippers"]) {
    const YAML::Node fl = root["flippers"];
    if (!fl.IsSequence()) r.fail("flippers", "expected a list");
    for (std::size_t i = 0; i < fl.size(); ++i) {
      c.flippers.push_back(read_flipper(r, fl[i], "flippers[" + std::to_string(i) + "]"));
    }
  }
  if (root["gravity"]) c.gravity = read_gravity(r, root["gravity"]);
  return c;
}

Calibration read_calibration(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::ostringstream s;
  s << in.rdbuf();
  return parse_calibration(s.str(), path);
}

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

void apply_calibration(const Calibration& c, const std::string& name, table::Board& board) {
  for (const FlipperCalibration& f : c.flippers) {
    table::Flipper* target = nullptr;
    for (table::Flipper& b : board.flippers) {
      if (b.name == f.name) target = &b;
    }
    if (!target) throw std::runtime_error(name + ":flippers: '" + f.name + "' is not a flipper of the board");
    target->pivot = f.pivot_m;
    target->length_m = f.length_m;
    target->theta_min_rad = f.theta_min_rad;
    target->theta_max_rad = f.theta_max_rad;
  }
  if (c.gravity) board.gravity_mps2 = c.gravity->g_mps2;
}

}  // namespace pinball::calibration
