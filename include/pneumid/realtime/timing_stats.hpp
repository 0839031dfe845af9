// Timing statistics of a fixed-period loop, collected without allocation.
//
// Per step k, scheduled to wake at t_k = t_0 + k Ts:
//   jitter_k  = t_wake,k - t_k          (wake-up lateness, >= 0 in practice)
//   compute_k = t_done,k - t_wake,k     (read + control + safety + write + log push)
//   overrun_k = t_done,k > t_(k+1)       (the step ended after the next deadline)
// Percentiles come from fixed 1-microsecond histograms allocated at
// construction (values beyond the histogram range fall in an overflow bin and
// are still counted in the maximum), so Add() is O(1) and allocation-free.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace pneumid {

/// Summary of the timing of a run, in microseconds.
struct TimingReport {
  std::int64_t samples = 0;      ///< steps recorded
  std::int64_t overruns = 0;     ///< steps that ended after the next deadline
  double period_us = 0.0;        ///< nominal period
  double jitter_p50_us = 0.0;    ///< median wake-up lateness
  double jitter_p99_us = 0.0;    ///< 99th percentile wake-up lateness
  double jitter_max_us = 0.0;    ///< worst wake-up lateness
  double jitter_mean_us = 0.0;   ///< mean wake-up lateness
  double compute_p50_us = 0.0;   ///< median compute time per step
  double compute_p99_us = 0.0;   ///< 99th percentile compute time per step
  double compute_max_us = 0.0;   ///< worst compute time per step
  double compute_mean_us = 0.0;  ///< mean compute time per step

  /// One line, e.g. "6000 samples, 0 overruns, jitter p50/p99/max 12/48/130 us, ...".
  std::string BriefReport() const;
  /// Keys: samples, overruns, period_us, jitter_p50_us, jitter_p99_us, jitter_max_us,
  /// jitter_mean_us, compute_p50_us, compute_p99_us, compute_max_us, compute_mean_us.
  nlohmann::json ToJson() const;
};

/// Allocation-free collector of a loop's jitter, compute time and overruns (see above).
class TimingStats {
 public:
  /// `period_s` is the nominal period (s); `histogram_range_us` the span of the
  /// 1-us histograms (values above land in the overflow bin).
  /// @throws InvalidArgument when period_s <= 0 or histogram_range_us < 1.
  explicit TimingStats(double period_s, int histogram_range_us = 100000);

  /// Records one step (times in nanoseconds). Never allocates.
  void Add(std::int64_t jitter_ns, std::int64_t compute_ns, bool overrun) noexcept;
  /// Forgets all samples.
  void Clear() noexcept;

  std::int64_t samples() const { return samples_; }    ///< steps recorded (since Clear())
  std::int64_t overruns() const { return overruns_; }  ///< steps flagged as overruns
  /// q-quantile (0 <= q <= 1) of the jitter / compute time in microseconds, to 1 us.
  /// Nearest rank on the histogram (0 without samples); @throws InvalidArgument for q
  /// outside [0, 1].
  double JitterQuantileUs(double q) const;
  double ComputeQuantileUs(double q) const;  ///< as JitterQuantileUs, for the compute time
  /// The statistics so far: counts, p50/p99/max/mean in microseconds.
  TimingReport Report() const;

 private:
  struct Histogram {
    std::vector<std::uint32_t> bins;  // bins[i]: values in [i, i+1) us; last = overflow
    std::int64_t count = 0;
    double sum_us = 0.0;
    double max_us = 0.0;
    void Add(double us) noexcept;
    double Quantile(double q) const;
  };
  double period_s_;
  Histogram jitter_;
  Histogram compute_;
  std::int64_t samples_ = 0;
  std::int64_t overruns_ = 0;
};

}  // namespace pneumid
