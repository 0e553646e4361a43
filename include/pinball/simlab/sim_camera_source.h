#pragma once
// A camera made of the simulator: it is fed the simulator's state every step
// and renders grayscale frames at its own frame rate, as a camera bolted over
// the table would see them: the playfield drawing, clutter and lamps, the
// ball with shading and motion blur over the exposure, plastics that hide it,
// an optional glare patch, sensor noise, all seen through a perspective
// homography. The static scene is rendered once at construction; a frame
// costs one copy, the ball patch and the noise. Deterministic by seed.
//
// What makes a real camera differ from that ideal pinhole (SimCameraRealism,
// each part off by default and switched on alone or all together with
// SimCameraRealism::typical()): lens distortion (the static scene is remapped
// once; patches and the ball are drawn through the lens), a rolling shutter
// (each row of the ball is drawn where the ball was when that row was
// exposed), exposure-start jitter, a delivery latency (the frame is stamped
// and handed over when it arrives, as a host clock stamps a real camera's),
// lamp flicker (per row, integrated over the exposure) and a slow gain drift.
// A frame that read() delivers shows the flippers at the angles they had
// while it was exposed (each row at its own time under a rolling shutter,
// blurred over the exposure), so that a flipper fired at a known time is
// seen late by exactly the camera's latency.

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "pinball/core/geometry.h"
#include "pinball/core/rng.h"
#include "pinball/table/board.h"
#include "pinball/sim/game_state.h"
#include "pinball/vision/camera_homography.h"
#include "pinball/vision/frame_source.h"
#include "pinball/vision/lens_model.h"

namespace pinball::simlab {

/// A piece of plastic above the playfield that hides the ball beneath it.
struct SimPlastic {
  std::vector<Vec2> polygon_board;  ///< convex outline in the board frame (m)
  double gray = 95.0;               ///< its brightness (0..255)
  double opacity = 1.0;             ///< 1: opaque; less lets some of the floor through
};

/// An additive bright patch (a reflection of a room light in the glass).
struct SimGlare {
  bool enabled = false;             ///< draw it at all
  Vec2 centre_board{0.20, 0.35};    ///< centre (m, board frame)
  double sigma_m = 0.03;            ///< Gaussian size on the table (m); the patch spans ±3σ
  double peak_gray = 150.0;         ///< brightness added at the centre (gray levels)
  double toggle_probability = 0.0;  ///< per frame: chance it switches on/off (0: always on)
};

/// The ways a real camera differs from the ideal one; each is off at its
/// zero (or empty) value. typical() is a 200 fps 640x480 USB3 machine-vision
/// camera with a rolling-shutter CMOS sensor and a 4 mm lens under mains lamps
/// (docs/vision.md, "A real camera", states and justifies each number).
struct SimCameraRealism {
  std::optional<vision::CameraIntrinsics> lens;  ///< lens distortion (its size must be the image's); empty: ideal pinhole
  double row_time_s = 0.0;             ///< rolling shutter: row v starts its exposure v · this after row 0 (s); 0: global
  double frame_jitter_s = 0.0;         ///< standard deviation of each exposure start about its nominal time (s)
  double latency_min_s = 0.0;          ///< delivery: the frame is stamped and handed over this long after row 0's
                                       ///< mid-exposure (s) ...
  double latency_jitter_mean_s = 0.0;  ///< ... plus an exponential delay of this mean (USB and driver scheduling, s)
  double flicker_hz = 100.0;           ///< lamp flicker frequency: twice the mains (Hz)
  double flicker_amplitude = 0.0;      ///< the light's brightness swings by ± this fraction at flicker_hz
  double gain_drift_sigma = 0.0;       ///< exposure/gain drift: stationary standard deviation of the relative gain
  double gain_drift_time_s = 30.0;     ///< its correlation time (s)

  /// The typical camera, for images of width_px x height_px.
  static SimCameraRealism typical(int width_px = 640, int height_px = 480);
  /// Mean delivery latency (s): latency_min_s + latency_jitter_mean_s.
  double latency_mean_s() const { return latency_min_s + latency_jitter_mean_s; }

