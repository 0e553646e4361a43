#include "board_loader_internal.h"

// The first layer of the loader: text to statements, tokens to values, and the
// phrasing of every error.

#include <charconv>
#include <cmath>
#include <optional>
#include <sstream>
#include <utility>

#include "pinball/core/format.h"
#include "pinball/table/board_loader.h"

namespace pinball::table {

namespace {

std::string what_text(const std::string& file, int line, const std::string& message) {
  return line > 0 ? file + ":" + std::to_string(line) + ": " + message : file + ": " + message;
}

}  // namespace

BoardError::BoardError(std::string file, int line, const std::string& message)
    : std::runtime_error(what_text(file, line, message)), file_(std::move(file)), line_(line) {}

namespace loader {

namespace {

/// A complete, finite decimal number, or nothing ("1.5x", "nan", "inf" are rejected).
std::optional<double> parse_number(std::string_view token) {
  double v = 0.0;
  const char* end = token.data() + token.size();
  const auto [ptr, ec] = std::from_chars(token.data(), end, v);
  if (token.empty() || ec != std::errc() || ptr != end || !std::isfinite(v)) return std::nullopt;
  return v;
}

/// True when `key` is one of the space-separated words of `list`.
bool in_list(std::string_view list, std::string_view key) {
  while (!list.empty()) {
    const std::size_t sp = list.find(' ');
    if (list.substr(0, sp) == key) return true;
    if (sp == std::string_view::npos) break;
    list.remove_prefix(sp + 1);
  }
  return false;
}

constexpr std::string_view kValueAttributes = "rho friction score kick contact bank name pull noise mu kickout spread bonus";
constexpr std::string_view kFlagAttributes = "eat hidden two-sided";

}  // namespace

std::string fmt(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

namespace {

// The first line of `text` and what follows it. A line ends at LF, CRLF or a
// lone CR (an old Mac editor's): each is one line end.
std::pair<std::string_view, std::string_view> split_first_line(std::string_view text) {
  const std::size_t end = text.find_first_of("\r\n");
  if (end == std::string_view::npos) return {text, {}};
  const bool crlf = text[end] == '\r' && end + 1 < text.size() && text[end + 1] == '\n';
  return {text.substr(0, end), text.substr(end + (crlf ? 2 : 1))};
}

}  // namespace

int line_of(std::string_view text, std::size_t offset) {
  int line = 1;
  for (std::string_view rest = text;; ++line) {
    rest = split_first_line(rest).second;
    if (rest.empty() || offset < text.size() - rest.size()) return line;
  }
}

std::vector<Statement> tokenize(std::string_view text) {
  std::vector<Statement> statements;
  int line = 0;
  while (!text.empty()) {
    ++line;
    auto [rest, following] = split_first_line(text);
    text = following;
    rest = rest.substr(0, rest.find('#'));
    Statement st{line, {}};
    while (true) {
      const std::size_t b = rest.find_first_not_of(" \t\r");
      if (b == std::string_view::npos) break;
      rest.remove_prefix(b);
      const std::size_t e = rest.find_first_of(" \t\r");
      st.tokens.push_back(rest.substr(0, e));
      rest = e == std::string_view::npos ? std::string_view{} : rest.substr(e);
    }
    if (!st.tokens.empty()) statements.push_back(std::move(st));
  }
  return statements;
}

Reader::Reader(const Statement& st, const std::string& file, std::string_view allowed) : st_(st), file_(file) {
  for (std::size_t i = 1; i < st.tokens.size(); ++i) {
    const std::string_view t = st.tokens[i];
    const std::size_t eq = t.find('=');
    const bool is_attribute = eq != std::string_view::npos || in_list(kFlagAttributes, t);
    if (!is_attribute) {
      if (!attributes_.empty()) {
        std::string quoted = "'";  // built piecewise: GCC 12 warns falsely on "literal" + std::string
        fail(quoted.append(t).append("' after the attributes: positional values come first"));
      }
      args_.push_back(t);
      continue;
    }
    Attribute a{t.substr(0, eq), eq == std::string_view::npos ? std::string_view{} : t.substr(eq + 1),
                eq != std::string_view::npos};
    const std::string key(a.key);
    const bool is_flag = in_list(kFlagAttributes, a.key);
    if (!is_flag && !in_list(kValueAttributes, a.key)) fail("unknown attribute '" + key + "'");
    if (!in_list(allowed, a.key)) fail("attribute '" + key + "' does not apply to '" + std::string(keyword()) + "'");
    if (find(a.key) != nullptr) fail("attribute '" + key + "' given twice");
    if (is_flag && a.has_value) fail("attribute '" + key + "' is a flag and takes no value");
    if (!is_flag && a.value.empty()) fail("attribute '" + key + "' needs a value (" + key + "=...)");
    attributes_.push_back(a);
  }
}

void Reader::fail(const std::string& message) const {
  throw BoardError(file_, st_.line, std::string(keyword()) + ": " + message);
}

double Reader::number(std::string_view token, const std::string& label) const {
  const std::optional<double> v = parse_number(token);
  if (!v) fail(label + " is not a finite number: '" + std::string(token) + "'");
  return *v;
}

std::vector<double> Reader::numbers(std::size_t first, std::initializer_list<std::string_view> names) const {
  const std::size_t got = args_.size() > first ? args_.size() - first : 0;
  if (got != names.size()) {
    if (got > names.size() && !parse_number(args_[first + names.size()])) {
      fail("unknown attribute '" + std::string(args_[first + names.size()]) + "'");
    }
    std::string list;
    for (const std::string_view n : names) {
      if (!list.empty()) list += ' ';
      list += n;
    }
    fail("expected " + std::to_string(names.size()) + " number" + (names.size() == 1 ? "" : "s") + " (" + list +
         "), got " + std::to_string(got));
  }
  std::vector<double> v;
  std::size_t i = first;
  for (const std::string_view n : names) v.push_back(number(args_[i++], "field " + std::string(n)));
  return v;
}

std::vector<Vec2> Reader::vertices(std::size_t first, std::size_t min_count) const {
  const std::size_t got = args_.size() > first ? args_.size() - first : 0;
  if (got % 2 != 0 || got < 2 * min_count) {
    fail("expected at least " + std::to_string(min_count) + " vertices as X Y pairs (X1 Y1 X2 Y2 ...), got " +
         std::to_string(got) + " number" + (got == 1 ? "" : "s"));
  }
  std::vector<Vec2> v;
  for (std::size_t i = 0; i < got; i += 2) {
    const std::string n = std::to_string(i / 2 + 1);
    v.emplace_back(number(args_[first + i], "field X" + n), number(args_[first + i + 1], "field Y" + n));
  }
  return v;
}

void Reader::require(bool ok, const std::string& label, const std::string& rule, double got) const {
  if (ok) return;
  // What the file gave, to the last digit: rounded, 10.0000001 read "at most 10, got 10".
  fail(label + " must be " + rule + ", got " + format_exact(got));
}

const Attribute* Reader::find(std::string_view key) const {
  for (const Attribute& a : attributes_) {
    if (a.key == key) return &a;
  }
  return nullptr;
}

double Reader::attribute(std::string_view key, double fallback) const {
  const Attribute* a = find(key);
  return a ? number(a->value, "attribute " + std::string(key)) : fallback;
}

std::string_view Reader::text(std::string_view key) const {
  const Attribute* a = find(key);
  return a ? a->value : std::string_view{};
}

}  // namespace loader

}  // namespace pinball::table
