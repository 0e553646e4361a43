#include "pinball/core/progress.h"

#include <cmath>
#include <cstdio>
#include <ostream>

#include <utility>

#include <unistd.h>

namespace pinball {

std::string format_duration(double s) {
  if (!std::isfinite(s) || s < 0.0) return "?";
  char buf[32];
  if (s < 1.0) {
    std::snprintf(buf, sizeof buf, "%.0f ms", s * 1e3);
  } else if (s < 60.0) {
    std::snprintf(buf, sizeof buf, "%.0f s", std::floor(s));
  } else if (s < 3600.0) {
    const long t = std::lround(std::floor(s));
    std::snprintf(buf, sizeof buf, "%ld min %02ld s", t / 60, t % 60);
  } else {
    const long t = std::lround(std::floor(s / 60.0));
    std::snprintf(buf, sizeof buf, "%ld h %02ld min", t / 60, t % 60);
  }
  return buf;
}

namespace {

std::string format_count(double x) {
  char buf[32];
  if (x == std::floor(x) && std::fabs(x) < 1e15) {
    std::snprintf(buf, sizeof buf, "%.0f", x);
  } else {
    std::snprintf(buf, sizeof buf, "%.1f", x);
  }
  return buf;
}

}  // namespace

std::string format_progress(std::string_view label, double done, double total, std::string_view unit,
                            double elapsed_s, std::string_view note, double done_in_no_time,
                            std::optional<double> eta_s) {
  // Appended piece by piece: GCC 12 warns (-Wrestrict, a false positive) on "a" + b + "c" chains here.
  std::string line(label);
  line.append(": ").append(format_count(done)).append("/").append(format_count(total));
  if (!unit.empty()) line.append(" ").append(unit);
  if (total > 0.0) {
    const double pct = std::floor(std::fmin(100.0, 100.0 * done / total));
    line.append(" (").append(format_count(pct)).append(" %)");
  }
  line.append(", ").append(format_duration(elapsed_s)).append(" elapsed");
  const double done_in_time = done - done_in_no_time;
  if (eta_s && total > done) {
    line.append(", ETA ").append(format_duration(*eta_s));
  } else if (done_in_time > 0.0 && total > done) {
    line.append(", ETA ").append(format_duration(elapsed_s / done_in_time * (total - done)));
  }
  if (!note.empty()) line.append("; ").append(note);
  return line;
}

double eta_by_kind_s(std::span<const KindProgress> kinds, double fallback_s_per_unit) {
  double eta_s = 0.0;
  for (const KindProgress& k : kinds) {
    const double left = std::fmax(0.0, k.total - k.done);
    eta_s += left * (k.done > 0.0 ? k.wall_s / k.done : fallback_s_per_unit);
  }
  return eta_s;
}

bool progress_wanted(bool asked) { return asked || ::isatty(STDERR_FILENO) == 1; }

ProgressMeter::ProgressMeter(std::ostream* out, std::string label, double total, std::string unit, bool rewrite,
                             double interval_s)
    : out_(out),
      label_(std::move(label)),
      total_(total),
      unit_(std::move(unit)),
      rewrite_(rewrite),
      interval_s_(interval_s),
      start_(std::chrono::steady_clock::now()) {}

double ProgressMeter::elapsed_s() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void ProgressMeter::update(double done, std::string_view note) { update_at(done, elapsed_s(), note); }

void ProgressMeter::update_at(double done, double elapsed_s, std::string_view note) {
  if (!out_ || finished_) return;
  const bool last = done >= total_;
  if (!last && last_shown_s_ >= 0.0 && elapsed_s - last_shown_s_ < interval_s_) return;
  last_shown_s_ = elapsed_s;
  const std::string line = format_progress(label_, done, total_, unit_, elapsed_s, note);
  if (rewrite_) {
    *out_ << "\r" << line << "\x1b[K" << (last ? "\n" : "") << std::flush;
  } else {
    *out_ << line << "\n" << std::flush;
  }
  finished_ = last;
}

SharedProgress::SharedProgress(long total, long every, std::function<void(long, double)> report)
    : total_(total), every_(every < 1 ? 1 : every), report_(std::move(report)) {}

void SharedProgress::one_done() {
  const std::lock_guard<std::mutex> lock(mutex_);
  const long d = ++done_;
  if (report_ && (d % every_ == 0 || d == total_)) {
    report_(d, std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count());
  }
}

long SharedProgress::done() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return done_;
}

}  // namespace pinball
