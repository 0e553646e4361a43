#pragma once
// A bench's progress callback that knows how many stages the bench has: the
// k-th line reported becomes "label: k/N stages (P %), elapsed, ETA; line"
// (pinball/core/progress.h). For benches whose stages take similar time.

#include <chrono>
#include <functional>
#include <memory>
#include <string>

#include "pinball/core/progress.h"

namespace pinball::bench {

/// Wraps `progress` (empty stays empty): each call is one of `stages` done stages of `label` in `unit`.
inline std::function<void(const std::string&)> staged_progress(const std::function<void(const std::string&)>& progress,
                                                                std::string label, int stages,
                                                                std::string unit = "stages") {
  if (!progress) return {};
  const auto start = std::chrono::steady_clock::now();
  auto done = std::make_shared<int>(0);
  return [=](const std::string& line) {
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    progress(format_progress(label, ++*done, stages, unit, elapsed, line));
  };
}

}  // namespace pinball::bench
