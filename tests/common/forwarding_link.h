#pragma once
// A CAN link that passes everything to another: the base of the tests' links
// that drop, hold or fail a frame, each overriding only what it changes. A send
// without waiting is its send(), as CanTransport has it: what a link does to
// a frame, it does on either path.

#include "pinball/firmware/can_transport.h"

namespace pinball::testing {

class ForwardingLink : public firmware::CanTransport {
 public:
  explicit ForwardingLink(firmware::CanTransport& inner) : inner_(inner) {}
  firmware::TxStatus send(const firmware::CanFrame& frame) override { return inner_.send(frame); }
  firmware::RxStatus receive(firmware::CanFrame& frame, int timeout_ms) override {
    return inner_.receive(frame, timeout_ms);
  }
  int poll_fd() const override { return inner_.poll_fd(); }
  bool reopen() override { return inner_.reopen(); }
  firmware::TransportCounters counters() const override { return inner_.counters(); }

 private:
  firmware::CanTransport& inner_;
};

}  // namespace pinball::testing
