#include "pinball/table/board_overlay.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "common/temp_path.h"
#include "pinball/table/board_loader.h"

namespace pinball::table {
namespace {

using pinball::testing::temp_path;

const std::string kBoard = PINBALL_SOURCE_DIR "/boards/mit1993.board";

IdentifiedValue value(double v, double se, int events) { return {v, se, events}; }

// Every field and every section, numbers that need all their digits.
BoardOverlay full() {
  BoardOverlay o;
  o.date = "2026-12-02T13:45:21Z";
  o.board = "boards/mit1993.board";
  o.recordings = {"lab/run1.lcmlog", "lab/run2.lcmlog"};
  o.gravity_mps2 = value(1.0 / 0.9, 1.0 / 300.0, 412);
  ObstacleGroupOverlay arcs;
  arcs.board_rho = 0.6;
  arcs.obstacles = {"top_right_arc", "top_left_arc"};
  arcs.rho = value(0.55, 0.02, 37);
  arcs.friction = value(0.11, 0.004, 35);
  ObstacleGroupOverlay bumpers;
  bumpers.board_rho = 1.1;
  bumpers.board_kick_mps = 0.8;
  bumpers.obstacles = {"bumper_left", "bumper_right", "bumper_low"};
  bumpers.rho = value(1.0, 0.05, 20);
  bumpers.kick_mps = value(0.7, 0.1, 20);
  o.obstacle_groups = {arcs, bumpers};
  o.flippers = {{"left_flipper", value(1.4, 0.1, 55), value(40.0, 2.0, 54), value(0.012, 0.001, 54)},
                {"right_flipper", value(1.7, 0.12, 48), std::nullopt, std::nullopt}};
  o.launcher = LauncherOverlay{value(0.9, 0.01, 30), value(0.05, 0.01, 30)};
  o.wall_thickness_m = value(0.00277, 0.00004, 32030);
  return o;
}

// The overlay's YAML with `from` replaced by `to` (once; it must be there).
std::string edited(const std::string& from, const std::string& to, const BoardOverlay& o = full()) {
  std::string text = board_overlay_to_yaml(o);
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from << " not in\n" << text;
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// Parses `text` expecting a KeyError at `key` whose message contains `part`.
void expect_key_error(const std::string& text, const std::string& key, const std::string& part) {
  try {
    parse_board_overlay(text, "over.yaml");
    ADD_FAILURE() << "no error for key " << key << " in:\n" << text;
  } catch (const KeyError& e) {
    EXPECT_EQ(e.file(), "over.yaml");
    EXPECT_EQ(e.key(), key) << e.what();
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what() << "\nwanted: " << part;
    EXPECT_EQ(std::string(e.what()).rfind("over.yaml:" + key + ": ", 0), 0u) << e.what();
  }
}

TEST(BoardOverlay, EveryFieldRoundTrips) {
  const std::string path = temp_path("board_overlay", "full.yaml");
  const BoardOverlay a = full();
  write_board_overlay(a, path);
  const BoardOverlay b = read_board_overlay(path);
  std::filesystem::remove(path);
  EXPECT_EQ(board_overlay_to_yaml(b), board_overlay_to_yaml(a));
  EXPECT_EQ(b.version, kBoardOverlayVersion);
  EXPECT_EQ(b.date, a.date);
  EXPECT_EQ(b.board, a.board);
  EXPECT_EQ(b.recordings, a.recordings);
  ASSERT_TRUE(b.gravity_mps2);
  EXPECT_EQ(b.gravity_mps2->value, 1.0 / 0.9);  // bit for bit
  EXPECT_EQ(b.gravity_mps2->stderr_, 1.0 / 300.0);
  EXPECT_EQ(b.gravity_mps2->events, 412);
  ASSERT_EQ(b.obstacle_groups.size(), 2u);
  EXPECT_EQ(b.obstacle_groups[0].obstacles, a.obstacle_groups[0].obstacles);
  EXPECT_EQ(b.obstacle_groups[0].board_rho, 0.6);
  EXPECT_FALSE(b.obstacle_groups[0].kick_mps);
  ASSERT_TRUE(b.obstacle_groups[0].friction);
  EXPECT_EQ(b.obstacle_groups[0].friction->value, 0.11);
  EXPECT_EQ(b.obstacle_groups[0].friction->events, 35);
  EXPECT_FALSE(b.obstacle_groups[1].friction);
  EXPECT_EQ(b.obstacle_groups[1].board_kick_mps, 0.8);
  ASSERT_TRUE(b.obstacle_groups[1].kick_mps);
  EXPECT_EQ(b.obstacle_groups[1].kick_mps->value, 0.7);
  EXPECT_EQ(b.obstacle_groups[1].rho.events, 20);
  ASSERT_EQ(b.flippers.size(), 2u);
  EXPECT_EQ(b.flippers[1].name, "right_flipper");
  EXPECT_EQ(b.flippers[1].mu->value, 1.7);
  EXPECT_FALSE(b.flippers[1].omega_rad_s);
  ASSERT_TRUE(b.flippers[0].omega_rad_s && b.flippers[0].rise_delay_s);
  EXPECT_EQ(b.flippers[0].omega_rad_s->value, 40.0);
  EXPECT_EQ(b.flippers[0].rise_delay_s->stderr_, 0.001);
  ASSERT_TRUE(b.launcher);
  EXPECT_EQ(b.launcher->pull.value, 0.9);
  EXPECT_EQ(b.launcher->noise_max.stderr_, 0.01);
  ASSERT_TRUE(b.wall_thickness_m);
  EXPECT_EQ(b.wall_thickness_m->value, 0.00277);
  EXPECT_EQ(b.wall_thickness_m->events, 32030);
}

TEST(BoardOverlay, OptionalSectionsMayBeAbsent) {
  BoardOverlay a;
  a.date = "2026-12-02T13:45:21Z";
  a.board = "boards/mit1993.board";
  const std::string text = board_overlay_to_yaml(a);
  for (const char* section : {"gravity_mps2", "obstacle_groups", "flippers", "launcher", "wall_thickness_m"}) {
    EXPECT_EQ(text.find(section), std::string::npos) << section << " written though empty:\n" << text;
  }
  const BoardOverlay b = parse_board_overlay(text, "min.yaml");
  EXPECT_FALSE(b.gravity_mps2);
  EXPECT_TRUE(b.obstacle_groups.empty());
  EXPECT_TRUE(b.flippers.empty());
  EXPECT_FALSE(b.launcher);
  EXPECT_TRUE(b.recordings.empty());
  EXPECT_EQ(board_overlay_to_yaml(b), text);
}

TEST(BoardOverlay, TheFileSaysWhatItIsAndWhenItWasWritten) {
  BoardOverlay o = full();
  o.date.clear();
  const std::string text = board_overlay_to_yaml(o);
  EXPECT_EQ(text.rfind("# pinball board overlay", 0), 0u) << text;
  EXPECT_NE(text.find("pinball identify"), std::string::npos);
  const BoardOverlay b = parse_board_overlay(text, "t.yaml");
  ASSERT_EQ(b.date.size(), 20u) << b.date;  // 2026-12-02T13:45:21Z
  EXPECT_EQ(b.date.back(), 'Z');
  EXPECT_NE(text.find("rho:\n"), std::string::npos) << "readable, one key a line:\n" << text;
  EXPECT_NE(text.find("value: 0.55\n"), std::string::npos) << "the shortest digits:\n" << text;
}

TEST(BoardOverlay, EveryKeyIsRequiredAndNoOtherAllowed) {
  expect_key_error(edited("board: boards/mit1993.board\n", ""), "board", "missing");
  expect_key_error(edited("recordings:", "records:"), "recordings", "missing");
  expect_key_error(edited("  events: 412\n", ""), "gravity_mps2.events", "missing");
  expect_key_error(edited("    board_kick_mps: 0\n", ""), "obstacle_groups[0].board_kick_mps", "missing");
  expect_key_error(edited("date:", "colour: red\ndate:"), "colour", "unknown key");
  expect_key_error(edited("  pull:\n", "  pul:\n"), "launcher.pull", "missing");  // a misspelt key is missed
  expect_key_error(edited("  pull:\n", "  push: 1\n  pull:\n"), "launcher.push", "unknown key");
  expect_key_error(edited("board: boards/mit1993.board\n", "board: a.board\nboard: b.board\n"), "board",
                   "duplicate key");
  expect_key_error(edited("  events: 412\n", "  events: 412\n  events: 413\n"), "gravity_mps2.events",
                   "duplicate key");
  expect_key_error(edited("  events: 412\n", "  events: many\n"), "gravity_mps2.events", "expected an integer");
}

TEST(BoardOverlay, EveryRangeIsChecked) {
  const auto group = [](double rho, std::optional<double> kick) {
    BoardOverlay o = full();
    o.obstacle_groups[1].rho.value = rho;
    if (kick) o.obstacle_groups[1].kick_mps->value = *kick;
    return board_overlay_to_yaml(o);
  };
  // g and rho in the board format's ranges (table/board.h): no world a board file could not give.
  expect_key_error(group(-0.1, {}), "obstacle_groups[1].rho.value", "must be in [0, 2]");
  expect_key_error(group(2.01, {}), "obstacle_groups[1].rho.value", "must be in [0, 2]");
  expect_key_error(group(1.0, -0.5), "obstacle_groups[1].kick_mps.value", "must be in [0, 10] m/s");
  expect_key_error(group(1.0, 10.5), "obstacle_groups[1].kick_mps.value", "must be in [0, 10] m/s");
  for (double friction : {-0.01, 2.01}) {
    BoardOverlay f = full();
    f.obstacle_groups[0].friction->value = friction;
    expect_key_error(board_overlay_to_yaml(f), "obstacle_groups[0].friction.value", "must be in [0, 2]");
  }
  BoardOverlay o = full();
  o.gravity_mps2->value = 0.0;
  expect_key_error(board_overlay_to_yaml(o), "gravity_mps2.value", "must be in (0, 10] m/s^2");
  o.gravity_mps2->value = 10.5;
  expect_key_error(board_overlay_to_yaml(o), "gravity_mps2.value", "must be in (0, 10] m/s^2");
  o = full();
  o.flippers[1].mu->value = 10.5;
  expect_key_error(board_overlay_to_yaml(o), "flippers[1].mu.value", "must be in [0, 10]");
  o.flippers[1].mu->value = -1.0;
  expect_key_error(board_overlay_to_yaml(o), "flippers[1].mu.value", "must be in [0, 10]");
  o = full();
  o.launcher->pull.value = 0.0;
  expect_key_error(board_overlay_to_yaml(o), "launcher.pull.value", "must be in (0, 1]");
  o.launcher->pull.value = 1.01;
  expect_key_error(board_overlay_to_yaml(o), "launcher.pull.value", "must be in (0, 1]");
  o = full();
  o.launcher->noise_max.value = 0.51;  // the board format's noise= is at most 0.5
  expect_key_error(board_overlay_to_yaml(o), "launcher.noise_max.value", "must be in [0, 0.5]");
  o.launcher->noise_max.value = -0.01;
  expect_key_error(board_overlay_to_yaml(o), "launcher.noise_max.value", "must be in [0, 0.5]");
  o = full();
  o.obstacle_groups[0].rho.stderr_ = -0.01;
  expect_key_error(board_overlay_to_yaml(o), "obstacle_groups[0].rho.stderr", "must be >= 0");
  o = full();
  o.flippers[0].omega_rad_s->value = 0.0;
  expect_key_error(board_overlay_to_yaml(o), "flippers[0].omega_rad_s.value", "must be in (0, 200] rad/s");
  o = full();
  o.flippers[0].rise_delay_s->value = 0.2;
  expect_key_error(board_overlay_to_yaml(o), "flippers[0].rise_delay_s.value", "must be in [0, 0.1] s");
  o = full();
  o.flippers[0].mu->events = -1;
  expect_key_error(board_overlay_to_yaml(o), "flippers[0].mu.events", "must be >= 0");
  o = full();
  o.wall_thickness_m->value = -0.001;
  expect_key_error(board_overlay_to_yaml(o), "wall_thickness_m.value", "must be in [0, 0.05] m");
  o.wall_thickness_m->value = 0.06;
  expect_key_error(board_overlay_to_yaml(o), "wall_thickness_m.value", "must be in [0, 0.05] m");
  o = full();
  o.obstacle_groups[0].board_rho = -1.0;
  expect_key_error(board_overlay_to_yaml(o), "obstacle_groups[0].board_rho", "must be >= 0");
  o = full();
  o.obstacle_groups[0].obstacles.clear();
  expect_key_error(board_overlay_to_yaml(o), "obstacle_groups[0].obstacles", "names no obstacle");
}

// A flipper listed twice played the last of its values; an obstacle in two groups, the last group's
// rho; a kick for walls the board gives none made them kickers (mean speed 0.9 -> 4.9 m/s).
TEST(BoardOverlay, ANameGivenTwiceAndAKickForAGroupWithoutOneAreRefused) {
  BoardOverlay o = full();
  o.flippers.push_back(o.flippers[0]);
  expect_key_error(board_overlay_to_yaml(o), "flippers[2].name",
                   "'left_flipper' is given twice (also flippers[0]): which value counts?");
  o = full();
  o.obstacle_groups[1].obstacles.push_back("top_left_arc");
  expect_key_error(board_overlay_to_yaml(o), "obstacle_groups[1].obstacles[3]",
                   "'top_left_arc' is given twice (also obstacle_groups[0].obstacles[1]): which value counts?");
  o = full();
  o.obstacle_groups[0].obstacles.push_back("top_right_arc");
  expect_key_error(board_overlay_to_yaml(o), "obstacle_groups[0].obstacles[2]", "is given twice");
  o = full();
  o.obstacle_groups[0].kick_mps = value(3.0, 0.1, 20);  // the arcs' board_kick_mps is 0
  expect_key_error(board_overlay_to_yaml(o), "obstacle_groups[0].kick_mps",
                   "is only for a group the board gives a kick (its board_kick_mps is 0)");
}

TEST(BoardOverlay, AnotherVersionIsRefusedAsSuch) {
  BoardOverlay o = full();
  o.version = kBoardOverlayVersion + 1;
  expect_key_error(board_overlay_to_yaml(o), "version", "is not the supported version 1");
  expect_key_error("board: x\n", "version", "missing");
  expect_key_error("- a list\n", "version", "not a board overlay file");
}

TEST(BoardOverlay, UnreadableOrUnparsableFilesNameTheFile) {
  const std::string missing = temp_path("board_overlay", "missing.yaml");
  try {
    read_board_overlay(missing);
    ADD_FAILURE() << "read a missing file";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()).rfind(missing + ": ", 0), 0u) << e.what();
  }
  const std::string bad = temp_path("board_overlay", "bad.yaml");
  std::ofstream(bad) << "version: 1\nboard: [unclosed\n";
  try {
    read_board_overlay(bad);
    ADD_FAILURE() << "parsed bad YAML";
  } catch (const KeyError& e) {  // YamlSyntaxError: "file:line: not valid YAML: what yaml-cpp says"
    EXPECT_EQ(e.file(), bad);
    EXPECT_EQ(e.key(), "3") << e.what();
    EXPECT_EQ(e.message().rfind("not valid YAML: ", 0), 0u) << e.what();
  }
  std::filesystem::remove(bad);
}

TEST(BoardOverlay, AFailedWriteNamesTheFileAndLeavesNothing) {
  const std::filesystem::path folder = temp_path("board_overlay", "no_such_folder");
  const std::string path = (folder / "over.yaml").string();
  try {
    write_board_overlay(full(), path);
    ADD_FAILURE() << "wrote into a missing folder";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()).rfind(path + ": ", 0), 0u) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(folder));
  // A path that is a folder: the temporary is written, the rename fails, and both are gone.
  const std::filesystem::path dir = temp_path("board_overlay", "a_folder");
  std::filesystem::create_directories(dir);
  EXPECT_THROW(write_board_overlay(full(), dir.string()), std::runtime_error);
  EXPECT_TRUE(std::filesystem::is_directory(dir));
  int left = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir.parent_path())) {
    left += entry.path().filename().string().rfind(dir.filename().string() + ".tmp", 0) == 0 ? 1 : 0;
  }
  EXPECT_EQ(left, 0) << "a temporary file was left beside " << dir;
  std::filesystem::remove_all(dir);
}

