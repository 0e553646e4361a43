#pragma once
// Conversions between the C++ protocol types (CanFrame, Payload) and the C11
// firmware core's (pbfw_frame, pbfw_message): the host's codec and the
// reference board both go through the core, so the wire format and the board
// rules exist once.

#include "pinball/firmware/can_frame.h"
#include "pinball/firmware/core/wire.h"
#include "pinball/firmware/messages.h"

namespace pinball::firmware {

/// The frame as the core sees it (the receive time stays behind).
pbfw_frame to_core(const CanFrame& frame);
/// The core's frame as the host sees it.
CanFrame from_core(const pbfw_frame& frame);
/// The message for board `board` as the core encodes it.
pbfw_message to_core(std::uint8_t board, const Payload& payload);
/// The core's decoded message.
Message from_core(const pbfw_message& message);
/// A driver configuration both ways.
pbfw_driver_config to_core(const DriverConfig& config);
DriverConfig from_core(const pbfw_driver_config& config);

}  // namespace pinball::firmware
