#include "latency_bench.h"

#include <gtest/gtest.h>

namespace pinball::bench {
namespace {

TEST(LatencyBench, MeasuresFireToCoilAndTheCodecWithBaselines) {
  LatencyBenchOptions o;
  o.samples = 100;
  o.codec_frames = 20'000;
  o.baseline_samples = 100;
  int lines = 0;
  const LatencyReport r = run_latency_bench(o, [&](const std::string&) { ++lines; });
  EXPECT_EQ(r.samples, 100);
  EXPECT_GT(r.fire_to_coil_p50_us, 0.0);
  EXPECT_LE(r.fire_to_coil_p50_us, r.fire_to_coil_p99_us);
  EXPECT_LE(r.fire_to_coil_p99_us, r.fire_to_coil_max_us);
  EXPECT_LT(r.fire_to_coil_p50_us, 20'000.0);  // well under a flipper stroke
  EXPECT_GT(r.raw_p50_us, 0.0);
  EXPECT_GT(r.encode_decode_ns, 0.0);
  EXPECT_GT(r.copy_baseline_ns, 0.0);
  EXPECT_EQ(r.coil_violations, 0u);
  EXPECT_EQ(lines, 3);
  const nlohmann::json j = to_json(r);
  EXPECT_EQ(j["benchmark"], "latency");
  EXPECT_TRUE(j.contains("fire_to_coil_p99_us"));
  EXPECT_THROW(run_latency_bench(LatencyBenchOptions{0, 1, 1}, {}), std::invalid_argument);
}

}  // namespace
}  // namespace pinball::bench
