#include "pinball/bus/lcm_bus.h"

#include <pthread.h>

#include <chrono>
#include <stdexcept>
#include <vector>

#include "pinball/bus/channels.h"
#include "pinball/bus/message_convert.h"

namespace pinball::bus {

namespace {

extern "C" void raw_callback(const lcm_recv_buf_t* rbuf, const char*, void* user_data) {
  (*static_cast<RawHandler*>(user_data))(rbuf->data, static_cast<int>(rbuf->data_size));
}

}  // namespace

void subscribe_raw(lcm::LCM& lcm, const char* channel, RawHandler& handler) {
  lcm_subscribe(lcm.getUnderlyingLCM(), channel, &raw_callback, &handler);
}

LcmBus::LcmBus(const std::string& url)
    : lcm_(std::make_unique<lcm::LCM>(url)),
      url_(url),
      observations_{{}, kObservationChannel},
      projections_{{}, kProjectionChannel},
      commands_{{}, kFlipperCommandChannel},
      statuses_{{}, kDriverStatusChannel},
      games_{{}, kGameChannel} {
  if (!lcm_->good()) throw std::runtime_error("lcm: cannot open '" + url + "'");
}

LcmBus::~LcmBus() { stop(); }

void LcmBus::start(std::function<void(lcm::LCM&)> periodic, double period_s, std::function<void()> on_start) {
  if (running_.exchange(true)) throw std::logic_error("lcm bus already running");
  thread_ = std::thread([this, periodic = std::move(periodic), period_s, on_start = std::move(on_start)] {
    pthread_setname_np(pthread_self(), "pb-lcm");
    if (on_start) on_start();
    run(periodic, period_s);
  });
}

void LcmBus::stop() {
  if (!running_.exchange(false)) return;
  if (thread_.joinable()) thread_.join();
}

template <class T, std::size_t N>
bool LcmBus::push(Outbox<T, N>& box, const T& m) {
  if (box.ring.try_push(m)) return true;
  overflows_.fetch_add(1, std::memory_order_relaxed);
  return false;
}

bool LcmBus::try_publish(const pinball_lcm::lcmt_pinball_observation& m) { return push(observations_, m); }
bool LcmBus::try_publish(const pinball_lcm::lcmt_pinball_projection& m) { return push(projections_, m); }
bool LcmBus::try_publish(const pinball_lcm::lcmt_pinball_flipper_command& m) { return push(commands_, m); }
bool LcmBus::try_publish(const pinball_lcm::lcmt_pinball_driver_status& m) { return push(statuses_, m); }
bool LcmBus::try_publish(const pinball_lcm::lcmt_pinball_game_event& m) { return push(games_, m); }

void LcmBus::subscribe_observations(ObservationRing& ring) {
  inbox_ = &ring;
  observation_handler_ = [this](const void* data, int size) { on_observation(data, size); };
  subscribe_raw(*lcm_, kObservationChannel, observation_handler_);
}

void LcmBus::on_observation(const void* data, int size) {
  pinball_lcm::lcmt_pinball_observation m{};
  bool found = false;
  track::Observation o;
  track::ContactSensors c;
  if (m.decode(data, 0, size) < 0 || !from_lcm_observation(m, found, o, c)) {
    malformed_.fetch_add(1, std::memory_order_relaxed);
    return;
  }
  if (inbox_->try_push(m)) {
    received_.fetch_add(1, std::memory_order_relaxed);
  } else {
    overflows_.fetch_add(1, std::memory_order_relaxed);
  }
}

template <class T, std::size_t N>
int LcmBus::drain(Outbox<T, N>& box) {
  int n = 0;
  T m;
  while (box.ring.try_pop(m)) {
    lcm_->publish(box.channel, &m);
    ++n;
  }
  return n;
}

int LcmBus::drain() {
  const int n = drain(observations_) + drain(projections_) + drain(commands_) + drain(statuses_) + drain(games_);
  published_.fetch_add(static_cast<std::uint64_t>(n), std::memory_order_relaxed);
  return n;
}

void LcmBus::run(const std::function<void(lcm::LCM&)>& periodic, double period_s) {
  using clock = std::chrono::steady_clock;
  auto next = clock::now() + std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(period_s));
  while (running_.load(std::memory_order_acquire)) {
    const int n = drain();
    // Dispatch what arrived (and, for memq://, empty its queue of our own messages).
    while (lcm_->handleTimeout(0) > 0) {
    }
    if (periodic && clock::now() >= next) {
      periodic(*lcm_);
      next += std::chrono::duration_cast<clock::duration>(std::chrono::duration<double>(period_s));
    }
    // Publishing is not on anyone's critical path: a short nap when idle.
    if (n == 0 && lcm_->handleTimeout(1) < 0) {
      std::this_thread::sleep_for(std::chrono::microseconds(500));  // a provider that cannot receive (file://...?mode=w)
    }
  }
  drain();
  if (periodic) periodic(*lcm_);
  while (lcm_->handleTimeout(0) > 0) {
  }
}

LcmBusCounters LcmBus::counters() const {
  return {published_.load(std::memory_order_relaxed), overflows_.load(std::memory_order_relaxed),
          received_.load(std::memory_order_relaxed), malformed_.load(std::memory_order_relaxed)};
}

}  // namespace pinball::bus
