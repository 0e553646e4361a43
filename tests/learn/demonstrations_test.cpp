#include "pinball/learn/demonstrations.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <set>
#include <stdexcept>

#include "common/thesis_board.h"
#include "pinball/learn/evaluator.h"
#include "pinball/sim/model_world.h"

namespace pinball::learn {
namespace {

using pinball::testing::thesis_board;

DemonstrationConfig short_config() {
  DemonstrationConfig c;
  c.teacher.fire_frames = 3;
  c.teacher.horizon_s = 1.0;
  c.max_ball_time_s = 6.0;
  return c;
}

void expect_sane(const control::ShotExample& e) {
  EXPECT_TRUE(e.flipper == 0 || e.flipper == 1);
  EXPECT_TRUE(e.fired_flipper >= -1 && e.fired_flipper <= 1);
  EXPECT_TRUE(std::isfinite(e.angle_rad) && std::abs(e.angle_rad) <= 1.5707963267948966 + 1e-12);
  EXPECT_TRUE(std::isfinite(e.h) && e.h >= 0.0);
  EXPECT_TRUE(std::isfinite(e.speed_mps) && e.speed_mps >= 0.0);
  if (e.fired_flipper >= 0) {
    EXPECT_GT(e.hold_s, 0.0);
  } else {
    EXPECT_EQ(e.hold_s, 0.0);
  }
}

// A ball's bytes are its values: a shot's padding (whatever the memory held)
// made the same run write different checkpoints.
TEST(Demonstrations, ABallsBytesAreItsValuesNotItsPadding) {
  DemonstrationBall clean;
  clean.shots = {{0, true, 0.25, 0.5, 1.5, 1, 0.03, 0.2}, {1, false, -0.1, 0.9, 2.0, -1, 0.0, 0.0}};
  clean.score = 1234.5;
  clean.teacher_fires = 3;
  DemonstrationBall dirty = clean;
  for (control::ShotExample& e : dirty.shots) {
    const control::ShotExample value = e;
    std::memset(static_cast<void*>(&e), 0xA5, sizeof e);  // padding as garbage, then the same fields
    e.flipper = value.flipper;
    e.rolling = value.rolling;
    e.angle_rad = value.angle_rad;
    e.h = value.h;
    e.speed_mps = value.speed_mps;
    e.fired_flipper = value.fired_flipper;
    e.d_fire_m = value.d_fire_m;
    e.hold_s = value.hold_s;
  }
  EXPECT_EQ(to_blob(dirty), to_blob(clean));
  const DemonstrationBall back = demonstration_ball_from_blob(to_blob(clean));
  ASSERT_EQ(back.shots.size(), 2u);
  EXPECT_EQ(back.shots[1].fired_flipper, -1);
  EXPECT_EQ(back.shots[0].rolling, true);
  EXPECT_EQ(back.shots[0].hold_s, 0.2);
  EXPECT_EQ(back.score, 1234.5);
  EXPECT_EQ(back.teacher_fires, 3);
}

TEST(Demonstrations, TheTeachersShotsAreRecordedOnePerApproach) {
  const sim::ThesisStepper model(thesis_board());
  const std::unique_ptr<sim::World> world = sim::make_model_world(thesis_board());
  const DemonstrationBall b = record_demonstration(thesis_board(), *world, model, short_config(), ball_seed(3, 0));
  ASSERT_FALSE(b.shots.empty());
  int fired = 0;
  for (const control::ShotExample& e : b.shots) {
    expect_sane(e);
    if (e.fired_flipper >= 0) {
      ++fired;
      // The teacher's holds are its plans' (30 or 100 ms at 5 ms frames).
      EXPECT_TRUE(std::abs(e.hold_s - 0.030) < 1e-12 || std::abs(e.hold_s - 0.100) < 1e-12) << e.hold_s;
    }
  }
  EXPECT_GT(fired, 0);
  EXPECT_LE(fired + b.unmatched_fires, b.teacher_fires) << "at most one example per flip";
  EXPECT_GT(b.duration_s, 0.0);
}

TEST(Demonstrations, SameSeedSameExamplesWhateverTheThreads) {
  const Demonstrations one = record_demonstrations(thesis_board(), short_config(), 3, 11, 1, {});
  const Demonstrations two = record_demonstrations(thesis_board(), short_config(), 3, 11, 2, {});
  ASSERT_EQ(one.shots.size(), two.shots.size());
  for (std::size_t i = 0; i < one.shots.size(); ++i) {
    EXPECT_EQ(one.shots[i].angle_rad, two.shots[i].angle_rad);
    EXPECT_EQ(one.shots[i].d_fire_m, two.shots[i].d_fire_m);
    EXPECT_EQ(one.shots[i].fired_flipper, two.shots[i].fired_flipper);
  }
  EXPECT_EQ(one.mean_teacher_score, two.mean_teacher_score);
  EXPECT_EQ(one.balls, 3);
}

// Three worlds around the thesis board, one of them on the event stepper,
// with g, the solenoid's delay and the camera's latency drawn.
std::vector<DrawnWorld> three_drawn_worlds() {
  const Randomization r = parse_randomization(
      "variants: 3\nseed: 4\nevent_stepper_share: 0.34\nranges:\n  gravity_pct: [-10, 10]\n"
      "  actuation_delay_ms: [2, 20]\n  camera_latency_ms: [0, 10]\n",
      "r.yaml");
  return draw_worlds(thesis_board(), EvaluatorConfig{}, r);
}

// What a ball played in drawn world `w` alone gives: its table, stepper,
// delay and camera, the teacher planning on that table.
DemonstrationBall played_alone(const DrawnWorld& w, const DemonstrationConfig& config, std::uint64_t seed) {
  sim::ModelWorldOptions options;
  options.stepper = w.stepper;
  const std::unique_ptr<sim::World> world = sim::make_model_world(w.settings.board, options);
  const sim::ThesisStepper teacher_model(w.settings.board);
  DemonstrationConfig c = config;
  c.actuation_delay_s = w.settings.actuation_delay_s;
  c.world_camera = w.settings.camera;
  return record_demonstration(thesis_board(), *world, teacher_model, c, seed);
}

TEST(Demonstrations, RandomizedTheTeacherPlaysEachBallInTheDrawnWorldItsSeedPicks) {
  const std::vector<DrawnWorld> drawn = three_drawn_worlds();
  ASSERT_EQ(drawn.size(), 3u);
  const TeacherWorlds worlds(thesis_board(), drawn);
  ASSERT_EQ(worlds.drawn().size(), 3u);
  const std::uint64_t seed = 13;
  const int balls = 6;
  const Demonstrations d = record_demonstrations(thesis_board(), short_config(), balls, seed, 2, {}, nullptr, &worlds);
  std::vector<control::ShotExample> alone;
  std::set<std::size_t> used;
  double score = 0.0;
  for (int i = 0; i < balls; ++i) {
    const std::uint64_t b = ball_seed(seed, static_cast<std::uint64_t>(i));
    used.insert(drawn_world_index(b, drawn.size()));
    const DemonstrationBall ball = played_alone(drawn[drawn_world_index(b, drawn.size())], short_config(), b);
    alone.insert(alone.end(), ball.shots.begin(), ball.shots.end());
    score += ball.score;
  }
  EXPECT_GE(used.size(), 2u) << "the balls must visit more than one world";
  ASSERT_EQ(d.shots.size(), alone.size());
  for (std::size_t i = 0; i < alone.size(); ++i) {
    EXPECT_EQ(d.shots[i].d_fire_m, alone[i].d_fire_m) << i;
    EXPECT_EQ(d.shots[i].fired_flipper, alone[i].fired_flipper) << i;
    EXPECT_EQ(d.shots[i].speed_mps, alone[i].speed_mps) << i;
  }
  EXPECT_DOUBLE_EQ(d.mean_teacher_score, score / balls);
  // Not the belief's own world: the same balls there play otherwise.
  const Demonstrations home = record_demonstrations(thesis_board(), short_config(), balls, seed, 2, {});
  EXPECT_NE(home.mean_teacher_score, d.mean_teacher_score);
}

TEST(Demonstrations, RandomizedTheTeacherLabelsTheLearnerInTheDrawnWorld) {
  // One drawn world only: every ball plays it, learner and teacher alike.
  const std::vector<DrawnWorld> drawn = three_drawn_worlds();
  const auto never = std::make_shared<const control::ShotTable>(
      std::vector<control::ShotExample>{{0, false, 0.0, 0.5, 1.0, -1, 0.0, 0.0}, {1, false, 0.0, 0.5, 1.0, -1, 0.0, 0.0}},
      control::ImitationConfig{});
  for (const DrawnWorld& w : drawn) {
    const TeacherWorlds one(thesis_board(), std::vector<DrawnWorld>{w});
    const Demonstrations d = record_demonstrations(thesis_board(), short_config(), 2, 5, 1, {}, never, &one);
    int fired = 0;
    for (const control::ShotExample& e : d.shots) {
      expect_sane(e);
      fired += e.fired_flipper >= 0 ? 1 : 0;
    }
    EXPECT_GT(fired, 0) << "the teacher must want to flip where the learner did not";
    // The learner's balls are played in that world: the same balls in the belief's model differ.
    const Demonstrations home = record_demonstrations(thesis_board(), short_config(), 2, 5, 1, {}, never);
    EXPECT_NE(home.mean_ball_time_s, d.mean_ball_time_s);
  }
}

TEST(Demonstrations, TeacherWorldsRefuseNoWorldsAndAnotherBelief) {
  EXPECT_THROW(TeacherWorlds(thesis_board(), std::vector<DrawnWorld>{}), std::invalid_argument);
  const TeacherWorlds worlds(thesis_board(), three_drawn_worlds());
  const table::Board other = thesis_board();  // equal, but not the board the worlds watch with
  EXPECT_THROW(record_demonstrations(other, short_config(), 1, 1, 1, {}, nullptr, &worlds), std::invalid_argument);
}

TEST(Demonstrations, WithALeadEachShotHoldsTheLedProjection) {
  // The same ball, recorded with and without a lead: the teacher plays the
  // same, the approaches and θ, h, s are the same; d is where the ball will be
  // when a command given at the frame acts, nearer the impact.
  const sim::ThesisStepper model(thesis_board());
  const std::unique_ptr<sim::World> world = sim::make_model_world(thesis_board());
  DemonstrationConfig led_config = short_config();
  led_config.lead_actuation_delay_s = 0.004;
  const DemonstrationBall plain = record_demonstration(thesis_board(), *world, model, short_config(), ball_seed(3, 0));
  const DemonstrationBall led = record_demonstration(thesis_board(), *world, model, led_config, ball_seed(3, 0));
  ASSERT_EQ(led.shots.size(), plain.shots.size());
  EXPECT_EQ(led.score, plain.score);
  int nearer = 0;
  for (std::size_t i = 0; i < led.shots.size(); ++i) {
    const control::ShotExample& a = led.shots[i];
    const control::ShotExample& b = plain.shots[i];
    EXPECT_EQ(a.angle_rad, b.angle_rad);
    EXPECT_EQ(a.h, b.h);
    EXPECT_EQ(a.speed_mps, b.speed_mps);
    EXPECT_EQ(a.fired_flipper, b.fired_flipper);
    if (b.fired_flipper < 0) continue;
    // 5 ms of camera latency + 4 ms of delay at under 5 m/s: at most 45 mm nearer.
    EXPECT_LE(a.d_fire_m, b.d_fire_m);
    EXPECT_GE(a.d_fire_m, std::max(0.0, b.d_fire_m - 0.045) - 1e-12);
    nearer += a.d_fire_m < b.d_fire_m ? 1 : 0;
  }
  EXPECT_GT(nearer, 0);
}

TEST(Demonstrations, ALearnerMustLeadAsItsShotsAreKeyed) {
  control::ImitationConfig led;
  led.lead_actuation_delay_s = 0.004;
  const auto learner = std::make_shared<const control::ShotTable>(std::vector<control::ShotExample>{}, led);
  EXPECT_THROW(record_demonstrations(thesis_board(), short_config(), 1, 1, 1, {}, learner), std::invalid_argument);
  ImitationLearningConfig c;
  c.demonstration = short_config();
  c.table = led;  // the demonstrations' lead is none
  EXPECT_THROW(learn_by_imitation(thesis_board(), c, 2, 9, 1, {}), std::invalid_argument);
}

TEST(Demonstrations, TheTeacherLabelsTheLearnersApproaches) {
  // A learner that never flips: the teacher, judging the states it reaches, fires to save the ball.
  const auto never = std::make_shared<const control::ShotTable>(
      std::vector<control::ShotExample>{{0, false, 0.0, 0.5, 1.0, -1, 0.0, 0.0}, {1, false, 0.0, 0.5, 1.0, -1, 0.0, 0.0}},
      control::ImitationConfig{});
  const Demonstrations d = record_demonstrations(thesis_board(), short_config(), 4, 5, 2, {}, never);
  ASSERT_FALSE(d.shots.empty());
  int fired = 0;
  for (const control::ShotExample& e : d.shots) {
    expect_sane(e);
    fired += e.fired_flipper >= 0 ? 1 : 0;
  }
  EXPECT_GT(fired, 0) << "the teacher must want to flip where the learner did not";
  EXPECT_EQ(d.teacher_fires, 0) << "fires count the player's flips: this learner never flips";
}

TEST(Demonstrations, LearningByImitationSharesTheBudgetOverRounds) {
  ImitationLearningConfig c;
  c.demonstration = short_config();
  c.rounds = 2;
  std::vector<std::string> lines;
  const ImitationResult r = learn_by_imitation(thesis_board(), c, 5, 9, 2, [&](const std::string& l) { lines.push_back(l); });
  ASSERT_EQ(r.rounds.size(), 2u);
  EXPECT_EQ(r.rounds[0].balls, 2);
  EXPECT_EQ(r.rounds[1].balls, 3) << "the last round takes the remainder";
  EXPECT_EQ(r.table->examples().size(), r.rounds[1].shots);
  EXPECT_GT(r.rounds[1].shots, r.rounds[0].shots);
  EXPECT_FALSE(lines.empty());
  EXPECT_THROW(learn_by_imitation(thesis_board(), c, 1, 9, 2, {}), std::invalid_argument);
  c.rounds = 0;
  EXPECT_THROW(learn_by_imitation(thesis_board(), c, 5, 9, 2, {}), std::invalid_argument);
}

// Balls cut at 0.05 s never reach a flipper: learn wrote a table of no shots, which never flips
// (and which no controller file may hold).
TEST(Demonstrations, ATeacherThatFiredNoShotGivesNoTable) {
  ImitationLearningConfig c;
  c.demonstration = short_config();
  c.demonstration.max_ball_time_s = 0.05;
  c.rounds = 1;
  try {
    learn_by_imitation(thesis_board(), c, 2, 9, 1, {});
    FAIL() << "a table of no shots was learned";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("imitation: the teacher fired no shot in 2 balls"), std::string::npos)
        << e.what();
  }
}

TEST(Demonstrations, TheLearnedTableOutscoresNoFlippingOnFreshBalls) {
  ImitationLearningConfig c;
  c.demonstration = short_config();
  c.demonstration.max_ball_time_s = 20.0;
  c.rounds = 2;
  const ImitationResult r = learn_by_imitation(thesis_board(), c, 12, 21, 2, {});
  control::ControllerSpec spec;
  spec.shot_table = r.table;
  EvaluatorConfig ec;
  ec.max_ball_time_s = 20.0;
  const PinballEvaluator ev(thesis_board(), ec);
  struct Idle final : control::FlipperController {
    void update(const track::TrackerOutput&, double, std::array<bool, 2>&) override {}
    void reset(std::array<bool, 2>& e) override { e = {false, false}; }
  } idle;
  double learned = 0.0;
  double none = 0.0;
  for (std::uint64_t i = 0; i < 30; ++i) {  // fresh balls: seeds apart from the rounds'
    learned += ev.play(spec, ball_seed(99, i)).score;
    none += ev.play_with(idle, -1.0, ball_seed(99, i)).score;
  }
  EXPECT_GT(learned, 1.5 * none) << "learned " << learned / 30 << " per ball, no flipping " << none / 30;
}

TEST(Demonstrations, TheCurveHasOneRowPerRoundAndTheTeacherIsNoBestSoFar) {
  ImitationResult r;
  r.rounds = {{0, 10, 80, 70000.0, 50.0, 3, 70, 2, 5.0}, {1, 10, 160, 20000.0, 20.0, 0, 60, 1, 2.0},
              {2, 12, 250, 18000.0, 18.0, 1, 70, 0, 2.5}};
  const SearchResult s = imitation_curve(r);
  EXPECT_EQ(s.method, "imitate");
  ASSERT_EQ(s.curve.size(), 3u);
  EXPECT_EQ(s.curve[0].generation, 1);
  EXPECT_EQ(s.curve[2].balls, 32u);
  EXPECT_EQ(s.curve[0].population_mean, 70000.0);
  EXPECT_EQ(s.curve[0].best_so_far, 0.0) << "the teacher cheats: it is not a controller";
  EXPECT_EQ(s.curve[1].best_so_far, 20000.0);
  EXPECT_EQ(s.curve[2].best_so_far, 20000.0);
  EXPECT_DOUBLE_EQ(s.curve[2].wall_s, 9.5);
  EXPECT_TRUE(s.cycle_found) << "a learner's ball was cut in round 3";
  EXPECT_EQ(s.balls_used, 32u);
}

}  // namespace
}  // namespace pinball::learn
