#include "play_window.h"

#include <chrono>
#include <stdexcept>
#include <thread>

#include <opencv2/highgui.hpp>
#include <opencv2/imgproc.hpp>

#include "keyboard_state.h"

namespace pinball::cli {
namespace {

using Clock = std::chrono::steady_clock;

// Without the X server's key map a press holds its flipper this long (s),
// refreshed by the keyboard's auto-repeat while the key is held.
constexpr double kTapHold_s = 0.25;

// waitKeyEx codes (GTK: X keysyms for the arrows and Return).
constexpr int kEsc = 27;
constexpr int kReturn = 13;
constexpr int kArrowLeft = 65361;
constexpr int kArrowRight = 65363;
constexpr int kArrowDown = 65364;

// The play key a waitKeyEx code stands for; false for any other key.
bool key_of(int code, simlab::Key* key) {
  switch (code) {
    case 'z': case 'Z': case kArrowLeft:
      *key = simlab::Key::kLeftFlipper;
      return true;
    case 'm': case 'M': case '/': case kArrowRight:
      *key = simlab::Key::kRightFlipper;
      return true;
    case ' ': case kReturn: case '\n': case kArrowDown: case 65293: case 65421:
      *key = simlab::Key::kLaunch;
      return true;
    default:
      return false;
  }
}

double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

}  // namespace

PlayWindowReport play_in_window(simlab::PlaySession& session, const table::Board& board,
                                const PlayWindowOptions& o) {
  using simlab::Key;
  PlayWindowReport report;
  KeyboardState keyboard;
  report.keyboard = keyboard.available() ? "x11" : "waitkey";
  cv::namedWindow(o.title, cv::WINDOW_AUTOSIZE);
  const std::string help = "Z/LShift/Left: left  M,/,RShift/Right: right  Space/Enter: launch  Esc/q: quit";
  double release_at_s[3] = {-1.0, -1.0, -1.0};  // waitKey fallback: when each pressed key lets go
  std::size_t next_event = 0;
  double draw_s = 0.0;
  // The first frame maps the window, which takes a while: show it before the game's clock starts.
  cv::imshow(o.title, sim::render_board(board, &session.state(), o.render));
  cv::waitKey(1);
  const Clock::time_point start = Clock::now();
  while (true) {
    const double wall_s = seconds_since(start);
    const double t_s = session.session_time_for_wall(wall_s);
    if (o.script != nullptr) {
      next_event = simlab::play_script_until(session, *o.script, next_event, t_s);
    } else {
      session.advance_to(t_s);
    }

    const Clock::time_point draw_start = Clock::now();
    cv::Mat frame = sim::render_board(board, &session.state(), o.render);
    cv::putText(frame, help, {8, frame.rows - 8}, cv::FONT_HERSHEY_PLAIN, 0.8, {200, 200, 200}, 1, cv::LINE_AA);
    cv::imshow(o.title, frame);
    const int code = cv::waitKeyEx(1);
    draw_s += seconds_since(draw_start);
    ++report.frames;
    if (o.after_frame) o.after_frame();

    // Esc, q, or the window closed by its title bar's button.
    if (code == kEsc || code == 'q' || code == 'Q' || cv::getWindowProperty(o.title, cv::WND_PROP_VISIBLE) < 1.0) {
      report.quit_by_player = true;
      break;
    }
    if (o.script == nullptr) {
      const double now_s = seconds_since(start);
      Key k{};
      const bool pressed = code >= 0 && key_of(code, &k);
      if (keyboard.available()) {
        keyboard.poll();
        for (const Key each : {Key::kLeftFlipper, Key::kRightFlipper, Key::kLaunch}) {
          session.key(each, keyboard.down(each));
        }
        // A tap shorter than a frame is gone from the key map but not from the window's presses:
        // it flips for one frame.
        if (pressed) session.press(k);
      } else {
        if (pressed) {
          session.press(k);
          release_at_s[static_cast<int>(k)] = now_s + kTapHold_s;
        }
        for (const Key held : {Key::kLeftFlipper, Key::kRightFlipper, Key::kLaunch}) {
          double& at = release_at_s[static_cast<int>(held)];
          if (at >= 0.0 && now_s >= at) {
            session.release(held);
            at = -1.0;
          }
        }
      }
    }
    if (o.balls > 0 && static_cast<int>(session.balls().size()) >= o.balls) break;
    if (o.script != nullptr && next_event == o.script->size() && !session.ball_in_play()) break;
    // Pace the frames; the physics catches up with the wall clock on the next frame.
    std::this_thread::sleep_until(start + std::chrono::duration_cast<Clock::duration>(
                                              std::chrono::duration<double>(report.frames / o.fps)));
  }
  cv::destroyWindow(o.title);
  cv::waitKey(1);  // lets the window close
  report.wall_s = seconds_since(start);
  report.draw_fps = report.wall_s > 0.0 ? static_cast<double>(report.frames) / report.wall_s : 0.0;
  report.mean_draw_ms = report.frames > 0 ? 1e3 * draw_s / static_cast<double>(report.frames) : 0.0;
  return report;
}

}  // namespace pinball::cli
