#pragma once
// A learned controller on disk: a readable JSON file with a format name and a
// version (docs/learning.md). Loading is all or nothing: a bad file throws
// ControllerFileError naming the file and the field.

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "pinball/control/action_function.h"
#include "pinball/control/actuator_controller.h"
#include "pinball/control/cradle_controller.h"
#include "pinball/control/imitation_controller.h"
#include "pinball/control/planner_settings.h"
#include "pinball/control/spastic_controller.h"
#include "pinball/table/board.h"

namespace pinball::control {

/// Version written by save_controller and the only one load_controller reads.
inline constexpr int kControllerFileVersion = 1;

/// Everything a controller file holds.
struct ControllerSpec {
  ActionFunction action_function{uniform_partition(4)};  ///< partitions and minicontrollers
  ActuatorConfig actuator;                            ///< actuator settings
  /// A shot table learned from a teacher (`pinball learn --method imitate`); when
  /// set, it drives the flippers instead of the action function.
  /// Shared, not copied, with every controller made from this spec.
  std::shared_ptr<const ShotTable> shot_table;
  /// The online planner (learn::PlanningController): when set, it drives the
  /// flippers, planning in the belief model, and the shot table and action
  /// function are not used. Only learn::make_controller, which is given the
  /// belief board, can build it.
  std::optional<PlannerSettings> planner;
  /// The spastic flipper (thesis 1.1.1): when set, it drives the flippers and
  /// nothing else in the file is used. A file, so that pinballd and every
  /// command that reads a controller can play the baseline
  /// (`controllers/spastic.json`); a file may not also hold a shot table or a
  /// planner.
  std::optional<SpasticConfig> spastic;
  /// The cradle cycle (issue 20's ball alive for 10 minutes): when set, it
  /// drives the flippers and nothing else in the file is used
  /// (`controllers/cradle.json`); a file may hold no other player beside it.
  std::optional<CradleConfig> cradle;
  double launcher_pull = -1.0;    ///< launcher pull fraction; negative: the board's
  bool randomise_launch = false;  ///< draw the pull per ball from [launch_pull_min, launch_pull_max] (thesis 7.1)
  double launch_pull_min = 0.5;   ///< lower end of a randomised pull
  double launch_pull_max = 1.0;   ///< upper end of a randomised pull
  std::string note;               ///< free text: how it was produced
};

/// The flipper controller a spec describes: the spastic flipper when it holds
/// spastic settings, the cradle cycle when it holds cradle settings, the
/// imitation controller when it holds a shot table, the
/// action function's actuator controller otherwise. Throws
/// std::invalid_argument for a planner spec, which needs the belief board
/// (learn::make_controller builds every kind), and for spastic or cradle
/// settings beside another player.
std::unique_ptr<FlipperController> make_flipper_controller(const ControllerSpec& spec);

/// Bad controller input; what() is "file: field: message".
class ControllerFileError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The controller as JSON text (pretty-printed).
std::string controller_to_json(const ControllerSpec& spec);
/// Parses JSON text; `source_name` is used in error messages.
ControllerSpec controller_from_json(const std::string& text, const std::string& source_name);
/// Writes a controller file. Throws ControllerFileError when it cannot be written.
void save_controller(const ControllerSpec& spec, const std::string& path);
/// Reads a controller file. Throws ControllerFileError for any bad input.
ControllerSpec load_controller(const std::string& path);

/// The launches a controller sets (launcher.pull, or a randomised range's low
/// end) leave `board`'s launcher (table::check_launch_pull). Throws
/// ControllerFileError "path: launcher.pull: ..."; the file alone cannot tell,
/// since a pull's launch speed depends on the board.
void check_controller_launch(const ControllerSpec& spec, const table::Board& board, const std::string& path);

}  // namespace pinball::control
