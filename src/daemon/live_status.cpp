#include "live_status.h"

#include <chrono>

#include <unistd.h>

#include "pinball/core/format.h"
#include "pinball/core/progress.h"

namespace pinball::daemon {

namespace {

double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

std::string format_live_status(const DaemonReport& r, int balls_total, bool lockstep, double elapsed_s) {
  std::string score;
  if (r.balls == 1) score = "mean score " + format_number(r.mean_score, 4) + " per ball";  // no interval yet
  if (r.balls > 1) score = "mean score " + format_mean_ci(r.mean_score, r.score_ci95) + " per ball";
  if (lockstep && balls_total > 0) return format_progress("pinballd", r.balls, balls_total, "balls", elapsed_s, score);
  std::string line = "pinballd: " + format_duration(elapsed_s);
  if (r.mode == "sim") {
    line += ", ball " + std::to_string(r.balls + 1);
    if (balls_total > 0) line += "/" + std::to_string(balls_total);
    if (!score.empty()) line += ", " + score;
  }
  const double fps = elapsed_s > 0.0 ? static_cast<double>(r.frames) / elapsed_s : 0.0;
  line += ", " + format_number(fps) + " fps";
  const LatencySummary& e2e = r.latency[kFrameToCan];
  if (e2e.count > 0) line += ", frame->CAN p99 " + format_number(e2e.p99_us) + " us";
  line += ", " + std::to_string(r.frames_dropped) + " frames dropped, " + std::to_string(r.fault_count) + " faults";
  return line;
}

LiveStatus LiveStatus::for_stderr(int balls_total, bool lockstep, bool asked) {
  const bool tty = ::isatty(STDERR_FILENO) == 1;
  return LiveStatus(progress_wanted(asked) ? stderr : nullptr, balls_total, lockstep, tty);
}

LiveStatus::LiveStatus(std::FILE* out, int balls_total, bool lockstep, bool rewrite, double interval_s)
    : out_(out), balls_total_(balls_total), lockstep_(lockstep), rewrite_(rewrite), interval_s_(interval_s),
      start_s_(now_s()) {}

void LiveStatus::tick(const std::function<DaemonReport()>& report) { tick_at(report, now_s() - start_s_); }

void LiveStatus::tick_at(const std::function<DaemonReport()>& report, double elapsed_s) {
  if (!out_ || (last_s_ >= 0.0 && elapsed_s - last_s_ < interval_s_)) return;
  last_s_ = elapsed_s;
  const std::string line = format_live_status(report(), balls_total_, lockstep_, elapsed_s);
  if (rewrite_) {
    std::fprintf(out_, "\r%s\x1b[K", line.c_str());
  } else {
    std::fprintf(out_, "%s\n", line.c_str());
  }
  std::fflush(out_);
  shown_ = true;
}

void LiveStatus::finish(const std::function<DaemonReport()>& report) {
  if (out_ && shown_) {
    last_s_ = -1.0;  // shown whatever the interval: a script's log had ended at "0/3 balls"
    tick_at(report, now_s() - start_s_);
    if (rewrite_) std::fputs("\n", out_);
    std::fflush(out_);
  }
  shown_ = false;
}

}  // namespace pinball::daemon
