#pragma once
// System identification (issue 20): the model's physical parameters from
// recorded play (bus::RecordedPlay, what `lcm-logger` keeps of pinballd), so
// the belief is the table that was recorded rather than the board file's
// guesses. What each kind of event identifies:
//  - free flights (free_flight.h): g along the table, with a sideways tilt,
//    a drag and the playfield's sliding friction (from the flights that
//    skid) reported as diagnostics the model cannot play;
//  - rebounds, two free flights joined at a board obstacle: the normal speed
//    out against the normal speed in gives ρ (and the kick, for obstacles the
//    board gives one) of each material group: the obstacles the board file
//    gives the same ρ and kick; the tangential speed lost gives the group's
//    wall friction (sim::wall_friction_loss_mps);
//  - launches, flights that start at the launcher: the pull and noise;
//  - the model itself, played from the recordings' moments 100 ms ahead
//    (prediction_error.h) with everything above laid over the board: the
//    two-sided walls' thickness, the one value that makes it predict best
//    (rebounds cannot give it: their flights' fits put the meeting point
//    a millimetre or more further out than the model wants the face);
//  - flipper shots, a free flight into a rising bat and one out of it after
//    the flipper's energize command (flipper_shots.h): each flipper's rise
//    delay, stroke speed and μ.
// Every figure comes with its standard uncertainty and the events behind it;
// a parameter without enough events is listed with the reason instead.
// The camera's latency is not identified apart from the rise delay: ball
// tracks cannot tell the two apart (docs/identification.md).

#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "pinball/bus/recorded_play.h"
#include "pinball/firmware/flipper_actuation.h"
#include "pinball/learn/flipper_shots.h"
#include "pinball/learn/free_flight.h"
#include "pinball/learn/prediction_error.h"
#include "pinball/table/board.h"
#include "pinball/table/board_overlay.h"

