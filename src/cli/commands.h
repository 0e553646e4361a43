#pragma once
// The `pinball` subcommands. Each has an argument struct filled by CLI11 and a
// run function that reports on `out` (one JSON object with --json) and shows
// progress on `err`. Bad input throws; main turns it into a one-line message.

#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "pinball/firmware/flipper_actuation.h"
#include "pinball/simlab/world_factory.h"
#include "pinball/track/camera_model.h"

namespace pinball::cli {

/// `pinball sim`
struct SimArgs {
  std::string board;             ///< board file
  std::string identified;        ///< identified overlay laid over the belief (docs/identification.md); empty: none
  std::string policy = "none";   ///< none | spastic | controller
  std::string controller;        ///< controller file (implies policy controller)
  int balls = 1;                 ///< balls to play
  std::uint64_t seed = 1;        ///< launch noise seed
  simlab::WorldSpec world;       ///< the world (default: the model of `board` on the thesis stepper)
  double max_ball_time_s = 300.0;///< cut a ball still in play after this
  std::string trace;             ///< CSV trace path, or empty
  std::string video;             ///< AVI path, or empty
  double video_fps = 60.0;       ///< video frame rate (simulated time)
  bool video_camera = false;     ///< video from the simulated camera's frames instead of the board view
  track::CameraModelConfig camera;  ///< the camera the spastic player sees through
  /// spastic: flip when the projected impact is this close (m); none: the spastic default
  std::optional<double> reach_m;
  std::string actuation = "direct";  ///< direct | can: flipper commands through the CAN path
  double actuation_delay_s = firmware::kDefaultActuationDelay_s;  ///< solenoid rise before the flipper moves (s)
  bool json = false;             ///< one JSON object on stdout
  bool progress = false;         ///< percent and ETA on stderr even when it is not a terminal
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
  std::string calibration;     ///< calibration file: flipper geometry and g (explicit --gravity wins)
  bool json = false;           ///< one JSON object on stdout
};
CLI::App* add_track_command(CLI::App& app, TrackArgs& args);
int run_track(const TrackArgs& args, std::ostream& out, std::ostream& err);

/// `pinball bench`
struct BenchArgs {
  std::string which;                                 ///< speed | tracker | latency | detector | camera | calibration | precision | ceiling | aim | cradle | transfer | protocol | draw
  std::string board = "boards/mit1993.board";        ///< board to measure on
  std::string identified;                            ///< ceiling, aim, cradle, transfer: overlay laid over the belief; empty: none
  std::uint64_t steps = 2'000'000;                   ///< steps per timed run
  int repeats = 3;                                   ///< timed runs per configuration
  int approaches = 2000;                             ///< tracker: free-flight approaches
  std::uint64_t seed = 1;                            ///< tracker: approach and noise seed
  bool quick = false;                                ///< tracker, detector, precision, ceiling: a short run
  int balls = 0;                                     ///< ceiling: balls per player; aim: ceiling balls; cradle: per drop; transfer: per cell (0: the bench's)
  int twin_balls = 0;                                ///< transfer: per cell in the twin (0: the bench's)
  int threads = 2;                                   ///< ceiling, cradle, transfer: worker threads (results do not depend on it)
  double max_ball_time_s = 0.0;                      ///< ceiling, aim, transfer, cradle: a ball alive after this is cut (0: the bench's, 60 s; cradle 600 s)
  std::vector<double> drop_ms;                       ///< cradle: drop durations FROM TO STEP (ms); empty: the bench's
  std::vector<std::string> perturb;                  ///< cradle: the sweep's table perturbations, "NAME=VALUE", laid over the world
  std::vector<std::string> flags_given;              ///< the long flags on the command line ("--noise-px"), set by the parser
  double target_ratio = 2.5;                         ///< transfer: the ratio to the spastic flipper the summary holds each world to
  std::vector<std::string> controllers;              ///< ceiling: one controller file; transfer: the controllers
  std::vector<double> true_state_noise;              ///< ceiling: play the controller fed the true state, noise (mm, m/s); empty: not
  std::string csv;                                   ///< precision, transfer: CSV file to write, or empty
  std::string png;                                   ///< precision, transfer: plot to write, or empty
  simlab::WorldSpec world;                           ///< ceiling: the world (default: the model of `board`)
  track::CameraModelConfig camera;                   ///< ceiling, transfer: the tracker-side players' (nominal) camera
  std::uint64_t frames = 1'000'000;                  ///< protocol: frames per seed
  int seeds = 1;                                     ///< protocol: seeds, from --seed on
  bool json = false;                                 ///< one JSON object on stdout
  bool progress = false;                             ///< progress on stderr even when it is not a terminal
};
CLI::App* add_bench_command(CLI::App& app, BenchArgs& args);
int run_bench(const BenchArgs& args, std::ostream& out, std::ostream& err);

/// `pinball learn`
struct LearnArgs {
  std::string board;                    ///< board file
  std::string identified;               ///< identified overlay laid over the belief (docs/identification.md); empty: none
  std::string randomize;                ///< searches: draw each ball's world from this file (docs/learning.md); empty: none
  std::string shot_values;              ///< imitate: the teacher values its plans' shots by this table (learn/shot_values.h); empty: none
  double drain_penalty = -1.0;          ///< imitate's teacher, shot-values' player: points a lost ball costs a plan; negative: the planner's default
  bool lead = false;                    ///< searches: controllers act on projections led by latency + actuation delay
  std::string method;                   ///< tournament | relay | cem | imitate | none | spastic | evaluate | launcher | shot-values
  std::uint64_t budget_balls = 2000;    ///< simulated balls the search may play
  std::uint64_t seed = 1;               ///< the only source of randomness
  std::string out;                      ///< controller file to write (searches)
  std::string controller;               ///< controller file to evaluate (method evaluate)
  int threads = 1;                      ///< worker threads (results do not depend on it)
  std::string curve;                    ///< learning curve CSV, or empty
  std::string plot;                     ///< learning curve PNG, or empty
  int eval_balls = -1;  ///< fresh balls to evaluate the result on (-1: by method, 0 after a search, else 1000)
  int partitions = 4;                   ///< k angle partitions per flipper
  bool partition_by_h = false;          ///< also split by h (thesis 7.1)
  bool rolling = false;                 ///< separate rolling minicontrollers (thesis 7.1)
  bool randomise_launch = false;        ///< random pull per ball (thesis 7.1)
  double pull = -1.0;                   ///< launcher pull; negative: the board's
  int balls_per_controller = 5;         ///< tournament: b
  int population = 0;                   ///< relay / cem population (0: the method's default)
  int rounds = 4;                       ///< imitate: rounds (1: the teacher's balls only; more: DAgger)
  double max_ball_time_s = 60.0;        ///< a ball alive after this is cut: a cycle
  double loss_penalty = 500.0;          ///< reward of an opportunity that lost the ball
  double actuation_delay_s = firmware::kDefaultActuationDelay_s;     ///< command to flipper motion (s): run_learn resolves it
  bool actuation_delay_given = false;   ///< --actuation-delay was given (else the identified one, cli::world_actuation_delay_s)
  double gravity_scale = 1.0;           ///< tracker's g / board's g
  track::CameraModelConfig camera;      ///< the camera the tracker sees through
  simlab::WorldSpec world;              ///< the world (default: the model of `board` on the thesis stepper)
  bool json = false;                    ///< one JSON object on stdout
  bool progress = false;                ///< percent and ETA on stderr even when it is not a terminal
  std::string checkpoint;               ///< record every batch here (resumable); empty: none
  bool resume = false;                  ///< continue the run recorded in `checkpoint`
  std::vector<std::string> flags_given;  ///< the long flags on the command line ("--rounds"), set by the parser
};
CLI::App* add_learn_command(CLI::App& app, LearnArgs& args);
int run_learn(const LearnArgs& args, std::ostream& out, std::ostream& err);

/// `pinball calibrate intrinsics|camera|flippers|gravity|latency`
struct CalibrateArgs {
  std::string kind;                  ///< intrinsics | camera | flippers | gravity | latency
  std::string sim_board;             ///< --sim BOARD: generate the inputs from the simulator
  std::string board;                 ///< the machine's board file (names, sides, rough places)
  std::string image;                 ///< camera: marker image
  std::string markers;               ///< camera: marker layout CSV x,y (m); empty: the default layout
  std::string down;                  ///< flippers: marker image, flippers down
  std::string up;                    ///< flippers: marker image, flippers held up
  std::vector<std::string> sweeps;   ///< flippers: one sweep video per flipper, board order
  std::string method = "markers";    ///< flippers: the method written to the file when both ran
  std::string target = "chessboard:10x7:0.025";  ///< intrinsics: the printed target (calibration::parse_target)
  std::vector<std::string> images;   ///< intrinsics: image files, or directories of .png/.jpg
  int sim_views = 20;                ///< intrinsics with --sim: views to render
  std::string camera_size = "640x480";  ///< intrinsics with --sim: the simulated camera's image size (WxH)
  std::string print_target;          ///< intrinsics: write the printable target here (PNG, 10 px/mm) and stop
  std::vector<std::string> rolls;    ///< gravity: observation CSVs, one roll each
  int sim_rolls = 5;                 ///< gravity with --sim: rolls to simulate
  double sigma_m = 0.001;            ///< gravity: observation noise per coordinate (m)
  std::string calibration;           ///< file to take the camera homography from (default: --out)
  std::string out;                   ///< calibration file to write or update
  std::string png;                   ///< picture of what was detected and fitted
  std::uint64_t seed = 1;            ///< --sim: the simulated lab's seed
  /// --sim: the simulated machine's flippers mounted off the board file
  /// (pivot x, y in mm; length in mm; both stops in degrees); zero: the
  /// machine the board file describes, as pinballd simulates it.
  std::vector<double> sim_pivot_offset_mm{0.0, 0.0};
  double sim_length_offset_mm = 0.0;
  double sim_theta_offset_deg = 0.0;
  std::string sim_camera = "ideal";  ///< --sim: the simulated camera, ideal or typical (lens, rolling shutter, ...)
  std::string device;                ///< latency: the camera, /dev/videoN
  std::string can;                   ///< latency: the driver board's SocketCAN interface (can0)
  std::string config;                ///< latency: pinballd's configuration (board id, coils, watchdog, devices)
  std::string flipper;               ///< latency: the flipper fired (board name); empty: the board's first
  int events = 20;                   ///< latency: times the flipper is fired
  double sim_latency_ms = -1.0;      ///< latency --sim: the camera's minimum latency (ms); < 0: the typical camera's
  double actuation_delay_ms = firmware::kDefaultActuationDelay_s * 1e3;  ///< latency: command to first motion (ms)
  double sim_actuation_delay_ms = -1.0;  ///< latency --sim: the machine's true delay (ms); < 0: actuation_delay_ms
  double row_time_us = -1.0;         ///< latency: rolling shutter row time (µs); < 0: the camera's (--sim) or the file's
  double exposure_us = -1.0;         ///< latency: the camera's exposure time (µs); < 0: the simulated camera's, or 0 in the lab
  double fps = 200.0;                ///< latency: the frame rate asked of the camera
  bool progress = false;             ///< intrinsics: images searched, with ETA, even when stderr is no terminal
  bool json = false;                 ///< one JSON object on stdout
  std::vector<std::string> flags_given;  ///< the long flags on the command line ("--sim-rolls"), set by the parser
};
CLI::App* add_calibrate_command(CLI::App& app, CalibrateArgs& args);
int run_calibrate(const CalibrateArgs& args, std::ostream& out, std::ostream& err);

/// `pinball play` (docs/play.md)
struct PlayArgs {
  std::string board;                  ///< board file to play (not with --stats)
  std::string stats;                  ///< --stats FILE: print the players' means of this score file and stop
  std::string player;                 ///< the player's name; empty: $USER, else "player"
  std::string csv = "play_scores.csv";///< score file each ball is appended to
  int balls = 0;                      ///< stop after this many balls; 0: when the player quits
  double max_ball_time_s = 300.0;     ///< a ball still in play after this is cut (simulated s)
  double pull = -1.0;                 ///< launcher pull fraction; negative: the board's
  std::uint64_t seed = 1;             ///< launch noise seed
  simlab::WorldSpec world;            ///< the world (default: the model of `board` on the thesis stepper)
  std::string keys;                   ///< key script (file or text); empty: the keyboard
  bool headless = false;              ///< no window: play the script as fast as possible
  double fps = 100.0;                 ///< frames drawn per wall second (at most)
  double px_per_m = 800.0;            ///< drawing scale
  bool json = false;                  ///< one JSON object on stdout
};
CLI::App* add_play_command(CLI::App& app, PlayArgs& args);
int run_play(const PlayArgs& args, std::ostream& out, std::ostream& err);

/// Parses argv and runs the chosen subcommand; returns the exit code
/// (0 success, 1 bad input or failure, 2 bad usage).
int run_pinball(int argc, const char* const* argv, std::ostream& out, std::ostream& err);

/// `pinball replay`
struct ReplayArgs {
  std::string log;         ///< LCM log file
  std::string config;      ///< pinballd configuration (optional)
  std::string board;       ///< board override
  std::string controller;  ///< controller override
  bool json = false;       ///< one JSON object on stdout
  bool progress = false;   ///< progress on stderr even when it is not a terminal
};
CLI::App* add_replay_command(CLI::App& app, ReplayArgs& args);
/// Exit 0 when reproduced, 3 when the decisions differ, 1 for bad input.
int run_replay(const ReplayArgs& args, std::ostream& out, std::ostream& err);

/// `pinball view`
struct ViewArgs {
  std::string log;            ///< LCM log to play; empty: live from lcm_url
  std::string lcm_url = "udpm://239.255.76.67:7667?ttl=0";  ///< live: the daemon's LCM URL
  std::string config;         ///< pinballd configuration: board, calibration, controller, LCM URL
  std::string board;          ///< board override
  std::string calibration;    ///< calibration override
  std::string controller;     ///< controller override (d_critical)
  std::string snapshot;       ///< PNG to write
  double at_s = -1.0;         ///< snapshot time (s from the log's start or from listening); negative: the end
  double quit_at_s = -1.0;    ///< window: play until this time, write the snapshot, quit; negative: never
  double speed = 1.0;         ///< log playback speed
  double px_per_m = 800.0;    ///< scale of the table
  double wait_s = 10.0;       ///< live snapshot: give up when nothing arrives for this long (s)
  bool json = false;          ///< one JSON object on stdout
};
CLI::App* add_view_command(CLI::App& app, ViewArgs& args);
/// Exit 0; 1 for bad input, no display for a window, or a live source that sent nothing.
int run_view(const ViewArgs& args, std::ostream& out, std::ostream& err);

/// `pinball identify`
struct IdentifyArgs {
  std::vector<std::string> logs;      ///< LCM logs of recorded play to identify from
  std::vector<std::string> held_out;  ///< LCM logs to judge the 100 ms prediction on (never fitted)
  std::string board = "boards/mit1993.board";  ///< the belief's board file: the recorded table's geometry
  std::string out;                    ///< overlay file to write; empty: report only
  double sigma_m = 0.001;             ///< detector noise of one coordinate (m)
  int bootstrap = 50;                 ///< resamples of flights behind g's uncertainty
  std::uint64_t seed = 1;             ///< bootstrap draws
  bool json = false;                  ///< one JSON object on stdout
  bool progress = false;              ///< percent and ETA on stderr even when it is not a terminal
};
CLI::App* add_identify_command(CLI::App& app, IdentifyArgs& args);
/// Exit 0; 1 for bad input (an empty, damaged or foreign log, a missing
/// channel, recordings with nothing to fit, an unwritable --out): nothing written.
int run_identify(const IdentifyArgs& args, std::ostream& out, std::ostream& err);

}  // namespace pinball::cli
