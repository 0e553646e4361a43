#include "pinball/calibration/calibration_target.h"

#include <array>
#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <utility>

#include "charuco_board.h"

namespace pinball::calibration {
namespace {

constexpr std::array<std::pair<std::string_view, cv::aruco::PREDEFINED_DICTIONARY_NAME>, 21> kDictionaries{{
    {"DICT_4X4_50", cv::aruco::DICT_4X4_50},
    {"DICT_4X4_100", cv::aruco::DICT_4X4_100},
    {"DICT_4X4_250", cv::aruco::DICT_4X4_250},
    {"DICT_4X4_1000", cv::aruco::DICT_4X4_1000},
    {"DICT_5X5_50", cv::aruco::DICT_5X5_50},
    {"DICT_5X5_100", cv::aruco::DICT_5X5_100},
    {"DICT_5X5_250", cv::aruco::DICT_5X5_250},
    {"DICT_5X5_1000", cv::aruco::DICT_5X5_1000},
    {"DICT_6X6_50", cv::aruco::DICT_6X6_50},
    {"DICT_6X6_100", cv::aruco::DICT_6X6_100},
    {"DICT_6X6_250", cv::aruco::DICT_6X6_250},
    {"DICT_6X6_1000", cv::aruco::DICT_6X6_1000},
    {"DICT_7X7_50", cv::aruco::DICT_7X7_50},
    {"DICT_7X7_100", cv::aruco::DICT_7X7_100},
    {"DICT_7X7_250", cv::aruco::DICT_7X7_250},
    {"DICT_7X7_1000", cv::aruco::DICT_7X7_1000},
    {"DICT_ARUCO_ORIGINAL", cv::aruco::DICT_ARUCO_ORIGINAL},
    {"DICT_APRILTAG_16h5", cv::aruco::DICT_APRILTAG_16h5},
    {"DICT_APRILTAG_25h9", cv::aruco::DICT_APRILTAG_25h9},
    {"DICT_APRILTAG_36h10", cv::aruco::DICT_APRILTAG_36h10},
    {"DICT_APRILTAG_36h11", cv::aruco::DICT_APRILTAG_36h11},
}};

std::optional<cv::aruco::PREDEFINED_DICTIONARY_NAME> dictionary_id(const std::string& name) {
  for (const auto& [text, id] : kDictionaries) {
    if (text == name) return id;
  }
  return std::nullopt;
}

// Markers a ChArUco board of this size holds: one per white square.
int markers_needed(const TargetSpec& t) { return t.squares_x * t.squares_y / 2; }

std::string mm(double m) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g mm", m * 1e3);
  return buf;
}

}  // namespace

cv::Ptr<cv::aruco::CharucoBoard> detail::make_charuco_board(const TargetSpec& t) {
  return cv::aruco::CharucoBoard::create(t.squares_x, t.squares_y, static_cast<float>(t.square_m),
                                         static_cast<float>(t.marker_m),
                                         cv::aruco::getPredefinedDictionary(*dictionary_id(t.dictionary)));
}

std::string TargetSpec::describe() const {
  const std::string size = std::to_string(squares_x) + "x" + std::to_string(squares_y) + " squares";
  if (kind == TargetKind::kChessboard) {
    return "chessboard " + size + " (" + std::to_string(squares_x - 1) + "x" + std::to_string(squares_y - 1) +
           " inner corners), " + mm(square_m);
  }
  return "ChArUco " + size + " (" + std::to_string((squares_x - 1) * (squares_y - 1)) + " corners), " + mm(square_m) +
         ", " + mm(marker_m) + " markers " + dictionary;
}

