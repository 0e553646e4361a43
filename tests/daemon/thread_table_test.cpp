#include "pinball/daemon/thread_table.h"

#include <gtest/gtest.h>
#include <pthread.h>
#include <sched.h>
#include <sys/resource.h>
#include <unistd.h>

#include <fstream>
#include <sstream>
#include <thread>

#include "pinball/daemon/daemon_config.h"

namespace pinball::daemon {
namespace {

std::vector<int> allowed_cpus() {
  cpu_set_t set;
  CPU_ZERO(&set);
  EXPECT_EQ(sched_getaffinity(0, sizeof set, &set), 0);
  std::vector<int> cpus;
  for (int c = 0; c < CPU_SETSIZE; ++c) {
    if (CPU_ISSET(c, &set)) cpus.push_back(c);
  }
  return cpus;
}

TEST(ThreadTable, DocsShowWhatPinballdPrints) {
  std::ifstream in(PINBALL_SOURCE_DIR "/docs/daemon.md");
  std::stringstream text;
  text << in.rdbuf();
  const std::string doc = text.str();
  const std::string begin = "<!-- pinballd --threads -->\n";
  const std::size_t from = doc.find(begin);
  const std::size_t to = doc.find("<!-- end pinballd --threads -->");
  ASSERT_NE(from, std::string::npos);
  ASSERT_NE(to, std::string::npos);
  EXPECT_EQ(doc.substr(from + begin.size(), to - from - begin.size()), thread_table_markdown())
      << "paste the output of `pinballd --threads` into docs/daemon.md";
}

TEST(ThreadTable, TheChainIsCameraControllerAndDriver) {
  EXPECT_TRUE(kThreadTable[kCameraThread].chain);
  EXPECT_TRUE(kThreadTable[kControllerThread].chain);
  EXPECT_TRUE(kThreadTable[kDriverThread].chain);
  EXPECT_FALSE(kThreadTable[kLcmThread].chain);
  EXPECT_FALSE(kThreadTable[kSimThread].chain);
  // Priorities rank the chain from its end: a late heartbeat costs the most.
  EXPECT_GT(kThreadTable[kDriverThread].fifo_priority, kThreadTable[kControllerThread].fifo_priority);
  EXPECT_GT(kThreadTable[kControllerThread].fifo_priority, kThreadTable[kCameraThread].fifo_priority);
  EXPECT_GT(kThreadTable[kLcmThread].nice, 0);
}

TEST(ThreadTable, OffPinsNothing) {
  const CpuPlan plan = plan_cpus("off");
  EXPECT_TRUE(plan.chain.empty());
  EXPECT_TRUE(plan.others.empty());
  EXPECT_EQ(plan.describe, "not pinned");
}

TEST(ThreadTable, AutoGivesTheChainTheHighestCpuAndTheOthersTheRest) {
  const std::vector<int> cpus = allowed_cpus();
  const CpuPlan plan = plan_cpus("auto");
  if (cpus.size() < 2) {
    EXPECT_TRUE(plan.chain.empty());
    return;
  }
  ASSERT_EQ(plan.chain.size(), 1u);
  EXPECT_EQ(plan.chain[0], cpus.back());
  EXPECT_EQ(plan.others, std::vector<int>(cpus.begin(), cpus.end() - 1));
}

TEST(ThreadTable, ANamedCpuMustBeOneTheProcessMayUse) {
  const std::vector<int> cpus = allowed_cpus();
  const CpuPlan plan = plan_cpus(std::to_string(cpus.front()));
  EXPECT_EQ(plan.chain, std::vector<int>{cpus.front()});
  EXPECT_FALSE(plan.others.empty());
  try {
    plan_cpus("1023");
    FAIL() << "CPU 1023 accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("threads.chain_cpu: CPU 1023 is not one this process may use"),
              std::string::npos)
        << e.what();
  }
}

TEST(ThreadTable, PinningAndNicenessApplyToTheCallingThreadOnly) {
  const std::vector<int> cpus = allowed_cpus();
  std::thread t([&] {
    std::string why;
    ASSERT_TRUE(pin_current_thread({cpus.back()}, why)) << why;
    EXPECT_EQ(sched_getcpu(), cpus.back());
    ASSERT_TRUE(configure_current_thread(kLcmThread, false, why)) << why;
    errno = 0;
    EXPECT_EQ(getpriority(PRIO_PROCESS, static_cast<id_t>(gettid())), kThreadTable[kLcmThread].nice);
    char name[16] = {};
    pthread_getname_np(pthread_self(), name, sizeof name);
    EXPECT_STREQ(name, "pb-lcm");
  });
  t.join();
  EXPECT_EQ(getpriority(PRIO_PROCESS, static_cast<id_t>(gettid())), 0);  // this thread kept its niceness
  EXPECT_EQ(allowed_cpus(), cpus);                                     // and its CPUs
  std::string why;
  EXPECT_FALSE(pin_current_thread({1023}, why));
  EXPECT_NE(why.find("CPU affinity 1023"), std::string::npos) << why;
}

TEST(ThreadTable, CpuLatencyRequestIsHeldOrExplainsTheRefusal) {
  const CpuLatencyRequest request(0);
  if (request.ok()) {
    EXPECT_TRUE(request.why().empty());
  } else {
    EXPECT_NE(request.why().find("/dev/cpu_dma_latency 0 us: "), std::string::npos) << request.why();
  }
}

}  // namespace
}  // namespace pinball::daemon