namespace pinball::learn {

/// Settings of an identification.
struct IdentifyOptions {
  FlightOptions flights;             ///< how free flights are found
  bool fit_drag = true;              ///< report the drag c that the flights show (the overlay's g is fitted without)
  int bootstrap = 50;                ///< resamples of flights for g's uncertainty (0: the fit's covariance)
  std::uint64_t seed = 1;            ///< bootstrap draws
  double max_rebound_gap_s = 0.05;   ///< two flights further apart in time are not one rebound (s)
  double contact_tolerance_m = 0.002;///< the extrapolated ball reaches the obstacle within this of its radius (m)
  double join_tolerance_m = 0.006;   ///< both flights put the ball within this of each other at contact (m)
  /// An obstacle with a kick (a pop bumper, a slingshot) holds the ball until
  /// its coil fires and throws it from its ring's reach: the flight out may
  /// pass this close to the contact (m), up to kick_dwell_s after it (s).
  double kick_join_tolerance_m = 0.02;
  double kick_dwell_s = 0.02;
  double min_normal_speed_mps = 0.15;///< a slower approach gives no usable ratio (m/s)
  int min_rebounds = 8;              ///< a group needs this many rebounds for ρ (and 2 more for a kick)
  /// A rebound whose speed out is above this share of the belief's clamp is
  /// left out of its group's fit (the flights' fits put a clamped ball's
  /// speed within about 1 % of the clamp).
  double clamp_share = 0.97;
  int min_launches = 5;              ///< launches needed for the pull and the noise
  double launch_reach_m = 0.03;      ///< a launch flight starts within this of the rest position across the chute, and up to 5x this above it (m)
  ShotOptions shots;                 ///< how flipper shots are found and fitted
  double nominal_actuation_delay_s = firmware::kDefaultActuationDelay_s;  ///< the delay the board's stroke prediction assumes
};

/// One rebound off a board obstacle.
struct Rebound {
  int group = -1;                 ///< index into IdentificationResult::groups
  int obstacle = -1;              ///< index into Board::obstacles
  double t_s = 0.0;               ///< contact time (s)
  Vec2 contact_m = Vec2::Zero();  ///< ball centre at contact (m)
  double speed_in_mps = 0.0;      ///< normal speed towards the obstacle (m/s, > 0)
  double speed_out_mps = 0.0;     ///< normal speed away from it (m/s)
  double tangent_in_mps = 0.0;    ///< speed along the obstacle coming in (m/s, >= 0)
  double tangent_out_mps = 0.0;   ///< speed along it going out, in the same direction (m/s; < 0: turned back)
};

/// A group's wall friction as its rebounds show it.
struct WallFrictionFit {
  double friction = 0.0;              ///< Coulomb coefficient (sim::wall_friction_loss_mps)
  double stderr_ = 0.0;               ///< its standard uncertainty (the fit's curvature)
  int used = 0;                       ///< rebounds kept
  int outliers = 0;                   ///< left out: residual beyond 3.5 robust σ
  double rms_frictionless_mps = 0.0;  ///< RMS of tangential speed out − in, over the rebounds kept (m/s)
  double rms_fitted_mps = 0.0;        ///< ... − the fitted friction's prediction (m/s)
};

/// Least squares over friction in [0, 2] of tangent out against what the
/// model's response (ρ, kick) with that friction gives, trimmed once at 3.5
/// robust σ. Needs at least 2 rebounds (throws std::invalid_argument).
WallFrictionFit fit_wall_friction(std::span<const Rebound> rebounds, double rho, double kick_mps);

/// One material group and what its rebounds say.
struct GroupResult {
  table::ObstacleGroupOverlay overlay;  ///< board values, names and (when identified) the fit
  bool identified = false;              ///< enough rebounds
  std::string why_not;                  ///< when not identified
  int rebounds = 0;                     ///< rebounds seen (before trimming outliers)
  /// Left out before the fit: the ball left at the belief's speed clamp,
  /// where the model's response no longer depends on ρ, kick or friction.
  int at_speed_clamp = 0;
  int outliers = 0;                     ///< left out: residual beyond 3.5 robust σ
  double rms_nominal_mps = 0.0;         ///< RMS of speed out − board prediction (m/s)
  double rms_fitted_mps = 0.0;          ///< ... − identified prediction (m/s)
  WallFrictionFit friction;             ///< when identified: the tangential speeds' fit
};

/// Fits one material group (its `overlay` holds the board's values) to its
/// rebounds: speed out against speed in, a line (through 0 without a kick)
/// trimmed once at 3.5 robust σ, then the wall friction. Rebounds that left
/// faster than o.clamp_share of `speed_max_mps`, where the model's clamp and
/// not ρ sets the speed, are counted and left out. Sets the group's counts,
/// residuals and fit, or its why_not when too few rebounds remain.
void fit_material_group(std::span<const Rebound> rebounds, const IdentifyOptions& o, double speed_max_mps,
                        GroupResult& group);

/// The two-sided walls' thickness that makes the model predict the
/// recordings' moments best (table::set_wall_thickness).
struct WallThicknessFit {
  bool identified = false;
  std::string why_not;                 ///< when not identified
  double thickness_m = 0.0;            ///< the best thickness (m)
  double stderr_m = 0.0;               ///< its standard uncertainty: bootstrap over the moments (m)
  bool at_scan_edge = false;           ///< least error at 0 or 4 mm: not bracketed, known no finer than a step
  std::size_t moments = 0;             ///< moments predicted at every thickness tried
  double error_at_zero_m = 0.0;        ///< mean 100 ms error with the walls the file's lines (m)
  double error_fitted_m = 0.0;         ///< ... with the best thickness (m)
  std::vector<std::pair<double, double>> scan;  ///< (thickness m, mean error m) at every thickness tried
};

/// Scans thicknesses 0 to 4 mm in steps of 0.5 mm, each the mean 100 ms
/// prediction error over the moments of `recordings` of `belief` with that
/// thickness, and takes the vertex of the parabola through the best and its
/// neighbours; `bootstrap` resamples of the moments give the uncertainty
/// (fewer than 2: not identified, for want of one).
/// Not identified (why_not) when the board has no two-sided wall or the
/// recordings hold fewer than 100 moments.
WallThicknessFit fit_wall_thickness(const table::Board& belief, std::span<const bus::RecordedPlay> recordings,
                                    const PredictionOptions& options, int bootstrap, std::uint64_t seed,
                                    const std::function<void(int, int)>& progress = {});

/// A parameter the recordings could not identify, and why.
struct NotIdentified {
  std::string parameter;  ///< e.g. "flipper mu", "obstacle group rho=1.4 kick=0.6 m/s"
  std::string why;        ///< what is missing or what else measures it
};

/// Everything an identification found.
struct IdentificationResult {
  table::BoardOverlay overlay;            ///< what the belief should lay over the board
  FlightGravity gravity;                  ///< shared acceleration, fitted with drag when asked (diagnostic)
  FlightGravity gravity_no_drag;          ///< the same without drag: what the model plays (the overlay's g)
  SlidingFriction sliding;                ///< what the skidding flights show (diagnostic: the model's ball never skids)
  std::vector<GroupResult> groups;        ///< every material group of the board with obstacles
  std::vector<Rebound> rebounds;          ///< every rebound used
  std::vector<double> launch_speeds_mps;  ///< launch speed at the launcher of every launch seen
  std::vector<FlipperShot> shots;         ///< every flipper shot found
  std::vector<FlipperStrokeFit> flipper_strokes;  ///< one per board flipper
  WallThicknessFit wall_thickness;        ///< the two-sided walls' thickness
  std::vector<NotIdentified> not_identified;
  std::size_t frames = 0;                 ///< frames read
  std::size_t sightings = 0;              ///< frames that saw the ball
  std::uint64_t malformed = 0;            ///< messages on the two channels left out: undecodable or a bad field
  std::string first_malformed;            ///< the first of them, its log and why (empty: none)
  std::size_t commands = 0;               ///< coil commands read
  double recorded_s = 0.0;                ///< total duration of the recordings (s)
  std::size_t flights = 0;                ///< free flights found
};

/// The board's material groups: obstacles with the same ρ and kick, named by
/// their obstacles' names (ball eaters left out: no ball comes back).
std::vector<table::ObstacleGroupOverlay> material_groups(const table::Board& board);
/// Each board obstacle's index into `groups` (-1: in none, e.g. a ball eater).
std::vector<int> material_group_of(const table::Board& board, const std::vector<table::ObstacleGroupOverlay>& groups);

/// Throws std::runtime_error naming the log when `play` cannot be of the
/// table `board` describes: more than 5 % of its sightings off the board by
/// more than 5 cm (another board, or a calibration in other units), commands
/// for a flipper the board lacks, or, in a log of 10 s or more, commands that
/// all lie outside the span of its frames (recorded on another clock). Said
/// instead of fitting nonsense.
void check_recording_fits_board(const bus::RecordedPlay& play, const table::Board& board);

/// Identifies what `recordings` show of the table `board` describes (the
/// belief: its geometry must be the recorded table's). `progress(stage,
/// done, total)` reports long stages, with done 0 as each starts. Throws std::runtime_error when the
/// recordings hold fewer than 2 free flights (nothing at all can be fitted).
IdentificationResult identify_table(const table::Board& board, std::span<const bus::RecordedPlay> recordings,
                                    const IdentifyOptions& options = {},
                                    const std::function<void(const std::string&, int, int)>& progress = {});

}  // namespace pinball::learn
