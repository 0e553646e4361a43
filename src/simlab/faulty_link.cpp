#include "pinball/simlab/faulty_link.h"

#include <stdexcept>
#include <string>

namespace pinball::simlab {

FaultyLink::FaultyLink(firmware::CanTransport& inner, FaultyLinkOptions options)
    : inner_(inner), options_(options), rng_(options.seed) {
  for (double p : {options.drop_p, options.delay_p, options.duplicate_p, options.corrupt_p}) {
    if (!(p >= 0.0 && p <= 1.0)) throw std::invalid_argument("FaultyLink: probability " + std::to_string(p) + " outside [0, 1]");
  }
  if (options.max_delay_frames < 1 || options.max_delay_frames > kMaxHeld) {
    throw std::invalid_argument("FaultyLink: max_delay_frames must be in 1.." + std::to_string(kMaxHeld));
  }
}

void FaultyLink::corrupt(firmware::CanFrame& frame) {
  ++faults_.corrupted;
  // One bit flip, as a noisy wire would do: mostly data, sometimes the length.
  if (frame.len == 0 || rng_.uniform01() < 0.1) {
    frame.len = static_cast<std::uint8_t>((frame.len ^ (1u << (rng_.next_u64() % 3))) & 0x0F);
    if (frame.len > 8) frame.len = 8;
    return;
  }
  const std::uint64_t bit = rng_.next_u64() % (8u * frame.len);
  frame.data[bit / 8] = static_cast<std::uint8_t>(frame.data[bit / 8] ^ (1u << (bit % 8)));
}

template <typename Emit>
void FaultyLink::process(const firmware::CanFrame& frame, bool outgoing, Emit&& emit) {
  ++faults_.frames;
  // Draw every decision up front so the stream does not depend on outcomes.
  const bool drop = rng_.uniform01() < options_.drop_p;
  const bool delay = rng_.uniform01() < options_.delay_p;
  const bool dup = rng_.uniform01() < options_.duplicate_p;
  const bool bad = rng_.uniform01() < options_.corrupt_p;
  const int wait = 1 + static_cast<int>(rng_.next_u64() % static_cast<std::uint64_t>(options_.max_delay_frames));
  firmware::CanFrame f = frame;
  if (!drop && bad) corrupt(f);
  if (drop) {
    ++faults_.dropped;
  } else if (delay && held_count_ < kMaxHeld) {
    ++faults_.delayed;
    held_[static_cast<std::size_t>(held_count_++)] = Held{f, wait + 1, outgoing};  // +1: this call decrements it
  } else {
    emit(f);
    if (dup) {
      ++faults_.duplicated;
      emit(f);
    }
  }
  // Frames held back in this direction come out after this one.
  for (int i = 0; i < held_count_;) {
    Held& h = held_[static_cast<std::size_t>(i)];
    if (h.outgoing == outgoing && --h.countdown <= 0) {
      emit(h.frame);
      held_[static_cast<std::size_t>(i)] = held_[static_cast<std::size_t>(--held_count_)];
    } else {
      ++i;
    }
  }
}

firmware::TxStatus FaultyLink::send(const firmware::CanFrame& frame) {
  if (!options_.on_send) return inner_.send(frame);
  firmware::TxStatus status = firmware::TxStatus::kOk;
  process(frame, true, [&](const firmware::CanFrame& f) {
    const firmware::TxStatus s = inner_.send(f);
    if (s != firmware::TxStatus::kOk) status = s;
  });
  return status;
}

firmware::RxStatus FaultyLink::receive(firmware::CanFrame& frame, int timeout_ms) {
  for (int first = 1;; first = 0) {
    if (rx_count_ > 0) {
      frame = rx_ready_[static_cast<std::size_t>(rx_head_)];
      rx_head_ = (rx_head_ + 1) % static_cast<int>(rx_ready_.size());
      --rx_count_;
      return firmware::RxStatus::kFrame;
    }
    firmware::CanFrame in;
    const firmware::RxStatus s = inner_.receive(in, first ? timeout_ms : 0);
    if (s != firmware::RxStatus::kFrame) return s;
    if (!options_.on_receive || in.error) return frame = in, firmware::RxStatus::kFrame;
    process(in, false, [&](const firmware::CanFrame& f) {
      if (rx_count_ >= static_cast<int>(rx_ready_.size())) return;  // cannot happen: bounded by kMaxHeld + 2
      rx_ready_[static_cast<std::size_t>((rx_head_ + rx_count_) % static_cast<int>(rx_ready_.size()))] = f;
      ++rx_count_;
    });
  }
}

void FaultyLink::flush_delayed() {
  for (int i = 0; i < held_count_; ++i) {
    const Held& h = held_[static_cast<std::size_t>(i)];
    if (h.outgoing) {
      (void)inner_.send(h.frame);
    } else if (rx_count_ < static_cast<int>(rx_ready_.size())) {
      rx_ready_[static_cast<std::size_t>((rx_head_ + rx_count_) % static_cast<int>(rx_ready_.size()))] = h.frame;
      ++rx_count_;
    }
  }
  held_count_ = 0;
}

}  // namespace pinball::simlab
