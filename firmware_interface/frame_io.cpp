#include "frame_io.h"

#include <linux/can.h>
#include <poll.h>
#include <sys/socket.h>

#include <cerrno>
#include <cstring>
#include <ctime>

namespace pinball::firmware::detail {
namespace {

void sleep_us(int us) {
  timespec ts{0, static_cast<long>(us) * 1000L};
  while (nanosleep(&ts, &ts) != 0 && errno == EINTR) {
  }
}

std::int64_t wall_ns() {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

}  // namespace

TxStatus send_frame(int fd, const CanFrame& frame, const TxRetryPolicy& retry, AtomicTransportCounters& counters) {
  if (fd < 0) {
    counters.tx_failures.fetch_add(1, std::memory_order_relaxed);
    return TxStatus::kDown;
  }
  can_frame raw{};
  raw.can_id = frame.error ? ((frame.id & CAN_ERR_MASK) | CAN_ERR_FLAG) : (frame.id & CAN_SFF_MASK);
  raw.len = frame.len > CAN_MAX_DLEN ? CAN_MAX_DLEN : frame.len;
  std::memcpy(raw.data, frame.data.data(), raw.len);
  int backoff_us = retry.first_backoff_us;
  for (int attempt = 0;; ++attempt) {
    const ssize_t n = ::send(fd, &raw, sizeof raw, MSG_DONTWAIT | MSG_NOSIGNAL);
    if (n == static_cast<ssize_t>(sizeof raw)) {
      counters.tx_frames.fetch_add(1, std::memory_order_relaxed);
      return TxStatus::kOk;
    }
    const int err = n < 0 ? errno : EIO;
    if (err == EINTR) continue;
    if ((err == ENOBUFS || err == EAGAIN) && attempt < retry.max_retries) {
      counters.tx_retries.fetch_add(1, std::memory_order_relaxed);
      sleep_us(backoff_us);
      backoff_us *= 2;
      continue;
    }
    counters.tx_failures.fetch_add(1, std::memory_order_relaxed);
    if (err == ENOBUFS || err == EAGAIN) return TxStatus::kBufferFull;
    if (err == EPIPE || err == ECONNRESET || err == ENETDOWN || err == ENODEV || err == ENOTCONN) return TxStatus::kDown;
    return TxStatus::kError;
  }
}

RxStatus receive_frame(int fd, CanFrame& frame, int timeout_ms, AtomicTransportCounters& counters) {
  if (fd < 0) return RxStatus::kDown;
  if (timeout_ms > 0) {
    pollfd p{fd, POLLIN, 0};
    int r = 0;
    do {
      r = ::poll(&p, 1, timeout_ms);
    } while (r < 0 && errno == EINTR);
    if (r == 0) return RxStatus::kTimeout;
    if (r < 0) {
      counters.rx_errors.fetch_add(1, std::memory_order_relaxed);
      return RxStatus::kError;
    }
  }
  can_frame raw{};
  iovec iov{&raw, sizeof raw};
  alignas(cmsghdr) char control[CMSG_SPACE(sizeof(timespec)) * 2];
  msghdr msg{};
  msg.msg_iov = &iov;
  msg.msg_iovlen = 1;
  msg.msg_control = control;
  msg.msg_controllen = sizeof control;
  ssize_t n = 0;
  do {
    n = ::recvmsg(fd, &msg, MSG_DONTWAIT);
  } while (n < 0 && errno == EINTR);
  if (n < 0) {
    if (errno == EAGAIN) return RxStatus::kTimeout;
    if (errno == ENETDOWN || errno == ECONNRESET || errno == ENODEV) return RxStatus::kDown;
    counters.rx_errors.fetch_add(1, std::memory_order_relaxed);
    return RxStatus::kError;
  }
  if (n == 0) return RxStatus::kDown;  // the peer closed (SOCK_SEQPACKET)
  if (n != static_cast<ssize_t>(sizeof raw) || (msg.msg_flags & MSG_TRUNC) || raw.len > CAN_MAX_DLEN) {
    counters.rx_errors.fetch_add(1, std::memory_order_relaxed);
    return RxStatus::kError;
  }
  frame = CanFrame{};
  frame.error = (raw.can_id & CAN_ERR_FLAG) != 0;
  // NOLINTNEXTLINE(bugprone-branch-clone): the two masks are equal in value; each is named for what it keeps
  frame.id = frame.error ? (raw.can_id & CAN_ERR_MASK) : (raw.can_id & CAN_EFF_MASK);
  frame.len = raw.len;
  std::memcpy(frame.data.data(), raw.data, raw.len);
  frame.rx_time_ns = 0;
  for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c != nullptr; c = CMSG_NXTHDR(&msg, c)) {
    if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMPNS) {
      timespec ts{};
      std::memcpy(&ts, CMSG_DATA(c), sizeof ts);
      frame.rx_time_ns = static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
    }
  }
  if (frame.rx_time_ns == 0) frame.rx_time_ns = wall_ns();
  if (frame.error) {
    counters.error_frames.fetch_add(1, std::memory_order_relaxed);
  } else {
    counters.rx_frames.fetch_add(1, std::memory_order_relaxed);
  }
  return RxStatus::kFrame;
}

}  // namespace pinball::firmware::detail
