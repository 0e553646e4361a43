#include <exception>
#include <ostream>

#include "commands.h"

namespace pinball::cli {

int run_pinball(int argc, const char* const* argv, std::ostream& out, std::ostream& err) {
  CLI::App app{"pinball: simulator and tools of the pinball controller (see README.md)", "pinball"};
  app.set_version_flag("--version", std::string("pinball ") + PINBALL_VERSION);
  app.require_subcommand(1);
  // Every option's help shows its default ("[100]"); subcommands inherit this.
  app.option_defaults()->always_capture_default();
  SimArgs sim;
  RenderArgs render;
  BenchArgs bench;
  TrackArgs track;
  LearnArgs learn;
  ReplayArgs replay;
  CalibrateArgs calibrate;
  ViewArgs view;
  PlayArgs play;
  IdentifyArgs identify;
  CLI::App* sim_cmd = add_sim_command(app, sim);
  CLI::App* render_cmd = add_render_command(app, render);
  CLI::App* bench_cmd = add_bench_command(app, bench);
  CLI::App* track_cmd = add_track_command(app, track);
  CLI::App* learn_cmd = add_learn_command(app, learn);
  CLI::App* replay_cmd = add_replay_command(app, replay);
  CLI::App* calibrate_cmd = add_calibrate_command(app, calibrate);
  CLI::App* view_cmd = add_view_command(app, view);
  CLI::App* play_cmd = add_play_command(app, play);
  CLI::App* identify_cmd = add_identify_command(app, identify);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp&) {
    out << app.help();
    return 0;
  } catch (const CLI::CallForAllHelp&) {
    out << app.help("", CLI::AppFormatMode::All);
    return 0;
  } catch (const CLI::CallForVersion& e) {
    out << e.what() << "\n";
    return 0;
  } catch (const CLI::ParseError& e) {
    err << "pinball: " << e.what() << " (try --help)\n";
    return 2;
  }
  try {
    if (sim_cmd->parsed()) return run_sim(sim, out, err);
    if (render_cmd->parsed()) return run_render(render, out, err);
    if (bench_cmd->parsed()) return run_bench(bench, out, err);
    if (track_cmd->parsed()) return run_track(track, out, err);
    if (learn_cmd->parsed()) return run_learn(learn, out, err);
    if (replay_cmd->parsed()) return run_replay(replay, out, err);
    if (calibrate_cmd->parsed()) return run_calibrate(calibrate, out, err);
    if (view_cmd->parsed()) return run_view(view, out, err);
    if (play_cmd->parsed()) return run_play(play, out, err);
    if (identify_cmd->parsed()) return run_identify(identify, out, err);
  } catch (const std::exception& e) {
    err << "pinball: " << e.what() << "\n";
    return 1;
  }
  return 2;
}

}  // namespace pinball::cli
