// Static map from staircase and ramp experiments: PAVA against closed forms,
// recovery of a known S-shaped map through first-order dynamics with noise,
// and the errors for data from which no map follows.
#include "pneumid/identify/nonlinear/static_map_fit.hpp"

#include <cmath>
#include <random>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/lti/response.hpp"
#include "pneumid/lti/transfer_function.hpp"

namespace pneumid {
namespace {

using ::testing::DoubleEq;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

// The plant's steady map: dead zone below u = 10, saturation above u = 85.
const StaticMap& TrueMap() {
  static const StaticMap m({0, 10, 30, 60, 85, 100}, {0, 0, 25, 80, 150, 150});
  return m;
}

// y = G f(u) + noise, G = 1 / (0.3 s + 1) sampled at Ts (unit gain).
Eigen::VectorXd Respond(const Eigen::VectorXd& u, double Ts, double noise, unsigned seed) {
  const Eigen::VectorXd v = TrueMap().Evaluate(u);
  Eigen::VectorXd y = Lsim(TransferFunction::Fopdt(1.0, 0.3, 0.0), v, Ts);
  std::mt19937 gen(seed);
  std::normal_distribution<double> e(0.0, noise);
  for (Eigen::Index k = 0; k < y.size(); ++k) y[k] += e(gen);
  return y;
}

TEST(PoolAdjacentViolatorsTest, MatchesHandComputedPools) {
  // 3 > 2 violates: pooled to their weighted mean.
  EXPECT_THAT(PoolAdjacentViolators({1, 3, 2, 4}, {1, 1, 1, 1}, true), ElementsAre(1, 2.5, 2.5, 4));
  EXPECT_THAT(PoolAdjacentViolators({1, 3, 2, 4}, {1, 1, 3, 1}, true),
              ElementsAre(1, 2.25, 2.25, 4));
  // A pool that grows backwards: (5 + 1 + 0) / 3 = 2 then meets 3 -> (3+6)/4.
  EXPECT_THAT(PoolAdjacentViolators({3, 5, 1, 0}, {1, 1, 1, 1}, true),
              ElementsAre(2.25, 2.25, 2.25, 2.25));
  EXPECT_THAT(PoolAdjacentViolators({4, 1, 2, 0}, {1, 1, 1, 1}, false),
              ElementsAre(4, 1.5, 1.5, 0));
  EXPECT_THAT(
      [] {
        PoolAdjacentViolators({1, 2}, {1, 0}, true);
      },
      ThrowsMessage<InvalidArgument>(HasSubstr("weight 1 is 0")));
}

TEST(StaticMapFitTest, RecoversAKnownMapFromAStaircase) {
  const double Ts = 0.01;
  std::vector<double> levels;
  for (double l = 0; l <= 100; l += 10) levels.push_back(l);
  for (double l = 95; l >= 5; l -= 10) levels.push_back(l);  // and down again
  Eigen::VectorXd u(static_cast<Eigen::Index>(levels.size()) * 250);
  for (std::size_t i = 0; i < levels.size(); ++i)
    u.segment(static_cast<Eigen::Index>(i) * 250, 250).setConstant(levels[i]);
  const Eigen::VectorXd y = Respond(u, Ts, 1.0, 3);
  const StaticMapFitResult r = FitStaticMap(u, y, Ts);
  EXPECT_EQ(r.summary.source, StaticMapSource::kStaircase);
  EXPECT_EQ(r.summary.segments_used, static_cast<int>(levels.size()));
  ASSERT_EQ(r.map.size(), 21u);  // 0, 5, 10, ..., 100
  EXPECT_TRUE(r.map.IsMonotone());
  // 125 samples of noise std 1 per level: the mean within 4 / sqrt(125) = 0.36;
  // after 1.25 s = 4.2 time constants the transient is below 1.5 % of a step of 25.
  for (std::size_t i = 0; i < r.map.size(); ++i)
    EXPECT_NEAR(r.map.y()[i], TrueMap().Evaluate(r.map.u()[i]), 0.8) << r.map.u()[i];
  const auto dz = r.map.DeadZone(1.0);
  ASSERT_TRUE(dz.has_value());
  EXPECT_EQ(dz->u_to, 10.0);
  const auto sat = r.map.Saturation(1.0);
  ASSERT_TRUE(sat.has_value());
  EXPECT_EQ(sat->u_from, 85.0);
  EXPECT_NEAR(r.map.Inverse(80.0), 60.0, 0.5);
}

TEST(StaticMapFitTest, SkipsShortSegmentsAndFitsSlowRamps) {
  const double Ts = 0.01;
  // 0.2 s pulses between 2 s levels: the pulses are skipped.
  Eigen::VectorXd u(2000);
  for (Eigen::Index k = 0; k < 2000; ++k) u[k] = k < 1000 ? 20.0 : 70.0;
  u.segment(980, 20).setConstant(50.0);
  const StaticMapFitResult r = FitStaticMap(u, Respond(u, Ts, 0.0, 1), Ts);
  EXPECT_EQ(r.summary.segments_used, 2);
  EXPECT_EQ(r.summary.segments_skipped, 1);
  EXPECT_THAT(r.map.u(), ElementsAre(20.0, 70.0));
  EXPECT_NEAR(r.map.y()[1], TrueMap().Evaluate(70.0), 1e-3);

  // A ramp 0 -> 100 over 200 s (time constant 0.3 s: lag 0.15 % / s * 0.3 s).
  Eigen::VectorXd ramp = Eigen::VectorXd::LinSpaced(20000, 0.0, 100.0);
  StaticMapFitOptions o;
  o.ramp_bins = 10;
  const StaticMapFitResult rr = FitStaticMap(ramp, Respond(ramp, Ts, 0.5, 2), Ts, o);
  EXPECT_EQ(rr.summary.source, StaticMapSource::kRamp);
  ASSERT_EQ(rr.map.size(), 10u);
  // Bin means of a piecewise-linear map: a bin of width w = 10 centred on a
  // kink where the slope changes by ds is off by ds w / 8 (2.8 * 10 / 8 = 3.5
  // at the saturation u = 85), plus the lag (slope 2.8 * 0.15 = 0.4).
  for (std::size_t i = 0; i < rr.map.size(); ++i)
    EXPECT_NEAR(rr.map.y()[i], TrueMap().Evaluate(rr.map.u()[i]), 4.0) << rr.map.u()[i];
}

TEST(StaticMapFitTest, ClearErrorsWhenNoMapFollows) {
  const Eigen::VectorXd u = Eigen::VectorXd::Constant(500, 42.0);
  EXPECT_THAT(
      [&] { FitStaticMap(u, Respond(u, 0.01, 0.1, 1), 0.01); },
      ThrowsMessage<InvalidArgument>(HasSubstr("never leaves one operating point: u stays at 42")));
  // A PRBS-like input: no settled level, not monotone.
  Eigen::VectorXd p(1000);
  for (Eigen::Index k = 0; k < 1000; ++k) p[k] = (k / 20) % 2 ? 80.0 : 20.0;
  EXPECT_THAT([&] { FitStaticMap(p, Respond(p, 0.01, 0.1, 1), 0.01); },
              ThrowsMessage<InvalidArgument>(HasSubstr("0 settled level(s) () of constant input "
                                                       "lasting >= 1 s (50 shorter run(s)")));
  StaticMapFitOptions ramp;
  ramp.source = StaticMapSource::kRamp;
  EXPECT_THAT([&] { FitStaticMap(p, p, 0.01, ramp); },
              ThrowsMessage<InvalidArgument>(HasSubstr("a ramp must be monotone")));
  StaticMapFitOptions bad;
  bad.settle_fraction = 0.0;
  EXPECT_THAT([&] { FitStaticMap(p, p, 0.01, bad); },
              ThrowsMessage<InvalidArgument>(HasSubstr("settle_fraction must be in (0, 1]")));
}

}  // namespace
}  // namespace pneumid
