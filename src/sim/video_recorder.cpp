#include "pinball/sim/video_recorder.h"

#include <sstream>
#include <stdexcept>

#include "pinball/core/file_name.h"

namespace pinball::sim {

void check_avi_name(const std::string& path) {
  if (lowercase_extension(path) != ".avi") {
    throw std::runtime_error(path + ": an MJPG AVI is written; give the file name an .avi extension");
  }
}

VideoRecorder::VideoRecorder(const std::string& path, double fps, cv::Size frame_size)
    : path_(path), size_(frame_size) {
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
    writer_.open(path_, cv::CAP_OPENCV_MJPEG, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), fps, size_,
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

void VideoRecorder::close() {
  if (!writer_.isOpened()) return;
  writer_.release();
  const int readable = avi_frame_count(path_);
  // An AVI of no frames does not open as a video: nothing to check.
  if (readable != frames_ && !(frames_ == 0 && readable <= 0)) {
    throw std::runtime_error(path_ + ": the video was not written whole: " +
                             (readable < 0 ? std::string("it does not open as a video")
                                           : std::to_string(readable) + " of its " + std::to_string(frames_) +
                                                 " frames are in its index") +
                             " (a full disk?)");
  }
}

int avi_frame_count(const std::string& path) {
  cv::VideoCapture reader;
  try {
    if (!reader.open(path, cv::CAP_OPENCV_MJPEG)) return -1;
  } catch (const cv::Exception&) {
    return -1;
  }
  return static_cast<int>(reader.get(cv::CAP_PROP_FRAME_COUNT));
}

// No destructor of our own: cv::VideoWriter's destructor releases the file,
// which is all close() does.

}  // namespace pinball::sim
