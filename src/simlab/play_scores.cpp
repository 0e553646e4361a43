#include "pinball/simlab/play_scores.h"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>
#include <string_view>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include "pinball/core/format.h"
#include "pinball/core/read_archive.h"
#include "pinball/core/running_stats.h"
#include "pinball/core/utc_date.h"

namespace pinball::simlab {
namespace {

constexpr std::size_t kColumns = 8;

[[noreturn]] void fail_at(const std::string& path, int line, const std::string& what) {
  throw std::runtime_error(path + ":" + std::to_string(line) + ": " + what);
}

std::string errno_text() { return std::strerror(errno); }

std::vector<std::string> fields_of(const std::string& line) {
  std::vector<std::string> out(1);
  for (const char c : line) {
    if (c == ',') {
      out.emplace_back();
    } else {
      out.back() += c;
    }
  }
  return out;
}

double finite_number(const std::string& path, int line, const std::string& text, const char* column) {
  double v = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size() || !std::isfinite(v) || v < 0.0) {
    fail_at(path, line, std::string("column '") + column + "' must be a number >= 0, got " + quote_value(text));
  }
  return v;
}

std::string csv_line(const PlayRow& r) {
  return r.player + ',' + r.date + ',' + r.board + ',' + r.world + ',' + std::to_string(r.ball) + ',' +
         format_exact(r.score) + ',' + format_exact(r.duration_s) + ',' + (r.cut ? "1" : "0") + '\n';
}

// The first line of an existing file, or "" for an empty one.
std::string first_line(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  if (!line.empty() && line.back() == '\r') line.pop_back();
  return line;
}

void check_text_field(const std::string& value, const char* what) {
  if (value.empty()) throw std::invalid_argument(std::string(what) + " must not be empty");
  for (const char c : value) {
    if (c == ',' || c == '"' || static_cast<unsigned char>(c) < 0x20) {
      throw std::invalid_argument(std::string(what) + " '" + value +
                                  "' must not contain a comma, a quote or a control character");
    }
  }
}

}  // namespace

void check_play_row(const PlayRow& row) {
  check_text_field(row.player, "player name");
  check_text_field(row.board, "board name");
  check_text_field(row.world, "world name");
}

void check_play_csv_appendable(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::exists(path, ec)) {
    if (fs::is_directory(path, ec)) throw std::runtime_error(path + ": is a folder, not a score file");
    if (!fs::is_regular_file(path, ec)) throw std::runtime_error(path + ": is not a regular file (a device, a pipe)");
    if (::access(path.c_str(), W_OK) != 0) throw std::runtime_error(path + ": cannot write the score file: " + errno_text());
    const std::string header = first_line(path);
    if (!header.empty() && header != kPlayCsvHeader) {
      throw std::runtime_error(path + ":1: not a play score file: the header must be '" + std::string(kPlayCsvHeader) +
                               "', got " + quote_value(header));
    }
    return;
  }
  fs::path folder = fs::path(path).parent_path();
  if (folder.empty()) folder = ".";
  if (!fs::is_directory(folder, ec)) throw std::runtime_error(path + ": cannot create the score file: no folder " + folder.string());
  if (::access(folder.c_str(), W_OK | X_OK) != 0) {
    throw std::runtime_error(path + ": cannot create the score file in " + folder.string() + ": " + errno_text());
  }
}

