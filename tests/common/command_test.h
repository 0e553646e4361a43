#pragma once
// Runs the `pinball` executable (PINBALL_EXE, from the source directory) as
// users and scripts do: stdout and stderr captured, exit code, and a fresh
// temporary directory per test for the files it writes.

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

namespace pinball::testing {

/// What one run of the command gave.
struct CommandResult {
  int exit_code = -1;  ///< exit status (-1: killed by a signal)
  std::string out;     ///< stdout
  std::string err;     ///< stderr
};

/// The whole file as bytes ("" when it cannot be read).
inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Lines in a command's output (its newlines): a one-line error is 1.
inline int count_lines(const std::string& s) {
  int n = 0;
  for (const char c : s) n += c == '\n' ? 1 : 0;
  return n;
}

/// A test fixture with run("args") and a temporary directory dir_, removed after the test.
class CommandTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = std::filesystem::temp_directory_path() / ("pinball_" + std::string(info->test_suite_name()) + "_" +
                                                     std::to_string(::getpid()) + "_" + info->name());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  /// Runs `pinball args` in the source directory.
  CommandResult run(const std::string& args) { return run_in(PINBALL_SOURCE_DIR, args); }

  /// Runs `pinball args` with `cwd` as the working directory.
  CommandResult run_in(const std::filesystem::path& cwd, const std::string& args) {
    return run_shell("cd " + cwd.string() + " && " PINBALL_EXE " " + args);
  }

  /// A bad input a command must refuse: the arguments, the exit code, and
  /// what its error must name.
  struct Refusal {
    std::string args;
    int exit_code;
    std::string names;
  };

  /// Runs `pinball <prefix><refusal.args>` and checks the refusal: the exit
  /// code, the error naming what it must, and nothing on stdout. Returns the
  /// result for a test's own further checks.
  CommandResult expect_refused(const std::string& prefix, const Refusal& refusal) {
    const std::string args = prefix + refusal.args;
    const CommandResult r = run(args);
    EXPECT_EQ(r.exit_code, refusal.exit_code) << args << "\n" << r.err;
    EXPECT_NE(r.err.find(refusal.names), std::string::npos) << args << "\n" << r.err;
    EXPECT_TRUE(r.out.empty()) << args;
    return r;
  }

  /// Runs a shell command line (e.g. `mpirun ... PINBALL_EXE ...`), its stderr captured too.
  CommandResult run_shell(const std::string& command_line) {
    const std::filesystem::path err = dir_ / "stderr.txt";
    const std::string cmd = "{ " + command_line + " ; } 2>" + err.string();
    CommandResult r;
    FILE* pipe = ::popen(cmd.c_str(), "r");
    if (!pipe) return r;
    char buf[4096];
    std::size_t n;
    while ((n = std::fread(buf, 1, sizeof buf, pipe)) > 0) r.out.append(buf, n);
    const int status = ::pclose(pipe);
    r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    r.err = slurp(err);
    return r;
  }

  std::filesystem::path dir_;
};

}  // namespace pinball::testing
