// `mpirun -n N pinball ...` (Open MPI, oversubscribed on this machine): the
// same controller, scores and curve as one process, bit for bit, for 2 and 3
// ranks with threads in each; a killed rank ends the job with an error.
// Skipped where the build has no MPI or mpirun is missing.

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "common/command_test.h"
#include "pinball/learn/team.h"

namespace pinball::learn {
namespace {

class Mpi : public testing::CommandTest {
 protected:
  void SetUp() override {
    CommandTest::SetUp();
    if (!team_has_mpi()) GTEST_SKIP() << "this build has no MPI (libopenmpi-dev)";
    if (std::system("command -v mpirun >/dev/null 2>&1") != 0) GTEST_SKIP() << "no mpirun (openmpi-bin)";
  }
  // Open MPI refuses root unless told; CI runs as root.
  // `time_limit_s` > 0: the job is killed after that long (exit 124), so a hang fails the test.
  static std::string mpirun(int ranks, const std::string& program = PINBALL_EXE, int time_limit_s = 0) {
    return std::string("cd " PINBALL_SOURCE_DIR " && ") + (time_limit_s > 0 ? "timeout " + std::to_string(time_limit_s) + " " : "") +
           "env OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun --oversubscribe -n " + std::to_string(ranks) +
           " " + program + " ";
  }
  // The report less what may differ between runs: wall times, rates, threads, the team.
  static nlohmann::json figures(const std::string& json_text) {
    nlohmann::json j = nlohmann::json::parse(json_text);
    for (const char* key : {"threads", "team", "search_wall_s", "search_balls_per_s", "out", "wall_s"}) j.erase(key);
    if (j.contains("evaluation")) {
      j["evaluation"].erase("balls_per_s");
      j["evaluation"].erase("wall_s");
    }
    if (j.contains("rounds")) {
      for (auto& r : j["rounds"]) r.erase("wall_s");
    }
    if (j.contains("players")) {
      for (auto& p : j["players"]) {
        p.erase("wall_s");
        p.erase("balls_per_s");
      }
    }
    return j;
  }
  std::string file(const std::string& name) const { return (dir_ / name).string(); }
};

TEST_F(Mpi, ASearchIsTheSameOnOneTwoAndThreeRanks) {
  const std::string args =
      "learn boards/mit1993.board --method cem --budget-balls 96 --population 8 --seed 5 --eval-balls 24 --json --out ";
  const testing::CommandResult one = run(args + file("one.json") + " --threads 2");
  ASSERT_EQ(one.exit_code, 0) << one.err;
  const testing::CommandResult two = run_shell(mpirun(2) + args + file("two.json") + " --threads 1");
  ASSERT_EQ(two.exit_code, 0) << two.err;
  const testing::CommandResult three = run_shell(mpirun(3) + args + file("three.json") + " --threads 2");
  ASSERT_EQ(three.exit_code, 0) << three.err;
  EXPECT_EQ(figures(two.out), figures(one.out));
  EXPECT_EQ(figures(three.out), figures(one.out));
  EXPECT_EQ(testing::slurp(file("two.json")), testing::slurp(file("one.json")));
  EXPECT_EQ(testing::slurp(file("three.json")), testing::slurp(file("one.json")));
  const auto team = nlohmann::json::parse(three.out)["team"];
  EXPECT_EQ(team["ranks"], 3);
  EXPECT_GT(team["mpi_batches"].get<int>(), 0);
  EXPECT_EQ(three.out.find('{'), 0u) << "one JSON object: the other ranks print nothing";
}

TEST_F(Mpi, AnEvaluationAndTheImitationTeacherAreTheSameOnTwoAndThreeRanks) {
  const std::string eval = "learn boards/mit1993.board --method spastic --eval-balls 40 --seed 9 --json";
  const testing::CommandResult one = run(eval);
  ASSERT_EQ(one.exit_code, 0) << one.err;
  const testing::CommandResult three = run_shell(mpirun(3) + eval);
  ASSERT_EQ(three.exit_code, 0) << three.err;
  EXPECT_EQ(figures(three.out), figures(one.out));

  const std::string imitate =
      "learn boards/mit1993.board --method imitate --budget-balls 4 --rounds 1 --max-ball-time 8 --seed 2 --eval-balls 40 "
      "--json --out ";
  const testing::CommandResult solo = run(imitate + file("solo.json"));
  ASSERT_EQ(solo.exit_code, 0) << solo.err;
  const testing::CommandResult pair = run_shell(mpirun(2) + imitate + file("pair.json"));
  ASSERT_EQ(pair.exit_code, 0) << pair.err;
  EXPECT_EQ(figures(pair.out), figures(solo.out));
  EXPECT_EQ(testing::slurp(file("pair.json")), testing::slurp(file("solo.json")));
}

TEST_F(Mpi, TheCeilingBenchIsTheSameOnTwoRanks) {
  const std::string args = "bench ceiling --quick --seed 4 --max-ball-time 10 --json";  // 10 s balls: half the time
  const testing::CommandResult one = run(args);
  ASSERT_EQ(one.exit_code, 0) << one.err;
  const testing::CommandResult two = run_shell(mpirun(2) + args + " --threads 1");
  ASSERT_EQ(two.exit_code, 0) << two.err;
  EXPECT_EQ(figures(two.out), figures(one.out));
}

TEST_F(Mpi, ARunCheckpointedOnThreeRanksResumesInOneProcessToTheSameResult) {
  const std::string args = "learn boards/mit1993.board --method tournament --budget-balls 120 --seed 8 --eval-balls 12 --json";
  const testing::CommandResult whole = run(args + " --out " + file("whole.json"));
  ASSERT_EQ(whole.exit_code, 0) << whole.err;
  const std::string ckpt = file("run.ckpt");
  const testing::CommandResult first = run_shell(mpirun(3) + args + " --out " + file("first.json") + " --checkpoint " + ckpt);
  ASSERT_EQ(first.exit_code, 0) << first.err;
  // A time limit strikes part way: only the first part of the file was written.
  std::filesystem::resize_file(ckpt, std::filesystem::file_size(ckpt) / 2);
  const testing::CommandResult resumed =
      run(args + " --out " + file("resumed.json") + " --checkpoint " + ckpt + " --resume --threads 2");
  ASSERT_EQ(resumed.exit_code, 0) << resumed.err;
  EXPECT_EQ(figures(resumed.out), figures(whole.out));
  EXPECT_EQ(testing::slurp(file("resumed.json")), testing::slurp(file("whole.json")));
  const auto k = nlohmann::json::parse(resumed.out)["team"]["checkpoint"];
  EXPECT_GT(k["replayed"].get<int>(), 0);
  EXPECT_GT(k["recorded"].get<int>(), 0);
  // The same file without --resume is refused, and nothing is lost.
  const auto size = std::filesystem::file_size(ckpt);
  const testing::CommandResult again = run(args + " --out " + file("again.json") + " --checkpoint " + ckpt);
  EXPECT_EQ(again.exit_code, 1);
  EXPECT_NE(again.err.find("already exists"), std::string::npos) << again.err;
  EXPECT_EQ(std::filesystem::file_size(ckpt), size);
  // Another seed is another run.
  const testing::CommandResult other = run(
      "learn boards/mit1993.board --method tournament --budget-balls 120 --seed 9 --eval-balls 12 --json --out " +
      file("other.json") + " --checkpoint " + ckpt + " --resume");
  EXPECT_EQ(other.exit_code, 1);
  EXPECT_NE(other.err.find("another run"), std::string::npos) << other.err;
  EXPECT_FALSE(std::filesystem::exists(file("other.json")));
}

TEST_F(Mpi, AKilledRankEndsTheJobWithAnError) {
  // A long evaluation; rank 1 is killed once it is playing.
  const std::string pidfile = file("rank1.pid");
  const std::string cmd = mpirun(2, "sh", 120) + "-c '[ \"$OMPI_COMM_WORLD_RANK\" = 1 ] && echo $$ > " + pidfile +
                          "; exec " PINBALL_EXE " learn boards/mit1993.board --method spastic --eval-balls 200000 --seed 1'";
  std::thread killer([&] {
    for (int i = 0; i < 300 && !std::filesystem::exists(pidfile); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(100));
    std::this_thread::sleep_for(std::chrono::seconds(2));
    std::ifstream in(pidfile);
    long pid = 0;
    in >> pid;
    if (pid > 0) std::system(("kill -9 " + std::to_string(pid)).c_str());
  });
  const auto start = std::chrono::steady_clock::now();
  const testing::CommandResult r = run_shell(cmd);
  killer.join();
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.exit_code, 124) << "the job hung after a rank died";
  EXPECT_NE(r.err.find("rank 1"), std::string::npos) << r.err;
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 100.0);
}

}  // namespace
}  // namespace pinball::learn
