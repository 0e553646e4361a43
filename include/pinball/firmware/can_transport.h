#pragma once
// The seam between the CAN stack and the wire: send and receive whole frames.
// Implementations: SocketCanTransport (the lab's can0), StreamTransport (a
// socket pair, for tests and the simulator), FaultyLink (a decorator that
// injects faults). Send never blocks for long; receive waits at most its timeout.

#include <atomic>
#include <cstdint>

#include "pinball/firmware/can_frame.h"

namespace pinball::firmware {

/// Outcome of a send.
enum class TxStatus : std::uint8_t {
  kOk = 0,       ///< queued for the wire
  kBufferFull,   ///< the kernel kept refusing (ENOBUFS/EAGAIN) after the retries
  kDown,         ///< the interface or the peer is gone
  kError,        ///< any other failure (counted)
};

/// Outcome of a receive.
enum class RxStatus : std::uint8_t {
  kFrame = 0,  ///< a frame was stored
  kTimeout,    ///< nothing arrived within the timeout
  kDown,       ///< the interface or the peer is gone
  kError,      ///< a malformed read or a socket error (counted)
};

/// Bounded retry with exponential back-off when the kernel's queue is full.
struct TxRetryPolicy {
  int max_retries = 4;        ///< retries after the first attempt
  int first_backoff_us = 50;  ///< first wait, doubled each retry (50+100+200+400 us at most)
};

/// Snapshot of a transport's counters.
struct TransportCounters {
  std::uint64_t tx_frames = 0;     ///< frames handed to the wire
  std::uint64_t tx_retries = 0;    ///< ENOBUFS/EAGAIN retries (back-off waits)
  std::uint64_t tx_failures = 0;   ///< sends that gave up
  std::uint64_t rx_frames = 0;     ///< data frames received
  std::uint64_t rx_errors = 0;     ///< malformed reads and socket errors
  std::uint64_t error_frames = 0;  ///< controller error frames received (bus-off, ...)
};

/// Counters shared between a transport's threads (relaxed atomics).
struct AtomicTransportCounters {
  std::atomic<std::uint64_t> tx_frames{0};     ///< see TransportCounters
  std::atomic<std::uint64_t> tx_retries{0};    ///< see TransportCounters
  std::atomic<std::uint64_t> tx_failures{0};   ///< see TransportCounters
  std::atomic<std::uint64_t> rx_frames{0};     ///< see TransportCounters
  std::atomic<std::uint64_t> rx_errors{0};     ///< see TransportCounters
  std::atomic<std::uint64_t> error_frames{0};  ///< see TransportCounters

  /// A consistent-enough copy for reporting.
  TransportCounters snapshot() const {
    return {tx_frames.load(std::memory_order_relaxed), tx_retries.load(std::memory_order_relaxed),
            tx_failures.load(std::memory_order_relaxed), rx_frames.load(std::memory_order_relaxed),
            rx_errors.load(std::memory_order_relaxed), error_frames.load(std::memory_order_relaxed)};
  }
};

/// Whole-frame CAN I/O.
class CanTransport {
 public:
  virtual ~CanTransport() = default;

  /// Sends one frame without blocking beyond the retry policy's back-off.
  virtual TxStatus send(const CanFrame& frame) = 0;
  /// Sends one frame, or reports kBufferFull at once where send() would back
  /// off and retry: for a real-time thread, which must not sleep. A transport
  /// that never waits need not override it.
  virtual TxStatus send_without_waiting(const CanFrame& frame) { return send(frame); }
  /// Receives one frame (data or error), waiting at most `timeout_ms` (0: poll only).
  virtual RxStatus receive(CanFrame& frame, int timeout_ms) = 0;
  /// A file descriptor that becomes readable when a frame may be waiting (-1: none).
  virtual int poll_fd() const = 0;
  /// Re-opens the link after bus-off or loss; true when it is usable again.
  virtual bool reopen() { return true; }
  /// The transport's counters.
  virtual TransportCounters counters() const = 0;
};

}  // namespace pinball::firmware