// Everything but ρ, kick, μ, pull, noise and g is the file's.
void expect_same_geometry(const Board& a, const Board& b) {
  EXPECT_EQ(a.source, b.source);
  EXPECT_EQ(a.width_m, b.width_m);
  EXPECT_EQ(a.height_m, b.height_m);
  EXPECT_EQ(a.ball.radius_m, b.ball.radius_m);
  EXPECT_EQ(a.ball.speed_max_mps, b.ball.speed_max_mps);
  EXPECT_EQ(a.dt_s, b.dt_s);
  EXPECT_EQ(a.balls_per_game, b.balls_per_game);
  EXPECT_EQ(a.launcher.position, b.launcher.position);
  ASSERT_EQ(a.shapes.size(), b.shapes.size());
  for (std::size_t i = 0; i < a.shapes.size(); ++i) {
    EXPECT_EQ(a.shapes[i].p0, b.shapes[i].p0);
    EXPECT_EQ(a.shapes[i].p1, b.shapes[i].p1);
    EXPECT_EQ(a.shapes[i].radius_m, b.shapes[i].radius_m);
  }
  ASSERT_EQ(a.obstacles.size(), b.obstacles.size());
  for (std::size_t i = 0; i < a.obstacles.size(); ++i) {
    EXPECT_EQ(a.obstacles[i].name, b.obstacles[i].name);
    EXPECT_EQ(a.obstacles[i].action.score, b.obstacles[i].action.score);
    EXPECT_EQ(a.obstacles[i].action.eats_ball, b.obstacles[i].action.eats_ball);
    EXPECT_EQ(a.obstacles[i].bank, b.obstacles[i].bank);
  }
  EXPECT_EQ(a.sensors.size(), b.sensors.size());
  ASSERT_EQ(a.flippers.size(), b.flippers.size());
  for (std::size_t i = 0; i < a.flippers.size(); ++i) {
    EXPECT_EQ(a.flippers[i].pivot, b.flippers[i].pivot);
    EXPECT_EQ(a.flippers[i].length_m, b.flippers[i].length_m);
    EXPECT_EQ(a.flippers[i].rho, b.flippers[i].rho);
  }
}

