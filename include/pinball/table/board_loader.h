#pragma once
// Reads board files (docs/board-format.md) into a Board. All or nothing: a
// bad file throws BoardError and no partly built board escapes.

#include <stdexcept>
#include <string>
#include <string_view>

#include "pinball/table/board.h"

namespace pinball::table {

/// Bad board input. what() is "file:line: message" (line omitted when the
/// problem is the file as a whole, e.g. a missing required line).
class BoardError : public std::runtime_error {
 public:
  BoardError(std::string file, int line, const std::string& message);
  const std::string& file() const { return file_; }  ///< file (or source name) at fault
  int line() const { return line_; }                 ///< 1-based line, 0 for the whole file

 private:
  std::string file_;
  int line_;
};

/// Loads a board file. Throws BoardError for any bad input, including an
/// unreadable file.
Board load_board(const std::string& path);

/// Parses board text; `source_name` is used in error messages and Board::source.
Board parse_board(std::string_view text, const std::string& source_name);

}  // namespace pinball::table
