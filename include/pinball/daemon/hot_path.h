#pragma once
// Marks the per-frame work of the real-time threads, so a test can check that
// nothing in it allocates: the test binary's allocator counts allocations
// made while the calling thread's flag is set. Costs one thread-local store.

namespace pinball::daemon {

/// True while the calling thread is inside a HotPathScope.
inline thread_local bool t_in_hot_path = false;

/// Sets t_in_hot_path for its lifetime.
class HotPathScope {
 public:
  HotPathScope() { t_in_hot_path = true; }
  ~HotPathScope() { t_in_hot_path = false; }
  HotPathScope(const HotPathScope&) = delete;
  HotPathScope& operator=(const HotPathScope&) = delete;
};

}  // namespace pinball::daemon
