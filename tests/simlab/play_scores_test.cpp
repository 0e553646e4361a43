#include "pinball/simlab/play_scores.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <string>

#include "common/error_text.h"
#include "common/temp_path.h"
#include "pinball/core/text_file.h"

namespace pinball::simlab {
namespace {

using pinball::testing::temp_path;

PlayRow row(const std::string& player, int ball, double score) {
  PlayRow r;
  r.player = player;
  r.date = "2026-12-02T13:45:21Z";
  r.board = "boards/mit1993.board";
  r.world = "thesis";
  r.ball = ball;
  r.score = score;
  r.duration_s = 12.25;
  return r;
}

std::string error_of(const std::string& path) {
  return pinball::testing::error_text([&] { read_play_csv(path); });
}

TEST(PlayScores, RowsRoundTripAndTheHeaderIsWrittenOnce) {
  const std::string path = temp_path("play_scores", "round_trip.csv");
  std::remove(path.c_str());
  check_play_csv_appendable(path);
  append_play_rows(path, {row("ada", 1, 1234.5)});
  PlayRow cut = row("bob", 1, 0.0);
  cut.cut = true;
  cut.world = "event";
  append_play_rows(path, {cut, row("ada", 2, 8388.0)});
  check_play_csv_appendable(path);
  const auto rows = read_play_csv(path);
  ASSERT_EQ(rows.size(), 3u);
  EXPECT_EQ(rows[0].player, "ada");
  EXPECT_EQ(rows[0].date, "2026-12-02T13:45:21Z");
  EXPECT_EQ(rows[0].board, "boards/mit1993.board");
  EXPECT_DOUBLE_EQ(rows[0].score, 1234.5);
  EXPECT_DOUBLE_EQ(rows[0].duration_s, 12.25);
  EXPECT_FALSE(rows[0].cut);
  EXPECT_EQ(rows[1].world, "event");
  EXPECT_TRUE(rows[1].cut);
  EXPECT_EQ(rows[2].ball, 2);
  std::ifstream in(path);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text.find(kPlayCsvHeader), 0u);
  EXPECT_EQ(text.find(kPlayCsvHeader, 1), std::string::npos);
  std::remove(path.c_str());
}

// A file whose last row lacks its line end (saved by an editor) took the next row on the same
// line, and --stats refused it for good; the append ends that row first.
TEST(PlayScores, AnAppendAfterARowWithoutALineEndStartsANewLine) {
  const std::string path = temp_path("play_scores", "no_newline.csv");
  {
    std::ofstream out(path, std::ios::trunc);
    out << kPlayCsvHeader << "\nada,2026-12-02T13:45:21Z,b,thesis,1,100,3,0";
  }
  append_play_rows(path, {row("bob", 1, 250.0)});
  const auto rows = read_play_csv(path);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].player, "ada");
  EXPECT_EQ(rows[1].player, "bob");
  std::remove(path.c_str());
}

// A disk that fills in the middle of a row (here a file size limit, EFBIG): the append fails
// and takes back what it wrote, so the file stays readable for the next session and --stats.
TEST(PlayScores, AFailedAppendLeavesNoHalfRow) {
  const std::string path = temp_path("play_scores", "full_disk.csv");
  std::remove(path.c_str());
  append_play_rows(path, {row("ada", 1, 1234.5)});
  const std::string before = read_text_file(path);
  const pid_t pid = fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {  // the limit and the signal in a child: the test process keeps its own
    std::signal(SIGXFSZ, SIG_IGN);
    const rlimit limit{static_cast<rlim_t>(before.size() + 20), static_cast<rlim_t>(before.size() + 20)};
    setrlimit(RLIMIT_FSIZE, &limit);
    try {
      append_play_rows(path, {row("bob", 1, 8388.0), row("bob", 2, 99.0)});
    } catch (const std::runtime_error&) {
      _exit(3);
    }
    _exit(0);
  }
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 3) << "the append past the limit did not fail";
  EXPECT_EQ(read_text_file(path), before) << "half a row was left";
  EXPECT_EQ(read_play_csv(path).size(), 1u);
  std::remove(path.c_str());
}

