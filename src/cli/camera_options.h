#pragma once
// The camera-model flags shared by every command that plays through a
// simulated camera (`pinball sim`, `pinball learn`).

#include <CLI/CLI.hpp>

#include "pinball/track/camera_model.h"

namespace pinball::cli {

/// Adds --fps, --m-per-px, --noise-px, --latency and --drop, writing into `camera`.
void add_camera_model_options(CLI::App& cmd, track::CameraModelConfig& camera);

}  // namespace pinball::cli
