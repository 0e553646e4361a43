#pragma once
// Where a recording goes (a file, a pipe, a device), opened so that writing
// to it never holds its thread for good and never kills the process: the
// descriptor is non-blocking, a full pipe is waited on in short polls that
// the caller may cut, and a pipe whose reader left is an error (EPIPE), not
// SIGPIPE. The CAN log's and the LCM log's writer threads write through it;
// they count what a failed write cost them.

#include <cstddef>
#include <functional>
#include <string>
#include <string_view>

namespace pinball {

/// What one FileSink::write did.
struct SinkWrite {
  std::size_t bytes = 0;  ///< bytes the sink took (a prefix of what was given)
  int error = 0;          ///< errno when it stopped short; ETIMEDOUT when the caller gave up waiting
};

/// A file opened for writing by one thread.
class FileSink {
 public:
  /// Opens `path` (truncated, or appended to with `append`); throws
  /// std::runtime_error naming the file when it cannot, and for a named pipe
  /// that no reader has open yet (start the reader first).
  explicit FileSink(const std::string& path, bool append = false);
  /// Closes (errors ignored: call close() to see them).
  ~FileSink();
  FileSink(const FileSink&) = delete;
  FileSink& operator=(const FileSink&) = delete;

  /// Writes `size` bytes. While the sink is full (a pipe nobody reads), asks
  /// `give_up()` (may be empty: wait on) and waits in polls of at most
  /// `poll_s` between the questions. Stops at the first error; a sink that will never take
  /// bytes again (EPIPE, EBADF) is gone() from then on.
  SinkWrite write(const char* data, std::size_t size, const std::function<bool()>& give_up = {},
                  double poll_s = 0.05);
  /// Closes the file; the errno of a failed close (some file systems report a
  /// failed write only here), 0 otherwise. Idempotent.
  int close();
  /// True once the sink cannot take anything again (its reader left).
  bool gone() const { return gone_; }
  /// The path it was opened with.
  const std::string& path() const { return path_; }

 private:
  bool wait_writable(const std::function<bool()>& give_up, double poll_s) const;

  std::string path_;
  int fd_ = -1;
  bool gone_ = false;
};

/// Writes `text` to `fd` (stderr) only while it takes it at once: before each
/// piece of at most PIPE_BUF bytes, a poll without waiting; what does not go
/// is dropped and the answer is false. For messages on a descriptor the
/// process does not own and nobody may be draining (a stderr pipe whose
/// reader sleeps): stdio would block there, and go on blocking after a
/// signal, since it retries a partial write.
bool write_if_ready(int fd, std::string_view text);

/// A program's exit status once its standard output is flushed: `code`, or 1
/// with a line on stderr naming `program` when the output did not all get
/// there (a full disk, a reader that left): a script must not take a missing
/// or cut report for a success.
int exit_status_after_stdout(const char* program, int code);

/// Blocks SIGPIPE in the calling thread, so that a write there to a pipe
/// without a reader returns EPIPE even where the process has not ignored
/// the signal (FileSink::write takes back the pending signal). For the
/// threads that own a FileSink.
void block_sigpipe_in_this_thread();

}  // namespace pinball
