#pragma once
// Private: the frame I/O shared by SocketCanTransport and StreamTransport.
// Both carry Linux's struct can_frame, one frame per datagram.

#include "pinball/firmware/can_transport.h"

namespace pinball::firmware::detail {

/// Non-blocking send of one frame with ENOBUFS/EAGAIN back-off (counted).
TxStatus send_frame(int fd, const CanFrame& frame, const TxRetryPolicy& retry, AtomicTransportCounters& counters);

/// poll() for up to timeout_ms, then recvmsg() one frame with its kernel
/// timestamp (SO_TIMESTAMPNS; the wall clock when the socket gives none).
RxStatus receive_frame(int fd, CanFrame& frame, int timeout_ms, AtomicTransportCounters& counters);

}  // namespace pinball::firmware::detail
