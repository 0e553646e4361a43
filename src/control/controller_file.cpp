#include "pinball/control/controller_file.h"

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include <nlohmann/json.hpp>

#include "pinball/core/check.h"
#include "pinball/core/json_read_archive.h"
#include "pinball/core/json_text.h"
#include "pinball/core/json_write_archive.h"
#include "pinball/core/text_file.h"

namespace pinball::control {

using nlohmann::json;

namespace {

const char* kFormat = "pinball-controller";

// The launcher keys, apart from ControllerSpec's own names for them.
struct LauncherSection {
  double pull = -1.0;
  bool randomise = false;
  double pull_min = 0.5;
  double pull_max = 1.0;
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(pull));
    a->Visit(PINBALL_NVP(randomise));
    a->Visit(PINBALL_NVP(pull_min));
    a->Visit(PINBALL_NVP(pull_max));
  }
};

// Fails at `key` for a setting out of its range (a RangeViolation names the sub-key).
void refuse(const JsonReadArchive& r, const std::string& path, const RangeViolation& v) {
  if (v) r.fail(join_key(path, v.key), v.rule);
}

// A shot's integer field, written as a number: refused unless it is exactly
// one of lo..hi, and only then converted (a cast of 1e300 is undefined).
bool small_integer(double v, int lo, int hi, int* out) {
  if (!(v >= lo && v <= hi) || v != std::floor(v)) return false;
  *out = static_cast<int>(v);
  return true;
}

// A key the format requires; the others keep their defaults when absent.
const json& need(const JsonReadArchive& r, const json& parent, const std::string& path, const char* key) {
  if (!parent.is_object() || !parent.contains(key)) r.fail(join_key(path, key), "missing");
  return parent.at(key);
}

// The keys an object the reader walks by hand may hold: a misspelt one
// (launcher.pul, minicontrollers[0].flipr) must not silently keep a default.
// The sections read through the archive are checked by it.
void refuse_unknown_keys(const JsonReadArchive& r, const json& object, const std::string& path,
                         std::initializer_list<const char*> known) {
  if (!object.is_object()) return;
  for (const auto& item : object.items()) {
    const bool ok = std::any_of(known.begin(), known.end(), [&](const char* k) { return item.key() == k; });
    if (!ok) r.fail(join_key(path, item.key()), "unknown key");
  }
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
  json table = to_json_value(t.config());
  table["shot_fields"] = kShotFields;
  table["shots"] = shots;
  return table;
}

ShotTable shot_table_from_json(const json& j, JsonReadArchive& r) {
  for (const char* key : {"neighbours", "angle_scale_rad", "h_scale", "speed_scale_mps"}) {
    need(r, j, "imitation", key);
  }
  // The rows' order is this build's (kShotFields); a file that names another was read as if it
  // named this one. It is for a reader: when given, it must be this order.
  if (j.is_object() && j.contains("shot_fields") && j["shot_fields"] != json(kShotFields)) {
    r.fail("imitation.shot_fields", "must be " + json_text(json(kShotFields)) + ", the order of each shot's numbers");
  }
  ImitationConfig c;
  json settings = j;  // the table's settings; its shots are rows, read below
  settings.erase("shots");
  settings.erase("shot_fields");
  r.read(&settings, "imitation", &c);
  refuse(r, "imitation", check_imitation_config(c));
  // The shots are rows of numbers, not keyed structs: read as lists, then checked here.
  const json& shots = need(r, j, "imitation", "shots");
  if (shots.is_array() && shots.size() > kMaxShots) {
    r.fail("imitation.shots", "more than " + std::to_string(kMaxShots) + " shots");
  }
  std::vector<std::vector<double>> rows;
  r.read(&shots, "imitation.shots", &rows);
  // No shot to imitate: the controller would never flip, and play as if nothing were wrong.
  if (rows.empty()) r.fail("imitation.shots", "is empty: a table of no shots never flips");
  std::vector<ShotExample> examples;
  examples.reserve(rows.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const std::string where = "imitation.shots[" + std::to_string(i) + "]";
    const std::vector<double>& v = rows[i];
    if (v.size() != kShotFieldCount) r.fail(where, "must have 8 numbers (see imitation.shot_fields)");
    ShotExample e;
    int rolling = 0;
    if (!small_integer(v[0], 0, 1, &e.flipper)) r.fail(where, "flipper must be 0 (left) or 1 (right)");
    if (!small_integer(v[1], 0, 1, &rolling)) r.fail(where, "rolling must be 0 or 1");
    if (!small_integer(v[5], -1, 1, &e.fired_flipper)) r.fail(where, "fired_flipper must be -1 (pass), 0 or 1");
    e.rolling = rolling == 1;
    e.angle_rad = v[2];
    e.h = v[3];
    e.speed_mps = v[4];
    e.d_fire_m = v[6];
    e.hold_s = v[7];
    if (const RangeViolation bad = check_shot_example(e)) r.fail(where, bad.key + " " + bad.rule);
    examples.push_back(e);
  }
  try {
    return ShotTable(std::move(examples), c);
  } catch (const std::invalid_argument& e) {
    r.fail("imitation", e.what());
  }
}

