#include "pinball/daemon/thread_table.h"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>

#include <cerrno>
#include <cstring>

namespace pinball::daemon {

bool configure_current_thread(ThreadId id, bool realtime, std::string& why, int priority) {
  const ThreadSpec& spec = kThreadTable[static_cast<std::size_t>(id)];
  pthread_setname_np(pthread_self(), spec.name);
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

bool lock_memory(std::string& why) {
  if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0) {
    why = std::string("mlockall: ") + std::strerror(errno);
    return false;
  }
  return true;
}

}  // namespace pinball::daemon
