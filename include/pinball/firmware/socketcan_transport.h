#pragma once
// The lab's transport: a CAN_RAW socket on a named interface (can0), with
// receive filters for our ids, error frames (bus-off, controller problems, tx
// timeout), non-blocking I/O with poll, ENOBUFS back-off (counted) and kernel
// receive timestamps (SO_TIMESTAMPNS through recvmsg).

#include <string>

#include "pinball/firmware/can_transport.h"

namespace pinball::firmware {

/// Settings of a SocketCanTransport.
struct SocketCanOptions {
  std::string interface = "can0";  ///< network interface name (can0, vcan0)
  bool error_frames = true;        ///< ask the kernel for error frames
  bool receive_own = false;        ///< also receive our own frames (CAN_RAW_RECV_OWN_MSGS; for tests)
  TxRetryPolicy retry;             ///< ENOBUFS back-off
};

/// A CanTransport on a SocketCAN interface.
class SocketCanTransport final : public CanTransport {
 public:
  /// Opens and binds the socket; throws std::runtime_error naming the
  /// interface and the failed call (no PF_CAN in the kernel, no such interface, ...).
  explicit SocketCanTransport(SocketCanOptions options);
  ~SocketCanTransport() override;
  SocketCanTransport(const SocketCanTransport&) = delete;
  SocketCanTransport& operator=(const SocketCanTransport&) = delete;

  /// Empty when `interface` can be opened here, else why not (for skipping tests).
  static std::string unavailable_reason(const std::string& interface);

  TxStatus send(const CanFrame& frame) override;
  TxStatus send_without_waiting(const CanFrame& frame) override;
  RxStatus receive(CanFrame& frame, int timeout_ms) override;
  int poll_fd() const override { return fd_; }
  /// Closes and opens the socket again (after bus-off, once the kernel restarted the controller).
  bool reopen() override;
  TransportCounters counters() const override { return counters_.snapshot(); }

 private:
  int open_socket();  // returns fd; throws std::runtime_error

  SocketCanOptions options_;
  int fd_ = -1;
  AtomicTransportCounters counters_;
};

}  // namespace pinball::firmware
