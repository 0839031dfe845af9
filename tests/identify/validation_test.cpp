// Tests of validation.hpp and residual_analysis.hpp.
#include "pneumid/identify/evaluation/validation.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "parametric_test_util.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/identify/parametric/arx.hpp"
#include "pneumid/identify/evaluation/residual_analysis.hpp"

namespace pneumid {
namespace {

Dataset OeData(Eigen::Index n, double noise, unsigned seed) {
  const PolynomialModel truth = testing::PaperArx();
  const Eigen::VectorXd u = testing::Prbs(n, 10, 90, 3, seed);
  const Eigen::VectorXd y =
      Simulate(truth, Eigen::MatrixXd(u)) + testing::WhiteNoise(n, noise, seed + 1);
  return Dataset::FromUniform(0.01, u, y);
}

TEST(Validation, CompareFitOfTheTrueModelMatchesTheNoiseLevel) {
  const Dataset d = OeData(3000, 1.0, 3);
  const PolynomialModel truth = testing::PaperArx();
  const CompareResult sim = Compare(truth, d);
  // NRMSE fit = 100 (1 - |e| / |y - mean|) with e the added noise.
  const Eigen::VectorXd y = d.y(0);
  const Eigen::VectorXd e = y - Simulate(truth, Eigen::MatrixXd(d.u(0)));
  const double expected = 100 * (1 - e.norm() / (y.array() - y.mean()).matrix().norm());
  EXPECT_NEAR(sim.fit_percent, expected, 1e-9);
  EXPECT_NEAR(sim.rmse, 1.0, 0.05);
  // The same model as a transfer function gives the same simulation.
  const CompareResult tf = Compare(truth.ToTransferFunction(), d);
  EXPECT_NEAR(tf.fit_percent, sim.fit_percent, 1e-8);
  CompareOptions k1;
  k1.horizon = 1;
  EXPECT_THROW(Compare(truth.ToTransferFunction(), d, k1), InvalidArgument);
  k1.horizon = -1;
  EXPECT_THROW(Compare(truth, d, k1), InvalidArgument);
}

TEST(Validation, SplitAndSlice) {
  const Dataset d = OeData(1000, 0.1, 1);
  const auto [est, val] = SplitDataset(d, 0.7);
  EXPECT_EQ(est.size(), 700);
  EXPECT_EQ(val.size(), 300);
  EXPECT_DOUBLE_EQ(val.time()[0], d.time()[700]);
  EXPECT_THROW(SplitDataset(d, 1.0), InvalidArgument);
  EXPECT_THROW(SplitDataset(d, 0.001), InvalidArgument);
  EXPECT_THROW(SliceDataset(d, 10, 5), InvalidArgument);
}

TEST(ResidualAnalysis, CorrectModelPassesAndWrongOrderFails) {
  // ARX data: the right ARX(3,3,1) leaves white residuals uncorrelated with u;
  // an ARX(1,1,1) leaves correlated ones (MATLAB resid's two tests).
  const PolynomialModel truth = testing::PaperArx();
  const Eigen::Index n = 5000;
  const Eigen::VectorXd u = testing::Prbs(n, 10, 90, 3, 9);
  const Eigen::VectorXd y = testing::SimulateArx(truth, u, testing::WhiteNoise(n, 0.5, 10));
  const Dataset d = Dataset::FromUniform(0.01, u, y);
  const ArxResult good = EstimateArx(d, ArxOptions{});
  const ResidualAnalysis rg = AnalyzeResiduals(good.model, d);
  EXPECT_TRUE(rg.whiteness_passed) << rg.BriefReport();
  EXPECT_TRUE(rg.independence_passed) << rg.BriefReport();
  EXPECT_NEAR(rg.bound, 2.5758 / std::sqrt(5000.0), 1e-4);
  EXPECT_EQ(rg.autocorr.size(), 26);
  EXPECT_DOUBLE_EQ(rg.autocorr[0], 1.0);
  EXPECT_EQ(rg.crosscorr.size(), 51);
  ArxOptions low;
  low.na = 1;
  low.nb = {1};
  const ResidualAnalysis rb = AnalyzeResiduals(EstimateArx(d, low).model, d);
  EXPECT_FALSE(rb.passed()) << rb.BriefReport();
  EXPECT_GT(rb.auto_outside + rb.cross_outside, 2);
  const auto j = rb.ToJson();
  EXPECT_EQ(j["passed"], false);
}

TEST(ResidualAnalysis, ChiSquareThresholdsAndErrors) {
  const Eigen::VectorXd e = testing::WhiteNoise(1000, 1.0, 1);
  const Eigen::VectorXd u = testing::WhiteNoise(1000, 1.0, 2);
  const ResidualAnalysis r = AnalyzeResiduals(e, u);
  // chi2 99 % quantiles: 25 dof -> 44.314, 51 dof -> 77.386 (scipy.stats.chi2.ppf).
  EXPECT_NEAR(r.whiteness_threshold, 44.314, 1e-3);
  EXPECT_NEAR(r.independence_threshold, 77.386, 1e-3);
  EXPECT_TRUE(r.passed());
  ResidualAnalysisOptions o;
  o.max_lag = 0;
  EXPECT_THROW(AnalyzeResiduals(e, u, o), InvalidArgument);
  EXPECT_THROW(AnalyzeResiduals(e, u.head(10)), InvalidArgument);
  EXPECT_THROW(AnalyzeResiduals(Eigen::VectorXd::Zero(1000), u), InvalidArgument);
}

}  // namespace
}  // namespace pneumid
