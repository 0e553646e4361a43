#include "pinball/track/observation_io.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string_view>

#include "pinball/core/format.h"
#include "pinball/core/read_archive.h"
#include "pinball/core/statistics.h"
#include "pinball/core/text_file.h"

namespace pinball::track {
namespace {

[[noreturn]] void fail(const std::string& path, int line, const std::string& what) {
  std::ostringstream msg;
  msg << path << ":" << line << ": " << what;
  throw std::runtime_error(msg.str());
}

std::vector<std::string_view> split(std::string_view s) {
  std::vector<std::string_view> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = s.find(',', start);
    std::string_view field = s.substr(start, comma == std::string_view::npos ? s.npos : comma - start);
    while (!field.empty() && (field.front() == ' ' || field.front() == '\t')) field.remove_prefix(1);
    while (!field.empty() && (field.back() == ' ' || field.back() == '\t' || field.back() == '\r')) field.remove_suffix(1);
    out.push_back(field);
    if (comma == std::string_view::npos) return out;
    start = comma + 1;
  }
}

double number(const std::string& path, int line, std::string_view field, const char* name) {
  double v = 0.0;
  const auto [end, ec] = std::from_chars(field.data(), field.data() + field.size(), v);
  if (ec != std::errc() || end != field.data() + field.size() || !std::isfinite(v)) {
    fail(path, line, std::string("column '") + name + "' is not a finite number: '" + std::string(field) + "'");
  }
  return v;
}

}  // namespace

std::vector<ObservationRow> read_observations_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot open observation file");
  std::string text;
  int line_no = 0;
  bool has_contacts = false;
  std::size_t columns = 3;
  bool sim_trace = false;
  std::vector<ObservationRow> rows;
  bool header_read = false;
  while (std::getline(in, text)) {
    ++line_no;
    if (!text.empty() && text.back() == '\r') text.pop_back();
    if (line_no == 1) text = std::string(without_utf8_bom(text));
    // A comment ('# camera 2, 200 fps', '# ball lost here'), anywhere: as in a marker layout.
    if (text.starts_with("#")) continue;
    if (!header_read) {
      header_read = true;
      const auto header = split(text);
      const bool txy = header.size() >= 3 && header[0] == "t" && header[1] == "x" && header[2] == "y";
      has_contacts = txy && header.size() == 5 && header[3] == "left_contact" && header[4] == "right_contact";
      // `pinball sim --trace`: the true state each step; its velocity and events are not observed.
      sim_trace =
          txy && header.size() == 6 && header[3] == "vx" && header[4] == "vy" && header[5] == "event";
      if (!(txy && header.size() == 3) && !has_contacts && !sim_trace) {
        fail(path, line_no,
             "header must be 't,x,y', 't,x,y,left_contact,right_contact' or sim --trace's 't,x,y,vx,vy,event', "
             "got " + quote_value(text));
      }
      columns = header.size();
      continue;
    }
    if (text.find_first_not_of(" \t") == std::string::npos) continue;  // blank line
    const auto f = split(text);
    if (f.size() != columns) {
      fail(path, line_no, "expected " + std::to_string(columns) + " columns, got " + std::to_string(f.size()));
    }
    ObservationRow row;
    row.observation.t_s = number(path, line_no, f[0], "t");
    row.observation.p_board = {number(path, line_no, f[1], "x"), number(path, line_no, f[2], "y")};
    if (has_contacts) {
      for (int k = 0; k < 2; ++k) {
        if (f[3 + k] != "0" && f[3 + k] != "1") {
          fail(path, line_no, std::string("column '") + (k == 0 ? "left_contact" : "right_contact") +
                                  "' must be 0 or 1, got " + quote_value(std::string(f[3 + k])));
        }
      }
      row.contacts = {f[3] == "1", f[4] == "1"};
    }
    // In a trace the ball lost and the next one served share their step's time: the served one stands.
    if (sim_trace && !rows.empty() && row.observation.t_s == rows.back().observation.t_s) {
      rows.back() = row;
      continue;
    }
    if (!rows.empty() && !(row.observation.t_s > rows.back().observation.t_s)) {
      fail(path, line_no, "time must increase from row to row");
    }
    rows.push_back(row);
  }
  if (!header_read) fail(path, std::max(line_no, 1), "empty file: expected the header 't,x,y'");
  if (rows.empty()) fail(path, line_no, "no observation after the header");
  return rows;
}

void check_observations_on_board(const std::vector<ObservationRow>& rows, const table::Board& board,
                                 const std::string& path) {
  const auto off = static_cast<std::size_t>(std::count_if(rows.begin(), rows.end(), [&](const ObservationRow& r) {
    return !table::near_playfield(board, r.observation.p_board);
  }));
  if (static_cast<double>(off) > table::kMostOffPlayfield * static_cast<double>(rows.size())) {
    throw std::runtime_error(path + ": " + std::to_string(off) + " of its " + std::to_string(rows.size()) +
                             " observations lie " + table::off_playfield_text(board) +
                             " (positions are in metres, board frame: a file in mm, or of another table?)");
  }
  // Times in ms or ns pass every other check (they increase) and give a tracker fits of nonsense,
  // or a gravity a million times too small: a camera gives its frames a few ms apart.
  if (rows.size() < 2) return;
  std::vector<double> spacing_s;
  spacing_s.reserve(rows.size() - 1);
  for (std::size_t i = 1; i < rows.size(); ++i) {
    spacing_s.push_back(rows[i].observation.t_s - rows[i - 1].observation.t_s);
  }
  const double typical_s = median(std::move(spacing_s));
  if (typical_s > kMostFramePeriod_s) {
    throw std::runtime_error(path + ": its observations are " + format_number(typical_s, 3) +
                             " s apart (the median): a camera's frames are a few ms apart, at most " +
                             format_number(kMostFramePeriod_s) + " s (times are in seconds: a file in ms or ns?)");
  }
}

}  // namespace pinball::track