  /// The fields as reports spell them (core/json_write_archive.h).
  template <class Archive>
  void Serialize(Archive* a) {
    a->Visit(PINBALL_NVP(lens));
    a->Visit(PINBALL_NVP(row_time_s));
    a->Visit(PINBALL_NVP(frame_jitter_s));
    a->Visit(PINBALL_NVP(latency_min_s));
    a->Visit(PINBALL_NVP(latency_jitter_mean_s));
    a->Visit(PINBALL_NVP(flicker_hz));
    a->Visit(PINBALL_NVP(flicker_amplitude));
    a->Visit(PINBALL_NVP(gain_drift_sigma));
    a->Visit(PINBALL_NVP(gain_drift_time_s));
  }
};

/// Every setting of the simulated camera.
struct SimCameraConfig {
  int width_px = 640;               ///< image width (px)
  int height_px = 480;              ///< image height (px)
  double fps = 200.0;               ///< frames per second
  double exposure_s = 0.002;        ///< shutter open time (s): motion blur spans the ball's travel over it
  double first_exposure_s = 0.0;    ///< simulated time the first exposure starts (s)
  vision::CameraView view;                  ///< where the camera sits (perspective)
  double lens_height_m = 0.9;       ///< the lens above the playfield, over its centre (m): a hopping ball
                                    ///< (the twin's) looks farther out from the centre and larger
  int supersample = 2;              ///< the static scene is drawn at this multiple of the image scale, then warped
  double floor_gain = 0.6;          ///< playfield drawing brightness: gray = gain · drawing + offset
  double floor_offset = 20.0;       ///< see floor_gain (gray levels)
  int clutter_shapes = 80;          ///< playfield art: random shapes drawn on the table
  double clutter_contrast = 28.0;   ///< their brightness offset, up to ± this (gray levels)
  double ball_gray = 215.0;         ///< ball body brightness (gray levels)
  double flipper_gray = 185.0;      ///< flipper brightness (gray levels); drawn at their current angle
  double flipper_width_m = 0.012;   ///< flipper width as seen from above (m)
  double ball_limb_darkening = 0.35;///< brightness lost at the ball's rim (fraction)
  double highlight_gray = 255.0;    ///< specular highlight peak
  Vec2 highlight_offset{-0.3, 0.3}; ///< highlight centre from the ball centre, in ball radii (board frame)
  double highlight_sigma = 0.22;    ///< highlight size, in ball radii
  int lamps = 14;                   ///< playfield lamps: half small round lamps, half long arrow inserts
  double lamp_delta_gray = 110.0;   ///< brightness a lit lamp adds
  double lamp_toggle_probability = 0.03;  ///< per lamp per frame: chance it switches
  std::vector<SimPlastic> plastics = default_plastics();  ///< occluders (board frame)
  SimGlare glare;                   ///< glare patch (off by default)
  double noise_sigma = 2.0;         ///< sensor noise, standard deviation (gray levels)
  double marker_radius_m = 0.007;   ///< calibration marker: bright disc radius (m), see set_markers()
  double marker_ring_m = 0.012;     ///< ... on a dark disc of this radius (m), so it stands out on any art
  double marker_gray = 245.0;       ///< bright disc brightness (gray levels)
  double marker_ring_gray = 15.0;   ///< dark disc brightness (gray levels)
  std::uint64_t seed = 1;           ///< clutter, lamps, noise
  SimCameraRealism realism;         ///< lens, rolling shutter, timing, flicker, drift (all off by default)

  /// Two plastics on the upper playfield, scaled to a 0.51 x 1.07 m table.
  static std::vector<SimPlastic> default_plastics();
};

/// What the simulator knows about a frame: for tests and benchmarks only,
/// never for the detector (thesis 4.1).
struct FrameTruth {
  bool ball_present = false;        ///< the ball was in play during some of the exposure
  bool ball_whole_exposure = false; ///< ... during all of it
  Vec2 p_board_mid = Vec2::Zero();  ///< ball centre at the true mid-exposure of its row (m)
  cv::Point2d uv_px_mid;            ///< the same in the image the sensor saw (px, distorted by the lens)
  double t_ball_exposure_s = 0.0;   ///< that time: the mid-exposure of the ball's row (s, simulated)
  double t_row0_exposure_s = 0.0;   ///< mid-exposure of row 0 (s, simulated)
  double latency_s = 0.0;           ///< the frame's stamp minus t_row0_exposure_s (s)
  double gain = 1.0;                ///< the frame's brightness gain from drift (flicker varies per row)
  double blur_px = 0.0;             ///< distance the ball's image travelled during the exposure (px)
  double radius_px = 0.0;           ///< ball radius in the image at mid-exposure (px)
  double occluded_fraction = 0.0;   ///< fraction of the ball's image under plastic
  bool glare_on = false;            ///< the glare patch was drawn
  bool in_glare = false;            ///< the glare was on within 3σ + a ball radius of the ball
  int lamps_lit = 0;                ///< lamps lit in this frame
};

/// The simulated camera.
class SimCameraSource final : public vision::FrameSource {
 public:
  /// Renders the static scene. Throws std::invalid_argument naming a bad setting.
  SimCameraSource(const table::Board& board, const SimCameraConfig& config);

