#pragma once
// Draws one picture of `pinball view`: the table from its board file with
// each flipper up while its coil is on, the ball and its trail, the fitted
// trajectory of the newest projection to its impact on the flippers' 'V' with
// d and d_critical, each flipper command as it is sent, and a strip with the
// daemon's frame rate, dropped frames, stalls and frame->CAN p99. The same
// picture is shown in the window and written by --snapshot.

#include <memory>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "pinball/control/controller_file.h"
#include "pinball/sim/renderer.h"
#include "pinball/table/board.h"
#include "pinball/track/flipper_geometry.h"
#include "pinball/view/view_state.h"

namespace pinball::view {

/// What the view draws on: the belief the daemon runs with.
struct ViewScene {
  table::Board board;                    ///< the table (its gravity bends the drawn trajectory)
  track::FlipperGeometry geometry;       ///< the flippers' 'V' the projections fall on
  double gravity_mps2 = 0.0;             ///< g along the table (calibrated when a calibration was given)
  std::shared_ptr<const control::ControllerSpec> controller;  ///< d_critical's source; null: d only
  sim::RenderOptions render;             ///< scale of the table drawing
};

/// Builds the scene of a board file, an optional calibration file (flipper
/// geometry and g) and an optional controller file. Throws naming the file.
ViewScene load_view_scene(const std::string& board_path, const std::string& calibration_path,
                          const std::string& controller_path, double px_per_m);

/// A line for the strip about where the view is ("log 12.34 / 60.00 s, paused").
struct ViewCaption {
  std::string source;  ///< what is shown: the log file or the LCM URL
  std::string status;  ///< position, speed, paused...
};

/// Colours of the picture (BGR), exposed for tests that find them.
inline const cv::Scalar kViewBallColour{0, 140, 255};      ///< the ball now (orange)
inline const cv::Scalar kViewTrailColour{255, 200, 120};   ///< its recent sightings (light blue)
inline const cv::Scalar kViewTrajectoryColour{200, 0, 200};  ///< the fitted path to the impact (magenta)
inline const cv::Scalar kViewCoilOnColour{40, 40, 230};    ///< a coil that is on (red)

/// d_critical the controller of `scene` applies to this projection (m), or
/// nothing without a controller.
std::optional<double> d_critical_m(const ViewScene& scene, const pinball_lcm::lcmt_pinball_projection& projection);

/// Where the newest projection's path is at `t` seconds after its observation:
/// the parabola under the scene's g through the observation and the impact point.
Vec2 projected_path_point(const ViewScene& scene, const Vec2& origin, const pinball_lcm::lcmt_pinball_projection& p,
                          double t_s);

/// The picture: the table with its overlays, a side panel and the strip. BGR.
cv::Mat render_view(const ViewScene& scene, const ViewState& state, const ViewCaption& caption);

/// Where the table lies in render_view's picture (the panel, its legend and the strip lie outside).
cv::Rect view_table_rect(const ViewScene& scene);

/// The pixel of board point `p_board` in render_view's picture (the table sits at its top-left).
cv::Point2d view_pixel(const ViewScene& scene, const Vec2& p_board);

}  // namespace pinball::view
