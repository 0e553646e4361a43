// `pinball calibrate camera|intrinsics|flippers|gravity|latency`: measures the
// lab machine (or the simulated one with --sim) and writes the calibration file.

#include <algorithm>
#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <memory>
#include <mutex>
#include <numbers>
#include <optional>
#include <ostream>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "commands.h"
#include "data_file.h"
#include "flag_uses.h"
#include "progress_option.h"
#include "pinball/calibration/calibration_figure.h"
#include "pinball/calibration/calibration_file.h"
#include "pinball/calibration/camera_calibration.h"
#include "pinball/calibration/flipper_calibration.h"
#include "pinball/calibration/gravity_calibration.h"
#include "pinball/calibration/intrinsics_calibration.h"
#include "pinball/calibration/latency_calibration.h"
#include "pinball/core/clock.h"
#include "pinball/core/file_name.h"
#include "pinball/core/format.h"
#include "pinball/core/json_text.h"
#include "pinball/core/json_write_archive.h"
#include "pinball/core/number_option.h"
#include "pinball/core/progress.h"
#include "pinball/core/rng.h"
#include "pinball/core/text_file.h"
#include "pinball/daemon/daemon_config.h"
#include "pinball/daemon/pipeline.h"
#include "pinball/firmware/can_link.h"
#include "pinball/firmware/driver_bus.h"
#include "pinball/firmware/socketcan_transport.h"
#include "pinball/plot/draw.h"
#include "pinball/plot/png_file.h"
#include "pinball/simlab/sim_lab.h"
#include "pinball/simlab/sim_latency_lab.h"
#include "pinball/simlab/sim_target_view.h"
#include "pinball/table/board_loader.h"
#include "pinball/track/observation_io.h"
#include "pinball/vision/capture_source.h"
#include "pinball/vision/lens_model.h"

namespace pinball::cli {

CLI::App* add_calibrate_command(CLI::App& app, CalibrateArgs& a) {
  CLI::App* cmd = app.add_subcommand(
      "calibrate", "measure the lens, the camera homography, the flippers, gravity or the camera's latency");
  cmd->add_option("kind", a.kind, "what to calibrate: intrinsics, camera, flippers, gravity, latency")
      ->required()
      ->check(CLI::IsMember({"intrinsics", "camera", "flippers", "gravity", "latency"}));
  auto* sim = cmd->add_option("--sim", a.sim_board, "generate the inputs from the simulator on this board")
                  ->transform(data_file());
  cmd->add_option("--board", a.board, "the machine's board file (flipper names, sides, rough places)")
      ->transform(data_file())
      ->excludes(sim);
  cmd->add_option("--image", a.image, "camera: image of the markers")->check(input_file())->excludes(sim);
  cmd->add_option("--markers", a.markers, "camera: marker positions, CSV x,y (m); default: the board's default layout")
      ->check(input_file())
      ->excludes(sim);  // the simulated lab sets out the default layout
  cmd->add_option("--down", a.down, "flippers: image of the pivot and tip markers, flippers down")
      ->check(input_file())
      ->excludes(sim);
  cmd->add_option("--up", a.up, "flippers: the same with the flippers held up")->check(input_file())->excludes(sim);
  cmd->add_option("--sweep", a.sweeps, "flippers: video of one flipper swept stop to stop (repeat, board order)")
      ->check(input_file())
      ->default_str("")
      ->excludes(sim);
  cmd->add_option("--method", a.method, "flippers: method written to the file when both ran")
      ->check(CLI::IsMember({"markers", "markerless"}));
  cmd->add_option("--target", a.target,
                  "intrinsics: the printed target, chessboard:SXxSY:SQUARE_M or "
                  "charuco:SXxSY:SQUARE_M:MARKER_M[:DICTIONARY] (squares, metres)")
      ->check(CLI::Validator(
          [](std::string& text) {
            try {
              (void)calibration::parse_target(text);
            } catch (const std::invalid_argument& e) {
              return std::string(e.what());
            }
            return std::string();
          },
          "SPEC"))
      ->capture_default_str();
  cmd->add_option("--images", a.images, "intrinsics: images of the target (repeat), or a directory: its .png and .jpg")
      ->check(CLI::ExistingPath)
      ->default_str("")
      ->excludes(sim);
  cmd->add_option("--sim-views", a.sim_views, "intrinsics with --sim: views of the target to render (5 at least: the fit needs 5)")
      ->check(finite_range(5, 500))
      ->capture_default_str()
      ->needs(sim);
  cmd->add_option("--camera-size", a.camera_size, "intrinsics with --sim: the simulated camera's image size, WxH")
      ->check(CLI::Validator(
          [](std::string& text) {
            int w = 0, h = 0;
            char x = 0, rest = 0;
            if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &rest) != 3 || x != 'x' || w < 32 || h < 32 ||
                w > 8192 || h > 8192) {
              return std::string("expected WxH, each in [32, 8192], e.g. 640x480");
            }
            return std::string();
          },
          "WxH"))
      ->capture_default_str()
      ->needs(sim);
  auto* print_target =
      cmd->add_option("--print-target", a.print_target,
                      "intrinsics: write the printable target (PNG, 10 px/mm: print at 254 dpi, 100 %) and stop")
          ->check(output_file())
          ->excludes(sim);
  cmd->add_option("--roll", a.rolls, "gravity: observation CSV (t,x,y) of one roll from rest (repeat)")
      ->check(input_file())
      ->default_str("")
      ->excludes(sim);
  cmd->add_option("--sim-rolls", a.sim_rolls, "gravity with --sim: rolls to simulate")
      ->check(finite_range(1, 1000))
      ->needs(sim);
  cmd->add_option("--sigma", a.sigma_m, "gravity: observation noise per coordinate (m)")
      ->check(finite_range(1e-6, 0.1));
  cmd->add_option("--calibration", a.calibration, "calibration file holding the camera homography (default: --out)")
      ->transform(data_file())
      ->excludes(sim);
  cmd->add_option("--out", a.out, "calibration file to write, or update keeping its other sections")
      ->check(output_file());
  cmd->add_option("--png", a.png, "picture of the detected markers, fitted circles or gravity fit");
  cmd->add_option("--seed", a.seed, "--sim: seed of the simulated lab")
      ->check(unsigned_64())
      ->needs(sim);
  cmd->add_option("--sim-pivot-offset-mm", a.sim_pivot_offset_mm,
                  "--sim: the machine's pivots sit X Y mm off the board file (default 0 0: the board file's machine)")
      ->expected(2)
      ->check(finite_range(-20.0, 20.0))
      ->needs(sim);
  cmd->add_option("--sim-length-offset-mm", a.sim_length_offset_mm, "--sim: the machine's flippers are this much longer (mm)")
      ->check(finite_range(-20.0, 20.0))
      ->needs(sim);
  cmd->add_option("--sim-theta-offset-deg", a.sim_theta_offset_deg, "--sim: both flipper stops this much higher (degrees)")
      ->check(finite_range(-10.0, 10.0))
      ->needs(sim);
  cmd->add_option("--sim-camera", a.sim_camera,
                  "camera, flippers with --sim: the simulated camera, ideal or typical (a wide lens: calibrate "
                  "intrinsics into the same --out first, docs/calibration.md)")
      ->check(CLI::IsMember({"ideal", "typical"}))
      ->needs(sim);
  cmd->add_option("--device", a.device, "latency: the camera, /dev/videoN")->excludes(sim);
  cmd->add_option("--can", a.can, "latency: the driver board's SocketCAN interface, e.g. can0")->excludes(sim);
  cmd->add_option("--config", a.config,
                  "latency: pinballd's configuration (YAML), to fire the board as pinballd does: its can.board_id, "
                  "coils and watchdog, and its can.interface when --can is not given")
      ->excludes(sim);
  cmd->add_option("--flipper", a.flipper, "latency: the flipper to fire, by the board's name (default: the first)");
  cmd->add_option("--events", a.events, "latency: times the flipper is fired")->check(finite_range(3, 1000));
  cmd->add_option("--sim-latency-ms", a.sim_latency_ms,
                  "latency --sim: the simulated camera's minimum latency (ms; default: the typical camera's 7)")
      ->check(finite_range(0.0, 100.0))
      ->default_str("")  // -1: the typical camera's
      ->needs(sim);
  cmd->add_option("--sim-actuation-delay-ms", a.sim_actuation_delay_ms,
                  "latency --sim: the simulated machine's true actuation delay (ms; default: --actuation-delay-ms), "
                  "to see what assuming another costs")
      ->check(finite_range(0.0, 100.0))
      ->default_str("")  // -1: --actuation-delay-ms
      ->needs(sim);
  cmd->add_option("--actuation-delay-ms", a.actuation_delay_ms,
                  "latency: the host's command to the flipper's first motion (ms)")
      ->check(finite_range(0.0, 100.0));
  cmd->add_option("--row-time-us", a.row_time_us,
                  "latency: rolling shutter row time (us; 0: global shutter; default: the simulated camera's, "
                  "or the file's camera_timing)")
      ->check(finite_range(0.0, 1000.0))
      ->default_str("");  // -1: the simulated camera's or the file's
  cmd->add_option("--exposure-us", a.exposure_us,
                  "latency: the camera's fixed exposure time (us), set on the camera (auto-exposure off) and "
                  "corrected for; 0: neither (default: the simulated camera's)")
      ->check(finite_range(0.0, 100000.0))
      ->default_str("");  // -1: the simulated camera's
  cmd->add_option("--fps", a.fps, "latency: the frame rate asked of the camera")->check(finite_range(1.0, 2000.0));
  add_progress_flag(*cmd, a.progress);
  cmd->add_flag("--json", a.json, "print one JSON object instead of text");
  // Printing the target is all a run with --print-target does: images to fit, or a file to write, would be ignored.
  for (const char* measured : {"--images", "--out", "--png"}) print_target->excludes(cmd->get_option(measured));
  record_flags_given(cmd, a.flags_given);
  return cmd;
}