  /// Feeds the simulator's state after a step (call every step, time increasing).
  void observe(const sim::GameState& state);
  /// The same from a bare ball position: `in_play` false means no ball in view.
  void observe_ball(double t_s, const Vec2& p_board, bool in_play);

  /// Next frame that has been read out and delivered by the latest observed
  /// time; false when none is due. Frames whose exposure is no longer in the
  /// history are skipped and counted as dropped. The frame's t_s is its
  /// delivery stamp (row 0's mid-exposure plus the latency; without latency,
  /// the mid-exposure), driver_t_s its exposure start.
  bool read(vision::Frame& out) override;

  /// Renders one frame directly: the ball at `path_board` positions spread
  /// evenly over the exposure (empty: no ball), stamped t_mid_s. Advances the
  /// lamps, glare and noise like read(). For tests and benchmarks.
  void render(std::span<const Vec2> path_board, double t_mid_s, vision::Frame& out);

  /// Truth of the last frame delivered by read() or render().
  const FrameTruth& truth() const { return truth_; }

  /// Restarts the frame clock: the next exposure starts at t_s; forgets the history.
  void reset(double t_s);

  /// Switches the glare on or off (and keeps it so unless it toggles by itself).
  void set_glare(bool on) { glare_on_ = on && glare_ready_; }
  /// Calibration markers (stickers on the table) drawn on top of everything
  /// from the next frame on, centred on these board points; empty: none.
  void set_markers(std::span<const Vec2> centres_board);
  /// Sets the flippers' angles (rad, board order) as observe() would, without
  /// a game state: render() draws them, and the next observe_ball() records
  /// them with its time for the frames read() delivers.
  void set_flipper_angles(std::span<const double> theta_rad);
  /// Freezes (false) or resumes (true) lamp toggling.
  void set_lamps_blinking(bool blinking) { lamps_blinking_ = blinking; }

  /// The camera's homography (board -> ideal image: before the lens distorts it).
  const vision::CameraHomography& homography() const { return homography_; }
  /// 255 where a plastic hides the playfield (the detector's occluder mask).
  const cv::Mat& occluder_mask() const { return occluder_mask_; }
  /// The static scene without lamps, glare, ball or noise (8-bit).
  const cv::Mat& static_scene() const { return floor_; }
  /// The settings.
  const SimCameraConfig& config() const { return config_; }
  /// Where a board point appears in the frames (px; through the lens when there is one).
  cv::Point2d image_from_board(const Vec2& p_board) const;

  cv::Size frame_size() const override { return {config_.width_px, config_.height_px}; }
  double fps() const override { return config_.fps; }
  vision::FrameSourceCounters counters() const override { return counters_; }
  std::string describe() const override;

 private:
  struct Sample {
    double t_s = 0.0;
    Vec2 p = Vec2::Zero();
    bool in_play = false;
  };
  struct Patch {
    cv::Rect roi;
    cv::Mat values;  // CV_8U: lamp delta, glare delta, or plastic alpha
  };
  // The ball's positions over the exposure, per image row under a rolling
  // shutter (rows == 0: one path for every row).
  struct BallPaths {
    std::span<const Vec2> common;  // every row's path (global shutter); the ball's centre row's (rolling)
    int first_row = 0;
    int rows = 0;                  // rolling shutter: paths of rows first_row .. first_row + rows - 1
    int total = 1;                 // samples over the whole exposure (fewer present: the ball left play)
    const Vec2* row_paths = nullptr;  // kMaxPath per row
    const int* row_counts = nullptr;
    std::span<const Vec2> row(int v) const;
  };
  static constexpr int kMaxRows = 160;
  // Board point under an integer pixel of the frame (through the lens).
  Vec2 board_at_pixel(int u, int v) const;
  // Ball paths for a frame whose row 0 starts its exposure at start_s (fills row_path_ under a rolling shutter).
  BallPaths ball_paths(double start_s);
  // The (fractional) row that sees the ball's centre and where the ball was then.
  double ball_row(double start_s, Vec2& p_board) const;
  // Draws the row-dependent gain (flicker, drift) of a frame exposed from start_s.
  void apply_gain(double start_s, cv::Mat& image);
  void schedule_next_frame(double nominal_start_s);
  // Draws the flippers at their current angles (render(), or when nothing is observed).
  void draw_flippers(cv::Mat& image) const;
  // Draws the flippers as a frame whose row 0 starts its exposure at start_s
  // saw them: each row at its own time, averaged over the exposure.
  void draw_flippers_exposed(double start_s, cv::Mat& image);
  // Flipper `i`'s angle at time t_s from the observed history (rad).
  double flipper_angle_at(std::size_t i, double t_s) const;
  // The two history samples around t_s (lo == hi at either end) and t_s's fraction between them.
  void bracket(double t_s, std::size_t& lo, std::size_t& hi, double& fraction) const;
  // Paints `gray` over `image` inside the patch, its values being the opacity (255: opaque).
  static void blend(const Patch& p, double gray, cv::Mat& image);

