#include "pinball/vision/capture_source.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <opencv2/imgproc.hpp>

namespace pinball::vision {
namespace {

bool all_digits(const std::string& s) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c) != 0; });
}

double steady_now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

double v4l2_exposure_units(double exposure_s) {
  constexpr double kUnit_s = 100e-6;  // V4L2_CID_EXPOSURE_ABSOLUTE (the V4L2 camera control reference)
  return std::max(1.0, std::round(exposure_s / kUnit_s));
}

bool is_device_source(const std::string& source) { return all_digits(source) || source.rfind("/dev/", 0) == 0; }

std::string missing_camera_device(const std::string& source) {
  if (source.rfind("/dev/", 0) != 0 || std::filesystem::exists(source)) return "";
  return source + ": no such camera device";
}

CaptureSource::CaptureSource(const CaptureConfig& config) : config_(config) {
  const std::string& src = config_.source;
  if (src.empty()) throw std::runtime_error("capture: no camera device or video file given");
  is_device_ = is_device_source(src);
  if (!is_device_ && !std::filesystem::exists(src)) {
    throw std::runtime_error("capture: cannot open video file '" + src + "': no such file");
  }
  if (is_device_ && !all_digits(src) && !std::filesystem::exists(src)) {
    throw std::runtime_error("capture: cannot open camera device '" + src + "': no such device");
  }
  if (is_device_) {
    // OpenCV's V4L2 backend waits 10 s for a frame by default: a camera that hangs would hold the
    // camera thread, and pinballd's exit, that long. A lab that set its own wait keeps it.
    ::setenv("OPENCV_VIDEOIO_V4L_SELECT_TIMEOUT", "1000", 0);
  }
  bool opened = false;
  try {
    if (is_device_) {
      opened = open_device();
    } else {
      // Files: the decoders that read files, not every backend (CAP_ANY also
      // probes camera plugins, which log noise and leak in libusb).
      for (const int api : {cv::CAP_FFMPEG, cv::CAP_OPENCV_MJPEG}) {
        if (capture_.open(src, api)) {
          opened = true;
          break;
        }
      }
    }
  } catch (const cv::Exception& e) {
    throw std::runtime_error("capture: cannot open " + std::string(is_device_ ? "camera device '" : "video file '") +
                             src + "': " + e.what());
  }
  if (!opened || !capture_.isOpened()) {
    throw std::runtime_error("capture: cannot open " +
                             std::string(is_device_ ? "camera device '" + src + "' (V4L2)"
                                                    : "video file '" + src + "': not a video OpenCV can decode"));
  }
  size_ = cv::Size(static_cast<int>(capture_.get(cv::CAP_PROP_FRAME_WIDTH)),
                   static_cast<int>(capture_.get(cv::CAP_PROP_FRAME_HEIGHT)));
  fps_ = capture_.get(cv::CAP_PROP_FPS);
  if (!(fps_ > 0.0) || !std::isfinite(fps_)) fps_ = config_.fps > 0.0 ? config_.fps : 30.0;
  if (size_.width <= 0 || size_.height <= 0) {
    throw std::runtime_error("capture: '" + src + "' reports no frame size");
  }
}

bool CaptureSource::open_device() {
  const std::string& src = config_.source;
  const bool opened = all_digits(src) ? capture_.open(std::stoi(src), cv::CAP_V4L2) : capture_.open(src, cv::CAP_V4L2);
  if (!opened || !capture_.isOpened()) return false;
  if (config_.fourcc.size() == 4) {
    capture_.set(cv::CAP_PROP_FOURCC, cv::VideoWriter::fourcc(config_.fourcc[0], config_.fourcc[1],
                                                              config_.fourcc[2], config_.fourcc[3]));
  }
  if (config_.width_px > 0) capture_.set(cv::CAP_PROP_FRAME_WIDTH, config_.width_px);
  if (config_.height_px > 0) capture_.set(cv::CAP_PROP_FRAME_HEIGHT, config_.height_px);
  if (config_.fps > 0.0) capture_.set(cv::CAP_PROP_FPS, config_.fps);
  if (config_.buffers > 0) capture_.set(cv::CAP_PROP_BUFFERSIZE, config_.buffers);
  if (config_.exposure_s >= 0.0) {
    capture_.set(cv::CAP_PROP_AUTO_EXPOSURE, 1);  // V4L2: 1 = manual
    capture_.set(cv::CAP_PROP_EXPOSURE, v4l2_exposure_units(config_.exposure_s));
  }
  return true;
}

