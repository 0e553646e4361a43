// Results as bytes (include/pinball/learn/blob.h and the outcome codecs):
// what goes in comes back, and a short or long blob is refused.

#include "pinball/learn/blob.h"

#include <gtest/gtest.h>

#include "pinball/learn/demonstrations.h"
#include "pinball/learn/parallel_runner.h"

namespace pinball::learn {
namespace {

TEST(Blob, ValuesAndVectorsComeBackInOrder) {
  const std::vector<double> three = {1, 2, 3};
  const Blob b = BlobWriter().put(1.5).put(std::int32_t{-7}).put_vector(three).put(true).take();
  BlobReader r(b);
  EXPECT_EQ(r.get<double>(), 1.5);
  EXPECT_EQ(r.get<std::int32_t>(), -7);
  EXPECT_EQ(r.get_vector<double>(), three);
  EXPECT_TRUE(r.get<bool>());
  EXPECT_NO_THROW(r.expect_end());
}

TEST(Blob, AnEmptyVectorComesBackEmptyAndTheNextFieldAfterIt) {
  const Blob b = BlobWriter().put_vector(std::vector<int>{}).put(std::int32_t{42}).take();
  BlobReader r(b);
  EXPECT_TRUE(r.get_vector<int>().empty());
  EXPECT_EQ(r.get<std::int32_t>(), 42);
  EXPECT_NO_THROW(r.expect_end());
}

TEST(Blob, RefusesShortAndOverlongBlobs) {
  const Blob b = BlobWriter().put_vector(std::vector<int>{1, 2}).take();
  Blob cut(b.begin(), b.end() - 1);
  BlobReader short_reader(cut);
  EXPECT_THROW(short_reader.get_vector<int>(), std::runtime_error);
  BlobReader reader(b);
  reader.get<std::uint64_t>();
  EXPECT_THROW(reader.expect_end(), std::runtime_error);
}

TEST(Blob, ABallOutcomeRoundTrips) {
  BallOutcome o;
  o.score = 1234.5;
  o.duration_s = 17.25;
  o.flips = 9;
  o.cut = true;
  o.opportunities = {{0, 10.0}, {3, -500.0}};
  const BallOutcome back = ball_outcome_from_blob(to_blob(o));
  EXPECT_EQ(back.score, o.score);
  EXPECT_EQ(back.duration_s, o.duration_s);
  EXPECT_EQ(back.flips, o.flips);
  EXPECT_EQ(back.cut, o.cut);
  ASSERT_EQ(back.opportunities.size(), 2u);
  EXPECT_EQ(back.opportunities[1].partition, 3);
  EXPECT_EQ(back.opportunities[1].value, -500.0);
}

TEST(Blob, ADemonstrationBallRoundTrips) {
  DemonstrationBall d;
  control::ShotExample shot;
  shot.angle_rad = 0.25;
  shot.fired_flipper = 1;
  shot.hold_s = 0.1;
  d.shots = {shot, shot};
  d.score = 5000;
  d.duration_s = 30;
  d.teacher_fires = 4;
  d.unmatched_fires = 1;
  const DemonstrationBall back = demonstration_ball_from_blob(to_blob(d));
  ASSERT_EQ(back.shots.size(), 2u);
  EXPECT_EQ(back.shots[1].angle_rad, 0.25);
  EXPECT_EQ(back.shots[1].fired_flipper, 1);
  EXPECT_EQ(back.score, 5000);
  EXPECT_EQ(back.teacher_fires, 4);
  EXPECT_EQ(back.unmatched_fires, 1);
}

}  // namespace
}  // namespace pinball::learn