TEST(BoardOverlay, ApplyChangesExactlyTheNamedParameters) {
  const Board file = load_board(kBoard);
  BoardOverlay o;
  o.board = kBoard;
  o.gravity_mps2 = value(1.2, 0.01, 10);
  ObstacleGroupOverlay arc;
  arc.board_rho = 0.6;
  arc.obstacles = {"top_right_arc"};
  arc.rho = value(0.45, 0.02, 12);
  arc.friction = value(0.12, 0.01, 11);
  ObstacleGroupOverlay bumpers;
  bumpers.board_rho = 1.1;
  bumpers.board_kick_mps = 0.8;
  bumpers.obstacles = {"bumper_left", "bumper_low"};
  bumpers.rho = value(0.95, 0.05, 20);
  bumpers.kick_mps = value(0.65, 0.1, 20);
  o.obstacle_groups = {arc, bumpers};
  o.flippers = {{"right_flipper", value(1.3, 0.1, 40), value(42.0, 3.0, 40), value(0.015, 0.001, 40)},
                {"left_flipper", std::nullopt, std::nullopt, value(0.019, 0.001, 30)}};
  o.launcher = LauncherOverlay{value(0.85, 0.01, 30), value(0.06, 0.01, 30)};
  Board b = file;
  apply_board_overlay(o, "over.yaml", b);

  expect_same_geometry(b, file);
  EXPECT_EQ(b.gravity_mps2, 1.2);
  EXPECT_EQ(b.launcher.pull, 0.85);
  EXPECT_EQ(b.launcher.noise_max, 0.06);
  int arc_shapes = 0;
  for (std::size_t i = 0; i < b.obstacles.size(); ++i) {
    const Obstacle& x = b.obstacles[i];
    const Obstacle& was = file.obstacles[i];
    SCOPED_TRACE(x.name);
    if (x.name == "top_right_arc") {
      ++arc_shapes;
      EXPECT_EQ(x.rho, 0.45);
      EXPECT_EQ(x.action.kick_mps, was.action.kick_mps);  // no kick identified: the file's
      EXPECT_EQ(x.friction, 0.12);
    } else if (x.name == "bumper_left" || x.name == "bumper_low") {
      EXPECT_EQ(x.rho, 0.95);
      EXPECT_EQ(x.action.kick_mps, 0.65);
      EXPECT_EQ(x.friction, was.friction);  // no friction identified: the file's
    } else {
      EXPECT_EQ(x.rho, was.rho);
      EXPECT_EQ(x.action.kick_mps, was.action.kick_mps);
      EXPECT_EQ(x.friction, was.friction);
    }
  }
  int file_arc_shapes = 0;
  for (const Obstacle& x : file.obstacles) file_arc_shapes += x.name == "top_right_arc" ? 1 : 0;
  EXPECT_GE(arc_shapes, 8) << "every segment of the polyline";
  EXPECT_EQ(arc_shapes, file_arc_shapes);
  for (std::size_t i = 0; i < b.flippers.size(); ++i) {
    EXPECT_EQ(b.flippers[i].mu, b.flippers[i].name == "right_flipper" ? 1.3 : file.flippers[i].mu);
    EXPECT_EQ(b.flippers[i].omega_rad_s, b.flippers[i].name == "right_flipper" ? 42.0 : file.flippers[i].omega_rad_s);
  }
  // The rise delay is not the board's: the actuation delay, the flippers' mean.
  EXPECT_NEAR(*identified_actuation_delay_s(o), 0.017, 1e-15);
  EXPECT_FALSE(identified_actuation_delay_s(BoardOverlay{}));
}

