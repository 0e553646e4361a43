#include "trace_writer.h"

#include <charconv>
#include <stdexcept>

namespace pinball::cli {
namespace {

void append_event(std::string& out, const char* kind, const std::string& name) {
  if (!out.empty()) out += '|';
  out += kind;
  if (!name.empty()) {
    out += ':';
    out += name;
  }
}

}  // namespace

std::string describe_events(const table::Board& board, const sim::StepEvents& e) {
  using F = sim::StepEvents;
  std::string out;
  if (e.has(F::kLaunch)) append_event(out, "launch", "");
  if (e.has(F::kFlipperPush)) append_event(out, "push", board.flippers[e.flipper].name);
  if (e.has(F::kFlipperStall)) append_event(out, "stall", board.flippers[e.flipper].name);
  if (e.has(F::kHitFlipper)) append_event(out, "flipper", board.flippers[e.flipper].name);
  if (e.has(F::kHitObstacle)) append_event(out, "hit", board.obstacles[e.obstacle].name);
  if (e.has(F::kBankComplete)) append_event(out, "bank", board.banks[board.obstacles[e.obstacle].bank].name);
  if (e.has(F::kSensor)) append_event(out, "sensor", board.sensors[e.sensor].name);
  if (e.has(F::kLeftTable)) append_event(out, "left_table", "");
  if (e.has(F::kBallLost)) append_event(out, "lost", "");
  return out;
}

TraceWriter::TraceWriter(const std::string& path) : path_(path), file_(std::fopen(path.c_str(), "w")) {
  if (!file_) throw std::runtime_error("cannot write trace file '" + path + "'");
  std::fputs("t,x,y,vx,vy,event\n", file_);
}

TraceWriter::~TraceWriter() {
  if (file_) std::fclose(file_);
}

void TraceWriter::write(const table::Board& board, const sim::GameState& state, const sim::StepEvents& events) {
  char line[256];
  char* p = line;
  char* const end = line + sizeof(line);
  const double values[] = {state.time_s, state.ball.position_m.x(), state.ball.position_m.y(),
                           state.ball.velocity_mps.x(), state.ball.velocity_mps.y()};
  for (const double v : values) {
    p = std::to_chars(p, end, v).ptr;  // shortest round-trip form
    *p++ = ',';
  }
  std::fwrite(line, 1, static_cast<std::size_t>(p - line), file_);
  if (events.flags != 0) std::fputs(describe_events(board, events).c_str(), file_);
  std::fputc('\n', file_);
}

void TraceWriter::close() {
  if (!file_) return;
  const bool failed = std::ferror(file_) != 0;
  const bool close_failed = std::fclose(file_) != 0;
  file_ = nullptr;
  if (failed || close_failed) throw std::runtime_error("error writing trace file '" + path_ + "'");
}

}  // namespace pinball::cli
