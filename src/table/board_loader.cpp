#include "pinball/table/board_loader.h"

// The loader in three layers: a tokenizer that turns text into statements, a
// Reader that reads one statement's fields and phrases every error, and one
// Loader method per statement kind. Whole-file checks run last, so a Board is
// returned only when the entire file is valid (docs/board-format.md).

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <numbers>
#include <optional>
#include <sstream>
#include <utility>
#include <vector>

namespace pinball::table {

namespace {

std::string what_text(const std::string& file, int line, const std::string& message) {
  return line > 0 ? file + ":" + std::to_string(line) + ": " + message : file + ": " + message;
}

std::string fmt(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

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

constexpr std::string_view kValueAttributes = "rho score kick contact bank name pull noise mu kickout bonus";
constexpr std::string_view kFlagAttributes = "eat hidden two-sided";
constexpr std::string_view kObstacleAttributes = "rho score kick contact eat hidden bank name";

/// One non-empty line of the file, split into tokens; tokens[0] is the keyword.
struct Statement {
  int line = 0;
  std::vector<std::string_view> tokens;
};

std::vector<Statement> tokenize(std::string_view text) {
  std::vector<Statement> statements;
  int line = 0;
  while (!text.empty()) {
    ++line;
    const std::size_t nl = text.find('\n');
    std::string_view rest = text.substr(0, nl);
    text = nl == std::string_view::npos ? std::string_view{} : text.substr(nl + 1);
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

struct Attribute {
  std::string_view key;
  std::string_view value;
  bool has_value = false;
};

/// Reads the fields of one statement and phrases its errors as
/// "file:line: keyword: what is wrong".
class Reader {
 public:
  Reader(const Statement& st, const std::string& file, std::string_view allowed) : st_(st), file_(file) {
    for (std::size_t i = 1; i < st.tokens.size(); ++i) {
      const std::string_view t = st.tokens[i];
      const std::size_t eq = t.find('=');
      const bool is_attribute = eq != std::string_view::npos || in_list(kFlagAttributes, t);
      if (!is_attribute) {
        if (!attributes_.empty()) fail("'" + std::string(t) + "' after the attributes: positional values come first");
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

  int line() const { return st_.line; }
  std::string_view keyword() const { return st_.tokens[0]; }
  std::size_t arg_count() const { return args_.size(); }
  std::string_view arg(std::size_t i) const { return args_[i]; }

  [[noreturn]] void fail(const std::string& message) const {
    throw BoardError(file_, st_.line, std::string(keyword()) + ": " + message);
  }

  /// `token` as a number; `label` names it in the error ("field X1", "attribute rho").
  double number(std::string_view token, const std::string& label) const {
    const std::optional<double> v = parse_number(token);
    if (!v) fail(label + " is not a finite number: '" + std::string(token) + "'");
    return *v;
  }

  /// Exactly names.size() numbers starting at positional `first`.
  std::vector<double> numbers(std::size_t first, std::initializer_list<std::string_view> names) const {
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

  /// A list of (x, y) pairs from positional `first` on, fields named X1 Y1 X2 Y2 ...
  std::vector<Vec2> vertices(std::size_t first, std::size_t min_count) const {
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

  /// Fails with "<label> must be <rule>, got <value>" unless ok.
  void require(bool ok, const std::string& label, const std::string& rule, double got) const {
    if (!ok) fail(label + " must be " + rule + ", got " + fmt(got));
  }

  const Attribute* find(std::string_view key) const {
    for (const Attribute& a : attributes_) {
      if (a.key == key) return &a;
    }
    return nullptr;
  }
  bool flag(std::string_view key) const { return find(key) != nullptr; }
  double attribute(std::string_view key, double fallback) const {
    const Attribute* a = find(key);
    return a ? number(a->value, "attribute " + std::string(key)) : fallback;
  }
  std::string_view text(std::string_view key) const {
    const Attribute* a = find(key);
    return a ? a->value : std::string_view{};
  }

 private:
  const Statement& st_;
  const std::string& file_;
  std::vector<std::string_view> args_;
  std::vector<Attribute> attributes_;
};

class Loader {
 public:
  Loader(std::string_view text, const std::string& file) : text_(text), file_(file) { board_.source = file; }

  Board run() {
    for (const Statement& st : tokenize(text_)) statement(st);
    check_whole_file();
    return std::move(board_);
  }

 private:
  using Handler = void (Loader::*)(const Reader&);
  struct Kind {
    std::string_view keyword;
    Handler handler;
    bool singleton;      // at most once
    bool dimensioned;    // uses a length or an angle: units/angles must come first
    std::string_view attributes;
  };

  static constexpr std::string_view kRequired[] = {"pinball-board", "size",  "ball",    "gravity",
                                                   "dt",            "balls", "launcher"};

  static const Kind* find_kind(std::string_view keyword) {
    static constexpr std::string_view kObstacleTwoSided = "rho score kick contact eat hidden bank name two-sided";
    static const Kind kKinds[] = {
        {"pinball-board", &Loader::header, true, false, ""},
        {"units", &Loader::units, true, false, ""},
        {"angles", &Loader::angles, true, false, ""},
        {"size", &Loader::size, true, true, ""},
        {"ball", &Loader::ball, true, true, ""},
        {"gravity", &Loader::gravity, true, true, ""},
        {"dt", &Loader::dt, true, false, ""},
        {"balls", &Loader::balls, true, false, ""},
        {"launcher", &Loader::launcher, true, true, "pull noise"},
        {"defaults", &Loader::defaults, false, false, "rho"},
        {"bank", &Loader::bank, false, false, "bonus"},
        {"line", &Loader::line, false, true, kObstacleAttributes},
        {"wall", &Loader::wall, false, true, kObstacleAttributes},
        {"point", &Loader::point, false, true, kObstacleAttributes},
        {"circle", &Loader::circle, false, true, kObstacleAttributes},
        {"polyline", &Loader::polyline, false, true, kObstacleTwoSided},
        {"polygon", &Loader::polygon, false, true, kObstacleAttributes},
        {"flipper", &Loader::flipper, false, true, "rho mu name"},
        {"sensor", &Loader::sensor, false, true, "score eat name"},
        {"hole", &Loader::hole, false, true, "score eat kickout name"},
    };
    for (const Kind& k : kKinds) {
      if (k.keyword == keyword) return &k;
    }
    return nullptr;
  }

  void statement(const Statement& st) {
    const std::string keyword(st.tokens[0]);
    const Kind* kind = find_kind(keyword);
    if (kind == nullptr) throw BoardError(file_, st.line, "unknown keyword '" + keyword + "'");
    if (seen_.empty() && keyword != "pinball-board") {
      throw BoardError(file_, st.line, "expected 'pinball-board 1' as the first statement, got '" + keyword + "'");
    }
    if (kind->singleton) {
      const auto [it, inserted] = seen_.emplace(keyword, st.line);
      if (!inserted) {
        throw BoardError(file_, st.line,
                         "duplicate '" + keyword + "' statement (first at line " + std::to_string(it->second) + ")");
      }
    }
    if (kind->dimensioned && first_dimensioned_line_ == 0) first_dimensioned_line_ = st.line;
    const Reader r(st, file_, kind->attributes);
    (this->*kind->handler)(r);
  }

  // ---- header and constants ----

  void header(const Reader& r) {
    const double version = r.numbers(0, {"VERSION"})[0];
    if (version != 1.0) r.fail("unsupported format version " + fmt(version) + " (this loader reads version 1)");
  }

  /// units/angles: a single word, before any length or angle.
  std::string_view unit_word(const Reader& r, std::string_view a, std::string_view b) {
    std::string choices = "'";  // built piecewise: GCC 12 warns falsely on "literal" + std::string
    choices.append(a).append("' or '").append(b).append("'");
    if (r.arg_count() != 1) r.fail("expected one word, " + choices + ", got " + std::to_string(r.arg_count()));
    if (r.arg(0) != a && r.arg(0) != b) r.fail("expected " + choices + ", got '" + std::string(r.arg(0)) + "'");
    if (first_dimensioned_line_ != 0) {
      r.fail("must come before the first statement that uses a length or angle (line " +
             std::to_string(first_dimensioned_line_) + ")");
    }
    return r.arg(0);
  }
  void units(const Reader& r) { length_scale_ = unit_word(r, "m", "mm") == "mm" ? 1e-3 : 1.0; }
  void angles(const Reader& r) { angle_scale_ = unit_word(r, "rad", "deg") == "deg" ? std::numbers::pi / 180.0 : 1.0; }

  void size(const Reader& r) {
    const auto v = r.numbers(0, {"W", "H"});
    r.require(v[0] > 0, "field W (width)", "> 0", v[0]);
    r.require(v[1] > 0, "field H (height)", "> 0", v[1]);
    board_.width_m = v[0] * length_scale_;
    board_.height_m = v[1] * length_scale_;
  }

  void ball(const Reader& r) {
    const auto v = r.numbers(0, {"R", "SPEED_MAX"});
    r.require(v[0] > 0, "field R (radius)", "> 0", v[0]);
    r.require(v[1] > 0, "field SPEED_MAX", "> 0", v[1]);
    board_.ball.radius_m = v[0] * length_scale_;
    board_.ball.speed_max_mps = v[1] * length_scale_;
  }

  void gravity(const Reader& r) {
    const double g = r.numbers(0, {"G"})[0];
    r.require(g >= 0, "field G", ">= 0", g);
    board_.gravity_mps2 = g * length_scale_;
  }

  void dt(const Reader& r) {
    const double dt = r.numbers(0, {"DT"})[0];
    r.require(dt > 0, "field DT (seconds)", "> 0", dt);
    board_.dt_s = dt;
  }

  void balls(const Reader& r) {
    const double n = r.numbers(0, {"N"})[0];
    r.require(n >= 1 && n == std::floor(n), "field N (balls per game)", "an integer >= 1", n);
    r.require(n <= 1e6, "field N (balls per game)", "at most 1000000", n);
    board_.balls_per_game = static_cast<int>(n);
  }

  void launcher(const Reader& r) {
    const auto v = r.numbers(0, {"X", "Y"});
    Launcher& l = board_.launcher;
    l.position = Vec2{v[0], v[1]} * length_scale_;
    l.pull = r.attribute("pull", 1.0);
    r.require(l.pull > 0 && l.pull <= 1, "attribute pull", "in (0, 1]", l.pull);
    l.noise_max = r.attribute("noise", 0.03);
    r.require(l.noise_max >= 0 && l.noise_max <= 0.5, "attribute noise", "in [0, 0.5]", l.noise_max);
  }

  void defaults(const Reader& r) {
    if (r.arg_count() != 0) r.fail("takes only attributes (rho=R), got '" + std::string(r.arg(0)) + "'");
    default_rho_ = r.attribute("rho", default_rho_);
    r.require(default_rho_ >= 0, "attribute rho", ">= 0", default_rho_);
  }

  void bank(const Reader& r) {
    if (r.arg_count() != 1) r.fail("expected one NAME, got " + std::to_string(r.arg_count()));
    const std::string name(r.arg(0));
    if (bank_index(name) >= 0) r.fail("bank '" + name + "' is declared twice");
    if (!r.flag("bonus")) r.fail("needs bonus=POINTS");
    board_.banks.push_back(Bank{name, r.attribute("bonus", 0.0), {}});
    bank_lines_.push_back(r.line());
  }

  // ---- obstacles ----

  int bank_index(std::string_view name) const {
    for (std::size_t k = 0; k < board_.banks.size(); ++k) {
      if (board_.banks[k].name == name) return static_cast<int>(k);
    }
    return -1;
  }

  /// The attributes every shape of one obstacle statement shares.
  Obstacle obstacle_attributes(const Reader& r) const {
    Obstacle o;
    o.rho = r.attribute("rho", default_rho_);
    r.require(o.rho >= 0, "attribute rho", ">= 0", o.rho);
    o.action.score = r.attribute("score", 0.0);
    const double kick = r.attribute("kick", 0.0);
    r.require(kick >= 0, "attribute kick", ">= 0", kick);
    o.action.kick_mps = kick * length_scale_;
    o.action.contact_score_per_s = r.attribute("contact", 0.0);
    o.action.eats_ball = r.flag("eat");
    o.visible = !r.flag("hidden");
    if (r.flag("bank")) {
      const std::string_view bank = r.text("bank");
      o.bank = bank_index(bank);
      if (o.bank < 0) r.fail("attribute bank names an undeclared bank '" + std::string(bank) + "'");
    }
    o.name = r.flag("name") ? std::string(r.text("name")) : default_name(r);
    o.source_line = r.line();
    return o;
  }

  static std::string default_name(const Reader& r) {
    return std::string(r.keyword()) + "@" + std::to_string(r.line());
  }

  void add(const Shape& shape, const Obstacle& o) {
    if (o.bank >= 0) {
      board_.banks[static_cast<std::size_t>(o.bank)].members.push_back(static_cast<int>(board_.obstacles.size()));
    }
    board_.shapes.push_back(shape);
    board_.obstacles.push_back(o);
  }

  /// Two points, in file units, checked to differ; returned in metres.
  std::pair<Vec2, Vec2> segment(const Reader& r, std::size_t first) const {
    const auto v = r.numbers(first, {"X1", "Y1", "X2", "Y2"});
    if (v[0] == v[2] && v[1] == v[3]) r.fail("zero-length segment");
    return {Vec2{v[0], v[1]} * length_scale_, Vec2{v[2], v[3]} * length_scale_};
  }

  void line(const Reader& r) {
    const auto [p0, p1] = segment(r, 0);
    add(make_line_shape(p0, p1), obstacle_attributes(r));
  }

  void wall(const Reader& r) {
    const auto [p0, p1] = segment(r, 0);
    const Obstacle o = obstacle_attributes(r);
    add(make_line_shape(p0, p1), o);
    add(make_line_shape(p1, p0), o);
    add(make_circle_shape(p0, 0.0), o);
    add(make_circle_shape(p1, 0.0), o);
  }

  void point(const Reader& r) {
    const auto v = r.numbers(0, {"X", "Y"});
    add(make_circle_shape(Vec2{v[0], v[1]} * length_scale_, 0.0), obstacle_attributes(r));
  }

  void circle(const Reader& r) {
    const auto v = r.numbers(0, {"X", "Y", "R"});
    r.require(v[2] >= 0, "field R (radius)", ">= 0", v[2]);
    add(make_circle_shape(Vec2{v[0], v[1]} * length_scale_, v[2] * length_scale_), obstacle_attributes(r));
  }

  /// Vertices in file units, checked for zero-length edges (closed: also last -> first).
  std::vector<Vec2> path(const Reader& r, std::size_t min_count, bool closed) const {
    const std::vector<Vec2> v = r.vertices(0, min_count);
    const std::size_t edges = closed ? v.size() : v.size() - 1;
    for (std::size_t i = 0; i < edges; ++i) {
      const std::size_t j = (i + 1) % v.size();
      if (v[i] == v[j]) {
        r.fail("zero-length segment (vertices " + std::to_string(i + 1) + " and " + std::to_string(j + 1) + ")");
      }
    }
    return v;
  }

  void polyline(const Reader& r) {
    const std::vector<Vec2> v = path(r, 2, false);
    const Obstacle o = obstacle_attributes(r);
    const bool two_sided = r.flag("two-sided");
    for (std::size_t i = 0; i + 1 < v.size(); ++i) {
      add(make_line_shape(v[i] * length_scale_, v[i + 1] * length_scale_), o);
      if (two_sided) add(make_line_shape(v[i + 1] * length_scale_, v[i] * length_scale_), o);
    }
    for (const Vec2& p : v) add(make_circle_shape(p * length_scale_, 0.0), o);
  }

  void polygon(const Reader& r) {
    std::vector<Vec2> v = path(r, 3, true);
    double twice_area = 0.0;
    for (std::size_t i = 0; i < v.size(); ++i) twice_area += cross(v[i], v[(i + 1) % v.size()]);
    if (twice_area == 0.0) r.fail("the vertices enclose no area");
    // Clockwise traversal puts each edge's left normal outside.
    if (twice_area > 0.0) std::reverse(v.begin(), v.end());
    const Obstacle o = obstacle_attributes(r);
    for (std::size_t i = 0; i < v.size(); ++i) {
      add(make_line_shape(v[i] * length_scale_, v[(i + 1) % v.size()] * length_scale_), o);
    }
    for (const Vec2& p : v) add(make_circle_shape(p * length_scale_, 0.0), o);
  }

  // ---- flippers and sensors ----

  void flipper(const Reader& r) {
    Flipper f;
    const std::string_view side = r.arg_count() > 0 ? r.arg(0) : std::string_view{};
    if (side != "left" && side != "right") {
      r.fail("field SIDE must be 'left' or 'right', got '" + std::string(side) + "'");
    }
    f.side = side == "left" ? Side::kLeft : Side::kRight;
    const auto v = r.numbers(1, {"PX", "PY", "LENGTH", "THETA_MIN", "THETA_MAX", "OMEGA"});
    r.require(v[2] > 0, "field LENGTH", "> 0", v[2]);
    if (!(v[3] < v[4])) r.fail("field THETA_MIN (" + fmt(v[3]) + ") must be less than THETA_MAX (" + fmt(v[4]) + ")");
    r.require(v[5] > 0, "field OMEGA", "> 0", v[5]);
    f.pivot = Vec2{v[0], v[1]} * length_scale_;
    f.length_m = v[2] * length_scale_;
    f.theta_min_rad = v[3] * angle_scale_;
    f.theta_max_rad = v[4] * angle_scale_;
    f.omega_rad_s = v[5] * angle_scale_;
    f.rho = r.attribute("rho", default_rho_);
    r.require(f.rho >= 0, "attribute rho", ">= 0", f.rho);
    f.mu = r.attribute("mu", 1.0);
    r.require(f.mu >= 0, "attribute mu", ">= 0", f.mu);
    f.name = r.flag("name") ? std::string(r.text("name")) : default_name(r);
    f.source_line = r.line();
    board_.flippers.push_back(f);
  }

  void sensor(const Reader& r) {
    Sensor s;
    const std::string_view shape = r.arg_count() > 0 ? r.arg(0) : std::string_view{};
    if (shape == "line") {
      const auto [p0, p1] = segment(r, 1);
      s.shape = make_line_shape(p0, p1);
    } else if (shape == "circle") {
      const auto v = r.numbers(1, {"X", "Y", "R"});
      r.require(v[2] >= 0, "field R (radius)", ">= 0", v[2]);
      s.shape = make_circle_shape(Vec2{v[0], v[1]} * length_scale_, v[2] * length_scale_);
    } else {
      r.fail("field SHAPE must be 'line' or 'circle', got '" + std::string(shape) + "'");
    }
    s.kind = SensorKind::kProximity;
    finish_sensor(r, s);
  }

  void hole(const Reader& r) {
    Sensor s;
    const auto v = r.numbers(0, {"X", "Y", "R"});
    r.require(v[2] > 0, "field R (radius)", "> 0", v[2]);
    s.kind = SensorKind::kHole;
    s.shape = make_circle_shape(Vec2{v[0], v[1]} * length_scale_, v[2] * length_scale_);
    const bool eat = r.flag("eat");
    if (eat == r.flag("kickout")) r.fail("needs exactly one of 'eat' or 'kickout=VX,VY'");
    if (!eat) {
      const std::string_view k = r.text("kickout");
      const std::size_t comma = k.find(',');
      if (comma == std::string_view::npos) r.fail("attribute kickout must be VX,VY, got '" + std::string(k) + "'");
      s.has_kickout = true;
      s.kickout_mps = Vec2{r.number(k.substr(0, comma), "attribute kickout VX"),
                           r.number(k.substr(comma + 1), "attribute kickout VY")} *
                      length_scale_;
    }
    finish_sensor(r, s);
  }

  void finish_sensor(const Reader& r, Sensor& s) {
    s.action.score = r.attribute("score", 0.0);
    s.action.eats_ball = r.flag("eat");
    s.name = r.flag("name") ? std::string(r.text("name")) : default_name(r);
    s.source_line = r.line();
    board_.sensors.push_back(s);
  }

  // ---- whole file ----

  void check_whole_file() {
    for (const std::string_view required : kRequired) {
      if (!seen_.contains(std::string(required))) {
        throw BoardError(file_, 0, "missing required '" + std::string(required) + "' statement");
      }
    }
    for (std::size_t k = 0; k < board_.banks.size(); ++k) {
      if (board_.banks[k].members.empty()) {
        throw BoardError(file_, bank_lines_[k],
                         "bank: bank '" + board_.banks[k].name + "' has no members (no obstacle says bank=" +
                             board_.banks[k].name + ")");
      }
    }
    for (const Flipper& f : board_.flippers) {
      Board one;
      one.ball = board_.ball;
      one.flippers.push_back(f);
      try {
        check_flipper_time_step(one, board_.dt_s);
      } catch (const std::invalid_argument& e) {
        throw BoardError(file_, f.source_line, std::string("flipper: ") + e.what());
      }
    }
    check_launcher_clear();
  }

  void check_launcher_clear() const {
    const Vec2 p = board_.launcher.position;
    const double r = board_.ball.radius_m;
    const int line = seen_.at("launcher");
    const auto overlap = [&](const std::string& what, double d) {
      throw BoardError(file_, line,
                       "launcher: ball at the launch position overlaps " + what + " (distance " + fmt(d) +
                           " m, ball radius " + fmt(r) + " m)");
    };
    for (std::size_t i = 0; i < board_.shapes.size(); ++i) {
      const double d = distance_to_shape(board_.shapes[i], p);
      if (d < r) overlap("'" + board_.obstacles[i].name + "'", d);
    }
    for (const Flipper& f : board_.flippers) {
      const double d = distance_point_segment(p, f.pivot, flipper_tip(f, f.theta_min_rad));
      if (d < r) overlap("flipper '" + f.name + "' in its down position", d);
    }
  }

  std::string_view text_;
  const std::string& file_;
  Board board_;
  double length_scale_ = 1.0;       // file length unit -> m
  double angle_scale_ = 1.0;        // file angle unit -> rad
  double default_rho_ = 1.0;        // `defaults rho=`
  int first_dimensioned_line_ = 0;  // first statement using a length or angle
  std::map<std::string, int> seen_; // singleton keyword -> its line
  std::vector<int> bank_lines_;     // same index as board_.banks
};

}  // namespace

BoardError::BoardError(std::string file, int line, const std::string& message)
    : std::runtime_error(what_text(file, line, message)), file_(std::move(file)), line_(line) {}

Board parse_board(std::string_view text, const std::string& source_name) {
  return Loader(text, source_name).run();
}

Board load_board(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw BoardError(path, 0, std::string("cannot open board file: ") + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw BoardError(path, 0, "cannot read board file");
  return parse_board(text.str(), path);
}

}  // namespace pinball::table
