#include "pinball/control/controller_file.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

namespace pinball::control {

using nlohmann::json;

namespace {

const char* kFormat = "pinball-controller";

[[noreturn]] void fail(const std::string& source, const std::string& field, const std::string& message) {
  throw ControllerFileError(source + ": " + field + ": " + message);
}

const json& need(const json& j, const char* key, const std::string& source, const std::string& where) {
  if (!j.is_object() || !j.contains(key)) fail(source, where + key, "missing");
  return j.at(key);
}

double number(const json& j, const std::string& source, const std::string& field) {
  if (!j.is_number()) fail(source, field, "must be a number");
  const double v = j.get<double>();
  if (!std::isfinite(v)) fail(source, field, "must be finite");
  return v;
}

std::vector<double> numbers(const json& j, const std::string& source, const std::string& field) {
  if (!j.is_array()) fail(source, field, "must be an array of numbers");
  std::vector<double> v;
  for (std::size_t i = 0; i < j.size(); ++i) v.push_back(number(j[i], source, field + "[" + std::to_string(i) + "]"));
  return v;
}

// Order of a shot's numbers in the file (one short array per shot keeps a
// table of thousands readable line by line).
const char* const kShotFields[] = {"flipper",   "rolling",       "angle_rad", "h", "speed_mps",
                                   "fired_flipper", "d_fire_m", "hold_s"};
constexpr std::size_t kShotFieldCount = 8;

json shot_table_json(const ShotTable& t) {
  json shots = json::array();
  for (const ShotExample& e : t.examples()) {
    shots.push_back({e.flipper, e.rolling ? 1 : 0, e.angle_rad, e.h, e.speed_mps, e.fired_flipper, e.d_fire_m, e.hold_s});
  }
  const ImitationConfig& c = t.config();
  return {{"neighbours", c.neighbours},
          {"angle_scale_rad", c.angle_scale_rad},
          {"h_scale", c.h_scale},
          {"speed_scale_mps", c.speed_scale_mps},
          {"max_hold_s", c.max_hold_s},
          {"lead_s", c.lead_s},
          {"shot_fields", kShotFields},
          {"shots", shots}};
}

ShotTable shot_table_from_json(const json& j, const std::string& src) {
  if (!j.is_object()) fail(src, "imitation", "must be an object");
  ImitationConfig c;
  const json& k = need(j, "neighbours", src, "imitation.");
  if (!k.is_number_integer()) fail(src, "imitation.neighbours", "must be an integer");
  c.neighbours = k.get<int>();
  c.angle_scale_rad = number(need(j, "angle_scale_rad", src, "imitation."), src, "imitation.angle_scale_rad");
  c.h_scale = number(need(j, "h_scale", src, "imitation."), src, "imitation.h_scale");
  c.speed_scale_mps = number(need(j, "speed_scale_mps", src, "imitation."), src, "imitation.speed_scale_mps");
  if (j.contains("max_hold_s")) c.max_hold_s = number(j["max_hold_s"], src, "imitation.max_hold_s");
  if (j.contains("lead_s")) c.lead_s = number(j["lead_s"], src, "imitation.lead_s");
  const json& shots = need(j, "shots", src, "imitation.");
  if (!shots.is_array()) fail(src, "imitation.shots", "must be an array");
  std::vector<ShotExample> examples;
  examples.reserve(shots.size());
  for (std::size_t i = 0; i < shots.size(); ++i) {
    const std::string where = "imitation.shots[" + std::to_string(i) + "]";
    const std::vector<double> v = numbers(shots[i], src, where);
    if (v.size() != kShotFieldCount) fail(src, where, "must have 8 numbers (see imitation.shot_fields)");
    ShotExample e;
    e.flipper = static_cast<int>(v[0]);
    e.rolling = v[1] != 0.0;
    e.angle_rad = v[2];
    e.h = v[3];
    e.speed_mps = v[4];
    e.fired_flipper = static_cast<int>(v[5]);
    e.d_fire_m = v[6];
    e.hold_s = v[7];
    if (v[0] != e.flipper || v[5] != e.fired_flipper) fail(src, where, "flipper numbers must be integers");
    examples.push_back(e);
  }
  try {
    return ShotTable(std::move(examples), c);
  } catch (const std::invalid_argument& e) {
    fail(src, "imitation", e.what());
  }
}

}  // namespace

std::unique_ptr<FlipperController> make_flipper_controller(const ControllerSpec& spec) {
  if (spec.shot_table) return std::make_unique<ImitationController>(spec.shot_table);
  return std::make_unique<ActuatorController>(spec.action_function, spec.actuator);
}

std::string controller_to_json(const ControllerSpec& s) {
  const ActionFunction& af = s.action_function;
  json minis = json::array();
  for (int i = 0; i < af.partitions(); ++i) {
    const Minicontroller& m = af.minicontroller(i);
    minis.push_back({{"partition", i},
                     {"name", af.partition_name(i)},
                     {"a", {m.a[0], m.a[1], m.a[2], m.a[3]}},
                     {"flipper", m.flipper == track::kLeftFlipper ? "left" : "right"}});
  }
  const auto& c = af.config();
  json j = {
      {"format", kFormat},
      {"version", kControllerFileVersion},
      {"note", s.note},
      {"partition",
       {{"angle_borders_rad", c.angle_borders_rad},
        {"h_borders", c.h_borders},
        {"rolling_minicontrollers", c.rolling_minicontrollers},
        {"gain_range", {c.gain_range[0], c.gain_range[1], c.gain_range[2], c.gain_range[3]}}}},
      {"minicontrollers", minis},
      {"actuator", {{"max_hold_s", s.actuator.max_hold_s}}},
      {"launcher",
       {{"pull", s.launcher_pull},
        {"randomise", s.randomise_launch},
        {"pull_min", s.launch_pull_min},
        {"pull_max", s.launch_pull_max}}},
  };
  if (!s.shot_table) return j.dump(2) + "\n";
  // One line per shot: the table stays readable (and diffable) at thousands of shots.
  json table = shot_table_json(*s.shot_table);
  std::string shots = "[";
  for (std::size_t i = 0; i < table["shots"].size(); ++i) {
    shots += (i == 0 ? "\n      " : ",\n      ") + table["shots"][i].dump();
  }
  shots += table["shots"].empty() ? "]" : "\n    ]";
  table["shots"] = "@SHOTS@";
  j["imitation"] = table;
  std::string text = j.dump(2);
  text.replace(text.find("\"@SHOTS@\""), 9, shots);
  return text + "\n";
}

ControllerSpec controller_from_json(const std::string& text, const std::string& src) {
  json j;
  try {
    j = json::parse(text);
  } catch (const json::parse_error& e) {
    fail(src, "(file)", std::string("not valid JSON: ") + e.what());
  }
  if (!j.is_object()) fail(src, "(file)", "must be a JSON object");
  const json& format = need(j, "format", src, "");
  if (!format.is_string() || format.get<std::string>() != kFormat) fail(src, "format", "must be \"pinball-controller\"");
  const json& version = need(j, "version", src, "");
  if (!version.is_number_integer() || version.get<int>() != kControllerFileVersion) {
    fail(src, "version", "unsupported (this build reads version " + std::to_string(kControllerFileVersion) + ")");
  }
  ControllerSpec s;
  if (j.contains("note") && j["note"].is_string()) s.note = j["note"].get<std::string>();
  const json& part = need(j, "partition", src, "");
  ActionFunctionConfig c;
  c.angle_borders_rad = numbers(need(part, "angle_borders_rad", src, "partition."), src, "partition.angle_borders_rad");
  if (part.contains("h_borders")) c.h_borders = numbers(part["h_borders"], src, "partition.h_borders");
  if (part.contains("rolling_minicontrollers")) {
    if (!part["rolling_minicontrollers"].is_boolean()) fail(src, "partition.rolling_minicontrollers", "must be true or false");
    c.rolling_minicontrollers = part["rolling_minicontrollers"].get<bool>();
  }
  if (part.contains("gain_range")) {
    const std::vector<double> g = numbers(part["gain_range"], src, "partition.gain_range");
    if (g.size() != 4) fail(src, "partition.gain_range", "must have 4 numbers");
    for (int i = 0; i < 4; ++i) c.gain_range[static_cast<std::size_t>(i)] = g[static_cast<std::size_t>(i)];
  }
  try {
    s.action_function = ActionFunction(c);
  } catch (const std::invalid_argument& e) {
    fail(src, "partition", e.what());
  }
  const json& minis = need(j, "minicontrollers", src, "");
  if (!minis.is_array() || static_cast<int>(minis.size()) != s.action_function.partitions()) {
    fail(src, "minicontrollers", "must be an array of " + std::to_string(s.action_function.partitions()) +
                                     " minicontrollers (one per partition)");
  }
  for (int i = 0; i < s.action_function.partitions(); ++i) {
    const std::string where = "minicontrollers[" + std::to_string(i) + "]";
    const json& m = minis[static_cast<std::size_t>(i)];
    const std::vector<double> a = numbers(need(m, "a", src, where + "."), src, where + ".a");
    if (a.size() != 4) fail(src, where + ".a", "must have 4 numbers (a1..a4)");
    const json& f = need(m, "flipper", src, where + ".");
    if (!f.is_string() || (f.get<std::string>() != "left" && f.get<std::string>() != "right")) {
      fail(src, where + ".flipper", "must be \"left\" or \"right\"");
    }
    Minicontroller& mc = s.action_function.minicontroller(i);
    for (int k = 0; k < 4; ++k) mc.a[static_cast<std::size_t>(k)] = a[static_cast<std::size_t>(k)];
    mc.flipper = f.get<std::string>() == "left" ? track::kLeftFlipper : track::kRightFlipper;
  }
  if (j.contains("imitation")) s.shot_table = std::make_shared<const ShotTable>(shot_table_from_json(j["imitation"], src));
  if (j.contains("actuator")) {
    const json& act = j["actuator"];
    if (act.contains("max_hold_s")) s.actuator.max_hold_s = number(act["max_hold_s"], src, "actuator.max_hold_s");
    if (s.actuator.max_hold_s < 0.0) fail(src, "actuator.max_hold_s", "must be >= 0");
  }
  if (j.contains("launcher")) {
    const json& l = j["launcher"];
    if (l.contains("pull")) s.launcher_pull = number(l["pull"], src, "launcher.pull");
    if (s.launcher_pull > 1.0) fail(src, "launcher.pull", "must be <= 1 (negative: the board's)");
    if (l.contains("randomise")) {
      if (!l["randomise"].is_boolean()) fail(src, "launcher.randomise", "must be true or false");
      s.randomise_launch = l["randomise"].get<bool>();
    }
    if (l.contains("pull_min")) s.launch_pull_min = number(l["pull_min"], src, "launcher.pull_min");
    if (l.contains("pull_max")) s.launch_pull_max = number(l["pull_max"], src, "launcher.pull_max");
    if (!(0.0 < s.launch_pull_min && s.launch_pull_min <= s.launch_pull_max && s.launch_pull_max <= 1.0)) {
      fail(src, "launcher.pull_min", "need 0 < pull_min <= pull_max <= 1");
    }
  }
  return s;
}

void save_controller(const ControllerSpec& spec, const std::string& path) {
  std::ofstream f(path);
  if (!f) throw ControllerFileError(path + ": cannot open for writing");
  f << controller_to_json(spec);
  if (!f) throw ControllerFileError(path + ": write failed");
}

ControllerSpec load_controller(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw ControllerFileError(path + ": cannot open");
  std::ostringstream ss;
  ss << f.rdbuf();
  return controller_from_json(ss.str(), path);
}

}  // namespace pinball::control
