// `pinball bench KIND`: the measurements behind docs/results.md.

#include <ostream>

#include "commands.h"
#include "pinball/sim/board_loader.h"
#include "speed_bench.h"

namespace pinball::cli {

CLI::App* add_bench_command(CLI::App& app, BenchArgs& a) {
  CLI::App* cmd = app.add_subcommand("bench", "run a benchmark (speed)");
  cmd->add_option("kind", a.which, "which benchmark: speed")->required()->check(CLI::IsMember({"speed"}));
  cmd->add_option("--board", a.board, "board file")->check(CLI::ExistingFile);
  cmd->add_option("--steps", a.steps, "steps per timed run")->check(CLI::Range(1000, 1'000'000'000));
  cmd->add_option("--repeats", a.repeats, "timed runs per configuration (median reported)")->check(CLI::Range(1, 99));
  cmd->add_flag("--json", a.json, "print one JSON object instead of text");
  return cmd;
}

int run_bench(const BenchArgs& a, std::ostream& out, std::ostream& err) {
  const sim::Board board = sim::load_board(a.board);
  bench::SpeedBenchOptions options;
  options.steps = a.steps;
  options.repeats = a.repeats;
  const bench::SpeedReport report =
      bench::run_speed_bench(board, options, [&](const std::string& line) { err << "bench speed: " << line << "\n"; });
  if (a.json) {
    out << bench::to_json(report).dump(2) << "\n";
    return 0;
  }
  out << "thesis stepper on " << report.board << ", dt " << report.dt_s << " s\n";
  for (const bench::SpeedRun& r : report.runs) {
    out << "  " << r.name << ": " << r.obstacles << " obstacles, " << r.steps_per_s << " steps/s, "
        << r.mean_candidates << " obstacles tested per step\n";
  }
  out << "grid speed-up over linear scan: " << report.grid_speedup << "x\n"
      << "cost with 10x obstacles out of reach: " << report.crowded_cost_ratio << "x\n"
      << "grid and linear scan bit-identical: " << (report.grid_matches_linear ? "yes" : "NO") << "\n";
  return 0;
}

}  // namespace pinball::cli