namespace {

// Which kinds read each flag that not every kind reads: `calibrate latency
// --sim-rolls 9` had run as if it were not there.
const std::vector<FlagUse>& calibrate_flag_uses() {
  static const std::vector<FlagUse> uses = {
      {{"--target", "--images", "--sim-views", "--camera-size", "--print-target"}, {"intrinsics"}},
      {{"--image"}, {"camera"}},
      {{"--markers"}, {"camera"}},
      {{"--sim-pivot-offset-mm", "--sim-length-offset-mm", "--sim-theta-offset-deg", "--sim-camera"},
       {"camera", "flippers"}},
      {{"--down", "--up", "--sweep", "--method"}, {"flippers"}},
      {{"--roll", "--sim-rolls", "--sigma"}, {"gravity"}},
      {{"--calibration"}, {"flippers", "latency"}},
      {{"--png"}, {"intrinsics", "camera", "flippers", "gravity"}},
      {{"--progress"}, {"intrinsics"}},
      {{"--device", "--can", "--config", "--flipper", "--events", "--sim-latency-ms", "--sim-actuation-delay-ms",
        "--actuation-delay-ms", "--row-time-us", "--exposure-us", "--fps"},
       {"latency"}},
  };
  return uses;
}

// The file --out updates, read first (a bad one is refused before any work). Its other
// sections stay, so a file whose camera, flippers or gravity are another board's is refused:
// written over with this board's name, it would claim them for this one.
calibration::Calibration calibration_to_update(const std::string& out, const std::string& board) {
  calibration::Calibration cal;
  if (out.empty() || !std::filesystem::exists(out)) return cal;
  cal = calibration::read_calibration(out);
  const bool board_sections = cal.camera || !cal.flippers.empty() || cal.gravity;
  const bool same = cal.board == board || same_file(cal.board, board);
  if (board_sections && !board.empty() && !cal.board.empty() && !same) {
    throw std::runtime_error("calibrate: --out " + out + " is a calibration of " + cal.board + ", not of " + board +
                             ": its other sections are that board's; write this one to another file");
  }
  return cal;
}

constexpr double kDeg = 180.0 / std::numbers::pi;

nlohmann::json vec_json(const Vec2& v) { return nlohmann::json::array({v.x(), v.y()}); }

nlohmann::json flipper_json(const calibration::FlipperCalibration& f) {
  return {{"method", calibration::to_string(f.method)}, {"pivot_m", vec_json(f.pivot_m)}, {"tip_m", vec_json(f.tip_m)},
          {"length_m", f.length_m}, {"theta_min_deg", f.theta_min_rad * kDeg}, {"theta_max_deg", f.theta_max_rad * kDeg},
          {"fit_rms_m", f.fit_rms_m}, {"points", f.points}};
}

// Errors against the simulated machine's truth.
nlohmann::json flipper_truth_json(const calibration::FlipperCalibration& f, const table::Flipper& t) {
  return {{"pivot_error_mm", (f.pivot_m - t.pivot).norm() * 1e3},
          {"tip_error_mm", (f.tip_m - table::flipper_tip(t, t.theta_min_rad)).norm() * 1e3},
          {"length_error_mm", (f.length_m - t.length_m) * 1e3},
          {"theta_min_error_deg", (f.theta_min_rad - t.theta_min_rad) * kDeg},
          {"theta_max_error_deg", (f.theta_max_rad - t.theta_max_rad) * kDeg}};
}

struct Context {
  const CalibrateArgs& a;
  std::ostream& err;
  table::Board board;
  std::unique_ptr<simlab::SimLab> lab;
  calibration::Calibration cal;
  nlohmann::json report;
  std::string text;  // the text report, when a kind has its own (else the file's YAML)
};

calibration::HomographyFit camera(Context& c, std::size_t* layout_markers = nullptr) {
  const std::vector<Vec2> layout = c.a.markers.empty() ? calibration::default_marker_layout(c.board)
                                                       : calibration::read_marker_layout_csv(c.a.markers, c.board);
  if (layout_markers) *layout_markers = layout.size();
  const cv::Mat image = c.lab ? c.lab->camera_image() : plot::read_gray_image(c.a.image);
  c.err << "calibrate camera: " << layout.size() << " markers in the layout, image " << image.cols << "x" << image.rows
        << "\n";
  // The homography maps the board into the ideal image: with the file's lens the markers are undistorted first.
  const std::optional<vision::CameraIntrinsics> lens =
      c.cal.intrinsics ? std::optional<vision::CameraIntrinsics>(c.cal.intrinsics->lens) : std::nullopt;
  if (lens) c.err << "calibrate camera: markers undistorted through the file's intrinsics\n";
  calibration::HomographyFit fit;
  try {
    fit = calibration::calibrate_camera(image, layout, {}, {}, lens);
  } catch (const std::runtime_error& e) {
    if (lens) throw;
    // A wide lens moves markers too far for any homography to match them.
    throw std::runtime_error(std::string(e.what()) +
                             " (without the lens's intrinsics in the file: if the lens bends the image, run "
                             "`pinball calibrate intrinsics` into the same --out first)");
  }
  c.err << "calibrate camera: " << fit.detections << " detected, " << fit.calibration.markers_used
        << " used, reprojection rms " << fit.calibration.reprojection_rms_px << " px\n";
  if (c.a.kind == "camera" && !c.a.png.empty()) plot::write_png(calibration::draw_camera_figure(image, fit), c.a.png);
  return fit;
}

void run_camera(Context& c) {
  if (!c.lab && c.a.image.empty()) throw std::runtime_error("calibrate camera: give --image (or --sim BOARD)");
  std::size_t layout_markers = 0;
  const calibration::HomographyFit fit = camera(c, &layout_markers);
  c.cal.camera = fit.calibration;
  // The section as the file writes it (homography, image size, markers, residuals), and the detections.
  nlohmann::json j = to_json_value(fit.calibration);
  j["markers_in_layout"] = layout_markers;
  j["markers_detected"] = fit.detections;
  if (c.lab) {
    const vision::CameraHomography h(fit.calibration.image_from_board);
    double worst = 0.0;
    for (int i = 0; i <= 10; ++i) {
      for (int k = 0; k <= 20; ++k) {
        const Vec2 p{c.board.width_m * i / 10.0, c.board.height_m * k / 20.0};
        worst = std::max(worst, (h.board_from_image(c.lab->true_homography().image_from_board(p)) - p).norm());
      }
    }
    j["truth"] = {{"homography_max_error_mm", worst * 1e3}};
  }
  c.report["camera"] = j;
}

std::string size_text(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }

void run_flippers(Context& c) {
  const bool markers = c.lab || (!c.a.down.empty() && !c.a.up.empty());
  const bool sweeps = c.lab || !c.a.sweeps.empty();
  if (!markers && !sweeps) throw std::runtime_error("calibrate flippers: give --down and --up, or --sweep (or --sim)");
  check_distinct_inputs(c.a.sweeps, "calibrate flippers: --sweep", "one video sweeps one flipper");
  // --method picks what is written when both ran: naming one that does not run would write the other.
  const bool markers_asked = c.a.method == "markers";
  const bool method_given =
      std::find(c.a.flags_given.begin(), c.a.flags_given.end(), "--method") != c.a.flags_given.end();
  if (method_given && !(markers_asked ? markers : sweeps)) {
    throw std::runtime_error(std::string("calibrate flippers: --method ") + c.a.method + " needs " +
                             (markers_asked ? "--down and --up" : "--sweep videos") + ", which were not given");
  }
  if (!c.lab && !c.a.sweeps.empty() && c.a.sweeps.size() != c.board.flippers.size()) {
    throw std::runtime_error("calibrate flippers: " + std::to_string(c.a.sweeps.size()) + " sweep videos for " +
                             std::to_string(c.board.flippers.size()) + " flippers");
  }
  // The homography: the simulated camera calibrated afresh, or the file's.
  cv::Mat background;
  std::optional<vision::CameraHomography> h;
  std::optional<calibration::IntrinsicsCalibration> lens = c.cal.intrinsics;  // the lens the homography was fitted after
  cv::Size camera_size;     // the image size the homography was measured at (lab files)
  std::string camera_file;  // the file holding it
  if (c.lab) {
    h.emplace(camera(c).calibration.image_from_board);
  } else {
    const std::string from = c.a.calibration.empty() ? c.a.out : c.a.calibration;
    if (from.empty()) throw std::runtime_error("calibrate flippers: give --calibration FILE with a camera section");
    if (!std::filesystem::exists(from)) {
      // The --out of a first run: nothing measured the camera yet.
      throw std::runtime_error("calibrate flippers: " + from + " does not exist: the markers are placed through the "
                               "camera's homography, so run `calibrate camera --out " + from + "` first");
    }
    const calibration::Calibration from_file = calibration::read_calibration(from);
    h.emplace(calibration::camera_homography(from_file, from));
    lens = from_file.intrinsics;
    camera_size = cv::Size(from_file.camera->image_width_px, from_file.camera->image_height_px);
    camera_file = from;
  }
  // The homography maps pixels of the camera's image size: a picture of another size (resized, another
  // camera mode) would place every marker mm off without a word.
  const auto check_image_size = [&](const cv::Size& size, const std::string& what) {
    if (c.lab || size == camera_size) return;
    throw std::runtime_error("calibrate flippers: " + what + " is " + size_text(size.width, size.height) + ", but " +
                             camera_file + "'s camera section was measured on " +
                             size_text(camera_size.width, camera_size.height) +
                             " images; take the flipper pictures at the camera's size; nothing written");
  };
  std::vector<Vec2> down, up;
  if (markers) {
    const cv::Mat di = c.lab ? c.lab->flipper_markers_image(false) : plot::read_gray_image(c.a.down);
    const cv::Mat ui = c.lab ? c.lab->flipper_markers_image(true) : plot::read_gray_image(c.a.up);
    check_image_size(di.size(), "--down " + c.a.down);
    check_image_size(ui.size(), "--up " + c.a.up);
    std::vector<calibration::DetectedMarker> seen_down = calibration::detect_markers(di);
    std::vector<calibration::DetectedMarker> seen_up = calibration::detect_markers(ui);
    if (lens) {  // the homography is the ideal image's
      calibration::undistort_markers(seen_down, lens->lens);
      calibration::undistort_markers(seen_up, lens->lens);
    }
    for (const auto& m : seen_down) down.push_back(h->board_from_image(m.uv_px));
    for (const auto& m : seen_up) up.push_back(h->board_from_image(m.uv_px));
    background = di;
    c.err << "calibrate flippers: " << down.size() << " markers down, " << up.size() << " up\n";
  }
  std::vector<calibration::FlipperCalibration> by_markers, markerless;
  std::vector<calibration::SweepTrack> tracks(c.board.flippers.size());
  nlohmann::json list = nlohmann::json::array();
  for (std::size_t i = 0; i < c.board.flippers.size(); ++i) {
    const table::Flipper& f = c.board.flippers[i];
    nlohmann::json j = {{"name", f.name}};
    if (markers) {
      by_markers.push_back(calibration::calibrate_flipper_markers(f, down, up));
      j["markers"] = flipper_json(by_markers.back());
    }
    if (sweeps) {
      calibration::FrameSourceFactory open;
      if (c.lab) {
        open = [&, i] { return c.lab->sweep_video(i); };
      } else {
        vision::CaptureConfig cc;
        cc.source = c.a.sweeps[i];
        open = [cc] { return std::make_unique<vision::CaptureSource>(cc); };
      }
      c.err << "calibrate flippers: sweep of " << f.name << "\n";
      if (!c.lab) {
        vision::Frame first;
        if (open()->read(first)) check_image_size(first.gray.size(), "--sweep " + c.a.sweeps[i]);
      }
      try {
        markerless.push_back(calibration::calibrate_flipper_sweep(open, *h, f, {}, &tracks[i]));
      } catch (const std::runtime_error& e) {  // which of the videos
        if (c.lab) throw;
        throw std::runtime_error("calibrate flippers: --sweep " + c.a.sweeps[i] + " (" + f.name + "): " + e.what());
      }
      j["markerless"] = flipper_json(markerless.back());
      if (background.empty()) {
        vision::Frame frame;
        if (open()->read(frame)) background = frame.gray.clone();
      }
    }
    if (markers && sweeps) {
      const calibration::FlipperDisagreement d = calibration::compare_flippers(by_markers[i], markerless[i]);
      j["disagreement"] = {{"pivot_mm", d.pivot_m * 1e3}, {"tip_mm", d.tip_m * 1e3}, {"length_mm", d.length_m * 1e3},
                           {"theta_min_deg", d.theta_min_rad * kDeg}, {"theta_max_deg", d.theta_max_rad * kDeg}};
    }
    if (c.lab) {
      const table::Flipper& t = c.lab->truth().flippers[i];
      if (markers) j["markers"]["truth"] = flipper_truth_json(by_markers[i], t);
      if (sweeps) j["markerless"]["truth"] = flipper_truth_json(markerless[i], t);
    }
    list.push_back(j);
    const bool use_markers = markers && (c.a.method == "markers" || !sweeps);
    calibration::FlipperCalibration chosen = use_markers ? by_markers[i] : markerless[i];
    if (markers && sweeps) {
      chosen.disagreement =
          calibration::compare_flippers(chosen, use_markers ? markerless[i] : by_markers[i]);
    }
    // Both methods when both ran, the one written first, then how far apart they are.
    auto print = [&](const calibration::FlipperCalibration& m, const char* role) {
      c.err << "calibrate flippers: " << f.name << " (" << calibration::to_string(m.method) << role << "): pivot ("
            << m.pivot_m.x() << ", " << m.pivot_m.y() << ") m, length " << m.length_m << " m, theta "
            << m.theta_min_rad * kDeg << " .. " << m.theta_max_rad * kDeg << " deg\n";
    };
    print(chosen, markers && sweeps ? ", written" : "");
    if (markers && sweeps) {
      print(use_markers ? markerless[i] : by_markers[i], ", not written");
      const calibration::FlipperDisagreement& d = *chosen.disagreement;
      c.err << "calibrate flippers: " << f.name << " methods disagree by: pivot " << d.pivot_m * 1e3 << " mm, tip "
            << d.tip_m * 1e3 << " mm, length " << d.length_m * 1e3 << " mm, theta " << d.theta_min_rad * kDeg
            << " / " << d.theta_max_rad * kDeg << " deg\n";
    }
    c.cal.flippers.push_back(chosen);
  }
  c.report["flippers"] = list;
  if (markers) c.report["markers_seen"] = {{"down", down.size()}, {"up", up.size()}};
  if (!c.a.png.empty()) {
    std::vector<calibration::FlipperFigureItem> items;
    for (std::size_t i = 0; i < c.board.flippers.size(); ++i) {
      items.push_back({sweeps ? &tracks[i] : nullptr, markers ? &by_markers[i] : nullptr,
                       sweeps ? &markerless[i] : nullptr});
    }
    plot::write_png(calibration::draw_flipper_figure(background, *h, items), c.a.png);
  }
}

void run_gravity(Context& c) {
  std::vector<calibration::GravityRoll> rolls;
  if (c.lab) {
    rolls = c.lab->rolls(c.a.sim_rolls);
  } else {
    if (c.a.rolls.empty()) throw std::runtime_error("calibrate gravity: give --roll FILE.csv (or --sim BOARD)");
    check_distinct_inputs(c.a.rolls, "calibrate gravity: --roll", "one roll would count twice");
    for (const std::string& path : c.a.rolls) {
      calibration::GravityRoll r;
      r.source = path;
      const std::vector<track::ObservationRow> rows = track::read_observations_csv(path);
      track::check_observations_on_board(rows, c.board, path);
      for (const track::ObservationRow& row : rows) r.observations.push_back(row.observation);
      rolls.push_back(std::move(r));
    }
  }
  calibration::GravityOptions o;
  o.sigma_m = c.a.sigma_m;
  const calibration::GravityCalibration g = calibration::calibrate_gravity(rolls, o);
  nlohmann::json per_roll = nlohmann::json::array();
  for (const calibration::RollFit& f : g.rolls) {
    nlohmann::json j = {{"source", f.source}, {"usable", f.usable}};
    if (f.usable) {
      j.update({{"accel_mps2", f.accel_mps2}, {"stderr_mps2", f.accel_stderr_mps2}, {"lateral_mps2", f.lateral_mps2},
                {"rms_m", f.rms_m}, {"points", f.last - f.first + 1}, {"outlier", f.outlier}});
    } else {
      j["why"] = f.why;
    }
    c.err << "calibrate gravity: " << f.source << ": "
          << (f.usable ? std::to_string(f.accel_mps2) + " m/s^2" + (f.outlier ? " (outlier)" : "") : f.why) << "\n";
    per_roll.push_back(j);
  }
  const calibration::GravityEstimate& e = g.estimate;
  c.report["gravity"] = {{"g_mps2", e.g_mps2},          {"ci_low_mps2", e.ci_low_mps2},
                         {"ci_high_mps2", e.ci_high_mps2}, {"confidence", e.confidence},
                         {"rolls_used", e.rolls_used},  {"rolls_rejected", e.rolls_rejected},
                         {"rolls", per_roll}};
  if (c.lab) {
    c.report["gravity"]["truth"] = {{"g_mps2", c.lab->truth().gravity_mps2},
                                    {"error_pct", (e.g_mps2 / c.lab->truth().gravity_mps2 - 1.0) * 100.0}};
  }
  c.err << "calibrate gravity: g = " << e.g_mps2 << " m/s^2, " << e.confidence * 100 << "% interval ["
        << e.ci_low_mps2 << ", " << e.ci_high_mps2 << "]\n";
  if (e.rolls_used < 2) {
    // Said, not refused: a first check of the rig may be one roll; the file is written all the same.
    const std::string warning =
        "one roll used: the interval is that roll's fit alone, not the spread between rolls (roll five or more)";
    c.err << "calibrate gravity: warning: " << warning << "\n";
    c.report["gravity"]["warning"] = warning;
  }
  c.cal.gravity = e;
  if (!c.a.png.empty()) plot::write_png(calibration::draw_gravity_figure(rolls, g), c.a.png);
}

// ---- latency: the camera's latency against a flipper fired at a known time ----

// The board's flipper named `name` (the first for an empty name). Throws naming the choices.
std::size_t flipper_index(const table::Board& board, const std::string& name) {
  if (board.flippers.empty()) throw std::runtime_error("calibrate latency: the board has no flipper");
  if (name.empty()) return 0;
  std::string names;
  for (std::size_t i = 0; i < board.flippers.size(); ++i) {
    if (board.flippers[i].name == name) return i;
    names += (names.empty() ? "" : ", ") + board.flippers[i].name;
  }
  throw std::runtime_error("calibrate latency: --flipper " + name + ": not on the board (" + names + ")");
}

// What one measurement reports, text and JSON.
void report_latency(Context& c, const calibration::LatencyEstimate& e, const calibration::LatencyOptions& o,
                    const std::string& flipper, const simlab::SimLatencyRun* truth) {
  nlohmann::json events = nlohmann::json::array();
  for (std::size_t i = 0; i < e.events.size(); ++i) {
    const calibration::LatencyEvent& ev = e.events[i];
    nlohmann::json j = {{"event", i + 1}, {"command_s", ev.command_t_s}, {"used", ev.used()}};
    if (ev.used()) {
      j.update({{"latency_ms", ev.latency_s * 1e3}, {"motion_row_px", ev.motion_row_px}, {"fit_frames", ev.fit_frames},
                {"fit_rms", ev.fit_rms}, {"stroke_sigmas", ev.stroke_sigmas}});
    } else {
      j["why"] = calibration::to_string(ev.rejection);
    }
    events.push_back(j);
  }
  nlohmann::json j = {{"flipper", flipper},
                      {"latency_ms", e.latency_s * 1e3},
                      {"spread_ms", e.spread_s * 1e3},
                      {"events_used", e.events_used},
                      {"events_rejected", e.events_rejected},
                      {"row_time_us", o.row_time_s * 1e6},
                      {"motion_row_px", e.motion_row_px},
                      {"exposure_ms", o.exposure_s * 1e3},
                      {"actuation_delay_ms", o.actuation_delay_s * 1e3},
                      {"frame_period_ms", o.frame_period_s * 1e3},
                      {"events", events}};
  if (truth) {
    j["truth"] = {{"latency_ms", truth->true_latency_s * 1e3},
                  {"mean_latency_ms", truth->true_mean_latency_s * 1e3},
                  {"actuation_delay_ms", truth->timing.actuation_delay_s * 1e3},
                  {"error_ms", (e.latency_s - truth->true_latency_s) * 1e3}};
  }
  c.report["latency"] = j;

  std::ostringstream s;
  s << std::fixed << std::setprecision(3);
  s << "event  command (s)  latency (ms)  fit frames  fit rms\n";
  for (std::size_t i = 0; i < e.events.size(); ++i) {
    const calibration::LatencyEvent& ev = e.events[i];
    s << std::setw(5) << i + 1 << "  " << std::setw(11) << ev.command_t_s << "  ";
    if (ev.used()) {
      s << std::setw(12) << ev.latency_s * 1e3 << "  " << std::setw(10) << ev.fit_frames << "  " << std::setw(7)
        << std::setprecision(4) << ev.fit_rms << std::setprecision(3) << "\n";
    } else {
      s << "not used: " << calibration::to_string(ev.rejection) << "\n";
    }
  }
  s << "camera latency " << e.latency_s * 1e3 << " ms (median of " << e.events_used << " of " << e.events.size()
    << " events; standard deviation " << e.spread_s * 1e3 << " ms), flipper " << flipper << ", row time "
    << o.row_time_s * 1e6 << " us, actuation delay " << o.actuation_delay_s * 1e3 << " ms\n";
  if (truth) {
    s << "simulated camera: true minimum latency " << truth->true_latency_s * 1e3 << " ms, error "
      << std::showpos << (e.latency_s - truth->true_latency_s) * 1e3 << std::noshowpos
      << " ms; the machine's actuation delay " << truth->timing.actuation_delay_s * 1e3 << " ms\n";
  }
  c.text = s.str();
}

// The text report of a kind without one of its own: the section it wrote, as the file now holds it.
// The whole file repeated every other section a lab had calibrated before (a lens, the flippers).
calibration::Calibration written_section(const calibration::Calibration& file, const std::string& kind) {
  calibration::Calibration part;
  part.date = file.date;
  part.board = file.board;
  if (kind == "camera") part.camera = file.camera;
  if (kind == "flippers") part.flippers = file.flippers;
  if (kind == "gravity") part.gravity = file.gravity;
  return part;
}

// A rolling shutter reads its rows out within one frame: a line time that makes the read-out longer
// (1000 us x 480 rows = 480 ms at 200 frames/s) is a unit or a digit wrong, and skews every event.
void check_row_time(double row_time_s, int rows, double fps) {
  const double readout_s = row_time_s * rows;
  if (readout_s * fps <= 1.0) return;
  throw std::invalid_argument("calibrate latency: --row-time-us " + format_number(row_time_s * 1e6) + ": " +
                              std::to_string(rows) + " rows take " + format_number(readout_s * 1e3, 3) +
                              " ms to read out, longer than a frame at --fps " + format_number(fps) + " (" +
                              format_number(1e3 / fps, 3) + " ms): the line time is at most " +
                              format_number(1e6 / (fps * rows), 3) + " us");
}

void run_latency_sim(Context& c) {
  const CalibrateArgs& a = c.a;
  simlab::SimLatencyOptions o;
  o.seed = a.seed;
  o.events = a.events;
  o.flipper = flipper_index(c.board, a.flipper);
  // The machine's true delay; --actuation-delay-ms is what the measurement assumes (below).
  o.actuation_delay_s = (a.sim_actuation_delay_ms >= 0.0 ? a.sim_actuation_delay_ms : a.actuation_delay_ms) * 1e-3;
  if (a.sim_latency_ms >= 0.0) o.camera.realism.latency_min_s = a.sim_latency_ms * 1e-3;
  // The simulated camera reads its rows out in a fixed time; far below 100 frames/s no event can be fitted.
  const double readout_s = o.camera.realism.row_time_s * o.camera.height_px;
  constexpr double kSimMinFps = 10.0;
  if (a.fps < kSimMinFps || a.fps * readout_s > 1.0) {
    throw std::invalid_argument("calibrate latency --sim: --fps " + format_number(a.fps) +
                                ": the simulated camera runs at " + format_number(kSimMinFps) + " to " +
                                format_number(std::floor(1.0 / readout_s)) + " frames/s (it reads a frame out in " +
                                format_number(readout_s * 1e3) + " ms)");
  }
  if (a.row_time_us >= 0.0) check_row_time(a.row_time_us * 1e-6, o.camera.height_px, a.fps);  // before any work
  // A long actuation delay needs longer between fires: the flipper at rest 0.2 s before the next command.
  o.spacing_s = std::max(o.spacing_s, o.actuation_delay_s + o.hold_s + o.return_s + 0.2);
  o.camera.fps = a.fps;  // the rate asked of the camera, as in the lab (it had stayed 200)
  o.camera.exposure_s = std::min(o.camera.exposure_s, 1.0 / a.fps);
  o.lead_in_s = std::max(o.lead_in_s, calibration::latency_lead_in_s(calibration::LatencyOptions{}, 1.0 / a.fps));
  // A slow camera with a long latency (10 fps, 100 ms) needs a longer step: it had failed with the step's own message.
  o.step_s = std::max(o.step_s, simlab::min_latency_step_s(o.camera));
  c.err << "calibrate latency: simulating " << o.events << " fires of " << c.board.flippers[o.flipper].name << "\n";
  const simlab::SimLatencyRun run = simlab::simulate_latency_run(c.board, o);
  calibration::LatencyOptions lo = run.timing;
  lo.actuation_delay_s = a.actuation_delay_ms * 1e-3;
  if (a.row_time_us >= 0.0) lo.row_time_s = a.row_time_us * 1e-6;
  if (a.exposure_us >= 0.0) lo.exposure_s = a.exposure_us * 1e-6;
  const calibration::LatencyEstimate e = calibration::measure_latency(run.recording, run.region, lo);
  c.cal.camera_timing = e.camera_timing();
  report_latency(c, e, lo, c.board.flippers[o.flipper].name, &run);
}

// SIGINT/SIGTERM during the lab run: stop firing, release, report.
std::atomic<bool> g_latency_interrupted{false};
extern "C" void on_latency_signal(int) { g_latency_interrupted.store(true); }

// Installs the handlers for its lifetime.
class InterruptGuard {
 public:
  InterruptGuard() {
    g_latency_interrupted.store(false);
    struct sigaction sa {};
    sa.sa_handler = on_latency_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, &old_int_);
    sigaction(SIGTERM, &sa, &old_term_);
  }
  ~InterruptGuard() {
    sigaction(SIGINT, &old_int_, nullptr);
    sigaction(SIGTERM, &old_term_, nullptr);
  }
  InterruptGuard(const InterruptGuard&) = delete;
  InterruptGuard& operator=(const InterruptGuard&) = delete;

