#include "pneumid/identify/parametric/rls.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "parametric_test_util.hpp"
#include "pneumid/common/check.hpp"

namespace pneumid {
namespace {

TEST(Rls, WithoutForgettingApproachesBatchLeastSquares) {
  // lambda = 1 and a large P0: RLS minimises the LS criterion plus
  // theta' theta / P0, so it matches the batch QR solution closely.
  const PolynomialModel truth = testing::PaperArx();
  const Eigen::Index n = 5000;
  const Eigen::VectorXd u = testing::Prbs(n, 10, 90, 3, 2);
  const Eigen::VectorXd y = testing::SimulateArx(truth, u, testing::WhiteNoise(n, 0.5, 3));
  RlsOptions ro;
  ro.forgetting_factor = 1.0;
  ro.initial_covariance = 1e8;
  RecursiveArx rarx(ArxOptions{}, ro);
  for (Eigen::Index k = 0; k < n; ++k) rarx.Update(u[k], y[k]);
  const ArxResult batch = EstimateArx(y, Eigen::MatrixXd(u), 0.01, ArxOptions{});
  const Eigen::VectorXd diff = rarx.Model(0.01).Parameters() - batch.model.Parameters();
  EXPECT_LT(diff.norm(), 1e-5 * batch.model.Parameters().norm());
  EXPECT_EQ(rarx.rls().num_updates(), n - 3);
}

TEST(Rls, ForgettingTracksAParameterChange) {
  // y = theta u + e with theta stepping from 1 to 2 halfway.
  const Eigen::Index n = 4000;
  const Eigen::VectorXd u = testing::WhiteNoise(n, 1.0, 7);
  const Eigen::VectorXd e = testing::WhiteNoise(n, 0.05, 8);
  RlsOptions ro;
  ro.forgetting_factor = 0.98;
  RecursiveLeastSquares fast(1, ro);
  ro.forgetting_factor = 1.0;
  RecursiveLeastSquares slow(1, ro);
  Eigen::VectorXd phi(1);
  for (Eigen::Index k = 0; k < n; ++k) {
    phi[0] = u[k];
    const double y = (k < n / 2 ? 1.0 : 2.0) * u[k] + e[k];
    fast.Update(phi, y);
    slow.Update(phi, y);
  }
  EXPECT_NEAR(fast.theta()[0], 2.0, 0.02);
  EXPECT_NEAR(slow.theta()[0], 1.5, 0.1);  // averages both halves
  EXPECT_TRUE(fast.P().isApprox(fast.P().transpose()));
}

TEST(Rls, InvalidOptions) {
  RlsOptions ro;
  ro.forgetting_factor = 1.5;
  EXPECT_THROW(RecursiveLeastSquares(2, ro), InvalidArgument);
  EXPECT_THROW(RecursiveLeastSquares(0), InvalidArgument);
  ArxOptions two;
  two.nb = {1, 1};
  two.nk = {1, 1};
  EXPECT_THROW(RecursiveArx(two, RlsOptions{}), InvalidArgument);
  RecursiveLeastSquares r(2);
  EXPECT_THROW(r.Reset(Eigen::VectorXd::Zero(3)), InvalidArgument);
}

}  // namespace
}  // namespace pneumid
