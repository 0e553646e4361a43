// `pinball sim BOARD`: plays N balls on the embedded simulator and reports the
// mean score per ball (95 % interval), mean ball time and steps per second.

#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <stdexcept>
#include <ostream>

#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>

#include "camera_options.h"
#include "data_file.h"
#include "commands.h"
#include "pinball/control/spastic_controller.h"
#include "pinball/core/format.h"
#include "pinball/core/json_text.h"
#include "pinball/core/json_write_archive.h"
#include "pinball/core/number_option.h"
#include "pinball/core/progress.h"
#include "pinball/core/running_stats.h"
#include "pinball/learn/planning_controller.h"
#include "progress_option.h"
#include "pinball/control/controller_file.h"
#include "pinball/sim/ball_runner.h"
#include "pinball/sim/renderer.h"
#include "pinball/sim/state_hash.h"
#include "pinball/sim/video_recorder.h"
#include "pinball/simlab/can_flipper_drive.h"
#include "pinball/simlab/delay_line.h"
#include "pinball/simlab/sim_camera_source.h"
#include "pinball/simlab/simulated_player.h"
#include "pinball/table/board_overlay.h"
#include "trace_writer.h"
#include "world_options.h"

namespace pinball::cli {

CLI::App* add_sim_command(CLI::App& app, SimArgs& a) {
  CLI::App* cmd = app.add_subcommand("sim", "play balls on the embedded simulator and report the scores");
  cmd->add_option("board", a.board, "board file (docs/board-format.md)")->required()->transform(data_file());
  add_identified_option(*cmd, a.identified);
  cmd->add_option("--policy", a.policy,
                  "who flips: none, or spastic (flip the flipper the tracker's projection names whenever the "
                  "ball is within --reach of impact; sees the ball only through the camera model)")
      ->check(CLI::IsMember({"none", "spastic", "controller"}));
  cmd->add_option("--controller", a.controller,
                  "a learned controller file (docs/learning.md); implies --policy controller")
      ->transform(data_file());
  cmd->add_option("--reach", a.reach_m, "spastic: flip when the projected impact is this close (m)")
      ->check(finite_range(0.0, 1.0))
      ->default_str(format_exact(control::SpasticConfig{}.reach_m));
  add_camera_model_options(*cmd, a.camera);
  cmd->add_option("--actuation", a.actuation,
                  "how commands reach the flippers: direct (the solenoid delay applied to the table), or can "
                  "(DriverBus, CAN frames, the virtual driver board and the solenoid delay)")
      ->check(CLI::IsMember({"direct", "can"}));
  cmd->add_option("--actuation-delay", a.actuation_delay_s,
                  "solenoid rise before the flipper moves (s), for either actuation: the evaluator's and pinballd's "
                  "default")
      ->check(finite_range(0.0, 0.1));
  cmd->add_option("--balls", a.balls, "balls to play")->check(finite_range(1, 100'000'000));
  cmd->add_option("--seed", a.seed, "random seed (launch noise); same seed, same results")
      ->check(unsigned_64());
  add_world_options(*cmd, a.world);
  cmd->add_option("--max-ball-time", a.max_ball_time_s, "seconds after which a ball still in play is cut")
      ->check(finite_positive());
  cmd->add_option("--trace", a.trace, "write every step to this CSV (t,x,y,vx,vy,event)")->check(output_file());
  CLI::Option* video =
      cmd->add_option("--video", a.video, "write an MJPG AVI of the play to this file")->check(output_file());
  cmd->add_option("--video-fps", a.video_fps, "video frames per simulated second")
      ->check(finite_range(1.0, 1000.0))
      ->needs(video);
  cmd->add_flag("--video-camera", a.video_camera,
                "--video: record what the simulated camera sees (perspective, lamps, blur, noise) at --video-fps")
      ->needs(video);
  cmd->add_flag("--json", a.json, "print one JSON object instead of text");
  add_progress_flag(*cmd, a.progress);
  return cmd;
}

int run_sim(const SimArgs& a, std::ostream& out, std::ostream& err) {
  check_output_folder(a.trace, "--trace", /*streamed=*/true);
  check_named_output(a.video, "--video", sim::check_avi_name);
  check_distinct_outputs({{"--trace", a.trace}, {"--video", a.video}});
  check_outputs_replace_no_input({{"--trace", a.trace}, {"--video", a.video}},
                                 {{"board", a.board},
                                  {"--identified", a.identified},
                                  {"--controller", a.controller},
                                  {"--world-board", a.world.board_path},
                                  {"--twin-params", a.world.twin_params_path}});
  const table::Board board = table::load_belief_board(a.board, a.identified);
  const simlab::WorldSpec world_spec = simlab::world_for_belief(a.world, a.board, a.identified);
  const simlab::OwnedWorld world = simlab::make_world(world_spec, board);
  const table::Board& world_board = *world.board;  // what the camera films and the trace records
  const double dt_s = world->dt_s();
  sim::GameState state = sim::make_game_state(world_board, a.seed);

  std::string policy = a.policy;
  if (!a.controller.empty()) {
    if (policy == "spastic") throw std::invalid_argument("sim: --controller and --policy spastic exclude each other");
    policy = "controller";
  }
  if (policy == "controller" && a.controller.empty()) throw std::invalid_argument("sim: --policy controller needs --controller FILE");
  if (a.reach_m && policy != "spastic") {
    throw std::invalid_argument("sim: --reach is the spastic flipper's: give --policy spastic (or a controller file's "
                                "spastic.reach_m)");
  }
  std::unique_ptr<control::FlipperController> learned;
  std::optional<simlab::SimulatedPlayer> learned_player;
  double pull = -1.0;
  if (policy == "controller") {
    const control::ControllerSpec spec = control::load_controller(a.controller);
    control::check_controller_launch(spec, board, a.controller);
    learned = learn::make_controller(spec, board);
    learned_player.emplace(board, a.camera, *learned, a.seed ^ 0x5DEECE66Dull);
    pull = spec.launcher_pull;
  }
  std::optional<simlab::SimulatedSpasticPlayer> spastic;
  if (policy == "spastic") {
    control::SpasticConfig spastic_config;
    if (a.reach_m) spastic_config.reach_m = *a.reach_m;
    spastic.emplace(board, a.camera, spastic_config, a.seed ^ 0x5DEECE66Dull);
  }
  // The recordings are opened once every input has loaded: a bad controller leaves no file behind.
  std::optional<TraceWriter> trace;
  std::unique_ptr<sim::VideoRecorder> video;
  sim::RenderOptions render_options;
  double next_frame_s = 0.0;
  std::unique_ptr<simlab::SimCameraSource> camera;  // --video-camera: the camera's own frames
  vision::Frame camera_frame;
  cv::Mat camera_bgr;
  if (!a.video.empty() && a.video_camera) {
    simlab::SimCameraConfig cc;
    cc.fps = a.video_fps;
    cc.exposure_s = std::min(cc.exposure_s, 1.0 / a.video_fps);
    cc.seed = a.seed;
    camera = std::make_unique<simlab::SimCameraSource>(world_board, cc);
    video = std::make_unique<sim::VideoRecorder>(a.video, a.video_fps, camera->frame_size());
  } else if (!a.video.empty()) {
    video = std::make_unique<sim::VideoRecorder>(a.video, a.video_fps, sim::render_size(world_board, render_options));
  }
  if (!a.trace.empty()) trace.emplace(a.trace);  // after the video, whose open can still fail

  std::optional<simlab::CanFlipperDrive> can_drive;
  // One actuation model everywhere: commands reach the flippers actuation_delay_s later, through the
  // CAN path or straight (the fast loop's solenoid delay), as in the evaluator and pinballd.
  std::optional<simlab::DelayLine> direct_drive;
  if (a.actuation == "can") {
    can_drive.emplace(world_board, a.actuation_delay_s);
  } else {
    direct_drive.emplace(world_board.flippers.size(), a.actuation_delay_s);
  }
  sim::BallLimits limits;
  limits.max_ball_time_s = a.max_ball_time_s;
  limits.pull = pull;
  RunningStats score;
  RunningStats ball_time;
  std::uint64_t steps = 0;
  int cut = 0;
  int left_table = 0;
  std::uint64_t flips = 0;
  std::uint64_t run_hash = sim::hash_state(state);
  const auto start = std::chrono::steady_clock::now();
  ProgressMeter progress(progress_wanted(a.progress) ? &err : nullptr, "sim", a.balls, "balls",
                         !a.progress && progress_wanted(false));

  const std::uint64_t events_before = state.events;
  auto play = [&] {
    return sim::play_ball(
        *world, state, limits,
        [&](sim::GameState& s) {
          if (spastic) spastic->act(s);
          if (learned_player) learned_player->act(s);
          if (can_drive) can_drive->apply(s);
          if (direct_drive) direct_drive->apply(s);
        },
        [&](const sim::GameState& s, const sim::StepEvents& e) {
          if (trace) trace->write(world_board, s, e);
          if (camera) {
            camera->observe(s);
            while (camera->read(camera_frame)) {
              cv::cvtColor(camera_frame.gray, camera_bgr, cv::COLOR_GRAY2BGR);
              video->write(camera_bgr);
            }
          } else if (video && s.time_s >= next_frame_s) {
            video->write(sim::render_board(world_board, &s, render_options));
            next_frame_s += 1.0 / a.video_fps;
          }
        });
  };
  for (int ball = 0; ball < a.balls; ++ball) {
    const sim::BallResult r = play();
    score.add(r.score);
    ball_time.add(r.duration_s);
    steps += r.steps;
    flips += static_cast<std::uint64_t>(r.flips);
    cut += r.cut ? 1 : 0;
    left_table += r.left_table ? 1 : 0;
    run_hash = sim::hash_combine_ball_end(sim::hash_combine_state(run_hash, state), r);
    progress.update(ball + 1, "mean score " + format_number(score.mean(), 4));
    if (trace && trace->failed()) trace->finish();  // throws now: --trace /dev/full had played the whole run first
  }
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // Both checked before either replaces its old file: a run that fails leaves what was there.
  if (video) video->finish();
  if (trace) trace->finish();
  if (video) video->commit();
  if (trace) trace->commit();

  const double steps_per_s = wall_s > 0.0 ? static_cast<double>(steps) / wall_s : 0.0;
  const std::uint64_t events = state.events - events_before;
  const double events_per_s = wall_s > 0.0 ? static_cast<double>(events) / wall_s : 0.0;
  char hash_hex[17];
  std::snprintf(hash_hex, sizeof(hash_hex), "%016llx", static_cast<unsigned long long>(run_hash));
  if (a.json) {
    nlohmann::json j = {
        {"board", a.board},
        {"policy", policy},
        {"controller", a.controller},
        {"seed", a.seed},
        {"dt_s", dt_s},
        {"balls", a.balls},
        {"camera",
         to_json_value(a.camera)},
        {"flips", flips},
        {"actuation", a.actuation},
        {"actuation_delay_s", a.actuation_delay_s},
        {"mean_score_per_ball", score.mean()},
        {"score_ci95_half_width", score.ci95_half_width()},
        {"score_stddev", score.stddev()},
        {"max_score", score.max()},
        {"mean_ball_time_s", ball_time.mean()},
        {"balls_cut_at_time_limit", cut},
        {"max_ball_time_s", a.max_ball_time_s},
        {"balls_left_table", left_table},
        {"steps", steps},
        {"state_hash", hash_hex},
        {"wall_s", wall_s},
        {"steps_per_s", steps_per_s},
        {"events", events},
        {"events_per_s", events_per_s},
    };
    j.update(identified_report(a.identified));
    j.update(world_report(world_spec, a.board, *world.world));
    out << json_text(j, 2) << "\n";
  } else {
    out << identified_text_line(a.identified);
    out << world_text_line(world_report(world_spec, a.board, *world.world));
    out << "board            " << a.board << " (policy " << policy << ", actuation " << a.actuation
        << ", world " << world.world->name() << ", dt "
        << format_number(dt_s) << " s, seed " << a.seed << ")\n"
        << "balls            " << a.balls << " (" << cut << " cut at " << format_number(a.max_ball_time_s) << " s, "
        << left_table << " left the table)\n"
        << "score per ball   " << format_mean_ci(score.mean(), score.ci95_half_width()) << " (95 % interval), max "
        << format_number(score.max()) << "\n"
        << "mean ball time   " << format_number(ball_time.mean()) << " s, " << flips << " flips\n"
        << "steps            " << steps << " in " << format_number(wall_s) << " s wall = " << format_number(steps_per_s)
        << " steps/s\n"
        << "events           " << events << " = " << format_number(events_per_s) << " events/s\n"
        << "state hash       " << hash_hex << "\n";
  }
  return 0;
}

}  // namespace pinball::cli
