#include "board_loader_internal.h"

// The checks that need the whole file, run after its last statement: a Board is
// returned only when all of them pass.

#include <stdexcept>

#include "pinball/table/board_loader.h"

namespace pinball::table::loader {

namespace {

constexpr std::string_view kRequired[] = {"pinball-board", "size", "ball", "gravity", "dt", "balls", "launcher"};

void check_launcher_clear(const LoadState& state) {
  const Board& board = state.board;
  const Vec2 p = board.launcher.position;
  const double r = board.ball.radius_m;
  const int line = state.seen.at("launcher");
  const auto overlap = [&](const std::string& what, double d) {
    throw BoardError(state.file, line,
                     "launcher: ball at the launch position overlaps " + what + " (distance " + fmt(d) +
                         " m, ball radius " + fmt(r) + " m)");
  };
  for (std::size_t i = 0; i < board.shapes.size(); ++i) {
    const double d = distance_to_shape(board.shapes[i], p);
    if (d < r) overlap("'" + board.obstacles[i].name + "'", d);
  }
  for (const Flipper& f : board.flippers) {
    const double d = distance_point_segment(p, f.pivot, flipper_tip(f, f.theta_min_rad));
    if (d < r) overlap("flipper '" + f.name + "' in its down position", d);
  }
}

}  // namespace

void check_whole_file(const LoadState& state) {
  const Board& board = state.board;
  for (const std::string_view required : kRequired) {
    if (!state.seen.contains(std::string(required))) {
      throw BoardError(state.file, 0, "missing required '" + std::string(required) + "' statement");
    }
  }
  for (std::size_t k = 0; k < board.banks.size(); ++k) {
    if (board.banks[k].members.empty()) {
      throw BoardError(state.file, state.bank_lines[k],
                       "bank: bank '" + board.banks[k].name + "' has no members (no obstacle says bank=" +
                           board.banks[k].name + ")");
    }
  }
  for (const Flipper& f : board.flippers) {
    Board one;
    one.ball = board.ball;
    one.flippers.push_back(f);
    try {
      check_flipper_time_step(one, board.dt_s);
    } catch (const std::invalid_argument& e) {
      throw BoardError(state.file, f.source_line, std::string("flipper: ") + e.what());
    }
  }
  check_launcher_clear(state);
}

}  // namespace pinball::table::loader
