// `pinball track --board BOARD --observations FILE.csv`: runs the tracker over
// recorded observations and prints one trajectory projection per observation.

#include <cstdio>
#include <ostream>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "data_file.h"
#include "pinball/calibration/calibration_file.h"
#include "pinball/core/json_text.h"
#include "pinball/core/number_option.h"
#include "pinball/table/board_loader.h"
#include "pinball/track/observation_io.h"
#include "pinball/track/tracker.h"

namespace pinball::cli {

CLI::App* add_track_command(CLI::App& app, TrackArgs& a) {
  CLI::App* cmd = app.add_subcommand("track", "run the tracker over an observation file (t,x,y)");
  cmd->add_option("--board", a.board, "board file: the flipper geometry")->required()->transform(data_file());
  cmd->add_option("--observations", a.observations,
                  "CSV with header t,x,y (s, m, board frame), optionally ,left_contact,right_contact (0/1); "
                  "or a sim --trace file")
      ->required()
      ->check(input_file());
  cmd->add_option("--gravity", a.gravity_mps2, "gravity along the table (m/s^2); default: the board's")
      ->check(finite_range(0.0, 100.0))
      ->default_str("");  // -1: the board's
  cmd->add_option("--sigma", a.sigma_m,
                  "observation noise, standard deviation per coordinate (m); default: the default camera's")
      ->check(finite_range(1e-7, 1.0))
      ->default_str("");  // 0: the camera's
  cmd->add_option("--calibration", a.calibration,
                  "calibration file (pinball calibrate): flipper geometry and gravity instead of the board's")
      ->transform(data_file());
  cmd->add_flag("--json", a.json, "print one JSON object instead of CSV");
  return cmd;
}

namespace {

const char* side_name(int flipper) { return flipper == track::kLeftFlipper ? "left" : "right"; }

}  // namespace

int run_track(const TrackArgs& a, std::ostream& out, std::ostream& err) {
  const table::Board board = table::load_board(a.board);
  const std::vector<track::ObservationRow> rows = track::read_observations_csv(a.observations);
  track::check_observations_on_board(rows, board, a.observations);
  track::TrackerConfig config = track::default_tracker_config(board, track::CameraModelConfig{});
  track::FlipperGeometry geometry = track::flipper_geometry_from_board(board);
  if (!a.calibration.empty()) {
    const calibration::Calibration c = calibration::read_calibration(a.calibration);
    calibration::check_calibration_matches_board(c, a.calibration, board);
    calibration::apply_calibration(c, a.calibration, config, geometry);
  }
  if (a.gravity_mps2 >= 0.0) config.g_mps2 = a.gravity_mps2;
  if (a.sigma_m > 0.0) config.sigma_m = a.sigma_m;
  track::Tracker tracker(geometry, config);

  // --json streams its projections, one line each, and closes with the counts: a whole array built
  // first took 2.5 GB for 10^6 observations.
  if (a.json) out << "{\n  \"projections\": [";
  bool first_projection = true;
  int valid = 0;
  int launches = 0;
  int losses = 0;
  if (!a.json) out << "t,valid,flipper,speed,angle,h,d,t_impact,rolling\n";
  for (const track::ObservationRow& row : rows) {
    const track::TrackerOutput& o = tracker.update(row.observation, row.contacts);
    const track::TrajectoryProjection& p = o.projection;
    valid += p.valid ? 1 : 0;
    launches += o.launch.launched ? 1 : 0;
    losses += o.launch.lost ? 1 : 0;
    if (a.json) {
      nlohmann::json j = {{"t", row.observation.t_s}, {"valid", p.valid}, {"reason", track::to_string(p.reason)},
                          {"window", o.window},       {"flushed", o.flushed}, {"pushed", o.pushed},
                          {"launched", o.launch.launched},
                          {"lost", o.launch.lost}};
      if (p.valid) {
        j.update({{"flipper", side_name(p.flipper)}, {"speed_mps", p.speed_mps}, {"angle_rad", p.angle_rad},
                  {"h", p.h}, {"d_m", p.d_m}, {"t_impact_s", p.t_impact_s}, {"hittable", p.hittable},
                  {"rolling", p.rolling}});
      }
      out << (first_projection ? "\n    " : ",\n    ") << json_text(j);
      first_projection = false;
    } else {
      char line[256];
      if (p.valid) {
        // t to the microsecond at any clock (a clock since the epoch printed 1.7e+09 on every row).
        std::snprintf(line, sizeof line, "%.6f,1,%s,%.9g,%.9g,%.9g,%.9g,%.9g,%d\n", row.observation.t_s,
                      side_name(p.flipper), p.speed_mps, p.angle_rad, p.h, p.d_m, p.t_impact_s, p.rolling ? 1 : 0);
      } else {
        std::snprintf(line, sizeof line, "%.6f,0,,,,,,,0\n", row.observation.t_s);
      }
      out << line;
    }
  }
  err << "track: " << rows.size() << " observations, " << valid << " projections, " << launches << " launches, "
      << losses << " losses, " << tracker.flushes() << " collision flushes, " << tracker.pushes()
      << " pushed fits, " << tracker.gap_restarts() << " new paths after a gap\n";
  if (a.json) {
    const nlohmann::json summary{{"board", a.board},
                                 {"observations_file", a.observations},
                                 {"calibration", a.calibration},
                                 {"gravity_mps2", config.g_mps2},
                                 {"sigma_m", config.sigma_m},
                                 {"observations", rows.size()},
                                 {"valid_projections", valid},
                                 {"launches", launches},
                                 {"losses", losses},
                                 {"collision_flushes", tracker.flushes()},
                                 {"pushed_fits", tracker.pushes()},
                                 {"gap_restarts", tracker.gap_restarts()},
                                 {"max_gap_s", config.max_gap_s}};
    const std::string counts = json_text(summary, 2);
    out << "\n  ],\n" << counts.substr(2) << "\n";  // the counts' keys after the array, in the one object
  }
  return 0;
}

}  // namespace pinball::cli
