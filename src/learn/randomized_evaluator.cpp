#include "pinball/learn/randomized_evaluator.h"

#include <cmath>
#include <stdexcept>

#include "pinball/core/format.h"
#include "pinball/core/rng.h"
#include "pinball/core/text_file.h"
#include "pinball/core/yaml_read_archive.h"
#include "pinball/sim/model_world.h"

namespace pinball::learn {
namespace {

// SplitMix64's finaliser: spreads consecutive ball seeds over the worlds.
std::uint64_t mix(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

void check_randomization(const Randomization& r, const YamlReadArchive& archive) {
  if (r.variants < 1 || r.variants > 1024)
    archive.fail("variants", std::to_string(r.variants) + " is out of range: must be in [1, 1024]");
  if (!(r.event_stepper_share >= 0.0 && r.event_stepper_share <= 1.0))
    archive.fail("event_stepper_share", "must be in [0, 1]");
  for (const Perturbation p : kAllPerturbations) {
    const PerturbationRange& range = r.range(p);
    if (!range) continue;
    const std::string key = "ranges." + std::string(perturbation_name(p));
    const auto [low, high] = *range;
    if (!std::isfinite(low) || !std::isfinite(high) || low > high)
      archive.fail(key, "must be [low, high] with low <= high");
    const bool absolute = !is_offset(p);  // a delay, latency or noise: never negative
    if (absolute && low < 0.0) archive.fail(key, "a delay, latency or noise cannot be negative");
  }
}

}  // namespace

const PerturbationRange& Randomization::range(Perturbation p) const {
  switch (p) {
    case Perturbation::kPivotY_mm: return ranges.pivot_y_mm;
    case Perturbation::kThetaMin_deg: return ranges.theta_min_deg;
    case Perturbation::kFlipperMu_pct: return ranges.flipper_mu_pct;
    case Perturbation::kWallRho: return ranges.wall_rho;
    case Perturbation::kGravity_pct: return ranges.gravity_pct;
    case Perturbation::kActuationDelay_ms: return ranges.actuation_delay_ms;
    case Perturbation::kCameraLatency_ms: return ranges.camera_latency_ms;
    case Perturbation::kCameraNoise_px: return ranges.camera_noise_px;
  }
  throw std::logic_error("unknown perturbation");
}

Randomization parse_randomization(const std::string& text, const std::string& name) {
  const YAML::Node root = load_yaml(text, name);
  YamlReadArchive archive(name, {.refuse_unknown_keys = true, .require_every_key = true});
  Randomization r;
  archive.read(root, "", &r);
  check_randomization(r, archive);
  r.source = name;
  return r;
}

Randomization load_randomization(const std::string& path) { return parse_randomization(read_text_file(path), path); }

std::vector<DrawnWorld> draw_worlds(const table::Board& belief, const EvaluatorConfig& config,
                                    const Randomization& randomization) {
  const WorldSettings nominal{belief, config.actuation_delay_s, config.camera};
  // Both ends of every range, before any draw: whether a bad range is refused must not
  // depend on which values the seed happens to draw.
  for (const Perturbation p : kAllPerturbations) {
    const PerturbationRange& range = randomization.range(p);
    if (!range) continue;
    for (const double end : *range) {
      try {
        (void)perturb(nominal, p, end);
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(randomization.source + ": ranges." + std::string(perturbation_name(p)) +
                                    ": its end " + format_number(end) + ": " + e.what());
      }
    }
  }
  std::vector<DrawnWorld> worlds;
  Rng rng(randomization.seed);
  const auto event_worlds = static_cast<int>(std::lround(randomization.event_stepper_share * randomization.variants));
  for (int v = 0; v < randomization.variants; ++v) {
    DrawnWorld w;
    w.settings = nominal;
    // The event stepper plays an even spread of the worlds, not a random share.
    w.stepper = v * event_worlds / randomization.variants != (v + 1) * event_worlds / randomization.variants
                    ? sim::StepperKind::kEvent
                    : sim::StepperKind::kThesis;
    for (const Perturbation p : kAllPerturbations) {
      const PerturbationRange& range = randomization.range(p);
      if (!range) continue;
      const double value = rng.uniform((*range)[0], (*range)[1]);
      try {
        // An offset adds to the nominal world; an absolute setting replaces it.
        w.settings = perturb(w.settings, p, value);
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(randomization.source + ": ranges." + std::string(perturbation_name(p)) + ": " +
                                    e.what());
      }
      w.values.emplace_back(p, value);
    }
    worlds.push_back(std::move(w));
  }
  return worlds;
}

RandomizedEvaluator::RandomizedEvaluator(const table::Board& belief, const EvaluatorConfig& config,
                                         const Randomization& randomization)
    : drawn_(draw_worlds(belief, config, randomization)) {
  for (const DrawnWorld& w : drawn_) {
    EvaluatorConfig c = config;  // the tracker keeps the nominal camera and g
    c.actuation_delay_s = w.settings.actuation_delay_s;
    c.world_camera = w.settings.camera;
    sim::ModelWorldOptions options;
    options.stepper = w.stepper;
    options.dt_s = config.dt_s;
    evaluators_.push_back(
        std::make_unique<PinballEvaluator>(belief, c, sim::make_model_world(w.settings.board, options)));
  }
}

std::size_t drawn_world_index(std::uint64_t ball_seed, std::size_t variants) {
  return static_cast<std::size_t>(mix(ball_seed) % variants);
}

std::size_t RandomizedEvaluator::world_of(std::uint64_t ball_seed) const {
  return drawn_world_index(ball_seed, evaluators_.size());
}

BallOutcome RandomizedEvaluator::play(const control::ControllerSpec& spec, std::uint64_t ball_seed) const {
  return evaluators_[world_of(ball_seed)]->play(spec, ball_seed);
}

control::ControllerSpec RandomizedEvaluator::prototype() const { return evaluators_.front()->prototype(); }

}  // namespace pinball::learn
