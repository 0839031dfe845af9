#include "pneumid/identify/evaluation/model_uncertainty.hpp"

#include <cmath>
#include <random>

#include <gtest/gtest.h>
#include <Eigen/Cholesky>

#include "parametric_test_util.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/identify/identified_model_io.hpp"
#include "pneumid/identify/parametric/parametric.hpp"
#include "pneumid/identify/step/step_methods.hpp"
#include "pneumid/lti/frequency.hpp"
#include "pneumid/lti/response.hpp"

namespace pneumid {
namespace {

// y(t) = -a y(t-1) + b u(t-1), Ts = 0.1, with covariance P of (a1, b1).
IdentifiedModel FirstOrderArx(double a, double b, const Eigen::Matrix2d& P) {
  PolynomialModel pm;
  pm.Ts = 0.1;
  pm.a = Eigen::Vector2d(1.0, a);
  pm.b = {Eigen::Vector2d(0.0, b)};
  pm.nk = {1};
  IdentifiedModel m;
  m.method = "arx";
  m.structure = "ARX";
  m.params = ModelParamsFromJson(pm.ParamsJson());
  m.discrete = pm.ToTransferFunction(0);
  m.tf = *m.discrete;  // kept discrete: the closed form below is the discrete one
  m.covariance = ParameterCovariance{{"a1", "b1"}, P};
  return m;
}

TEST(ModelUncertaintyTest, FirstOrderArxStepStdMatchesClosedForm) {
  const double a = -0.8, b = 0.3;
  Eigen::Matrix2d P;
  P << 4e-4, -1e-4, -1e-4, 9e-4;
  const IdentifiedModel m = FirstOrderArx(a, b, P);
  ASSERT_TRUE(HasCovariance(m));
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(31, 0.0, 3.0);
  const Eigen::VectorXd sd = StepResponseStd(m, t);
  ASSERT_EQ(sd.size(), t.size());
  // s(k) = b (1 - p^k) / (1 - p), p = -a: ds/db = (1 - p^k)/(1 - p),
  // ds/da = -b sum_{j=1}^{k-1} j p^(j-1).
  const double p = -a;
  for (Eigen::Index k = 0; k < t.size(); ++k) {
    const double dsdb = (1.0 - std::pow(p, static_cast<double>(k))) / (1.0 - p);
    double sum = 0.0;
    for (Eigen::Index j = 1; j < k; ++j) sum += static_cast<double>(j) * std::pow(p, j - 1.0);
    const Eigen::Vector2d J(-b * sum, dsdb);
    const double expected = std::sqrt(J.dot(P * J));
    EXPECT_NEAR(sd[k], expected, 1e-6 * expected + 1e-12) << "k = " << k;
  }
  EXPECT_EQ(sd[0], 0.0);  // the response is 0 at t = 0 whatever the parameters
}

TEST(ModelUncertaintyTest, FirstOrderArxBodeStdMatchesClosedForm) {
  const double a = -0.8, b = 0.3;
  Eigen::Matrix2d P;
  P << 4e-4, -1e-4, -1e-4, 9e-4;
  const IdentifiedModel m = FirstOrderArx(a, b, P);
  const Eigen::VectorXd w = LogSpace(-1.0, std::log10(M_PI / 0.1), 20);
  const BodeStd sd = BodeResponseStd(m, w);
  ASSERT_EQ(sd.magnitude_db.size(), w.size());
  for (Eigen::Index k = 0; k < w.size(); ++k) {
    // G = b z^-1 / (1 + a z^-1): d ln G / db = 1/b, d ln G / da = -z^-1 / (1 + a z^-1).
    const std::complex<double> zi = std::exp(std::complex<double>(0.0, -w[k] * 0.1));
    const std::complex<double> dlda = -zi / (1.0 + a * zi);
    const Eigen::Vector2d Jm = 20.0 / std::log(10.0) * Eigen::Vector2d(dlda.real(), 1.0 / b);
    const Eigen::Vector2d Jp = 180.0 / M_PI * Eigen::Vector2d(dlda.imag(), 0.0);
    EXPECT_NEAR(sd.magnitude_db[k], std::sqrt(Jm.dot(P * Jm)), 1e-5 * std::sqrt(Jm.dot(P * Jm)));
    EXPECT_NEAR(sd.phase_deg[k], std::sqrt(Jp.dot(P * Jp)), 1e-5 * std::sqrt(Jp.dot(P * Jp)));
  }
}

// Sample standard deviation of response(theta) with theta ~ N(theta0, P).
template <typename Response>
Eigen::MatrixXd MonteCarloStd(const IdentifiedModel& m, int samples, Response response) {
  const Eigen::VectorXd theta0 = CovarianceParameters(m);
  const Eigen::MatrixXd L = m.covariance->matrix.llt().matrixL();
  std::mt19937_64 gen(12345);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd sum, sum2;
  for (int s = 0; s < samples; ++s) {
    Eigen::VectorXd z(theta0.size());
    for (Eigen::Index i = 0; i < z.size(); ++i) z[i] = normal(gen);
    const Eigen::MatrixXd r = response(ModelWithParameters(m, theta0 + L * z));
    if (s == 0) {
      sum = Eigen::MatrixXd::Zero(r.rows(), r.cols());
      sum2 = sum;
    }
    sum += r;
    sum2 += r.cwiseProduct(r);
  }
  const double n = samples;
  return ((sum2 - sum.cwiseProduct(sum) / n) / (n - 1.0)).cwiseMax(0.0).cwiseSqrt();
}

// An ARX(2,2,1) model identified from noisy data: full covariance, continuous form.
IdentifiedModel IdentifiedArx() {
  PolynomialModel truth;
  truth.Ts = 0.1;
  truth.a = Eigen::Vector3d(1.0, -1.2, 0.36);
  truth.b = {Eigen::Vector3d(0.0, 0.1, 0.06)};
  truth.nk = {1};
  const Eigen::Index n = 600;
  const Eigen::VectorXd u = testing::Prbs(n, 0.0, 1.0, 5);
  const Eigen::VectorXd y = testing::SimulateArx(truth, u, testing::WhiteNoise(n, 0.05, 7));
  IdentifyRequest req;
  req.na = 2;
  req.nb = 2;
  req.nk = 1;
  return IdentifyParametric("arx", Dataset::FromUniform(0.1, u, y), req);
}

TEST(ModelUncertaintyTest, IdentifiedArxHasFullCovarianceThatSurvivesJson) {
  const IdentifiedModel m = IdentifiedArx();
  ASSERT_TRUE(m.covariance.has_value());
  EXPECT_EQ(m.covariance->names, (std::vector<std::string>{"a1", "a2", "b1", "b2"}));
  EXPECT_NE(m.covariance->matrix(0, 1), 0.0);  // correlations kept
  const IdentifiedModel back = IdentifiedModelFromJson(ToJson(m));
  ASSERT_TRUE(back.covariance.has_value());
  EXPECT_EQ(back.covariance->names, m.covariance->names);
  EXPECT_TRUE(back.covariance->matrix.isApprox(m.covariance->matrix, 1e-15));
  EXPECT_FALSE(ToJson(m).at("covariance").at("matrix").empty());
}

TEST(ModelUncertaintyTest, StepAndBodeStdMatchMonteCarlo) {
  const IdentifiedModel m = IdentifiedArx();
  ASSERT_TRUE(HasCovariance(m));
  ASSERT_FALSE(m.tf.IsDiscrete());
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(41, 0.0, 4.0);
  const Eigen::VectorXd w = LogSpace(-1.0, 1.3, 12);
  const Eigen::VectorXd sd = StepResponseStd(m, t);
  const BodeStd bsd = BodeResponseStd(m, w);
  const Eigen::MatrixXd mc_step = MonteCarloStd(
      m, 4000, [&t](const TransferFunction& g) -> Eigen::MatrixXd { return StepResponseAt(g, t); });
  const Eigen::MatrixXd mc_bode = MonteCarloStd(m, 4000, [&w](const TransferFunction& g) {
    const BodeData bd = Bode(g, w);
    Eigen::MatrixXd r(w.size(), 2);
    r << bd.magnitude_db, bd.phase_deg;
    return r;
  });
  for (Eigen::Index k = 2; k < t.size(); ++k)
    EXPECT_NEAR(sd[k], mc_step(k, 0), 0.10 * mc_step(k, 0)) << "t = " << t[k];
  for (Eigen::Index k = 0; k < w.size(); ++k) {
    EXPECT_NEAR(bsd.magnitude_db[k], mc_bode(k, 0), 0.10 * mc_bode(k, 0)) << "w = " << w[k];
    EXPECT_NEAR(bsd.phase_deg[k], mc_bode(k, 1), 0.10 * mc_bode(k, 1)) << "w = " << w[k];
  }
  // The discrete form agrees with the continuous (zoh) one at the samples.
  UncertaintyOptions discrete;
  discrete.discrete = true;
  EXPECT_TRUE(StepResponseStd(m, t, discrete).isApprox(sd, 1e-4));
}

TEST(ModelUncertaintyTest, ProcessModelDiagonalCovarianceMatchesClosedForm) {
  // K (1 - exp(-(t - theta) / tau)) for t > theta.
  IdentifiedModel m;
  m.method = "fit-p1d";
  m.structure = "P1D";
  m.params = {{"K", 2.0}, {"tau", 0.5}, {"theta", 0.1}, {"y0", 1.0}};
  m.param_std = {{"K", 0.05}, {"tau", 0.02}, {"theta", 0.01}, {"y0", 0.3}};
  ProcessParams p;
  p.K = 2.0;
  p.T1 = 0.5;
  p.theta = 0.1;
  m.tf = ProcessTransferFunction(ProcessStructure::kP1D, false, p);
  SetDiagonalCovariance(&m, {"K", "tau", "theta", "y0"});
  ASSERT_TRUE(m.covariance.has_value());
  EXPECT_DOUBLE_EQ(m.covariance->matrix(1, 1), 0.02 * 0.02);
  EXPECT_EQ(m.covariance->matrix(0, 1), 0.0);
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(301, 0.0, 3.0);
  const Eigen::VectorXd sd = StepResponseStd(m, t);
  for (Eigen::Index k = 0; k < t.size(); ++k) {
    const double s = t[k] - 0.1;
    if (s < 0.05) continue;  // the derivative w.r.t. the delay has a kink at t = theta
    const double e = std::exp(-s / 0.5);
    const double dK = 1.0 - e, dtau = -2.0 * e * s / 0.25, dtheta = -2.0 * e / 0.5;
    const double expected =
        std::sqrt(std::pow(0.05 * dK, 2) + std::pow(0.02 * dtau, 2) + std::pow(0.01 * dtheta, 2));
    EXPECT_NEAR(sd[k], expected, 1e-4 * expected) << "t = " << t[k];
  }
}

TEST(ModelUncertaintyTest, DelayAtItsBoundUsesOneSidedDifference) {
  // theta = 0 cannot be perturbed downwards: dy/dtheta by a forward difference.
  IdentifiedModel m;
  m.method = "fit-p1d";
  m.structure = "P1D";
  m.params = {{"K", 2.0}, {"tau", 0.5}, {"theta", 0.0}, {"y0", 0.0}};
  m.param_std = {{"K", 0.05}, {"tau", 0.02}, {"theta", 0.01}};
  ProcessParams p;
  p.K = 2.0;
  p.T1 = 0.5;
  m.tf = ProcessTransferFunction(ProcessStructure::kP1D, false, p);
  SetDiagonalCovariance(&m, {"K", "tau", "theta", "y0"});
  ASSERT_EQ(m.covariance->names.size(), 3u);  // y0 has no standard deviation
  const Eigen::VectorXd t = Eigen::VectorXd::LinSpaced(101, 0.0, 2.0);
  const Eigen::VectorXd sd = StepResponseStd(m, t);
  ASSERT_TRUE(sd.allFinite());
  for (Eigen::Index k = 5; k < t.size(); ++k) {
    const double e = std::exp(-t[k] / 0.5);
    const double dK = 1.0 - e, dtau = -2.0 * e * t[k] / 0.25, dtheta = -2.0 * e / 0.5;
    const double expected =
        std::sqrt(std::pow(0.05 * dK, 2) + std::pow(0.02 * dtau, 2) + std::pow(0.01 * dtheta, 2));
    EXPECT_NEAR(sd[k], expected, 1e-3 * expected) << "t = " << t[k];
  }
}

TEST(ModelUncertaintyTest, FitP1dGetsItsFullCovariance) {
  const TransferFunction g = TransferFunction::Continuous({1.5}, {0.4, 1.0}, 0.2);
  const Eigen::Index n = 400;
  Eigen::VectorXd u = Eigen::VectorXd::Zero(n);
  u.tail(n - 20).setConstant(1.0);
  const Eigen::VectorXd y = Lsim(g, u, 0.01) + testing::WhiteNoise(n, 0.01, 3);
  const IdentifiedModel m =
      IdentifyStepMethod("fit-p1d", Dataset::FromUniform(0.01, u, y), IdentifyRequest{});
  ASSERT_TRUE(m.covariance.has_value());
  EXPECT_EQ(m.covariance->names, (std::vector<std::string>{"K", "tau", "theta", "y0"}));
  EXPECT_NEAR(std::sqrt(m.covariance->matrix(0, 0)), m.param_std.Scalar("K"),
              1e-12 * m.param_std.Scalar("K"));
  EXPECT_NE(m.covariance->matrix(0, 1), 0.0);  // K and tau are correlated: not a diagonal
  const Eigen::VectorXd sd = StepResponseStd(m, Eigen::VectorXd::LinSpaced(50, 0.0, 2.0));
  ASSERT_EQ(sd.size(), 50);
  EXPECT_TRUE(sd.allFinite());
  EXPECT_GT(sd[49], 0.0);
}

TEST(ModelUncertaintyTest, ModelWithoutCovarianceHasNoBand) {
  IdentifiedModel m;
  m.method = "reaction-curve";
  m.structure = "FOPDT";
  m.params = {{"K", 1.0}, {"tau", 0.3}, {"theta", 0.0}};
  m.tf = TransferFunction::Continuous({1.0}, {0.3, 1.0});
  EXPECT_FALSE(HasCovariance(m));
  EXPECT_EQ(StepResponseStd(m, Eigen::VectorXd::LinSpaced(5, 0.0, 1.0)).size(), 0);
  EXPECT_EQ(BodeResponseStd(m, LogSpace(-1.0, 1.0, 5)).magnitude_db.size(), 0);
  EXPECT_THROW(CovarianceParameters(m), InvalidArgument);
  // A covariance naming a parameter the model does not have is not usable either.
  m.covariance = ParameterCovariance{{"b7"}, Eigen::MatrixXd::Identity(1, 1)};
  EXPECT_FALSE(HasCovariance(m));
  EXPECT_EQ(StepResponseStd(m, Eigen::VectorXd::LinSpaced(5, 0.0, 1.0)).size(), 0);
}

TEST(ModelUncertaintyTest, JsonWithoutCovarianceStillReadsAndBadCovarianceIsNamed) {
  const IdentifiedModel m = IdentifiedArx();
  nlohmann::json j = ToJson(m);
  j.erase("covariance");
  EXPECT_FALSE(IdentifiedModelFromJson(j).covariance.has_value());
  j["covariance"] = {{"names", {"a1", "a2"}}, {"matrix", {{1.0, 0.0}}}};
  try {
    IdentifiedModelFromJson(j);
    FAIL() << "expected InvalidArgument";
  } catch (const InvalidArgument& e) {
    EXPECT_NE(std::string(e.what()).find("'covariance.matrix' must be 2 rows"), std::string::npos)
        << e.what();
  }
  UncertaintyOptions bad;
  bad.relative_step = 0.0;
  EXPECT_THROW(StepResponseStd(m, Eigen::VectorXd::LinSpaced(5, 0.0, 1.0), bad), InvalidArgument);
}

}  // namespace
}  // namespace pneumid
