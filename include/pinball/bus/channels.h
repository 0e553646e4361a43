#pragma once
// LCM channel names of the daemon (upper case, the LCM convention). One
// message type per channel, defined in src/bus/lcmtypes/.

#include <array>

namespace pinball::bus {

inline constexpr const char* kObservationChannel = "PINBALL_OBSERVATION";     ///< lcmt_pinball_observation
inline constexpr const char* kProjectionChannel = "PINBALL_PROJECTION";       ///< lcmt_pinball_projection
inline constexpr const char* kFlipperCommandChannel = "PINBALL_FLIPPER_CMD";  ///< lcmt_pinball_flipper_command
inline constexpr const char* kDriverStatusChannel = "PINBALL_DRIVER_STATUS";  ///< lcmt_pinball_driver_status
inline constexpr const char* kGameChannel = "PINBALL_GAME";                   ///< lcmt_pinball_game_event
inline constexpr const char* kStatsChannel = "PINBALL_STATS";                 ///< lcmt_pinball_daemon_stats

/// Every channel the daemon publishes, for the readers that take them all.
inline constexpr std::array<const char*, 6> kDaemonChannels = {kObservationChannel,    kProjectionChannel,
                                                               kFlipperCommandChannel, kDriverStatusChannel,
                                                               kGameChannel,           kStatsChannel};

}  // namespace pinball::bus
