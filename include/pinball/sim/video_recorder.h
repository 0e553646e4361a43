#pragma once
// Writes rendered frames to an AVI with OpenCV's MJPG encoder.

#include <string>

#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

#include "pinball/core/staged_file.h"

namespace pinball::sim {

/// Throws std::runtime_error "PATH: an MJPG AVI is written; give the file
/// name an .avi extension" unless `path` ends in .avi (any case): OpenCV's
/// MJPEG writer opens nothing else.
void check_avi_name(const std::string& path);

/// Frames an AVI's index says it holds, as OpenCV's MJPEG reader opens it;
/// -1 when it cannot be opened as a video.
int avi_frame_count(const std::string& path);

/// An open AVI file receiving frames of one fixed size. It is written under
/// a temporary name beside `path` (core/staged_file.h) and put in place by
/// close(): a run that fails, or is stopped by a signal, leaves the file that
/// was there as it was.
class VideoRecorder {
 public:
  /// Opens `path` for frames of `frame_size` at `fps`. Throws
  /// std::runtime_error naming the path when the file cannot be opened.
  VideoRecorder(const std::string& path, double fps, cv::Size frame_size);
  VideoRecorder(const VideoRecorder&) = delete;             ///< one writer, one owner
  VideoRecorder& operator=(const VideoRecorder&) = delete;

  /// Appends a frame; it must be 8-bit BGR of the size given at open
  /// (throws std::invalid_argument otherwise).
  void write(const cv::Mat& frame_bgr);

  /// Frames written so far.
  int frames_written() const { return frames_; }

  /// Finishes the file and reads its index back: throws std::runtime_error
  /// naming the path when it does not hold every frame written (OpenCV's
  /// writer reports no write error: a full disk left a cut file and exit 0).
  /// The file is not in place yet: commit() puts it there, so that several
  /// outputs of one run are all checked before any replaces its old file.
  void finish();
  /// Renames the finished file over `path` (throws naming it when it cannot).
  void commit();
  /// finish() and commit(). The destructor of a recorder not committed
  /// removes what it wrote.
  void close() {
    finish();
    commit();
  }

 private:
  StagedFile file_;
  std::string path_;
  cv::Size size_;
  cv::VideoWriter writer_;
  int frames_ = 0;
};

}  // namespace pinball::sim
