#include "pinball/view/lcm_listener.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <stdexcept>

#include "common/temp_path.h"
#include "view/view_log.h"

namespace pinball::view {
namespace {

// liblcm's own file:// provider stands in for the network: the listener
// subscribes and receives exactly as it does on udpm://.
TEST(LcmListener, ReceivesEveryDaemonChannelThroughLiblcm) {
  const std::string path = pinball::testing::temp_path("lcm_listener", "game.lcmlog");
  const int events = pinball::testing::write_view_log(path);
  ViewState state;
  LcmListener listener("file://" + path + "?speed=0", state);
  int polls = 0;
  while (listener.poll(100) >= 0 && ++polls < 1000) {
  }
  EXPECT_EQ(listener.received(), static_cast<std::uint64_t>(events));
  EXPECT_EQ(state.observations(), static_cast<std::uint64_t>(pinball::testing::kViewLogFrames - 1));
  EXPECT_EQ(state.malformed(), 0u);
  ASSERT_TRUE(state.ball().has_value());
  EXPECT_EQ(state.ball()->seq, pinball::testing::kViewLogFrames - 1);
  EXPECT_EQ(state.commands().size(), 2u);
  // Stamped with liblcm's receive time, which the file provider takes from the log.
  EXPECT_NEAR(state.now_s(), 1.0, 1e-6);  // the daemon's clock: the messages' utime
}

// A log played at full speed arrives in one burst: the poll stops where the view looks.
TEST(LcmListener, APollStopsAtTheTimeAskedForEvenInABurst) {
  const std::string path = pinball::testing::temp_path("lcm_listener", "burst.lcmlog");
  pinball::testing::write_view_log(path);
  ViewState state;
  LcmListener listener("file://" + path + "?speed=0", state);
  int polls = 0;
  while (state.now_s() < 0.5 && listener.poll(100, 0.5) >= 0 && ++polls < 1000) {
  }
  EXPECT_GE(state.now_s(), 0.5);
  EXPECT_LT(state.now_s(), 0.6) << "it had played the whole log in one poll";
}

// liblcm plays a damaged log by the lengths it reads (a length of 2^31 crashed it): refused first.
TEST(LcmListener, ADamagedLogIsRefusedBeforeLiblcmReadsIt) {
  const std::string path = pinball::testing::temp_path("lcm_listener", "damaged.lcmlog");
  pinball::testing::write_view_log(path);
  std::filesystem::resize_file(path, std::filesystem::file_size(path) - 7);
  ViewState state;
  try {
    LcmListener listener("file://" + path + "?speed=0", state);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path + ": damaged LCM log"), std::string::npos) << e.what();
  }
  std::filesystem::remove(path);
}

TEST(LcmListener, ABadUrlIsNamed) {
  ViewState state;
  try {
    LcmListener listener("nosuchprovider://x", state);
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("nosuchprovider://x"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace pinball::view
