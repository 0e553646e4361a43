// The transfer bench's sweep: what each perturbation changes in the world,
// and the values (the measurement: transfer_bench.cpp).
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "transfer_bench.h"

namespace pinball::bench {

double nominal_value(Perturbation p, const TransferBenchOptions& options) {
  switch (p) {
    case Perturbation::kActuationDelay_ms: return options.actuation_delay_s * 1e3;
    case Perturbation::kCameraLatency_ms: return options.camera.latency_s * 1e3;
    case Perturbation::kCameraNoise_px: return options.camera.noise_px;
    default: return 0.0;
  }
}

std::vector<SweepFamily> default_transfer_sweep() {
  return {{Perturbation::kPivotY_mm, {-5, -3, -1, 1, 3, 5}},
          {Perturbation::kThetaMin_deg, {-1, -0.5, 0.5, 1}},
          {Perturbation::kFlipperMu_pct, {-20, 20}},
          {Perturbation::kWallRho, {-0.1, 0.1}},
          {Perturbation::kGravity_pct, {-10, -5, -3, 3, 5, 10}},
          {Perturbation::kActuationDelay_ms, {0, 10, 20}},
          {Perturbation::kCameraLatency_ms, {0, 10}},
          {Perturbation::kCameraNoise_px, {1, 2}}};
}

std::vector<CombinedWorld> default_combined_worlds() {
  std::vector<CombinedWorld> out;
  for (const double mu_pct : {-20.0, 20.0}) {
    out.push_back({std::string("combined_mu") + (mu_pct > 0 ? "+" : "") + std::to_string(static_cast<int>(mu_pct)),
                   sim::StepperKind::kEvent,
                   {{Perturbation::kFlipperMu_pct, mu_pct},
                    {Perturbation::kGravity_pct, -3.0},
                    {Perturbation::kCameraLatency_ms, 5.0}}});
  }
  return out;
}

std::vector<SweepFamily> quick_transfer_sweep() {
  return {{Perturbation::kPivotY_mm, {3}},         {Perturbation::kThetaMin_deg, {-1}},
          {Perturbation::kFlipperMu_pct, {20}},    {Perturbation::kWallRho, {-0.1}},
          {Perturbation::kGravity_pct, {10}},      {Perturbation::kActuationDelay_ms, {20}},
          {Perturbation::kCameraLatency_ms, {10}}, {Perturbation::kCameraNoise_px, {2}}};
}

}  // namespace pinball::bench
