#pragma once
// Percent done and time left of a long run, shown on stderr by `pinball sim`,
// `pinball learn`, `pinball bench` and pinballd's balls. One estimate (the
// rate so far, elapsed / done, times what is left) and one format:
//   "sim: 40/100 balls (40 %), 12 s elapsed, ETA 18 s; mean score 8120"
// Shown only when stderr is a terminal or --progress asks for it, so that a
// script's stderr stays quiet; stdout (the report, the JSON) never sees it.

#include <chrono>
#include <functional>
#include <iosfwd>
#include <mutex>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace pinball {

/// A duration for people: "850 ms", "12 s", "3 min 05 s", "2 h 04 min"; "?" when not finite or negative.
std::string format_duration(double s);

/// The progress line for `done` of `total` `unit` after `elapsed_s`, with an
/// optional note after a semicolon. The ETA is left out until something is
/// done; the percent is rounded down, so 100 % means finished. `done_in_no_time`
/// of the done units took none of the time (taken from a checkpoint): the ETA
/// comes from the rate of the others. `eta_s`, when given, is the ETA instead.
std::string format_progress(std::string_view label, double done, double total, std::string_view unit,
                            double elapsed_s, std::string_view note = {}, double done_in_no_time = 0.0,
                            std::optional<double> eta_s = std::nullopt);

/// Work of one kind among several that run at different rates (a twin ball
/// costs many model balls): its units in all, done, and the wall time spent on them (s).
struct KindProgress {
  double total = 0.0;
  double done = 0.0;
  double wall_s = 0.0;
};

/// The time left (s): each kind's units left at that kind's own rate, or at
/// `fallback_s_per_unit` (the rate over everything so far) while none of it
/// is done. One rate over every unit had put a bench's ETA far off.
double eta_by_kind_s(std::span<const KindProgress> kinds, double fallback_s_per_unit);

/// Whether to show progress: asked for (--progress), or stderr is a terminal.
bool progress_wanted(bool asked);

/// Reports progress on a stream at most once per interval, and always when
/// the run finishes; on a terminal one line rewritten in place, otherwise one
/// line per report. A null stream shows nothing.
class ProgressMeter {
 public:
  /// `out` borrowed for the meter's life; `rewrite`: overwrite one line (a terminal).
  ProgressMeter(std::ostream* out, std::string label, double total, std::string unit, bool rewrite = false,
                double interval_s = 1.0);
  /// `done` units finished so far, on the steady clock.
  void update(double done, std::string_view note = {});
  /// The same at a given elapsed time (tests).
  void update_at(double done, double elapsed_s, std::string_view note = {});
  /// Seconds since the meter was made.
  double elapsed_s() const;

 private:
  std::ostream* out_;
  std::string label_;
  double total_;
  std::string unit_;
  bool rewrite_;
  double interval_s_;
  std::chrono::steady_clock::time_point start_;
  double last_shown_s_ = -1.0;
  bool finished_ = false;
};

/// Units finished by worker threads, counted and reported in order: the count
/// and its report share one lock, so a line never shows fewer units than the
/// line before it (two threads finishing together once printed "10/10" and
/// then "9/10"). `report(done, elapsed_s)` runs for every `every`-th unit and
/// for the `total`-th; an empty `report` only counts.
class SharedProgress {
 public:
  SharedProgress(long total, long every, std::function<void(long done, double elapsed_s)> report);
  /// One more unit finished (any thread).
  void one_done();
  /// Units finished so far.
  long done() const;

 private:
  long total_;
  long every_;
  std::function<void(long, double)> report_;
  mutable std::mutex mutex_;
  long done_ = 0;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

}  // namespace pinball
