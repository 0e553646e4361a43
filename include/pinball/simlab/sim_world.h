#pragma once
// The world of the embedded simulation, run by the daemon's simulator thread:
// the table (any sim::World), the camera that films it (SimCameraSource), and
// the far end of the CAN link (the reference VirtualDriverBoard, whose coils
// move the simulated flippers after the solenoid's delay). The daemon sees it
// only through frames and CAN frames, exactly as it sees the lab machine.

#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

#include "pinball/firmware/can_transport.h"
#include "pinball/firmware/flipper_actuation.h"
#include "pinball/firmware/virtual_driver_board.h"
#include "pinball/table/board.h"
#include "pinball/sim/game_state.h"
#include "pinball/sim/world.h"
#include "pinball/track/observation.h"
#include "pinball/simlab/sim_camera_source.h"

namespace pinball::simlab {

/// Settings of the simulated world.
struct SimWorldOptions {
  int balls = 10;                     ///< balls to play
  std::uint64_t seed = 1;             ///< ball i launches with noise from ball_seed(seed, i)
  double actuation_delay_s = firmware::kDefaultActuationDelay_s;   ///< coil on -> flipper moves (s)
  double max_ball_time_s = 60.0;      ///< a ball alive this long is cut (a cycle)
  double launcher_pull = -1.0;        ///< pull fraction; negative: the board's
  int background_frames = 30;         ///< ball-free frames rendered first for the detector's background
  int board_id = 0;                   ///< the simulated driver board's CAN id (can.board_id), 0..15
};

/// One played ball.
struct SimBallResult {
  double score = 0.0;       ///< points
  double duration_s = 0.0;  ///< simulated seconds from launch to loss or cut
  int flips = 0;            ///< flipper activations (button presses seen by the table)
  bool cut = false;         ///< alive at the time limit
};

/// Something the table did that the daemon reports on PINBALL_GAME.
struct GameEvent {
  enum Kind : std::int8_t { kLaunch = 1, kBallLost = 2, kScore = 3, kBallCut = 4 };
  Kind kind = kLaunch;       ///< what
  int ball = 0;              ///< ball number from 0
  double t_s = 0.0;          ///< simulated time (s)
  double points = 0.0;       ///< points of the event (score) or of the whole ball (lost, cut)
  double ball_time_s = 0.0;  ///< since the launch (s)
};

/// The table, its camera and its driver board.
class SimWorld {
 public:
  /// Plays a fork of `world` (whose board must outlive this) and borrows the
  /// board's end of the CAN link. Throws std::invalid_argument for a board
  /// without two flippers or bad options.
  SimWorld(const sim::World& world, firmware::CanTransport& board_link, const simlab::SimCameraConfig& camera,
           const SimWorldOptions& options);

  /// Ball-free frames for the detector's background (lamps still, glare off).
  void render_background(vision::Frame& frame, double t_s);

  /// Steps the world until the camera delivers its next frame; fills `frame`
  /// and the flipper contact sensors of its exposure. Returns false once every
  /// ball has been played. `on_event` sees launches, scores and losses.
  template <class OnEvent>
  bool next_frame(vision::Frame& frame, track::ContactSensors& contacts, OnEvent&& on_event);

  /// Runs the table without a ball for `duration_s`: the board answers the
  /// bus, the flippers follow their coils (start-up handshake, shutdown).
  void idle(double duration_s);
  /// True when every coil of the driver board is off.
  bool all_coils_off() const;

  /// The driver board (its coils, counters, watchdog).
  const firmware::VirtualDriverBoard& driver_board() const { return driver_board_; }
  /// Board flipper index of tracker flipper f.
  int board_flipper(int f) const { return board_flipper_[static_cast<std::size_t>(f)]; }
  /// Balls finished so far, in order: a copy, safe to take from any thread
  /// while the simulator thread plays (the daemon's statistics do).
  std::vector<SimBallResult> results() const {
    const std::size_t n = finished_.load(std::memory_order_acquire);
    return {results_.begin(), results_.begin() + static_cast<std::ptrdiff_t>(n)};
  }
  /// Simulated time now (s).
  double time_s() const { return state_.time_s; }
  /// The camera.
  simlab::SimCameraSource& camera() { return camera_; }
  /// Steady clock at which each driver's coil last switched on (the latency table's last stage).
  double coil_on_wall_s(int driver) const { return coil_on_wall_s_[static_cast<std::size_t>(driver)]; }
  /// Coil-on events since construction (to find new ones).
  std::uint64_t coil_on_count() const { return coil_on_count_; }

 private:
  class CoilWatch final : public firmware::CoilListener {
   public:
    explicit CoilWatch(SimWorld& world) : world_(world) {}
    void on_coil_change(int driver, const firmware::CoilOutput& output) override;

   private:
    SimWorld& world_;
  };
  // One step of the table; reports through on_event. False when all balls are done.
  bool step(GameEvent* events, int& event_count);
  // The board reads the bus and the flippers follow their coils (start of every step).
  void drive_flippers();
  void start_ball();

  std::unique_ptr<sim::World> world_;
  const table::Board& board_;  // the world's
  firmware::CanTransport& link_;
  SimWorldOptions options_;
  sim::GameState state_;
  simlab::SimCameraSource camera_;
  firmware::VirtualDriverBoard driver_board_;
  std::vector<std::unique_ptr<firmware::FlipperActuation>> actuation_;
  CoilWatch coil_watch_{*this};
  std::array<int, 2> board_flipper_{};
  std::array<double, firmware::kMaxDrivers> coil_on_wall_s_{};
  std::uint64_t coil_on_count_ = 0;
  std::vector<SimBallResult> results_;   // one slot per ball, sized at construction
  std::atomic<std::size_t> finished_{0};  // slots written; released after each write
  int ball_ = 0;
  bool ball_active_ = false;
  double ball_t0_s_ = 0.0;
  double ball_score0_ = 0.0;
  std::uint64_t ball_flips0_ = 0;
  double pull_ = 1.0;
};

template <class OnEvent>
bool SimWorld::next_frame(vision::Frame& frame, track::ContactSensors& contacts, OnEvent&& on_event) {
  std::array<GameEvent, 4> events{};
  while (true) {
    int n = 0;
    const bool more = step(events.data(), n);
    for (int i = 0; i < n; ++i) on_event(static_cast<const GameEvent&>(events[static_cast<std::size_t>(i)]));
    if (!more) return false;
    if (camera_.read(frame)) {
      contacts.left = state_.flippers[static_cast<std::size_t>(board_flipper_[0])].ball_contact;
      contacts.right = state_.flippers[static_cast<std::size_t>(board_flipper_[1])].ball_contact;
      return true;
    }
  }
}

}  // namespace pinball::simlab
