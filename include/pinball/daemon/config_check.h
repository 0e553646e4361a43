#pragma once
// `pinballd --check`: a configuration and every file it names, loaded and
// checked as pinballd would at start, without running a game. In the lab it
// also looks for the camera device and reads the CAN interface's state (an
// ioctl, no socket); it opens neither, and no LCM.

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "pinball/daemon/daemon_config.h"

namespace pinball::daemon {

/// What pinballd would run with, every path resolved.
struct ConfigCheck {
  std::string mode;                               ///< sim | lab
  std::string board;                              ///< the belief's board file
  std::string identified;                         ///< its overlay (empty: none)
  std::string world;                              ///< sim: the world that plays (model on a stepper, or twin)
  std::string controller;                         ///< the controller file
  std::string controller_kind;                    ///< spastic, planner, imitation or action function
  std::string calibration;                        ///< the calibration file (empty: none)
  std::vector<std::string> calibration_sections;  ///< the sections it holds, file order
  std::string camera;                             ///< the source as it would open
  std::string occluder_mask;                      ///< the mask file (empty: none)
  std::string can;                                ///< sim, or the interface and its bit rate
  std::string lcm_url;                            ///< where messages go
  std::vector<std::string> warnings;              ///< notes worth a look (e.g. a virtual CAN interface)
};

/// Validates `config` (after the command line's overrides), finds its data
/// files, loads the board with its overlay, the controller (and builds it on
/// that board), the calibration, the twin's parameters or the world board,
/// and for a lab camera the homography and the occluder mask; in mode lab,
/// the camera device must exist and the CAN interface be fit to run
/// (check_can_link). Throws ConfigError or std::runtime_error naming the
/// file and key of the first problem.
ConfigCheck check_daemon_config(DaemonConfig config);

/// Mode lab: the camera device exists (a file source decodes as a video) and
/// the CAN interface is fit to run (check_can_link), every missing piece
/// named at once in one ConfigError; returns the notes worth a warning.
/// pinballd's start runs it before it opens anything.
std::vector<std::string> check_lab_hardware(const DaemonConfig& config);

/// The check as text (one line per item) and as one JSON object.
std::string config_check_to_text(const ConfigCheck& check);
nlohmann::json config_check_to_json(const ConfigCheck& check);
/// A check that failed, as one JSON object: {"ok": false, "error": what the
/// check threw (every missing piece of the lab's hardware at once)}.
nlohmann::json config_check_failure_to_json(const std::string& error);

}  // namespace pinball::daemon
