#pragma once
// The LCM log format (lcm-logger, liblcm's eventlog.c), written and checked
// here: LcmBus writes file:// logs itself, because liblcm's provider ignores
// its write errors, and `pinball replay` checks a log before liblcm reads it,
// because liblcm trusts the lengths it reads (a length of 0x7fffffff crashes
// liblcm 1.3.1). Each event, integers big-endian:
//   uint32 sync 0xEDA1DA01, int64 event number, int64 timestamp (us since
//   the epoch), int32 channel length, int32 data length, channel, data.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace pinball::bus {

/// The word that starts every event.
constexpr std::uint32_t kLcmLogSync = 0xEDA1DA01u;
/// Bytes of an event header.
constexpr std::size_t kLcmEventHeaderBytes = 28;
/// The longest channel name liblcm reads back (it refuses 1000 and more).
constexpr std::int32_t kLcmMaxChannelBytes = 999;

/// One event's header.
struct LcmEventHeader {
  std::uint32_t sync = 0;         ///< kLcmLogSync in a good event
  std::int64_t event_number = 0;  ///< 0, 1, ... in the order written
  std::int64_t utime = 0;         ///< us since the epoch (pinballd: the message's utime + the run's anchor)
  std::int32_t channel_bytes = 0; ///< length of the channel name
  std::int32_t data_bytes = 0;    ///< length of the encoded message
};

/// Appends one event (header, channel, data) to `out`.
void append_lcm_event(std::string& out, std::int64_t event_number, std::int64_t utime, std::string_view channel,
                      const void* data, std::size_t data_bytes);

/// Reads the header at `p` (kLcmEventHeaderBytes bytes).
LcmEventHeader read_lcm_event_header(const unsigned char* p);

/// What a check of a whole log found.
struct LcmLogCheck {
  std::uint64_t events = 0;  ///< whole, well-formed events before the damage (all of them when ok)
  bool ok = true;            ///< every byte belongs to a whole, well-formed event
  std::uint64_t offset = 0;  ///< where the damage starts (bytes from the file's start)
  std::string problem;       ///< what is wrong there, e.g. "truncated event header (12 of 28 bytes)"
};

/// Walks every event header of the log at `path` against the file's size,
/// reading only the headers. Throws std::runtime_error naming the file when
/// it cannot be read.
LcmLogCheck check_lcm_log(const std::string& path);

/// Throws std::runtime_error naming the file unless `path` is a readable,
/// non-empty LCM log whose every event is whole and well-formed. liblcm reads
/// anything else as an empty log, stops silently at a damaged event and trusts
/// the lengths it reads, so every reader checks a log with this first.
void require_lcm_log(const std::string& path);

/// One event of a log, read into memory.
struct LcmLogEvent {
  std::int64_t utime = 0;          ///< the event's timestamp (us since the epoch, as written)
  std::string channel;             ///< channel name
  std::vector<std::uint8_t> data;  ///< the encoded message
};

/// Every event of the log at `path`, in file order, after require_lcm_log.
std::vector<LcmLogEvent> read_lcm_log(const std::string& path);

}  // namespace pinball::bus
