#include "pneumid/realtime/timing_stats.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"

namespace pneumid {

std::string TimingReport::BriefReport() const {
  return fmt::format(
      "{} samples at {:g} us, {} overruns, jitter p50/p99/max {:.0f}/{:.0f}/{:.0f} us, "
      "compute p50/p99/max {:.0f}/{:.0f}/{:.0f} us",
      samples, period_us, overruns, jitter_p50_us, jitter_p99_us, jitter_max_us, compute_p50_us,
      compute_p99_us, compute_max_us);
}

nlohmann::json TimingReport::ToJson() const {
  return {{"samples", samples},
          {"overruns", overruns},
          {"period_us", period_us},
          {"jitter_p50_us", jitter_p50_us},
          {"jitter_p99_us", jitter_p99_us},
          {"jitter_max_us", jitter_max_us},
          {"jitter_mean_us", jitter_mean_us},
          {"compute_p50_us", compute_p50_us},
          {"compute_p99_us", compute_p99_us},
          {"compute_max_us", compute_max_us},
          {"compute_mean_us", compute_mean_us}};
}

TimingStats::TimingStats(double period_s, int histogram_range_us) : period_s_(period_s) {
  PNEUMID_CHECK(period_s > 0.0 && std::isfinite(period_s), "period must be positive, got {} s",
                period_s);
  PNEUMID_CHECK(histogram_range_us >= 1, "histogram range must be >= 1 us, got {}",
                histogram_range_us);
  jitter_.bins.assign(static_cast<std::size_t>(histogram_range_us) + 1, 0);
  compute_.bins.assign(static_cast<std::size_t>(histogram_range_us) + 1, 0);
}

void TimingStats::Histogram::Add(double us) noexcept {
  if (!(us >= 0.0)) us = 0.0;  // early wake-ups (clock granularity) count as zero lateness
  const std::size_t last = bins.size() - 1;
  const std::size_t i = us >= static_cast<double>(last) ? last : static_cast<std::size_t>(us);
  ++bins[i];
  ++count;
  sum_us += us;
  max_us = std::max(max_us, us);
}

double TimingStats::Histogram::Quantile(double q) const {
  if (count == 0) return 0.0;
  // Nearest-rank definition: the smallest value v with at least ceil(q N) samples <= v.
  const auto rank = std::max<std::int64_t>(
      1, static_cast<std::int64_t>(std::ceil(q * static_cast<double>(count))));
  std::int64_t seen = 0;
  for (std::size_t i = 0; i < bins.size(); ++i) {
    seen += bins[i];
    if (seen >= rank) {
      if (i + 1 == bins.size()) return max_us;  // overflow bin
      // Upper edge of the bin, but never above the observed maximum.
      return std::min(static_cast<double>(i + 1), max_us);
    }
  }
  return max_us;
}

void TimingStats::Add(std::int64_t jitter_ns, std::int64_t compute_ns, bool overrun) noexcept {
  jitter_.Add(static_cast<double>(jitter_ns) * 1e-3);
  compute_.Add(static_cast<double>(compute_ns) * 1e-3);
  ++samples_;
  if (overrun) ++overruns_;
}

void TimingStats::Clear() noexcept {
  for (Histogram* h : {&jitter_, &compute_}) {
    std::fill(h->bins.begin(), h->bins.end(), 0u);
    h->count = 0;
    h->sum_us = 0.0;
    h->max_us = 0.0;
  }
  samples_ = 0;
  overruns_ = 0;
}

double TimingStats::JitterQuantileUs(double q) const {
  PNEUMID_CHECK(q >= 0.0 && q <= 1.0, "quantile must be in [0, 1], got {}", q);
  return jitter_.Quantile(q);
}

double TimingStats::ComputeQuantileUs(double q) const {
  PNEUMID_CHECK(q >= 0.0 && q <= 1.0, "quantile must be in [0, 1], got {}", q);
  return compute_.Quantile(q);
}

TimingReport TimingStats::Report() const {
  TimingReport r;
  r.samples = samples_;
  r.overruns = overruns_;
  r.period_us = period_s_ * 1e6;
  r.jitter_p50_us = jitter_.Quantile(0.5);
  r.jitter_p99_us = jitter_.Quantile(0.99);
  r.jitter_max_us = jitter_.max_us;
  r.jitter_mean_us = jitter_.count ? jitter_.sum_us / static_cast<double>(jitter_.count) : 0.0;
  r.compute_p50_us = compute_.Quantile(0.5);
  r.compute_p99_us = compute_.Quantile(0.99);
  r.compute_max_us = compute_.max_us;
  r.compute_mean_us = compute_.count ? compute_.sum_us / static_cast<double>(compute_.count) : 0.0;
  return r;
}

}  // namespace pneumid
