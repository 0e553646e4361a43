// `pinball bench KIND`: the measurements behind docs/results.md.

#include <algorithm>
#include <array>
#include <filesystem>
#include <ostream>
#include <stdexcept>
#include <string_view>
#include <vector>

#include "camera_options.h"
#include "data_file.h"
#include "flag_uses.h"
#include "pinball/core/format.h"
#include "pinball/core/json_text.h"
#include "pinball/core/number_option.h"
#include "pinball/core/progress.h"
#include "pinball/core/text_file.h"
#include "progress_option.h"
#include "commands.h"
#include "world_options.h"
#include "pinball/table/board_overlay.h"
#include "calibration_bench.h"
#include <optional>

#include "aim_bench.h"
#include "cradle_bench.h"
#include "ceiling_bench.h"
#include "transfer_bench.h"
#include "pinball/control/controller_file.h"
#include "pinball/learn/planning_controller.h"
#include "pinball/learn/world_perturbation.h"
#include "camera_bench.h"
#include "detector_bench.h"
#include "daemon_latency_bench.h"
#include "latency_bench.h"
#include "precision_bench.h"
#include "protocol_bench.h"
#include "speed_bench.h"
#include "tracker_bench.h"
#include "draw_bench.h"

namespace pinball::cli {

CLI::App* add_bench_command(CLI::App& app, BenchArgs& a) {
  const bench::AimBenchOptions aim_defaults;
  CLI::App* cmd = app.add_subcommand(
      "bench",
      "run a benchmark (speed, tracker, latency, detector, camera, calibration, precision, ceiling, aim, cradle, "
      "transfer, protocol, draw)");
  cmd->add_option("kind", a.which,
                  "which benchmark: speed, tracker, latency, detector, camera (a real camera's faults, uncorrected and "
                  "corrected), calibration, precision, ceiling, aim (how exactly a shot's direction follows from a noisy "
                  "ball), cradle (how long a cycle shot from a ball at rest on a raised bat keeps it alive), transfer "
                  "(every controller in several worlds and a sweep of world errors, the belief nominal), protocol, "
                  "draw (the pictures of pinball play and pinball view)")
      ->required()
      ->check(CLI::IsMember(
          {"speed", "tracker", "latency", "detector", "camera", "calibration", "precision", "ceiling", "aim", "cradle",
           "transfer", "protocol", "draw"}));
  cmd->add_option("--board", a.board, "board file (ceiling, transfer: the belief)")->transform(data_file());
  add_identified_option(*cmd, a.identified);
  cmd->add_option("--steps", a.steps,
                  "speed: steps per timed run, at least (whole balls are played; the report gives the steps run; "
                  "the MuJoCo twin's runs: a tenth)")
      ->check(finite_range(1000, 1'000'000'000));
  cmd->add_option("--repeats", a.repeats, "timed runs per configuration (median reported)")->check(finite_range(1, 99));
  cmd->add_option("--approaches", a.approaches, "tracker: free-flight approaches to collect")
      ->check(finite_range(10, 1'000'000));
  cmd->add_option("--seed", a.seed,
                  "tracker, detector, camera, calibration, ceiling, aim, cradle, transfer: seed for play, camera noise, "
                  "placements and balls")
      ->check(unsigned_64());
  cmd->add_flag("--quick", a.quick,
                "tracker, detector, camera, calibration, latency, precision, ceiling, aim, cradle, transfer, protocol, "
                "draw: a short run (fewer approaches, frames, roll sets, balls or settings; transfer: 5 balls per "
                "cell, one value per family; cradle: 2 balls, 3 drops, 60 s); --balls, when given, wins");
  cmd->add_option("--balls", a.balls,
                  "ceiling: balls per player; aim: ceiling balls whose fires are replayed; cradle: balls per drop "
                  "duration; transfer: balls per world and controller (the same ball seeds for every player)")
      ->check(finite_range(1, 1'000'000))
      ->default_str("ceiling 200, aim " + std::to_string(aim_defaults.balls) + ", cradle " +
                    std::to_string(bench::CradleBenchOptions{}.balls) + ", transfer " +
                    std::to_string(bench::TransferBenchOptions{}.balls));
  cmd->add_option("--twin-balls", a.twin_balls,
                  "transfer: balls per controller in the MuJoCo twin, the first of the same seeds (it plays about "
                  "100x slower than the model)")
      ->check(finite_range(1, 1'000'000))
      ->default_str(std::to_string(bench::TransferBenchOptions{}.twin_balls));
  cmd->add_option("--threads", a.threads, "ceiling, cradle, transfer: worker threads (results do not depend on it)")
      ->check(finite_range(1, 256));
  cmd->add_option("--controller", a.controllers,
                  "latency: the controller pinballd plays (default: pinballd's, controllers/imitation.json); ceiling: also play this controller file through the camera model and tracker (a planner file: the ceiling plans with its settings); aim: a planner file whose settings the ceiling player plans with; transfer "
                  "(repeatable): play these instead of controllers/best.json, imitation.json and cem.json")
      ->transform(data_file())
      ->default_str("latency controllers/imitation.json, ceiling none, transfer controllers/best.json imitation.json cem.json");
  cmd->add_option("--true-state-noise", a.true_state_noise,
                  "ceiling: also play the --controller (a planner file) fed the TRUE ball every frame instead of "
                  "the tracker's estimate, "
                  "plus Gaussian noise of MM (position, mm) and MPS (velocity, m/s) per coordinate; aim: replay the "
                  "shots from a ball with this noise only (default: 0.3 mm 0.005, 1 mm 0.02 and 3 mm 0.1 m/s)")
      ->expected(2)
      ->type_name("MM MPS")
      ->check(finite_non_negative());
  cmd->add_option("--max-ball-time", a.max_ball_time_s,
                  "ceiling, aim, cradle, transfer: seconds after which a ball still alive is cut")
      ->check(finite_range(1.0, 3600.0))
      ->default_str("60; cradle 600");
  cmd->add_option("--drop-ms", a.drop_ms,
                  "cradle: the drop durations to try, FROM TO STEP in ms: how long the bat a ball rests on is "
                  "dropped before it shoots")
      ->expected(3)
      ->type_name("FROM TO STEP")
      ->check(finite_positive())
      ->default_str("230 250 1");
  cmd->add_option("--perturb", a.perturb,
                  "cradle (repeatable): change the model world's table as the transfer sweep's cells do, NAME=VALUE "
                  "in the perturbation's unit: pivot_y_mm, theta_min_deg, flipper_mu_pct, wall_rho, gravity_pct "
                  "(e.g. --perturb gravity_pct=-3); the delay and camera ones do not apply: the cradle player sees "
                  "the true ball at rest")
      ->type_name("NAME=VALUE");
  cmd->add_option("--target-ratio", a.target_ratio,
                  "transfer: the ratio to the spastic flipper the summary holds every world to (counts the worlds at "
                  "it and those whose interval lies below it)")
      ->check(finite_range(0.01, 1000.0))
      ->default_str(format_number(bench::TransferBenchOptions{}.target_ratio));
  cmd->add_option("--frames", a.frames, "protocol: random and mutated frames per seed")
      ->check(finite_range(std::uint64_t{1}, std::uint64_t{1'000'000'000}));
  cmd->add_option("--seeds", a.seeds, "protocol: seeds to run, from --seed on")->check(finite_range(1, 1000));
  cmd->add_option("--csv", a.csv,
                  "precision: write scene,stepper,setting,max_error_m,final_error_m,run_time_s here; transfer: one "
                  "row per world and controller")
      ->check(output_file());
  cmd->add_option("--png", a.png,
                  "precision: write the log-log plot of error against run time here; transfer: the score ratio to "
                  "the spastic flipper against each perturbation")
      ->check(output_file());
  add_world_options(*cmd, a.world);
  add_camera_model_options(*cmd, a.camera);
  cmd->add_flag("--json", a.json, "print one JSON object instead of text");
  add_progress_flag(*cmd, a.progress);
  // Which flags were given, for run_bench to refuse one the chosen bench would not read.
  record_flags_given(cmd, a.flags_given);
  return cmd;
}

namespace {

// Whether the command line gave `flag` ("--frames"): a value given wins over --quick's.
bool given(const BenchArgs& a, std::string_view flag) {
  return std::find(a.flags_given.begin(), a.flags_given.end(), flag) != a.flags_given.end();
}

int run_tracker(const BenchArgs& a, const table::Board& board, std::ostream& out, std::ostream& err) {
  bench::TrackerBenchOptions options = a.quick ? bench::quick_tracker_bench_options() : bench::TrackerBenchOptions{};
  if (!a.quick || given(a, "--approaches")) options.approaches = a.approaches;  // given, it wins over --quick
  options.seed = a.seed;
  const bench::TrackerReport report = bench::run_tracker_bench(
      board, options, [&](const std::string& line) { err << "bench tracker: " << line << "\n"; });
  if (a.json) {
    out << json_text(bench::to_json(report), 2) << "\n";
  } else {
    out << bench::to_text(report);
  }
  return 0;
}

int run_detector(const BenchArgs& a, const table::Board& board, std::ostream& out, std::ostream& err) {
  bench::DetectorBenchOptions options = a.quick ? bench::quick_detector_bench_options() : bench::DetectorBenchOptions{};
  options.seed = a.seed;
  const bench::DetectorReport report = bench::run_detector_bench(
      board, options, [&](const std::string& line) { err << "bench detector: " << line << "\n"; });
  if (a.json) {
    out << json_text(bench::to_json(report), 2) << "\n";
  } else {
    out << bench::to_text(report);
  }
  return 0;
}

int run_camera(const BenchArgs& a, const table::Board& board, std::ostream& out, std::ostream& err) {
  bench::CameraBenchOptions options = a.quick ? bench::quick_camera_bench_options() : bench::CameraBenchOptions{};
  options.seed = a.seed;
  // The latency as the lab measures it (`pinball calibrate latency --sim`), not the simulation's truth.
  const int latency_events = a.quick ? 8 : 20;
  options.measured_latency_s = bench::measure_simulated_latency_s(board, options.camera, latency_events, a.seed);
  options.measured_latency_source =
      "pinball calibrate latency --sim, " + std::to_string(latency_events) + " events, seed " + std::to_string(a.seed);
  // The lens as the lab calibrates it (`pinball calibrate intrinsics --sim`: the chessboard), not the truth.
  const int views = a.quick ? 8 : 20;
  options.calibrated_lens = bench::calibrate_simulated_lens(*options.camera.lens, views, a.seed);
  options.calibrated_lens_source =
      "pinball calibrate intrinsics --sim, chessboard, " + std::to_string(views) + " views, seed " + std::to_string(a.seed);
  const bench::CameraReport report =
      bench::run_camera_bench(board, options, [&](const std::string& line) { err << "bench camera: " << line << "\n"; });
  if (a.json) {
    out << json_text(bench::to_json(report), 2) << "\n";
  } else {
    out << bench::to_text(report);
  }
  return 0;
}

int run_calibration(const BenchArgs& a, const table::Board& board, std::ostream& out, std::ostream& err) {
  bench::CalibrationBenchOptions options;
  options.seed = a.seed;
  if (a.quick) {
    options.gravity_sets = 5;
    options.approaches = 50;
  }
  const bench::CalibrationReport report = bench::run_calibration_bench(
      board, options, [&](const std::string& line) { err << "bench calibration: " << line << "\n"; });
  if (a.json) {
    out << json_text(bench::to_json(report), 2) << "\n";
  } else {
    out << bench::to_text(report);
  }
  return 0;
}

int run_latency(const BenchArgs& a, std::ostream& out, std::ostream& err) {
  auto progress = [&](const std::string& line) { err << "bench latency: " << line << "\n"; };
  bench::LatencyBenchOptions lo;
  bench::DaemonLatencyOptions dlo;
  if (a.controllers.size() > 1) throw std::invalid_argument("bench latency: pinballd plays one --controller");
  if (!a.controllers.empty()) dlo.controller = a.controllers.front();
  if (a.quick) {
    lo.samples = 200;
    lo.codec_frames = 10'000;
    lo.baseline_samples = 200;
    dlo.lockstep_balls = 2;
    dlo.realtime_s = 1.0;
    dlo.baseline_samples = 200;
  }
  const bench::LatencyReport r = bench::run_latency_bench(lo, progress);
  const bench::DaemonLatencyReport d = bench::run_daemon_latency_bench(dlo, progress);
  if (a.json) {
    nlohmann::json j = bench::to_json(r);
    j["daemon"] = bench::to_json(d);
    out << json_text(j, 2) << "\n";
    return 0;
  }
  out << "fire() to coil output over the stream transport, " << r.samples << " samples\n"
      << "  p50 " << r.fire_to_coil_p50_us << " us, p99 " << r.fire_to_coil_p99_us << " us, max "
      << r.fire_to_coil_max_us << " us; longest fire() call " << r.fire_call_max_us << " us\n"
      << "  baseline raw 16-byte write+read: p50 " << r.raw_p50_us << " us, p99 " << r.raw_p99_us << " us ("
      << r.stack_overhead_ratio << "x)\n"
      << "encode+decode per frame " << r.encode_decode_ns << " ns (copy baseline " << r.copy_baseline_ns << " ns)\n"
      << "coil safety violations " << r.coil_violations << "\n"
      << "pinballd plays " << d.controller << "\n";
  const std::array<std::pair<const char*, const bench::DaemonLatencyRun*>, 4> runs{{
      {"lockstep", &d.lockstep},
      {"lockstep, threads free to move (baseline)", &d.lockstep_unpinned},
      {"real-time", &d.realtime},
      {"real-time, idle cores polling", &d.realtime_idle_poll}}};
  for (const auto& [name, run] : runs) {
    const daemon::LatencySummary& e2e = run->stages[daemon::kFrameToCan];
    out << "pinballd " << name << " at " << d.fps << " fps, " << run->frames << " frames: frame -> CAN written ";
    if (e2e.count > 0) {
      out << "p50 " << e2e.p50_us << " us, p99 " << e2e.p99_us << " us, max " << e2e.max_us << " us (" << e2e.count
          << " commands; " << run->cpus << ")\n";
    } else {
      out << "not measured: the controller gave no command (" << run->cpus << ")\n";
    }
    for (const std::string& w : run->warnings) out << "  warning: " << w << "\n";
  }
  out << "  baseline eventfd wake-up of another thread: p50 " << d.wake_p50_us << " us, p99 " << d.wake_p99_us
      << " us\n";
  return 0;
}

// The CSV and the plot are two files, neither of them an input (a controller's file written over by a CSV).
void check_bench_outputs(const BenchArgs& a) {
  const std::vector<std::pair<const char*, std::string>> outputs{{"--csv", a.csv}, {"--png", a.png}};
  check_distinct_outputs(outputs);
  std::vector<std::pair<const char*, std::string>> inputs{{"--board", a.board}, {"--identified", a.identified}};
  for (const std::string& c : a.controllers) inputs.emplace_back("--controller", c);
  check_outputs_replace_no_input(outputs, inputs);
}

int run_precision(const BenchArgs& a, const table::Board& board, std::ostream& out, std::ostream& err) {
  check_output_folder(a.csv, "--csv");
  check_png_output(a.png, "--png");
  check_bench_outputs(a);
  const bench::PrecisionBenchOptions options =
      a.quick ? bench::quick_precision_bench_options() : bench::default_precision_bench_options();
  const bench::PrecisionReport report = bench::run_precision_bench(
      board, options, [&](const std::string& line) { err << "bench precision: " << line << "\n"; });
  if (!a.png.empty()) bench::plot_precision_png(report, a.png);
  if (!a.csv.empty()) write_text_file(a.csv, bench::to_csv(report));
  if (a.json) {
    out << json_text(bench::to_json(report), 2) << "\n";
  } else {
    out << bench::to_markdown(report);
  }
  return 0;
}

int run_ceiling(const BenchArgs& a, const table::Board& board, std::ostream& out, std::ostream& err) {
  bench::CeilingBenchOptions options = a.quick ? bench::quick_ceiling_bench_options() : bench::CeilingBenchOptions{};
  if (a.balls > 0) options.balls = a.balls;  // given, it wins over --quick's, as in cradle and transfer
  options.seed = a.seed;
  options.threads = a.threads;
  if (a.max_ball_time_s > 0.0) options.max_ball_time_s = a.max_ball_time_s;
  options.camera = a.camera;
  if (a.controllers.size() > 1) throw std::invalid_argument("bench ceiling: one --controller at most");
  std::optional<control::ControllerSpec> controller;
  if (!a.controllers.empty()) {
    controller = control::load_controller(a.controllers.front());
    control::check_controller_launch(*controller, board, a.controllers.front());
    options.controller = &*controller;
    options.controller_name = a.controllers.front();
    // The online planner beside the same planner on the true state: what the
    // tracker's view of the ball costs it, and nothing else.
    if (controller->planner) options.planner = learn::lookahead_config(*controller->planner, board.dt_s);
  }
  if (!a.true_state_noise.empty()) {
    if (!controller) throw std::invalid_argument("bench ceiling: --true-state-noise needs a --controller to feed");
    options.true_state_feed = bench::CeilingBenchOptions::TrueStateFeed{a.true_state_noise[0] * 1e-3, a.true_state_noise[1]};
  }
  const simlab::WorldSpec world_spec = simlab::world_for_belief(a.world, a.board, a.identified);
  options.actuation_delay_s = world_actuation_delay_s(std::nullopt, world_spec, a.identified);
  const simlab::OwnedWorld world = simlab::make_world(world_spec, board);
  const bench::CeilingReport report = bench::run_ceiling_bench(
      board, options, [&](const std::string& line) { err << "bench ceiling: " << line << "\n"; }, world.world.get());
  const nlohmann::json world_json = world_report(world_spec, a.board, *world.world);
  if (a.json) {
    nlohmann::json j = bench::to_json(report);
    j.update(identified_report(a.identified));
    j.update(world_json);
    out << json_text(j, 2) << "\n";
  } else {
    out << bench::to_text(report) << identified_text_line(a.identified);
    if (a.world.kind == simlab::WorldKind::kTwin) out << world_text_line(world_json);
  }
  return 0;
}


int run_cradle(const BenchArgs& a, const table::Board& board, std::ostream& out, std::ostream& err) {
  bench::CradleBenchOptions options;
  if (a.quick) {
    options.balls = 2;
    options.drop_to_s = options.drop_from_s + 2.0 * options.drop_step_s;
    options.max_ball_time_s = 60.0;
  }
  if (a.balls > 0) options.balls = a.balls;
  if (a.max_ball_time_s > 0.0) options.max_ball_time_s = a.max_ball_time_s;
  if (!a.drop_ms.empty()) {
    options.drop_from_s = a.drop_ms[0] * 1e-3;
    options.drop_to_s = a.drop_ms[1] * 1e-3;
    options.drop_step_s = a.drop_ms[2] * 1e-3;
  }
  options.seed = a.seed;
  options.threads = a.threads;
  const simlab::WorldSpec world_spec = simlab::world_for_belief(a.world, a.board, a.identified);
  // The player reads the world's true ball, never the belief, so a perturbed
  // copy of the belief can simply be the model world's table.
  learn::WorldSettings table{board, 0.0, {}};
  nlohmann::json perturbations = nlohmann::json::object();
  for (const std::string& setting : a.perturb) {
    const auto [p, value] = learn::parse_perturbation_setting(setting);
    if (!learn::changes_table(p)) {
      throw std::invalid_argument("bench cradle: --perturb " + setting +
                                  ": the cradle player sees the true ball at rest and acts on the world's step, so "
                                  "the solenoid's delay and the camera do not apply");
    }
    const std::string name(learn::perturbation_name(p));
    if (perturbations.contains(name)) {
      // Applied twice, the two compounded while the report showed the last alone.
      throw std::invalid_argument("bench cradle: --perturb " + name + " is given twice: give one value");
    }
    table = learn::perturb(table, p, value);
    perturbations[name] = value;
  }
  if (!a.perturb.empty() && (world_spec.kind != simlab::WorldKind::kModel || !world_spec.board_path.empty())) {
    throw std::invalid_argument("bench cradle: --perturb changes the model world's table; not with --world twin or "
                                "--world-board");
  }
  const simlab::OwnedWorld world = simlab::make_world(world_spec, table.board);
  const bench::CradleReport report =
      bench::run_cradle_bench(*world.world, options, [&](const std::string& line) { err << "bench " << line << "\n"; });
  if (a.json) {
    nlohmann::json j = bench::to_json(report);
    j.update(world_report(world_spec, a.board, *world.world));
    j.update(identified_report(a.identified));
    j["perturbations"] = perturbations;
    out << json_text(j, 2) << "\n";
  } else {
    out << bench::to_text(report) << identified_text_line(a.identified);
    if (!a.perturb.empty()) {
      out << "the world's table perturbed:";
      for (const std::string& setting : a.perturb) out << " " << setting;
      out << "\n";
    }
  }
  return 0;
}

int run_aim(const BenchArgs& a, const table::Board& board, std::ostream& out, std::ostream& err) {
  bench::AimBenchOptions options;
  options.balls = a.balls > 0 ? a.balls : (a.quick ? 3 : options.balls);
  options.seed = a.seed;
  if (a.max_ball_time_s > 0.0) options.max_ball_time_s = a.max_ball_time_s;
  if (a.controllers.size() > 1) throw std::invalid_argument("bench aim: one --controller at most");
  if (!a.controllers.empty()) {
    const control::ControllerSpec planner = control::load_controller(a.controllers.front());
    if (!planner.planner) throw std::invalid_argument("bench aim: " + a.controllers.front() + ": not a planner file");
    options.planner = learn::lookahead_config(*planner.planner, board.dt_s);
  }
  if (!a.true_state_noise.empty()) options.noise = {{a.true_state_noise[0] * 1e-3, a.true_state_noise[1]}};
  options.actuation_delay_s = world_actuation_delay_s(std::nullopt, simlab::WorldSpec{}, a.identified);
  const bench::AimReport report =
      bench::run_aim_bench(board, options, [&](const std::string& line) { err << "bench " << line << "\n"; });
  if (a.json) {
    nlohmann::json j = bench::to_json(report);
    j.update(identified_report(a.identified));
    out << json_text(j, 2) << "\n";
  } else {
    out << bench::to_text(report) << identified_text_line(a.identified);
  }
  return 0;
}

int run_transfer(const BenchArgs& a, const table::Board& board, std::ostream& out, std::ostream& err) {
  check_output_folder(a.csv, "--csv");
  check_png_output(a.png, "--png");
  check_bench_outputs(a);
  bench::TransferBenchOptions options =
      a.quick ? bench::quick_transfer_bench_options() : bench::TransferBenchOptions{};
  if (a.balls > 0) options.balls = a.balls;
  if (a.twin_balls > 0) options.twin_balls = a.twin_balls;
  options.seed = a.seed;
  options.threads = a.threads;
  if (a.max_ball_time_s > 0.0) options.max_ball_time_s = a.max_ball_time_s;
  options.target_ratio = a.target_ratio;
  options.camera = a.camera;
  options.twin_params_path = a.world.twin_params_path;
  options.identified = a.identified;
  // The model worlds play the identified delay when the overlay has one; the twin its driver's (world_actuation_delay_s).
  options.actuation_delay_s = world_actuation_delay_s(std::nullopt, simlab::WorldSpec{}, a.identified);
  std::vector<std::string> files = a.controllers;
  if (files.empty()) {
    for (const char* f : {"controllers/best.json", "controllers/imitation.json", "controllers/cem.json"}) {
      files.push_back(find_data_file(f));
    }
  }
  std::vector<control::ControllerSpec> specs;
  specs.reserve(files.size());  // the options borrow them
  for (const std::string& f : files) {
    specs.push_back(control::load_controller(f));
    control::check_controller_launch(specs.back(), board, f);
    options.controllers.push_back({std::filesystem::path(f).stem().string(), f, &specs.back()});
  }
  const bench::TransferReport report = bench::run_transfer_bench(
      board, options, [&](const std::string& line) { err << "bench transfer: " << line << "\n"; });
  // The files only now, from a finished run.
  if (!a.png.empty()) bench::plot_transfer_png(report, a.png);
  if (!a.csv.empty()) write_text_file(a.csv, bench::to_csv(report));
  if (a.json) {
    out << json_text(bench::to_json(report), 2) << "\n";
  } else {
    out << bench::to_text(report);
  }
  return 0;
}

int run_protocol(const BenchArgs& a, std::ostream& out, std::ostream& err) {
  bench::ProtocolBenchOptions o;
  o.frames = a.quick && !given(a, "--frames") ? 100'000 : a.frames;  // given, it wins over --quick
  if (a.quick) o.release_cycles = 100;
  o.seed = a.seed;
  o.seeds = a.seeds;
  const bench::ProtocolBenchReport r =
      bench::run_protocol_bench(o, [&](const std::string& line) { err << "bench protocol: " << line << "\n"; });
  if (a.json) {
    out << json_text(bench::to_json(r), 2) << "\n";
  } else {
    out << r.frames << " frames (" << r.mutated << " with bits flipped, " << r.noise << " random) over "
        << format_number(r.simulated_s) << " s of board time; " << r.valid_frames << " decoded for the board, " << r.bad_frames
        << " refused as bad\n"
        << "coil switch-ons " << r.switch_ons << ", stale " << r.stale << ", watchdog trips " << r.watchdog_trips
        << ", hold caps " << r.hold_cap_trips << ", locked refusals " << r.refused_locked << "\n"
        << "rule violations " << r.rule_violations << ", cap violations " << r.cap_violations
        << (r.first_violation.empty() ? "" : " (first: " + r.first_violation + ")") << "\n"
        << "board + checker " << format_number(r.frames_per_s) << " frames/s; baseline decode only "
        << format_number(r.decode_only_frames_per_s) << " frames/s\n";
    for (const bench::ReleaseUnderLoss& x : r.release_under_loss) {
      out << "release under " << format_number(x.drop_p * 100) << " % loss, closed loop "
          << (x.closed_loop ? "on " : "off") << ": on after release p50 " << format_number(x.p50_s * 1e3)
          << " ms, p99 " << format_number(x.p99_s * 1e3) << " ms, worst " << format_number(x.worst_s * 1e3)
          << " ms over " << x.cycles << " cycles (" << x.release_retries << " retries, "
          << x.release_escalations << " escalations)\n";
    }
  }
  std::uint64_t violations = r.rule_violations + r.cap_violations;
  for (const bench::ReleaseUnderLoss& x : r.release_under_loss) violations += x.cap_violations;
  return violations == 0 ? 0 : 1;
}

int run_draw(const BenchArgs& a, const table::Board& board, std::ostream& out, std::ostream& err) {
  bench::DrawBenchOptions o;
  if (a.quick) o.frames = 200;
  o.repeats = a.repeats;
  const bench::DrawBenchReport r =
      bench::run_draw_bench(board, o, [&](const std::string& line) { err << "bench draw: " << line << "\n"; });
  if (a.json) {
    out << json_text(bench::to_json(r), 2) << "\n";
    return 0;
  }
  auto row = [&](const char* what, const bench::DrawCost& c) {
    out << what << c.width_px << "x" << c.height_px << " px: " << format_number(c.frames_per_s) << " frames/s ("
        << format_number(c.ms_per_frame) << " ms each)\n";
  };
  row("pinball play picture ", r.play);
  row("pinball view picture ", r.view);
  row("baseline: a copy of  ", r.copy);
  out << "best of " << r.repeats << " runs of " << r.frames << " pictures, one core, headless; the windows need 60 frames/s\n";
  return 0;
}

// Which benches read each flag that not every bench reads. A flag given to a
// bench that would ignore it is refused, so that `bench tracker --noise-px 1`
// does not quietly run the tracker bench's own camera grid instead.
const std::vector<FlagUse>& bench_flag_uses() {
  static const std::vector<FlagUse> uses = {
      {{"--board"}, {"speed", "tracker", "detector", "camera", "calibration", "precision", "ceiling", "aim", "cradle",
                     "transfer", "draw"}},
      {{"--steps"}, {"speed"}},
      {{"--repeats"}, {"speed", "draw"}},
      {{"--approaches"}, {"tracker"}},
      {{"--seed"}, {"tracker", "detector", "camera", "calibration", "ceiling", "aim", "cradle", "transfer", "protocol"}},
      {{"--quick"}, {"tracker", "latency", "detector", "camera", "calibration", "precision", "ceiling", "aim", "cradle",
                     "transfer", "protocol", "draw"}},
      {{"--balls", "--max-ball-time", "--identified"}, {"ceiling", "aim", "cradle", "transfer"}},
      {{"--twin-balls", "--target-ratio"}, {"transfer"}},
      {{"--threads"}, {"ceiling", "cradle", "transfer"}},
      {{"--controller"}, {"latency", "ceiling", "aim", "transfer"}},
      {{"--true-state-noise"}, {"ceiling", "aim"}},
      {{"--drop-ms", "--perturb"}, {"cradle"}},
      {{"--frames", "--seeds"}, {"protocol"}},
      {{"--csv", "--png"}, {"precision", "transfer"}},
      // aim plays the belief's model only; transfer's worlds are its rows.
      {{"--world", "--world-board", "--stepper", "--dt"}, {"ceiling", "cradle"}},
      {{"--twin-params"}, {"ceiling", "cradle", "transfer"}},
      {{"--fps", "--m-per-px", "--noise-px", "--latency", "--drop"}, {"ceiling", "transfer"}},
  };
  return uses;
}

}  // namespace

int run_bench(const BenchArgs& args, std::ostream& out, std::ostream& all_err) {
  BenchArgs a = args;
  a.board = find_data_file(a.board);  // the default boards/mit1993.board from any folder
  // Progress only on a terminal or with --progress: a stream without a buffer swallows it.
  std::ostream no_progress(nullptr);
  std::ostream& err = progress_wanted(a.progress) ? all_err : no_progress;
  refuse_flags_not_read(a.flags_given, bench_flag_uses(), "bench", a.which);
  if (a.which == "latency") return run_latency(a, out, err);
  if (a.which == "protocol") return run_protocol(a, out, err);
  const table::Board board = table::load_belief_board(a.board, a.identified);  // the belief of ceiling and transfer
  if (a.which == "tracker") return run_tracker(a, board, out, err);
  if (a.which == "detector") return run_detector(a, board, out, err);
  if (a.which == "camera") return run_camera(a, board, out, err);
  if (a.which == "calibration") return run_calibration(a, board, out, err);
  if (a.which == "precision") return run_precision(a, board, out, err);
  if (a.which == "ceiling") return run_ceiling(a, board, out, err);
  if (a.which == "aim") return run_aim(a, board, out, err);
  if (a.which == "cradle") return run_cradle(a, board, out, err);
  if (a.which == "transfer") return run_transfer(a, board, out, err);
  if (a.which == "draw") return run_draw(a, board, out, err);
  bench::SpeedBenchOptions options;
  options.steps = a.steps;
  options.twin_steps = std::max<std::uint64_t>(1000, a.steps / 10);
  options.repeats = a.repeats;
  const bench::SpeedReport report =
      bench::run_speed_bench(board, options, [&](const std::string& line) { err << "bench speed: " << line << "\n"; });
  if (a.json) {
    out << json_text(bench::to_json(report), 2) << "\n";
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
  out << "event stepper (step horizon " << report.dt_s << " s) and the MuJoCo twin (its own step)\n";
  for (const bench::EventSpeedRun& r : report.event_runs) {
    out << "  " << r.name << ": " << r.obstacles << " obstacles, " << r.events_per_s << " events/s, "
        << r.sim_s_per_wall_s << " simulated s per wall s, " << r.steps_per_s << " steps/s\n";
  }
  out << "event stepper cost with 10x obstacles out of reach: " << report.event_crowded_cost_ratio << "x\n"
      << "real time: thesis " << format_number(report.thesis_sim_s_per_wall_s) << "x";
  for (const bench::EventSpeedRun& r : report.event_runs) {
    if (r.name != "event_crowded") out << ", " << r.name << " " << format_number(r.sim_s_per_wall_s) << "x";
  }
  if (!report.twin_skipped.empty()) out << " (twin skipped: " << report.twin_skipped << ")";
  out << "\n";
  return 0;
}

}  // namespace pinball::cli
