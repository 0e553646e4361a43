#pragma once
// The reconstructed thesis table, loaded once per test binary.

#include "pinball/table/board_loader.h"

namespace pinball::testing {

/// boards/mit1993.board, parsed on first use.
inline const table::Board& thesis_board() {
  static const table::Board board = table::load_board(PINBALL_SOURCE_DIR "/boards/mit1993.board");
  return board;
}

}  // namespace pinball::testing
