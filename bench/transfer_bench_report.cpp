// The transfer bench's report: JSON, text and CSV (the measurement:
// transfer_bench.cpp; the figure: transfer_bench_plot.cpp).
#include <algorithm>
#include <cmath>
#include <sstream>

#include "pinball/core/json_write_archive.h"
#include "pinball/core/format.h"
#include "pinball/core/progress.h"
#include "transfer_bench.h"

namespace pinball::bench {
namespace {

constexpr const char* kRatioInterval =
    "95 %, delta method on log(ratio) with Welch-Satterthwaite's degrees of freedom, the two players' balls taken "
    "as independent games";
constexpr const char* kPivotAxis = "y: both pivots moved up (+) or down (-) the table by the same amount";
constexpr const char* kWallRhoRule =
    "added to every obstacle with rho <= 1 that eats no ball, clamped to [0, 1]; kickers and flippers keep theirs";
constexpr const char* kDrainRule =
    "where the ball last went down past the flippers' pivot line: left of the leftmost pivot (left outlane), right "
    "of the rightmost (right outlane), between them (centre), never (other)";
constexpr const char* kBelief =
    "the nominal board, g and camera noise in every world; the world alone is perturbed";

nlohmann::json cell_json(const TransferCell& c) {
  return {{"mean_score_per_ball", c.score.mean()},
          {"score_ci95_half_width", c.score.ci95_half_width()},
          {"score_stddev", c.score.stddev()},
          {"max_score_per_ball", c.score.max()},
          {"balls", c.score.count()},
          {"ratio_to_spastic", c.ratio_to_spastic},
          {"ratio_ci95_low", c.ratio_interval ? nlohmann::json(c.ratio_interval->low) : nlohmann::json()},
          {"ratio_ci95_high", c.ratio_interval ? nlohmann::json(c.ratio_interval->high) : nlohmann::json()},
          {"mean_ball_time_s", c.duration_s.mean()},
          {"flips_per_ball", c.flips.mean()},
          {"balls_cut_at_time_limit", c.cut},
          {"drains_left_outlane", c.drains.left_outlane},
          {"drains_right_outlane", c.drains.right_outlane},
          {"drains_centre", c.drains.centre},
          {"drains_other", c.drains.other},
          {"drains_left_table", c.drains.left_table},
          {"outlane_drain_after_flipper_s_mean",
           c.outlane_after_flipper_s.count() > 0 ? nlohmann::json(c.outlane_after_flipper_s.mean()) : nlohmann::json()},
          {"wall_s", c.wall_s}};
}

// " (1.96–2.31)": a ratio's interval as the text tables show it; "" for none.
std::string interval_text(const std::optional<RatioInterval>& interval) {
  if (!interval) return "";
  return " (" + format_number(interval->low, 3) + "–" + format_number(interval->high, 3) + ")";
}

// "9325 ± 700": a mean and its interval, or the ratio, as the text tables show them.
std::string score_text(const TransferCell& c, bool with_ratio) {
  std::string s = format_mean_ci(c.score.mean(), c.score.ci95_half_width());
  if (with_ratio) s += ", " + format_number(c.ratio_to_spastic, 3) + "x" + interval_text(c.ratio_interval);
  if (c.cut > 0) s += ", " + std::to_string(c.cut) + " cut";
  return s;
}

// A number's CSV cell: empty where it is undefined (the interval of one ball, a ratio to a
// spastic score of 0), as JSON writes null; a reader's float() takes no 'inf'.
std::string csv_number(double x) {
  if (!std::isfinite(x)) return "";
  std::ostringstream out;
  out.precision(10);
  out << x;
  return out.str();
}

std::string csv_text(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (const char ch : s) q += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return q + "\"";
}

std::vector<std::string> player_names(const TransferReport& r) {
  std::vector<std::string> names{"spastic"};
  for (const TransferController& c : r.options.controllers) names.push_back(c.name);
  return names;
}

}  // namespace

nlohmann::json to_json(const TransferReport& r) {
  const TransferBenchOptions& o = r.options;
  nlohmann::json controllers = nlohmann::json::array();
  controllers.push_back({{"name", "spastic"}, {"file", ""}, {"role", "baseline: the tracker-side spastic flipper"}});
  for (const TransferController& c : o.controllers) controllers.push_back({{"name", c.name}, {"file", c.file}});
  nlohmann::json sweep = nlohmann::json::array();
  for (const SweepFamily& f : o.sweep) {
    sweep.push_back({{"family", perturbation_name(f.kind)}, {"label", perturbation_label(f.kind)},
                     {"offset", is_offset(f.kind)}, {"values", f.values}});
  }
  nlohmann::json combined = nlohmann::json::array();
  for (const CombinedWorld& c : o.combined) {
    nlohmann::json changes = nlohmann::json::array();
    for (const auto& [kind, change] : c.changes)
      changes.push_back({{"family", perturbation_name(kind)}, {"change", change}});
    combined.push_back({{"name", c.name}, {"stepper", sim::stepper_kind_name(c.stepper)}, {"changes", changes}});
  }
  nlohmann::json worlds = nlohmann::json::array();
  for (const TransferWorld& w : r.worlds) {
    nlohmann::json cells = nlohmann::json::object();
    for (const TransferCell& c : w.cells) cells[c.controller] = cell_json(c);
    nlohmann::json row = {{"name", w.name},       {"family", w.family}, {"value", w.value},
                          {"world", w.world},     {"played", w.played}, {"balls", w.balls},
                          {"world_warnings", to_json_value(w.world_warnings)},       {"wall_s", w.wall_s},
                          {"cells", cells}};
    if (!w.played) row["skipped_reason"] = w.skipped_reason;
    worlds.push_back(row);
  }
  nlohmann::json sensitivity = nlohmann::json::object();
  for (const TransferSensitivity& s : r.sensitivities) {
    nlohmann::json& family = sensitivity[s.family];
    family["unit"] = s.unit;
    family["controllers"][s.controller] = {{"points_per_ball_lost_per_unit", s.points_per_ball_lost_per_unit},
                                           {"ci95_half_width", s.ci95_half_width},
                                           {"worlds", s.worlds}};
  }
  nlohmann::json summary = nlohmann::json::array();
  for (const TransferSummary& m : r.summaries) {
    summary.push_back({{"controller", m.controller},
                       {"worlds", m.worlds},
                       {"median_ratio", m.median_ratio},
                       {"lowest_ratio", m.lowest_ratio},
                       {"lowest_world", m.lowest_world},
                       {"lowest_ratio_ci95_low", m.lowest_interval ? nlohmann::json(m.lowest_interval->low) : nlohmann::json()},
                       {"lowest_ratio_ci95_high", m.lowest_interval ? nlohmann::json(m.lowest_interval->high) : nlohmann::json()},
                       {"worlds_at_target", m.worlds_at_target},
                       {"worlds_below_target", m.worlds_below_target}});
  }
  std::int64_t balls = 0;
  for (const TransferWorld& w : r.worlds) {
    for (const TransferCell& c : w.cells) balls += c.score.count();
  }
  return {{"benchmark", "transfer"},
          {"board", r.board},
          {"identified", o.identified.empty() ? nlohmann::json() : nlohmann::json(o.identified)},
          {"belief", kBelief},
          {"balls", o.balls},
          {"twin_balls", o.twin_balls},
          {"seed", o.seed},
          {"threads", o.threads},
          {"max_ball_time_s", o.max_ball_time_s},
          {"actuation_delay_s", o.actuation_delay_s},
          {"twin_actuation_delay_s", o.twin_actuation_delay_s},
          {"camera", to_json_value(o.camera)},
          {"pivot_axis", kPivotAxis},
          {"wall_rho_rule", kWallRhoRule},
          {"drains_rule", kDrainRule},
          {"ratio_interval", kRatioInterval},
          {"controllers", controllers},
          {"sweep", sweep},
          {"combined", combined},
          {"worlds", worlds},
          {"target_ratio", o.target_ratio},
          {"summary", summary},
          {"sensitivity", sensitivity},
          {"balls_played", balls},
          {"wall_s", r.wall_s}};
}

std::string to_text(const TransferReport& r) {
  const TransferBenchOptions& o = r.options;
  const std::vector<std::string> names = player_names(r);
  std::ostringstream out;
  out << "transfer on " << r.board << ": " << names.size() << " controllers x " << r.worlds.size() << " worlds, "
      << o.balls << " balls per cell (seed " << o.seed << ", the same balls in every cell), balls cut at "
      << format_number(o.max_ball_time_s) << " s; wall " << format_duration(r.wall_s) << "\n"
      << "belief: " << kBelief << (o.identified.empty() ? "" : ", " + o.identified + " laid over it")
      << "; pivots along " << kPivotAxis << "; wall rho " << kWallRhoRule << "\n";
  for (const CombinedWorld& c : o.combined) {
    out << c.name << ": the " << sim::stepper_kind_name(c.stepper) << " stepper";
    for (const auto& [kind, change] : c.changes) out << ", " << perturbation_name(kind) << " " << value_text(change, true);
    out << " (each relative to the model world)\n";
  }
  out << "mean score per ball (95 %), ratio to the spastic flipper in the same world (ratio interval: "
      << kRatioInterval << "), balls cut at " << format_number(o.max_ball_time_s) << " s:\n\n| world |";
  for (const std::string& n : names) out << ' ' << n << " |";
  out << "\n|---|";
  for (std::size_t i = 0; i < names.size(); ++i) out << "---:|";
  out << '\n';
  for (const TransferWorld& w : r.worlds) {
    std::string label = w.name;
    if ((w.family == "nominal" || w.family == "combined") && w.played) {
      const bool fewer = w.balls > 0 && w.balls != o.balls;
      label += " (" + w.world + (fewer ? ", " + std::to_string(w.balls) + " balls" : "") + ")";
    }
    out << "| " << label << " |";
    if (!w.played) {
      out << " skipped: " << w.skipped_reason << " |\n";
      continue;
    }
    for (const TransferCell& c : w.cells) out << ' ' << score_text(c, c.controller != "spastic") << " |";
    out << '\n';
  }
  if (!r.summaries.empty()) {
    out << "\nover the " << r.summaries.front().worlds << " worlds played, against " << format_number(o.target_ratio)
        << "x the spastic flipper (below it: worlds whose whole 95 % interval lies under it):\n\n"
        << "| controller | median world | lowest world | at " << format_number(o.target_ratio) << "x or more | below it |\n"
        << "|---|---:|---|---:|---:|\n";
    for (const TransferSummary& m : r.summaries) {
      out << "| " << m.controller << " | " << format_number(m.median_ratio, 3) << "x | " << format_number(m.lowest_ratio, 3)
          << "x" << interval_text(m.lowest_interval) << ", " << m.lowest_world << " | " << m.worlds_at_target << " | " << m.worlds_below_target << " |\n";
    }
  }
  out << "\ndrains: left outlane / right outlane / centre / other; of them left the table; mean s from the last "
         "flipper touch to an outlane drain (" << kDrainRule << "):\n\n"
      << "| world |";
  for (const std::string& n : names) out << ' ' << n << " |";
  out << "\n|---|";
  for (std::size_t i = 0; i < names.size(); ++i) out << "---:|";
  out << '\n';
  for (const TransferWorld& w : r.worlds) {
    if (!w.played) continue;
    out << "| " << w.name << " |";
    for (const TransferCell& c : w.cells) {
      out << ' ' << c.drains.left_outlane << " / " << c.drains.right_outlane << " / " << c.drains.centre << " / "
          << c.drains.other << "; " << c.drains.left_table;
      if (c.outlane_after_flipper_s.count() > 0) out << "; " << format_number(c.outlane_after_flipper_s.mean(), 2) << " s";
      out << " |";
    }
    out << '\n';
  }
  if (!r.sensitivities.empty()) {
    out << "\nwhat calibration errors cost: points per ball lost per unit of |error| (least squares over the "
           "sweep and the model world; 95 %, cells taken as independent):\n\n| error | unit |";
    for (const std::string& n : names) out << ' ' << n << " |";
    out << "\n|---|---|";
    for (std::size_t i = 0; i < names.size(); ++i) out << "---:|";
    out << '\n';
    std::vector<std::string> families;
    for (const TransferSensitivity& s : r.sensitivities) {
      if (std::find(families.begin(), families.end(), s.family) == families.end()) families.push_back(s.family);
    }
    for (const std::string& family : families) {
      std::string unit;
      std::ostringstream row;
      for (const std::string& n : names) {
        row << ' ';
        for (const TransferSensitivity& s : r.sensitivities) {
          if (s.family != family || s.controller != n) continue;
          unit = s.unit;
          row << format_mean_ci(s.points_per_ball_lost_per_unit, s.ci95_half_width);
        }
        row << " |";
      }
      out << "| " << family << " | " << unit << " |" << row.str() << '\n';
    }
  }
  return out.str();
}

std::string to_csv(const TransferReport& r) {
  std::ostringstream out;
  out.precision(10);
  out << "world,family,value,stepper,controller,status,balls,mean_score_per_ball,score_ci95_half_width,"
         "ratio_to_spastic,balls_cut_at_time_limit,max_ball_time_s,mean_ball_time_s,flips_per_ball,"
         "drains_left_outlane,drains_right_outlane,drains_centre,drains_other,drains_left_table,wall_s,"
         "ratio_ci95_low,ratio_ci95_high,outlane_drain_after_flipper_s_mean,max_score_per_ball\n";
  const std::vector<std::string> names = player_names(r);
  for (const TransferWorld& w : r.worlds) {
    std::ostringstream value;
    value << w.value;
    const std::string head = csv_text(w.name) + ',' + w.family + ',' + value.str() + ',' + w.world + ',';
    if (!w.played) {
      for (const std::string& n : names) {
        out << head << n << ',' << csv_text("skipped: " + w.skipped_reason) << ",0,,,,," << r.options.max_ball_time_s
            << ",,,,,,,,,,,,\n";
      }
      continue;
    }
    for (const TransferCell& c : w.cells) {
      out << head << c.controller << ",played," << c.score.count() << ',' << c.score.mean() << ','
          << csv_number(c.score.ci95_half_width()) << ',' << csv_number(c.ratio_to_spastic) << ',' << c.cut << ','
          << r.options.max_ball_time_s
          << ',' << c.duration_s.mean() << ',' << c.flips.mean() << ',' << c.drains.left_outlane << ','
          << c.drains.right_outlane << ',' << c.drains.centre << ',' << c.drains.other << ',' << c.drains.left_table
          << ',' << c.wall_s << ',';
      if (c.ratio_interval) out << c.ratio_interval->low << ',' << c.ratio_interval->high;
      else out << ',';
      out << ',';
      if (c.outlane_after_flipper_s.count() > 0) out << c.outlane_after_flipper_s.mean();
      out << ',' << c.score.max() << '\n';
    }
  }
  return out.str();
}

}  // namespace pinball::bench
