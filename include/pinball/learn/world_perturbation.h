#pragma once
// One thing changed in the world while the belief keeps its value: the
// transfer bench's sweep plays each alone (bench/transfer_bench.h), and
// `pinball learn --randomize` draws several at once for every ball
// (randomized_evaluator.h), so a controller learns not to lean on one model.

#include <string_view>
#include <utility>

#include "pinball/firmware/flipper_actuation.h"
#include "pinball/table/board.h"
#include "pinball/track/camera_model.h"

namespace pinball::learn {

/// One thing the sweep changes in the world (the belief keeps the nominal value).
enum class Perturbation : unsigned char {
  kPivotY_mm,          ///< both flipper pivots moved up (+) or down (−) the table, along y
  kThetaMin_deg,       ///< both flippers' rest stop θ_min turned (+ raises the flipper)
  kFlipperMu_pct,      ///< both flippers' μ scaled by 1 + v/100
  kWallRho,            ///< v added to ρ of every obstacle with ρ ≤ 1 that eats no ball, clamped to [0, 1]
  kGravity_pct,        ///< g along the table scaled by 1 + v/100; the tracker keeps the nominal g
  kActuationDelay_ms,  ///< command to flipper motion (absolute value)
  kCameraLatency_ms,   ///< exposure to delivery (absolute value)
  kCameraNoise_px,     ///< the camera's centroid noise (absolute; the tracker keeps the nominal noise)
};

/// Every perturbation, in report order.
inline constexpr Perturbation kAllPerturbations[] = {
    Perturbation::kPivotY_mm,     Perturbation::kThetaMin_deg,       Perturbation::kFlipperMu_pct,
    Perturbation::kWallRho,       Perturbation::kGravity_pct,        Perturbation::kActuationDelay_ms,
    Perturbation::kCameraLatency_ms, Perturbation::kCameraNoise_px};

/// The report's name: "pivot_y_mm", "theta_min_deg", "flipper_mu_pct", "wall_rho", "gravity_pct",
/// "actuation_delay_ms", "camera_latency_ms", "camera_noise_px".
std::string_view perturbation_name(Perturbation p);
/// For people and plots: "flipper pivots along y (mm)", ...
std::string_view perturbation_label(Perturbation p);
/// The perturbation whose perturbation_name() is `name`; throws
/// std::invalid_argument naming `name` and listing every name otherwise.
Perturbation parse_perturbation(std::string_view name);
/// One perturbation as a person writes it: "NAME=VALUE" ("gravity_pct=-10",
/// "pivot_y_mm=+3"), VALUE in the perturbation's unit. Throws
/// std::invalid_argument naming the text for no '=', an unknown name
/// (parse_perturbation) or a value that is not a whole finite number.
std::pair<Perturbation, double> parse_perturbation_setting(std::string_view text);
/// True for a change of the table itself (pivots, θ_min, μ, wall ρ, g), which
/// a world plays; false for the solenoid's delay and the camera, which the
/// controller's loop plays.
bool changes_table(Perturbation p);
/// True for an offset from the nominal world (the nominal value is 0); false
/// for an absolute setting (delay, latency, noise). The table's perturbations
/// are the offsets: each is an error of a calibrated or identified value.
bool is_offset(Perturbation p);

/// The world a cell plays beside its board: the perturbed table and the
/// world-side settings (the solenoid's delay, the real camera).
struct WorldSettings {
  table::Board board;               ///< the world's table
  double actuation_delay_s = 0.0;   ///< command to flipper motion (s)
  track::CameraModelConfig camera;  ///< the camera the world really has
};

/// `nominal` with perturbation `p` of `value` applied (`value` in p's unit).
/// Throws std::invalid_argument when the result is no table (a negative g or
/// delay, μ ≤ 0, a negative noise).
WorldSettings perturb(const WorldSettings& nominal, Perturbation p, double value);

}  // namespace pinball::learn
