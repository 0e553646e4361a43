#include "pinball/vision/background_model.h"

#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

namespace pinball::vision {
namespace {

void check_frame(const cv::Mat& gray, cv::Size size, const char* what) {
  if (gray.type() != CV_8UC1 || gray.size() != size) {
    throw std::invalid_argument(std::string("background model: ") + what + " needs an 8-bit gray image of " +
                                std::to_string(size.width) + "x" + std::to_string(size.height) + " px");
  }
}

}  // namespace

BackgroundModel::BackgroundModel(cv::Size size) : size_(size) {
  if (size.width <= 0 || size.height <= 0) throw std::invalid_argument("background model: size must be positive");
  sum_ = cv::Mat::zeros(size, CV_32F);
  background_ = cv::Mat::zeros(size, CV_8U);
  mask_ = cv::Mat(size, CV_8U, cv::Scalar(255));
}

void BackgroundModel::add_training_frame(const cv::Mat& gray) {
  check_frame(gray, size_, "a training frame");
  if (ready_) {  // training again starts a fresh mean
    sum_.setTo(0.0);
    training_frames_ = 0;
    ready_ = false;
  }
  cv::accumulate(gray, sum_);
  ++training_frames_;
}

void BackgroundModel::finish_training() {
  if (training_frames_ == 0) throw std::logic_error("background model: no training frames");
  sum_.convertTo(sum_, CV_32F, 1.0 / training_frames_);
  sum_.convertTo(background_, CV_8U);
  ready_ = true;
}

void BackgroundModel::set(const cv::Mat& gray) {
  check_frame(gray, size_, "set()");
  gray.copyTo(background_);
  background_.convertTo(sum_, CV_32F);
  training_frames_ = 0;
  ready_ = true;
}

void BackgroundModel::update(const cv::Mat& gray, double rate, const cv::Rect& exclude) {
  if (!ready_ || gray.type() != CV_8UC1 || gray.size() != size_ || !(rate > 0.0)) return;
  const cv::Rect hole = exclude & cv::Rect(0, 0, size_.width, size_.height);
  if (hole.area() > 0) mask_(hole).setTo(0);
  cv::accumulateWeighted(gray, sum_, rate, mask_);
  if (hole.area() > 0) mask_(hole).setTo(255);
  sum_.convertTo(background_, CV_8U);
}

}  // namespace pinball::vision
