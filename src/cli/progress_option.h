#pragma once
// --progress: percent and ETA of a long run on stderr even when stderr is not
// a terminal (a terminal gets them anyway; pinball/core/progress.h).

#include <CLI/CLI.hpp>

namespace pinball::cli {

/// Adds --progress, writing into `progress`.
inline void add_progress_flag(CLI::App& cmd, bool& progress) {
  cmd.add_flag("--progress", progress,
               "show percent done and ETA on stderr even when it is not a terminal (a terminal always gets them)");
}

}  // namespace pinball::cli
