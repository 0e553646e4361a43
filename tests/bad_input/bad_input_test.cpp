// The bad-input corpus (tests/bad_input/README.md): every file under
// tests/bad_input/<kind>/ goes through the loader pinballd and `pinball`
// use for that kind, and must be refused with an exception (not a crash, not
// a hang) whose message names the file and the place in it that
// <kind>/expected.txt gives: a line, a key, or `-` for the file as a whole.
// Every file under tests/bad_input/good/<kind>/ must load. A new kind of
// input is a directory and one entry in kKinds.

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>
#include <map>
#include <memory>
#include <ostream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "pinball/control/controller_file.h"
#include "pinball/daemon/daemon_config.h"
#include "pinball/daemon/pipeline.h"
#include "pinball/daemon/replay.h"
#include "pinball/table/board_loader.h"
#ifdef PINBALL_HAVE_TWIN
#include "pinball/simlab/twin_params.h"
#endif

namespace pinball {
namespace {

namespace fs = std::filesystem;

const fs::path kCorpus = fs::path(PINBALL_SOURCE_DIR) / "tests" / "bad_input";

// A load that takes longer is a hang (sanitizer builds included).
constexpr auto kHangAfter = std::chrono::seconds(5);

// ---- the loaders, as the programs call them ----

void load_board(const std::string& path) { (void)table::load_board(path); }

void load_config(const std::string& path) { (void)daemon::load_daemon_config(path); }

void load_controller(const std::string& path) { (void)control::load_controller(path); }

// As pinballd applies a calibration: read, checked against the table's board,
// applied to the tracker.
void load_calibration(const std::string& path) {
  static const table::Board board = table::load_board(std::string(PINBALL_SOURCE_DIR) + "/boards/mit1993.board");
  daemon::DaemonConfig config;
  config.calibration = path;
  (void)daemon::tracking_setup_for(config, board);
}

// As `pinball replay LOG` reads a recording: the log is checked whole before
// liblcm sees it, then replayed through the shipped board and controller.
void load_lcm_log(const std::string& path) {
  daemon::DaemonConfig config;
  config.sim.board = std::string(PINBALL_SOURCE_DIR) + "/boards/mit1993.board";
  config.controller = std::string(PINBALL_SOURCE_DIR) + "/controllers/best.json";
  (void)daemon::replay_log(path, config);
}

#ifdef PINBALL_HAVE_TWIN
// As `--world twin --twin-params FILE` and pinballd's sim.twin_params read it.
void load_twin_params(const std::string& path) { (void)simlab::load_twin_params(path); }
#endif

/// One kind of input file: its directory under tests/bad_input and its loader.
struct Kind {
  const char* dir;
  void (*load)(const std::string& path);
  const char* shipped_good = nullptr;  ///< a shipped file (from the source root) that must load too
};

// Test names and failures show the directory.
void PrintTo(const Kind& kind, std::ostream* out) { *out << kind.dir; }

constexpr Kind kKinds[] = {
    {"lcm", &load_lcm_log},
    {"board", &load_board},
    {"config", &load_config},
    {"controller", &load_controller},
    {"calibration", &load_calibration},
#ifdef PINBALL_HAVE_TWIN
    {"twin", &load_twin_params, "config/twin.yaml"},
#endif
};

// ---- running one load ----

/// What a load did.
struct Outcome {
  enum What { kLoaded, kRefused, kThrewNonStd, kHung } what = kHung;
  std::string message;  ///< what() of the refusal
};

// Runs `load` on its own thread and waits kHangAfter for it. A hung load's
// thread is left behind (detached); the test fails and its process ends.
Outcome load_with_deadline(void (*load)(const std::string&), const std::string& path) {
  auto done = std::make_shared<std::promise<Outcome>>();
  std::future<Outcome> result = done->get_future();
  std::thread([done, load, path] {
    try {
      load(path);
      done->set_value({Outcome::kLoaded, ""});
    } catch (const std::exception& e) {
      done->set_value({Outcome::kRefused, e.what()});
    } catch (...) {
      done->set_value({Outcome::kThrewNonStd, ""});
    }
  }).detach();
  if (result.wait_for(kHangAfter) != std::future_status::ready) return {};
  return result.get();
}

// ---- the corpus ----

/// Where a refusal must point: a line, a key, or the whole file.
struct Place {
  std::string text;  ///< as expected.txt gives it: "12", "coils.hold_duty_pct" or "-"
  bool is_line() const { return !text.empty() && text.find_first_not_of("0123456789") == std::string::npos; }
  bool is_file() const { return text == "-"; }
};

// expected.txt: "<file> <place>", then an optional "# why"; '#' lines are comments.
std::map<std::string, Place> read_expected(const fs::path& dir) {
  std::map<std::string, Place> out;
  std::ifstream in(dir / "expected.txt");
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream words(line.substr(0, line.find('#')));
    std::string name, place;
    if (words >> name >> place) out[name] = Place{place};
  }
  return out;
}

// Every file of a directory but the manifest, in name order.
std::vector<fs::path> files_in(const fs::path& dir) {
  std::vector<fs::path> out;
  if (!fs::is_directory(dir)) return out;
  for (const fs::directory_entry& e : fs::directory_iterator(dir)) {
    if (e.is_regular_file() && e.path().filename() != "expected.txt") out.push_back(e.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

// True when `message` names `path` and then the place: "path:12: ..." for a
// line, "path:key: ..." or "path: key: ..." for a key (the archives and the
// module errors spell it both ways), "path: ..." for the whole file.
bool points_at(const std::string& message, const std::string& path, const Place& place) {
  if (place.is_file()) return message.rfind(path + ": ", 0) == 0;
  if (place.is_line()) return message.find(path + ":" + place.text + ":") != std::string::npos;
  return message.find(path + ":" + place.text + ":") != std::string::npos ||
         message.find(path + ": " + place.text + ":") != std::string::npos;
}

const char* what_happened(Outcome::What what) {
  switch (what) {
    case Outcome::kLoaded: return "was accepted";
    case Outcome::kRefused: return "was refused";
    case Outcome::kThrewNonStd: return "threw something that is not a std::exception";
    case Outcome::kHung: return "did not return within 5 s (a hang)";
  }
  return "?";
}

class BadInput : public ::testing::TestWithParam<Kind> {};

TEST_P(BadInput, EveryFileIsRefusedNamingTheFileAndThePlace) {
  const fs::path dir = kCorpus / GetParam().dir;
  const std::map<std::string, Place> expected = read_expected(dir);
  const std::vector<fs::path> files = files_in(dir);
  ASSERT_FALSE(files.empty()) << "no corpus in " << dir;
  for (const fs::path& file : files) {
    const std::string path = file.string();
    const auto place = expected.find(file.filename().string());
    if (place == expected.end()) {
      ADD_FAILURE() << file.filename() << " has no line in " << (dir / "expected.txt");
      continue;
    }
    const Outcome o = load_with_deadline(GetParam().load, path);
    if (o.what != Outcome::kRefused) {
      ADD_FAILURE() << path << " " << what_happened(o.what);
      continue;
    }
    EXPECT_NE(o.message.find(path), std::string::npos) << "does not name the file: " << o.message;
    EXPECT_TRUE(points_at(o.message, path, place->second))
        << "does not point at " << (place->second.is_file() ? "the whole file" : place->second.text) << ": "
        << o.message;
  }
  for (const auto& [name, place] : expected) {
    EXPECT_TRUE(fs::exists(dir / name)) << (dir / "expected.txt") << " names a missing file " << name;
  }
}

TEST_P(BadInput, GoodFilesLoad) {
  std::vector<fs::path> files = files_in(kCorpus / "good" / GetParam().dir);
  if (GetParam().shipped_good != nullptr) files.push_back(fs::path(PINBALL_SOURCE_DIR) / GetParam().shipped_good);
  ASSERT_FALSE(files.empty()) << "no good " << GetParam().dir << " files";
  for (const fs::path& file : files) {
    const Outcome o = load_with_deadline(GetParam().load, file.string());
    EXPECT_EQ(o.what, Outcome::kLoaded) << file << " " << what_happened(o.what) << " " << o.message;
  }
}

INSTANTIATE_TEST_SUITE_P(Corpus, BadInput, ::testing::ValuesIn(kKinds),
                         [](const ::testing::TestParamInfo<Kind>& kind) { return std::string(kind.param.dir); });

}  // namespace
}  // namespace pinball
