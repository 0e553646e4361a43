#pragma once
// The MuJoCo lab twin's physical parameters (issue 19): one file,
// config/twin.yaml, where every number has its value, its unit and the
// source of the number (a measurement, a datasheet or a reasoned choice), so
// a lab can replace each with its own. The board file says where things are;
// this file says what they are made of and how strong the coils are.

#include <string>

#include "pinball/core/name_value.h"

namespace pinball::simlab {

/// One physical parameter as the file states it.
struct TwinQuantity {
  double value = 0.0;  ///< in `unit`
  std::string unit;    ///< must be the unit the twin expects for the key (checked at load)
  std::string source;  ///< where the number comes from; never empty

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(value));
    a->Visit(PINBALL_NVP(unit));
    a->Visit(PINBALL_NVP(source));
  }
};

/// Every physical parameter of the twin. Key names carry their SI unit; the
/// file's `unit` must match it (`m`, `kg`, `s`, `N*m`, ...).
struct TwinParams {
  std::string source;  ///< the file it was loaded from (not a key)

  // Simulation.
  TwinQuantity timestep_s;             ///< MuJoCo's step; bounds tunnelling (docs/worlds.md)
  TwinQuantity contact_duration_s;     ///< contact softness: how long a bounce lasts (half the contact spring's period)
  TwinQuantity penetration_warning_m;  ///< a contact deeper than this is counted as a warning
  // The table.
  TwinQuantity gravity_mps2;           ///< full g; the slope is asin(board g along the table / g)
  TwinQuantity glass_height_m;         ///< the cover glass above the playfield (a hopping ball hits it)
  TwinQuantity playfield_friction;     ///< sliding friction, steel ball on the playfield
  TwinQuantity playfield_rolling_friction_m;   ///< rolling resistance arm (MuJoCo's rolling friction)
  TwinQuantity playfield_torsional_friction_m; ///< spin about the normal (MuJoCo's torsional friction)
  TwinQuantity playfield_restitution;  ///< a ball dropping onto the playfield
  // The ball.
  TwinQuantity ball_mass_kg;           ///< the radius is the board's
  // Rails (board lines of a middling ρ), rubber (circles, lively lines) and dead surfaces (ρ < 0.4).
  TwinQuantity rail_height_m;          ///< height of a wall above the playfield
  TwinQuantity rail_thickness_m;       ///< solid behind each line (tunnelling margin)
  TwinQuantity rail_restitution;       ///< steel ball on a metal or plastic guide
  TwinQuantity rail_friction;
  TwinQuantity rubber_restitution;     ///< steel ball on a rubber ring or post
  TwinQuantity rubber_friction;
  TwinQuantity dead_restitution;       ///< a surface the board makes nearly dead (chute floor, drain)
  TwinQuantity pin_radius_m;           ///< a two-sided wall becomes a bar, a lone board point a pin, of this radius
  TwinQuantity lively_rho;             ///< board ρ from which a line or circle is rubber
  TwinQuantity dead_rho;               ///< board ρ below which a surface is dead
  // Kickers: obstacles with a board kick (pop bumpers: circles; slingshots: lines).
  TwinQuantity kicker_delay_s;         ///< switch closes -> coil strikes
  TwinQuantity bumper_kick_mps;        ///< speed a pop bumper adds along the normal
  TwinQuantity slingshot_kick_mps;     ///< speed a slingshot adds along the normal
  TwinQuantity kicker_recycle_s;       ///< a kicker fires at most once in this time
  TwinQuantity kicker_reach_m;         ///< it strikes only a ball still this close to its surface
  // Flippers: a hinged bat driven by a solenoid through the driver board.
  TwinQuantity flipper_mass_kg;        ///< bat, shaft and link
  TwinQuantity flipper_inertia_kgm2;   ///< about the pivot, the solenoid's plunger included
  TwinQuantity flipper_radius_m;       ///< the rubber's half thickness (a capsule at the ball's equator)
  TwinQuantity flipper_restitution;
  TwinQuantity flipper_friction;
  TwinQuantity coil_pulse_torque_nm;   ///< torque at the pivot while the coil pulses
  TwinQuantity coil_hold_torque_nm;    ///< torque while the hold winding (PWM) holds
  TwinQuantity coil_pulse_s;           ///< pulse time before the hold (the driver board's)
  TwinQuantity coil_rise_s;            ///< the coil's L/R time constant: torque rises and falls with it
  TwinQuantity return_spring_torque_nm;///< pulls the bat down, always
  TwinQuantity end_stop_restitution;   ///< the bat's bounce at its stops
  TwinQuantity flipper_damping_nms;    ///< viscous friction in the pivot

  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(timestep_s));
    a->Visit(PINBALL_NVP(contact_duration_s));
    a->Visit(PINBALL_NVP(penetration_warning_m));
    a->Visit(PINBALL_NVP(gravity_mps2));
    a->Visit(PINBALL_NVP(glass_height_m));
    a->Visit(PINBALL_NVP(playfield_friction));
    a->Visit(PINBALL_NVP(playfield_rolling_friction_m));
    a->Visit(PINBALL_NVP(playfield_torsional_friction_m));
    a->Visit(PINBALL_NVP(playfield_restitution));
    a->Visit(PINBALL_NVP(ball_mass_kg));
    a->Visit(PINBALL_NVP(rail_height_m));
    a->Visit(PINBALL_NVP(rail_thickness_m));
    a->Visit(PINBALL_NVP(rail_restitution));
    a->Visit(PINBALL_NVP(rail_friction));
    a->Visit(PINBALL_NVP(rubber_restitution));
    a->Visit(PINBALL_NVP(rubber_friction));
    a->Visit(PINBALL_NVP(dead_restitution));
    a->Visit(PINBALL_NVP(pin_radius_m));
    a->Visit(PINBALL_NVP(lively_rho));
    a->Visit(PINBALL_NVP(dead_rho));
    a->Visit(PINBALL_NVP(kicker_delay_s));
    a->Visit(PINBALL_NVP(bumper_kick_mps));
    a->Visit(PINBALL_NVP(slingshot_kick_mps));
    a->Visit(PINBALL_NVP(kicker_recycle_s));
    a->Visit(PINBALL_NVP(kicker_reach_m));
    a->Visit(PINBALL_NVP(flipper_mass_kg));
    a->Visit(PINBALL_NVP(flipper_inertia_kgm2));
    a->Visit(PINBALL_NVP(flipper_radius_m));
    a->Visit(PINBALL_NVP(flipper_restitution));
    a->Visit(PINBALL_NVP(flipper_friction));
    a->Visit(PINBALL_NVP(coil_pulse_torque_nm));
    a->Visit(PINBALL_NVP(coil_hold_torque_nm));
    a->Visit(PINBALL_NVP(coil_pulse_s));
    a->Visit(PINBALL_NVP(coil_rise_s));
    a->Visit(PINBALL_NVP(return_spring_torque_nm));
    a->Visit(PINBALL_NVP(end_stop_restitution));
    a->Visit(PINBALL_NVP(flipper_damping_nms));
  }
};

/// Loads and checks a parameter file. Throws KeyError ("file:key: message")
/// for a missing, unknown, duplicate or mistyped key, a wrong unit, an empty
/// source or a value out of its range (the range is in the message), and for
/// settings that contradict each other (a pulse weaker than the hold, a
/// contact softer than two steps); std::runtime_error when the file cannot be read.
TwinParams load_twin_params(const std::string& path);

/// The same checks on parameters built in code (tests): throws
/// std::invalid_argument naming the key.
void check_twin_params(const TwinParams& params);

}  // namespace pinball::simlab