 private:
  struct sigaction old_int_ {};
  struct sigaction old_term_ {};
};

// Sleeps until steady time t_s (s), in short naps so that an interrupt is seen.
void sleep_until(double t_s) {
  while (!g_latency_interrupted.load()) {
    const double left = t_s - steady_now_s();
    if (left <= 0.0) return;
    std::this_thread::sleep_for(std::chrono::duration<double>(std::min(left, 0.01)));
  }
}

// Writes what the bus has queued (a Fire or a Release) now and returns the
// steady time it was written to the socket (s).
double send_now(firmware::DriverBus& bus) {
  // The bus thread may hold the socket for a moment: try again until the queue is out.
  for (int i = 0; i < 1000; ++i) {
    if (bus.send_queued(steady_now_s())) return steady_now_s();
    std::this_thread::sleep_for(std::chrono::microseconds(20));
  }
  return steady_now_s();  // the bus thread sent it meanwhile, within its period
}

void run_latency_lab(Context& c) {
  const CalibrateArgs& a = c.a;
  // pinballd's own settings, when given: a board strapped to another id than 0 never answered the
  // defaults, and the coil fired with timings the game does not use.
  const std::optional<daemon::DaemonConfig> lab =
      a.config.empty() ? std::nullopt : std::optional<daemon::DaemonConfig>(daemon::load_daemon_config(a.config));
  std::string can = a.can;
  if (can.empty() && lab && lab->can.interface != "sim") can = lab->can.interface;
  std::string device = a.device;
  if (device.empty() && lab && lab->camera.source == "v4l2") device = lab->camera.device;
  if (device.empty() || can.empty()) {
    throw std::runtime_error("calibrate latency: give --device /dev/videoN and --can IFACE (or --config with "
                             "pinballd's lab camera.device and can.interface; or --sim BOARD)");
  }
  const std::string from = a.calibration.empty() ? a.out : a.calibration;
  if (from.empty()) {
    throw std::runtime_error("calibrate latency: give --calibration FILE with the camera and flippers sections");
  }
  // Everything that can be checked before the hardware moves.
  const calibration::Calibration file = calibration::read_calibration(from);
  const vision::CameraHomography h = calibration::camera_homography(file, from);
  calibration::check_calibration_matches_board(file, from, c.board);
  const std::size_t index = flipper_index(c.board, a.flipper);
  const std::string& name = c.board.flippers[index].name;
  table::Flipper flipper = c.board.flippers[index];
  bool calibrated = false;
  for (const calibration::FlipperCalibration& f : file.flippers) {
    if (f.name != name) continue;
    flipper.pivot = f.pivot_m;
    flipper.length_m = f.length_m;
    flipper.theta_min_rad = f.theta_min_rad;
    flipper.theta_max_rad = f.theta_max_rad;
    calibrated = true;
  }
  if (!calibrated) throw std::runtime_error(from + ":flippers: " + name + " is not calibrated (pinball calibrate flippers)");
  calibration::LatencyOptions lo;
  lo.actuation_delay_s = a.actuation_delay_ms * 1e-3;
  lo.exposure_s = std::max(a.exposure_us, 0.0) * 1e-6;
  if (a.row_time_us >= 0.0) {
    lo.row_time_s = a.row_time_us * 1e-6;
  } else if (file.camera_timing) {
    lo.row_time_s = file.camera_timing->row_time_s;
  } else {
    throw std::runtime_error("calibrate latency: give --row-time-us (the sensor's line time; 0 for a global shutter): " +
                             from + " has no camera_timing section to take it from");
  }
  const cv::Size size(file.camera->image_width_px, file.camera->image_height_px);
  check_row_time(lo.row_time_s, size.height, a.fps);
  const std::optional<vision::CameraIntrinsics> lens =
      file.intrinsics ? std::optional<vision::CameraIntrinsics>(file.intrinsics->lens) : std::nullopt;
  const calibration::FlipperRegion region = calibration::flipper_region(
      flipper,
      [&](const Vec2& p) {
        const cv::Point2d ideal = h.image_from_board(p);
        return lens ? vision::distort_pixel(*lens, ideal) : ideal;
      },
      size);

  // The hardware: say everything that is missing at once, before opening anything.
  std::string missing;
  if (!vision::is_device_source(device)) {
    missing = device + ": not a camera device (a video file cannot watch a flipper being fired)";
  } else {
    missing = vision::missing_camera_device(device);
  }
  const firmware::CanLinkVerdict link =
      firmware::judge_can_link(firmware::read_can_link(can), can, firmware::kBitrate_bps);
  if (!link.ok) missing += (missing.empty() ? "" : "; ") + std::string("--can ") + link.message;
  if (!missing.empty()) throw std::runtime_error("calibrate latency: " + missing + "; nothing was fired or written");

  vision::CaptureConfig cc;
  cc.source = device;
  cc.width_px = size.width;
  cc.height_px = size.height;
  cc.fps = a.fps;
  if (a.exposure_us > 0.0) cc.exposure_s = a.exposure_us * 1e-6;  // fixed, as pinballd's camera.exposure_s fixes it
  vision::CaptureSource camera(cc);
  if (camera.frame_size() != size) {
    throw std::runtime_error("calibrate latency: " + device + " gives " + std::to_string(camera.frame_size().width) +
                             "x" + std::to_string(camera.frame_size().height) + " frames, the calibration is for " +
                             std::to_string(size.width) + "x" + std::to_string(size.height));
  }
  const int drivers = static_cast<int>(c.board.flippers.size());
  firmware::DriverBusOptions bo;
  bo.driver_count = drivers;
  if (lab) bo = daemon::driver_bus_options_for(*lab, drivers);
  const WriterLock board_lock = firmware::lock_driver_board(can, bo.board_id);  // not beside a running pinballd
  firmware::SocketCanOptions so;
  so.interface = can;
  firmware::SocketCanTransport transport(so);
  firmware::DriverBus bus(transport, bo);  // its destructor stops the thread with every coil off
  InterruptGuard interrupts;
  bus.start();  // from here the bus's destructor stops it with every coil off
  const double answer_by = steady_now_s() + 2.0;
  while (bus.state() != firmware::BusState::kRunning && steady_now_s() < answer_by && !g_latency_interrupted.load()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  if (bus.state() != firmware::BusState::kRunning) {
    throw std::runtime_error("calibrate latency: the driver board " + std::to_string(bo.board_id) +
                             " did not answer on " + can + " within 2 s" +
                             (lab ? "" : " (board id 0 and the protocol's coil timings: --config takes pinballd's)"));
  }

  // The camera's thread keeps the region of every frame; this one fires.
  calibration::LatencyRecording recording;
  std::atomic<bool> stop{false};
  std::string camera_error;  // written by the reader before it ends, read after the join
  std::thread reader([&] {
    try {
      vision::Frame frame;
      int failures = 0;
      while (!stop.load()) {
        if (camera.read(frame)) {
          recording.add_frame(region, frame.gray, frame.t_s, frame.sequence);
          failures = 0;
        } else if (++failures > 100) {
          throw std::runtime_error("the camera stopped delivering frames");
        } else {
          std::this_thread::sleep_for(std::chrono::milliseconds(1));
        }
      }
    } catch (const std::exception& e) {
      camera_error = e.what();
      stop.store(true);
    }
  });
  struct Join {
    std::thread& t;
    std::atomic<bool>& stop;
    ~Join() {
      stop.store(true);
      if (t.joinable()) t.join();
    }
  } join{reader, stop};
  // Every coil off first on the way out, whatever happens below (declared
  // last: released before the camera's thread is joined).
  struct CoilsOff {
    firmware::DriverBus& bus;
    ~CoilsOff() {
      bus.release_all();
      bus.send_queued(steady_now_s());
    }
  } coils_off{bus};
  const double period = 1.0 / camera.fps();
  const double hold_s = 0.1, spacing_s = 0.5;
  Rng rng(a.seed);
  std::vector<double> commands;
  const int driver = static_cast<int>(index);
  double next = steady_now_s() + calibration::latency_lead_in_s(lo, period);  // the frame clock settles first
  c.err << "calibrate latency: firing " << name << " " << a.events << " times, " << spacing_s << " s apart\n";
  for (int k = 0; k < a.events && !stop.load() && !g_latency_interrupted.load(); ++k) {
    sleep_until(next + rng.uniform(0.0, period));  // a random phase against the frames
    if (g_latency_interrupted.load() || stop.load()) break;
    if (!bus.fire(driver)) throw std::runtime_error("calibrate latency: the driver bus refused the fire command");
    commands.push_back(send_now(bus));
    sleep_until(commands.back() + hold_s);
    bus.release(driver);
    send_now(bus);
    next = commands.back() + spacing_s;
  }
  sleep_until(steady_now_s() + 0.3);  // the last event's window
  stop.store(true);
  reader.join();
  if (g_latency_interrupted.load()) throw std::runtime_error("calibrate latency: interrupted; every coil released, nothing written");
  if (!camera_error.empty()) throw std::runtime_error("calibrate latency: " + device + ": " + camera_error);
  if (bus.counters().coils_dropped > 0 || bus.state() != firmware::BusState::kRunning) {
    throw std::runtime_error("calibrate latency: the driver board dropped the coils or the session during the run");
  }
  recording.command_t_s = commands;
  lo.frame_period_s = calibration::estimate_frame_period_s(recording, period);
  const calibration::LatencyEstimate e = calibration::measure_latency(recording, region, lo);
  c.cal.camera_timing = e.camera_timing();
  report_latency(c, e, lo, name, nullptr);
}

// ---- intrinsics ----

constexpr double kPrintPxPerM = 10'000.0;  // --print-target: 10 px/mm (254 dpi)

cv::Size parse_size(const std::string& text) {
  int w = 0, h = 0;
  std::sscanf(text.c_str(), "%dx%d", &w, &h);  // checked by the option's validator
  return {w, h};
}


bool is_image_name(const std::filesystem::path& p) {
  const std::string ext = lowercase_extension(p);
  return ext == ".png" || ext == ".jpg" || ext == ".jpeg";
}

// --images: files as given, a directory as its .png and .jpg files in name order.
std::vector<std::string> image_paths(const std::vector<std::string>& given) {
  std::vector<std::string> out;
  for (const std::string& g : given) {
    if (!std::filesystem::is_directory(g)) {
      out.push_back(g);
      continue;
    }
    std::vector<std::string> found;
    for (const auto& e : std::filesystem::directory_iterator(g)) {
      if (e.is_regular_file() && is_image_name(e.path())) found.push_back(e.path().string());
    }
    if (found.empty()) throw std::runtime_error(g + ": no .png or .jpg images in this directory");
    std::sort(found.begin(), found.end());
    out.insert(out.end(), found.begin(), found.end());
  }
  return out;
}

// Files written all or not at all: each to a temporary beside it, renamed when every one is written.
class Outputs {
 public:
  Outputs() = default;
  Outputs(const Outputs&) = delete;
  Outputs& operator=(const Outputs&) = delete;
  ~Outputs() {
    for (const auto& [path, tmp] : pending_) std::filesystem::remove(tmp);
  }
  void add(const std::string& path, const std::string& bytes) {
    pending_.emplace_back(path, write_temporary_beside(path, bytes));
  }
  void commit() {
    for (const auto& [path, tmp] : pending_) std::filesystem::rename(tmp, path);
    pending_.clear();
  }

 private:
  std::vector<std::pair<std::string, std::string>> pending_;
};

std::string png_bytes(const cv::Mat& image, const std::string& path) {
  std::vector<unsigned char> buf;
  if (!cv::imencode(".png", image, buf)) throw std::runtime_error(path + ": cannot encode the PNG");
  return std::string(buf.begin(), buf.end());
}

int print_target(const CalibrateArgs& a, const calibration::TargetSpec& target, std::ostream& out) {
  const int margin_px = static_cast<int>(std::lround(target.square_m * kPrintPxPerM));
  cv::Mat img;
  try {
    img = calibration::target_image(target, kPrintPxPerM, margin_px);
  } catch (const std::invalid_argument& e) {  // said as the options the user gave
    throw std::invalid_argument("calibrate intrinsics: --target " + a.target + " printed at " +
                                format_number(kPrintPxPerM * 1e-3) + " px/mm: " + e.what() +
                                "; print a target of fewer or smaller squares");
  }
  Outputs files;
  files.add(a.print_target, png_bytes(img, a.print_target));
  files.commit();
  const double w_mm = img.cols / kPrintPxPerM * 1e3, h_mm = img.rows / kPrintPxPerM * 1e3;
  if (a.json) {
    out << json_text(nlohmann::json{{"kind", "intrinsics"},
                                    {"target", target.describe()},
                                    {"print_target", a.print_target},
                                    {"width_px", img.cols},
                                    {"height_px", img.rows},
                                    {"px_per_mm", kPrintPxPerM * 1e-3},
                                    {"sheet_width_mm", w_mm},
                                    {"sheet_height_mm", h_mm},
                                    {"square_mm", target.square_m * 1e3}},
                     2)
        << "\n";
  } else {
    out << "wrote " << a.print_target << ": " << target.describe() << ", " << img.cols << "x" << img.rows
        << " px at 10 px/mm: print at 254 dpi, 100 % (no fit to page): " << format_number(w_mm) << " x "
        << format_number(h_mm) << " mm with a white border one square wide; measure a printed square and give its side "
        << "in --target\n";
  }
  return 0;
}

nlohmann::json lens_comparison_json(const calibration::LensComparison& c) {
  return {{"fx_error_pct", c.fx_error_pct},
          {"fy_error_pct", c.fy_error_pct},
          {"principal_point_error_px", c.principal_point_error_px},
          {"distortion_max_error_px", c.distortion_max_error_px},
          {"distortion_sensor_max_error_px", c.distortion_sensor_max_error_px}};
}

int run_intrinsics(const CalibrateArgs& a, std::ostream& out, std::ostream& err) {
  const calibration::TargetSpec target = calibration::parse_target(a.target);
  if (!a.print_target.empty()) return print_target(a, target, out);
  const bool simulated = !a.sim_board.empty();
  // The file to update: read first (a bad one is refused before any work).
  calibration::Calibration cal = calibration_to_update(a.out, simulated ? a.sim_board : a.board);
  // The camera's homography (and the flippers placed through it) were fitted on pixels undistorted by
  // the file's lens, or by none: a new lens beside them makes the file disagree with itself.
  if (cal.camera) {
    throw std::runtime_error("calibrate intrinsics: --out " + a.out + " holds a camera section fitted " +
                             (cal.intrinsics ? "through its present lens" : "without a lens model") +
                             ": the lens comes first, then camera and flippers; write the lens to a new file and "
                             "calibrate camera and flippers into it (or remove the camera and flippers sections)");
  }
  std::vector<calibration::TargetImage> images;
  std::optional<vision::CameraIntrinsics> truth;
  if (simulated) {
    (void)table::load_board(a.sim_board);  // the practice machine's board, named in the file
    const cv::Size size = parse_size(a.camera_size);
    truth = vision::typical_wide_lens(size.width, size.height);
    images = simlab::simulated_target_images(*truth, target, a.sim_views, a.seed);
    err << "calibrate intrinsics: rendered " << images.size() << " views of the target through the simulated "
        << size_text(size.width, size.height) << " lens\n";
  } else {
    if (a.images.empty()) throw std::runtime_error("calibrate intrinsics: give --images FILES or DIR (or --sim BOARD)");
    const std::vector<std::string> paths = image_paths(a.images);
    const int needed = calibration::IntrinsicsFitConfig{}.min_images;
    if (static_cast<int>(paths.size()) < needed) {  // before reading and searching every image
      throw std::runtime_error("calibrate intrinsics: " + std::to_string(paths.size()) +
                               " images; the fit needs at least " + std::to_string(needed) +
                               " views of the target (15-25 recommended)");
    }
    check_distinct_inputs(paths, "calibrate intrinsics: image", "one view would count twice");
    for (const std::string& path : paths) images.push_back({path, plot::read_gray_image(path)});
  }
  err << "calibrate intrinsics: " << images.size() << " images of the " << target.describe() << "\n";
  // Searching a large image that lacks the target takes seconds: 25 of them, minutes.
  ProgressMeter meter(progress_wanted(a.progress) ? &err : nullptr, "calibrate intrinsics: searching for the target",
                      static_cast<double>(images.size()), "images", !a.progress && progress_wanted(false));
  meter.update(0);
  const calibration::IntrinsicsFit fit = calibration::calibrate_intrinsics(
      images, target, {}, [&](std::size_t searched) { meter.update(static_cast<double>(searched)); });
  const calibration::IntrinsicsCalibration& in = fit.calibration;
  const vision::CameraIntrinsics& lens = in.lens;

  nlohmann::json per_image = nlohmann::json::array();
  for (const calibration::ImageResult& r : fit.images) {
    per_image.push_back({{"name", r.name},
                         {"used", r.used},
                         {"rejection", r.rejection},
                         {"corners", r.corners},
                         {"reprojection_rms_px", r.reprojection_rms_px}});
  }
  nlohmann::json report = {{"kind", "intrinsics"},
                           {"target", in.target},
                           {"simulated", simulated},
                           {"out", a.out},
                           {"lens", to_json_value(lens)},
                           {"reprojection_rms_px", in.reprojection_rms_px},
                           {"images_used", in.images_used},
                           {"images_rejected", in.images_rejected},
                           {"images", per_image}};
  std::optional<calibration::LensComparison> against;
  if (truth) {
    against = calibration::compare_lenses(lens, *truth);
    report["truth"] = lens_comparison_json(*against);
    report["truth"]["lens"] = to_json_value(*truth);
    report["sim_views"] = a.sim_views;
    report["seed"] = a.seed;
  }

  // Every output at once, or none.
  Outputs files;
  if (!a.png.empty()) files.add(a.png, png_bytes(calibration::draw_intrinsics_figure(fit, images), a.png));
  if (!a.out.empty()) {
    cal.intrinsics = in;
    if (simulated) cal.board = a.sim_board;
    else if (!a.board.empty()) cal.board = a.board;
    cal.date.clear();
    files.add(a.out, calibration::calibration_to_yaml(cal));
  }
  files.commit();
  if (!a.out.empty()) err << "calibrate: wrote " << a.out << "\n";

  if (a.json) {
    out << json_text(report, 2) << "\n";
    return 0;
  }
  out << "intrinsics: " << in.target << "; " << fit.images.size() << " images, " << in.images_used << " used, "
      << in.images_rejected << " rejected\n";
  out << "lens (" << size_text(lens.width_px, lens.height_px) << "): fx " << format_number(lens.fx_px, 5) << " px, fy "
      << format_number(lens.fy_px, 5) << " px, cx " << format_number(lens.cx_px, 4) << " px, cy "
      << format_number(lens.cy_px, 4) << " px\n";
  out << "distortion: k1 " << format_number(lens.k1) << ", k2 " << format_number(lens.k2) << ", k3 "
      << format_number(lens.k3) << ", p1 " << format_number(lens.p1) << ", p2 " << format_number(lens.p2) << "\n";
  out << "reprojection rms " << format_number(in.reprojection_rms_px) << " px\n";
  std::size_t width = 0;
  for (const calibration::ImageResult& r : fit.images) width = std::max(width, r.name.size());
  for (const calibration::ImageResult& r : fit.images) {
    out << "  " << r.name << std::string(width - r.name.size() + 2, ' ');
    if (r.used) {
      out << "used      " << r.corners << " corners, rms " << format_number(r.reprojection_rms_px) << " px\n";
    } else {
      out << "rejected  " << r.rejection << "\n";
    }
  }
  if (against) {
    out << "against the simulated lens: fx " << format_number(against->fx_error_pct, 2) << " %, fy "
        << format_number(against->fy_error_pct, 2) << " %, principal point "
        << format_number(against->principal_point_error_px, 2) << " px off, distortion within "
        << format_number(against->distortion_max_error_px, 2) << " px over the image ("
        << format_number(against->distortion_sensor_max_error_px, 2) << " px to the sensor's corners)\n";
  }
  return 0;
}

}  // namespace

