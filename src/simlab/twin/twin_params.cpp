#include "pinball/simlab/twin_params.h"

#include <stdexcept>

#include "pinball/core/check.h"
#include "pinball/core/format.h"
#include "pinball/core/text_file.h"
#include "pinball/core/yaml_read_archive.h"

namespace pinball::simlab {
namespace {

// What the twin expects of each key: its unit and its physical range.
struct QuantitySpec {
  const char* key;
  TwinQuantity TwinParams::*field;
  const char* unit;
  double min;
  double max;
};

constexpr QuantitySpec kSpecs[] = {
    {"timestep_s", &TwinParams::timestep_s, "s", 1e-5, 0.002},
    {"contact_duration_s", &TwinParams::contact_duration_s, "s", 1e-4, 0.02},
    {"penetration_warning_m", &TwinParams::penetration_warning_m, "m", 1e-4, 0.01},
    {"gravity_mps2", &TwinParams::gravity_mps2, "m/s^2", 9.0, 10.5},
    {"glass_height_m", &TwinParams::glass_height_m, "m", 0.03, 0.5},
    {"playfield_friction", &TwinParams::playfield_friction, "1", 0.01, 2.0},
    {"playfield_rolling_friction_m", &TwinParams::playfield_rolling_friction_m, "m", 0.0, 1e-3},
    {"playfield_torsional_friction_m", &TwinParams::playfield_torsional_friction_m, "m", 0.0, 0.01},
    {"playfield_restitution", &TwinParams::playfield_restitution, "1", 0.0, 0.95},
    {"ball_mass_kg", &TwinParams::ball_mass_kg, "kg", 0.01, 0.5},
    {"rail_height_m", &TwinParams::rail_height_m, "m", 0.005, 0.2},
    {"rail_thickness_m", &TwinParams::rail_thickness_m, "m", 0.002, 0.05},
    {"rail_restitution", &TwinParams::rail_restitution, "1", 0.0, 0.95},
    {"rail_friction", &TwinParams::rail_friction, "1", 0.0, 2.0},
    {"rubber_restitution", &TwinParams::rubber_restitution, "1", 0.0, 0.95},
    {"rubber_friction", &TwinParams::rubber_friction, "1", 0.0, 2.0},
    {"dead_restitution", &TwinParams::dead_restitution, "1", 0.0, 0.95},
    {"pin_radius_m", &TwinParams::pin_radius_m, "m", 1e-4, 0.02},
    {"lively_rho", &TwinParams::lively_rho, "1", 0.0, 2.0},
    {"dead_rho", &TwinParams::dead_rho, "1", 0.0, 2.0},
    {"kicker_delay_s", &TwinParams::kicker_delay_s, "s", 0.0, 0.1},
    {"bumper_kick_mps", &TwinParams::bumper_kick_mps, "m/s", 0.0, 10.0},
    {"slingshot_kick_mps", &TwinParams::slingshot_kick_mps, "m/s", 0.0, 10.0},
    {"kicker_recycle_s", &TwinParams::kicker_recycle_s, "s", 0.0, 2.0},
    {"kicker_reach_m", &TwinParams::kicker_reach_m, "m", 0.0, 0.02},
    {"flipper_mass_kg", &TwinParams::flipper_mass_kg, "kg", 0.005, 1.0},
    {"flipper_inertia_kgm2", &TwinParams::flipper_inertia_kgm2, "kg*m^2", 1e-6, 0.01},
    {"flipper_radius_m", &TwinParams::flipper_radius_m, "m", 0.001, 0.02},
    {"flipper_restitution", &TwinParams::flipper_restitution, "1", 0.0, 0.95},
    {"flipper_friction", &TwinParams::flipper_friction, "1", 0.0, 2.0},
    {"coil_pulse_torque_nm", &TwinParams::coil_pulse_torque_nm, "N*m", 0.01, 20.0},
    {"coil_hold_torque_nm", &TwinParams::coil_hold_torque_nm, "N*m", 0.0, 20.0},
    {"coil_pulse_s", &TwinParams::coil_pulse_s, "s", 0.001, 0.2},
    {"coil_rise_s", &TwinParams::coil_rise_s, "s", 1e-5, 0.05},
    {"return_spring_torque_nm", &TwinParams::return_spring_torque_nm, "N*m", 0.0, 5.0},
    {"end_stop_restitution", &TwinParams::end_stop_restitution, "1", 0.0, 0.95},
    {"flipper_damping_nms", &TwinParams::flipper_damping_nms, "N*m*s", 0.0, 0.1},
};

// The first thing wrong with `p`, as a key and a rule; an empty key when all is well.
RangeViolation find_violation(const TwinParams& p) {
  for (const QuantitySpec& s : kSpecs) {
    const TwinQuantity& q = p.*s.field;
    if (q.unit != s.unit) return {s.key, "must be given in " + std::string(s.unit) + ", not '" + q.unit + "'"};
    if (q.source.empty()) return {s.key, "needs a source (a measurement, a datasheet or a reason)"};
    if (!(q.value >= s.min && q.value <= s.max)) {
      const std::string unit = std::string_view(s.unit) == "1" ? "" : " " + std::string(s.unit);  // "1": a ratio
      return {s.key, "is " + format_number(q.value) + unit + ", must be in [" + format_number(s.min) + ", " +
                         format_number(s.max) + "]" + unit};
    }
  }
  // Settings that contradict each other.
  if (p.contact_duration_s.value < 4.0 * p.timestep_s.value) {
    return {"contact_duration_s", "must be at least 4 x timestep_s (a bounce resolved over several steps)"};
  }
  if (p.coil_hold_torque_nm.value > p.coil_pulse_torque_nm.value) {
    return {"coil_hold_torque_nm", "must not exceed coil_pulse_torque_nm (the hold winding is the weaker)"};
  }
  if (p.return_spring_torque_nm.value >= p.coil_hold_torque_nm.value) {
    return {"return_spring_torque_nm", "must be below coil_hold_torque_nm (else a held flipper falls)"};
  }
  if (p.dead_rho.value >= p.lively_rho.value) return {"dead_rho", "must be below lively_rho"};
  if (p.rail_height_m.value > p.glass_height_m.value) return {"rail_height_m", "must not exceed glass_height_m"};
  return {};
}

}  // namespace

void check_twin_params(const TwinParams& params) { check_input(find_violation(params), "twin parameters"); }

TwinParams load_twin_params(const std::string& path) {
  const std::string text = read_text_file(path);  // "path: cannot open", a folder, a device
  TwinParams p;
  const YAML::Node root = load_yaml(text, path);  // "path:line: not valid YAML: ..."
  YamlReadArchive(path, {.refuse_unknown_keys = true, .require_every_key = true}).read(root, "", &p);
  if (const RangeViolation bad = find_violation(p)) throw KeyError(path, bad.key, bad.rule);
  p.source = path;
  return p;
}

}  // namespace pinball::simlab
