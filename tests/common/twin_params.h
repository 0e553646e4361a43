#pragma once
// The twin's shipped parameters (config/twin.yaml), loaded once per test binary.

#include "pinball/simlab/twin_params.h"

namespace pinball::testing {

/// config/twin.yaml, loaded on first use.
inline const simlab::TwinParams& shipped_twin_params() {
  static const simlab::TwinParams params = simlab::load_twin_params(PINBALL_SOURCE_DIR "/config/twin.yaml");
  return params;
}

}  // namespace pinball::testing