RangeViolation check_target(const TargetSpec& t) {
  if (t.squares_x < 3 || t.squares_x > 100) return {"squares_x", "must be in [3, 100]"};
  if (t.squares_y < 3 || t.squares_y > 100) return {"squares_y", "must be in [3, 100]"};
  if (!std::isfinite(t.square_m) || !(t.square_m > 0.0) || t.square_m > 1.0) {
    return {"square_m", "must be in (0, 1] m (25 mm is 0.025)"};
  }
  if (t.kind == TargetKind::kCharuco) {
    if (!std::isfinite(t.marker_m) || !(t.marker_m > 0.0) || !(t.marker_m < t.square_m)) {
      return {"marker_m", "must be in (0, square_m) m: the marker sits inside a square"};
    }
    const std::optional<cv::aruco::PREDEFINED_DICTIONARY_NAME> id = dictionary_id(t.dictionary);
    if (!id) return {"dictionary", "'" + t.dictionary + "' is not a cv::aruco predefined dictionary (e.g. DICT_4X4_50)"};
    const int size = cv::aruco::getPredefinedDictionary(*id)->bytesList.rows;
    if (markers_needed(t) > size) {
      return {"dictionary", t.dictionary + " has " + std::to_string(size) + " markers but a " +
                                std::to_string(t.squares_x) + "x" + std::to_string(t.squares_y) + " board needs " +
                                std::to_string(markers_needed(t))};
    }
  }
  return {};
}

