// Which calibration errors cost most (issue 19, item 5): per offset family of
// the transfer bench's sweep and per controller, the least-squares slope of
// the mean score per ball against the size of the error.
#include <cmath>
#include <utility>

#include "pinball/core/least_squares_line.h"
#include "pinball/core/statistics.h"
#include "transfer_bench.h"

namespace pinball::bench {
namespace {

std::string unit_of(Perturbation p) {
  switch (p) {
    case Perturbation::kPivotY_mm: return "mm";
    case Perturbation::kThetaMin_deg: return "deg";
    case Perturbation::kFlipperMu_pct:
    case Perturbation::kGravity_pct: return "%";
    default: return "1";
  }
}

const TransferCell* find_cell(const TransferWorld& w, const std::string& controller) {
  for (const TransferCell& c : w.cells) {
    if (c.controller == controller) return &c;
  }
  return nullptr;
}

}  // namespace

std::vector<TransferSensitivity> transfer_sensitivities(const std::vector<TransferWorld>& worlds,
                                                        const TransferBenchOptions& options) {
  std::vector<TransferSensitivity> out;
  const TransferWorld* model = nullptr;
  for (const TransferWorld& w : worlds) {
    if (w.name == "model" && w.played) model = &w;
  }
  if (model == nullptr) return out;
  for (const Perturbation p : kAllPerturbations) {
    if (!is_offset(p)) continue;  // delay, latency and noise are settings, not errors of a calibrated value
    const std::string family(perturbation_name(p));
    for (const TransferCell& nominal : model->cells) {
      // (|error|, mean score) and each mean's standard error, the model world at |error| = 0.
      std::vector<std::pair<double, double>> xy{{0.0, nominal.score.mean()}};
      std::vector<const RunningStats*> stats{&nominal.score};
      for (const TransferWorld& w : worlds) {
        const TransferCell* c = w.played && w.family == family ? find_cell(w, nominal.controller) : nullptr;
        if (c == nullptr) continue;
        xy.emplace_back(std::fabs(w.value), c->score.mean());
        stats.push_back(&c->score);
      }
      if (xy.size() < 2) continue;
      const std::vector<double> weights = slope_weights(xy);
      double variance = 0.0;
      for (std::size_t i = 0; i < xy.size(); ++i) {
        const double n = static_cast<double>(stats[i]->count());
        variance += weights[i] * weights[i] * stats[i]->variance() / n;
      }
      TransferSensitivity s;
      s.family = family;
      s.unit = unit_of(p);
      s.controller = nominal.controller;
      s.points_per_ball_lost_per_unit = -fit_line(xy).slope;
      s.ci95_half_width = student_t95(options.balls - 1) * std::sqrt(variance);
      s.worlds = static_cast<int>(xy.size());
      out.push_back(s);
    }
  }
  return out;
}

}  // namespace pinball::bench
