#pragma once
// One writer per recording: two pinballd runs given the same LCM or CAN log
// interleaved their bytes into a damaged file, and both reported a whole
// recording. A WriterLock holds an exclusive flock(2) on the file for its
// lifetime; a second process asking for the same file is refused at once.
// Only regular files (or a file not yet there, created empty) are locked: a
// pipe or a device has its reader, not a file, to protect. The same lock on
// a lock file of its own keeps a second host off one driver board.

#include <string>

namespace pinball {

class WriterLock {
 public:
  /// Locks `path` ("" locks nothing). Throws std::runtime_error "PATH is
  /// being written by another process ..." when another holds it (or
  /// `held_elsewhere`, when given, in its place), or naming the file when it
  /// cannot be opened or locked.
  explicit WriterLock(const std::string& path, const std::string& held_elsewhere = {});
  ~WriterLock();
  WriterLock(const WriterLock&) = delete;
  WriterLock& operator=(const WriterLock&) = delete;
  WriterLock(WriterLock&& other) noexcept;
  WriterLock& operator=(WriterLock&& other) noexcept;

 private:
  int fd_ = -1;
};

}  // namespace pinball
