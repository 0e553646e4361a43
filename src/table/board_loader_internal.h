#pragma once
// The loader in three layers: a tokenizer that turns text into statements, a
// Reader that reads one statement's fields and phrases every error, and one
// function per statement kind over a LoadState. Whole-file checks run last, so a
// Board is returned only when the entire file is valid (docs/board-format.md).
// Internal to pinball_table: board_reader.cpp (tokens, values, errors),
// board_statements.cpp (the statement kinds), board_checks.cpp (the whole-file
// checks), board_loader.cpp (the driver).

#include <initializer_list>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "pinball/core/geometry.h"
#include "pinball/table/board.h"

namespace pinball::table::loader {

/// `v` as an error message shows it (stream default: 6 significant digits).
std::string fmt(double v);

/// One non-empty line of the file, split into tokens; tokens[0] is the keyword.
struct Statement {
  int line = 0;
  std::vector<std::string_view> tokens;
};

/// The statements of `text`, comments and blank lines dropped.
std::vector<Statement> tokenize(std::string_view text);

/// The line (from 1, as tokenize counts them) that holds byte `offset` of `text`.
int line_of(std::string_view text, std::size_t offset);

struct Attribute {
  std::string_view key;
  std::string_view value;
  bool has_value = false;
};

/// Reads the fields of one statement and phrases its errors as
/// "file:line: keyword: what is wrong".
class Reader {
 public:
  /// Splits the statement into positional values and attributes; `allowed`
  /// lists the attributes this keyword takes (space-separated).
  Reader(const Statement& st, const std::string& file, std::string_view allowed);

  int line() const { return st_.line; }
  std::string_view keyword() const { return st_.tokens[0]; }
  std::size_t arg_count() const { return args_.size(); }
  std::string_view arg(std::size_t i) const { return args_[i]; }

  [[noreturn]] void fail(const std::string& message) const;

  /// `token` as a number; `label` names it in the error ("field X1", "attribute rho").
  double number(std::string_view token, const std::string& label) const;

  /// Exactly names.size() numbers starting at positional `first`.
  std::vector<double> numbers(std::size_t first, std::initializer_list<std::string_view> names) const;

  /// A list of (x, y) pairs from positional `first` on, fields named X1 Y1 X2 Y2 ...
  std::vector<Vec2> vertices(std::size_t first, std::size_t min_count) const;

  /// Fails with "<label> must be <rule>, got <value>" unless ok.
  void require(bool ok, const std::string& label, const std::string& rule, double got) const;

  const Attribute* find(std::string_view key) const;
  bool flag(std::string_view key) const { return find(key) != nullptr; }
  double attribute(std::string_view key, double fallback) const;
  std::string_view text(std::string_view key) const;

 private:
  const Statement& st_;
  const std::string& file_;
  std::vector<std::string_view> args_;
  std::vector<Attribute> attributes_;
};

/// What the statements of one file build up: the board so far and the settings
/// that later statements and the whole-file checks read.
struct LoadState {
  explicit LoadState(const std::string& file_name) : file(file_name) { board.source = file_name; }

  const std::string& file;          // source name for errors
  Board board;                      // built up statement by statement
  double length_scale = 1.0;        // file length unit -> m
  double angle_scale = 1.0;         // file angle unit -> rad
  double default_rho = 1.0;         // `defaults rho=`
  int first_dimensioned_line = 0;   // first statement using a length or angle
  std::map<std::string, int> seen;  // singleton keyword -> its line
  std::map<std::string, int> names;  // statement name -> its line
  std::vector<int> bank_lines;      // same index as board.banks
  struct Polygon {
    std::vector<Vec2> vertices_m;
    std::string name;
  };
  std::vector<Polygon> polygons;    // solid outlines: a ball must not start inside one
};

/// The file's length unit as messages spell it: "m" or "mm".
std::string unit_name(const LoadState& state);

/// A length in metres (per second with per = "/s", ...) as the file states
/// lengths: "48.5 mm/s" in a `units mm` file, "0.0485 m/s" otherwise.
std::string in_file_unit(const LoadState& state, double si, const std::string& per = "");

/// One statement kind: how the driver treats it, and the function that reads it.
struct StatementKind {
  std::string_view keyword;
  void (*handler)(LoadState&, const Reader&);
  bool singleton;      // at most once
  bool dimensioned;    // uses a length or an angle: units/angles must come first
  std::string_view attributes;
};

/// The kind spelled `keyword`, or nullptr when there is none.
const StatementKind* find_kind(std::string_view keyword);

/// The checks that need the whole file (required statements, banks with
/// members, flipper time step, launcher clear, launch speed, start); throws
/// BoardError.
void check_whole_file(const LoadState& state);

}  // namespace pinball::table::loader
