#pragma once
// One camera image and when it was taken: what a FrameSource hands the
// BallDetector. The image is 8-bit grayscale in the image frame (u right,
// v down, pixels).

#include <cstdint>
#include <limits>

#include <opencv2/core.hpp>

namespace pinball::vision {

/// A grayscale frame with its timestamps. Sources reuse `gray`'s buffer from
/// one read to the next, so a consumer that keeps a frame copies it.
struct Frame {
  cv::Mat gray;                    ///< CV_8UC1 image (u right, v down)
  double t_s = 0.0;                ///< time of the exposure on the pipeline's clock (s): steady clock at
                                   ///< capture for cameras, mid-exposure simulated time for the simulator
  double driver_t_s = std::numeric_limits<double>::quiet_NaN();  ///< the driver's or file's own timestamp (s);
                                                                 ///< NaN when the backend gives none
  std::uint64_t sequence = 0;      ///< frame number from the source's clock; a gap means frames were dropped
};

}  // namespace pinball::vision
