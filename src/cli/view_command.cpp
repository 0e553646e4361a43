// `pinball view [LOG]`: a window onto a running pinballd (live over LCM) or a
// recorded LCM log (pause, seek, frame by frame), or one picture of either
// with --snapshot, without a display.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>
#include <ostream>
#include <stdexcept>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/highgui.hpp>

#include "commands.h"
#include "data_file.h"
#include "display_check.h"
#include "pinball/bus/channels.h"
#include "pinball/bus/lcm_bus.h"
#include "pinball/bus/lcm_log_format.h"
#include "pinball/bus/recorded_play.h"
#include "pinball/core/format.h"
#include "pinball/core/json_text.h"
#include "pinball/core/number_option.h"
#include "pinball/daemon/daemon_config.h"
#include "pinball/plot/draw.h"
#include "pinball/plot/png_file.h"
#include "pinball/view/lcm_listener.h"
#include "pinball/view/log_player.h"
#include "pinball/view/view_render.h"

namespace pinball::cli {
namespace {

constexpr const char* kWindow = "pinball view";
constexpr double kFramePeriod_s = 1.0 / 60.0;

double steady_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// The board, calibration and controller the daemon runs with: --config's,
// then the overrides; the daemon's defaults otherwise.
view::ViewScene scene_for(const ViewArgs& a) {
  daemon::DaemonConfig config;
  if (!a.config.empty()) config = daemon::load_daemon_config(a.config);
  daemon::find_data_files(config);  // the defaults name the shipped data from any folder, as pinballd's do
  std::string board = config.mode == "lab" ? config.board : config.sim.board;
  std::string calibration = config.calibration;
  std::string controller = a.config.empty() ? std::string() : config.controller;
  if (!a.board.empty()) board = a.board;
  if (!a.calibration.empty()) calibration = a.calibration;
  if (!a.controller.empty()) controller = a.controller;
  return view::load_view_scene(board, calibration, controller, a.px_per_m);
}

// The URL to listen on. One that writes a log is refused: liblcm opens it for writing and so emptied
// the recording a pinballd configuration names (`view --config rec.yaml`), or damaged one being made.
std::string live_url(const ViewArgs& a) {
  const bool from_config = !a.config.empty() && a.lcm_url == ViewArgs{}.lcm_url;
  const std::string url = from_config ? daemon::load_daemon_config(a.config).lcm_url : a.lcm_url;
  if (const std::optional<bus::LcmLogTarget> log = bus::lcm_log_target(url)) {
    throw std::invalid_argument("view: " + (from_config ? a.config + "'s lcm_url '" : "--lcm-url '") + url +
                                "' writes a log, and listening there would replace " + log->path +
                                "; to watch that recording give its file: pinball view " + log->path);
  }
  return url;
}

// What the window shows and the summary reports.
struct Session {
  std::uint64_t frames_drawn = 0;
  double draw_s = 0.0;
  cv::Mat last;
};

nlohmann::json ball_json(const view::ViewScene& scene, const view::ViewState& state) {
  const std::optional<view::Sighting> ball = state.ball();
  if (!ball) return nullptr;
  const cv::Point2d px = view::view_pixel(scene, ball->p_board);
  return {{"x_m", ball->p_board.x()}, {"y_m", ball->p_board.y()}, {"t_s", ball->t_s}, {"u_px", px.x}, {"v_px", px.y}};
}

void report(const ViewArgs& a, const std::string& source, double t_s, const view::ViewScene& scene,
            const view::ViewState& state, const Session& s, std::ostream& out) {
  const view::DaemonFigures f = state.figures();
  const double draw_fps = s.draw_s > 0.0 ? static_cast<double>(s.frames_drawn) / s.draw_s : 0.0;
  if (a.json) {
    nlohmann::json j{{"source", source},
                     {"t_s", t_s},
                     {"messages", state.messages()},
                     {"malformed", state.malformed()},
                     {"observations", state.observations()},
                     {"ball", ball_json(scene, state)},
                     {"projection_valid", state.projection().has_value()},
                     {"commands_listed", state.commands().size()},
                     {"camera_fps", f.frame_rate_hz},
                     {"frames_dropped", f.frames_dropped},
                     {"camera_stalls", f.camera_stalls},
                     {"frame_to_can_p99_us", f.has_stats && f.frame_to_can_p99_us >= 0.0 ? nlohmann::json(f.frame_to_can_p99_us)
                                                                                       : nlohmann::json(nullptr)},
                     {"frames_drawn", s.frames_drawn},
                     {"draw_fps", draw_fps}};
    j["snapshot"] = a.snapshot.empty() ? nlohmann::json(nullptr) : nlohmann::json(a.snapshot);
    out << json_text(j, 2) << "\n";
    return;
  }
  out << source << " at " << format_number(t_s) << " s: " << state.messages() << " messages (" << state.malformed()
      << " malformed), " << state.observations() << " observations";
  if (const std::optional<view::Sighting> b = state.ball()) {
    out << ", ball at (" << format_number(b->p_board.x()) << ", " << format_number(b->p_board.y()) << ") m";
  } else {
    out << ", no ball in the last frame";
  }
  out << "\n";
  if (s.frames_drawn > 0) out << "drew " << s.frames_drawn << " frames at " << format_number(draw_fps) << " frames/s\n";
  if (!a.snapshot.empty()) out << "wrote " << a.snapshot << "\n";
}

void write_snapshot(const ViewArgs& a, const cv::Mat& picture) {
  if (!a.snapshot.empty()) plot::write_png(picture, a.snapshot);
}

// The window's keys, for the help line and the docs.
constexpr const char* kKeys = "space pause | . , frame +/- | l j 1 s +/- | L J 10 s +/- | + - speed | s snapshot | q quit";

// A time past the log's end (--at, --quit-at) is refused: --quit-at had played on for ever, the view
// held at the end and never reaching it.
void check_within_log(const char* option, double t_s, const ViewArgs& a, const view::LogPlayer& player) {
  const double end_s = player.duration_s();
  if (t_s <= end_s + 1e-9) return;
  // Exact only where rounding would hide the difference: "--at 35.9000001" had been refused as
  // "--at 35.9 ... ends at 35.9 s", and a plain end had read 20.851499999999998 s.
  const bool close = t_s - end_s < 1e-3;
  auto shown = [close](double x) { return close ? format_exact(x) : format_number(x, 6); };
  throw std::runtime_error(std::string(option) + " " + shown(t_s) + ": the log " + a.log + " ends at " +
                           shown(end_s) + " s");
}

int view_log_snapshot(const ViewArgs& a, const view::ViewScene& scene, view::LogPlayer& player, std::ostream& out) {
  const double t_s = a.at_s < 0.0 ? player.duration_s() : a.at_s;
  check_within_log("--at", t_s, a, player);
  player.seek(t_s);
  const cv::Mat picture = view::render_view(scene, player.state(), {a.log, "log " + format_number(t_s) + " s"});
  write_snapshot(a, picture);
  report(a, a.log, t_s, scene, player.state(), Session{}, out);
  return 0;
}

int view_log_window(const ViewArgs& a, const view::ViewScene& scene, view::LogPlayer& player, std::ostream& out) {
  if (a.quit_at_s >= 0.0) check_within_log("--quit-at", a.quit_at_s, a, player);
  cv::namedWindow(kWindow, cv::WINDOW_AUTOSIZE);
  Session s;
  bool paused = false;
  double speed = a.speed;
  double position_s = 0.0;
  double last_tick_s = steady_s();
  const double start_s = last_tick_s;
  while (true) {
    const double now_s = steady_s();
    if (!paused) position_s = std::min(player.duration_s(), position_s + speed * (now_s - last_tick_s));
    last_tick_s = now_s;
    if (a.quit_at_s >= 0.0) position_s = std::min(position_s, a.quit_at_s);
    player.seek(position_s);
    char status[160];
    std::snprintf(status, sizeof status, "log %.3f / %.3f s  x%.3g%s   %s", position_s, player.duration_s(), speed,
                  paused ? "  paused" : "", kKeys);
    s.last = view::render_view(scene, player.state(), {a.log, status});
    cv::imshow(kWindow, s.last);
    ++s.frames_drawn;
    if (a.quit_at_s >= 0.0 && position_s >= a.quit_at_s - 1e-9) break;
    const int wait_ms = std::max(1, static_cast<int>(1e3 * (kFramePeriod_s - (steady_s() - now_s))));
    const int key = cv::waitKey(wait_ms);
    if (key == 'q' || key == 27) break;
    if (cv::getWindowProperty(kWindow, cv::WND_PROP_VISIBLE) < 1.0) break;  // closed by its frame
    switch (key) {
      case ' ': paused = !paused; break;
      case '.': paused = true; player.step_frame_forward(); position_s = player.position_s(); break;
      case ',': paused = true; player.step_frame_back(); position_s = player.position_s(); break;
      case 'l': position_s = std::min(player.duration_s(), position_s + 1.0); break;
      case 'j': position_s = std::max(0.0, position_s - 1.0); break;
      case 'L': position_s = std::min(player.duration_s(), position_s + 10.0); break;
      case 'J': position_s = std::max(0.0, position_s - 10.0); break;
      case '+': case '=': speed = std::min(64.0, speed * 2.0); break;
      case '-': speed = std::max(1.0 / 64.0, speed / 2.0); break;
      case 's': {
        char name[64];
        std::snprintf(name, sizeof name, "view_%.3f.png", position_s);
        plot::write_png(s.last, name);
        break;
      }
      default: break;
    }
  }
  s.draw_s = steady_s() - start_s;
  write_snapshot(a, s.last);
  cv::destroyAllWindows();
  report(a, a.log, player.position_s(), scene, player.state(), s, out);
  return 0;
}

int view_live(const ViewArgs& a, const view::ViewScene& scene, bool window, std::ostream& out, std::ostream& err) {
  const std::string url = live_url(a);
  view::ViewState state;
  view::LcmListener listener(url, state);
  if (window) cv::namedWindow(kWindow, cv::WINDOW_AUTOSIZE);
  Session s;
  const double start_s = steady_s();
  double last_message_s = start_s;
  bool ended = false;
  // Without a window, a snapshot is taken once the view reaches --at (message
  // time from the first message), or when the source ends or goes quiet.
  const double until_s = window ? a.quit_at_s : a.at_s;
  while (true) {
    const int n = ended ? 0 : listener.poll(window ? 5 : 50, until_s);
    if (n < 0) ended = true;
    const double now_s = steady_s();
    if (n > 0) last_message_s = now_s;
    const bool reached = until_s >= 0.0 && listener.received() > 0 && state.now_s() >= until_s;
    const bool quiet = now_s - last_message_s > a.wait_s;
    if (window) {
      const std::string status = "live " + format_number(state.now_s()) + " s" +
                                 (listener.received() == 0 ? "  (nothing received yet)" : "") + "   q quit, s snapshot";
      s.last = view::render_view(scene, state, {url, status});
      cv::imshow(kWindow, s.last);
      ++s.frames_drawn;
      const int key = cv::waitKey(std::max(1, static_cast<int>(1e3 * (kFramePeriod_s - (steady_s() - now_s)))));
      if (key == 'q' || key == 27 || reached) break;
      if (key == 's') plot::write_png(s.last, "view_live.png");
      if (cv::getWindowProperty(kWindow, cv::WND_PROP_VISIBLE) < 1.0) break;
    } else if (reached || ended || quiet) {
      break;
    }
  }
  s.draw_s = steady_s() - start_s;
  if (listener.received() == 0) {
    throw std::runtime_error(url + ": nothing arrived on the daemon's channels in " +
                             format_number(steady_s() - start_s) + " s (is pinballd running with this --lcm-url?)");
  }
  if (!window) s.last = view::render_view(scene, state, {url, "live " + format_number(state.now_s()) + " s"});
  if (!window && a.at_s >= 0.0 && state.now_s() < a.at_s) {
    err << "view: the source " << (ended ? "ended" : "went quiet") << " at " << format_number(state.now_s())
        << " s, before --at " << format_number(a.at_s) << " s: the snapshot shows its last moment\n";
  }
  write_snapshot(a, s.last);
  if (window) cv::destroyAllWindows();
  report(a, url, state.now_s(), scene, state, s, out);
  return 0;
}

}  // namespace

CLI::App* add_view_command(CLI::App& app, ViewArgs& a) {
  CLI::App* cmd = app.add_subcommand(
      "view", "watch pinballd: live over LCM, or a recorded LCM log with pause, seek and frame stepping");
  // Options one mode reads and the other would drop are refused together (CLI11's excludes and needs).
  CLI::Option* log =
      cmd->add_option("log", a.log, "LCM log to play (pinballd --lcm-url file://...?mode=w, lcm-logger); none: live")
          ->check(input_file());
  cmd->add_option("--lcm-url", a.lcm_url, "live: the LCM URL pinballd publishes on (default: --config's, else udpm)")
      ->check(lcm_url_given())
      ->excludes(log);
  cmd->add_option("--config", a.config, "the pinballd configuration: board, calibration, controller, LCM URL")
      ->transform(data_file());
  cmd->add_option("--board", a.board, "board file (default: the configuration's, boards/mit1993.board)")
      ->transform(data_file());
  cmd->add_option("--calibration", a.calibration, "calibration file: flipper geometry and g (default: the configuration's)")
      ->transform(data_file());
  cmd->add_option("--controller", a.controller, "controller file, for d_critical (default: the configuration's, else none)")
      ->transform(data_file());
  cmd->add_option("--snapshot", a.snapshot,
                  "PNG to write: with --at, the picture at that time and no window; with --quit-at, the window's "
                  "last frame")
      ->check(output_file());
  CLI::Option* at = cmd->add_option("--at", a.at_s,
                                    "snapshot time: seconds from the log's first event or the first live message "
                                    "(default: the end)")
                        ->check(finite_range(0.0, 1e9))
                        ->default_str("");  // -1: the end
  cmd->add_option("--quit-at", a.quit_at_s, "window: play until this time (s), write --snapshot, quit")
      ->check(finite_range(0.0, 1e9))
      ->default_str("")  // -1: play until q
      ->excludes(at);
  cmd->add_option("--speed", a.speed, "log playback speed in the window (keys + and - change it)")
      ->check(finite_range(1.0 / 64.0, 64.0))
      ->needs(log)
      ->excludes(at);
  cmd->add_option("--px-per-m", a.px_per_m, "scale of the table in pixels per metre")
      ->check(finite_range(100.0, 4000.0));
  cmd->add_option("--wait-s", a.wait_s, "live without a window: stop when nothing arrives for this long (s)")
      ->check(finite_range(0.1, 3600.0))
      ->excludes(log);
  cmd->add_flag("--json", a.json, "print one JSON object (what the view showed last)");
  return cmd;
}

int run_view(const ViewArgs& a, std::ostream& out, std::ostream& err) {
  check_png_output(a.snapshot, "--snapshot");
  // A snapshot named as the log or a file the scene reads had replaced it with a picture, exit 0.
  check_outputs_replace_no_input({{"--snapshot", a.snapshot}}, {{"log", a.log},
                                                               {"--config", a.config},
                                                               {"--board", a.board},
                                                               {"--calibration", a.calibration},
                                                               {"--controller", a.controller}});
  const bool window = a.snapshot.empty() || a.quit_at_s >= 0.0;
  if (const std::string problem = window ? display_problem() : ""; !problem.empty()) {
    throw std::runtime_error("pinball view needs a display for its window (" + problem +
                             "); write a picture without one with --snapshot FILE.png --at SECONDS");
  }
  const view::ViewScene scene = scene_for(a);
  if (!a.log.empty()) {
    std::vector<bus::LcmLogEvent> events = bus::read_lcm_log(a.log);
    bus::check_log_holds_one_run(a.log, events);  // two runs appended would play interleaved
    // A log of another program had drawn an empty table and exited 0.
    const bool any = std::any_of(events.begin(), events.end(), [](const bus::LcmLogEvent& e) {
      return std::ranges::find_if(bus::kDaemonChannels, [&](const char* c) { return e.channel == c; }) !=
             bus::kDaemonChannels.end();
    });
    if (!any) {
      throw std::runtime_error(a.log + ": none of its " + std::to_string(events.size()) +
                               " messages is on the daemon's channels (PINBALL_*): a log of another program?");
    }
    view::LogPlayer player(std::move(events));
    return window ? view_log_window(a, scene, player, out) : view_log_snapshot(a, scene, player, out);
  }
  return view_live(a, scene, window, out, err);
}

}  // namespace pinball::cli