TEST(BoardOverlay, AWallThicknessMovesTheTwoSidedWallsFacesOnly) {
  const Board file = load_board(kBoard);
  BoardOverlay o;
  o.board = kBoard;
  o.wall_thickness_m = value(0.003, 0.0001, 500);
  Board b = file;
  apply_board_overlay(o, "over.yaml", b);
  Board expected = file;
  set_wall_thickness(expected, 0.003);
  EXPECT_EQ(b.wall_thickness_m, 0.003);
  int moved = 0;
  for (std::size_t i = 0; i < b.shapes.size(); ++i) {
    EXPECT_EQ(b.shapes[i].p0, expected.shapes[i].p0) << i;
    moved += b.shapes[i].p0 != file.shapes[i].p0 ? 1 : 0;
  }
  EXPECT_GT(moved, 20);  // the thesis table's walls, guides and sling backs
  EXPECT_LT(moved, static_cast<int>(b.shapes.size()));  // not its outer arcs, points or posts
}

TEST(BoardOverlay, AnUnknownNameThrowsAndLeavesTheBoardUntouched) {
  const Board file = load_board(kBoard);
  const auto expect_refused = [&](const BoardOverlay& o, const std::string& key, const std::string& name) {
    Board b = file;
    try {
      apply_board_overlay(o, "over.yaml", b);
      ADD_FAILURE() << "applied an overlay naming " << name;
    } catch (const KeyError& e) {
      EXPECT_EQ(e.file(), "over.yaml");
      EXPECT_EQ(e.key(), key);
      EXPECT_NE(e.message().find("'" + name + "'"), std::string::npos) << e.what();
      EXPECT_NE(e.message().find(kBoard), std::string::npos) << "names the board: " << e.what();
    }
    expect_same_geometry(b, file);
    EXPECT_EQ(b.gravity_mps2, file.gravity_mps2);
    EXPECT_EQ(b.launcher.pull, file.launcher.pull);
    for (std::size_t i = 0; i < b.obstacles.size(); ++i) EXPECT_EQ(b.obstacles[i].rho, file.obstacles[i].rho);
    for (std::size_t i = 0; i < b.flippers.size(); ++i) EXPECT_EQ(b.flippers[i].mu, file.flippers[i].mu);
  };
  BoardOverlay o = full();  // g, groups and launcher would all change before the bad name is met
  o.obstacle_groups[1].obstacles.push_back("bumper_nowhere");
  expect_refused(o, "obstacle_groups[1].obstacles[3]", "bumper_nowhere");
  o = full();
  o.flippers[1].name = "middle_flipper";
  expect_refused(o, "flippers[1].name", "middle_flipper");
}

