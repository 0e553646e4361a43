#pragma once
// An output written under a temporary name beside its path and renamed over
// it once whole, for files that are streamed as a run goes (a trace, a
// video): a run that fails, or is stopped by SIGINT, SIGTERM or SIGHUP,
// leaves the file that was there as it was and no partial one. A path that
// names a device or a pipe is written in place: its reader, not a file, is
// what there is to protect.

#include <string>

namespace pinball {

class StagedFile {
 public:
  /// Picks where to write `path` ("" stages nothing): a temporary beside it
  /// that keeps its extension ("t.csv" → "t.partial<pid>.csv", which
  /// OpenCV's writers pick their container by), or `path` itself for a
  /// device or a pipe. Creates nothing.
  explicit StagedFile(std::string path);
  /// Removes the temporary unless commit() renamed it.
  ~StagedFile();
  StagedFile(const StagedFile&) = delete;
  StagedFile& operator=(const StagedFile&) = delete;

  /// Where the writer writes.
  const std::string& writing_path() const { return writing_; }
  /// The file it becomes.
  const std::string& path() const { return path_; }

  /// Renames the temporary over path(); throws std::runtime_error "PATH:
  /// cannot write (why)" and removes the temporary when it cannot.
  void commit();

 private:
  std::string path_;
  std::string writing_;
  bool staged_ = false;  // writing_ is a temporary of ours
};

}  // namespace pinball
