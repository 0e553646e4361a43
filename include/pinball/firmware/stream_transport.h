#pragma once
// CAN frames over any message-preserving socket (a socketpair in tests and in
// the simulator): each frame travels as Linux's 16-byte struct can_frame, the
// same bytes a CAN_RAW socket carries, so every test runs the real
// encode/send/receive path.

#include <memory>
#include <utility>

#include "pinball/firmware/can_transport.h"

namespace pinball::firmware {

/// A CanTransport over a SOCK_SEQPACKET or SOCK_DGRAM socket it owns.
class StreamTransport final : public CanTransport {
 public:
  /// Takes ownership of `fd`; throws std::invalid_argument unless it is a
  /// message-preserving socket (SOCK_SEQPACKET or SOCK_DGRAM).
  explicit StreamTransport(int fd, TxRetryPolicy retry = {});
  ~StreamTransport() override;
  StreamTransport(const StreamTransport&) = delete;
  StreamTransport& operator=(const StreamTransport&) = delete;

  /// Two connected ends of a fresh AF_UNIX SOCK_SEQPACKET socketpair (non-blocking).
  static std::pair<std::unique_ptr<StreamTransport>, std::unique_ptr<StreamTransport>> make_pair(
      TxRetryPolicy retry = {});

  TxStatus send(const CanFrame& frame) override;
  TxStatus send_without_waiting(const CanFrame& frame) override;
  RxStatus receive(CanFrame& frame, int timeout_ms) override;
  int poll_fd() const override { return fd_; }
  TransportCounters counters() const override { return counters_.snapshot(); }

  /// Closes the socket now (the peer then sees kDown): a cable pulled out.
  void close();
  /// The socket (for baselines that bypass the stack).
  int fd() const { return fd_; }

 private:
  int fd_ = -1;
  TxRetryPolicy retry_;
  AtomicTransportCounters counters_;
};

}  // namespace pinball::firmware
