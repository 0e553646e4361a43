#include "pinball/table/board_loader.h"

// The driver: each statement through its kind's function, then the whole-file
// checks. The stages are in board_reader.cpp, board_statements.cpp and
// board_checks.cpp (board_loader_internal.h).

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <utility>

#include "board_loader_internal.h"
#include "pinball/core/read_archive.h"
#include "pinball/core/text_file.h"

namespace pinball::table {

namespace {

void statement(loader::LoadState& state, const loader::Statement& st) {
  const std::string keyword(st.tokens[0]);
  const loader::StatementKind* kind = loader::find_kind(keyword);
  if (kind == nullptr) {
    // A no-break space or a second byte-order mark glues itself to the keyword and is invisible when printed.
    const bool odd_bytes = std::any_of(keyword.begin(), keyword.end(), [](char c) {
      return static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) >= 0x7f;
    });
    throw BoardError(state.file, st.line,
                     "unknown keyword " + quote_value(keyword) +
                         (odd_bytes ? " (holding bytes that are not printable ASCII, shown as '?': a no-break space "
                                      "or a byte-order mark where a space or nothing belongs?)"
                                    : ""));
  }
  if (state.seen.empty() && keyword != "pinball-board") {
    throw BoardError(state.file, st.line, "expected 'pinball-board 1' as the first statement, got '" + keyword + "'");
  }
  if (kind->singleton) {
    const auto [it, inserted] = state.seen.emplace(keyword, st.line);
    if (!inserted) {
      throw BoardError(state.file, st.line,
                       "duplicate '" + keyword + "' statement (first at line " + std::to_string(it->second) + ")");
    }
  }
  if (kind->dimensioned && state.first_dimensioned_line == 0) state.first_dimensioned_line = st.line;
  const loader::Reader r(st, state.file, kind->attributes);
  kind->handler(state, r);
}

}  // namespace

Board parse_board(std::string_view text, const std::string& source_name) {
  text = without_utf8_bom(text);
  if (const std::size_t nul = text.find('\0'); nul != std::string_view::npos) {
    throw BoardError(source_name, loader::line_of(text, nul), "a NUL byte (at byte " + std::to_string(nul + 1) +
                                            "): a board file is text; is this the file you meant?");
  }
  loader::LoadState state(source_name);
  for (const loader::Statement& st : loader::tokenize(text)) statement(state, st);
  loader::check_whole_file(state);
  return std::move(state.board);
}

Board load_board(const std::string& path) {
  if (const std::string problem = input_file_problem(path); !problem.empty()) throw BoardError(path, 0, problem);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw BoardError(path, 0, std::string("cannot open board file: ") + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw BoardError(path, 0, "cannot read board file");
  return parse_board(text.str(), path);
}

}  // namespace pinball::table
