// SeededNoise: the draws are sigma times the standard normal sequence of
// std::mt19937_64 at the seed, restarted by Reset.
#include "pneumid/plant/seeded_noise.hpp"

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"

namespace pneumid {
namespace {

std::vector<double> Draws(SeededNoise& n, int count) {
  std::vector<double> v{n.value()};
  for (int k = 1; k < count; ++k) {
    n.Next();
    v.push_back(n.value());
  }
  return v;
}

TEST(SeededNoiseTest, IsSigmaTimesTheSeededNormalSequence) {
  SeededNoise n(0.5, 11);
  std::mt19937_64 rng(11);
  std::normal_distribution<double> w(0.0, 1.0);
  for (double v : Draws(n, 100)) EXPECT_DOUBLE_EQ(v, 0.5 * w(rng));
}

TEST(SeededNoiseTest, ResetRepeatsTheSequenceAndSeedsDiffer) {
  SeededNoise a(2.0, 7), b(2.0, 8);
  const std::vector<double> first = Draws(a, 50);
  a.Reset();
  EXPECT_EQ(Draws(a, 50), first);
  EXPECT_NE(Draws(b, 50), first);
}

TEST(SeededNoiseTest, SampleStatisticsMatchSigma) {
  SeededNoise n(0.3, 3);
  const std::vector<double> v = Draws(n, 20000);
  double mean = 0.0, sq = 0.0;
  for (double x : v) mean += x;
  mean /= static_cast<double>(v.size());
  for (double x : v) sq += (x - mean) * (x - mean);
  // Standard errors: 0.3 / sqrt(20000) = 0.0021 on the mean, ~0.0015 on sigma.
  EXPECT_NEAR(mean, 0.0, 0.01);
  EXPECT_NEAR(std::sqrt(sq / static_cast<double>(v.size() - 1)), 0.3, 0.006);
}

TEST(SeededNoiseTest, ZeroSigmaIsSilentAndNegativeIsRefused) {
  SeededNoise n;
  for (double v : Draws(n, 10)) EXPECT_EQ(v, 0.0);
  EXPECT_EQ(n.sigma(), 0.0);
  EXPECT_THROW(SeededNoise(-1.0), InvalidArgument);
  EXPECT_THROW(SeededNoise(std::nan("")), InvalidArgument);
}

}  // namespace
}  // namespace pneumid
