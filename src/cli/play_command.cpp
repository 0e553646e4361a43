// `pinball play BOARD`: a person plays the simulated table at the keyboard in
// real time (docs/play.md), each ball's score appended to a CSV with the
// player's name and the date; `pinball play --stats FILE` prints Table 2.1 of
// the thesis (balls and mean score per ball per player) with 95 % intervals.

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <map>
#include <ostream>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "data_file.h"
#include "display_check.h"
#include "pinball/core/data_path.h"
#include "pinball/core/format.h"
#include "pinball/core/json_text.h"
#include "pinball/core/json_write_archive.h"
#include "pinball/core/number_option.h"
#include "pinball/core/running_stats.h"
#include "pinball/core/utc_date.h"
#include "pinball/simlab/human_play.h"
#include "pinball/simlab/play_scores.h"
#include "pinball/table/board_loader.h"
#include "play_window.h"
#include "world_options.h"

namespace pinball::cli {
namespace {

// Simulated seconds a headless session advances between looks at its balls.
constexpr double kHeadlessChunk_s = 0.05;

// The pooled human mean per ball the thesis measured (2.3, Table 2.1's text).
constexpr double kThesisHumanMeanPerBall = 8388.0;

std::string default_player() {
  const char* user = std::getenv("USER");
  return user != nullptr && *user != '\0' ? user : "player";
}

// The script's text: the file it names, or the argument itself.
std::string key_script_text(const std::string& keys) {
  if (const std::string device = device_input_problem(keys); !device.empty()) {
    throw std::invalid_argument("play: --keys " + device);
  }
  std::ifstream in(keys);
  if (!in) return keys;
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// Balls per value of one column (world, board): the means pool them, so the report says what they pool.
std::map<std::string, std::int64_t> balls_by(const std::vector<simlab::PlayRow>& rows,
                                             std::string simlab::PlayRow::*column) {
  std::map<std::string, std::int64_t> n;
  for (const simlab::PlayRow& r : rows) ++n[r.*column];
  return n;
}

std::string counts_in_words(const std::map<std::string, std::int64_t>& counts) {
  std::string text;
  for (const auto& [name, n] : counts) text += (text.empty() ? "" : ", ") + name + " " + std::to_string(n);
  return text;
}

int run_stats(const PlayArgs& a, std::ostream& out) {
  const std::vector<simlab::PlayRow> rows = simlab::read_play_csv(a.stats);
  const std::vector<simlab::PlayerStats> stats = simlab::play_stats(rows);
  const std::map<std::string, std::int64_t> worlds = balls_by(rows, &simlab::PlayRow::world);
  const std::map<std::string, std::int64_t> boards = balls_by(rows, &simlab::PlayRow::board);
  if (a.json) {
    nlohmann::json players = nlohmann::json::array();
    for (std::size_t i = 0; i + 1 < stats.size(); ++i) players.push_back(to_json_value(stats[i]));
    out << json_text(nlohmann::json{{"file", a.stats},
                                    {"balls_by_world", worlds},
                                    {"balls_by_board", boards},
                                    {"players", players},
                                    {"pooled", stats.empty() ? nlohmann::json(nullptr) : to_json_value(stats.back())},
                                    {"thesis_human_mean_per_ball", kThesisHumanMeanPerBall}},
                     2)
        << "\n";
    return 0;
  }
  out << a.stats << ": " << rows.size() << " balls\n";
  if (stats.empty()) {
    out << "\nno balls played yet\n";
    return 0;
  }
  out << "worlds: " << counts_in_words(worlds) << "; boards: " << counts_in_words(boards) << "\n";
  if (worlds.size() > 1 || boards.size() > 1) out << "the means below pool these games\n";
  out << "\n";
  out << std::left << std::setw(20) << "Subject" << std::right << std::setw(14) << "Number balls"
      << "   Mean per ball (95 % interval)\n";
  for (const simlab::PlayerStats& s : stats) {
    const bool pooled = &s == &stats.back();
    out << std::left << std::setw(20) << (pooled ? "all players" : s.player) << std::right << std::setw(14) << s.balls
        << "   " << format_mean_ci(s.mean_score, s.ci95_half_width, 4) << "\n";
  }
  out << "\nthesis 2.3: pooled human mean " << format_number(kThesisHumanMeanPerBall, 4)
      << " per ball on the 1993 table\n";
  return 0;
}

}  // namespace

CLI::App* add_play_command(CLI::App& app, PlayArgs& a) {
  CLI::App* cmd = app.add_subcommand(
      "play", "play the simulated table at the keyboard in real time; --stats FILE: the players' means (docs/play.md)");
  // Checked, not transformed: the score file keeps the name as the player gave it.
  cmd->add_option("board", a.board, "board file (docs/board-format.md); not with --stats")->check(data_file());
  cmd->add_option("--stats", a.stats,
                  "print balls and mean score per ball (95 % interval) per player of this score CSV")
      ->check(input_file());
  cmd->add_option("--player", a.player, "the player's name in the score file (default: $USER, else 'player')");
  cmd->add_option("--csv", a.csv, "score file each ball is appended to (created with its header)")
      ->check(output_file());
  cmd->add_option("--balls", a.balls, "stop after this many balls (default 0: play until Esc or q)")
      ->check(finite_range(0, 1'000'000));
  cmd->add_option("--max-ball-time", a.max_ball_time_s, "simulated seconds after which a ball still in play is cut")
      ->check(finite_positive());
  cmd->add_option("--pull", a.pull, "launcher pull fraction (default: the board's)")
      ->check(finite_range(0.0, 1.0))
      ->default_str("");  // -1: the board's
  cmd->add_option("--seed", a.seed, "random seed (launch noise)")
      ->check(unsigned_64());
  add_world_options(*cmd, a.world);
  cmd->add_option("--keys", a.keys,
                  "play a key script instead of the keyboard's flippers: a file or 'T:ACTION,...' in simulated seconds, "
                  "ACTION launch, left-down, left-up, right-down, right-up, left, right (a 0.1 s tap)");
  cmd->add_flag("--headless", a.headless, "no window: play the --keys script as fast as possible (no display needed)");
  cmd->add_option("--fps", a.fps, "frames drawn per second (at most)")->check(finite_range(30.0, 1000.0));
  cmd->add_option("--px-per-m", a.px_per_m, "scale of the drawn table in pixels per metre")
      ->check(finite_range(200.0, 3000.0));
  cmd->add_flag("--json", a.json, "print one JSON object instead of text");
  return cmd;
}

int run_play(const PlayArgs& a, std::ostream& out, std::ostream& err) {
  if (!a.stats.empty()) {
    if (!a.board.empty()) throw std::invalid_argument("play: --stats FILE takes no BOARD");
    return run_stats(a, out);
  }
  if (a.board.empty()) throw std::invalid_argument("play: give a BOARD to play, or --stats FILE");
  // Everything the user gave is checked before the game starts and before anything is written.
  const std::string board_path = find_data_file(a.board);
  const table::Board board = table::load_board(board_path);
  const simlab::OwnedWorld world = simlab::make_world(a.world, board);
  const std::string player = a.player.empty() ? default_player() : a.player;
  const std::string world_name(world->name());
  simlab::check_play_row({player, "", a.board, world_name});
  simlab::check_play_csv_appendable(a.csv);
  std::vector<simlab::KeyEvent> script;
  if (!a.keys.empty()) script = simlab::parse_key_script(key_script_text(a.keys));
  if (a.headless && script.empty()) throw std::invalid_argument("play: --headless needs --keys SCRIPT (nobody is at the keyboard)");
  if (const std::string problem = a.headless ? "" : display_problem(); !problem.empty()) {
    throw std::runtime_error("pinball play needs a display (" + problem +
                             "); use --headless with --keys to play a script");
  }
  simlab::PlayConfig config;
  config.seed = a.seed;
  config.max_ball_time_s = a.max_ball_time_s;
  config.pull = a.pull;
  simlab::PlaySession session(*world, config);

  // Each finished ball goes to the file at once: a crash or a closed window loses none.
  std::size_t recorded = 0;
  RunningStats score;
  auto record = [&] {
    std::vector<simlab::PlayRow> rows;
    const std::size_t limit = a.balls > 0 ? static_cast<std::size_t>(a.balls) : session.balls().size();
    for (; recorded < session.balls().size() && recorded < limit; ++recorded) {
      const simlab::PlayedBall& b = session.balls()[recorded];
      rows.push_back({player, utc_now_iso8601(), a.board, world_name, static_cast<int>(recorded + 1), b.score,
                      b.duration_s, b.cut});
      score.add(b.score);
      err << "ball " << recorded + 1 << ": " << format_number(b.score, 6) << " points in "
          << format_number(b.duration_s) << " s" << (b.cut ? " (cut)" : "") << "\n";
    }
    if (!rows.empty()) simlab::append_play_rows(a.csv, rows);
  };

  PlayWindowReport window;
  const auto start = std::chrono::steady_clock::now();
  if (a.headless) {
    std::size_t next = 0;
    for (double t_s = kHeadlessChunk_s;; t_s += kHeadlessChunk_s) {
      next = simlab::play_script_until(session, script, next, t_s);
      record();
      if (a.balls > 0 && static_cast<int>(recorded) >= a.balls) break;
      if (next == script.size() && !session.ball_in_play()) break;
    }
  } else {
    PlayWindowOptions wo;
    wo.title = "pinball play: " + a.board;
    wo.render.px_per_m = a.px_per_m;
    wo.fps = a.fps;
    wo.script = script.empty() ? nullptr : &script;
    wo.balls = a.balls;
    wo.after_frame = record;
    window = play_in_window(session, *world.board, wo);
    record();
  }
  // The window's own clock leaves out opening and closing it; headless, the whole loop.
  const double wall_s = a.headless ? std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count()
                                   : window.wall_s;
  const simlab::PlayCounters& c = session.counters();
  const double steps_per_s = wall_s > 0.0 ? static_cast<double>(c.steps) / wall_s : 0.0;
  const double physics_hz = 1.0 / world->dt_s();

  if (a.json) {
    nlohmann::json balls = nlohmann::json::array();
    for (std::size_t i = 0; i < recorded; ++i) balls.push_back(to_json_value(session.balls()[i]));
    nlohmann::json j = {{"board", a.board},
                        {"player", player},
                        {"csv", a.csv},
                        {"mode", a.headless ? "headless" : "window"},
                        {"keys", script.empty() ? "keyboard" : "script"},
                        {"balls", recorded},
                        {"ball_scores", balls},
                        {"mean_score_per_ball", score.mean()},
                        {"score_ci95_half_width", score.ci95_half_width()},
                        {"max_score", score.max()},
                        {"dt_s", world->dt_s()},
                        {"physics_hz", physics_hz},
                        {"simulated_s", session.time_s()},
                        {"steps_per_s", steps_per_s}};
    j.update(to_json_value(c));
    if (!a.headless) {
      j.update(to_json_value(window));
      j["target_fps"] = a.fps;
    }
    j["wall_s"] = wall_s;
    j.update(world_report(a.world, a.board, *world.world));
    out << json_text(j, 2) << "\n";
    return 0;
  }
  out << world_text_line(world_report(a.world, a.board, *world.world));
  out << "player           " << player << " (" << recorded << (recorded == 1 ? " ball" : " balls")
      << " appended to " << a.csv << ")\n";
  if (recorded > 0) {
    out << "score per ball   " << format_mean_ci(score.mean(), score.ci95_half_width()) << " (95 % interval), max "
        << format_number(score.max(), 6) << "\n";
  }
  out << "physics          " << c.steps << " steps of " << format_number(world->dt_s() * 1e3) << " ms = "
      << format_number(session.time_s()) << " s simulated in " << format_number(wall_s) << " s wall, "
      << format_number(steps_per_s, 4) << " steps/s";
  if (!a.headless) {
    out << " (real time: " << format_number(physics_hz, 4) << "); fell behind " << c.fell_behind << " times, "
        << format_number(c.dropped_s) << " s dropped\n"
        << "drawing          " << window.frames << " frames = " << format_number(window.draw_fps, 4)
        << " frames/s (target " << format_number(a.fps, 4) << "), " << format_number(window.mean_draw_ms)
        << " ms to draw one; keyboard " << window.keyboard << "\n";
  } else {
    out << " (headless: as fast as it goes)\n";
  }
  return 0;
}

}  // namespace pinball::cli
