#pragma once
// Whether a window can open here. OpenCV's window (Qt) aborts the whole
// process when its display does not answer: a stale SSH X forwarding gave
// SIGABRT and exit 134 in place of a message. The check connects to the
// server first, as the window would.

#include <string>

namespace pinball::cli {

/// "" when a window can open: QT_QPA_PLATFORM offscreen or minimal, a
/// Wayland compositor answering at WAYLAND_DISPLAY, or an X server at
/// DISPLAY (its Unix socket, or TCP port 6000 + N on another host, waited
/// on for at most a second). Else why not: "DISPLAY is not set", or the
/// display named and where nothing answered.
std::string display_problem();

}  // namespace pinball::cli
