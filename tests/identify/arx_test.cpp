#include "pneumid/identify/parametric/arx.hpp"

#include <cmath>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <Eigen/Dense>

#include "parametric_test_util.hpp"
#include "pneumid/common/check.hpp"

namespace pneumid {
namespace {

using ::testing::HasSubstr;

struct ArxLstsqCase {
  const char* name;
  int na;
  std::vector<int> nb;
  std::vector<int> nk;
  std::vector<double> y;
  std::vector<double> u;  // column-major N x nu
  std::vector<double> theta;
};

// Recorded by tests/identify/gen_arx_lstsq.py with numpy.linalg.lstsq.
const std::vector<ArxLstsqCase>& LstsqCases() {
  static const std::vector<ArxLstsqCase> cases = {
#include "arx_lstsq_cases.inc"
  };
  return cases;
}

TEST(Arx, EqualsNumpyLstsqOnRecordedCases) {
  ASSERT_EQ(LstsqCases().size(), 5u);
  for (const auto& c : LstsqCases()) {
    SCOPED_TRACE(c.name);
    const Eigen::Index n = static_cast<Eigen::Index>(c.y.size());
    const Eigen::Index nu = static_cast<Eigen::Index>(c.nb.size());
    const Eigen::VectorXd y = Eigen::Map<const Eigen::VectorXd>(c.y.data(), n);
    const Eigen::MatrixXd u = Eigen::Map<const Eigen::MatrixXd>(c.u.data(), n, nu);
    const Eigen::VectorXd ref = Eigen::Map<const Eigen::VectorXd>(
        c.theta.data(), static_cast<Eigen::Index>(c.theta.size()));
    ArxOptions o;
    o.na = c.na;
    o.nb = c.nb;
    o.nk = c.nk;
    const ArxResult r = EstimateArx(y, u, 0.01, o);
    ASSERT_EQ(r.summary.termination, Termination::kConvergence) << r.summary.message;
    const Eigen::VectorXd theta = r.model.Parameters();
    ASSERT_EQ(theta.size(), ref.size());
    EXPECT_LT((theta - ref).norm() / ref.norm(), 1e-10) << theta.transpose() << "\n"
                                                        << ref.transpose();
  }
}

TEST(Arx, RegressorsMatchTheDocumentedLayout) {
  const Eigen::VectorXd y = Eigen::VectorXd::LinSpaced(6, 1, 6);
  Eigen::MatrixXd u(6, 1);
  u.col(0) = Eigen::VectorXd::LinSpaced(6, 10, 60);
  ArxOptions o;
  o.na = 2;
  o.nb = {2};
  o.nk = {1};
  Eigen::MatrixXd phi;
  Eigen::VectorXd target;
  ArxRegressors(y, u, o, &phi, &target);
  ASSERT_EQ(phi.rows(), 4);  // t = 2..5
  // t = 2: [-y1 -y0 u1 u0]
  EXPECT_EQ(phi.row(0), (Eigen::RowVector4d() << -2, -1, 20, 10).finished());
  EXPECT_EQ(target[0], 3);
}

// Error of the estimate against the paper's coefficients, averaged over seeds.
double MeanParameterError(Eigen::Index n, int seeds) {
  const PolynomialModel truth = testing::PaperArx();
  const Eigen::VectorXd theta0 = truth.Parameters();
  double sum = 0.0;
  for (int s = 0; s < seeds; ++s) {
    Eigen::MatrixXd u(n, 1);
    u.col(0) = testing::Prbs(n, 10.0, 90.0, 2, 1 + 37 * s);
    const Eigen::VectorXd y =
        testing::SimulateArx(truth, u.col(0), testing::WhiteNoise(n, 1.0, 100 + s));
    ArxOptions o;  // na = nb = 3, nk = 1
    const ArxResult r = EstimateArx(y, u, 0.01, o);
    sum += (r.model.Parameters() - theta0).norm() / theta0.norm();
  }
  return sum / seeds;
}

TEST(Arx, ConvergesToThePaperModelAsOneOverSqrtN) {
  // Paper Eq. 5 ARX(3,3,1) with PRBS input and white equation noise: the
  // least-squares estimate is consistent and its error falls as 1/sqrt(N)
  // (Ljung 1999, eq. 9.18). Fit the slope of log(error) against log(N).
  const std::vector<Eigen::Index> ns = {1000, 4000, 16000, 64000};
  std::vector<double> le, ln;
  for (auto n : ns) {
    const double err = MeanParameterError(n, 6);
    le.push_back(std::log(err));
    ln.push_back(std::log(static_cast<double>(n)));
  }
  const double mx = (ln[0] + ln[1] + ln[2] + ln[3]) / 4, my = (le[0] + le[1] + le[2] + le[3]) / 4;
  double sxy = 0, sxx = 0;
  for (int i = 0; i < 4; ++i) {
    sxy += (ln[i] - mx) * (le[i] - my);
    sxx += (ln[i] - mx) * (ln[i] - mx);
  }
  const double slope = sxy / sxx;
  EXPECT_NEAR(slope, -0.5, 0.12);
  EXPECT_LT(std::exp(le.back()), 0.02);  // 64000 samples: about 1 % relative error
}

TEST(Arx, ChunkedAccumulationEqualsOneShot) {
  const PolynomialModel truth = testing::PaperArx();
  const Eigen::Index n = 5000;
  Eigen::MatrixXd u(n, 1);
  u.col(0) = testing::Prbs(n, 0.0, 80.0, 3);
  const Eigen::VectorXd y = testing::SimulateArx(truth, u.col(0), testing::WhiteNoise(n, 0.5, 7));
  ArxOptions o;
  const ArxResult one = EstimateArx(y, u, 0.01, o);
  ArxAccumulator acc(o);
  for (Eigen::Index k = 0; k < n;) {
    const Eigen::Index m = std::min<Eigen::Index>(1 + (k % 7) * 113, n - k);  // uneven chunks
    acc.AddSamples(y.segment(k, m), u.middleRows(k, m));
    k += m;
  }
  EXPECT_EQ(acc.num_rows(), n - 3);
  const ArxResult chunked = acc.Solve(0.01);
  EXPECT_LT((chunked.model.Parameters() - one.model.Parameters()).norm(),
            1e-12 * one.model.Parameters().norm());
  EXPECT_NEAR(chunked.summary.loss, one.summary.loss, 1e-12 * one.summary.loss);
}

TEST(Arx, SeveralExperimentsStackTheirRowsOnly) {
  const PolynomialModel truth = testing::PaperArx();
  const Eigen::Index n = 800;
  std::vector<Dataset> exps;
  Eigen::MatrixXd phi_all(0, 6);
  Eigen::VectorXd y_all(0);
  for (int e = 0; e < 3; ++e) {
    const Eigen::VectorXd u = testing::Prbs(n, 0.0, 50.0 + 10 * e, 1 + e, 3 + e);
    const Eigen::VectorXd y = testing::SimulateArx(truth, u, testing::WhiteNoise(n, 0.3, 11 + e));
    exps.push_back(Dataset::FromUniform(0.01, u, y));
    Eigen::MatrixXd phi;
    Eigen::VectorXd t;
    ArxRegressors(y, u, ArxOptions{}, &phi, &t);
    Eigen::MatrixXd p2(phi_all.rows() + phi.rows(), 6);
    p2 << phi_all, phi;
    Eigen::VectorXd y2(y_all.size() + t.size());
    y2 << y_all, t;
    phi_all = p2;
    y_all = y2;
  }
  const ArxResult r = EstimateArx(exps, ArxOptions{});
  EXPECT_EQ(r.summary.num_rows, 3 * (n - 3));
  const Eigen::VectorXd ref = phi_all.colPivHouseholderQr().solve(y_all);
  EXPECT_LT((r.model.Parameters() - ref).norm(), 1e-10 * ref.norm());
  // Covariance lambda (Phi' Phi)^-1, computed independently through an SVD.
  const double lambda = (y_all - phi_all * ref).squaredNorm() / (phi_all.rows() - 6.0);
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(phi_all, Eigen::ComputeThinV);
  const Eigen::MatrixXd cov =
      lambda * svd.matrixV() *
      svd.singularValues().array().inverse().square().matrix().asDiagonal() *
      svd.matrixV().transpose();
  EXPECT_LT((r.model.covariance - cov).norm(), 1e-8 * cov.norm());
  EXPECT_EQ(r.model.ParameterStd().size(), 6);
}

TEST(Arx, MultiInputRecoversBothTransferFunctions) {
  const Eigen::Index n = 20000;
  Eigen::MatrixXd u(n, 2);
  u.col(0) = testing::Prbs(n, -1, 1, 1, 5);
  u.col(1) = testing::WhiteNoise(n, 1.0, 9);
  PolynomialModel truth;
  truth.Ts = 0.1;
  truth.a = Eigen::Vector3d(1, -1.2, 0.5);
  truth.b = {Eigen::Vector3d(0, 1.0, 0.5), Eigen::Vector3d(0, 0, -0.7)};
  truth.nk = {1, 2};
  PolynomialModel noise = truth;
  noise.b = {Eigen::VectorXd::Ones(1)};
  noise.nk = {0};
  const Eigen::VectorXd y = Simulate(truth, u) + Simulate(noise, testing::WhiteNoise(n, 0.1, 4));
  ArxOptions o;
  o.na = 2;
  o.nb = {2, 1};
  o.nk = {1, 2};
  const ArxResult r = EstimateArx(y, u, 0.1, o);
  const Eigen::VectorXd expect = (Eigen::VectorXd(5) << -1.2, 0.5, 1.0, 0.5, -0.7).finished();
  EXPECT_LT((r.model.Parameters() - expect).cwiseAbs().maxCoeff(), 0.01);
  ASSERT_EQ(r.model.b.size(), 2u);
  EXPECT_EQ(r.model.b[1].size(), 3);
  EXPECT_EQ(r.model.b[1][0], 0.0);
  EXPECT_EQ(r.model.ParameterNames()[4], "b2_1");
}

TEST(Arx, WarnsAboutPoorExcitationOfAStepTest) {
  // A single step sampled at 10 ms: the lagged outputs are nearly collinear.
  const PolynomialModel truth = testing::PaperArx();
  const Eigen::Index n = 300;
  Eigen::MatrixXd u = Eigen::MatrixXd::Constant(n, 1, 82.0);
  u.topRows(20).setConstant(0.61);
  const Eigen::VectorXd y = testing::SimulateArx(truth, u.col(0), testing::WhiteNoise(n, 0.01, 2));
  const ArxResult r = EstimateArx(y, u, 0.01, ArxOptions{});
  EXPECT_GT(r.summary.scaled_condition_number, 1e4);
  ASSERT_FALSE(r.summary.warnings.empty());
  EXPECT_THAT(r.summary.warnings.front(), HasSubstr("poor excitation"));
}

TEST(Arx, ConstantInputIsRankDeficient) {
  const Eigen::Index n = 200;
  Eigen::MatrixXd u = Eigen::MatrixXd::Constant(n, 1, 3.0);
  const Eigen::VectorXd y = testing::WhiteNoise(n, 1.0, 3);
  const ArxResult r = EstimateArx(y, u, 0.01, ArxOptions{});
  EXPECT_EQ(r.summary.termination, Termination::kRankDeficient);
  EXPECT_TRUE(r.model.Parameters().allFinite());
}

TEST(Arx, InvalidArgumentsThrowWithValues) {
  ArxOptions o;
  o.na = -1;
  std::string error;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_THAT(error, HasSubstr("na must be >= 0, got -1"));
  EXPECT_THROW(ArxAccumulator{o}, InvalidArgument);
  ArxOptions two;
  two.nb = {3, 3};
  EXPECT_FALSE(two.IsValid(&error));
  const Eigen::VectorXd y = Eigen::VectorXd::Ones(10);
  Eigen::MatrixXd u = Eigen::MatrixXd::Ones(9, 1);
  EXPECT_THROW(EstimateArx(y, u, 0.01, ArxOptions{}), InvalidArgument);
  Eigen::MatrixXd u2 = Eigen::MatrixXd::Ones(10, 2);
  try {
    EstimateArx(y, u2, 0.01, ArxOptions{});
    FAIL();
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("1 input(s), the data have 2"));
  }
  Eigen::VectorXd ynan = y;
  ynan[4] = std::nan("");
  EXPECT_THROW(EstimateArx(ynan, u2.leftCols(1), 0.01, ArxOptions{}), InvalidArgument);
  // Too short: a failure in the summary, not a throw.
  const ArxResult r = EstimateArx(y.head(6), u2.topLeftCorner(6, 1), 0.01, ArxOptions{});
  EXPECT_EQ(r.summary.termination, Termination::kFailure);
}

}  // namespace
}  // namespace pneumid
