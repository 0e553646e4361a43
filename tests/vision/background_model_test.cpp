#include "pinball/vision/background_model.h"

#include <stdexcept>

#include <gtest/gtest.h>

namespace pinball::vision {
namespace {

TEST(BackgroundModel, LearnsTheMeanOfItsTrainingFrames) {
  BackgroundModel model({64, 48});
  EXPECT_FALSE(model.ready());
  model.add_training_frame(cv::Mat(48, 64, CV_8U, cv::Scalar(10)));
  model.add_training_frame(cv::Mat(48, 64, CV_8U, cv::Scalar(20)));
  model.add_training_frame(cv::Mat(48, 64, CV_8U, cv::Scalar(30)));
  model.finish_training();
  ASSERT_TRUE(model.ready());
  EXPECT_EQ(model.training_frames(), 3);
  double lo = 0.0, hi = 0.0;
  cv::minMaxLoc(model.image(), &lo, &hi);
  EXPECT_EQ(lo, 20.0);
  EXPECT_EQ(hi, 20.0);
}

TEST(BackgroundModel, RefusesWrongFramesAndEmptyTraining) {
  BackgroundModel model({64, 48});
  EXPECT_THROW(model.finish_training(), std::logic_error);
  EXPECT_THROW(model.add_training_frame(cv::Mat(48, 63, CV_8U, cv::Scalar(0))), std::invalid_argument);
  EXPECT_THROW(model.add_training_frame(cv::Mat(48, 64, CV_8UC3, cv::Scalar(0, 0, 0))), std::invalid_argument);
  EXPECT_THROW(model.set(cv::Mat(10, 10, CV_8U, cv::Scalar(0))), std::invalid_argument);
}

TEST(BackgroundModel, RunningUpdateLeavesTheBallRegionAlone) {
  BackgroundModel model({64, 48});
  model.set(cv::Mat(48, 64, CV_8U, cv::Scalar(40)));
  const cv::Mat bright(48, 64, CV_8U, cv::Scalar(140));
  const cv::Rect ball(20, 10, 12, 12);
  for (int i = 0; i < 50; ++i) model.update(bright, 0.2, ball);
  EXPECT_EQ(model.image().at<std::uint8_t>(16, 26), 40);  // inside the excluded ball region
  EXPECT_GE(model.image().at<std::uint8_t>(40, 5), 139);  // elsewhere it followed the light
  model.update(bright, 0.2, cv::Rect());
  EXPECT_GT(model.image().at<std::uint8_t>(16, 26), 40);  // nothing excluded now
}

}  // namespace
}  // namespace pinball::vision
