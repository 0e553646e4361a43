// The transfer bench's figure: each controller's score ratio to the spastic
// flipper against each perturbation, one panel per family, the `model` world
// as every family's nominal point (the report: transfer_bench_report.cpp).
#include <algorithm>
#include <cstdio>
#include <map>
#include <stdexcept>

#include "pinball/plot/chart.h"
#include "pinball/plot/png_file.h"
#include "transfer_bench.h"

namespace pinball::bench {
namespace {

// One curve: (value, ratio) points of a controller in a family, by value.
using Curve = std::map<double, double>;

}  // namespace

void plot_transfer_png(const TransferReport& report, const std::string& path) {
  const TransferWorld* model = nullptr;
  for (const TransferWorld& w : report.worlds) {
    if (w.name == "model" && w.played) model = &w;
  }
  if (model == nullptr) throw std::runtime_error(path + ": no model world to plot against");
  std::vector<std::string> names;  // the controllers drawn: all but the baseline, whose ratio is 1
  for (const TransferCell& c : model->cells) {
    if (c.controller != "spastic") names.push_back(c.controller);
  }
  plot::Figure figure;
  figure.title = "Transfer: score ratio to the spastic flipper per perturbation - pinball bench transfer";
  char note[160];
  std::snprintf(note, sizeof(note), "%d balls per cell (seed %llu), each ball cut at %g s;", report.options.balls,
                static_cast<unsigned long long>(report.options.seed), report.options.max_ball_time_s);
  figure.notes = {note, "every controller believes the nominal board; triangle: the nominal world (model)"};
  figure.panel_size = {420, 320};
  figure.share_y = true;  // panels compare
  for (const SweepFamily& f : report.options.sweep) {
    std::map<std::string, Curve> curves;  // by controller
    const std::string family(perturbation_name(f.kind));
    const double nominal = nominal_value(f.kind, report.options);
    for (const TransferCell& c : model->cells) curves[c.controller][nominal] = c.ratio_to_spastic;
    for (const TransferWorld& w : report.worlds) {
      if (!w.played || w.family != family) continue;
      for (const TransferCell& c : w.cells) curves[c.controller][w.value] = c.ratio_to_spastic;
    }
    plot::Panel panel;
    panel.title = family;
    panel.x.label = std::string(perturbation_label(f.kind));
    panel.y.label = "score ratio to spastic";
    panel.references.push_back({.vertical = false,
                                .at = 1.0,
                                .colour = plot::muted_colour(),
                                .line = plot::LineStyle::kSolid,
                                .label = "spastic (= 1)"});
    for (std::size_t k = 0; k < names.size(); ++k) {
      const auto it = curves.find(names[k]);
      if (it == curves.end()) continue;
      plot::Series s;
      s.label = names[k];
      s.colour = plot::palette_colour(static_cast<int>(k));
      s.marker = plot::Marker::kDot;
      for (const auto& [x, y] : it->second) {
        s.x.push_back(x);
        s.y.push_back(y);
      }
      panel.series.push_back(std::move(s));
    }
    // The nominal point (the model world): a triangle at ratio 1.
    plot::Series nominal_point{.label = "nominal world (model)",
                               .colour = plot::muted_colour(),
                               .line = plot::LineStyle::kNone,
                               .marker = plot::Marker::kTriangle};
    nominal_point.x = {nominal};
    nominal_point.y = {1.0};
    panel.series.push_back(std::move(nominal_point));
    figure.panels.push_back(std::move(panel));
  }
  if (figure.panels.empty()) throw std::runtime_error(path + ": no sweep to plot");
  figure.columns = std::min(4, static_cast<int>(figure.panels.size()));
  plot::write_png(plot::render(figure), path);
}

}  // namespace pinball::bench