int run_calibrate(const CalibrateArgs& a, std::ostream& out, std::ostream& err) {
  // What is written at the end can be written: checked before any work, and
  // before `latency` fires a flipper in the lab.
  refuse_flags_not_read(a.flags_given, calibrate_flag_uses(), "calibrate", a.kind);
  check_output_folder(a.out, "--out");
  check_png_output(a.png, "--png");
  check_png_output(a.print_target, "--print-target");
  check_distinct_outputs({{"--out", a.out}, {"--png", a.png}, {"--print-target", a.print_target}});
  if (a.kind == "intrinsics") return run_intrinsics(a, out, err);
  const std::string board_path = a.sim_board.empty() ? a.board : a.sim_board;
  if (board_path.empty()) throw std::runtime_error("calibrate: give --board BOARD (or --sim BOARD)");
  Context c{a, err, table::load_board(board_path), nullptr, {}, {}, {}};
  if (!a.sim_board.empty() && a.kind != "latency") {
    simlab::SimLabOptions o;
    o.seed = a.seed;
    o.pivot_offset_m = Vec2{a.sim_pivot_offset_mm.at(0), a.sim_pivot_offset_mm.at(1)} * 1e-3;
    o.length_offset_m = a.sim_length_offset_mm * 1e-3;
    o.theta_offset_rad = a.sim_theta_offset_deg / kDeg;
    if (a.sim_camera == "typical") o.camera.realism.lens = vision::typical_wide_lens(o.camera.width_px, o.camera.height_px);
    c.lab = std::make_unique<simlab::SimLab>(c.board, o);
    c.report["sim_mounting_error"] = {{"pivot_offset_mm", a.sim_pivot_offset_mm},
                                      {"length_offset_mm", a.sim_length_offset_mm},
                                      {"theta_offset_deg", a.sim_theta_offset_deg}};
  }
  // --out updates an existing file: the other sections stay.
  c.cal = calibration_to_update(a.out, board_path);
  c.cal.board = board_path;
  c.cal.date.clear();
  if (a.kind == "flippers") c.cal.flippers.clear();
  if (a.kind == "camera") run_camera(c);
  if (a.kind == "flippers") run_flippers(c);
  if (a.kind == "gravity") run_gravity(c);
  if (a.kind == "latency") {
    if (a.sim_board.empty()) {
      run_latency_lab(c);
    } else {
      run_latency_sim(c);
    }
  }
  if (!a.out.empty()) {
    calibration::write_calibration(c.cal, a.out);
    err << "calibrate: wrote " << a.out << "\n";
  }
  c.report["kind"] = a.kind;
  c.report["board"] = board_path;
  c.report["simulated"] = !a.sim_board.empty();
  c.report["out"] = a.out;
  if (a.json) {
    out << json_text(c.report, 2) << "\n";
  } else if (!c.text.empty()) {
    out << c.text;
  } else {
    out << calibration::calibration_to_yaml(written_section(c.cal, a.kind));
  }
  return 0;
}

}  // namespace pinball::cli