void append_play_rows(const std::string& path, const std::vector<PlayRow>& rows) {
  for (const PlayRow& r : rows) check_play_row(r);
  const int fd = ::open(path.c_str(), O_RDWR | O_APPEND | O_CREAT | O_CLOEXEC, 0644);  // read: its last byte
  if (fd < 0) throw std::runtime_error(path + ": cannot open the score file: " + errno_text());
  std::string text;
  bool ok = ::flock(fd, LOCK_EX) == 0;
  struct stat st {};
  ok = ok && ::fstat(fd, &st) == 0;
  if (ok && st.st_size == 0) text = std::string(kPlayCsvHeader) + "\n";
  // A file whose last row has no line end (an editor's save) would get the new row glued to it.
  char last = '\n';
  if (ok && st.st_size > 0) ok = ::pread(fd, &last, 1, st.st_size - 1) == 1;
  if (last != '\n') text = "\n";
  for (const PlayRow& r : rows) text += csv_line(r);
  std::size_t done = 0;
  while (ok && done < text.size()) {
    const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
    if (n < 0 && errno == EINTR) continue;
    ok = n > 0;
    if (ok) done += static_cast<std::size_t>(n);
  }
  const std::string why = ok ? "" : errno_text();
  // A failed append (a full disk) takes back what it wrote: half a row would break the file for
  // every later session and for --stats.
  const bool part_left = !ok && done > 0 && ::ftruncate(fd, st.st_size) != 0;
  const bool closed = ::close(fd) == 0;  // releases the lock
  if (!ok || !closed) {
    throw std::runtime_error(path + ": cannot append to the score file: " + (ok ? errno_text() : why) +
                             (part_left ? " (part of a row is left at its end: remove it)" : ""));
  }
}

std::vector<PlayRow> read_play_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open the score file");
  std::vector<PlayRow> rows;
  std::string text;
  int line = 0;
  while (std::getline(in, text)) {
    ++line;
    if (!text.empty() && text.back() == '\r') text.pop_back();
    if (line == 1) {
      if (text != kPlayCsvHeader) {
        fail_at(path, line, "the header must be '" + std::string(kPlayCsvHeader) + "', got " + quote_value(text));
      }
      continue;
    }
    if (text.empty()) continue;
    const std::vector<std::string> f = fields_of(text);
    if (f.size() != kColumns) {
      fail_at(path, line, "expected " + std::to_string(kColumns) + " columns, got " + std::to_string(f.size()));
    }
    PlayRow r;
    r.player = f[0];
    if (r.player.empty()) fail_at(path, line, "column 'player' is empty");
    r.date = f[1];
    if (!is_utc_iso8601(r.date)) {
      fail_at(path, line, "column 'date' must be a UTC date like 2026-12-02T13:45:21Z, got " + quote_value(r.date));
    }
    r.board = f[2];
    if (r.board.empty()) fail_at(path, line, "column 'board' is empty");
    r.world = f[3];
    if (r.world != "thesis" && r.world != "event" && r.world != "twin") {
      fail_at(path, line, "column 'world' must be thesis, event or twin, got " + quote_value(r.world));
    }
    const auto [end, ec] = std::from_chars(f[4].data(), f[4].data() + f[4].size(), r.ball);
    if (f[4].empty() || ec != std::errc() || end != f[4].data() + f[4].size() || r.ball < 1) {
      fail_at(path, line, "column 'ball' must be a whole number >= 1, got " + quote_value(f[4]));
    }
    r.score = finite_number(path, line, f[5], "score");
    r.duration_s = finite_number(path, line, f[6], "duration_s");
    if (f[7] != "0" && f[7] != "1") fail_at(path, line, "column 'cut' must be 0 or 1, got " + quote_value(f[7]));
    r.cut = f[7] == "1";
    rows.push_back(std::move(r));
  }
  if (line == 0) fail_at(path, 1, "empty file: expected the header '" + std::string(kPlayCsvHeader) + "'");
  return rows;
}

std::vector<PlayerStats> play_stats(const std::vector<PlayRow>& rows) {
  std::map<std::string, RunningStats> by_player;
  RunningStats pooled;
  for (const PlayRow& r : rows) {
    by_player[r.player].add(r.score);
    pooled.add(r.score);
  }
  auto line = [](const std::string& name, const RunningStats& s) {
    PlayerStats p;
    p.player = name;
    p.balls = s.count();
    p.mean_score = s.mean();
    p.ci95_half_width = s.ci95_half_width();  // infinite for one ball
    p.max_score = s.max();
    return p;
  };
  std::vector<PlayerStats> out;
  if (rows.empty()) return out;
  for (const auto& [name, s] : by_player) out.push_back(line(name, s));
  out.push_back(line("all", pooled));
  return out;
}

}  // namespace pinball::simlab
