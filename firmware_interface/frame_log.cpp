#include "pinball/firmware/frame_log.h"

#include <linux/can.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <stdexcept>

namespace pinball::firmware {
namespace {

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

}  // namespace

std::string format_log_line(const CanFrame& frame, double time_s, std::string_view interface) {
  const auto whole = static_cast<long long>(time_s);
  long long micros = static_cast<long long>((time_s - static_cast<double>(whole)) * 1e6 + 0.5);
  long long secs = whole;
  if (micros >= 1'000'000) {
    micros -= 1'000'000;
    ++secs;
  }
  char stamp[40];
  std::snprintf(stamp, sizeof stamp, "(%lld.%06lld) ", secs, micros);
  std::string line = stamp;
  line.append(interface);
  line.push_back(' ');
  line += to_candump(frame);
  return line;
}

std::optional<LogEntry> parse_log_line(std::string_view line) {
  // (SECONDS.MICROS) IFACE ID#HEX
  if (line.size() < 4 || line.front() != '(') return std::nullopt;
  const std::size_t close = line.find(") ");
  if (close == std::string_view::npos) return std::nullopt;
  LogEntry e;
  const std::string stamp(line.substr(1, close - 1));
  char* end = nullptr;
  e.time_s = std::strtod(stamp.c_str(), &end);
  if (end == stamp.c_str() || *end != '\0') return std::nullopt;
  const std::string_view rest = line.substr(close + 2);
  const std::size_t space = rest.find(' ');
  if (space == std::string_view::npos || space == 0) return std::nullopt;
  e.interface = std::string(rest.substr(0, space));
  std::string_view body = rest.substr(space + 1);
  while (!body.empty() && (body.back() == '\n' || body.back() == '\r' || body.back() == ' ')) body.remove_suffix(1);
  const std::size_t hash = body.find('#');
  if (hash == std::string_view::npos || (hash != 3 && hash != 8)) return std::nullopt;
  std::uint32_t id = 0;
  for (std::size_t i = 0; i < hash; ++i) {
    const int d = hex_digit(body[i]);
    if (d < 0) return std::nullopt;
    id = (id << 4) | static_cast<std::uint32_t>(d);
  }
  const std::string_view hex = body.substr(hash + 1);
  if (hex.size() % 2 != 0 || hex.size() > 16) return std::nullopt;
  if (hash == 8) {
    if ((id & CAN_ERR_FLAG) == 0) return std::nullopt;  // extended data frames are not ours
    e.frame.error = true;
    e.frame.id = id & CAN_ERR_MASK;
  } else {
    e.frame.id = id;
  }
  e.frame.len = static_cast<std::uint8_t>(hex.size() / 2);
  for (std::size_t i = 0; i < e.frame.len; ++i) {
    const int hi = hex_digit(hex[2 * i]);
    const int lo = hex_digit(hex[2 * i + 1]);
    if (hi < 0 || lo < 0) return std::nullopt;
    e.frame.data[i] = static_cast<std::uint8_t>((hi << 4) | lo);
  }
  e.frame.rx_time_ns = static_cast<std::int64_t>(e.time_s * 1e9);
  return e;
}

FrameLog::FrameLog(const std::string& path, std::string interface) : interface_(std::move(interface)) {
  file_ = std::fopen(path.c_str(), "w");
  if (file_ == nullptr) throw std::runtime_error("FrameLog: cannot open " + path + ": " + std::strerror(errno));
}

FrameLog::~FrameLog() {
  if (file_ != nullptr) std::fclose(file_);
}

void FrameLog::record(const CanFrame& frame, double time_s) {
  const std::string line = format_log_line(frame, time_s, interface_);
  std::lock_guard<std::mutex> lock(mutex_);
  std::fputs(line.c_str(), file_);
  std::fputc('\n', file_);
  ++lines_;
}

void FrameLog::record(const CanFrame& frame) {
  double t = static_cast<double>(frame.rx_time_ns) * 1e-9;
  if (frame.rx_time_ns == 0) {
    t = std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
  }
  record(frame, t);
}

void FrameLog::flush() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::fflush(file_);
}

std::uint64_t FrameLog::lines() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return lines_;
}

}  // namespace pinball::firmware
