#pragma once
// Identified parameters laid over a board (issue 20): `pinball identify`
// fits the model's physical parameters to recorded play and writes them as
// an overlay; every command that holds a belief (`pinball sim`, `learn`,
// `bench transfer`, `pinballd`) reads it with --identified FILE (the
// daemon's configuration: `identified:`) and plays the board with those
// values instead of the file's. The board file keeps saying where things
// are; the overlay says how they behave on the table that was recorded.
// Every section is optional: a parameter the recordings could not identify
// is left out and keeps the board's value. Format: docs/identification.md.

#include <optional>
#include <string>
#include <vector>

#include "pinball/core/name_value.h"
#include "pinball/table/board.h"

namespace pinball::table {

/// The version this code writes and reads.
inline constexpr int kBoardOverlayVersion = 1;

/// The largest kick an overlay's obstacle group may give (m/s): a hard shot's speed.
inline constexpr double kMaxOverlayKick_mps = 10.0;

/// One identified number: its value, its standard uncertainty, and how many
/// recorded events it rests on.
struct IdentifiedValue {
  double value = 0.0;   ///< the estimate, in the unit its key names
  double stderr_ = 0.0; ///< one standard uncertainty (bootstrap or the fit's covariance), same unit
  int events = 0;       ///< events behind it (free flights, rebounds, shots, launches)

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(value));
    a->Visit(make_name_value("stderr", &stderr_));
    a->Visit(PINBALL_NVP(events));
  }
};

/// A group of obstacles that the board gives the same material (the same ρ
/// and kick): one identified ρ and kick for all of them.
struct ObstacleGroupOverlay {
  double board_rho = 0.0;               ///< the ρ the board file gives the group (what identified it)
  double board_kick_mps = 0.0;          ///< the kick the board file gives the group (m/s)
  std::vector<std::string> obstacles;   ///< the board's obstacle names in the group (every shape of each)
  IdentifiedValue rho;                  ///< identified reflectivity: normal speed out = ρ · normal speed in + kick
  std::optional<IdentifiedValue> kick_mps;  ///< identified kick (m/s); only for groups the board gives a kick
  std::optional<IdentifiedValue> friction;  ///< identified wall friction (sim::wall_friction_loss_mps); absent: the board's

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(board_rho));
    a->Visit(PINBALL_NVP(board_kick_mps));
    a->Visit(PINBALL_NVP(obstacles));
    a->Visit(PINBALL_NVP(rho));
    a->Visit(PINBALL_NVP(kick_mps));
    a->Visit(PINBALL_NVP(friction));
  }
};

/// One flipper as its shots identified it (learn/flipper_shots.h).
struct FlipperOverlay {
  std::string name;  ///< the board's flipper name
  std::optional<IdentifiedValue> mu;           ///< moment factor μ (dimensionless), at omega_rad_s when given, else the board's stroke speed
  std::optional<IdentifiedValue> omega_rad_s;   ///< the stroke's angular speed (rad/s); identify writes it only with μ
  std::optional<IdentifiedValue> rise_delay_s;  ///< command to the bat's first motion (s): the actuation delay

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(name));
    a->Visit(PINBALL_NVP(mu));
    a->Visit(PINBALL_NVP(omega_rad_s));
    a->Visit(PINBALL_NVP(rise_delay_s));
  }
};

/// The launcher as identified from launch speeds.
struct LauncherOverlay {
  IdentifiedValue pull;       ///< pull fraction P in (0, 1]: the fastest launch is P · speed clamp
  IdentifiedValue noise_max;  ///< launch speed P · (1 − R) · speed clamp, R ~ U[0, noise_max]

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(pull));
    a->Visit(PINBALL_NVP(noise_max));
  }
};

