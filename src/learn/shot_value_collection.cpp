#include "pinball/learn/shot_value_collection.h"

#include <chrono>
#include <stdexcept>

#include "pinball/core/progress.h"
#include "pinball/core/rng.h"
#include "pinball/learn/blob.h"
#include "pinball/learn/parallel_runner.h"
#include "pinball/sim/ball_runner.h"
#include "pinball/sim/model_world.h"

namespace pinball::learn {

namespace {

// One ball of the player, its shots added to `table`.
void play_collecting(const sim::ThesisStepper& model, sim::World& world, const ShotValueCollectionConfig& config,
                     std::uint64_t ball_seed, ShotValueTable& table) {
  sim::GameState state = sim::make_game_state(world.board(), ball_seed);
  LookaheadPlayer player(model, config.player, config.actuation_delay_s);
  sim::BallLimits limits;
  limits.max_ball_time_s = config.max_ball_time_s;
  limits.pull = config.pull;
  int seen = 0;
  sim::play_ball(
      world, state, limits,
      [&](sim::GameState& s) {
        player.act(s);
        if (player.decisions() == seen) return;
        seen = player.decisions();
        for (const LookaheadCandidate& c : player.planner().candidates()) {
          if (c.shot_flipper >= 0) add_shot(table, c.shot_flipper, c.shot_direction_deg, c.shot_speed_mps, c.value - c.score_at_shot);
        }
      },
      [](const sim::GameState&, const sim::StepEvents&) {});
}

}  // namespace

ShotValueTable collect_shot_values(const table::Board& belief, const ShotValueCollectionConfig& config, int balls,
                                   std::uint64_t seed, int threads,
                                   const std::function<void(const std::string&)>& progress) {
  if (balls < 1) throw std::invalid_argument("shot values: balls must be >= 1");
  if (config.player.shot_values) throw std::invalid_argument("shot values: the player must value plans by their branches");
  const int flippers = static_cast<int>(belief.flippers.size());
  ShotValueTable total = make_shot_value_table(flippers);
  const sim::ThesisStepper model(belief);
  const std::unique_ptr<sim::World> prototype = sim::make_model_world(belief);
  SharedProgress balls_done(balls, balls / 20, [&](long d, double elapsed_s) {
    if (progress) progress(format_progress("shot values", d, balls, "balls", elapsed_s));
  });
  // Each ball's table is a blob: batches of kShotValueBatchBalls keep memory to one batch's.
  constexpr std::size_t kShotValueBatchBalls = 500;
  distributed_batches(
      static_cast<std::size_t>(balls), kShotValueBatchBalls, threads,
      [&](std::size_t i) {
        ShotValueTable table = make_shot_value_table(flippers);
        const std::unique_ptr<sim::World> world = prototype->fork();
        play_collecting(model, *world, config, ball_seed(seed, i), table);
        balls_done.one_done();
        BlobWriter w;
        w.put_vector(table.sum).put_vector(table.count);
        return w.take();
      },
      [&](std::size_t, std::vector<Blob>& blobs) {
        for (const Blob& b : blobs) {
          BlobReader r(b);
          const std::vector<double> sum = r.get_vector<double>();
          const std::vector<double> count = r.get_vector<double>();
          for (std::size_t k = 0; k < total.sum.size(); ++k) {
            total.sum[k] += sum[k];
            total.count[k] += count[k];
          }
        }
      });
  smooth(total);
  return total;
}

}  // namespace pinball::learn
