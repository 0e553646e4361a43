#pragma once
// The playfield without the ball: the image the detector subtracts. Learned
// as the mean of frames known to hold no ball, then optionally kept current
// by a slow running average that leaves out the region around the ball (so a
// lamp that changes for good, or a drift in the light, fades into it).

#include <cstdint>

#include <opencv2/core.hpp>

namespace pinball::vision {

/// A background image learned from ball-free frames.
class BackgroundModel {
 public:
  /// An empty model for frames of `size`; buffers are allocated here.
  explicit BackgroundModel(cv::Size size);

  /// Adds one ball-free frame (CV_8UC1 of the model's size) to the mean.
  /// Throws std::invalid_argument on a wrong size or type.
  void add_training_frame(const cv::Mat& gray);

  /// Ends training: the background is the mean of the training frames.
  /// Throws std::logic_error when no frame was added.
  void finish_training();

  /// Sets the background directly (a saved image, a test); CV_8UC1 of the model's size.
  void set(const cv::Mat& gray);

  /// Running update: background += rate · (frame − background) everywhere but
  /// inside `exclude` (the ball's neighbourhood; empty excludes nothing).
  /// Allocates nothing. Requires ready().
  void update(const cv::Mat& gray, double rate, const cv::Rect& exclude);

  /// True once trained or set.
  bool ready() const { return ready_; }
  /// Frames averaged so far (training).
  int training_frames() const { return training_frames_; }
  /// The background (CV_8UC1); empty until ready().
  const cv::Mat& image() const { return background_; }
  /// Frame size.
  cv::Size size() const { return size_; }

 private:
  cv::Size size_;
  cv::Mat sum_;         // CV_32F: training sum, then the running average
  cv::Mat background_;  // CV_8U
  cv::Mat mask_;        // CV_8U: where the running update applies
  int training_frames_ = 0;
  bool ready_ = false;
};

}  // namespace pinball::vision