void CaptureSource::reopen_device() {
  // An unplugged camera fails every read on its dead handle; plugged back, it is a new device node
  // behind the same path, and only a new open sees it.
  capture_.release();
  try {
    if (!open_device()) return;
  } catch (const cv::Exception&) {
    capture_.release();
    return;
  }
  const cv::Size size(static_cast<int>(capture_.get(cv::CAP_PROP_FRAME_WIDTH)),
                      static_cast<int>(capture_.get(cv::CAP_PROP_FRAME_HEIGHT)));
  if (size != size_) {  // another camera, or another mode: its frames would not fit the detector
    capture_.release();
    return;
  }
  ++counters_.reopens;
  have_last_ = false;  // the gap while it was away is no count of dropped frames
}

std::string CaptureSource::describe() const {
  std::ostringstream s;
  s << (is_device_ ? "camera " : "video file ") << config_.source << " " << size_.width << "x" << size_.height << " at "
    << fps_ << " fps";
  return s.str();
}

bool CaptureSource::read(Frame& out) {
  if (at_end_) return false;
  bool ok = false;
  try {
    ok = capture_.read(raw_);
  } catch (const cv::Exception&) {
    ok = false;
  }
  const double now_s = steady_now_s();
  if (!ok || raw_.empty()) {
    if (is_device_) {
      ++counters_.read_failures;
      if (++failures_in_a_row_ >= kReopenAfterFailures) {
        failures_in_a_row_ = 0;
        reopen_device();
      }
    } else {
      at_end_ = true;
    }
    return false;
  }
  failures_in_a_row_ = 0;
  if (raw_.channels() == 3) {
    cv::cvtColor(raw_, out.gray, cv::COLOR_BGR2GRAY);
  } else if (raw_.channels() == 4) {
    cv::cvtColor(raw_, out.gray, cv::COLOR_BGRA2GRAY);
  } else if (raw_.depth() != CV_8U) {
    raw_.convertTo(out.gray, CV_8U, 1.0 / 256.0);
  } else {
    raw_.copyTo(out.gray);
  }
  size_ = out.gray.size();
  const double pos_ms = capture_.get(cv::CAP_PROP_POS_MSEC);
  // A file's first frame is at 0 ms; a device without timestamps reports 0 for every frame.
  const bool have_driver = std::isfinite(pos_ms) && (pos_ms > 0.0 || (!is_device_ && counters_.frames == 0));
  out.driver_t_s = have_driver ? pos_ms * 1e-3 : std::numeric_limits<double>::quiet_NaN();
  out.t_s = now_s;
  if (!is_device_ && have_driver) {
    // A file's frames on its own clock: stamped at decoding, 60 frames of 200 fps had spanned 25 ms,
    // and the tracker saw the ball 12 times too fast.
    if (file_start_steady_s_ < 0.0) {
      file_start_steady_s_ = now_s;
      file_start_pos_s_ = out.driver_t_s;
    }
    out.t_s = file_start_steady_s_ + (out.driver_t_s - file_start_pos_s_);
    if (config_.pace_file && out.t_s > now_s) {
      std::this_thread::sleep_for(std::chrono::duration<double>(out.t_s - now_s));
    }
  }
  // Dropped frames: from the driver's clock when it has one, else (devices only) from the steady clock.
  const bool use_driver = have_driver;
  const double stamp_s = use_driver ? out.driver_t_s : now_s;
  if (have_last_ && (use_driver || is_device_)) {
    const std::uint64_t missing = frames_dropped_between(last_stamp_s_, stamp_s, 1.0 / fps_);
    counters_.dropped += missing;
    sequence_ += missing;
  }
  if (use_driver || is_device_) {
    last_stamp_s_ = stamp_s;
    have_last_ = true;
  }
  out.sequence = sequence_++;
  ++counters_.frames;
  return true;
}

std::uint64_t frames_dropped_between(double previous_s, double current_s, double period_s) {
  const double gap_s = current_s - previous_s;
  if (!(period_s > 0.0) || !(gap_s > 1.5 * period_s)) return 0;
  return static_cast<std::uint64_t>(std::llround(gap_s / period_s)) - 1;
}

}  // namespace pinball::vision
