#include "pneumid/realtime/timing_stats.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"

namespace pneumid {
namespace {

TEST(TimingStats, NearestRankPercentilesOfKnownSamples) {
  TimingStats s(0.01);
  // Jitter 0..99 us (one sample each, in the middle of each 1-us bin); compute 500 us.
  for (int i = 0; i < 100; ++i) s.Add(i * 1000 + 500, 500000, i == 99);
  const TimingReport r = s.Report();
  EXPECT_EQ(r.samples, 100);
  EXPECT_EQ(r.overruns, 1);
  EXPECT_DOUBLE_EQ(r.period_us, 10000.0);
  // Nearest rank: p50 is the 50th smallest value, 49.5 us, reported as its bin's upper edge.
  EXPECT_DOUBLE_EQ(r.jitter_p50_us, 50.0);
  EXPECT_DOUBLE_EQ(r.jitter_p99_us, 99.0);
  EXPECT_DOUBLE_EQ(r.jitter_max_us, 99.5);
  EXPECT_DOUBLE_EQ(r.jitter_mean_us, 50.0);
  EXPECT_DOUBLE_EQ(r.compute_p50_us, 500.0);
  EXPECT_DOUBLE_EQ(r.compute_max_us, 500.0);
  EXPECT_THAT(r.BriefReport(), ::testing::HasSubstr("100 samples"));
  EXPECT_EQ(r.ToJson()["jitter_p99_us"], 99.0);
}

TEST(TimingStats, ValuesBeyondTheHistogramStillSetTheMaximum) {
  TimingStats s(0.001, 1000);
  for (int i = 0; i < 99; ++i) s.Add(10000, 1000, false);  // 10 us
  s.Add(5000000000LL, 1000, true);                         // 5 s late
  EXPECT_DOUBLE_EQ(s.JitterQuantileUs(0.5), 11.0);
  EXPECT_DOUBLE_EQ(s.Report().jitter_max_us, 5e6);
  EXPECT_DOUBLE_EQ(s.JitterQuantileUs(1.0), 5e6);
  s.Clear();
  EXPECT_EQ(s.samples(), 0);
  EXPECT_DOUBLE_EQ(s.Report().jitter_max_us, 0.0);
}

TEST(TimingStats, RejectsBadArguments) {
  EXPECT_THROW(TimingStats(0.0), InvalidArgument);
  EXPECT_THROW(TimingStats(0.01, 0), InvalidArgument);
  TimingStats s(0.01);
  EXPECT_THROW(s.JitterQuantileUs(1.5), InvalidArgument);
}

}  // namespace
}  // namespace pneumid
