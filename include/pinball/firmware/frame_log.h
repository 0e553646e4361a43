#pragma once
// A frame log in candump's log format, one frame a line:
//   (1700000000.123456) can0 123#DEADBEEF
// so that lab engineers read it with their eyes and replay it with
// `canplayer -I FILE` (can-utils).

#include <cstdio>
#include <mutex>
#include <optional>
#include <string>
#include <string_view>

#include "pinball/firmware/can_frame.h"

namespace pinball::firmware {

/// One parsed log line.
struct LogEntry {
  double time_s = 0.0;    ///< timestamp (s since the epoch, as candump writes it)
  std::string interface;  ///< interface name
  CanFrame frame;         ///< the frame (rx_time_ns set from time_s)
};

/// Formats one line (without the newline).
std::string format_log_line(const CanFrame& frame, double time_s, std::string_view interface);

/// Parses one line; std::nullopt when it is not a candump log line.
std::optional<LogEntry> parse_log_line(std::string_view line);

/// Appends frames to a file; safe to call from several threads.
class FrameLog {
 public:
  /// Opens (truncates) `path`; throws std::runtime_error naming the file when it cannot.
  FrameLog(const std::string& path, std::string interface = "can0");
  ~FrameLog();
  FrameLog(const FrameLog&) = delete;
  FrameLog& operator=(const FrameLog&) = delete;

  /// Writes one frame stamped `time_s` (s since the epoch).
  void record(const CanFrame& frame, double time_s);
  /// Writes one frame stamped with its rx_time_ns, or the wall clock when 0.
  void record(const CanFrame& frame);
  /// Flushes the file.
  void flush();
  /// Lines written.
  std::uint64_t lines() const;

 private:
  mutable std::mutex mutex_;
  std::FILE* file_ = nullptr;
  std::string interface_;
  std::uint64_t lines_ = 0;
};

}  // namespace pinball::firmware
