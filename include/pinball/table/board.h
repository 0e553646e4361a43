#pragma once
// The static description of a pinball table (thesis 3.2): obstacles, flippers,
// launcher, sensors and the constants of the game. Built once by the board
// loader and never changed while a game runs; everything that changes lives in
// GameState. Units: metres, seconds, radians, board frame (origin bottom-left
// of the playfield, +x right, +y up the table).

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "pinball/core/geometry.h"

namespace pinball::table {

/// Primitive shape of an obstacle or sensor (thesis 3.2.3).
enum class ShapeKind : std::uint8_t {
  kLine,    ///< directed segment p0 -> p1; reflects only on the side of its normal
  kCircle,  ///< circle of radius_m around p0; radius 0 is a point
};

/// Geometry of one primitive: the hot data the collision search reads.
struct Shape {
  ShapeKind kind = ShapeKind::kLine;  ///< line or circle
  Vec2 p0 = Vec2::Zero();             ///< line start X1, or circle centre (m)
  Vec2 p1 = Vec2::Zero();             ///< line end X2 (m); unused for circles
  Vec2 normal = Vec2::Zero();         ///< line unit normal, left of p0 -> p1; unused for circles
  double radius_m = 0.0;              ///< circle radius (m); 0 for points and lines
};

/// What happens when the ball strikes (or, for sensors, enters) something.
struct Action {
  double score = 0.0;                ///< points per hit or entry
  double kick_mps = 0.0;             ///< speed added along the contact normal on a hit (active bumper)
  double contact_score_per_s = 0.0;  ///< points per second while the ball touches it (left passage)
  bool eats_ball = false;            ///< ball eater: the ball is lost (drain, thesis 3.2.3)
};

/// The largest wall friction a board or an overlay may give: no surface a ball rolls on has more.
inline constexpr double kMaxWallFriction = 2.0;

/// The largest reflectivity ρ a board or an overlay may give: > 1 kicks, and 2
/// already doubles the normal speed.
inline constexpr double kMaxRho = 2.0;

/// The largest g along the table a board or an overlay may give (m/s²): at
/// most g itself (9.81), with rounding.
inline constexpr double kMaxGravity_mps2 = 10.0;

/// The largest launch noise R_max a board or an overlay may give: a launch
/// is P · (1 − R) · the clamp, R ~ U[0, R_max], so 0.5 already halves it.
inline constexpr double kMaxLaunchNoise = 0.5;

/// The largest flipper friction coefficient a board or an overlay may give
/// (rubber on a ball is about 1; 1e154 overflowed the clamp to a stopped ball).
inline constexpr double kMaxFlipperMu = 10.0;
/// The fastest flipper stroke a board or an overlay may give (rad/s): a real
/// coil turns a blade at 30 to 60 rad/s; 1e5 rad/s, the whole stroke inside
/// one step, had passed with a blade no longer than the ball's radius.
inline constexpr double kMaxFlipperOmega_rad_s = 200.0;
/// The most points one hit, one second of contact or one bank may give: a
/// score summed over a long game stays far from overflow, and none is negative.
inline constexpr double kMaxPoints = 1e6;

/// The time steps a board's `dt` line, and a command's --dt, may give (s).
/// Below 1 µs a ball takes millions of steps a second of play (1e-12: never
/// ends); above 10 ms a 5 m/s ball jumps 5 cm, through any post.
inline constexpr double kMinDt_s = 1e-6;
inline constexpr double kMaxDt_s = 0.01;

/// A reflecting obstacle: shape, reflectivity and action (thesis 3.2.3).
struct Obstacle {
  double rho = 1.0;       ///< reflectivity: normal speed out = rho x normal speed in; > 1 kicks
  double friction = 0.0;  ///< Coulomb friction at a hit (sim::wall_friction_loss_mps); 0: the thesis's frictionless wall
  Action action;          ///< score, kick, eat
  bool visible = true;    ///< visibility at the start of a game (thesis 3.4); hidden ones are not hit
  int bank = -1;          ///< index into Board::banks when it is a flag of a bank, else -1
  std::string name;       ///< for traces and errors: the file's name= or "<kind>@<line>"
  int source_line = 0;    ///< line of the board file it came from; the shapes of one line are one
                          ///< object (a flag made of a wall falls whole); 0 (built in code): its own object
};

/// Kind of a non-reflecting sensor (thesis 3.4).
enum class SensorKind : std::uint8_t {
  kProximity,  ///< fires when the ball touches its shape; does not reflect
  kHole,       ///< fires when the ball's centre enters the circle (the ball falls in)
};

/// Default half-width of a kickout's direction spread (rad): 5°. A saucer's
/// kicker never strikes the ball the same way twice; without a spread a table
/// can hold the ball in a loop that repeats to the bit (issue 17).
inline constexpr double kDefaultKickoutSpread_rad = 0.087266462599716474;
/// Default kickout speed noise: the speed is scaled by 1 − R, R ~ U[0, 0.1].
inline constexpr double kDefaultKickoutNoise = 0.1;

/// A proximity sensor or a hole. Fires once per entry.
struct Sensor {
  SensorKind kind = SensorKind::kProximity;  ///< proximity or hole
  Shape shape;                               ///< line or circle (holes: circle)
  Action action;                             ///< score, eat
  bool has_kickout = false;                  ///< hole that ejects the ball instead of eating it
  Vec2 kickout_mps = Vec2::Zero();           ///< nominal velocity the ball leaves a hole with (m/s)
  double kickout_spread_rad = kDefaultKickoutSpread_rad;  ///< kickout turned by U[−spread, spread] (rad)
  double kickout_noise = kDefaultKickoutNoise;            ///< kickout speed × (1 − R), R ~ U[0, noise]
  std::string name;                          ///< for traces and errors
  int source_line = 0;                       ///< line of the board file it came from
};

/// A bank of flags (drop targets, thesis 3.4): each flag hides when hit; when
/// all are hidden the bank pays its bonus and all reappear.
struct Bank {
  std::string name;          ///< as declared in the file
  double bonus = 0.0;        ///< points when the last flag falls
  std::vector<int> members;  ///< indices into Board::obstacles
};

/// Which way a flipper points from its pivot.
enum class Side : std::uint8_t { kLeft, kRight };

/// A flipper (thesis 3.2.4): a segment of length_m rotating about the pivot,
/// with an end point at each end. theta is the elevation of the flipper above
/// the horizontal, measured the same way for both sides: a left flipper points
/// along (cos θ, sin θ), a right one along (−cos θ, sin θ). θ_min is the rest
/// ("down") stop, θ_max the energised ("up") stop; positive θ̇ raises it.
struct Flipper {
  Side side = Side::kLeft;     ///< left flippers point right, right flippers point left
  Vec2 pivot = Vec2::Zero();   ///< pivot point (m)
  double length_m = 0.0;       ///< pivot to tip (m)
  double theta_min_rad = 0.0;  ///< down stop (rad)
  double theta_max_rad = 0.0;  ///< up stop (rad)
  double omega_rad_s = 0.0;    ///< θ̇₀: angular speed while moving (rad/s), > 0
  double rho = 1.0;            ///< reflectivity of the flipper's three obstacles
  double mu = 0.0;             ///< moment factor μ: imparted speed = l_moment·μ·θ̇ (dimensionless)
  std::string name;            ///< for traces and errors
  int source_line = 0;         ///< line of the board file it came from
};

/// The plunger (thesis 3.2.2, 3.3.1).
struct Launcher {
  Vec2 position = Vec2::Zero();  ///< where the ball sits in the chute before a launch (m)
  double pull = 1.0;             ///< default pull fraction P_val in (0, 1]
  double noise_max = 0.03;       ///< launch speed is P·(1 − R)·speed_max with R ~ U[0, noise_max]
};

/// A ball in play within one ball radius of the launch point and slower than
/// this is back in the launcher and is launched again (thesis 5.1).
inline constexpr double kLauncherStillSpeed_mps = 0.05;

/// Where a ball is served and how fast, in place of the plunger's launch
/// (board statement `start`; scenes and tests).
struct BallStart {
  Vec2 position = Vec2::Zero();      ///< centre (m)
  Vec2 velocity_mps = Vec2::Zero();  ///< velocity (m/s)
};

/// Ball constants (thesis 3.2.1).
struct BallSpec {
  double radius_m = 0.0135;     ///< ball radius (m)
  double speed_max_mps = 5.0;   ///< speed clamp (m/s): stands in for friction
};

/// The whole static table.
struct Board {
  std::string source;            ///< file it was loaded from (for messages)
  double width_m = 0.51;         ///< playfield width (m)
  double height_m = 1.07;        ///< playfield height (m)
  BallSpec ball;                 ///< ball radius and speed clamp
  double gravity_mps2 = 1.11;    ///< component of g along the table, pointing −y (m/s²)
  double dt_s = 0.0005;          ///< default time step of the thesis stepper (s)
  int balls_per_game = 3;        ///< balls before the game resets
  Launcher launcher;             ///< plunger
  std::optional<BallStart> start;  ///< serve every ball from here instead of launching it; none: the plunger
  std::vector<Shape> shapes;     ///< reflecting obstacles' geometry (hot)
  std::vector<Obstacle> obstacles;  ///< reflecting obstacles' attributes, same index as shapes (cold)
  std::vector<Sensor> sensors;   ///< proximity sensors and holes
  std::vector<Flipper> flippers; ///< flippers, in file order
  std::vector<Bank> banks;       ///< banks of flags
  double wall_thickness_m = 0.0; ///< every two-sided wall's thickness: its faces lie half of it either side of the file's line (set_wall_thickness)
};

/// A line shape from p0 to p1 whose normal points to the left of p0 -> p1.
Shape make_line_shape(const Vec2& p0, const Vec2& p1);

/// A circle shape around `centre` (radius 0: a point).
Shape make_circle_shape(const Vec2& centre, double radius_m);

/// Gives every two-sided wall (a line and its exact reverse, whichever
/// statements made them) the thickness `thickness_m`: its two faces move to
/// half of it either side of the wall's centre line, the board file's line,
/// so the ball bounces off a guide's faces rather than off its middle. The
/// end points stay on the centre line (a guide's end is square, not round);
/// one-sided lines and circles keep their place. Setting it again starts
/// from the centre lines. Throws std::invalid_argument for a negative or
/// non-finite thickness.
void set_wall_thickness(Board& board, double thickness_m);

/// Distance from a point p to a shape's surface (lines: to the segment,
/// either side; circles: to the rim, negative inside).
double distance_to_shape(const Shape& shape, const Vec2& p);

/// What a ball of the board's radius centred at `p` would overlap: an
/// obstacle (by name) or a flipper in its down position ("flipper 'name'
/// in its down position"), and the distance from `p` to it (m).
struct BallOverlap {
  std::string what;
  double distance_m = 0.0;
};
/// The first overlap of a ball centred at `p`; std::nullopt when it is clear
/// of every obstacle and flipper (down).
std::optional<BallOverlap> ball_overlap(const Board& board, const Vec2& p);

/// "left" or "right": how board and calibration files spell a side.
std::string_view side_name(Side side);

/// The side `text` names ("left" or "right"); nullopt for anything else.
std::optional<Side> parse_side(std::string_view text);

/// Unit vector from pivot to tip at elevation theta_rad.
Vec2 flipper_direction(const Flipper& f, double theta_rad);

/// Unit normal of the flipper's upper face at theta_rad: the direction the
/// face moves when θ increases.
Vec2 flipper_up_normal(const Flipper& f, double theta_rad);

/// Tip position at theta_rad (m).
Vec2 flipper_tip(const Flipper& f, double theta_rad);

/// The board's index of its left and of its right flipper, in that order
/// (the order controllers give commands in); -1 where the board has none.
/// With two of one side, the last in the file.
std::array<int, 2> flippers_by_side(const Board& board);

/// The flipper whose rest segment (pivot to tip at θ_min) is nearest to `p`,
/// and that distance (m): {-1, inf} on a board without flippers.
std::pair<int, double> nearest_flipper_at_rest(const Board& board, const Vec2& p);

/// The largest time step for which a flipper moving at its θ̇₀ cannot jump
/// over the ball: l·sin(θ̇₀·dt/2) < r (thesis 3.3.3). Infinite with no flippers.
double max_stable_dt_s(const Board& board);

/// The slowest launch that leaves the launcher (m/s): a ball launched
/// straight up at v rises v²/(2g), and while it is within one radius of the
/// launch point and slower than kLauncherStillSpeed_mps it counts as back in
/// the launcher and is launched again, for ever. So v must exceed
/// √(2·g·r + v_still²), plus g·dt for the thesis stepper's Euler lag (its
/// apex falls short of v²/(2g) by up to v·dt/2).
double min_launch_speed_mps(const Board& board);

/// The slowest launch the plunger gives at pull fraction `pull` (m/s):
/// pull·(1 − noise_max)·speed_max (thesis 3.3.1).
double slowest_launch_mps(const Board& board, double pull);

/// Throws std::invalid_argument if launches at `pull` can be slower than
/// min_launch_speed_mps (the ball would be relaunched at its apex for ever).
/// A board with a `start` never launches: any pull passes.
void check_launch_pull(const Board& board, double pull);

/// How far off the playfield a point a file gives (a sighting, a marker) may
/// lie (m) before the file is taken for another table's or for other units:
/// the rim, and a calibration's error, fit well within it.
inline constexpr double kOffPlayfieldMargin_m = 0.05;
/// The share of a recording's sightings that may lie that far off: a
/// detector's stray sightings stay well below it.
inline constexpr double kMostOffPlayfield = 0.05;

/// True when `p` (m, board frame) lies within kOffPlayfieldMargin_m of the playfield.
bool near_playfield(const Board& board, const Vec2& p);

/// "over 5 cm off the 0.51 x 1.07 m playfield of B": what the messages that
/// refuse such points say of them.
std::string off_playfield_text(const Board& board);

/// How far a flipper's tip region sweeps across in one step: l·sin(θ̇₀·dt/2)
/// (m), its length once the half sweep passes π/2. It must stay below the
/// ball's radius, or the bat can jump over the ball.
double flipper_step_chord_m(const Flipper& flipper, double dt_s);

/// Throws std::invalid_argument naming the flipper if dt_s violates
/// l·sin(θ̇₀·dt/2) < r for any flipper.
void check_flipper_time_step(const Board& board, double dt_s);

/// Why flipper `f`'s tip is too fast for `board`'s ball, or "": a tip at or
/// above the speed clamp overtakes every ball it strikes (the event stepper
/// struck one again and again, frozen mid-stroke, until its guard held it).
std::string flipper_tip_speed_problem(const Board& board, const Flipper& f);

}  // namespace pinball::table
