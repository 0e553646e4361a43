#include "pinball/sim/video_recorder.h"

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <system_error>

#include "pinball/core/file_name.h"

namespace pinball::sim {
namespace {

// Whether an AVI's RIFF structure is whole: its header's size within the file, every chunk in it
// within that size, and an index (idx1). A writer stopped by a full disk leaves sizes of 0 or chunks
// that run past the end. Reads the chunk headers only.
bool avi_structure_whole(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  auto read_u32 = [&in](std::uint32_t& v) {
    unsigned char b[4];
    if (!in.read(reinterpret_cast<char*>(b), 4)) return false;
    v = static_cast<std::uint32_t>(b[0]) | static_cast<std::uint32_t>(b[1]) << 8 |
        static_cast<std::uint32_t>(b[2]) << 16 | static_cast<std::uint32_t>(b[3]) << 24;
    return true;
  };
  char tag[4];
  std::uint32_t riff_size = 0;
  if (!in.read(tag, 4) || std::memcmp(tag, "RIFF", 4) != 0 || !read_u32(riff_size) || !in.read(tag, 4) ||
      std::memcmp(tag, "AVI ", 4) != 0) {
    return false;
  }
  std::error_code ec;
  const std::uintmax_t file_bytes = std::filesystem::file_size(path, ec);
  const std::uintmax_t riff_end = std::uintmax_t{riff_size} + 8;
  if (ec || riff_size < 4 || riff_end > file_bytes) return false;
  bool index = false;
  for (std::uintmax_t at = 12; at < riff_end;) {
    std::uint32_t size = 0;
    in.seekg(static_cast<std::streamoff>(at));
    if (!in.read(tag, 4) || !read_u32(size)) return false;
    index = index || std::memcmp(tag, "idx1", 4) == 0;
    at += 8 + std::uintmax_t{size} + (size & 1u);
    if (at > riff_end) return false;
  }
  return index;
}

}  // namespace

void check_avi_name(const std::string& path) {
  if (lowercase_extension(path) != ".avi") {
    throw std::runtime_error(path + ": an MJPG AVI is written; give the file name an .avi extension");
  }
}

VideoRecorder::VideoRecorder(const std::string& path, double fps, cv::Size frame_size)
    : file_(path), path_(path), size_(frame_size) {
  if (!(fps > 0.0) || frame_size.width <= 0 || frame_size.height <= 0) {
    std::ostringstream msg;
    msg << "VideoRecorder: '" << path << "': needs fps > 0 and a positive frame size, got fps " << fps << " and "
        << frame_size.width << " x " << frame_size.height;
    throw std::invalid_argument(msg.str());
  }
  check_avi_name(path_);
  try {
    // OpenCV's own MJPEG writer: always built in, and unlike FFmpeg's it keeps
    // odd frame sizes (render_size often gives one) instead of cropping them.
    writer_.open(file_.writing_path(), cv::CAP_OPENCV_MJPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), fps, size_,
                 /*isColor=*/true);
  } catch (const cv::Exception& e) {
    throw std::runtime_error(path_ + ": cannot open the video for writing: " + e.what());
  }
  if (!writer_.isOpened()) throw std::runtime_error(path_ + ": cannot open the video for writing");
}

void VideoRecorder::write(const cv::Mat& frame_bgr) {
  if (frame_bgr.size() != size_ || frame_bgr.type() != CV_8UC3) {
    std::ostringstream msg;
    msg << "VideoRecorder: '" << path_ << "': frame must be 8-bit BGR (CV_8UC3) of " << size_.width << " x "
        << size_.height << ", got type " << frame_bgr.type() << " of " << frame_bgr.cols << " x " << frame_bgr.rows;
    throw std::invalid_argument(msg.str());
  }
  if (!writer_.isOpened()) throw std::logic_error("VideoRecorder: '" + path_ + "' is closed");
  writer_.write(frame_bgr);
  ++frames_;
}

void VideoRecorder::finish() {
  if (!writer_.isOpened()) return;
  writer_.release();
  const int readable = avi_frame_count(file_.writing_path());
  // An AVI of no frames does not open as a video: nothing to check.
  if (readable != frames_ && !(frames_ == 0 && readable <= 0)) {
    throw std::runtime_error(path_ + ": the video was not written whole: " +
                             (readable < 0 ? std::string("it does not open as a video")
                                           : std::to_string(readable) + " of its " + std::to_string(frames_) +
                                                 " frames are in its index") +
                             " (a full disk?)");
  }
}

void VideoRecorder::commit() {
  if (writer_.isOpened()) throw std::logic_error("VideoRecorder: '" + path_ + "': commit before finish");
  file_.commit();
}

int avi_frame_count(const std::string& path) {
  // A cut file is known by its chunks: OpenCV's reader would print "Unexpected element" on stderr (an
  // fprintf, which no log level silences) before it failed.
  if (!avi_structure_whole(path)) return -1;
  cv::VideoCapture reader;
  try {
    if (!reader.open(path, cv::CAP_OPENCV_MJPEG)) return -1;
  } catch (const cv::Exception&) {
    return -1;
  }
  return static_cast<int>(reader.get(cv::CAP_PROP_FRAME_COUNT));
}

// No destructor of our own: cv::VideoWriter's destructor releases the file
// before file_'s removes it (members go in reverse order).

}  // namespace pinball::sim
