#pragma once
// A real camera (V4L2 device) or a video file through OpenCV's VideoCapture.
// Frames come out gray, stamped with the steady clock when the grab returned
// and, when the backend has one, the driver's own timestamp (V4L2 buffer time,
// or the file's presentation time). Gaps in the timestamps longer than 1.5
// frame periods count as dropped frames and advance the sequence number.

#include <chrono>
#include <cstdint>
#include <string>

#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>

#include "pinball/vision/frame_source.h"

namespace pinball::vision {

/// What to open and how to ask for it.
struct CaptureConfig {
  std::string source;          ///< "0" (V4L2 index), "/dev/video0" (V4L2 path) or a video file path
  int width_px = 640;          ///< requested width (devices; 0 leaves the driver's)
  int height_px = 480;         ///< requested height (devices; 0 leaves the driver's)
  double fps = 200.0;          ///< requested frame rate (devices; 0 leaves the driver's); a file's own rate is used
  std::string fourcc;          ///< requested pixel format, e.g. "GREY", "YUYV", "MJPG" (devices; empty: the driver's)
  double exposure_s = -1.0;    ///< fixed exposure (s), set with auto-exposure off (devices); < 0 leaves the driver's
  int buffers = 2;             ///< driver buffer count (devices; fewer: less latency, more drops); 0 leaves it
  /// A video file's frames are stamped on the steady clock at their recorded
  /// times after the first (Frame::t_s), never at their decoding. true: read()
  /// also waits until that time, so the file plays as a camera delivers
  /// (pinballd); false: as fast as it decodes (calibration's sweep videos).
  bool pace_file = false;
};

/// An exposure time in V4L2's exposure_time_absolute units of 100 µs,
/// rounded, at least 1 (the shortest a driver has).
double v4l2_exposure_units(double exposure_s);

/// True when `source` names a V4L2 device (a number or a /dev/ path) rather than a file.
bool is_device_source(const std::string& source);

/// "SOURCE: no such camera device" when `source` is a /dev/ path that does
/// not exist (a number is left to V4L2), else "": what pinballd --check and
/// calibrate latency say before they open anything.
std::string missing_camera_device(const std::string& source);

/// Frames lost between two frames stamped previous_s and current_s at a
/// nominal period: a gap above 1.5 periods counts round(gap / period) − 1.
std::uint64_t frames_dropped_between(double previous_s, double current_s, double period_s);

/// OpenCV capture of a device or a file.
class CaptureSource final : public FrameSource {
 public:
  /// Opens the source. Throws std::runtime_error naming it when it cannot be
  /// opened (no such device, no such file, not a video, no frames).
  explicit CaptureSource(const CaptureConfig& config);
  CaptureSource(const CaptureSource&) = delete;             ///< one owner of the device
  CaptureSource& operator=(const CaptureSource&) = delete;

  /// Blocks until the next frame (devices) or decodes the next one (files).
  /// False at the end of a file or on a failed grab (counted).
  bool read(Frame& out) override;

  /// True after a file's last frame was read.
  bool at_end() const { return at_end_; }
  /// True when the source is a device rather than a file.
  bool is_device() const { return is_device_; }

  cv::Size frame_size() const override { return size_; }
  double fps() const override { return fps_; }
  FrameSourceCounters counters() const override { return counters_; }
  std::string describe() const override;

 public:
  /// Reads failed in a row after which a camera is opened again (an unplugged
  /// and replugged camera is seen only by a new open): about 5 s of pinballd's
  /// retries, whose wait grows to 0.1 s.
  static constexpr int kReopenAfterFailures = 50;

 private:
  bool open_device();    // opens config_.source with V4L2 and asks for the configured format
  void reopen_device();  // after kReopenAfterFailures: release, open again if it is back at the same size

  CaptureConfig config_;
  int failures_in_a_row_ = 0;
  bool is_device_ = false;
  cv::VideoCapture capture_;
  cv::Mat raw_;
  cv::Size size_;
  double fps_ = 0.0;
  bool at_end_ = false;
  bool have_last_ = false;
  double last_stamp_s_ = 0.0;
  double file_start_steady_s_ = -1.0;  // a file: the steady time of its first frame (< 0: none read yet)
  double file_start_pos_s_ = 0.0;      // and that frame's own time in the file
  std::uint64_t sequence_ = 0;
  FrameSourceCounters counters_;
};

}  // namespace pinball::vision
