#include "pinball/learn/learning_curve.h"

#include <sstream>

#include "pinball/core/text_file.h"
#include "pinball/plot/chart.h"

namespace pinball::learn {

void write_curve_csv(const SearchResult& r, const std::string& path) {
  std::ostringstream f;
  f << "method,generation,balls,population_mean,generation_best,best_so_far,wall_s,population_ci95\n";
  for (const CurvePoint& p : r.curve) {
    f << r.method << ',' << p.generation << ',' << p.balls << ',' << p.population_mean << ',' << p.generation_best
      << ',' << p.best_so_far << ',' << p.wall_s << ',' << p.population_ci95 << '\n';
  }
  write_text_file(path, f.str());  // whole or not at all: a full disk is an error, not a cut file
}

cv::Mat draw_curve(const SearchResult& r) {
  plot::Figure figure;
  figure.title = "Learning curve of " + r.method + ": mean score per ball - pinball learn";
  figure.notes = {"population: the mean over each generation's balls, band: its 95 % interval (Student's t)",
                  "generation best and best so far: the controllers' estimated means"};
  plot::Panel panel;
  panel.x.label = "balls played";
  panel.x.lo = 0.0;
  panel.y.label = "mean score per ball";
  panel.y.include_zero = true;
  plot::Series population{.label = "population mean (95 % interval)", .colour = plot::palette_colour(0)};
  population.interval = plot::IntervalStyle::kBand;
  plot::Series generation{
      .label = "generation best", .colour = plot::palette_colour(1), .line = plot::LineStyle::kDashed};
  plot::Series best{.label = "best so far", .colour = plot::palette_colour(2)};
  for (const CurvePoint& p : r.curve) {
    const double balls = static_cast<double>(p.balls);
    population.x.push_back(balls);
    population.y.push_back(p.population_mean);
    population.y_low.push_back(p.population_mean - p.population_ci95);
    population.y_high.push_back(p.population_mean + p.population_ci95);
    generation.x.push_back(balls);
    generation.y.push_back(p.generation_best);
    best.x.push_back(balls);
    best.y.push_back(p.best_so_far);
  }
  // A single generation draws as markers: a line needs two points.
  if (r.curve.size() < 2) population.marker = generation.marker = best.marker = plot::Marker::kCircle;
  panel.series = {population, generation, best};
  figure.panels.push_back(std::move(panel));
  return plot::render(figure);
}

}  // namespace pinball::learn
