#include "pinball/simlab/delay_line.h"

namespace pinball::simlab {

DelayLine::DelayLine(std::size_t flippers, double delay_s) : last_(flippers, false) {
  actuation_.reserve(flippers);
  for (std::size_t i = 0; i < flippers; ++i) actuation_.emplace_back(static_cast<int>(i), delay_s);
}

void DelayLine::apply(sim::GameState& s) {
  for (std::size_t i = 0; i < actuation_.size(); ++i) {
    const bool want = s.flippers[i].energized;
    if (want != last_[i]) {
      const firmware::CoilOutput coil{want ? firmware::CoilState::kPulse : firmware::CoilState::kOff,
                                      want ? 1.0 : 0.0, s.time_s};
      actuation_[i].on_coil_change(static_cast<int>(i), coil);
      last_[i] = want;
    }
    s.flippers[i].energized = actuation_[i].energized(s.time_s);
  }
}

}  // namespace pinball::simlab