TEST(PlayScores, StatsMatchAHandComputation) {
  // ada: 1000, 2000, 6000: mean 3000, s² = (4e6 + 1e6 + 9e6)/2 = 7e6, half-width t(2)·s/√3.
  const auto stats = play_stats({row("ada", 1, 1000), row("bob", 1, 500), row("ada", 2, 2000), row("ada", 3, 6000)});
  ASSERT_EQ(stats.size(), 3u);
  EXPECT_EQ(stats[0].player, "ada");
  EXPECT_EQ(stats[0].balls, 3);
  EXPECT_DOUBLE_EQ(stats[0].mean_score, 3000.0);
  EXPECT_NEAR(stats[0].ci95_half_width, 4.302653 * std::sqrt(7e6) / std::sqrt(3.0), 0.5);
  EXPECT_DOUBLE_EQ(stats[0].max_score, 6000.0);
  EXPECT_EQ(stats[1].player, "bob");
  EXPECT_EQ(stats[1].balls, 1);
  EXPECT_TRUE(std::isinf(stats[1].ci95_half_width));  // one ball: no interval
  EXPECT_EQ(stats[2].player, "all");
  EXPECT_EQ(stats[2].balls, 4);
  EXPECT_DOUBLE_EQ(stats[2].mean_score, 9500.0 / 4.0);
  EXPECT_TRUE(play_stats({}).empty());
}

TEST(PlayScores, ABadRowIsNamedByFileAndLine) {
  const std::string path = temp_path("play_scores", "bad.csv");
  std::ofstream(path) << kPlayCsvHeader << "\n"
                      << "ada,2026-12-02T13:45:21Z,b.board,thesis,1,100,3.5,0\n"
                      << "ada,2026-12-02T13:46:00Z,b.board,thesis,2,lots,3.5,0\n";
  EXPECT_EQ(error_of(path), path + ":3: column 'score' must be a number >= 0, got 'lots'");
  std::ofstream(path) << kPlayCsvHeader << "\nada,2026,b,thesis,1,100\n";
  EXPECT_EQ(error_of(path), path + ":2: expected 8 columns, got 6");
  std::ofstream(path) << kPlayCsvHeader << "\nada,2026-12-02T13:45:21Z,b,thesis,1,100,3,yes\n";
  EXPECT_EQ(error_of(path), path + ":2: column 'cut' must be 0 or 1, got 'yes'");
  // Another file's columns in the right number: a date that is not one, a world no command plays.
  std::ofstream(path) << kPlayCsvHeader << "\nada,2026,b,thesis,1,100,3,0\n";
  EXPECT_EQ(error_of(path), path + ":2: column 'date' must be a UTC date like 2026-12-02T13:45:21Z, got '2026'");
  std::ofstream(path) << kPlayCsvHeader << "\nada,2026-12-02T13:45:21Z,b,mujoco,1,100,3,0\n";
  EXPECT_EQ(error_of(path), path + ":2: column 'world' must be thesis, event or twin, got 'mujoco'");
  std::ofstream(path) << kPlayCsvHeader << "\nada,2026-12-02T13:45:21Z,,thesis,1,100,3,0\n";
  EXPECT_EQ(error_of(path), path + ":2: column 'board' is empty");
  std::ofstream(path) << "t,x,y\n";
  EXPECT_NE(error_of(path).find(path + ":1: the header must be"), std::string::npos);
  EXPECT_THROW(check_play_csv_appendable(path), std::runtime_error);  // not a score file: never appended to
  std::remove(path.c_str());
  EXPECT_EQ(error_of(path), path + ": cannot open the score file");
}

TEST(PlayScores, AnUnwritablePlaceAndBadNamesAreRefused) {
  EXPECT_THROW(check_play_csv_appendable("/nonexistent-folder/scores.csv"), std::runtime_error);
  EXPECT_THROW(check_play_csv_appendable(::testing::TempDir()), std::runtime_error);  // a folder
  PlayRow named = row("Ada L.", 1, 0.0);
  EXPECT_NO_THROW(check_play_row(named));
  named.player = "";
  EXPECT_THROW(check_play_row(named), std::invalid_argument);
  named.player = "smith, j";
  EXPECT_THROW(check_play_row(named), std::invalid_argument);
  EXPECT_THROW(append_play_rows(temp_path("play_scores", "never.csv"), {named}), std::invalid_argument);
  named.player = "ada";
  named.board = "my,board";
  EXPECT_THROW(check_play_row(named), std::invalid_argument);
}

}  // namespace
}  // namespace pinball::simlab
