#include "pinball/track/observation_io.h"

#include <gtest/gtest.h>

#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/error_text.h"
#include "common/temp_path.h"

namespace pinball::track {
namespace {

std::string write_csv(const std::string& name, const std::string& text) {
  const std::string path = pinball::testing::temp_path("observation_io", name);
  std::ofstream(path) << text;
  return path;
}

std::string read_error(const std::string& path) {
  return pinball::testing::error_text([&] { read_observations_csv(path); });
}

TEST(ObservationIo, ReadsPositionsAndContacts) {
  const auto plain = read_observations_csv(write_csv("plain.csv", "t,x,y\n0,0.1,0.2\n0.005,0.1,0.19\n"));
  ASSERT_EQ(plain.size(), 2u);
  EXPECT_DOUBLE_EQ(plain[1].observation.t_s, 0.005);
  EXPECT_DOUBLE_EQ(plain[1].observation.p_board.y(), 0.19);
  EXPECT_FALSE(plain[1].contacts.left);
  const auto contacts = read_observations_csv(
      write_csv("contacts.csv", "t,x,y,left_contact,right_contact\n0,0.1,0.2,1,0\n"));
  ASSERT_EQ(contacts.size(), 1u);
  EXPECT_TRUE(contacts[0].contacts.left);
  EXPECT_FALSE(contacts[0].contacts.right);
}

// `pinball sim --trace` feeds `pinball track` as it is: positions read,
// velocity and events (one field, '|' between several) left out.
TEST(ObservationIo, ReadsASimTrace) {
  const auto rows = read_observations_csv(write_csv(
      "trace.csv", "t,x,y,vx,vy,event\n0.0005,0.45,0.05,0,1.2,launch\n0.001,0.45,0.0506,0,1.19,hit:post|bank:b\n"));
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_DOUBLE_EQ(rows[1].observation.p_board.x(), 0.45);
  EXPECT_DOUBLE_EQ(rows[1].observation.p_board.y(), 0.0506);
  // Balls after the first: the lost one and the next one served share a time; the served one stands.
  const auto balls = read_observations_csv(write_csv(
      "balls.csv", "t,x,y,vx,vy,event\n5.0,0.25,0.01,0,-1,\n5.0005,0.25,0.0,0,-1,lost\n5.0005,0.45,0.05,0,0,\n"
                   "5.001,0.45,0.0506,0,1.2,launch\n"));
  ASSERT_EQ(balls.size(), 3u);
  EXPECT_DOUBLE_EQ(balls[1].observation.p_board.x(), 0.45);
  // Observations proper keep the rule: a time twice is refused.
  const std::string twice = write_csv("twice.csv", "t,x,y\n0.01,0,0\n0.01,0,0\n");
  EXPECT_NE(read_error(twice).find(twice + ":3: time must increase"), std::string::npos);
}

TEST(ObservationIo, BadFilesAreRefusedNamingTheLine) {
  const std::string header = write_csv("header.csv", "time,x,y\n0,0,0\n");
  EXPECT_NE(read_error(header).find(header + ":1: header must be 't,x,y'"), std::string::npos) << read_error(header);
  const std::string short_row = write_csv("short.csv", "t,x,y,vx,vy,event\n0,0.1,0.2\n");
  EXPECT_NE(read_error(short_row).find(short_row + ":2: expected 6 columns, got 3"), std::string::npos)
      << read_error(short_row);
  const std::string backwards = write_csv("backwards.csv", "t,x,y\n0.01,0,0\n0.005,0,0\n");
  EXPECT_NE(read_error(backwards).find(backwards + ":3: time must increase"), std::string::npos);
  const std::string nan = write_csv("nan.csv", "t,x,y\n0,nan,0\n");
  EXPECT_NE(read_error(nan).find(nan + ":2: column 'x' is not a finite number"), std::string::npos);
  const std::string empty = write_csv("empty.csv", "");
  EXPECT_NE(read_error(empty).find(empty + ":1: empty file"), std::string::npos);
  // A header and nothing else tracked nothing and exited 0.
  const std::string only_header = write_csv("only_header.csv", "t,x,y\n\n");
  EXPECT_NE(read_error(only_header).find(only_header + ":2: no observation after the header"), std::string::npos)
      << read_error(only_header);
}

// Positions in mm, or another table's: refused as a whole, a stray sighting kept.
TEST(ObservationIo, AFileMostlyOffTheBoardIsRefusedAsOtherUnits) {
  table::Board board;
  board.width_m = 0.51;
  board.height_m = 1.07;
  board.source = "lab.board";
  std::vector<ObservationRow> rows(20);
  for (std::size_t i = 0; i < rows.size(); ++i) rows[i].observation.p_board = Vec2(0.25, 0.5 + 0.01 * i);
  const auto check = [&] {
    return pinball::testing::error_text([&] { check_observations_on_board(rows, board, "roll.csv"); });
  };
  rows[0].observation.p_board = Vec2(250.0, 500.0);  // one stray sighting in 20: 5 %, kept
  EXPECT_EQ(check(), "no error");
  rows[1].observation.p_board = Vec2(0.25, -0.2);
  EXPECT_EQ(check(), "roll.csv: 2 of its 20 observations lie over 5 cm off the 0.51 x 1.07 m playfield of lab.board "
                     "(positions are in metres, board frame: a file in mm, or of another table?)");
}

// '#' lines were accepted in a marker layout but not here: a comment before the header, or a note
// between rows, was 'header must be ...' or 'expected 3 columns, got 1'.
TEST(ObservationIo, CommentLinesAreSkippedAnywhere) {
  const std::string path =
      write_csv("comments.csv", "# camera 2, 200 fps\nt,x,y\n0,0.1,0.2\n# a pause\n0.005,0.1,0.21\n");
  const std::vector<ObservationRow> rows = read_observations_csv(path);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[1].observation.p_board.y(), 0.21);
  const std::string only = write_csv("only_comments.csv", "# nothing yet\n");
  EXPECT_NE(read_error(only).find(only + ":1: empty file: expected the header 't,x,y'"), std::string::npos)
      << read_error(only);
}

// A binary file's first bytes were echoed into the message and garbled the terminal.
TEST(ObservationIo, ABinaryFilesHeaderIsQuotedPrintably) {
  const std::string path = write_csv("binary.csv", std::string("\x7f" "ELF\x02\x01\x01\0\0\0\n", 11));
  const std::string e = read_error(path);
  EXPECT_NE(e.find("got '?ELF??????" "'"), std::string::npos) << e;
  EXPECT_EQ(e.find('\x7f'), std::string::npos);
}

// Times in ms passed (they increase): track gave 176 'valid' projections where the seconds gave 73,
// and calibrate gravity wrote g = 1.1e-6 m/s^2.
TEST(ObservationIo, TimesInMillisecondsAreRefused) {
  table::Board board;
  board.source = "lab.board";
  std::vector<ObservationRow> rows(20);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    rows[i].observation.p_board = Vec2(0.25, 0.5 + 0.001 * i);
    rows[i].observation.t_s = 5.0 * i;  // 200 fps, in ms
  }
  EXPECT_EQ(pinball::testing::error_text([&] { check_observations_on_board(rows, board, "obs.csv"); }),
            "obs.csv: its observations are 5 s apart (the median): a camera's frames are a few ms apart, at most 1 s "
            "(times are in seconds: a file in ms or ns?)");
  for (std::size_t i = 0; i < rows.size(); ++i) rows[i].observation.t_s = 1.7e9 + 0.005 * i;  // Unix time, seconds
  rows[10].observation.t_s += 30.0;  // one long gap (the ball out of sight) is no unit
  for (std::size_t i = 11; i < rows.size(); ++i) rows[i].observation.t_s += 30.0;
  EXPECT_EQ(pinball::testing::error_text([&] { check_observations_on_board(rows, board, "obs.csv"); }), "no error");
}

// A byte-order mark before the header (an editor's) is skipped, as in board files.
TEST(ObservationIo, AByteOrderMarkBeforeTheHeaderIsSkipped) {
  const std::string bom = write_csv("bom.csv", "\xEF\xBB\xBFt,x,y\n0,0.1,0.2\n");
  const std::vector<ObservationRow> rows = read_observations_csv(bom);
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].observation.p_board.y(), 0.2);
}

}  // namespace
}  // namespace pinball::track
