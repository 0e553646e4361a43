// Nothing on the daemon's per-frame path allocates after start-up: this test
// binary replaces malloc and operator new with versions that count the calls
// made while the calling thread is inside a HotPathScope (the camera and
// controller threads' per-frame work), then runs pinballd's embedded
// simulation for two balls.

#include <gtest/gtest.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <execinfo.h>
#include <new>

#include "pinball/control/controller_file.h"
#include "pinball/core/rng.h"
#include "pinball/daemon/daemon.h"
#include "pinball/daemon/hot_path.h"

#if defined(__SANITIZE_ADDRESS__)
#define PINBALL_COUNTING_ALLOCATOR 0
#else
#define PINBALL_COUNTING_ALLOCATOR 1
#endif

namespace {
std::atomic<long> g_hot_allocations{0};
thread_local bool t_tracing = false;
std::atomic<bool> g_trace{false};  // set once the counter itself is checked
void note() {
  if (!pinball::daemon::t_in_hot_path) return;
  g_hot_allocations.fetch_add(1, std::memory_order_relaxed);
  if (g_trace.load(std::memory_order_relaxed) && !t_tracing) {  // where: for whoever must fix it
    t_tracing = true;
    void* frames[32];
    backtrace_symbols_fd(frames, backtrace(frames, 32), 2);
    t_tracing = false;
  }
}
}  // namespace

#if PINBALL_COUNTING_ALLOCATOR
extern "C" {
// glibc's own entry points behind malloc and kin, which the counters below wrap.
// NOLINTBEGIN(bugprone-reserved-identifier)
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);
// NOLINTEND(bugprone-reserved-identifier)
void* malloc(std::size_t n) {
  note();
  return __libc_malloc(n);
}
void* calloc(std::size_t a, std::size_t b) {
  note();
  return __libc_calloc(a, b);
}
void* realloc(void* p, std::size_t n) {
  note();
  return __libc_realloc(p, n);
}
int posix_memalign(void** out, std::size_t align, std::size_t n) {
  note();
  *out = __libc_memalign(align, n);
  return *out != nullptr ? 0 : ENOMEM;
}
void* aligned_alloc(std::size_t align, std::size_t n) {
  note();
  return __libc_memalign(align, n);
}
void* memalign(std::size_t align, std::size_t n) {
  note();
  return __libc_memalign(align, n);
}
}
#endif

namespace pinball::daemon {
namespace {

// Plays 2 balls with `controller` and counts allocations on the per-frame path.
void expect_no_allocation_per_frame(const std::string& controller, const std::string& sim_camera = "ideal") {
  // The counter sees allocations: check that it does before trusting a zero.
  {
    HotPathScope hot;
    void* volatile p = std::malloc(64);  // volatile: the compiler may not elide the pair
    std::free(p);
    int* volatile q = new int(3);
    delete q;
  }
  ASSERT_EQ(g_hot_allocations.load(), 2);
  g_hot_allocations = 0;
  g_trace = std::getenv("PINBALL_TRACE_ALLOC") != nullptr;

  DaemonConfig c;
  c.sim.board = std::string(PINBALL_SOURCE_DIR) + "/boards/mit1993.board";
  c.controller = controller;
  c.sim.balls = 2;
  c.sim.seed = 4;
  c.sim.camera = sim_camera;
  Daemon d(c);
  const DaemonReport r = d.run();
  ASSERT_EQ(r.balls, 2);
  ASSERT_GT(r.frames, 1000u);
  ASSERT_GT(r.commands, 0u);
  EXPECT_EQ(g_hot_allocations.load(), 0) << "allocations on the per-frame path over " << r.frames << " frames";
}

TEST(HotPath, CameraAndControllerThreadsAllocateNothingPerFrame) {
  if (!PINBALL_COUNTING_ALLOCATOR) GTEST_SKIP() << "the sanitizer owns malloc in this build";
  expect_no_allocation_per_frame(std::string(PINBALL_SOURCE_DIR) + "/controllers/best.json");
}

TEST(HotPath, CorrectingARealCamerasFaultsAllocatesNothingPerFrame) {
  if (!PINBALL_COUNTING_ALLOCATOR) GTEST_SKIP() << "the sanitizer owns malloc in this build";
  // The typical camera: the detector undistorts each centroid, dates it by its row and the steady clock.
  expect_no_allocation_per_frame(std::string(PINBALL_SOURCE_DIR) + "/controllers/best.json", "typical");
}

TEST(HotPath, TheSpasticControllerFileAllocatesNothingPerFrame) {
  if (!PINBALL_COUNTING_ALLOCATOR) GTEST_SKIP() << "the sanitizer owns malloc in this build";
  expect_no_allocation_per_frame(std::string(PINBALL_SOURCE_DIR) + "/controllers/spastic.json");
}

TEST(HotPath, TheImitationControllerAllocatesNothingPerFrame) {
  if (!PINBALL_COUNTING_ALLOCATOR) GTEST_SKIP() << "the sanitizer owns malloc in this build";
  // A table of random shots, most of them fired, so lookups and flips happen every approach.
  Rng rng(5);
  std::vector<control::ShotExample> shots;
  for (int i = 0; i < 2000; ++i) {
    const int f = i % 2;
    const bool fire = rng.uniform01() < 0.8;
    shots.push_back({f, i % 10 == 0, rng.uniform(-1.57, 1.57), rng.uniform(0.0, 1.3), rng.uniform(0.4, 5.0),
                     fire ? f : -1, fire ? rng.uniform(0.02, 0.1) : 0.0, fire ? 0.03 : 0.0});
  }
  control::ControllerSpec spec;
  spec.shot_table = std::make_shared<const control::ShotTable>(std::move(shots), control::ImitationConfig{});
  const std::string path = ::testing::TempDir() + "/hot_path_imitation.json";
  control::save_controller(spec, path);
  expect_no_allocation_per_frame(path);
  std::remove(path.c_str());
}

TEST(HotPath, TheOnlinePlannerAllocatesNothingPerFrame) {
  if (!PINBALL_COUNTING_ALLOCATOR) GTEST_SKIP() << "the sanitizer owns malloc in this build";
  // Every plan copies the belief state into the planner's scratch state: same sizes, no allocation.
  expect_no_allocation_per_frame(std::string(PINBALL_SOURCE_DIR) + "/controllers/planner.json");
}

}  // namespace
}  // namespace pinball::daemon
