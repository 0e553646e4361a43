#include "pinball/learn/evaluator.h"

#include <gtest/gtest.h>

#include "pinball/control/spastic_controller.h"
#include "pinball/table/board_loader.h"
#include "common/thesis_board.h"
#include "pinball/sim/model_world.h"

namespace pinball::learn {
namespace {

using pinball::testing::thesis_board;

control::ControllerSpec spastic_like(const PinballEvaluator& ev) {
  control::ControllerSpec s = ev.prototype();
  for (int p = 0; p < s.action_function.partitions(); ++p) {
    s.action_function.minicontroller(p).a = {0.0, 0.0, 0.0, 0.02};
    s.action_function.minicontroller(p).flipper = p < s.action_function.partitions() / 2 ? 0 : 1;
  }
  return s;
}

TEST(Evaluator, SameSeedSameBall) {
  const PinballEvaluator ev(thesis_board(), EvaluatorConfig{});
  const control::ControllerSpec s = spastic_like(ev);
  const BallOutcome a = ev.play(s, 11);
  const BallOutcome b = ev.play(s, 11);
  EXPECT_EQ(a.score, b.score);
  EXPECT_EQ(a.duration_s, b.duration_s);
  EXPECT_EQ(a.flips, b.flips);
  EXPECT_EQ(a.opportunities.size(), b.opportunities.size());
}

TEST(Evaluator, ItsDefaultWorldIsTheBeliefsModelOnTheThesisStepper) {
  const PinballEvaluator implicit(thesis_board(), EvaluatorConfig{});
  const PinballEvaluator explicit_world(thesis_board(), EvaluatorConfig{}, sim::make_model_world(thesis_board()));
  const control::ControllerSpec s = spastic_like(implicit);
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    EXPECT_EQ(implicit.play(s, seed).score, explicit_world.play(s, seed).score);
  }
  EXPECT_EQ(implicit.world().name(), "thesis");
}

TEST(Evaluator, AWorldSwappedUnderItPlaysThatWorldWithTheSameBelief) {
  // The world is the same board with weaker gravity; the tracker is not told.
  table::Board weak = thesis_board();
  weak.gravity_mps2 *= 0.9;
  const PinballEvaluator model(thesis_board(), EvaluatorConfig{});
  const PinballEvaluator swapped(thesis_board(), EvaluatorConfig{}, sim::make_model_world(weak));
  sim::ModelWorldOptions event;
  event.stepper = sim::StepperKind::kEvent;
  const PinballEvaluator other_stepper(thesis_board(), EvaluatorConfig{}, sim::make_model_world(thesis_board(), event));
  EXPECT_EQ(&swapped.board(), &thesis_board());
  EXPECT_EQ(swapped.world().board().gravity_mps2, weak.gravity_mps2);
  const control::ControllerSpec s = spastic_like(model);
  int differ = 0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const BallOutcome a = model.play(s, seed);
    const BallOutcome b = swapped.play(s, seed);
    const BallOutcome c = other_stepper.play(s, seed);
    differ += (a.score != b.score) + (a.score != c.score);
    EXPECT_EQ(b.score, swapped.play(s, seed).score);  // still deterministic
  }
  EXPECT_GT(differ, 6);  // of 12 comparisons: the world, not the belief, decides the play
}

TEST(Evaluator, AWorldWithOtherFlippersIsRefused) {
  table::Board one = thesis_board();
  one.flippers.pop_back();
  EXPECT_THROW(PinballEvaluator(thesis_board(), EvaluatorConfig{}, sim::make_model_world(one)), std::invalid_argument);
  EXPECT_THROW(PinballEvaluator(thesis_board(), EvaluatorConfig{}, nullptr), std::invalid_argument);
}

TEST(Evaluator, OpportunitiesCarryScoreAndTheLossPenalty) {
  EvaluatorConfig c;
  c.loss_penalty = 777.0;
  const PinballEvaluator ev(thesis_board(), c);
  const control::ControllerSpec s = spastic_like(ev);
  int balls_with_opportunities = 0;
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    const BallOutcome o = ev.play(s, seed);
    EXPECT_FALSE(o.cut);
    if (o.opportunities.empty()) continue;
    ++balls_with_opportunities;
    EXPECT_EQ(o.opportunities.back().value, -777.0) << "the last opportunity lost the ball";
    double sum = 0.0;
    for (std::size_t i = 0; i + 1 < o.opportunities.size(); ++i) {
      EXPECT_GE(o.opportunities[i].value, 0.0);
      EXPECT_GE(o.opportunities[i].partition, 0);
      EXPECT_LT(o.opportunities[i].partition, s.action_function.partitions());
      sum += o.opportunities[i].value;
    }
    EXPECT_LE(sum, o.score);  // score before the first opportunity is nobody's
  }
  EXPECT_GT(balls_with_opportunities, 5);
}

TEST(Evaluator, FlippingBeatsNotFlippingAndAGameIsCutAtTheTimeLimit) {
  EvaluatorConfig c;
  c.max_ball_time_s = 2.0;
  const PinballEvaluator ev(thesis_board(), c);
  control::SpasticController spastic;
  int cut = 0;
  for (std::uint64_t seed = 1; seed <= 5; ++seed) cut += ev.play_with(spastic, -1.0, seed).cut ? 1 : 0;
  EXPECT_GT(cut, 0) << "balls alive at 2 s are cut and reported";
  EvaluatorConfig bad;
  bad.max_ball_time_s = -1.0;
  EXPECT_THROW(PinballEvaluator(thesis_board(), bad), std::invalid_argument);
}

TEST(Evaluator, BallSeedsAreDistinct) {
  EXPECT_NE(ball_seed(1, 0), ball_seed(1, 1));
  EXPECT_NE(ball_seed(1, 0), ball_seed(2, 0));
  EXPECT_EQ(ball_seed(3, 4), ball_seed(3, 4));
}

}  // namespace
}  // namespace pinball::learn
