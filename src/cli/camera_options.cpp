#include "camera_options.h"

namespace pinball::cli {

void add_camera_model_options(CLI::App& cmd, track::CameraModelConfig& camera) {
  cmd.add_option("--fps", camera.fps, "camera model: frames per second")->check(CLI::Range(1.0, 10000.0));
  cmd.add_option("--m-per-px", camera.m_per_px, "camera model: metres per pixel on the table")
      ->check(CLI::Range(1e-5, 0.1));
  cmd.add_option("--noise-px", camera.noise_px, "camera model: centroid noise, standard deviation (px)")
      ->check(CLI::Range(0.0, 100.0));
  cmd.add_option("--latency", camera.latency_s, "camera model: exposure to delivery (s)")->check(CLI::Range(0.0, 1.0));
  cmd.add_option("--drop", camera.drop_probability, "camera model: probability a frame is lost")
      ->check(CLI::Range(0.0, 0.99));
}

}  // namespace pinball::cli
