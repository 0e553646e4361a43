#pragma once
// The window of `pinball play`: draws the table with render_board at a fixed
// frame rate while the session's physics catches up with the wall clock at
// its own dt, and turns the keyboard (or a key script) into key events. The
// game logic is simlab::PlaySession; this only wires the window to it.

#include <functional>
#include <string>
#include <vector>

#include "pinball/core/name_value.h"
#include "pinball/sim/renderer.h"
#include "pinball/simlab/human_play.h"
#include "pinball/table/board.h"

namespace pinball::cli {

/// How to run the window.
struct PlayWindowOptions {
  std::string title = "pinball play";        ///< window title
  sim::RenderOptions render;                 ///< how the table is drawn
  double fps = 100.0;                        ///< frames drawn per wall second (at most)
  const std::vector<simlab::KeyEvent>* script = nullptr;  ///< play these keys instead of the keyboard's flippers
  int balls = 0;                             ///< stop after this many balls; 0: when the player quits
  std::function<void()> after_frame;         ///< called after every frame (record finished balls)
};

/// What the window measured.
struct PlayWindowReport {
  long frames = 0;             ///< frames drawn
  double wall_s = 0.0;         ///< wall time of the session (s)
  double draw_fps = 0.0;       ///< frames / wall_s
  double mean_draw_ms = 0.0;   ///< mean time to render and show one frame (ms)
  std::string keyboard;        ///< "x11" (true key state) or "waitkey" (presses held a short time)
  bool quit_by_player = false; ///< the player pressed Esc or q

  /// The figures as reports spell them (core/json_write_archive.h).
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(frames));
    a->Visit(PINBALL_NVP(wall_s));
    a->Visit(PINBALL_NVP(draw_fps));
    a->Visit(PINBALL_NVP(mean_draw_ms));
    a->Visit(PINBALL_NVP(keyboard));
    a->Visit(PINBALL_NVP(quit_by_player));
  }
};

/// Opens the window and plays until the player quits, `balls` balls are
/// done, or the script has run out with no ball on the table. Keys: see
/// docs/play.md. Throws std::runtime_error when the window cannot be opened.
PlayWindowReport play_in_window(simlab::PlaySession& session, const table::Board& board,
                                const PlayWindowOptions& options);

}  // namespace pinball::cli
