#include "pneumid/identify/subspace.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "parametric_test_util.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/lti/conversion.hpp"

namespace pneumid {
namespace {

class SubspaceNoise : public ::testing::TestWithParam<double> {};

TEST_P(SubspaceNoise, RecoversThePaperModelPolesAndGain) {
  // Output-error data of the paper's ARX model (Eq. 5), white input. Exact
  // without noise; with noise the weakly visible fast pair is the least accurate.
  const double noise = GetParam();
  const double tol = noise == 0.0 ? 1e-6 : 0.04;
  const PolynomialModel truth = testing::PaperArx();
  const Eigen::Index n = 20000;
  const Eigen::VectorXd u = testing::WhiteNoise(n, 10.0, 3);
  const Eigen::VectorXd y = Simulate(truth, Eigen::MatrixXd(u)) + testing::WhiteNoise(n, noise, 4);
  SubspaceOptions o;
  o.order = 3;
  const SubspaceResult r = EstimateSubspace(y, u, 0.01, o);
  ASSERT_EQ(r.summary.termination, EstimationTermination::kConvergence);
  EXPECT_EQ(r.order, 3);
  EXPECT_EQ(r.model.Ts(), 0.01);
  // Poles 0.95685, -0.17407 +- 0.18062j (docs/paper.md, reference value 2; more digits
  // from numpy.roots([1, -0.6087, -0.2702, -0.06021])).
  Eigen::VectorXcd p = r.model.Poles();
  std::sort(p.data(), p.data() + p.size(), [](auto a, auto b) {
    return a.real() > b.real() || (a.real() == b.real() && a.imag() > b.imag());
  });
  EXPECT_NEAR(p[0].real(), 0.95684847, std::max(1e-6, tol / 10));
  EXPECT_NEAR(p[1].real(), -0.17407423, tol);
  EXPECT_NEAR(std::abs(p[1].imag()), 0.18061973, tol);
  EXPECT_NEAR(r.model.DcGain()(0, 0), 1.59796, std::max(1e-5, tol / 4));
  // The fast complex pair (|z| = 0.25) is weakly visible: the singular values
  // drop after the first, and again after the third.
  EXPECT_GT(r.singular_values[2] / r.singular_values[3], 3.0);
}

INSTANTIATE_TEST_SUITE_P(Subspace, SubspaceNoise, ::testing::Values(0.0, 0.05));

TEST(Subspace, FixedOrderAndErrors) {
  const Eigen::Index n = 2000;
  const Eigen::VectorXd u = testing::WhiteNoise(n, 1.0, 5);
  PolynomialModel first;
  first.Ts = 0.1;
  first.a = Eigen::Vector2d(1, -0.9);
  first.b = {Eigen::Vector2d(0, 0.5)};
  first.nk = {1};
  const Eigen::VectorXd y = Simulate(first, Eigen::MatrixXd(u));
  SubspaceOptions o;  // automatic order: the gap after the first singular value
  const SubspaceResult r = EstimateSubspace(y, u, 0.1, o);
  EXPECT_EQ(r.order, 1);
  o.order = 1;
  EXPECT_NEAR(r.model.A()(0, 0), 0.9, 1e-6);
  EXPECT_NEAR(r.model.DcGain()(0, 0), 5.0, 1e-5);
  o.horizon = 1;  // must exceed the order
  EXPECT_THROW(EstimateSubspace(y, u, 0.1, o), InvalidArgument);
  EXPECT_THROW(EstimateSubspace(y.head(50), u.head(50), 0.1, SubspaceOptions{}), InvalidArgument);
}

}  // namespace
}  // namespace pneumid
