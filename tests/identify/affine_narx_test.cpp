// The input-affine NARX of affine_narx.hpp on data of a known system of its
// class (a chamber that fills faster than it vents, a valve dead band):
// noise-free data give back the map and coefficients, the written NARX
// simulates the system, the method runs through IdentifyNonlinear and the
// model file; bad input gives clear errors.
#include "pneumid/identify/nonlinear/affine_narx.hpp"

#include <cmath>
#include <random>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/identify/evaluation/fit_metrics.hpp"
#include "pneumid/identify/identified_model_io.hpp"
#include "pneumid/identify/nonlinear/nonlinear.hpp"

namespace pneumid {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

// z(t) = z(t-1) + a(z) + f(u) b(z), z = y / 100:
// a(z) = -0.02 z - 0.03 z^2 (venting, faster at high pressure),
// b(z) = 0.15 - 0.05 z (filling, slower as the chamber fills),
// f: dead band to 20 %, linear to 1 at 80 %, saturated beyond.
const std::vector<double> kKnots = {0, 20, 40, 60, 80, 100};
const std::vector<double> kMap = {0, 0, 0.3, 0.7, 1, 1};
double A(double z) { return -0.02 * z - 0.03 * z * z; }
double B(double z) { return 0.15 - 0.05 * z; }

struct Record {
  Eigen::VectorXd u, y;
};

Record Simulate(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> level(0, 20);
  const StaticMap f(kKnots, kMap);
  Record r{Eigen::VectorXd(n), Eigen::VectorXd(n)};
  double z = 0.0, u = 0.0;
  for (int t = 0; t < n; ++t) {
    if (t % 40 == 0) u = 5.0 * level(rng);  // a level every 40 samples, 0..100 %
    r.u[t] = u;
    r.y[t] = 100.0 * z;
    z = z + A(z) + f.Evaluate(u) * B(z);  // y(t+1) from u(t): nk = 1
  }
  return r;
}

TEST(AffineNarxTest, RecoversTheSystemFromNoiseFreeData) {
  const Record r = Simulate(4000, 3);
  AffineNarxOptions o;
  o.knots = kKnots;
  const AffineNarxResult res = EstimateAffineNarx(r.u, r.y, 0.01, o);
  EXPECT_EQ(res.summary.termination, Termination::kConvergence) << res.summary.message;
  // f up to its normalisation (0 at the first knot, 1 at the last): the true one.
  ASSERT_EQ(res.map.size(), kKnots.size());
  for (std::size_t j = 0; j < kKnots.size(); ++j)
    EXPECT_NEAR(res.map.Evaluate(kKnots[j]), kMap[j], 1e-6) << "knot " << kKnots[j];
  // NARX in z = y / y_scale: theta of z^p and v z^p follow from a, b by the scale.
  const double s = res.narx.y_scale / 100.0;  // z_model = z_true / s
  ASSERT_EQ(res.narx.theta.size(), 6u);
  const std::vector<double> expected = {0.0, 1.0 - 0.02, -0.03 * s, 0.15 / s, -0.05, 0.0};
  for (std::size_t i = 0; i < expected.size(); ++i)
    EXPECT_NEAR(res.narx.theta[i], expected[i], 1e-7) << res.narx.TermName(res.narx.terms[i]);
  EXPECT_GT(res.simulation_fit_percent, 99.999);
  // A new record of the same system: the model's free run reproduces it.
  const Record v = Simulate(3000, 11);
  const Eigen::VectorXd sim = res.narx.Simulate(res.map.Evaluate(v.u), v.y);
  EXPECT_LT((sim - v.y).cwiseAbs().maxCoeff(), 1e-4);
  // The free run's band, as a polynomial NARX's: the estimation output's
  // range widened by a quarter each way. A model whose run leaves it
  // (theta of z(t-1) raised to 1.5: z grows by half each sample until its
  // -z^2 term turns it down without bound) is held at the band's edges, not
  // carried to infinity.
  const double lo = r.y.minCoeff(), hi = r.y.maxCoeff();
  EXPECT_NEAR(res.narx.y_min, lo - 0.25 * (hi - lo), 1e-9);
  EXPECT_NEAR(res.narx.y_max, hi + 0.25 * (hi - lo), 1e-9);
  NarxModel runaway = res.narx;
  runaway.theta[1] = 1.5;
  const Eigen::VectorXd held = runaway.Simulate(res.map.Evaluate(v.u), v.y);
  ASSERT_TRUE(held.allFinite());
  EXPECT_GE(held.minCoeff(), res.narx.y_min);
  EXPECT_LE(held.maxCoeff(), res.narx.y_max);
  EXPECT_GT((held.array() == res.narx.y_min || held.array() == res.narx.y_max).count(),
            held.size() / 2);
}

TEST(AffineNarxTest, RunsAsAnIdentifyMethodAndThroughTheModelFile) {
  const Record r = Simulate(3000, 5);
  const Dataset data = Dataset::FromUniform(0.01, r.u, r.y);
  IdentifyRequest req;
  req.nk = 1;
  NonlinearOptions o;
  o.block.knots = kKnots;
  const IdentifiedModel m = IdentifyNonlinear("affine-narx", data, req, o);
  ASSERT_TRUE(m.narx && m.input_map);
  EXPECT_GT(m.fit_percent, 99.99);
  const IdentifiedModel back = IdentifiedModelFromJson(ToJson(m));
  const Eigen::VectorXd a = SimulateNonlinear(m, data, 0, 0);
  const Eigen::VectorXd b = SimulateNonlinear(back, data, 0, 0);
  EXPECT_LT((a - b).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_NEAR(NrmseFit(r.y, a), m.fit_percent, 1e-6);
}

TEST(AffineNarxTest, BadInputGivesClearErrors) {
  const Record r = Simulate(500, 1);
  EXPECT_THAT([&] { EstimateAffineNarx(Eigen::VectorXd::Constant(500, 40.0), r.y, 0.01); },
              ThrowsMessage<InvalidArgument>(HasSubstr("never leaves one operating point")));
  EXPECT_THAT(
      [&] { EstimateAffineNarx(r.u.head(10), r.y, 0.01); },
      ThrowsMessage<InvalidArgument>(HasSubstr("the input has 10 samples, the output 500")));
  AffineNarxOptions k21;
  k21.num_knots = 21;
  EXPECT_THAT(
      [&] { EstimateAffineNarx(Eigen::VectorXd::LinSpaced(20, 0, 100), r.y.head(20), 0.01, k21); },
      ThrowsMessage<InvalidArgument>(
          HasSubstr("27 parameters (degree 2, 21 knots) exceed the 19 regression rows")));
  AffineNarxOptions o;
  o.degree = 4;
  EXPECT_THAT([&] { EstimateAffineNarx(r.u, r.y, 0.01, o); },
              ThrowsMessage<InvalidArgument>(HasSubstr("degree must be in 1..3, got 4")));
  o = {};
  o.knots = {0, 50, 50, 100};
  EXPECT_THAT([&] { EstimateAffineNarx(r.u, r.y, 0.01, o); },
              ThrowsMessage<InvalidArgument>(HasSubstr("knots must increase strictly")));
  Eigen::VectorXd bad = r.y;
  bad[7] = std::nan("");
  EXPECT_THAT([&] { EstimateAffineNarx(r.u, bad, 0.01); },
              ThrowsMessage<InvalidArgument>(HasSubstr("non-finite")));
}

}  // namespace
}  // namespace pneumid
