#pragma once
// The seam between the camera thread and whatever produces images: a real
// camera or video file (CaptureSource) or the simulator (SimCameraSource).
// The detector and the daemon see only this interface.

#include <cstdint>
#include <string>

#include <opencv2/core.hpp>

#include "pinball/vision/frame.h"

namespace pinball::vision {

/// What a source has delivered and lost since it opened.
struct FrameSourceCounters {
  std::uint64_t frames = 0;         ///< frames delivered by read()
  std::uint64_t dropped = 0;        ///< frames the source knows it lost (timestamp gaps)
  std::uint64_t read_failures = 0;  ///< reads that failed while the source was still open
  std::uint64_t reopens = 0;        ///< a camera opened again after failing kReopenAfterFailures reads in a row
};

/// A stream of grayscale frames.
class FrameSource {
 public:
  virtual ~FrameSource() = default;

  /// Fills `out` with the next frame, reusing its buffer, and returns true;
  /// returns false when no frame is available (simulator: none due yet;
  /// camera: a failed grab; file: the end). Never throws once open.
  virtual bool read(Frame& out) = 0;

  /// Size of the frames it delivers (px).
  virtual cv::Size frame_size() const = 0;

  /// Nominal frame rate (frames per second).
  virtual double fps() const = 0;

  /// Frames delivered, dropped and failed so far.
  virtual FrameSourceCounters counters() const = 0;

  /// One line for logs: what it reads from, size and rate.
  virtual std::string describe() const = 0;
};

}  // namespace pinball::vision
