// pinballd's live status line: progress with ETA in lockstep, a glance at the
// table paced to the wall clock (src/daemon/live_status.h).

#include "live_status.h"

#include <cstdio>
#include <string>

#include <gtest/gtest.h>

namespace pinball::daemon {
namespace {

DaemonReport report_after(int balls) {
  DaemonReport r;
  r.mode = "sim";
  r.balls = balls;
  r.mean_score = 9193.456;
  r.score_ci95 = 5430.12;
  r.frames = 4000;
  r.frames_dropped = 2;
  r.fault_count = 1;
  r.latency[kFrameToCan] = {100, 120.0, 183.4567, 400.0};
  return r;
}

TEST(LiveStatus, LockstepShowsBallsWithPercentAndEta) {
  EXPECT_EQ(format_live_status(report_after(4), 10, true, 8.0),
            "pinballd: 4/10 balls (40 %), 8 s elapsed, ETA 12 s; mean score 9193 ± 5430 per ball");
}

TEST(LiveStatus, RealtimeShowsTheTableAtAGlance) {
  EXPECT_EQ(format_live_status(report_after(4), 10, false, 20.0),
            "pinballd: 20 s, ball 5/10, mean score 9193 ± 5430 per ball, 200 fps, frame->CAN p99 183 us, "
            "2 frames dropped, 1 faults");
  DaemonReport lab = report_after(0);
  lab.mode = "lab";
  EXPECT_EQ(format_live_status(lab, 0, false, 20.0),
            "pinballd: 20 s, 200 fps, frame->CAN p99 183 us, 2 frames dropped, 1 faults");
}

TEST(LiveStatus, RewritesOneLineAtMostOncePerInterval) {
  char buf[1024] = {};
  std::FILE* f = fmemopen(buf, sizeof buf - 1, "w");
  ASSERT_NE(f, nullptr);
  int reports = 0;
  auto report = [&] {
    ++reports;
    return report_after(reports);
  };
  LiveStatus s(f, 10, true, true, 1.0);
  s.tick_at(report, 1.0);
  s.tick_at(report, 1.5);  // too soon: the report is not even taken
  s.tick_at(report, 2.0);
  s.finish([] { return report_after(10); });  // the end, shown whatever the interval
  std::fclose(f);
  EXPECT_EQ(reports, 2);
  const std::string out = buf;
  EXPECT_EQ(out.rfind("\rpinballd: 1/10 balls (10 %)", 0), 0u) << out;
  EXPECT_NE(out.find("\x1b[K\rpinballd: 2/10 balls (20 %)"), std::string::npos) << out;
  EXPECT_NE(out.find("\x1b[K\rpinballd: 10/10 balls (100 %)"), std::string::npos) << out;
  EXPECT_EQ(out.back(), '\n');
}

// --progress into a file or a pipe: one line per interval and the end, which had been left out.
TEST(LiveStatus, APipeGetsALinePerIntervalAndTheEnd) {
  char buf[1024] = {};
  std::FILE* f = fmemopen(buf, sizeof buf - 1, "w");
  ASSERT_NE(f, nullptr);
  LiveStatus s(f, 3, true, false, 1.0);
  s.tick_at([] { return report_after(0); }, 0.0);
  s.finish([] { return report_after(3); });
  std::fclose(f);
  const std::string out = buf;
  EXPECT_EQ(out.rfind("pinballd: 0/3 balls (0 %)", 0), 0u) << out;
  EXPECT_NE(out.find("\npinballd: 3/3 balls (100 %)"), std::string::npos) << out;
  EXPECT_EQ(out.back(), '\n');
}

}  // namespace
}  // namespace pinball::daemon
