#include "pinball/daemon/thread_table.h"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <fcntl.h>
#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstring>
#include <thread>

#include "pinball/daemon/daemon_config.h"

namespace pinball::daemon {

std::string thread_table_markdown() {
  std::string out = "| thread | SCHED_FIFO | nice | CPU | runs | does |\n|---|---|---|---|---|---|\n";
  for (const ThreadSpec& t : kThreadTable) {
    out += std::string("| ") + t.name + " | " + (t.fifo_priority > 0 ? std::to_string(t.fifo_priority) : "-") +
           " | " + std::to_string(t.nice) + " | " + t.cpu + " | " + t.period + " | " + t.job + " |\n";
  }
  return out;
}

bool configure_current_thread(ThreadId id, bool realtime, std::string& why, int priority) {
  const ThreadSpec& spec = kThreadTable[static_cast<std::size_t>(id)];
  pthread_setname_np(pthread_self(), spec.name);
  // On Linux a thread's niceness is its own: PRIO_PROCESS with the thread id.
  if (spec.nice != 0 && setpriority(PRIO_PROCESS, static_cast<id_t>(gettid()), spec.nice) != 0) {
    why = std::string("nice ") + std::to_string(spec.nice) + " for " + spec.name + ": " + std::strerror(errno);
    return false;
  }
  if (priority < 0) priority = spec.fifo_priority;
  if (!realtime || priority <= 0) return true;
  sched_param p{};
  p.sched_priority = priority;
  const int rc = pthread_setschedparam(pthread_self(), SCHED_FIFO, &p);
  if (rc != 0) {
    why = std::string("SCHED_FIFO ") + std::to_string(priority) + " for " + spec.name + ": " + std::strerror(rc);
    return false;
  }
  return true;
}

namespace {
std::string cpu_list(const std::vector<int>& cpus) {
  std::string s;
  for (const int c : cpus) {
    if (!s.empty()) s += ',';
    s += std::to_string(c);  // appended piecewise: GCC 12 warns falsely (-Wrestrict) on "," + string
  }
  return s;
}
}  // namespace

CpuPlan plan_cpus(const std::string& chain_cpu) {
  CpuPlan plan;
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  if (chain_cpu == "off" || sched_getaffinity(0, sizeof allowed, &allowed) != 0) {
    plan.describe = "not pinned";
    return plan;
  }
  std::vector<int> cpus;
  for (int c = 0; c < CPU_SETSIZE; ++c) {
    if (CPU_ISSET(c, &allowed)) cpus.push_back(c);
  }
  int chain = -1;
  if (chain_cpu == "auto") {
    if (cpus.size() < 2) {
      plan.describe = "not pinned (one CPU)";
      return plan;
    }
    chain = cpus.back();
  } else {
    chain = std::stoi(chain_cpu);
    if (std::find(cpus.begin(), cpus.end(), chain) == cpus.end()) {
      throw ConfigError("threads.chain_cpu: CPU " + chain_cpu + " is not one this process may use (" +
                        cpu_list(cpus) + ")");
    }
  }
  plan.chain = {chain};
  for (const int c : cpus) {
    if (c != chain) plan.others.push_back(c);
  }
  if (plan.others.empty()) plan.others = plan.chain;  // one CPU named: everything on it
  plan.describe = "chain on CPU " + std::to_string(chain) + ", others on " + cpu_list(plan.others);
  return plan;
}

bool pin_current_thread(const std::vector<int>& cpus, std::string& why) {
  if (cpus.empty()) return true;
  cpu_set_t set;
  CPU_ZERO(&set);
  for (const int c : cpus) CPU_SET(c, &set);
  const int rc = pthread_setaffinity_np(pthread_self(), sizeof set, &set);
  if (rc != 0) {
    why = "CPU affinity " + cpu_list(cpus) + ": " + std::strerror(rc);
    return false;
  }
  return true;
}

CpuLatencyRequest::CpuLatencyRequest(int limit_us) {
  // The kernel keeps the request for as long as the file stays open.
  fd_ = ::open("/dev/cpu_dma_latency", O_WRONLY | O_CLOEXEC);
  const std::int32_t value = limit_us;
  if (fd_ >= 0 && ::write(fd_, &value, sizeof value) == static_cast<ssize_t>(sizeof value)) return;
  why_ = "/dev/cpu_dma_latency " + std::to_string(limit_us) + " us: " + std::strerror(errno);
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

CpuLatencyRequest::~CpuLatencyRequest() {
  if (fd_ >= 0) ::close(fd_);
}

std::string probe_sched_fifo(ThreadId id, int priority) {
  std::string why;
  std::thread([&] { configure_current_thread(id, true, why, priority); }).join();
  return why;
}

std::string probe_lock_memory() {
  std::string why;
  if (lock_memory(why)) munlockall();
  return why;
}

bool lock_memory(std::string& why) {
  if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0) {
    why = std::string("mlockall: ") + std::strerror(errno);
    return false;
  }
  return true;
}

}  // namespace pinball::daemon
