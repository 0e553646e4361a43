#include "camera_options.h"

#include "pinball/core/number_option.h"

namespace pinball::cli {

void add_camera_model_options(CLI::App& cmd, track::CameraModelConfig& camera) {
  cmd.add_option("--fps", camera.fps, "camera model: frames per second")->check(finite_range(1.0, 10000.0));
  cmd.add_option("--m-per-px", camera.m_per_px, "camera model: metres per pixel on the table")
      ->check(finite_range(1e-5, 0.1));
  cmd.add_option("--noise-px", camera.noise_px, "camera model: centroid noise, standard deviation (px)")
      ->check(finite_range(0.0, 100.0));
  cmd.add_option("--latency", camera.latency_s, "camera model: exposure to delivery (s)")
      ->check(finite_range(0.0, 1.0));
  cmd.add_option("--drop", camera.drop_probability, "camera model: probability a frame is lost")
      ->check(finite_range(0.0, 0.99));
}

}  // namespace pinball::cli
