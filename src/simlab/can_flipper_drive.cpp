#include "pinball/simlab/can_flipper_drive.h"

#include <stdexcept>

namespace pinball::simlab {

CanFlipperDrive::CanFlipperDrive(const table::Board& board, double actuation_delay_s) {
  const int n = static_cast<int>(board.flippers.size());
  if (n < 1 || n > firmware::kMaxDrivers) {
    throw std::invalid_argument("CAN flipper drive: the board needs 1 to " + std::to_string(firmware::kMaxDrivers) +
                                " flippers, it has " + std::to_string(n));
  }
  auto [host, link] = firmware::StreamTransport::make_pair();
  host_end_ = std::move(host);
  board_end_ = std::move(link);
  firmware::DriverBusOptions options;
  options.driver_count = n;
  bus_ = std::make_unique<firmware::DriverBus>(*host_end_, options);
  for (int i = 0; i < n; ++i) {
    actuation_.push_back(std::make_unique<firmware::FlipperActuation>(i, actuation_delay_s));
    board_.add_listener(actuation_.back().get());
  }
  commanded_.assign(static_cast<std::size_t>(n), false);
  for (const table::Flipper& f : board.flippers) theta_max_.push_back(f.theta_max_rad);
}

void CanFlipperDrive::apply(sim::GameState& state) {
  const double now = state.time_s;
  for (std::size_t i = 0; i < commanded_.size(); ++i) {
    board_.set_end_of_stroke(static_cast<int>(i), state.flippers[i].theta_rad >= theta_max_[i]);
  }
  for (std::size_t i = 0; i < commanded_.size(); ++i) {
    const bool want = state.flippers[i].energized;
    if (want == commanded_[i]) continue;
    // A refused command (bus not running yet, queue full) is retried next step.
    const bool queued = want ? bus_->fire(static_cast<int>(i)) : bus_->release(static_cast<int>(i));
    if (queued) commanded_[i] = want;
  }
  bus_->poll_once(now);
  board_.service(*board_end_, now);
  bus_->poll_once(now);  // read the board's answers within the same step
  for (std::size_t i = 0; i < commanded_.size(); ++i) {
    state.flippers[i].energized = actuation_[i]->energized(now);
  }
}

}  // namespace pinball::simlab
