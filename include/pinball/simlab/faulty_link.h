#pragma once
// A CanTransport decorator that drops, delays (reorders), duplicates and
// corrupts frames with given probabilities, deterministic by seed. Delay is
// counted in frames, not seconds, so that runs replay exactly.

#include <array>
#include <cstdint>

#include "pinball/core/rng.h"
#include "pinball/firmware/can_transport.h"

namespace pinball::simlab {

/// Fault probabilities (each drawn independently per frame) and where they apply.
struct FaultyLinkOptions {
  double drop_p = 0.0;        ///< probability a frame vanishes
  double delay_p = 0.0;       ///< probability a frame is held back behind later ones
  int max_delay_frames = 3;   ///< a delayed frame comes out after 1..max later frames
  double duplicate_p = 0.0;   ///< probability a frame arrives twice
  double corrupt_p = 0.0;     ///< probability one bit of the frame (data or length) flips
  std::uint64_t seed = 1;     ///< random stream
  bool on_send = true;        ///< apply to frames sent through this link
  bool on_receive = false;    ///< apply to frames received through this link
};

/// What the link did.
struct FaultyLinkCounters {
  std::uint64_t frames = 0;      ///< frames offered
  std::uint64_t dropped = 0;     ///< dropped
  std::uint64_t delayed = 0;     ///< held back
  std::uint64_t duplicated = 0;  ///< sent twice
  std::uint64_t corrupted = 0;   ///< a bit flipped
};

/// Fault injection on a link; owns nothing, borrows the inner transport.
class FaultyLink final : public firmware::CanTransport {
 public:
  /// Wraps `inner`; throws std::invalid_argument for a probability outside [0, 1]
  /// or max_delay_frames outside 1..kMaxHeld.
  FaultyLink(firmware::CanTransport& inner, FaultyLinkOptions options);

  firmware::TxStatus send(const firmware::CanFrame& frame) override;
  firmware::RxStatus receive(firmware::CanFrame& frame, int timeout_ms) override;
  int poll_fd() const override { return inner_.poll_fd(); }
  bool reopen() override { return inner_.reopen(); }
  firmware::TransportCounters counters() const override { return inner_.counters(); }

  /// Releases every held-back frame now (in the direction it was going).
  void flush_delayed();
  /// What the link did so far.
  const FaultyLinkCounters& fault_counters() const { return faults_; }

  /// Most frames held back at once.
  static constexpr int kMaxHeld = 16;

 private:
  struct Held {
    firmware::CanFrame frame;
    int countdown = 0;
    bool outgoing = true;
  };
  // Applies the faults to one frame; emits what survives through `emit`.
  template <typename Emit>
  void process(const firmware::CanFrame& frame, bool outgoing, Emit&& emit);
  void corrupt(firmware::CanFrame& frame);

  firmware::CanTransport& inner_;
  FaultyLinkOptions options_;
  Rng rng_;
  FaultyLinkCounters faults_;
  std::array<Held, kMaxHeld> held_{};
  int held_count_ = 0;
  std::array<firmware::CanFrame, 2 * kMaxHeld + 4> rx_ready_{};
  int rx_head_ = 0;
  int rx_count_ = 0;
};

}  // namespace pinball::simlab
