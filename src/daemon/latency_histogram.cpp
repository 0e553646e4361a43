#include "pinball/daemon/latency_histogram.h"

#include "pinball/core/statistics.h"

#include <algorithm>
#include <cmath>

namespace pinball::daemon {
namespace {

const double kLogMin = std::log(LatencyHistogram::kMinUs);
const double kLogSpan = std::log(LatencyHistogram::kMaxUs) - kLogMin;

int bin_of(double us) {
  if (us <= LatencyHistogram::kMinUs) return 0;
  const double x = (std::log(us) - kLogMin) / kLogSpan * LatencyHistogram::kBins;
  return std::clamp(static_cast<int>(x), 0, LatencyHistogram::kBins - 1);
}

}  // namespace

double latency_bin_upper_us(int bin) {
  return std::exp(kLogMin + kLogSpan * (bin + 1) / LatencyHistogram::kBins);
}

void LatencyHistogram::record(double latency_us) {
  if (!(latency_us >= 0.0)) return;
  bins_[static_cast<std::size_t>(bin_of(latency_us))].fetch_add(1, std::memory_order_relaxed);
  count_.fetch_add(1, std::memory_order_relaxed);
  // Single writer: a plain compare is enough.
  if (latency_us > max_us_.load(std::memory_order_relaxed)) max_us_.store(latency_us, std::memory_order_relaxed);
}

LatencySummary LatencyHistogram::summary() const {
  LatencySummary s;
  std::array<std::uint32_t, kBins> copy{};
  std::uint64_t total = 0;
  for (int i = 0; i < kBins; ++i) {
    copy[static_cast<std::size_t>(i)] = bins_[static_cast<std::size_t>(i)].load(std::memory_order_relaxed);
    total += copy[static_cast<std::size_t>(i)];
  }
  s.count = total;
  s.max_us = max_us_.load(std::memory_order_relaxed);
  if (total == 0) return s;
  // The project's quantile rule (core/statistics.h): the smallest bin whose
  // cumulative count reaches the nearest rank.
  auto quantile = [&](double q) {
    const std::uint64_t rank = quantile_rank(q, static_cast<std::size_t>(total));
    std::uint64_t seen = 0;
    for (int i = 0; i < kBins; ++i) {
      seen += copy[static_cast<std::size_t>(i)];
      if (seen >= rank) return std::min(latency_bin_upper_us(i), s.max_us);
    }
    return s.max_us;
  };
  s.p50_us = quantile(0.5);
  s.p99_us = quantile(0.99);
  return s;
}

void LatencyHistogram::reset() {
  for (auto& b : bins_) b.store(0, std::memory_order_relaxed);
  count_.store(0, std::memory_order_relaxed);
  max_us_.store(0.0, std::memory_order_relaxed);
}

}  // namespace pinball::daemon
