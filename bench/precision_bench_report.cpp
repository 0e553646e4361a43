// The precision bench's report: JSON, CSV, Markdown and the PNG plot (the measurement: precision_bench.cpp).
#include "precision_bench.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <stdexcept>

#include "pinball/plot/chart.h"
#include "pinball/plot/png_file.h"
#include "pinball/sim/event_stepper.h"

namespace pinball::bench {
namespace {

std::string sci(double v, int digits = 2) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.*e", digits - 1, v);
  return buf;
}

}  // namespace

nlohmann::json to_json(const PrecisionReport& report) {
  nlohmann::json points = nlohmann::json::array();
  for (const PrecisionPoint& p : report.points) {
    points.push_back({{"scene", p.scene},
                      {"stepper", p.stepper},
                      {"setting", p.setting},
                      {"max_error_m", p.max_error_m},
                      {"final_error_m", p.final_error_m},
                      {"run_time_s", p.run_time_s},
                      {"steps", p.steps},
                      {"events", p.events}});
  }
  nlohmann::json comparisons = nlohmann::json::array();
  for (const PrecisionComparison& c : report.comparisons) {
    comparisons.push_back({{"scene", c.scene},
                           {"tolerance", c.tolerance},
                           {"event_error_m", c.event_error_m},
                           {"event_time_s", c.event_time_s},
                           {"error_ratio", c.error_ratio},
                           {"error_ratio_extrapolated", c.error_ratio_extrapolated},
                           {"speedup", c.speedup},
                           {"speedup_extrapolated", c.speedup_extrapolated},
                           {"thesis_fit_exponent", c.thesis_fit_exponent},
                           {"thesis_best_error_m", c.thesis_best_error_m},
                           {"thesis_best_time_s", c.thesis_best_time_s},
                           {"best_speedup", c.best_speedup}});
  }
  const PrecisionBenchOptions& o = report.options;
  const PrecisionTargets& t = report.targets;
  nlohmann::json targets = nullptr;
  if (t.evaluated) {
    targets = {{"tolerance", t.tolerance},
               {"worst_closed_form_error_m", t.worst_closed_form_error_m},
               {"worst_scene", t.worst_scene},
               {"error_target_met", t.worst_closed_form_error_m <= 1e-9},
               {"min_error_ratio", t.min_error_ratio},
               {"error_ratio_target_met", t.min_error_ratio >= 1000.0},
               {"min_best_speedup", t.min_best_speedup},
               {"best_speedup_target_met", t.min_best_speedup >= 100.0},
               {"min_fit_speedup", std::isfinite(t.min_fit_speedup) ? nlohmann::json(t.min_fit_speedup) : nullptr}};
  }
  return {{"benchmark", "precision"},
          {"horizon_s", o.horizon_s},
          {"event_step_s", o.event_step_s},
          {"event_rest_height_m", o.event_rest_height_m},
          {"table_horizon_s", o.table_horizon_s},
          {"table_reference_tolerance", o.table_reference_tolerance},
          {"table_reference_step_s", o.table_reference_step_s},
          {"repeats", o.repeats},
          {"error_floor_m", kPrecisionErrorFloor_m},
          {"points", points},
          {"comparisons", comparisons},
          {"targets", targets}};
}

std::string to_csv(const PrecisionReport& report) {
  std::ostringstream out;
  out << "scene,stepper,setting,max_error_m,final_error_m,run_time_s\n";
  out.precision(6);
  for (const PrecisionPoint& p : report.points) {
    out << p.scene << ',' << p.stepper << ',' << p.setting << ',' << p.max_error_m << ',' << p.final_error_m << ','
        << p.run_time_s << '\n';
  }
  return out.str();
}

