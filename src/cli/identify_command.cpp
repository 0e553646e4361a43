// `pinball identify LOG...`: the model's physical parameters from recorded
// play (learn/identification.h), reported with their uncertainties and
// residuals before and after, and written as a board overlay that every
// command holding a belief reads with --identified (docs/identification.md).

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <ostream>
#include <stdexcept>
#include <system_error>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "data_file.h"
#include "pinball/core/format.h"
#include "pinball/core/json_text.h"
#include "pinball/core/json_write_archive.h"
#include "pinball/core/number_option.h"
#include "pinball/core/progress.h"
#include "pinball/learn/identification.h"
#include "pinball/learn/prediction_error.h"
#include "pinball/table/board_loader.h"
#include "pinball/table/board_overlay.h"
#include "progress_option.h"

namespace pinball::cli {
namespace {

// Reading a log of half an hour takes seconds: shown as a stage of its own.
std::vector<bus::RecordedPlay> read_all(const std::vector<std::string>& paths, std::ostream* shown,
                                        const std::string& label) {
  std::vector<bus::RecordedPlay> plays;
  if (paths.empty()) return plays;
  ProgressMeter meter(shown, "identify: " + label, static_cast<double>(paths.size()), "logs");
  meter.update(0);
  for (const std::string& path : paths) {
    plays.push_back(bus::read_recorded_play(path));
    meter.update(static_cast<double>(plays.size()));
  }
  return plays;
}

// The same file twice would count its events twice (and a held-out log that
// is fitted is no test); an --out that is an input would be replaced by the overlay.
void check_distinct_files(const IdentifyArgs& a) {
  check_distinct_inputs(a.logs, "identify: log", "its events would count twice");
  check_distinct_inputs(a.held_out, "identify: --held-out", "its moments would count twice");
  for (std::size_t i = 0; i < a.logs.size(); ++i) {
    for (const std::string& held : a.held_out) {
      if (same_file(a.logs[i], held) || same_contents(a.logs[i], held)) {
        throw std::runtime_error("identify: --held-out " + held + " is also a fitted log" +
                                 (same_file(a.logs[i], held) ? "" : " (a copy of " + a.logs[i] + ")") +
                                 ": a held-out log must be one never fitted");
      }
    }
  }
  std::vector<std::pair<const char*, std::string>> inputs{{"--board", find_data_file(a.board)}};
  for (const std::string& log : a.logs) inputs.emplace_back("log", log);
  for (const std::string& log : a.held_out) inputs.emplace_back("--held-out", log);
  check_outputs_replace_no_input({{"identify: --out", a.out}}, inputs);
}

// Copies of one recording whose bytes differ (a channel dropped, a log re-logged) pass
// check_distinct_files; they still share every frame, and would count twice, or test on fitted play.
void check_no_recording_twice(const std::vector<bus::RecordedPlay>& plays, const std::vector<bus::RecordedPlay>& held) {
  const auto check = [](const bus::RecordedPlay& a, const bus::RecordedPlay& b, const std::string& what_b,
                        const char* why) {
    const bus::SharedSightings s = bus::shared_sightings(a, b);
    if (!s.same_recording()) return;
    throw std::runtime_error("identify: " + what_b + " and " + a.source + " share " + std::to_string(s.shared) +
                             " sightings of the moving ball (of " + std::to_string(s.moving_b) + " and " +
                             std::to_string(s.moving_a) + "; the first at frame " + std::to_string(s.first_seq) +
                             ", t = " + format_number(s.first_t_s) + " s): one recording twice; " + why);
  };
  for (std::size_t i = 0; i < plays.size(); ++i) {
    for (std::size_t k = i + 1; k < plays.size(); ++k) {
      check(plays[i], plays[k], "log " + plays[k].source, "its events would count twice");
    }
    for (const bus::RecordedPlay& h : held) {
      check(plays[i], h, "--held-out " + h.source, "a held-out log must be one never fitted");
    }
  }
  for (std::size_t i = 0; i < held.size(); ++i) {
    for (std::size_t k = i + 1; k < held.size(); ++k) {
      check(held[i], held[k], "--held-out " + held[k].source, "its moments would count twice");
    }
  }
}

// The standard uncertainty of the flippers' mean rise delay (the actuation
// delay the model worlds play): independent flippers, sqrt(sum s^2) / n.
double actuation_delay_stderr_s(const table::BoardOverlay& overlay) {
  double sum_sq = 0.0;
  int n = 0;
  for (const table::FlipperOverlay& f : overlay.flippers) {
    if (!f.rise_delay_s) continue;
    sum_sq += f.rise_delay_s->stderr_ * f.rise_delay_s->stderr_;
    ++n;
  }
  return n > 0 ? std::sqrt(sum_sq) / n : 0.0;
}

std::string value_text(const table::IdentifiedValue& v, const char* unit) {
  return format_number(v.value) + " ± " + format_number(v.stderr_, 2) + unit;
}

// A mean error in mm, or "none" for a class with no moment (NaN).
std::string mm_text(double m) { return std::isnan(m) ? std::string("none") : format_number(m * 1000.0) + " mm"; }

std::string prediction_text(const learn::PredictionError& e) {
  return format_mean_ci(e.mean_m * 1000.0, e.mean_ci95_m * 1000.0) + " mm mean, " + format_number(e.median_m * 1000.0) +
         " mm median, " + format_number(e.p90_m * 1000.0) + " mm p90 (mean " + mm_text(e.free_mean_m) + " over " +
         std::to_string(e.free_moments) + " free flights, " + mm_text(e.collision_mean_m) +
         " where the ball hit something)";
}

struct HeldOut {
  std::size_t moments = 0;
  learn::PredictionError nominal, identified;
};

// A figure of a fit that did not run is null, not 0 (which reads as a perfect fit).
nlohmann::json when(bool measured, double value) { return measured ? nlohmann::json(value) : nlohmann::json(); }


// The board's own model misses a log of its table by a few mm 100 ms ahead (1-5 mm; a twin's, up to
// 15 mm). Far beyond, the log is of another table, or its camera calibration is another's: the fit
// runs and writes an overlay all the same (a log shifted 60 mm gave an overlay that lost every ball).
constexpr double kForeignLogError_m = 0.025;

std::vector<std::string> identify_warnings(const learn::IdentificationResult& r, const table::Board& board) {
  std::vector<std::string> out;
  if (r.wall_thickness.moments > 0 && r.wall_thickness.error_at_zero_m > kForeignLogError_m) {
    out.push_back("the board's own model misses the ball by " +
                  format_number(r.wall_thickness.error_at_zero_m * 1e3, 3) + " mm on average 100 ms ahead (a few mm on a log of its table): is the log of " + board.source +
                  ", and its calibration this table's?");
  }
  return out;
}
nlohmann::json result_json(const IdentifyArgs& a, const table::Board& board, const learn::IdentificationResult& r,
                           const std::optional<HeldOut>& held_out) {
  nlohmann::json groups = nlohmann::json::array();
  for (const learn::GroupResult& g : r.groups) {
    groups.push_back({{"board_rho", g.overlay.board_rho},
                      {"board_kick_mps", g.overlay.board_kick_mps},
                      {"obstacles", g.overlay.obstacles},
                      {"identified", g.identified},
                      {"why_not", g.identified ? nlohmann::json(nullptr) : nlohmann::json(g.why_not)},
                      {"rebounds", g.rebounds},
                      {"at_speed_clamp", g.at_speed_clamp},
                      {"outliers", g.outliers},
                      {"rho", g.identified ? to_json_value(g.overlay.rho) : nlohmann::json(nullptr)},
                      {"kick_mps", g.overlay.kick_mps ? to_json_value(*g.overlay.kick_mps) : nlohmann::json(nullptr)},
                      {"rms_nominal_mps", when(g.rebounds > 0, g.rms_nominal_mps)},
                      {"rms_fitted_mps", when(g.identified, g.rms_fitted_mps)},
                      {"friction", g.overlay.friction ? to_json_value(*g.overlay.friction) : nlohmann::json(nullptr)},
                      {"friction_outliers", g.friction.outliers},
                      {"tangent_rms_frictionless_mps",
                       when(g.overlay.friction.has_value(), g.friction.rms_frictionless_mps)},
                      {"tangent_rms_fitted_mps", when(g.overlay.friction.has_value(), g.friction.rms_fitted_mps)}});
  }
  const learn::WallThicknessFit& t = r.wall_thickness;
  nlohmann::json scan = nlohmann::json::array();
  for (const auto& [thickness_m, error_m] : t.scan) scan.push_back({{"thickness_m", thickness_m}, {"mean_error_m", error_m}});
  const nlohmann::json thickness = {{"identified", t.identified},
                                    {"why_not", t.identified ? nlohmann::json(nullptr) : nlohmann::json(t.why_not)},
                                    {"thickness_m", when(t.identified, t.thickness_m)},
                                    {"stderr_m", when(t.identified, t.stderr_m)},
                                    {"at_scan_edge", t.at_scan_edge},
                                    {"moments", t.moments},
                                    {"error_at_zero_m", when(!t.scan.empty(), t.error_at_zero_m)},
                                    {"error_fitted_m", when(t.identified, t.error_fitted_m)},
                                    {"scan", scan}};
  nlohmann::json strokes = nlohmann::json::array();
  for (const learn::FlipperStrokeFit& f : r.flipper_strokes) {
    const table::Flipper& on_board = board.flippers[static_cast<std::size_t>(&f - r.flipper_strokes.data())];
    strokes.push_back({{"name", f.name},
                       {"board_omega_rad_s", on_board.omega_rad_s},
                       {"board_mu", on_board.mu},
                       {"shots", f.shots},
                       {"outliers", f.outliers},
                       {"identified", f.identified},
                       {"why_not", f.identified ? nlohmann::json(nullptr) : nlohmann::json(f.why_not)},
                       {"rise_delay_s", f.identified ? to_json_value(f.rise_delay_s) : nlohmann::json(nullptr)},
                       {"omega_rad_s", f.identified ? to_json_value(f.omega_rad_s) : nlohmann::json(nullptr)},
                       {"mu", f.mu ? to_json_value(*f.mu) : nlohmann::json(nullptr)},
                       {"timing_rms_nominal_s", when(f.shots > 0, f.timing_rms_nominal_s)},
                       {"timing_rms_fitted_s", when(f.identified, f.timing_rms_fitted_s)},
                       {"velocity_error_nominal_mps", when(f.shots > 0, f.velocity_error_nominal_mps)},
                       {"velocity_error_delay_only_mps", when(f.identified, f.velocity_error_delay_only_mps)},
                       {"stroke_laid_over_board", f.identified && f.stroke_replays_better()},
                       {"velocity_error_fitted_mps", when(f.identified, f.velocity_error_fitted_mps)}});
  }
  nlohmann::json not_identified = nlohmann::json::array();
  for (const learn::NotIdentified& n : r.not_identified)
    not_identified.push_back({{"parameter", n.parameter}, {"why", n.why}});
  nlohmann::json j{{"warnings", identify_warnings(r, board)},
                   {"board", board.source},
                   {"recordings", a.logs},
                   {"recorded_s", r.recorded_s},
                   {"frames", r.frames},
                   {"sightings", r.sightings},
                   {"malformed_messages", r.malformed},
                   {"first_malformed",
                    r.first_malformed.empty() ? nlohmann::json() : nlohmann::json(r.first_malformed)},
                   {"commands", r.commands},
                   {"free_flights", r.flights},
                   {"board_gravity_mps2", board.gravity_mps2},
                   {"gravity", to_json_value(r.gravity_no_drag)},
                   {"gravity_with_drag", to_json_value(r.gravity)},
                   {"sliding_friction", to_json_value(r.sliding)},
                   {"obstacle_groups", groups},
                   {"rebounds", r.rebounds.size()},
                   {"launches", r.launch_speeds_mps.size()},
                   {"flipper_shots", r.shots.size()},
                   {"flippers", strokes},
                   {"actuation_delay_s", table::identified_actuation_delay_s(r.overlay)
                                             ? nlohmann::json(*table::identified_actuation_delay_s(r.overlay))
                                             : nlohmann::json(nullptr)},
                   {"actuation_delay_stderr_s", table::identified_actuation_delay_s(r.overlay)
                                                    ? nlohmann::json(actuation_delay_stderr_s(r.overlay))
                                                    : nlohmann::json(nullptr)},
                   {"launcher", r.overlay.launcher ? to_json_value(*r.overlay.launcher) : nlohmann::json(nullptr)},
                   {"wall_thickness", thickness},
                   {"not_identified", not_identified},
                   {"overlay", a.out.empty() ? nlohmann::json(nullptr) : nlohmann::json(a.out)},
                   {"held_out", nullptr}};
  if (held_out) {
    const learn::ErrorRatio ratio = learn::paired_error_ratio(held_out->identified, held_out->nominal);
    j["held_out"] = {{"recordings", a.held_out},
                     {"horizon_s", learn::PredictionOptions{}.horizon_s},
                     {"nominal", to_json_value(held_out->nominal)},
                     {"identified", to_json_value(held_out->identified)},
                     {"error_ratio", ratio.ratio},
                     {"error_ratio_ci95", ratio.ci95},
                     {"error_ratio_moments", ratio.moments}};
  }
  if (r.sliding.skidding == 0) {  // no flight skidded: no friction was measured, not a friction of 0
    j["sliding_friction"]["decel_mps2"] = nullptr;
    j["sliding_friction"]["decel_stderr_mps2"] = nullptr;
  } else if (r.sliding.skidding == 1) {  // one flight has no spread: its uncertainty is unknown, not 0
    j["sliding_friction"]["decel_stderr_mps2"] = nullptr;
  }
  return j;
}

void print_text(const IdentifyArgs& a, const table::Board& board, const learn::IdentificationResult& r,
                const std::optional<HeldOut>& held_out, std::ostream& out) {
  const double seen = r.frames > 0 ? 100.0 * static_cast<double>(r.sightings) / static_cast<double>(r.frames) : 0.0;
  out << "identify: " << a.logs.size() << " recording(s), " << format_number(r.recorded_s) << " s, " << r.frames
      << " frames (" << format_number(seen) << " % saw the ball), " << r.commands << " commands, " << r.flights
      << " free flights\n";
  if (r.malformed > 0) {
    out << "  " << r.malformed << " messages on PINBALL_OBSERVATION and PINBALL_FLIPPER_CMD left out (they do not "
        << "decode, or have a bad field); the first: " << r.first_malformed << "\n";
  }
  const learn::FlightGravity& g = r.gravity_no_drag;
  out << "  g along the table  " << value_text(*r.overlay.gravity_mps2, " m/s²") << " (board "
      << format_number(board.gravity_mps2) << "; " << g.flights << " flights, " << g.flights_dropped
      << " left out; " << (g.bootstrap_resamples > 0 ? std::to_string(g.bootstrap_resamples) + " bootstrap resamples"
                                                     : std::string("the fit's covariance"))
      << "); flight residual " << format_number(g.rms_nominal_m * 1000.0) << " mm -> "
      << format_number(g.rms_fitted_m * 1000.0) << " mm\n";
  out << "  sideways tilt      " << format_number(g.lateral_mps2) << " ± " << format_number(g.lateral_stderr_mps2, 2)
      << " m/s² (diagnostic: the model has none)\n";
  if (r.gravity.drag_fitted)
    out << "  drag               " << format_number(r.gravity.drag_per_s) << " ± "
        << format_number(r.gravity.drag_stderr_per_s, 2) << " 1/s, with g " << format_number(r.gravity.g_mps2)
        << " ± " << format_number(r.gravity.g_stderr_mps2, 2)
        << " (diagnostic: the model has no drag; its speed clamp stands in)\n";
  out << "  sliding friction   ";
  if (r.sliding.skidding > 0)
    out << format_number(r.sliding.decel_mps2) << " ± "
        << (r.sliding.skidding > 1 ? format_number(r.sliding.decel_stderr_mps2, 2) : std::string("?"))
        << " m/s² (mu times g normal to the table)";
  else
    out << "none seen";
  out << ": " << r.sliding.skidding << " of " << r.sliding.flights << " flights of "
      << format_number(r.sliding.min_duration_s) << " s or more skid (diagnostic: the model's ball has no spin)\n";
  for (const learn::GroupResult& group : r.groups) {
    if (!group.identified) continue;
    out << "  rho " << format_number(group.overlay.board_rho);
    if (group.overlay.board_kick_mps > 0.0) out << " kick " << format_number(group.overlay.board_kick_mps);
    out << " (" << group.overlay.obstacles.size() << " obstacles: " << group.overlay.obstacles.front()
        << (group.overlay.obstacles.size() > 1 ? ", ..." : "") << "): rho " << value_text(group.overlay.rho, "");
    if (group.overlay.kick_mps) out << ", kick " << value_text(*group.overlay.kick_mps, " m/s");
    out << " (" << group.rebounds << " rebounds, "
        << (group.at_speed_clamp > 0 ? std::to_string(group.at_speed_clamp) + " at the speed clamp, " : std::string())
        << group.outliers << " outliers); residual "
        << format_number(group.rms_nominal_mps) << " -> " << format_number(group.rms_fitted_mps) << " m/s";
    if (group.overlay.friction)
      out << "; friction " << value_text(*group.overlay.friction, "") << " (" << group.friction.outliers
          << " outliers), tangential residual " << format_number(group.friction.rms_frictionless_mps) << " -> "
          << format_number(group.friction.rms_fitted_mps) << " m/s";
    out << "\n";
  }
  for (const learn::FlipperStrokeFit& f : r.flipper_strokes) {
    if (!f.identified) continue;
    const table::Flipper& on_board = board.flippers[static_cast<std::size_t>(&f - r.flipper_strokes.data())];
    out << "  flipper " << f.name << ": rise delay " << format_number(f.rise_delay_s.value * 1000.0) << " ± "
        << format_number(f.rise_delay_s.stderr_ * 1000.0, 2) << " ms, stroke " << value_text(f.omega_rad_s, " rad/s")
        << " (board " << format_number(on_board.omega_rad_s) << ")";
    if (f.mu) out << ", mu " << value_text(*f.mu, "") << " (board " << format_number(on_board.mu) << ")";
    out << " (" << f.shots << " shots, " << f.outliers << " outliers); contact time residual "
        << format_number(f.timing_rms_nominal_s * 1000.0) << " -> " << format_number(f.timing_rms_fitted_s * 1000.0)
        << " ms; replayed shots' velocity error (median): board " << format_number(f.velocity_error_nominal_mps)
        << ", identified delay " << format_number(f.velocity_error_delay_only_mps) << ", identified delay, stroke and mu "
        << format_number(f.velocity_error_fitted_mps) << " m/s\n";
  }
  if (const std::optional<double> delay = table::identified_actuation_delay_s(r.overlay))
    out << "  actuation delay    " << format_number(*delay * 1000.0) << " ± "
        << format_number(actuation_delay_stderr_s(r.overlay) * 1000.0, 2)
        << " ms, the flippers' mean rise delay: the model worlds of learn and bench play it with --identified\n";
  if (r.overlay.launcher)
    out << "  launcher           pull " << value_text(r.overlay.launcher->pull, "") << ", noise "
        << value_text(r.overlay.launcher->noise_max, "") << " (" << r.launch_speeds_mps.size() << " launches)\n";
  if (r.wall_thickness.identified)
    out << "  wall thickness     " << format_number(r.wall_thickness.thickness_m * 1000.0) << " ± "
        << format_number(r.wall_thickness.stderr_m * 1000.0, 2) << " mm, every two-sided wall (" << r.wall_thickness.moments
        << " moments: the model's mean error 100 ms ahead " << format_number(r.wall_thickness.error_at_zero_m * 1000.0)
        << " mm with the file's lines -> " << format_number(r.wall_thickness.error_fitted_m * 1000.0) << " mm"
        << (r.wall_thickness.at_scan_edge ? "; least at the scan's edge: its uncertainty is half a scan step" : "")
        << ")\n";
  for (const learn::NotIdentified& n : r.not_identified)
    out << "  not identified: " << n.parameter << ": " << n.why << "\n";
  for (const std::string& w : identify_warnings(r, board)) out << "  warning: " << w << "\n";
  if (held_out) {
    out << "  held out, ball " << format_number(learn::PredictionOptions{}.horizon_s * 1000.0) << " ms ahead ("
        << held_out->nominal.moments << " moments): board " << prediction_text(held_out->nominal) << "; identified "
        << prediction_text(held_out->identified) << "\n";
    const learn::ErrorRatio ratio = learn::paired_error_ratio(held_out->identified, held_out->nominal);
    out << "  held out, identified / board mean error: " << format_number(ratio.ratio, 3) << " ± "
        << format_number(ratio.ci95, 2) << " (95 %, paired over " << ratio.moments << " moments)\n";
    const learn::PredictionError& nominal = held_out->nominal;
    const learn::PredictionError& fitted = held_out->identified;
    out << "  held out, by what moved the ball in the history (mean error, board -> identified): g alone "
        << fitted.under_g_moments << " moments, " << mm_text(nominal.under_g_mean_m) << " -> "
        << mm_text(fitted.under_g_mean_m) << "; something more (a skid, a wall or flipper it "
        << "rolled along) " << fitted.pushed_moments << " moments, " << mm_text(nominal.pushed_mean_m) << " -> "
        << mm_text(fitted.pushed_mean_m) << "\n";
    out << "  held out, where the ball hit something, by what the identified model hit first (mean error, board -> "
           "identified):\n";
    for (const learn::CollisionError& c : held_out->identified.collisions_by_model_hit) {
      if (c.moments == 0) continue;  // a kind of hit the held-out play never had: no mean to give
      const auto& board_hits = held_out->nominal.collisions_by_model_hit;
      const auto same = std::find_if(board_hits.begin(), board_hits.end(),
                                     [&](const learn::CollisionError& b) { return b.model_hit == c.model_hit; });
      out << "    " << c.model_hit << ": " << c.moments << " moments, "
          << (same == board_hits.end() ? std::string("-") : format_number(same->mean_m * 1000.0)) << " -> "
          << format_number(c.mean_m * 1000.0) << " mm\n";
    }
  }
  if (!a.out.empty()) out << "wrote " << a.out << " (use it with --identified)\n";
}

}  // namespace

CLI::App* add_identify_command(CLI::App& app, IdentifyArgs& a) {
  CLI::App* cmd = app.add_subcommand(
      "identify", "fit the model's physical parameters to recorded play (LCM logs of PINBALL_OBSERVATION and "
                  "PINBALL_FLIPPER_CMD) and write a board overlay (docs/identification.md)");
  cmd->add_option("logs", a.logs, "LCM logs of recorded play (pinballd --lcm-url file://...?mode=w, lcm-logger)")
      ->required()
      ->check(input_file());
  cmd->add_option("--held-out", a.held_out, "LCM logs never fitted: the 100 ms prediction error of board and overlay")
      ->check(input_file());
  cmd->add_option("--board", a.board, "board file of the recorded table (its geometry; the values it guesses are fitted)")
      ->transform(data_file());
  cmd->add_option("--out", a.out, "overlay file to write (YAML); none: report only")->check(output_file());
  cmd->add_option("--sigma-m", a.sigma_m, "detector noise of one coordinate (m): the free-flight χ² test")
      ->check(finite_range(1e-5, 0.05));
  cmd->add_option("--bootstrap", a.bootstrap,
                  "resamples behind g's and the wall thickness's uncertainties, 2..10000 (0: g's from the fit's "
                  "covariance, the thickness not identified)")
      ->check(zero_or_range(2, 10000));
  cmd->add_option("--seed", a.seed, "seed of the bootstrap")
      ->check(unsigned_64());
  cmd->add_flag("--json", a.json, "print one JSON object");
  add_progress_flag(*cmd, a.progress);
  return cmd;
}

int run_identify(const IdentifyArgs& a, std::ostream& out, std::ostream& err) {
  const auto start = std::chrono::steady_clock::now();
  check_output_folder(a.out, "--out");
  check_distinct_files(a);
  const table::Board board = table::load_board(find_data_file(a.board));  // the default too, from any folder
  std::ostream* shown = progress_wanted(a.progress) ? &err : nullptr;
  const std::vector<bus::RecordedPlay> plays = read_all(a.logs, shown, "reading logs");
  const std::vector<bus::RecordedPlay> held = read_all(a.held_out, shown, "reading held-out logs");
  check_no_recording_twice(plays, held);
  for (const std::vector<bus::RecordedPlay>* logs : {&plays, &held}) {
    for (const bus::RecordedPlay& play : *logs) learn::check_recording_fits_board(play, board);
  }
  learn::IdentifyOptions options;
  options.flights.sigma_m = a.sigma_m;
  options.bootstrap = a.bootstrap;
  options.seed = a.seed;
  std::optional<ProgressMeter> meter;
  std::string stage;
  // The held-out moments first: a log too short to test on is said before the fit, not as a ratio of 0.
  learn::PredictionOptions prediction;
  prediction.sigma_m = a.sigma_m;
  const std::vector<learn::PredictionStart> starts = learn::prediction_starts(held, prediction);
  if (!held.empty() && starts.empty()) {
    std::string names;
    for (const std::string& h : a.held_out) names += (names.empty() ? "" : ", ") + h;
    throw std::runtime_error("identify: --held-out " + names + " holds no moment to predict from (none with " +
                             format_number(prediction.horizon_s * 1e3) +
                             " ms of seen ball ahead); record more play to test on");
  }
  const learn::IdentificationResult r =
      learn::identify_table(board, plays, options, [&](const std::string& name, int done, int total) {
        if (name != stage) meter.emplace(shown, "identify: " + name, total, "");
        stage = name;
        meter->update(done);
      });
  std::optional<HeldOut> held_out;
  if (!held.empty()) {
    table::Board identified = board;
    table::apply_board_overlay(r.overlay, "(identified)", identified);
    held_out = HeldOut{starts.size(), learn::prediction_error(board, held, starts, prediction),
                       learn::prediction_error(identified, held, starts, prediction)};
  }
  if (!a.out.empty()) table::write_board_overlay(r.overlay, a.out);
  if (a.json) {
    nlohmann::json j = result_json(a, board, r, held_out);
    j["wall_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    out << json_text(j, 2) << "\n";
  } else {
    print_text(a, board, r, held_out, out);
  }
  return 0;
}

}  // namespace pinball::cli
