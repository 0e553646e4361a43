#pragma once
// The MuJoCo lab twin's model, generated from the board file, never written
// by hand (issue 19): the playfield is the plane z = 0 of the board frame
// with gravity tilted by the board's slope; each board line is a rail (a box
// whose front face is the line, solid behind it), each circle a cylinder,
// each flipper a hinged capsule at the ball's equator driven by a motor (the
// solenoid), the ball an 80 g sphere with sliding, torsional and rolling
// friction (condim 6), a glass above. What the surfaces are made of comes
// from TwinParams. This header builds the MJCF text and says which geom is
// what; twin_world.h compiles and plays it.

#include <string>
#include <vector>

#include "pinball/simlab/twin_params.h"
#include "pinball/table/board.h"

namespace pinball::simlab {

/// What a board surface is made of in the twin (by its ρ and kick).
enum class TwinMaterial : std::uint8_t {
  kRail,    ///< a guide or wall (ρ between dead_rho and lively_rho)
  kRubber,  ///< a ring, post or rubber-lined wall (ρ ≥ lively_rho, or a kicker)
  kDead,    ///< nearly dead (ρ < dead_rho: shooter lane floor, drain)
};

/// The material of obstacle `index` of `board`.
TwinMaterial twin_material(const table::Board& board, int index, const TwinParams& params);

/// A MuJoCo contact's softness (solref): a spring-damper whose time
/// constant and damping ratio set how long a bounce lasts and what it returns.
struct TwinSolref {
  double timeconst_s = 0.02;  ///< solref[0]
  double dampratio = 1.0;     ///< solref[1]
};

/// The contact of each kind of surface, from the restitutions the
/// parameters ask for (found by simulation: twin_world.h).
struct TwinContacts {
  TwinSolref rail;       ///< ball on a rail
  TwinSolref rubber;     ///< ball on rubber
  TwinSolref dead;       ///< ball on a dead surface
  TwinSolref flipper;    ///< ball on a flipper
  TwinSolref playfield;  ///< ball dropping onto the playfield or hitting the glass
  TwinSolref end_stop;   ///< a flipper at its stops
};

/// What one MuJoCo geom stands for, in the model's geom order. Board shapes
/// become as few geoms as keep their surfaces: a two-sided pair of lines
/// (a wall, a two-sided polyline's edge) one bar (a box pin_radius_m either
/// side of the line), a one-sided
/// line a box whose front face is the line and whose solid lies behind it,
/// a circle a post (a vertical capsule), and a point at the end of a line
/// joins that line's geom (the box's corner); a lone point is a pin.
struct TwinGeom {
  enum Kind : std::uint8_t { kPlayfield, kGlass, kObstacle, kFlipper, kBall };
  Kind kind = kPlayfield;    ///< what
  int flipper = -1;          ///< flipper index for kFlipper; else -1
  std::vector<int> members;  ///< board obstacles it stands for (kObstacle)
  bool one_sided = false;    ///< a box for one line: solid only to a ball in front of it
};

/// The generated model.
struct TwinModelText {
  std::string mjcf;             ///< the MJCF document
  std::vector<TwinGeom> geoms;  ///< geom id -> what it stands for (MJCF order)
  double slope_rad = 0.0;       ///< the playfield's inclination
};

/// The board's obstacles grouped as the twin's geoms (TwinGeom), in geom
/// order: each group's first member decides the geom's shape and material.
std::vector<std::vector<int>> twin_obstacle_groups(const table::Board& board);

/// The slope of `board` under the parameters' g: asin(g along the table / g).
/// Throws std::invalid_argument naming the board when it cannot be (g along
/// the table not below g).
double twin_slope_rad(const table::Board& board, const TwinParams& params);

/// Throws std::invalid_argument naming the board when the twin cannot play
/// it as the model does: a ball too big for the glass, fast enough to pass
/// through the twin's thinnest solid (its step or its sink into a soft
/// contact), or put (chute, start, kickout) where it overlaps a solid the
/// board draws as a line. twin_model_text calls it.
void check_board_fits_the_twin(const table::Board& board, const TwinParams& params, double timestep_s);

/// Builds the MJCF of `board`. Throws std::invalid_argument naming the board
/// and the element for a board the twin cannot represent (see
/// docs/worlds.md): a slope not below 45°, a flipper shorter than its rubber
/// or sweeping half a turn or more.
TwinModelText twin_model_text(const table::Board& board, const TwinParams& params, double timestep_s,
                              const TwinContacts& contacts);

}  // namespace pinball::simlab
