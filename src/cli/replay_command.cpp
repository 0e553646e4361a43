// `pinball replay LOG`: the recorded observations of an LCM log through the
// daemon's tracker and controller, offline; reports whether the recorded
// decisions come out again.

#include <nlohmann/json.hpp>

#include <filesystem>
#include <ostream>
#include <system_error>
#include <string>

#include "commands.h"
#include "data_file.h"
#include "progress_option.h"
#include "pinball/core/json_text.h"
#include "pinball/core/progress.h"
#include "pinball/daemon/replay.h"

namespace pinball::cli {

CLI::App* add_replay_command(CLI::App& app, ReplayArgs& a) {
  CLI::App* cmd = app.add_subcommand(
      "replay", "replay the observations of an LCM log (lcm-logger, pinballd) through the tracker and controller");
  cmd->add_option("log", a.log, "LCM log file")->required()->check(input_file());
  cmd->add_option("--config", a.config, "the pinballd configuration the log was recorded with (default: none)")
      ->transform(data_file());
  const daemon::DaemonConfig defaults;
  cmd->add_option("--board", a.board, "board file (default: the configuration's, else " + defaults.sim.board + ")")
      ->transform(data_file());
  cmd->add_option("--controller", a.controller,
                  "controller file (default: the configuration's, else " + defaults.controller + ")")
      ->transform(data_file());
  cmd->add_flag("--json", a.json, "print one JSON object");
  add_progress_flag(*cmd, a.progress);
  return cmd;
}

namespace {

// The verdict in one sentence, the text's last line and the JSON's "verdict".
// (A log with nothing to compare is refused before: replay_log throws.)
std::string verdict(const daemon::ReplayReport& r) {
  if (r.reproduced) return "reproduced: every recorded decision came out again, in order";
  return "NOT reproduced: first difference at decision " + std::to_string(r.first_mismatch) + ": " + r.mismatch;
}

}  // namespace

int run_replay(const ReplayArgs& a, std::ostream& out, std::ostream& err) {
  daemon::DaemonConfig config;
  if (!a.config.empty()) config = daemon::load_daemon_config(a.config);
  if (!a.board.empty()) {
    config.sim.board = a.board;
    config.board = a.board;
  }
  if (!a.controller.empty()) config.controller = a.controller;
  // What the decisions were replayed with: a log recorded with another controller is "NOT reproduced".
  const std::string board = config.mode == "sim" ? config.sim.board : config.board;
  const bool defaults_only = a.config.empty() && a.controller.empty();
  // By bytes of the log, with the ETA; stderr stays quiet for a script.
  std::error_code size_error;
  const double log_mb = static_cast<double>(std::filesystem::file_size(a.log, size_error)) * 1e-6;
  ProgressMeter meter(progress_wanted(a.progress) ? &err : nullptr, "replay", log_mb, "MB of the log",
                      !a.progress && progress_wanted(false));
  const daemon::ReplayReport r = daemon::replay_log(a.log, config, [&](const daemon::ReplayProgress& p) {
    meter.update(static_cast<double>(p.bytes_read) * 1e-6, std::to_string(p.observations) + " observations");
  });
  if (a.json) {
    out << json_text(nlohmann::json{{"board", board},
                                    {"controller", config.controller},
                                    {"events", r.events},
                                    {"observations", r.observations},
                                    {"observations_without_latency", r.observations_without_latency},
                                    {"malformed", r.malformed},
                                    {"recorded_commands", r.recorded_commands},
                                    {"replayed_commands", r.replayed_commands},
                                    {"matched", r.matched},
                                    {"first_mismatch", r.first_mismatch},
                                    {"mismatch", r.mismatch},
                                    {"skipped_timing", r.skipped_timing},
                                    {"reproduced", r.reproduced},
                                    {"verdict", verdict(r)}},
                     2)
        << "\n";
  } else {
    out << "replayed with    controller " << config.controller << ", board " << board
        << (defaults_only ? " (the defaults: give --controller or --config as recorded)" : "") << "\n";
    out << "observations " << r.observations << "  recorded decisions " << r.recorded_commands << "  replayed "
        << r.replayed_commands << "  matched " << r.matched << "  malformed " << r.malformed << "\n";
    out << verdict(r) << "\n";
    if (r.observations_without_latency > 0) {
      out << r.observations_without_latency << " observations were recorded before the delivery stamp: their camera "
          << "latency is unknown (replayed as 0), so a leading controller's decisions may differ\n";
    }
  }
  return r.reproduced ? 0 : 3;
}

}  // namespace pinball::cli