/// A whole overlay file.
struct BoardOverlay {
  int version = kBoardOverlayVersion;          ///< file format version
  std::string date;                            ///< when written, ISO 8601 UTC; set by write_board_overlay when empty
  std::string board;                           ///< the board file it was identified against
  std::vector<std::string> recordings;         ///< the logs it was identified from
  std::optional<IdentifiedValue> gravity_mps2; ///< g along the table (m/s², pointing −y)
  std::vector<ObstacleGroupOverlay> obstacle_groups;  ///< empty: none identified (section left out)
  std::vector<FlipperOverlay> flippers;        ///< empty: none identified (section left out)
  std::optional<LauncherOverlay> launcher;     ///< launch pull and noise
  std::optional<IdentifiedValue> wall_thickness_m;  ///< every two-sided wall's thickness (m; table::set_wall_thickness)

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(version));
    a->Visit(PINBALL_NVP(date));
    a->Visit(PINBALL_NVP(board));
    a->Visit(PINBALL_NVP(recordings));
    a->Visit(PINBALL_NVP(gravity_mps2));
    // Empty lists are not written; an absent section reads as empty.
    std::optional<std::vector<ObstacleGroupOverlay>> groups;
    if (!obstacle_groups.empty()) groups = obstacle_groups;
    a->Visit(make_name_value("obstacle_groups", &groups));
    obstacle_groups = groups.value_or(std::vector<ObstacleGroupOverlay>{});
    std::optional<std::vector<FlipperOverlay>> flips;
    if (!flippers.empty()) flips = flippers;
    a->Visit(make_name_value("flippers", &flips));
    flippers = flips.value_or(std::vector<FlipperOverlay>{});
    a->Visit(PINBALL_NVP(launcher));
    a->Visit(PINBALL_NVP(wall_thickness_m));
  }
};

/// The overlay as YAML text (what write_board_overlay writes).
std::string board_overlay_to_yaml(const BoardOverlay& overlay);

/// Writes the overlay to `path` (the date set to now when empty). Throws
/// std::runtime_error naming the file when it cannot be written.
void write_board_overlay(const BoardOverlay& overlay, const std::string& path);

/// Reads an overlay file. Throws KeyError "path:key: what is wrong" for a
/// missing, unknown, repeated, mistyped or out-of-range key (ρ in [0, 2],
/// kick in [0, 10] m/s, wall friction in [0, 2], wall thickness in [0, 0.05]
/// m, g in (0, 10] m/s², μ in [0, 10], ω in (0, 200] rad/s, rise delay in
/// [0, 0.1] s, pull in (0, 1], noise_max in [0, 0.5], stderr ≥ 0, events ≥
/// 0), an obstacle or flipper given twice, a kick for a group the board gives
/// none, or a wrong version; std::runtime_error naming the file when it
/// cannot be read or parsed.
BoardOverlay read_board_overlay(const std::string& path);

/// Parses YAML text; `name` stands for the file in messages.
BoardOverlay parse_board_overlay(const std::string& text, const std::string& name);

/// Lays the overlay over `board`: g, each group's obstacles' ρ, kick and friction (by
/// name, every shape of a named obstacle), each flipper's μ (by name), the
/// launcher's pull and noise, the two-sided walls' thickness, and each flipper's stroke speed where given (its
/// rise delay is not the board's: identified_actuation_delay_s). All or nothing: throws KeyError "name:key: ..."
/// (`name` stands for the overlay file) for an obstacle or flipper name the
/// board does not have, or for a pull, noise and g with which a launch could
/// not leave the launcher (the board loader's rule), leaving `board` untouched.
void apply_board_overlay(const BoardOverlay& overlay, const std::string& name, Board& board);

/// The actuation delay the overlay's flippers show: the mean of their
/// identified rise delays (s); nullopt when none has one.
std::optional<double> identified_actuation_delay_s(const BoardOverlay& overlay);

/// The belief every playing command holds: the board file, with the overlay
/// at `overlay_path` laid over it when that is not empty.
Board load_belief_board(const std::string& board_path, const std::string& overlay_path);

}  // namespace pinball::table