ControllerSpec spec_from_json(const json& j, JsonReadArchive& r) {
  if (!j.is_object()) r.fail("(file)", "must be a JSON object");
  const json& format = need(r, j, "", "format");
  if (!format.is_string() || format.get<std::string>() != kFormat) r.fail("format", "must be \"pinball-controller\"");
  // Compared as a 64-bit integer: get<int>() would truncate 4294967297 to 1.
  const json& version = need(r, j, "", "version");
  if (!version.is_number_integer()) {  // "1" (a string) is no version number, not an unsupported one
    r.fail("version", "must be a whole number (" + std::to_string(kControllerFileVersion) + "), got " +
                          json_text(version));
  }
  if (version.get<std::int64_t>() != kControllerFileVersion) {
    r.fail("version", "unsupported (this build reads version " + std::to_string(kControllerFileVersion) + ")");
  }
  ControllerSpec s;
  if (j.contains("note") && j["note"].is_string()) s.note = j["note"].get<std::string>();
  const json& part = need(r, j, "", "partition");
  need(r, part, "partition", "angle_borders_rad");
  ActionFunctionConfig c;
  r.read(&part, "partition", &c);
  refuse(r, "partition", check_action_function_config(c));
  try {
    s.action_function = ActionFunction(c);
  } catch (const std::invalid_argument& e) {
    r.fail("partition", e.what());
  }
  const json& minis = need(r, j, "", "minicontrollers");
  if (!minis.is_array() || static_cast<int>(minis.size()) != s.action_function.partitions()) {
    r.fail("minicontrollers", "must be an array of " + std::to_string(s.action_function.partitions()) +
                                  " minicontrollers (one per partition)");
  }
  for (int i = 0; i < s.action_function.partitions(); ++i) {
    const std::string where = "minicontrollers[" + std::to_string(i) + "]";
    const json& m = minis[static_cast<std::size_t>(i)];
    Minicontroller& mc = s.action_function.minicontroller(i);
    r.read(&need(r, m, where, "a"), where + ".a", &mc.a);
    const json& f = need(r, m, where, "flipper");
    if (!f.is_string() || (f.get<std::string>() != "left" && f.get<std::string>() != "right")) {
      r.fail(where + ".flipper", "must be \"left\" or \"right\"");
    }
    mc.flipper = f.get<std::string>() == "left" ? track::kLeftFlipper : track::kRightFlipper;
    refuse_unknown_keys(r, m, where, {"partition", "name", "a", "flipper"});  // partition, name: for a reader
    // The list's order places each minicontroller; a partition number that says otherwise misleads.
    if (m.contains("partition") && m["partition"] != json(i)) {
      r.fail(where + ".partition", "must be " + std::to_string(i) + ", got " + json_text(m["partition"]) +
                                       ": its place in the list decides its partition");
    }
    refuse(r, where, check_minicontroller(mc));
  }
  if (j.contains("imitation")) s.shot_table = std::make_shared<const ShotTable>(shot_table_from_json(j["imitation"], r));
  if (j.contains("planner")) {
    // The planner would play and the shot table be read for nothing: which did the file mean?
    if (s.shot_table) r.fail("planner", "a controller file holds an imitation or a planner object, not both");
    PlannerSettings p;
    r.read(&j["planner"], "planner", &p);
    refuse(r, "planner", check_planner_settings(p));
    s.planner = p;
  }
  if (j.contains("spastic")) {
    if (s.shot_table || s.planner) r.fail("spastic", "a spastic controller file holds no imitation or planner object");
    SpasticConfig spastic;
    r.read(&j["spastic"], "spastic", &spastic);
    refuse(r, "spastic", check_spastic_config(spastic));
    s.spastic = spastic;
  }
  if (j.contains("cradle")) {
    if (s.shot_table || s.planner || s.spastic) {
      r.fail("cradle", "a cradle controller file holds no imitation, planner or spastic object");
    }
    CradleConfig cradle;
    r.read(&j["cradle"], "cradle", &cradle);
    refuse(r, "cradle", check_cradle_config(cradle));
    s.cradle = cradle;
  }
  if (j.contains("actuator")) {
    r.read(&j["actuator"], "actuator", &s.actuator);
    refuse(r, "actuator", check_actuator_config(s.actuator));
  }
  if (j.contains("launcher")) {
    LauncherSection l{s.launcher_pull, s.randomise_launch, s.launch_pull_min, s.launch_pull_max};
    r.read(&j["launcher"], "launcher", &l);
    s.launcher_pull = l.pull;
    s.randomise_launch = l.randomise;
    s.launch_pull_min = l.pull_min;
    s.launch_pull_max = l.pull_max;
    if (s.launcher_pull > 1.0) r.fail("launcher.pull", "must be <= 1 (negative: the board's)");
    if (!(0.0 < s.launch_pull_min && s.launch_pull_min <= s.launch_pull_max && s.launch_pull_max <= 1.0)) {
      r.fail("launcher.pull_min", "need 0 < pull_min <= pull_max <= 1");
    }
  }
  // Last: a required key misspelt is reported as missing, which says more.
  refuse_unknown_keys(r, j, "", {"format", "version", "note", "partition", "minicontrollers", "actuator", "launcher",
                                 "planner", "spastic", "cradle", "imitation"});
  return s;
}

}  // namespace