  static constexpr std::size_t kHistory = 2048;
  static constexpr std::size_t kMaxPath = 64;

  void build_lens_map();
  void build_floor();
  void build_lamps();
  void build_plastics();
  void build_glare();
  void build_noise();
  void advance_effects();
  // `exposed`: the flippers as observed over the exposure (read()), else at their current angles (render()).
  void compose(const BallPaths& paths, double start_s, bool exposed, vision::Frame& out);
  void draw_ball(const BallPaths& paths, cv::Mat& image);
  double ball_scale_ = 1.0;  // apparent size of the ball now (1 on the playfield; > 1 while it hops)
  bool sample_at(double t_s, Vec2& p, bool& in_play) const;

  const table::Board& board_;
  SimCameraConfig config_;
  vision::CameraHomography homography_;
  Rng rng_;
  Rng timing_rng_{1};  // frame jitter, latency, flicker phase, gain drift
  std::vector<double> flipper_theta_;  // latest angle per board flipper (sized once)
  cv::Mat floor_;          // CV_8U static scene: drawing, clutter, unlit lamps
  cv::Mat occluder_mask_;  // CV_8U
  std::vector<Patch> lamps_;
  std::vector<std::uint8_t> lamp_on_;
  std::vector<Patch> plastics_;
  std::vector<double> plastic_gray_;
  std::vector<Patch> markers_;          // per marker: dark disc, then bright disc
  std::vector<double> marker_gray_;
  Patch glare_;
  bool glare_ready_ = false;
  bool glare_on_ = false;
  bool lamps_blinking_ = true;
  std::vector<std::uint8_t> noise_pos_;  // |noise| where noise > 0, else 0
  std::vector<std::uint8_t> noise_neg_;  // |noise| where noise < 0, else 0
  std::size_t noise_span_ = 0;           // offsets in [0, noise_span_)
  std::array<Sample, kHistory> history_{};
  std::vector<double> flipper_history_;  // kHistory x flippers: the angles recorded with each sample (rad)
  cv::Mat flipper_sample_;               // CV_8U scratch: one flipper drawn at one instant (coverage 0..255)
  cv::Mat flipper_sum_;                  // CV_16U scratch: its coverage summed per row over the row's exposure
  std::vector<int> flipper_row_count_;   // instants summed per row of that scratch
  std::vector<double> flipper_instant_;  // the flipper's angle at each instant (rad)
  std::size_t history_head_ = 0;         // index of the oldest sample
  std::size_t history_size_ = 0;
  double next_nominal_s_ = 0.0;  // the next frame's nominal exposure start (s)
  double next_start_s_ = 0.0;    // ... with its jitter
  double next_latency_s_ = 0.0;  // ... and its delivery latency
  cv::Mat ideal_map_;            // CV_32FC2: per frame pixel, the ideal-image pixel it shows (lens only)
  double flicker_phase_rad_ = 0.0;
  double drift_ = 0.0;           // relative gain offset (Ornstein–Uhlenbeck)
  std::array<Vec2, kMaxRows * kMaxPath> row_path_{};
  std::array<int, kMaxRows> row_count_{};
  double period_s_ = 0.0;
  std::uint64_t sequence_ = 0;
  std::array<Vec2, kMaxPath> path_{};
  FrameTruth truth_;
  vision::FrameSourceCounters counters_;
};

}  // namespace pinball::simlab
