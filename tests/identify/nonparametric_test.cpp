// Tests of cra.hpp and nonparametric_freq.hpp against the exact impulse and
// frequency responses of the paper's ARX model (Eq. 5).
#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "parametric_test_util.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/identify/nonparametric/cra.hpp"
#include "pneumid/identify/nonparametric/nonparametric_freq.hpp"

namespace pneumid {
namespace {

struct Signals {
  Eigen::VectorXd u, y, g;  // g: true impulse response
};

// Output-error data: y = G u + v, white v, input white or coloured.
Signals MakeData(Eigen::Index n, bool coloured) {
  Signals s;
  const PolynomialModel truth = testing::PaperArx();
  Eigen::VectorXd w = testing::WhiteNoise(n, 1.0, 42);
  if (coloured) {  // u = 1 / (1 - 0.8 q^-1) w: the case prewhitening is for
    for (Eigen::Index t = 1; t < n; ++t) w[t] += 0.8 * w[t - 1];
  }
  s.u = w;
  s.y = Simulate(truth, Eigen::MatrixXd(s.u)) + testing::WhiteNoise(n, 0.01, 43);
  Eigen::VectorXd imp = Eigen::VectorXd::Zero(61);
  imp[0] = 1;
  s.g = Simulate(truth, Eigen::MatrixXd(imp));
  return s;
}

TEST(Cra, PrewhiteningRecoversTheImpulseResponseOfColouredInput) {
  const Signals s = MakeData(20000, true);
  CraOptions o;
  o.num_lags = 60;
  const CraResult r = Cra(s.y, s.u, 0.01, o);
  ASSERT_EQ(r.impulse.size(), 61);
  EXPECT_NEAR(r.t[60], 0.6, 1e-12);
  // Within a few confidence bounds of the truth at every lag (bound ~ 2.6 sigma).
  EXPECT_LT((r.impulse - s.g).cwiseAbs().maxCoeff(), 2 * r.bound);
  EXPECT_NEAR(r.impulse[1], 0.03938, 0.004);
  // Without prewhitening the coloured input smears the estimate.
  o.prewhitening_order = 0;
  const CraResult raw = Cra(s.y, s.u, 0.01, o);
  EXPECT_GT((raw.impulse - s.g).cwiseAbs().maxCoeff(), 5 * (r.impulse - s.g).cwiseAbs().maxCoeff());
}

TEST(Cra, RejectsBadInput) {
  const Eigen::VectorXd y = Eigen::VectorXd::Ones(500);
  EXPECT_THROW(Cra(y, y, 0.01), InvalidArgument);  // constant input
  CraOptions o;
  o.num_lags = 0;
  EXPECT_THROW(Cra(y, testing::WhiteNoise(500, 1, 1), 0.01, o), InvalidArgument);
  EXPECT_THROW(Cra(y, testing::WhiteNoise(499, 1, 1), 0.01), InvalidArgument);
}

TEST(Spa, MatchesTheTrueFrequencyResponse) {
  const Signals s = MakeData(20000, false);
  SpaOptions o;
  o.lag_window = 100;
  o.num_frequencies = 64;
  const FrequencyResponseEstimate r = Spa(s.y, s.u, 0.01, o);
  ASSERT_EQ(r.omega.size(), 64);
  EXPECT_NEAR(r.omega[63], M_PI / 0.01, 1e-9);
  const TransferFunction g = PaperArxModel();
  for (int k = 0; k < 64; k += 7) {
    const std::complex<double> gt = g.FrequencyResponse(r.omega[k]);
    EXPECT_NEAR(r.magnitude[k], std::abs(gt), 0.08 * std::abs(gt) + 0.005) << r.omega[k];
  }
  EXPECT_EQ(r.noise_spectrum.size(), 64);
  EXPECT_TRUE((r.magnitude_std.array() >= 0).all());
}

TEST(Etfe, RawAndSmoothedEstimates) {
  const Signals s = MakeData(4096, false);
  const FrequencyResponseEstimate raw = Etfe(s.y, s.u, 0.01);
  EXPECT_EQ(raw.omega.size(), 2048);
  EXPECT_NEAR(raw.omega[0], 2 * M_PI / (4096 * 0.01), 1e-12);
  EtfeOptions o;
  o.num_frequencies = 32;
  const FrequencyResponseEstimate sm = Etfe(s.y, s.u, 0.01, o);
  ASSERT_EQ(sm.omega.size(), 32);
  const TransferFunction g = PaperArxModel();
  // The first band spans 0.15 .. 9.8 rad/s, across the dominant pole where |G|
  // falls by 40 %: averaging over it is biased by design, so start at band 1.
  for (int k = 1; k < 32; ++k) {
    const std::complex<double> gt = g.FrequencyResponse(sm.omega[k]);
    EXPECT_LT(std::abs(sm.response[k] - gt), 0.05 * std::abs(gt) + 0.01) << sm.omega[k];
  }
  EXPECT_THROW(Etfe(s.y, Eigen::VectorXd::Zero(4096), 0.01), InvalidArgument);
}

}  // namespace
}  // namespace pneumid
