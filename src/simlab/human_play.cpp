#include "pinball/simlab/human_play.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>
#include <string_view>

#include "pinball/core/format.h"
#include "pinball/sim/ball_runner.h"

namespace pinball::simlab {
namespace {

// A tap ("left", "right" in a script) holds the flipper this long (s).
constexpr double kTapHold_s = 0.1;

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

[[noreturn]] void bad_entry(int index, std::string_view entry, const std::string& what) {
  throw std::invalid_argument("key script entry " + std::to_string(index) + " '" + std::string(entry) + "': " + what);
}

}  // namespace

std::vector<KeyEvent> parse_key_script(const std::string& text) {
  std::vector<KeyEvent> events;
  double last_t_s = 0.0;
  int index = 0;
  std::size_t start = 0;
  while (start <= text.size()) {
    std::size_t end = text.find_first_of(",\n", start);
    if (end == std::string::npos) end = text.size();
    const std::string_view entry = trim(std::string_view(text).substr(start, end - start));
    start = end + 1;
    if (entry.empty() || entry.front() == '#') continue;
    ++index;
    const std::size_t colon = entry.find(':');
    if (colon == std::string_view::npos) bad_entry(index, entry, "expected TIME:ACTION");
    const std::string time_text(trim(entry.substr(0, colon)));
    char* time_end = nullptr;
    const double t_s = std::strtod(time_text.c_str(), &time_end);
    if (time_text.empty() || time_end != time_text.c_str() + time_text.size() || !std::isfinite(t_s) || t_s < 0.0) {
      bad_entry(index, entry, "time must be a number of seconds >= 0");
    }
    // A headless session steps every dt up to the last entry: a time of 1e300 s never ended.
    if (t_s > kMaxKeyScriptTime_s) {
      bad_entry(index, entry, "time must be at most " + format_number(kMaxKeyScriptTime_s) + " s (a day of play)");
    }
    if (t_s < last_t_s) bad_entry(index, entry, "times must not decrease");
    last_t_s = t_s;
    const std::string_view action = trim(entry.substr(colon + 1));
    if (action == "launch") {
      events.push_back({t_s, Key::kLaunch, true});
      events.push_back({t_s, Key::kLaunch, false});
    } else if (action == "left-down" || action == "left-up") {
      events.push_back({t_s, Key::kLeftFlipper, action == "left-down"});
    } else if (action == "right-down" || action == "right-up") {
      events.push_back({t_s, Key::kRightFlipper, action == "right-down"});
    } else if (action == "left" || action == "right") {
      const Key k = action == "left" ? Key::kLeftFlipper : Key::kRightFlipper;
      events.push_back({t_s, k, true});
      events.push_back({t_s + kTapHold_s, k, false});
    } else {
      bad_entry(index, entry,
                "unknown action '" + std::string(action) +
                    "' (launch, left-down, left-up, right-down, right-up, left, right)");
    }
  }
  if (events.empty()) throw std::invalid_argument("key script has no entries (expected TIME:ACTION, ...)");
  // Taps end after later entries may begin: order by time, keeping the script's order at equal times.
  std::stable_sort(events.begin(), events.end(), [](const KeyEvent& a, const KeyEvent& b) { return a.t_s < b.t_s; });
  return events;
}

PlaySession::PlaySession(sim::World& world, const PlayConfig& config)
    : world_(world), config_(config), state_(sim::make_game_state(world.board(), config.seed)) {
  if (config_.pull < 0.0) config_.pull = world_.board().launcher.pull;
  table::check_launch_pull(world_.board(), config_.pull);
  if (!(config_.max_ball_time_s > 0.0)) throw std::invalid_argument("play: the ball time limit must be positive");
  max_steps_ = config_.max_steps_per_advance > 0
                   ? config_.max_steps_per_advance
                   : std::max(1, static_cast<int>(std::ceil(0.1 / world_.dt_s())));
}

void PlaySession::key(Key k, bool down) {
  const int i = static_cast<int>(k);
  if (held_[i] == down) return;  // auto-repeat of a held key, or a release of a key not held
  held_[i] = down;
  ++counters_.key_events;
  if (k == Key::kLaunch) {
    if (down) launch();
    return;
  }
  set_coils(k, down);
}

void PlaySession::set_coils(Key k, bool energized) {
  const table::Side side = k == Key::kLeftFlipper ? table::Side::kLeft : table::Side::kRight;
  const auto& flippers = world_.board().flippers;
  for (std::size_t f = 0; f < flippers.size(); ++f) {
    if (flippers[f].side == side) state_.flippers[f].energized = energized;
  }
}

void PlaySession::launch() {
  if (!in_ball_) {
    sim::begin_ball(world_, state_, config_.pull);
    // A new game drops the flippers (sim::reset_game); the player's hands have not moved.
    for (const Key k : {Key::kLeftFlipper, Key::kRightFlipper}) set_coils(k, held(k));
    in_ball_ = true;
    ball_t0_s_ = state_.time_s;
    score_before_ = state_.score;
    launches_ = 1;
  } else if (sim::resting_in_launcher(world_.board(), state_)) {
    world_.launch(state_, config_.pull);
    ++launches_;
  }
}

void PlaySession::end_ball(bool cut) {
  PlayedBall b;
  b.score = state_.score - score_before_;
  b.duration_s = state_.time_s - ball_t0_s_;
  b.launches = launches_;
  b.cut = cut;
  balls_.push_back(b);
  in_ball_ = false;
}

void PlaySession::step() {
  const sim::StepEvents events = world_.step(state_);
  ++counters_.steps;
  time_s_ = static_cast<double>(counters_.steps) * world_.dt_s();
  if (!in_ball_) return;
  if (events.has(sim::StepEvents::kBallLost)) {
    end_ball(false);
  } else if (state_.time_s - ball_t0_s_ >= config_.max_ball_time_s - 0.5 * world_.dt_s()) {
    sim::cut_ball(world_.board(), state_);
    end_ball(true);
  }
}

int PlaySession::advance_to(double t_s) {
  ++counters_.advances;
  const double dt_s = world_.dt_s();
  int steps = 0;
  // A step fits when it ends at or before t_s; a millionth of a step of slack for rounding.
  while (time_s_ + dt_s <= t_s + 1e-6 * dt_s) {
    if (steps == max_steps_) {
      ++counters_.fell_behind;
      counters_.dropped_s += t_s - time_s_;
      break;
    }
    step();
    ++steps;
  }
  return steps;
}

std::size_t play_script_until(PlaySession& session, const std::vector<KeyEvent>& script, std::size_t next, double t_s) {
  while (next < script.size() && script[next].t_s <= t_s) {
    session.advance_to(script[next].t_s);
    session.key(script[next].key, script[next].down);
    ++next;
  }
  session.advance_to(t_s);
  return next;
}

}  // namespace pinball::simlab