// An overlay naming 'point@61' of a board one comment line longer said "an obstacle's name is its
// name=", though that point has none: the line-number name moved with the lines.
TEST(BoardOverlay, AnUnnamedObstacleThatMovedLinesIsSaidSo) {
  Board b = load_board(kBoard);
  BoardOverlay o;
  ObstacleGroupOverlay g;
  g.obstacles = {"point@9999"};
  g.rho = value(0.5, 0.01, 10);
  o.obstacle_groups = {g};
  try {
    apply_board_overlay(o, "over.yaml", b);
    FAIL() << "no error";
  } catch (const KeyError& e) {
    EXPECT_NE(e.message().find("an obstacle without name= is named by its keyword and line: the board's lines moved"),
              std::string::npos)
        << e.what();
  }
}

// "key: message" of the KeyError applying `o` to the thesis board throws; "" when it applies.
std::string refusal(const BoardOverlay& o) {
  Board b = load_board(kBoard);
  try {
    apply_board_overlay(o, "over.yaml", b);
  } catch (const KeyError& e) {
    return e.key() + ": " + e.message();
  }
  return "";
}

// A stroke of 200 rad/s on a board stepped at 5 ms sweeps 36 mm a step: the stepper's message named
// no overlay and no key.
TEST(BoardOverlay, AStrokeTooFastForTheBoardsStepIsRefusedAtItsKey) {
  Board b = load_board(kBoard);
  b.dt_s = 0.005;
  const Board file = b;
  BoardOverlay o;
  o.flippers = {{"left_flipper", std::nullopt, value(200.0, 1.0, 10), std::nullopt}};
  try {
    apply_board_overlay(o, "over.yaml", b);
    FAIL() << "no error";
  } catch (const KeyError& e) {
    EXPECT_EQ(e.key(), "flippers[0].omega_rad_s");
    EXPECT_NE(e.message().find("flipper 'left_flipper': l*sin(omega*dt/2) = "), std::string::npos) << e.what();
    EXPECT_NE(e.message().find("at dt = 0.005 s"), std::string::npos) << e.what();
  }
  EXPECT_EQ(b.flippers[0].omega_rad_s, file.flippers[0].omega_rad_s);  // all or nothing
  o.flippers[0].omega_rad_s->value = 20.0;
  EXPECT_NO_THROW(apply_board_overlay(o, "over.yaml", b));
  // At the board's own step, a tip faster than the speed clamp (70 rad/s x 76 mm > 5 m/s) is refused too.
  b = file;
  b.dt_s = 0.0005;
  o.flippers[0].omega_rad_s->value = 70.0;
  try {
    apply_board_overlay(o, "over.yaml", b);
    FAIL() << "no error";
  } catch (const KeyError& e) {
    EXPECT_EQ(e.key(), "flippers[0].omega_rad_s");
    EXPECT_NE(e.message().find("its tip moves at 5.32 m/s (OMEGA x LENGTH), not below the ball's speed clamp"),
              std::string::npos)
        << e.what();
  }
}

