#include "pinball/learn/shot_values.h"

#include <cmath>
#include <fstream>
#include <algorithm>
#include <limits>
#include <numbers>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "pinball/core/json_read_archive.h"
#include "pinball/core/json_text.h"
#include "pinball/core/text_file.h"

namespace pinball::learn {

namespace {

int direction_bins(const ShotValueTable& t) { return static_cast<int>(std::ceil(180.0 / t.direction_bin_deg)); }

std::size_t cells(const ShotValueTable& t) {
  return static_cast<std::size_t>(t.flippers) * static_cast<std::size_t>(direction_bins(t)) *
         static_cast<std::size_t>(t.speed_bins);
}

std::size_t index(const ShotValueTable& t, int flipper, int d, int s) {
  return (static_cast<std::size_t>(flipper) * static_cast<std::size_t>(direction_bins(t)) +
          static_cast<std::size_t>(d)) * static_cast<std::size_t>(t.speed_bins) + static_cast<std::size_t>(s);
}

// The bins of a shot; none outside the table.
std::optional<std::pair<int, int>> bin_of(const ShotValueTable& t, int flipper, double direction_deg,
                                          double speed_mps) {
  if (flipper < 0 || flipper >= t.flippers || !(direction_deg >= 0.0 && direction_deg < 180.0) ||
      !(speed_mps >= 0.0)) {
    return std::nullopt;
  }
  const int d = std::min(direction_bins(t) - 1, static_cast<int>(direction_deg / t.direction_bin_deg));
  const int s = std::min(t.speed_bins - 1, static_cast<int>(speed_mps / t.speed_bin_mps));
  return std::make_pair(d, s);
}

}  // namespace

double shot_line_y_m(const table::Board& board, double exit_height_m) {
  double pivot_y_m = -std::numeric_limits<double>::infinity();
  for (const table::Flipper& f : board.flippers) pivot_y_m = std::max(pivot_y_m, f.pivot.y());
  return pivot_y_m + exit_height_m;
}

std::optional<Shot> read_shot(const sim::GameState& state, double line_y_m, int& touched) {
  for (std::size_t i = 0; i < state.flippers.size(); ++i) {
    if (state.flippers[i].ball_contact) touched = static_cast<int>(i);
  }
  const Vec2& v = state.ball.velocity_mps;
  if (touched < 0 || state.ball.position_m.y() < line_y_m || !(v.y() > 0.0)) return std::nullopt;
  return Shot{touched, std::atan2(v.y(), v.x()) * 180.0 / std::numbers::pi, v.norm()};
}

ShotValueTable make_shot_value_table(int flippers) {
  ShotValueTable t;
  t.flippers = flippers;
  t.sum.assign(cells(t), 0.0);
  t.count.assign(cells(t), 0.0);
  t.smoothed.assign(cells(t), std::numeric_limits<double>::quiet_NaN());
  return t;
}

void add_shot(ShotValueTable& t, int flipper, double direction_deg, double speed_mps, double value) {
  const auto b = bin_of(t, flipper, direction_deg, speed_mps);
  if (!b || !std::isfinite(value)) return;
  const std::size_t i = index(t, flipper, b->first, b->second);
  t.sum[i] += value;
  t.count[i] += 1.0;
}

void smooth(ShotValueTable& t) {
  const int nd = direction_bins(t);
  // Bins within three kernel widths count.
  const int rd = static_cast<int>(std::ceil(3.0 * t.kernel_direction_deg / t.direction_bin_deg));
  const int rs = static_cast<int>(std::ceil(3.0 * t.kernel_speed_mps / t.speed_bin_mps));
  // The kernel's weight at each bin offset, computed once (a table is smoothed
  // whenever a planner is built, once a ball in an evaluation).
  const int wd = 2 * rd + 1;
  std::vector<double> weight(static_cast<std::size_t>(wd * (2 * rs + 1)));
  for (int od = -rd; od <= rd; ++od) {
    const double ed = od * t.direction_bin_deg / t.kernel_direction_deg;
    for (int os = -rs; os <= rs; ++os) {
      const double es = os * t.speed_bin_mps / t.kernel_speed_mps;
      weight[static_cast<std::size_t>((os + rs) * wd + od + rd)] = std::exp(-0.5 * (ed * ed + es * es));
    }
  }
  t.smoothed.assign(cells(t), std::numeric_limits<double>::quiet_NaN());
  for (int f = 0; f < t.flippers; ++f) {
    for (int d = 0; d < nd; ++d) {
      for (int s = 0; s < t.speed_bins; ++s) {
        double w_sum = 0.0;
        double v_sum = 0.0;
        for (int dd = std::max(0, d - rd); dd <= std::min(nd - 1, d + rd); ++dd) {
          for (int ss = std::max(0, s - rs); ss <= std::min(t.speed_bins - 1, s + rs); ++ss) {
            const double k = weight[static_cast<std::size_t>((ss - s + rs) * wd + dd - d + rd)];
            const std::size_t i = index(t, f, dd, ss);
            w_sum += k * t.count[i];
            v_sum += k * t.sum[i];
          }
        }
        if (w_sum >= t.min_weight) t.smoothed[index(t, f, d, s)] = v_sum / w_sum;
      }
    }
  }
}

std::optional<double> shot_value(const ShotValueTable& t, int flipper, double direction_deg, double speed_mps) {
  const auto b = bin_of(t, flipper, direction_deg, speed_mps);
  if (!b) return std::nullopt;
  const double v = t.smoothed[index(t, flipper, b->first, b->second)];
  if (std::isnan(v)) return std::nullopt;
  return v;
}

double shots_in(const ShotValueTable& t) {
  double n = 0.0;
  for (const double c : t.count) n += c;
  return n;
}

void write_shot_value_table(const ShotValueTable& t, const std::string& path) {
  nlohmann::json j;
  j["format"] = "pinball-shot-values";
  j["version"] = 1;
  j["flippers"] = t.flippers;
  j["direction_bin_deg"] = t.direction_bin_deg;
  j["speed_bin_mps"] = t.speed_bin_mps;
  j["speed_bins"] = t.speed_bins;
  j["exit_height_m"] = t.exit_height_m;
  j["kernel_direction_deg"] = t.kernel_direction_deg;
  j["kernel_speed_mps"] = t.kernel_speed_mps;
  j["min_weight"] = t.min_weight;
  j["sum"] = t.sum;
  j["count"] = t.count;
  write_text_file(path, json_text(j) + "\n");
}

ShotValueTable read_shot_value_table(const std::string& path) {
  const std::string text = read_text_file(path);
  const nlohmann::json j = parse_json(text, path);  // "path: (file): not valid JSON: ...", a key given twice
  if (!j.is_object() || j.value("format", "") != "pinball-shot-values") {
    throw std::runtime_error(path + ": not a shot-value table (format must be \"pinball-shot-values\")");
  }
  try {
    ShotValueTable t;
    t.flippers = j.at("flippers").get<int>();
    t.direction_bin_deg = j.at("direction_bin_deg").get<double>();
    t.speed_bin_mps = j.at("speed_bin_mps").get<double>();
    t.speed_bins = j.at("speed_bins").get<int>();
    t.exit_height_m = j.at("exit_height_m").get<double>();
    t.kernel_direction_deg = j.at("kernel_direction_deg").get<double>();
    t.kernel_speed_mps = j.at("kernel_speed_mps").get<double>();
    t.min_weight = j.at("min_weight").get<double>();
    if (t.flippers < 1 || !(t.direction_bin_deg > 0.0) || !(t.speed_bin_mps > 0.0) || t.speed_bins < 1 ||
        !(t.kernel_direction_deg > 0.0) || !(t.kernel_speed_mps > 0.0)) {
      throw std::runtime_error("a bin, kernel or size is not positive");
    }
    t.sum = j.at("sum").get<std::vector<double>>();
    t.count = j.at("count").get<std::vector<double>>();
    if (t.sum.size() != cells(t) || t.count.size() != cells(t)) {
      throw std::runtime_error("sum and count must have " + std::to_string(cells(t)) + " bins");
    }
    smooth(t);
    return t;
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(path + ": " + e.what());
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(path + ": " + e.what());
  }
}

}  // namespace pinball::learn
