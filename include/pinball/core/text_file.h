#pragma once
// The project's one way to read a whole text file (configuration, calibration,
// overlay, randomization): its bytes, or an error naming the file; and to
// write one whole (controller, overlay, calibration, shot values): a kill,
// a full disk or a failed write never leaves half a file, nor harms the old one.

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <string>
#include <string_view>
#include <system_error>

namespace pinball {

/// `text` without a UTF-8 byte-order mark at its start, which some editors
/// write first: no reader should take it for part of a keyword or a header.
inline std::string_view without_utf8_bom(std::string_view text) {
  return text.starts_with("\xEF\xBB\xBF") ? text.substr(3) : text;
}

/// Why `path` is no file to read whole, or "" when it may be tried: "is a
/// folder, not a file" (a folder opens, then fails its first read with a
/// library message that names nothing) or "is a device, not a file"
/// (/dev/zero would be read until memory runs out).
inline std::string input_file_problem(const std::string& path) {
  std::error_code ec;
  const std::filesystem::file_status st = std::filesystem::status(path, ec);
  if (ec) return "";
  if (std::filesystem::is_directory(st)) return "is a folder, not a file";
  if (std::filesystem::is_character_file(st) || std::filesystem::is_block_file(st)) return "is a device, not a file";
  return "";
}

/// Whether two paths name one file (the same path, a link or a hard link); false when either is missing.
inline bool same_file(const std::string& a, const std::string& b) {
  std::error_code ec;
  return std::filesystem::equivalent(a, b, ec) && !ec;
}

/// The file a write to `path` would reach: absolute, without . and .., a
/// symbolic link followed even when its target is not made yet (a write
/// through it creates the target).
inline std::filesystem::path write_target(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::path p = fs::absolute(path, ec);
  for (int hops = 0; hops < 40 && fs::is_symlink(fs::symlink_status(p, ec)); ++hops) {
    const fs::path to = fs::read_symlink(p, ec);
    if (ec) break;
    p = to.is_absolute() ? to : p.parent_path() / to;
  }
  const fs::path canonical = fs::weakly_canonical(p, ec);
  return ec ? p.lexically_normal() : canonical;
}

/// Whether writing `a` would write `b` (or read it): one file now (a link or
/// a hard link, same_file), or, for files not made yet, one write_target.
inline bool same_written_file(const std::string& a, const std::string& b) {
  return !a.empty() && !b.empty() && (same_file(a, b) || write_target(a) == write_target(b));
}

/// Whether two files hold the same bytes (a copy); false when either cannot be read.
inline bool same_contents(const std::string& a, const std::string& b) {
  std::error_code ec_a, ec_b;
  const auto size_a = std::filesystem::file_size(a, ec_a);
  const auto size_b = std::filesystem::file_size(b, ec_b);
  if (ec_a || ec_b || size_a != size_b) return false;
  std::ifstream in_a(a, std::ios::binary), in_b(b, std::ios::binary);
  if (!in_a || !in_b) return false;
  return std::equal(std::istreambuf_iterator<char>(in_a), std::istreambuf_iterator<char>(),
                    std::istreambuf_iterator<char>(in_b), std::istreambuf_iterator<char>());
}

/// The whole file at `path`. Throws std::runtime_error "path: cannot open",
/// "path: " + input_file_problem(path), or "path: cannot read".
inline std::string read_text_file(const std::string& path) {
  if (const std::string problem = input_file_problem(path); !problem.empty()) {
    throw std::runtime_error(path + ": " + problem);
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::ostringstream s;
  s << in.rdbuf();
  if (in.bad()) throw std::runtime_error(path + ": cannot read");
  return s.str();
}

/// Writes `bytes` to a temporary beside `path` and returns its name, for a
/// rename over `path` once whole (write_text_file, or several files renamed
/// together). Throws std::runtime_error "path: cannot write (why)", leaving
/// none; and "path: is not a regular file ..." when something other than a
/// file is there (a device such as /dev/null, a pipe): the rename would
/// replace it with a file.
inline std::string write_temporary_beside(const std::string& path, const std::string& bytes) {
  std::error_code ec;
  const std::filesystem::file_status there = std::filesystem::status(path, ec);
  if (!ec && std::filesystem::exists(there) && !std::filesystem::is_regular_file(there)) {
    throw std::runtime_error(path + ": is not a regular file (a device, a pipe or a folder); it would be replaced by "
                                    "the file written, so it is refused");
  }
  const std::string tmp = path + ".tmp" + std::to_string(::getpid());
  std::ofstream out(tmp, std::ios::binary);
  const int open_errno = out.is_open() ? 0 : errno;
  out << bytes;
  out.close();
  if (!out) {
    std::filesystem::remove(tmp, ec);
    throw std::runtime_error(path + ": cannot write" +
                             (open_errno != 0 ? " (" + std::string(std::strerror(open_errno)) + ")" : std::string()));
  }
  return tmp;
}

/// Writes `bytes` to `path` whole: to a temporary beside it, renamed over it
/// once written and closed. Throws std::runtime_error "path: cannot write"
/// (the old file, if any, is as it was).
inline void write_text_file(const std::string& path, const std::string& bytes) {
  const std::string tmp = write_temporary_beside(path, bytes);
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    const std::string why = ec.message();
    std::filesystem::remove(tmp, ec);
    throw std::runtime_error(path + ": cannot write (" + why + ")");
  }
}

}  // namespace pinball