TEST(BoardOverlay, ALaunchThatCannotLeaveTheLauncherIsRefused) {
  BoardOverlay o;
  o.launcher = LauncherOverlay{value(0.03, 0.01, 30), value(0.03, 0.01, 30)};
  EXPECT_EQ(refusal(o).rfind("launcher.pull: ", 0), 0u) << "a pull of 0.03 launched: " << refusal(o);
}

// Walls so thick that the launch position lies inside the chute's wall: the ball would start
// in it and leave the table through it (found at 0.05 m, the key's own upper bound).
TEST(BoardOverlay, WallsThatReachTheBallsFirstPositionAreRefused) {
  BoardOverlay o;
  o.wall_thickness_m = value(0.05, 0.001, 500);
  EXPECT_EQ(refusal(o).rfind("wall_thickness_m: with walls 0.05 m thick the ball at the launch position overlaps "
                             "'right_wall'",
                             0),
            0u)
      << refusal(o);
}

TEST(BoardOverlay, TheBeliefIsTheBoardFileWithTheOverlay) {
  const Board file = load_board(kBoard);
  const Board plain = load_belief_board(kBoard, "");
  EXPECT_EQ(plain.gravity_mps2, file.gravity_mps2);
  const std::string path = temp_path("board_overlay", "belief.yaml");
  write_board_overlay(full(), path);
  const Board belief = load_belief_board(kBoard, path);
  EXPECT_EQ(belief.gravity_mps2, 1.0 / 0.9);
  EXPECT_EQ(belief.source, file.source);
  std::filesystem::remove(path);
  BoardOverlay unknown = full();
  unknown.flippers[0].name = "nobody";
  write_board_overlay(unknown, path);
  try {
    load_belief_board(kBoard, path);
    ADD_FAILURE() << "laid an overlay naming an unknown flipper";
  } catch (const KeyError& e) {
    EXPECT_EQ(e.file(), path);
  }
  std::filesystem::remove(path);
}

// The overlays under config/ that docs/results.md's figures rest on lay over the board they name.
TEST(BoardOverlay, EveryShippedOverlayLaysOverItsBoard) {
  int loaded = 0;
  for (const auto& entry : std::filesystem::directory_iterator(PINBALL_SOURCE_DIR "/config")) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("twin.identified", 0) != 0) continue;
    EXPECT_NO_THROW(load_belief_board(kBoard, entry.path().string())) << name;
    ++loaded;
  }
  EXPECT_GE(loaded, 3);
}

}  // namespace
}  // namespace pinball::table
