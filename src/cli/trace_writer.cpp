#include "trace_writer.h"

#include <cerrno>
#include <charconv>
#include <cstring>
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

TraceWriter::TraceWriter(const std::string& path)
    : staged_(path), path_(path), file_(std::fopen(staged_.writing_path().c_str(), "w")) {
  if (!file_) throw std::runtime_error("cannot write trace file '" + path + "' (" + std::strerror(errno) + ")");
  std::fputs("t,x,y,vx,vy,event\n", file_);
}

TraceWriter::~TraceWriter() {
  if (file_) std::fclose(file_);
}

void TraceWriter::write(const table::Board& board, const sim::GameState& state, const sim::StepEvents& events) {
  char line[256];
  char* p = line;
  char* const end = line + sizeof(line);
  // A lost ball's row is where it was lost: the state after that step holds it in the launcher.
  const bool lost = events.has(sim::StepEvents::kBallLost);
  const Vec2& position_m = lost ? events.lost_position_m : state.ball.position_m;
  const Vec2& velocity_mps = lost ? events.lost_velocity_mps : state.ball.velocity_mps;
  const double values[] = {state.time_s, position_m.x(), position_m.y(), velocity_mps.x(), velocity_mps.y()};
  for (const double v : values) {
    p = std::to_chars(p, end, v).ptr;  // shortest round-trip form
    *p++ = ',';
  }
  const std::size_t bytes = static_cast<std::size_t>(p - line);
  bool written = std::fwrite(line, 1, bytes, file_) == bytes;
  if (events.flags != 0) written = std::fputs(describe_events(board, events).c_str(), file_) >= 0 && written;
  written = std::fputc('\n', file_) != EOF && written;
  if (!written && write_errno_ == 0) write_errno_ = errno != 0 ? errno : EIO;
}

void TraceWriter::finish() {
  if (!file_) return;
  if (std::fflush(file_) != 0 && write_errno_ == 0) write_errno_ = errno;
  if (std::ferror(file_) != 0 && write_errno_ == 0) write_errno_ = EIO;
  const bool close_failed = std::fclose(file_) != 0;
  if (close_failed && write_errno_ == 0) write_errno_ = errno;
  file_ = nullptr;
  if (write_errno_ != 0) {
    throw std::runtime_error("error writing trace file '" + path_ + "' (" + std::strerror(write_errno_) + ")");
  }
}

}  // namespace pinball::cli
