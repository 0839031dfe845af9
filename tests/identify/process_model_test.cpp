// Output-error process-model fitting (MATLAB procest structures) with Ceres.
#include "pneumid/identify/parametric/process_model.hpp"

#include <cmath>
#include <random>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include "pneumid/common/check.hpp"
#include "step_test_util.hpp"

namespace pneumid {
namespace {

using ::testing::HasSubstr;

// A pseudo-random binary input (seeded), switching at most every `hold` samples.
Eigen::VectorXd BinaryInput(int N, int hold, unsigned seed) {
  std::mt19937 gen(seed);
  std::bernoulli_distribution coin(0.5);
  Eigen::VectorXd u(N);
  double level = 0.0;
  for (int k = 0; k < N; ++k) {
    if (k >= 20 && k % hold == 0) level = coin(gen) ? 1.0 : -1.0;
    u[k] = level;
  }
  return u;
}

// Recorded SOPDT plant under ten alternating steps, 1 % noise
// (gen_synthetic_steps.py): the P2D fit recovers K, tau1, tau2 within 2 % and
// the delay within one sample (Ts = 0.01 s).
TEST(ProcessModelTest, P2dRecoversSopdtFromTenSteps) {
  const Dataset d = testing::LoadSynthetic("sopdt_steps");
  ProcessFitOptions o;
  o.structure = ProcessStructure::kP2D;
  const ProcessFitResult r = FitProcessModel(d, 0, 0, o);
  EXPECT_EQ(r.summary.termination, Termination::kConvergence) << r.summary.BriefReport();
  EXPECT_NEAR(r.params.K, 1.2, 0.02 * 1.2);
  EXPECT_NEAR(r.params.T1, 2.0, 0.02 * 2.0);
  EXPECT_NEAR(r.params.T2, 0.7, 0.02 * 0.7);
  EXPECT_NEAR(r.params.theta, 0.537, 0.01);
  EXPECT_THAT(r.summary.initial_guess, HasSubstr("first step"));
  // Standard deviations consistent with the actual errors and the noise (0.6).
  EXPECT_TRUE(r.summary.covariance_ok);
  EXPECT_LT(std::abs(r.params.T2 - 0.7), 4.0 * r.param_std.T2);
  EXPECT_NEAR(r.summary.sigma, 0.6, 0.05);
  // The full covariance: named like NamedParams, its diagonal the squared
  // standard deviations (after the lags are sorted, so the permutation is
  // checked), symmetric and positive semi-definite; gain and lags of a step
  // fit are correlated, which the diagonal alone would miss.
  ASSERT_EQ(r.covariance_names,
            (std::vector<std::string>{"K", "tau1", "tau2", "theta", "y0"}));
  ASSERT_EQ(r.covariance.rows(), 5);
  const double sd[] = {r.param_std.K, r.param_std.T1, r.param_std.T2, r.param_std.theta,
                       r.param_std.y0};
  for (int i = 0; i < 5; ++i)
    EXPECT_NEAR(std::sqrt(r.covariance(i, i)), sd[i], 1e-9 * sd[i]) << r.covariance_names[i];
  EXPECT_LT((r.covariance - r.covariance.transpose()).cwiseAbs().maxCoeff(),
            1e-12 * r.covariance.cwiseAbs().maxCoeff());
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(r.covariance);
  EXPECT_GE(eig.eigenvalues().minCoeff(), -1e-12 * eig.eigenvalues().maxCoeff());
  const double corr = r.covariance(0, 1) / (sd[0] * sd[1]);
  EXPECT_GT(std::abs(corr), 0.1);
  EXPECT_LE(std::abs(corr), 1.0);
}

// Any input: a binary pseudo-random input through each structure (noise-free,
// generated with the library's own simulation) is fitted back exactly from the
// grid-search initial guess; the delay is a fraction of a sample.
TEST(ProcessModelTest, AnyInputEveryStructure) {
  const double Ts = 0.05;
  const Eigen::VectorXd u = BinaryInput(1200, 7, 11);
  struct Case {
    ProcessStructure s;
    bool zero;
    ProcessParams p;
  };
  std::vector<Case> cases;
  ProcessParams p;
  p.K = 1.7;
  p.T1 = 1.3;
  p.theta = 0.37;
  p.y0 = 4.0;
  cases.push_back({ProcessStructure::kP1D, false, p});
  p.T2 = 0.4;
  cases.push_back({ProcessStructure::kP2D, false, p});
  p.T3 = 0.15;
  cases.push_back({ProcessStructure::kP3D, false, p});
  ProcessParams q = p;
  q.Tw = 0.6;
  q.zeta = 0.3;
  cases.push_back({ProcessStructure::kP2DU, false, q});
  ProcessParams z = p;
  z.Tz = 0.5;
  cases.push_back({ProcessStructure::kP2D, true, z});
  for (const Case& c : cases) {
    const TransferFunction g = ProcessTransferFunction(c.s, c.zero, c.p);
    Eigen::VectorXd y = Lsim(g, u, Ts).array() + c.p.y0;
    const Dataset d = Dataset::FromUniform(Ts, u, y);
    ProcessFitOptions o;
    o.structure = c.s;
    o.zero = c.zero;
    const ProcessFitResult r = FitProcessModel(d, 0, 0, o);
    const std::string what = ToString(c.s) + (c.zero ? "Z" : "") + ": " + r.summary.BriefReport();
    EXPECT_NE(r.summary.termination, Termination::kFailure) << what;
    for (const auto& [name, value] : NamedParams(c.s, c.zero, c.p)) {
      const auto fitted = NamedParams(c.s, c.zero, r.params);
      for (const auto& [n2, v2] : fitted) {
        if (n2 == name)
          EXPECT_NEAR(v2, value, 1e-3 * std::max(1.0, std::abs(value))) << what << " " << name;
      }
    }
  }
}

// Inputs that change from the first sample (white noise, a binary sequence
// switching at once, a chirp) of a plant at rest at u = 0 before the record:
// the input before the first change, u(0), is no rest, and simulated from it
// the fits carried a transient no lag fits (a SOPDT K 1.5, tau 0.8 s and
// 0.3 s, theta 0.4 s under white noise: K 0.95, fit 50 %; an integrator
// under a binary input: K = -0.008). The grid search also tries the rest at
// zero and at the input's mean, and sample delays; noise-free data give the
// plant back.
TEST(ProcessModelTest, InputsWithoutARestAtTheStartGiveThePlantBack) {
  const double Ts = 0.05;
  const int N = 2000;
  std::mt19937 gen(17);
  std::normal_distribution<double> normal(0.0, 1.0);
  Eigen::VectorXd white(N), chirp(N);
  for (int k = 0; k < N; ++k) {
    white[k] = normal(gen);
    const double t = k * Ts;
    chirp[k] = std::cos(2.0 * M_PI * (0.01 + 0.5 * (2.0 - 0.01) * t / (N * Ts)) * t);
  }
  Eigen::VectorXd binary = BinaryInput(N + 20, 6, 5).tail(N);
  binary[0] = binary[0] == 0.0 ? 1.0 : binary[0];
  const ProcessParams sopdt{.K = 1.5, .T1 = 0.8, .T2 = 0.3, .theta = 0.4};
  const ProcessParams integrator{.K = 0.5, .T1 = 0.3, .theta = 0.1};
  struct Case {
    const char* name;
    const Eigen::VectorXd* u;
    ProcessStructure s;
    ProcessParams p;
  };
  const Case cases[] = {{"white, P2D", &white, ProcessStructure::kP2D, sopdt},
                        {"binary, P2D", &binary, ProcessStructure::kP2D, sopdt},
                        {"chirp, P2D", &chirp, ProcessStructure::kP2D, sopdt},
                        {"binary, P1DI", &binary, ProcessStructure::kP1DI, integrator},
                        {"white, P1DI", &white, ProcessStructure::kP1DI, integrator}};
  for (const Case& c : cases) {
    const TransferFunction g = ProcessTransferFunction(c.s, false, c.p);
    const Dataset d = Dataset::FromUniform(Ts, *c.u, Lsim(g, *c.u, Ts));
    ProcessFitOptions o;
    o.structure = c.s;
    const ProcessFitResult r = FitProcessModel(d, 0, 0, o);
    const std::string what = std::string(c.name) + ": " + r.summary.BriefReport();
    EXPECT_EQ(r.summary.termination, Termination::kConvergence) << what;
    EXPECT_EQ(r.params.u0, 0.0) << what;
    for (const auto& [name, value] : NamedParams(c.s, false, c.p)) {
      for (const auto& [n2, v2] : NamedParams(c.s, false, r.params)) {
        if (n2 == name)
          EXPECT_NEAR(v2, value, 2e-3 * std::max(1.0, std::abs(value))) << what << " " << name;
      }
    }
  }
}

TEST(ProcessModelTest, IntegratingProcess) {
  // K / (s (T s + 1)) exp(-theta s), step input.
  ProcessParams p;
  p.K = 0.5;
  p.T1 = 0.8;
  p.theta = 0.2;
  const TransferFunction g = ProcessTransferFunction(ProcessStructure::kP1DI, false, p);
  const Dataset d = testing::MakeStepData(g, 0.02, 50, 500, 1.0, 3.0, 0.01, 5);
  ProcessFitOptions o;
  o.structure = ProcessStructure::kP1DI;
  const ProcessFitResult r = FitProcessModel(d, 0, 0, o);
  EXPECT_NEAR(r.params.K, 0.5, 0.01);
  EXPECT_NEAR(r.params.T1, 0.8, 0.03);
  EXPECT_NEAR(r.params.theta, 0.2, 0.02);
}

TEST(ProcessModelTest, RobustLossResistsOutliers) {
  const TransferFunction g = TransferFunction::Fopdt(2.0, 1.0, 0.3);
  Dataset clean = testing::MakeStepData(g, 0.02, 50, 600, 0.0, 1.0, 0.02, 9);
  Eigen::VectorXd y = clean.y(0);
  for (int k = 100; k < 600; k += 37) y[k] += 1.5;  // spikes of 75 % of the step
  const Dataset d = Dataset::FromUniform(0.02, clean.u(0), y);
  ProcessFitOptions o;
  const ProcessFitResult ls = FitProcessModel(d, 0, 0, o);
  o.loss = RobustLoss::kCauchy;
  const ProcessFitResult rob = FitProcessModel(d, 0, 0, o);
  EXPECT_LT(std::abs(rob.params.K - 2.0), std::abs(ls.params.K - 2.0));
  EXPECT_NEAR(rob.params.K, 2.0, 0.01);
  EXPECT_NEAR(rob.params.T1, 1.0, 0.02);
}

TEST(ProcessModelTest, NamesAndErrors) {
  bool zero = false;
  EXPECT_EQ(ProcessStructureFromString("p2dz", &zero), ProcessStructure::kP2D);
  EXPECT_TRUE(zero);
  EXPECT_EQ(ToString(ProcessStructureFromString("P1DI")), "P1DI");
  EXPECT_THAT([] { ProcessStructureFromString("P9"); },
              ::testing::ThrowsMessage<InvalidArgument>(HasSubstr("P9")));
  EXPECT_EQ(RobustLossFromString("huber"), RobustLoss::kHuber);
  EXPECT_THROW(RobustLossFromString("l1"), InvalidArgument);
  ProcessFitOptions o;
  o.max_iterations = 0;
  std::string why;
  EXPECT_FALSE(o.IsValid(&why));
  const Dataset flat =
      Dataset::FromUniform(0.1, Eigen::VectorXd::Ones(50), Eigen::VectorXd::LinSpaced(50, 0, 1));
  EXPECT_THAT([&] { FitProcessModel(flat, 0, 0, {}); },
              ::testing::ThrowsMessage<DataError>(HasSubstr("never changes")));
  EXPECT_THROW(FitProcessModel(flat, 0, 0, o), InvalidArgument);
  ProcessParams bad;
  bad.K = 1.0;
  bad.T1 = -1.0;
  EXPECT_THROW(ProcessTransferFunction(ProcessStructure::kP1D, false, bad), InvalidArgument);
}

}  // namespace
}  // namespace pneumid