TargetSpec parse_target(const std::string& text) {
  const std::string context = "target '" + text + "'";
  std::vector<std::string> parts;
  std::stringstream s(text);
  for (std::string part; std::getline(s, part, ':');) parts.push_back(part);
  TargetSpec t;
  const bool chess = !parts.empty() && parts[0] == "chessboard";
  const bool charuco = !parts.empty() && parts[0] == "charuco";
  check_input((chess && parts.size() == 3) || (charuco && (parts.size() == 4 || parts.size() == 5)), context,
              "expected chessboard:SXxSY:SQUARE_M or charuco:SXxSY:SQUARE_M:MARKER_M[:DICTIONARY] "
              "(e.g. chessboard:10x7:0.025)");
  t.kind = chess ? TargetKind::kChessboard : TargetKind::kCharuco;
  // Whole-field numbers only: "10x7" and "0.025", nothing trailing.
  const auto number = [&](const std::string& field, const char* what) {
    std::size_t used = 0;
    double value = 0.0;
    try {
      value = std::stod(field, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    check_input(used > 0 && used == field.size(), context, std::string(what) + " '" + field + "' is not a number");
    return value;
  };
  const std::size_t x = parts[1].find('x');
  check_input(x != std::string::npos, context, "squares '" + parts[1] + "' should be SXxSY, e.g. 10x7");
  const double sx = number(parts[1].substr(0, x), "squares across");
  const double sy = number(parts[1].substr(x + 1), "squares down");
  check_input(sx == std::floor(sx) && sy == std::floor(sy) && std::abs(sx) < 1e6 && std::abs(sy) < 1e6, context,
              "squares '" + parts[1] + "' should be whole numbers");
  t.squares_x = static_cast<int>(sx);
  t.squares_y = static_cast<int>(sy);
  t.square_m = number(parts[2], "square side");
  if (charuco) {
    t.marker_m = number(parts[3], "marker side");
    if (parts.size() == 5) t.dictionary = parts[4];
  }
  check_input(check_target(t), context);
  return t;
}

int target_corner_count(const TargetSpec& t) { return (t.squares_x - 1) * (t.squares_y - 1); }

std::vector<cv::Point3d> target_points_m(const TargetSpec& t) {
  check_input(check_target(t), "target");
  std::vector<cv::Point3d> out;
  out.reserve(static_cast<std::size_t>(target_corner_count(t)));
  for (int j = 1; j < t.squares_y; ++j) {
    for (int i = 1; i < t.squares_x; ++i) out.emplace_back(i * t.square_m, j * t.square_m, 0.0);
  }
  return out;
}

cv::Mat target_image(const TargetSpec& t, double px_per_m, int margin_px) {
  check_input(check_target(t), "target");
  check_input(std::isfinite(px_per_m) && px_per_m > 0.0, "target image", "px_per_m must be > 0");
  check_input(margin_px >= 0 && margin_px <= 100000, "target image", "margin_px must be in [0, 100000]");
  const double w_px = t.squares_x * t.square_m * px_per_m, h_px = t.squares_y * t.square_m * px_per_m;
  check_input(w_px >= 2.0 * t.squares_x && h_px >= 2.0 * t.squares_y && w_px * h_px < 4e8, "target image",
              "the pattern would be " + std::to_string(std::lround(std::min(w_px, 1e9))) + "x" +
                  std::to_string(std::lround(std::min(h_px, 1e9))) +
                  " px (at most 4e8 px in all, at least 2 px a square)");
  const int w = static_cast<int>(std::lround(w_px)), h = static_cast<int>(std::lround(h_px));
  cv::Mat img;
  if (t.kind == TargetKind::kCharuco) {
    detail::make_charuco_board(t)->draw(cv::Size(w + 2 * margin_px, h + 2 * margin_px), img, margin_px, 1);
    return img;
  }
  img.create(h + 2 * margin_px, w + 2 * margin_px, CV_8UC1);
  img.setTo(255);
  const TargetPattern pattern(t);
  for (int r = 0; r < h; ++r) {
    auto* row = img.ptr<std::uint8_t>(r + margin_px) + margin_px;
    for (int c = 0; c < w; ++c) row[c] = pattern.ink((c + 0.5) / px_per_m, (r + 0.5) / px_per_m) ? 0 : 255;
  }
  return img;
}

TargetPattern::TargetPattern(const TargetSpec& t)
    : squares_x_(t.squares_x), squares_y_(t.squares_y), square_m_(t.square_m), marker_m_(t.marker_m) {
  check_input(check_target(t), "target");
  if (t.kind != TargetKind::kCharuco) return;
  // The markers as cv::aruco places them: which square holds which, and its bits.
  const cv::Ptr<cv::aruco::CharucoBoard> board = detail::make_charuco_board(t);
  const cv::Ptr<cv::aruco::Dictionary>& dict = board->dictionary;
  cells_ = dict->markerSize + 2;
  marker_of_square_.assign(static_cast<std::size_t>(squares_x_ * squares_y_), -1);
  for (std::size_t m = 0; m < board->objPoints.size(); ++m) {
    const cv::Point3f& top_left = board->objPoints[m][0];
    const int i = static_cast<int>(std::floor(top_left.x / t.square_m));
    const int j = static_cast<int>(std::floor(top_left.y / t.square_m));
    marker_of_square_[static_cast<std::size_t>(j * squares_x_ + i)] = static_cast<int>(bits_.size());
    const int id = board->ids[m];
    bits_.push_back(cv::aruco::Dictionary::getBitsFromByteList(dict->bytesList.rowRange(id, id + 1), dict->markerSize));
  }
}

bool TargetPattern::ink(double x_m, double y_m) const {
  const double fx = x_m / square_m_, fy = y_m / square_m_;
  if (!(fx >= 0.0 && fy >= 0.0 && fx < squares_x_ && fy < squares_y_)) return false;
  const int i = static_cast<int>(fx), j = static_cast<int>(fy);
  if ((i + j) % 2 == 0) return true;  // a black square
  if (marker_of_square_.empty()) return false;
  const int m = marker_of_square_[static_cast<std::size_t>(j * squares_x_ + i)];
  if (m < 0) return false;
  // Inside the square: the marker is centred, its cells a border of ink around the bits.
  const double inset = 0.5 * (square_m_ - marker_m_);
  const double u = (x_m - i * square_m_ - inset) / marker_m_, v = (y_m - j * square_m_ - inset) / marker_m_;
  if (!(u >= 0.0 && v >= 0.0 && u < 1.0 && v < 1.0)) return false;
  const int col = static_cast<int>(u * cells_), row = static_cast<int>(v * cells_);
  if (row == 0 || col == 0 || row == cells_ - 1 || col == cells_ - 1) return true;
  return bits_[static_cast<std::size_t>(m)].at<std::uint8_t>(row - 1, col - 1) == 0;
}

}  // namespace pinball::calibration
