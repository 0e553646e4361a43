#include "pinball/simlab/sim_world.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "common/thesis_board.h"
#include "pinball/firmware/stream_transport.h"
#include "pinball/simlab/world_factory.h"

namespace pinball::simlab {
namespace {

using pinball::testing::thesis_board;

// pinballd's table launches with the controller's pull: one too weak to
// leave the plunger used to be relaunched at its apex for ever, in silence.
TEST(SimWorld, APullTooWeakToLeaveThePlungerIsRefused) {
  const OwnedWorld w = make_world(WorldSpec{}, thesis_board());
  auto [host, board_end] = firmware::StreamTransport::make_pair();
  SimWorldOptions o;
  o.launcher_pull = 0.01;
  EXPECT_THROW(SimWorld(*w, *board_end, SimCameraConfig{}, o), std::invalid_argument);
  o.launcher_pull = 0.9;
  EXPECT_NO_THROW(SimWorld(*w, *board_end, SimCameraConfig{}, o));
}

}  // namespace
}  // namespace pinball::simlab
