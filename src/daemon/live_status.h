#pragma once
// pinballd's one-line live status on stderr while it runs: in lockstep
// simulation the balls played with percent and ETA; paced to the wall clock
// (--realtime) or in the lab, what a person watching the table wants at a
// glance: ball, mean score, frame rate, end-to-end p99, drops and faults.
// A plain function of the report, so that its test needs no threads.

#include <cstdio>
#include <functional>
#include <string>

#include "pinball/daemon/daemon.h"

namespace pinball::daemon {

/// The status line for `report` after `elapsed_s` of wall time; `balls_total`
/// the balls the simulation will play (0: no end, the lab); `lockstep`: the
/// virtual clock, where the line is progress with an ETA.
std::string format_live_status(const DaemonReport& report, int balls_total, bool lockstep, double elapsed_s);

/// Shows format_live_status at most once per interval on a stream (stderr),
/// one line rewritten in place on a terminal. Null stream: nothing.
class LiveStatus {
 public:
  /// On stderr when it is a terminal (or `asked`), else off.
  static LiveStatus for_stderr(int balls_total, bool lockstep, bool asked = false);
  LiveStatus(std::FILE* out, int balls_total, bool lockstep, bool rewrite, double interval_s = 1.0);
  /// From the daemon's main loop: a line when the interval has passed (`report` is called only then).
  void tick(const std::function<DaemonReport()>& report);
  /// The same at a given elapsed time (tests).
  void tick_at(const std::function<DaemonReport()>& report, double elapsed_s);
  /// The last line (the run's end: 100 % in simulation), when any line was
  /// shown, then ends a rewritten line, so that the report starts on its own.
  void finish(const std::function<DaemonReport()>& report);

 private:
  std::FILE* out_;
  int balls_total_;
  bool lockstep_;
  bool rewrite_;
  double interval_s_;
  double start_s_;
  double last_s_ = -1.0;
  bool shown_ = false;
};

}  // namespace pinball::daemon
