// The precision bench's report: JSON, CSV, Markdown and the PNG plot (the measurement: precision_bench.cpp).
#include "precision_bench.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <stdexcept>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

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
  std::vector<std::string> scenes;
  double t_lo = 1e300, t_hi = 0.0, e_lo = 1e300, e_hi = 0.0;
  for (const PrecisionPoint& p : report.points) {
    if (std::find(scenes.begin(), scenes.end(), p.scene) == scenes.end()) scenes.push_back(p.scene);
    const double e = std::max(p.max_error_m, kPrecisionErrorFloor_m);
    t_lo = std::min(t_lo, p.run_time_s);
    t_hi = std::max(t_hi, p.run_time_s);
    e_lo = std::min(e_lo, e);
    e_hi = std::max(e_hi, e);
  }
  if (scenes.empty()) throw std::runtime_error(path + ": nothing to plot");
  // Whole decades around the data, shared by every panel so that panels compare.
  const int tx0 = static_cast<int>(std::floor(std::log10(std::max(t_lo, 1e-12))));
  const int tx1 = std::max(tx0 + 1, static_cast<int>(std::ceil(std::log10(std::max(t_hi, 1e-12)))));
  const int ey0 = static_cast<int>(std::floor(std::log10(e_lo)));
  const int ey1 = std::max(ey0 + 1, static_cast<int>(std::ceil(std::log10(e_hi))));
  constexpr int kPanelW = 460, kPanelH = 360, kCols = 3, kLeft = 62, kRight = 26, kTop = 30, kBottom = 44;
  constexpr int kHeader = 40;
  const int rows = (static_cast<int>(scenes.size()) + kCols - 1) / kCols;
  cv::Mat img(kHeader + rows * kPanelH, kCols * kPanelW, CV_8UC3, cv::Scalar(255, 255, 255));
  const cv::Scalar black(0, 0, 0), grey(215, 215, 215), thesis_colour(200, 90, 0), event_colour(0, 0, 210);
  const auto font = cv::FONT_HERSHEY_SIMPLEX;
  cv::putText(img, "max position error (m) against run time (s), log-log; blue o: thesis (dt sweep), red []: event (tolerance sweep)",
              cv::Point(10, 26), font, 0.5, black, 1, cv::LINE_AA);
  for (std::size_t k = 0; k < scenes.size(); ++k) {
    const int ox = static_cast<int>(k % kCols) * kPanelW;
    const int oy = kHeader + static_cast<int>(k / kCols) * kPanelH;
    const int w = kPanelW - kLeft - kRight, h = kPanelH - kTop - kBottom;
    auto to_px = [&](double t, double e) {
      const double fx = (std::log10(t) - tx0) / (tx1 - tx0);
      const double fy = (std::log10(std::max(e, kPrecisionErrorFloor_m)) - ey0) / (ey1 - ey0);
      return cv::Point(ox + kLeft + static_cast<int>(w * fx), oy + kTop + h - static_cast<int>(h * fy));
    };
    char label[32];
    for (int d = tx0; d <= tx1; ++d) {
      const cv::Point a = to_px(std::pow(10.0, d), std::pow(10.0, ey0));
      cv::line(img, a, to_px(std::pow(10.0, d), std::pow(10.0, ey1)), grey, 1);
      std::snprintf(label, sizeof(label), "1e%d", d);
      cv::putText(img, label, a + cv::Point(-14, 16), font, 0.38, black, 1, cv::LINE_AA);
    }
    const int ey_step = std::max(1, (ey1 - ey0 + 7) / 8);  // at most ~8 labelled decades
    for (int d = ey0; d <= ey1; ++d) {
      const cv::Point a = to_px(std::pow(10.0, tx0), std::pow(10.0, d));
      cv::line(img, a, to_px(std::pow(10.0, tx1), std::pow(10.0, d)), grey, 1);
      if ((d - ey0) % ey_step != 0) continue;
      std::snprintf(label, sizeof(label), "1e%d", d);
      cv::putText(img, label, a + cv::Point(-44, 4), font, 0.38, black, 1, cv::LINE_AA);
    }
    cv::rectangle(img, to_px(std::pow(10.0, tx0), std::pow(10.0, ey1)), to_px(std::pow(10.0, tx1), std::pow(10.0, ey0)),
                  black, 1);
    cv::putText(img, scenes[k] + ": error (m)", cv::Point(ox + kLeft - 40, oy + kTop - 8), font, 0.5, black, 1,
                cv::LINE_AA);
    cv::putText(img, "run time (s)", cv::Point(ox + kLeft + w / 2 - 40, oy + kPanelH - 8), font, 0.4, black, 1,
                cv::LINE_AA);
    for (const std::string stepper : {"thesis", "event"}) {
      std::vector<cv::Point> pts;  // in sweep order, so a curve runs from coarse to fine
      for (const PrecisionPoint& p : report.points) {
        if (p.scene == scenes[k] && p.stepper == stepper) pts.push_back(to_px(p.run_time_s, p.max_error_m));
      }
      const bool is_thesis = stepper == std::string("thesis");
      const cv::Scalar colour = is_thesis ? thesis_colour : event_colour;
      if (pts.size() >= 2) cv::polylines(img, pts, false, colour, 1, cv::LINE_AA);
      for (const cv::Point& q : pts) {
        if (is_thesis) {
          cv::circle(img, q, 4, colour, 1, cv::LINE_AA);
        } else {
          cv::rectangle(img, q - cv::Point(3, 3), q + cv::Point(3, 3), colour, 1);
        }
      }
    }
    // Legend in each panel's top right corner.
    const cv::Point lg(ox + kPanelW - kRight - 90, oy + kTop + 16);
    cv::circle(img, lg, 4, thesis_colour, 1, cv::LINE_AA);
    cv::putText(img, "thesis", lg + cv::Point(10, 4), font, 0.4, thesis_colour, 1, cv::LINE_AA);
    cv::rectangle(img, lg + cv::Point(-3, 15), lg + cv::Point(3, 21), event_colour, 1);
    cv::putText(img, "event", lg + cv::Point(10, 22), font, 0.4, event_colour, 1, cv::LINE_AA);
  }
  if (!cv::imwrite(path, img)) throw std::runtime_error(path + ": cannot write PNG");
}

}  // namespace pinball::bench
