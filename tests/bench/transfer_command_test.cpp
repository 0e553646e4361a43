// `pinball bench transfer` end to end: the quick run's table and files, the
// same JSON whatever --threads, and bad input refused with nothing written.
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "common/command_test.h"

namespace pinball::testing {
namespace {

namespace fs = std::filesystem;

using TransferCommand = CommandTest;

// The JSON without what depends on the machine: wall times and the thread count.
nlohmann::json without_timing(nlohmann::json j) {
  if (j.is_object()) {
    j.erase("wall_s");
    j.erase("threads");
    for (auto& [key, value] : j.items()) value = without_timing(value);
  } else if (j.is_array()) {
    for (auto& value : j) value = without_timing(value);
  }
  return j;
}

TEST_F(TransferCommand, QuickRunGivesEveryCellAndWritesItsFiles) {
  const fs::path csv = dir_ / "transfer.csv";
  const fs::path png = dir_ / "transfer.png";
  const CommandResult r =
      run("bench transfer --quick --json --progress --csv " + csv.string() + " --png " + png.string());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);  // exactly one object
  EXPECT_EQ(j.at("benchmark"), "transfer");
  EXPECT_EQ(j.at("balls"), 5);
  EXPECT_EQ(j.at("twin_balls"), 2) << "the twin plays fewer of the same balls";
  EXPECT_EQ(j.at("max_ball_time_s"), 60.0);
  ASSERT_EQ(j.at("controllers").size(), 4u) << "spastic, best, imitation, cem";
  ASSERT_EQ(j.at("worlds").size(), 3u + 8u + 2u) << "model, event, twin, one world per family, two combined";
  ASSERT_EQ(j.at("combined").size(), 2u);
  EXPECT_EQ(j.at("combined")[0].at("stepper"), "event");
  EXPECT_EQ(j.at("worlds").back().at("family"), "combined");
  for (const auto& w : j.at("worlds")) {
    if (!w.at("played").get<bool>()) {
      EXPECT_EQ(w.at("name"), "twin") << "only the twin may be missing";
      EXPECT_NE(w.at("skipped_reason").get<std::string>().find("twin"), std::string::npos);
      continue;
    }
    for (const char* c : {"spastic", "best", "imitation", "cem"}) {
      const auto& cell = w.at("cells").at(c);
      EXPECT_EQ(cell.at("balls"), w.at("name") == "twin" ? 2 : 5) << w.at("name") << " " << c;
      EXPECT_TRUE(cell.contains("score_ci95_half_width"));
    }
    EXPECT_EQ(w.at("cells").at("spastic").at("ratio_to_spastic"), 1.0) << w.at("name");
  }
  EXPECT_EQ(j.at("target_ratio"), 2.5) << "issue 20's target by default";
  ASSERT_EQ(j.at("summary").size(), 3u) << "best, imitation, cem";
  EXPECT_EQ(j.at("summary")[0].at("controller"), "best");
  std::size_t played = 0;
  for (const auto& w : j.at("worlds")) played += w.at("played").get<bool>() ? 1 : 0;
  EXPECT_EQ(j.at("summary")[0].at("worlds"), played) << "every world played, the skipped twin none";
  EXPECT_TRUE(j.at("sensitivity").contains("pivot_y_mm"));
  EXPECT_TRUE(j.at("sensitivity").contains("theta_min_deg"));
  EXPECT_TRUE(j.at("sensitivity").contains("gravity_pct"));
  EXPECT_NE(r.err.find("bench transfer: transfer: "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("(100 %)"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("ETA"), std::string::npos) << r.err;
  const std::string table = slurp(csv);
  EXPECT_EQ(table.rfind("world,family,value,stepper,controller,status,", 0), 0u) << table;
  EXPECT_EQ(count_lines(table), 1 + 13 * 4);
  const std::string picture = slurp(png);
  ASSERT_GT(picture.size(), 1000u);
  EXPECT_EQ(picture.substr(1, 3), "PNG");
}

TEST_F(TransferCommand, SameSeedSameJsonWhateverTheThreads) {
  // Balls cut at 5 s: every cell and the twin still play, in a third of the time.
  const CommandResult one = run("bench transfer --quick --balls 3 --seed 9 --max-ball-time 5 --threads 1 --json");
  const CommandResult two = run("bench transfer --quick --balls 3 --seed 9 --max-ball-time 5 --threads 2 --json");
  ASSERT_EQ(one.exit_code, 0) << one.err;
  ASSERT_EQ(two.exit_code, 0) << two.err;
  EXPECT_EQ(without_timing(nlohmann::json::parse(one.out)).dump(), without_timing(nlohmann::json::parse(two.out)).dump());
}

// An identified delay is the model worlds' nominal; the twin keeps its driver's.
TEST_F(TransferCommand, TheModelWorldsPlayTheIdentifiedDelayAndTheTwinItsOwn) {
  const fs::path over = dir_ / "delay.yaml";
  std::ofstream(over) << "version: 1\ndate: 2026-12-02T13:45:21Z\nboard: boards/mit1993.board\nrecordings: []\n"
                         "flippers:\n  - name: left_flipper\n    rise_delay_s: {value: 0.016, stderr: 0.001, events: 9}\n";
  const CommandResult r = run("bench transfer --quick --balls 1 --twin-balls 1 --max-ball-time 2 --json --identified " +
                              over.string() + " --controller controllers/best.json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_DOUBLE_EQ(j.at("actuation_delay_s").get<double>(), 0.016);
  EXPECT_DOUBLE_EQ(j.at("twin_actuation_delay_s").get<double>(), 0.004);
}

TEST_F(TransferCommand, TextIsARoundedTableWithTheCap) {
  const CommandResult r =
      run("bench transfer --quick --balls 2 --max-ball-time 5 --controller controllers/best.json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("| world | spastic | best |"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("balls cut at 5 s"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("| gravity_pct=+10 |"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("| twin |"), std::string::npos) << r.out;
}

TEST_F(TransferCommand, BadInputSaysWhatIsWrongInOneLineAndWritesNothing) {
  const fs::path csv = dir_ / "out.csv";
  const fs::path png = dir_ / "out.png";
  const std::string files = " --csv " + csv.string() + " --png " + png.string();
  const fs::path bad = dir_ / "bad.json";
  std::ofstream(bad) << "{\"format\": \"pinball-controller\", \"version\": 1, \"minicontrollers\": 7}\n";
  for (const Refusal& c :
       {Refusal{"--controller controllers/no_such.json", 2, "no_such.json"},
        Refusal{"--controller " + bad.string(), 1, "bad.json"},
        Refusal{"--balls 0", 2, "--balls"},
        Refusal{"--balls many", 2, "--balls"},
        Refusal{"--max-ball-time -1", 2, "--max-ball-time"},
        Refusal{"--threads 0", 2, "--threads"},
        Refusal{"--target-ratio 0", 2, "--target-ratio"},
        Refusal{"--world twin", 1, "--world"},
        Refusal{"--png " + png.string() + " --csv " + (dir_ / "no_such_folder" / "x.csv").string(), 1,
                "no_such_folder"}}) {
    const bool names_files = c.args.find("--csv") != std::string::npos;
    const CommandResult r =
        expect_refused("bench transfer --quick ", {c.args + (names_files ? "" : files), c.exit_code, c.names});
    EXPECT_EQ(count_lines(r.err), 1) << c.args << "\n" << r.err;
    EXPECT_FALSE(fs::exists(csv)) << c.args;
    EXPECT_FALSE(fs::exists(png)) << c.args;
  }
}

}  // namespace
}  // namespace pinball::testing
