#pragma once
// Latency percentiles without storing samples: a fixed log-spaced histogram
// from 0.1 µs to 10 s (2 % wide bins), so recording is a few instructions,
// allocates nothing and may run on a real-time thread while another thread
// reads a snapshot. p50 and p99 are exact to one bin (±1 %); max is exact.

#include <array>
#include <atomic>
#include <cstdint>
#include <string>

namespace pinball::daemon {

/// Percentiles of one latency stage.
struct LatencySummary {
  std::uint64_t count = 0;  ///< samples
  double p50_us = 0.0;      ///< median (µs)
  double p99_us = 0.0;      ///< 99th percentile (µs)
  double max_us = 0.0;      ///< largest sample (µs)
};

/// One writer thread, any number of reader threads.
class LatencyHistogram {
 public:
  /// Bins between kMin and kMax.
  static constexpr int kBins = 1024;
  static constexpr double kMinUs = 0.1;   ///< smaller samples land in the first bin (µs)
  static constexpr double kMaxUs = 1e7;   ///< larger samples land in the last bin (µs)

  /// Records one sample (µs). Negative or NaN samples are ignored.
  void record(double latency_us);
  /// Percentiles so far (from any thread).
  LatencySummary summary() const;
  /// Clears everything (only while nobody records).
  void reset();

 private:
  std::array<std::atomic<std::uint32_t>, kBins> bins_{};
  std::atomic<std::uint64_t> count_{0};
  std::atomic<double> max_us_{0.0};
};

/// Upper edge of bin i (µs): the value summary() reports for it.
double latency_bin_upper_us(int bin);

}  // namespace pinball::daemon