std::unique_ptr<FlipperController> make_flipper_controller(const ControllerSpec& spec) {
  check_input(!spec.spastic || (!spec.shot_table && !spec.planner), "controller",
              "spastic settings beside a shot table or a planner");
  check_input(!spec.cradle || (!spec.shot_table && !spec.planner && !spec.spastic), "controller",
              "cradle settings beside another player");
  if (spec.spastic) return std::make_unique<SpasticController>(*spec.spastic);
  if (spec.cradle) return std::make_unique<CradleController>(*spec.cradle);
  if (spec.planner) {
    throw std::invalid_argument("controller: the planner needs the belief board (learn::make_controller)");
  }
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
  json j = {
      {"format", kFormat},
      {"version", kControllerFileVersion},
      {"note", s.note},
      {"partition", to_json_value(af.config())},
      {"minicontrollers", minis},
      {"actuator", to_json_value(s.actuator)},
      {"launcher", to_json_value(LauncherSection{s.launcher_pull, s.randomise_launch, s.launch_pull_min,
                                                 s.launch_pull_max})},
  };
  if (s.planner) j["planner"] = to_json_value(*s.planner);
  if (s.spastic) j["spastic"] = to_json_value(*s.spastic);
  if (s.cradle) j["cradle"] = to_json_value(*s.cradle);
  if (!s.shot_table) return json_text(j, 2) + "\n";
  // One line per shot: the table stays readable (and diffable) at thousands of shots.
  json table = shot_table_json(*s.shot_table);
  std::string shots = "[";
  for (std::size_t i = 0; i < table["shots"].size(); ++i) {
    shots += (i == 0 ? "\n      " : ",\n      ") + json_text(table["shots"][i]);
  }
  shots += table["shots"].empty() ? "]" : "\n    ]";
  table["shots"] = "@SHOTS@";
  j["imitation"] = table;
  std::string text = json_text(j, 2);
  text.replace(text.find("\"@SHOTS@\""), 9, shots);
  return text + "\n";
}

ControllerSpec controller_from_json(const std::string& text, const std::string& src) {
  try {
    const json j = parse_json(text, src);  // refuses a repeated key too
    // An unknown key is refused, as in every other file, and so is a missing one (docs/learning.md): a
    // dropped key must not play the default.
    JsonReadArchive r(src, ReadOptions{.refuse_unknown_keys = true, .require_every_key = true});
    return spec_from_json(j, r);
  } catch (const KeyError& e) {
    // The archive says "file:key: message"; controller files say "file: field: message".
    throw ControllerFileError(e.file() + ": " + e.key() + ": " + e.message());
  }
}

void save_controller(const ControllerSpec& spec, const std::string& path) {
  try {
    write_text_file(path, controller_to_json(spec));  // a run's result, or a cycle rewritten mid-run: never half
  } catch (const std::runtime_error& e) {
    throw ControllerFileError(e.what());
  }
}

ControllerSpec load_controller(const std::string& path) {
  std::string text;
  try {
    text = read_text_file(path);
  } catch (const std::runtime_error& e) {
    throw ControllerFileError(e.what());
  }
  ControllerSpec spec = controller_from_json(text, path);
  // A planner's shot-value table is named relative to the controller file, so
  // that the two travel together.
  if (spec.planner && spec.planner->shot_values) {
    std::string& table = *spec.planner->shot_values;
    if (table.empty()) {
      throw ControllerFileError(path + ": planner.shot_values: names no file (leave the key out for none)");
    }
    if (std::filesystem::path(table).is_relative()) {
      table = (std::filesystem::path(path).parent_path() / table).string();
    }
    std::error_code ec;
    if (!std::filesystem::is_regular_file(table, ec)) {
      throw ControllerFileError(path + ": planner.shot_values: " + table +
                                (std::filesystem::exists(table, ec) ? " is not a file" : " does not exist") +
                                " (a relative path is from the controller file's folder)");
    }
  }
  return spec;
}

void check_controller_launch(const ControllerSpec& spec, const table::Board& board, const std::string& path) {
  const bool randomised = spec.randomise_launch;
  const double pull = randomised ? spec.launch_pull_min : spec.launcher_pull;
  if (!randomised && pull < 0.0) return;  // the board's own pull, checked with the board
  try {
    table::check_launch_pull(board, pull);
  } catch (const std::invalid_argument& e) {
    throw ControllerFileError(path + ": " + (randomised ? "launcher.pull_min" : "launcher.pull") + ": " + e.what());
  }
}

}  // namespace pinball::control
