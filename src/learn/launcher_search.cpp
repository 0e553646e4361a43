#include "pinball/learn/launcher_search.h"

#include <stdexcept>

#include "pinball/simlab/simulated_player.h"
#include "pinball/sim/ball_runner.h"
#include "pinball/sim/model_world.h"

namespace pinball::learn {

namespace {

// Never flips; remembers whether the tracker ever saw a hittable state.
class HittableWatcher final : public control::FlipperController {
 public:
  void update(const track::TrackerOutput& out, double, std::array<bool, 2>&) override {
    if (out.projection.valid && out.projection.hittable) hittable = true;
  }
  void reset(std::array<bool, 2>& energized) override { energized = {false, false}; }
  bool hittable = false;
};

}  // namespace

LauncherSearchResult search_launcher(const table::Board& board, const LauncherSearchConfig& config,
                                     const sim::World* world) {
  if (config.pulls < 1 || config.launches_per_pull < 1 || !(config.time_limit_s > 0.0)) {
    throw std::invalid_argument("launcher search: pulls and launches must be >= 1 and the time limit > 0");
  }
  const std::unique_ptr<sim::World> world_prototype = world != nullptr ? world->fork() : sim::make_model_world(board);
  sim::check_same_flippers(world_prototype->board(), board);
  LauncherSearchResult result;
  result.best_successes = -1;
  for (int i = 1; i <= config.pulls; ++i) {
    const double pull = static_cast<double>(i) / config.pulls;
    int successes = 0;
    for (int l = 0; l < config.launches_per_pull; ++l) {
      const std::uint64_t seed = config.seed * 1000003ull + static_cast<std::uint64_t>(i * 1000 + l);
      const std::unique_ptr<sim::World> ball_world = world_prototype->fork();
      sim::GameState state = sim::make_game_state(ball_world->board(), seed);
      HittableWatcher watcher;
      simlab::SimulatedPlayer player(board, config.camera, watcher, seed ^ 0x9E3779B97F4A7C15ull);
      sim::BallLimits limits;
      limits.max_ball_time_s = config.time_limit_s;
      limits.pull = pull;
      sim::play_ball(
          *ball_world, state, limits, [&](sim::GameState& s) { player.act(s); },
          [&](const sim::GameState&, const sim::StepEvents&) {});
      successes += watcher.hittable ? 1 : 0;
    }
    result.pull.push_back(pull);
    result.successes.push_back(successes);
    if (successes > result.best_successes) {
      result.best_successes = successes;
      result.best_pull = pull;
    }
  }
  return result;
}

}  // namespace pinball::learn
