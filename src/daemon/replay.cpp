#include "pinball/daemon/replay.h"

#include <lcm/lcm-cpp.hpp>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <system_error>
#include <stdexcept>
#include <vector>

#include "pinball/bus/channels.h"
#include "pinball/bus/lcm_log_format.h"
#include "pinball/bus/message_convert.h"
#include "pinball/bus/recorded_play.h"
#include "pinball/control/actuator_controller.h"
#include "pinball/control/controller_file.h"
#include "pinball/core/utime.h"
#include "pinball/daemon/pipeline.h"
#include "pinball/firmware/stream_transport.h"
#include "pinball/track/flipper_geometry.h"
#include "pinball/learn/planning_controller.h"

namespace pinball::daemon {
namespace {

// A decision and the frame it was made on: the camera's frame number when the log maps projections to
// frames, else the projection's number (one per observation, live and replayed alike while the log
// lost none).
struct Decision {
  int flipper;
  bool energize;
  int cause;
  std::int64_t frame;
  bool operator==(const Decision&) const = default;
};

// The frame behind live projection `seq`: the log's own PINBALL_PROJECTION, or, for one the log lost,
// counted on from the nearest earlier one while the frames ran without a gap up to the next. -1: unknown.
std::int64_t frame_of_projection(const std::map<std::int64_t, std::int64_t>& frames, std::int64_t seq) {
  const auto after = frames.lower_bound(seq);
  if (after != frames.end() && after->first == seq) return after->second;
  if (after == frames.begin() || after == frames.end()) return -1;
  const auto before = std::prev(after);
  const bool no_gap = after->second - before->second == after->first - before->first;
  return no_gap ? before->second + (seq - before->first) : -1;
}

// Commands that follow from the observations alone; the others depend on
// when a thread woke up (stall), on the CAN link, or on the end of the run.
bool decided_by_observations(int cause) {
  return cause == static_cast<int>(CommandCause::kProjection) || cause == static_cast<int>(CommandCause::kLaunch) ||
         cause == static_cast<int>(CommandCause::kBallLost);
}

}  // namespace

ReplayReport replay_log(const std::string& log_path, DaemonConfig config,
                        const std::function<void(const ReplayProgress&)>& progress, std::uint64_t progress_every) {
  find_data_files(config);  // the defaults name the shipped data from any folder, as pinballd's do
  try {
    bus::require_lcm_log(log_path);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(std::string(e.what()) + "; nothing replayed");
  }
  lcm::LogFile log(log_path, "r");
  if (!log.good()) throw std::runtime_error(log_path + ": cannot read the LCM log");
  // What the daemon starts with, loaded the way it loads it.
  const DaemonInputs inputs = load_daemon_inputs(config);
  const table::Board& board = inputs.board;
  const std::unique_ptr<control::FlipperController> controller = learn::make_controller(inputs.spec, board);
  const TrackingSetup& setup = inputs.setup;
  track::Tracker tracker(setup.geometry, setup.tracker);
  CameraStage camera(nullptr, tracker, lost_after_s_for(config));
  // The stage drives a DriverBus with no board behind it: its commands go
  // nowhere, the decisions are what counts.
  auto [host, far] = firmware::StreamTransport::make_pair();
  firmware::DriverBusOptions bo;
  bo.driver_count = static_cast<int>(board.flippers.size());
  firmware::DriverBus bus(*host, bo);
  ControllerStage stage(*controller, bus, controller_stage_options_for(config, board));

  ReplayReport r;
  bus::RunClock observation_clock;
  std::vector<Decision> recorded, replayed;
  std::vector<std::int64_t> replayed_frames;            // the frame behind each replayed decision
  std::map<std::int64_t, std::int64_t> live_frames;      // live projection number -> its frame
  std::uint64_t command_messages = 0;
  ProjectionRecord record;
  ControllerStage::Commands cmds;
  ReplayProgress done;
  std::error_code size_error;
  done.bytes_total = std::filesystem::file_size(log_path, size_error);
  auto report_progress = [&] {
    if (!progress) return;
    const long at = std::ftell(log.getFilePtr());
    done.bytes_read = at < 0 ? done.bytes_read : static_cast<std::uint64_t>(at);
    done.observations = r.observations;
    progress(done);
  };
  for (const lcm::LogEvent* e = log.readNextEvent(); e != nullptr; e = log.readNextEvent()) {
    ++r.events;
    if (e->channel == bus::kProjectionChannel) {
      pinball_lcm::lcmt_pinball_projection m{};
      if (m.decode(e->data, 0, static_cast<int>(e->datalen)) >= 0 && bus::valid_projection(m)) {
        live_frames[m.seq] = m.observation_seq;
      }
    } else if (e->channel == bus::kObservationChannel) {
      pinball_lcm::lcmt_pinball_observation m{};
      bool found = false;
      track::Observation o;
      track::ContactSensors c;
      const bus::ObservationLayout layout = bus::decode_observation(e->data, static_cast<std::size_t>(e->datalen), m);
      if (layout == bus::ObservationLayout::kMalformed || !bus::from_lcm_observation(m, found, o, c)) {
        ++r.malformed;
        continue;
      }
      bus::check_one_run(log_path, observation_clock, o.t_s, m.seq);
      ++r.observations;
      if (layout == bus::ObservationLayout::kBeforeDelivery) ++r.observations_without_latency;
      camera.track(found, o, from_utime(m.delivered_utime), c, 0.0, record);
      const int n = stage.on_record(record, record.t_s, 0.0, cmds);
      for (int i = 0; i < n; ++i) {
        const CommandRecord& k = cmds[static_cast<std::size_t>(i)];
        if (decided_by_observations(static_cast<int>(k.cause))) {
          replayed.push_back({k.flipper, k.energize, static_cast<int>(k.cause), k.projection_seq});
          replayed_frames.push_back(m.seq);
        }
      }
      bus.poll_once(record.t_s);  // keeps its queue empty
      // Nobody reads the far end: drained here, or each send backs off on a full socket (4 s of sleeps a log).
      firmware::CanFrame sent;
      while (far->receive(sent, 0) == firmware::RxStatus::kFrame) {
      }
      if (r.observations % progress_every == 0) report_progress();
    } else if (e->channel == bus::kFlipperCommandChannel) {
      ++command_messages;
      pinball_lcm::lcmt_pinball_flipper_command m{};
      if (m.decode(e->data, 0, static_cast<int>(e->datalen)) < 0 || !bus::valid_flipper_command(m)) {
        ++r.malformed;
        continue;
      }
      if (decided_by_observations(m.cause)) {
        recorded.push_back({m.flipper, m.energize != 0, m.cause, m.projection_seq});
      } else {
        ++r.skipped_timing;
      }
    }
  }
  report_progress();
  // Nothing to compare is no verdict (it had been "NOT reproduced", exit 3).
  if (r.observations == 0) {
    throw std::runtime_error(
        log_path + ": no PINBALL_OBSERVATION message decoded among its " + std::to_string(r.events) + " events" +
        (r.malformed > 0 ? " (" + std::to_string(r.malformed) +
                               " malformed: another message type on the daemon's channels, or a log of another version)"
                         : " (a log of another program, or of a run that played no ball?)") +
        "; nothing replayed");
  }
  if (command_messages == 0) {
    throw std::runtime_error(log_path +
                             ": no PINBALL_FLIPPER_CMD message: nothing to compare the replay with (recorded without "
                             "that channel?)");
  }
  if (!live_frames.empty()) {  // compared by camera frame: a lost observation shifts nothing after it
    for (Decision& d : recorded) d.frame = d.frame < 0 ? -1 : frame_of_projection(live_frames, d.frame);
    for (std::size_t i = 0; i < replayed.size(); ++i) replayed[i].frame = replayed_frames[i];
  }
  r.recorded_commands = recorded.size();
  r.replayed_commands = replayed.size();
  const std::size_t n = std::min(recorded.size(), replayed.size());
  while (r.matched < n && recorded[r.matched] == replayed[r.matched]) ++r.matched;
  if (r.matched < std::max(recorded.size(), replayed.size())) {
    r.first_mismatch = static_cast<std::int64_t>(r.matched);
    auto show = [](const std::vector<Decision>& v, std::size_t k) {
      if (k >= v.size()) return std::string("none");
      return std::string(v[k].flipper < 0 ? "all" : v[k].flipper == 0 ? "left" : "right") +
             (v[k].energize ? " fire" : " release") + " (cause " + std::to_string(v[k].cause) + ", frame " +
             std::to_string(v[k].frame) + ")";
    };
    r.mismatch = "recorded " + show(recorded, r.matched) + ", replayed " + show(replayed, r.matched);
  }
  r.reproduced = r.first_mismatch < 0 && r.observations > 0;
  return r;
}

}  // namespace pinball::daemon
