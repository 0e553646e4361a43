#pragma once
// Flipper shots in recorded play, and the stroke they show (issue 20). The
// log does not show the bat, but it shows when each coil was energized and
// where the ball was struck: a shot is a free flight into a flipper's sweep
// and a free flight out of it, joined at one point, after an energize
// command of that flipper given while its bat was down. In the model the
// bat rises from its down stop at a constant ω after a delay d, so it meets
// a ball whose centre lies Δθ above the down position (the bat's angle that
// puts the ball one radius above its line) at
//     t_contact − t_command = d + Δθ / ω,
// a straight line in Δθ whose intercept is the rise delay (command to first
// motion, on the recording's clock: CAN, the coil's rise and any error in
// the frames' exposure stamps together, which is the delay a controller must
// lead by) and whose slope is the stroke's 1/ω. μ then comes from the model
// itself: each shot is played again on the thesis stepper from the flight in,
// with the bat moving as the command, d and ω say, and μ is the value whose
// ball leaves as the flight out does (a closed form would miss the second
// and third pushes a ball sliding out along the rising bat gets).

#include <algorithm>
#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "pinball/bus/recorded_play.h"
#include "pinball/learn/free_flight.h"
#include "pinball/table/board.h"
#include "pinball/table/board_overlay.h"

namespace pinball::learn {

/// How shots are found and fitted.
struct ShotOptions {
  double max_gap_s = 0.3;            ///< the flights in and out are at most this far apart (s)
  double join_tolerance_m = 0.008;   ///< both flights put the ball within this of each other at contact (m): a worse join is a double contact (a bounce on the bat before the stroke)
  double contact_tolerance_m = 0.003;///< the ball may start this far inside the down bat's line (m)
  double max_stroke_s = 0.1;         ///< contact at most this long after the command: the bat still moving (s)
  double min_down_s = 0.1;           ///< the flipper's last release at least this long before the command (s)
  double min_speed_out_mps = 0.5;    ///< a slower ball leaving the bat was not struck (m/s)
  int min_shots = 8;                 ///< a flipper needs this many shots for its stroke
};

/// One shot: a flipper's bat striking the ball while it rises.
struct FlipperShot {
  int flipper = -1;               ///< index into Board::flippers
  std::size_t recording = 0;      ///< index into the recordings
  double command_t_s = 0.0;       ///< the energize command (s)
  double contact_t_s = 0.0;       ///< where the flights in and out meet (s)
  Vec2 contact_m = Vec2::Zero();  ///< ball centre there (m)
  double stroke_rad = 0.0;        ///< Δθ: the bat's angle at contact above its down stop (rad)
  double arm_m = 0.0;             ///< contact point's distance along the bat from the pivot (m)
  double speed_in_mps = 0.0;      ///< ball's normal speed towards the bat before (m/s; ≤ 0: moving away)
  double speed_out_mps = 0.0;     ///< normal speed away from it after (m/s)
  double before_t_s = 0.0;        ///< the flight in's last frame (s)
  Vec2 before_p_m = Vec2::Zero();  ///< ball there, from the flight in's fit (m)
  Vec2 before_v_mps = Vec2::Zero();
  double after_t_s = 0.0;         ///< the flight out's first frame (s)
  Vec2 after_p_m = Vec2::Zero();   ///< ball there, from the flight out's fit (m)
  Vec2 after_v_mps = Vec2::Zero();
};

/// What one flipper's shots say.
struct FlipperStrokeFit {
  std::string name;                   ///< the board's flipper name
  int shots = 0;                      ///< shots found
  int outliers = 0;                   ///< left out of the timing fit
  bool identified = false;            ///< enough shots over enough of the stroke
  std::string why_not;                ///< when not identified
  table::IdentifiedValue rise_delay_s;  ///< d: command to the bat's first motion (s)
  table::IdentifiedValue omega_rad_s;   ///< ω: the stroke's angular speed (rad/s)
  std::optional<table::IdentifiedValue> mu;  ///< μ at the identified ω and d (trimmed mean over shots)
  double timing_rms_nominal_s = 0.0;  ///< RMS of contact time − board's prediction (board ω, nominal delay) (s)
  double timing_rms_fitted_s = 0.0;   ///< ... − identified prediction (s)
  double velocity_error_nominal_mps = 0.0; ///< median over shots of |velocity out − the model's replay| with the board's μ, ω and the nominal delay (m/s)
  double velocity_error_delay_only_mps = 0.0;  ///< ... with the board's μ and ω and the identified d (m/s)
  double velocity_error_fitted_mps = 0.0;  ///< ... with the identified μ, ω and d (m/s)
  /// The identified ω and μ replay the shots clearly closer (by a fifth) than
  /// the board's do at either delay, the nominal or the identified: only then
  /// are they worth laying over the board.
  bool stroke_replays_better() const {
    return mu && velocity_error_fitted_mps < 0.8 * std::min(velocity_error_nominal_mps, velocity_error_delay_only_mps);
  }
};

/// Every shot the recordings show. `flights` are free flights of
/// `recordings` in time order within each recording (find_free_flights).
std::vector<FlipperShot> find_flipper_shots(const table::Board& board, std::span<const bus::RecordedPlay> recordings,
                                            std::span<const FreeFlight> flights, const ShotOptions& options = {});

/// Fits flipper `flipper`'s rise delay, stroke speed and μ to its shots.
/// `nominal_delay_s` is the delay the board's prediction assumes. `board` is
/// the belief whose model replays the shots.
FlipperStrokeFit fit_flipper_stroke(const table::Board& board, int flipper, std::span<const FlipperShot> shots,
                                    double nominal_delay_s, const ShotOptions& options = {});

}  // namespace pinball::learn
