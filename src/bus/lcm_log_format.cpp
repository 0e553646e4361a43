#include "pinball/bus/lcm_log_format.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <array>
#include <filesystem>
#include <fstream>
#include <system_error>
#include <stdexcept>

namespace pinball::bus {
namespace {

void put_be(std::string& out, std::uint64_t v, int bytes) {
  for (int i = bytes - 1; i >= 0; --i) out.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
}

std::uint64_t get_be(const unsigned char* p, int bytes) {
  std::uint64_t v = 0;
  for (int i = 0; i < bytes; ++i) v = (v << 8) | p[i];
  return v;
}

std::string hex32(std::uint32_t v) {
  char s[16];
  std::snprintf(s, sizeof s, "0x%08X", v);
  return s;
}

// What is wrong with the event whose header `h` starts at `offset` of a file of `size` bytes; "" when nothing.
std::string event_problem(const LcmEventHeader& h, std::uint64_t offset, std::uint64_t size) {
  if (h.sync != kLcmLogSync) return "no event starts here (sync word " + hex32(h.sync) + ", not " + hex32(kLcmLogSync) + ")";
  if (h.channel_bytes <= 0 || h.channel_bytes > kLcmMaxChannelBytes) {
    return "bad channel length " + std::to_string(h.channel_bytes) + " (1.." + std::to_string(kLcmMaxChannelBytes) + ")";
  }
  if (h.data_bytes < 0) return "bad data length " + std::to_string(h.data_bytes);
  const std::uint64_t end = offset + kLcmEventHeaderBytes + static_cast<std::uint64_t>(h.channel_bytes) +
                            static_cast<std::uint64_t>(h.data_bytes);
  if (end > size) {
    return "truncated event: channel length " + std::to_string(h.channel_bytes) + " and data length " +
           std::to_string(h.data_bytes) + " need " + std::to_string(end - offset) + " bytes, the file has " +
           std::to_string(size - offset) + " left";
  }
  return "";
}

}  // namespace

void append_lcm_event(std::string& out, std::int64_t event_number, std::int64_t utime, std::string_view channel,
                      const void* data, std::size_t data_bytes) {
  put_be(out, kLcmLogSync, 4);
  put_be(out, static_cast<std::uint64_t>(event_number), 8);
  put_be(out, static_cast<std::uint64_t>(utime), 8);
  put_be(out, static_cast<std::uint32_t>(channel.size()), 4);
  put_be(out, static_cast<std::uint32_t>(data_bytes), 4);
  out.append(channel);
  out.append(static_cast<const char*>(data), data_bytes);
}

LcmEventHeader read_lcm_event_header(const unsigned char* p) {
  LcmEventHeader h;
  h.sync = static_cast<std::uint32_t>(get_be(p, 4));
  h.event_number = static_cast<std::int64_t>(get_be(p + 4, 8));
  h.utime = static_cast<std::int64_t>(get_be(p + 12, 8));
  h.channel_bytes = static_cast<std::int32_t>(static_cast<std::uint32_t>(get_be(p + 20, 4)));
  h.data_bytes = static_cast<std::int32_t>(static_cast<std::uint32_t>(get_be(p + 24, 4)));
  return h;
}

LcmLogCheck check_lcm_log(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw std::runtime_error(path + ": cannot read the LCM log: " + std::strerror(errno));
  const auto size = static_cast<std::uint64_t>(in.tellg());
  LcmLogCheck c;
  std::uint64_t offset = 0;
  unsigned char buf[kLcmEventHeaderBytes];
  while (offset < size) {
    c.offset = offset;
    const std::uint64_t left = size - offset;
    if (left < kLcmEventHeaderBytes) {
      c.ok = false;
      c.problem = "truncated event header (" + std::to_string(left) + " of " +
                  std::to_string(kLcmEventHeaderBytes) + " bytes)";
      return c;
    }
    in.seekg(static_cast<std::streamoff>(offset));
    in.read(reinterpret_cast<char*>(buf), sizeof buf);
    if (!in) throw std::runtime_error(path + ": cannot read the LCM log at byte " + std::to_string(offset));
    const LcmEventHeader h = read_lcm_event_header(buf);
    c.problem = event_problem(h, offset, size);
    if (!c.problem.empty()) {
      c.ok = false;
      return c;
    }
    offset += kLcmEventHeaderBytes + static_cast<std::uint64_t>(h.channel_bytes) + static_cast<std::uint64_t>(h.data_bytes);
    ++c.events;
  }
  c.offset = offset;
  return c;
}

void require_lcm_log(const std::string& path) {
  // A log is read more than once (checked here, then played): a pipe would be emptied by the check, and
  // one with no writer had held the reader for ever.
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(path, ec);
  if (!ec && std::filesystem::exists(status) && !std::filesystem::is_regular_file(status)) {
    throw std::runtime_error(path + ": is " +
                             (std::filesystem::is_fifo(status) ? "a pipe" : std::string("not a regular file")) +
                             ": an LCM log is read twice (checked, then played); give the file itself");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot read the LCM log");
  std::array<unsigned char, 4> word{};
  in.read(reinterpret_cast<char*>(word.data()), static_cast<std::streamsize>(word.size()));
  if (in.gcount() == 0) throw std::runtime_error(path + ": is empty (0 bytes), not an LCM log");
  if (in.gcount() < 4 || static_cast<std::uint32_t>(get_be(word.data(), 4)) != kLcmLogSync) {
    throw std::runtime_error(path + ": not an LCM log (no LCM event header at byte 0)");
  }
  const LcmLogCheck c = check_lcm_log(path);
  if (!c.ok) {
    throw std::runtime_error(path + ": damaged LCM log at byte " + std::to_string(c.offset) + ": " + c.problem +
                             " (" + std::to_string(c.events) + " whole events before it)");
  }
}

std::vector<LcmLogEvent> read_lcm_log(const std::string& path) {
  require_lcm_log(path);
  std::ifstream in(path, std::ios::binary);
  std::vector<LcmLogEvent> events;
  unsigned char buf[kLcmEventHeaderBytes];
  while (in.read(reinterpret_cast<char*>(buf), sizeof buf)) {
    const LcmEventHeader h = read_lcm_event_header(buf);
    LcmLogEvent e;
    e.utime = h.utime;
    e.channel.resize(static_cast<std::size_t>(h.channel_bytes));
    e.data.resize(static_cast<std::size_t>(h.data_bytes));
    in.read(e.channel.data(), h.channel_bytes);
    in.read(reinterpret_cast<char*>(e.data.data()), h.data_bytes);
    if (!in) throw std::runtime_error(path + ": cannot read the LCM log (it changed while being read)");
    events.push_back(std::move(e));
  }
  return events;
}

}  // namespace pinball::bus
