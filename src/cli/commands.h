#pragma once
// The `pinball` subcommands. Each has an argument struct filled by CLI11 and a
// run function that reports on `out` (one JSON object with --json) and shows
// progress on `err`. Bad input throws; main turns it into a one-line message.

#include <cstdint>
#include <iosfwd>
#include <string>

#include <CLI/CLI.hpp>

#include "pinball/track/camera_model.h"

namespace pinball::cli {

/// `pinball sim`
struct SimArgs {
  std::string board;             ///< board file
  std::string policy = "none";   ///< none | spastic
  int balls = 1;                 ///< balls to play
  std::uint64_t seed = 1;        ///< launch noise seed
  std::string stepper = "thesis";///< integrator
  double dt_s = 0.0;             ///< time step override (0: the board's)
  double max_ball_time_s = 300.0;///< cut a ball still in play after this
  std::string trace;             ///< CSV trace path, or empty
  std::string video;             ///< AVI path, or empty
  double video_fps = 60.0;       ///< video frame rate (simulated time)
  track::CameraModelConfig camera;  ///< the camera the spastic player sees through
  double reach_m = 0.02;         ///< spastic: flip when the projected impact is this close (m)
  std::string actuation = "direct";  ///< direct | can: flipper commands through the CAN path
  double actuation_delay_s = 0.004;  ///< can: solenoid rise before the flipper moves (s)
  bool json = false;             ///< one JSON object on stdout
};
CLI::App* add_sim_command(CLI::App& app, SimArgs& args);
int run_sim(const SimArgs& args, std::ostream& out, std::ostream& err);

/// `pinball render`
struct RenderArgs {
  std::string board;          ///< board file
  std::string out;            ///< PNG path
  double px_per_m = 800.0;    ///< scale
  bool normals = false;       ///< draw line normals
  bool json = false;          ///< one JSON object on stdout
};
CLI::App* add_render_command(CLI::App& app, RenderArgs& args);
int run_render(const RenderArgs& args, std::ostream& out, std::ostream& err);

/// `pinball track`
struct TrackArgs {
  std::string board;           ///< board file (flipper geometry)
  std::string observations;    ///< observation CSV
  double gravity_mps2 = -1.0;  ///< calibrated g; negative: the board's
  double sigma_m = 0.0;        ///< observation noise; 0: the default camera's
  bool json = false;           ///< one JSON object on stdout
};
CLI::App* add_track_command(CLI::App& app, TrackArgs& args);
int run_track(const TrackArgs& args, std::ostream& out, std::ostream& err);

/// `pinball bench`
struct BenchArgs {
  std::string which;                                 ///< speed | tracker
  std::string board = "boards/mit1993.board";        ///< board to measure on
  std::uint64_t steps = 2'000'000;                   ///< steps per timed run
  int repeats = 3;                                   ///< timed runs per configuration
  int approaches = 2000;                             ///< tracker: free-flight approaches
  std::uint64_t seed = 1;                            ///< tracker: approach and noise seed
  bool quick = false;                                ///< tracker: 100 approaches, target camera only
  bool json = false;                                 ///< one JSON object on stdout
};
CLI::App* add_bench_command(CLI::App& app, BenchArgs& args);
int run_bench(const BenchArgs& args, std::ostream& out, std::ostream& err);

/// Parses argv and runs the chosen subcommand; returns the exit code
/// (0 success, 1 bad input or failure, 2 bad usage).
int run_pinball(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

}  // namespace pinball::cli