std::string to_markdown(const PrecisionReport& report) {
  std::vector<std::string> scenes;
  for (const PrecisionPoint& p : report.points) {
    if (std::find(scenes.begin(), scenes.end(), p.scene) == scenes.end()) scenes.push_back(p.scene);
  }
  std::ostringstream out;
  for (const std::string stepper : {"thesis", "event"}) {
    std::map<double, std::map<std::string, const PrecisionPoint*>, std::greater<>> rows;
    for (const PrecisionPoint& p : report.points) {
      if (p.stepper == stepper) rows[p.setting][p.scene] = &p;
    }
    if (rows.empty()) continue;
    out << "| " << (stepper == std::string("thesis") ? "thesis dt (s)" : "event tolerance") << " |";
    for (const std::string& s : scenes) out << ' ' << s << " |";
    out << "\n|---|";
    for (std::size_t i = 0; i < scenes.size(); ++i) out << "---:|";
    out << '\n';
    for (const auto& [setting, by_scene] : rows) {
      out << "| " << sci(setting, 1) << " |";
      for (const std::string& s : scenes) {
        const auto it = by_scene.find(s);
        out << ' ';
        if (it != by_scene.end()) out << sci(it->second->max_error_m) << " m / " << sci(it->second->run_time_s) << " s";
        out << " |";
      }
      out << '\n';
    }
    out << '\n';
  }
  if (report.comparisons.empty()) return out.str();
  // Headline at the event stepper's default tolerance.
  const double tol = sim::EventStepperOptions{}.relative_tolerance;
  out << "| scene (event tolerance " << sci(tol, 1) << ") | event error (m) | event run time (s) | thesis error at "
      << "equal run time (m) | error ratio | thesis best error (m) at run time (s) | speed-up over thesis best "
      << "(measured) | speed-up at equal error (power-law fit) |\n|---|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const PrecisionComparison& c : report.comparisons) {
    if (c.tolerance != tol) continue;
    out << "| " << c.scene << " | " << sci(c.event_error_m) << " | " << sci(c.event_time_s) << " | "
        << sci(c.error_ratio * std::max(c.event_error_m, kPrecisionErrorFloor_m))
        << (c.error_ratio_extrapolated ? "*" : "") << " | " << sci(c.error_ratio) << " | " << sci(c.thesis_best_error_m) << " at " << sci(c.thesis_best_time_s)
        << " | " << sci(c.best_speedup) << " | ";
    if (std::isfinite(c.speedup)) {
      out << sci(c.speedup) << (c.speedup_extrapolated ? "*" : "") << " (p = " << sci(c.thesis_fit_exponent) << ")";
    } else {
      out << "never (p = " << sci(c.thesis_fit_exponent) << ")";
    }
    out << " |\n";
  }
  const PrecisionTargets& tg = report.targets;
  if (tg.evaluated) {
    auto met = [](bool ok) { return ok ? "met" : "NOT met"; };
    out << "| target (event tolerance " << sci(tg.tolerance, 1) << ") | measured | |\n|---|---:|---|\n"
        << "| event error <= 1e-9 m on every closed-form scene | " << sci(tg.worst_closed_form_error_m) << " m ("
        << tg.worst_scene << ") | " << met(tg.worst_closed_form_error_m <= 1e-9) << " |\n"
        << "| error >= 1000x lower at equal run time | " << sci(tg.min_error_ratio) << "x | "
        << met(tg.min_error_ratio >= 1000.0) << " |\n"
        << "| >= 100x faster at equal error (over the thesis's best, measured) | " << sci(tg.min_best_speedup)
        << "x | " << met(tg.min_best_speedup >= 100.0) << " |\n"
        << "| ... at equal error by power-law extrapolation | " << sci(tg.min_fit_speedup) << "x | "
        << met(tg.min_fit_speedup >= 100.0) << " |\n";
  }
  out << "\n| event tolerance |";
  for (const std::string& s : scenes) out << ' ' << s << " |";
  out << "\n|---|";
  for (std::size_t i = 0; i < scenes.size(); ++i) out << "---:|";
  out << '\n';
  std::map<double, std::map<std::string, const PrecisionComparison*>, std::greater<>> rows;
  for (const PrecisionComparison& c : report.comparisons) rows[c.tolerance][c.scene] = &c;
  for (const auto& [t, by_scene] : rows) {
    out << "| " << sci(t, 1) << " |";
    for (const std::string& s : scenes) {
      const auto it = by_scene.find(s);
      out << ' ';
      if (it != by_scene.end()) {
        const PrecisionComparison& c = *it->second;
        out << sci(c.error_ratio) << (c.error_ratio_extrapolated ? "*" : "") << " / " << sci(c.best_speedup);
      }
      out << " |";
    }
    out << '\n';
  }
  return out.str();
}

void plot_precision_png(const PrecisionReport& report, const std::string& path) {
  plot::Figure figure;
  figure.title = "Precision: max position error against run time per scene - pinball bench precision";
  char note[200];
  std::snprintf(note, sizeof(note),
                "log-log; thesis stepper over its dt sweep, event stepper over its tolerance sweep; "
                "errors below %g m drawn at %g m",
                kPrecisionErrorFloor_m, kPrecisionErrorFloor_m);
  figure.notes = {note};
  figure.panel_size = {470, 360};
  figure.share_x = figure.share_y = true;  // panels compare
  for (const PrecisionPoint& p : report.points) {
    const auto same_scene = [&](const plot::Panel& panel) { return panel.title == p.scene; };
    auto panel = std::find_if(figure.panels.begin(), figure.panels.end(), same_scene);
    if (panel == figure.panels.end()) {
      plot::Panel fresh;
      fresh.title = p.scene;
      fresh.x = {.label = "run time (s)", .log = true};
      fresh.y = {.label = "max position error (m)", .log = true};
      const plot::LineStyle solid = plot::LineStyle::kSolid;
      fresh.series = {{.label = "thesis (dt sweep)", .colour = plot::palette_colour(0), .line = solid,
                       .marker = plot::Marker::kCircle, .thickness_px = 1},
                      {.label = "event (tolerance sweep)", .colour = plot::palette_colour(1), .line = solid,
                       .marker = plot::Marker::kSquare, .thickness_px = 1}};
      figure.panels.push_back(std::move(fresh));
      panel = figure.panels.end() - 1;
    }
    // In sweep order, so a curve runs from coarse to fine.
    plot::Series& s = panel->series[p.stepper == "thesis" ? 0 : 1];
    s.x.push_back(p.run_time_s);
    s.y.push_back(std::max(p.max_error_m, kPrecisionErrorFloor_m));
  }
  if (figure.panels.empty()) throw std::runtime_error(path + ": nothing to plot");
  figure.columns = std::min(3, static_cast<int>(figure.panels.size()));
  plot::write_png(plot::render(figure), path);
}

}  // namespace pinball::bench
