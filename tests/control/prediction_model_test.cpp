// The sampled prediction model: step response against the closed form of the
// zoh-sampled FOPDT, the dynamic matrix of the paper's tuning
// (lambda_max(A'A)/500 = 2.250797, gen_dmc_reference.py), and one sampled
// model serving tuning, DMC and GPC of a design with the results of the
// designs that sampled the model themselves; its state space is the MPC's
// model (SampledStateSpace) from the same discretization.
#include "pneumid/control/prediction_model.hpp"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <Eigen/Eigenvalues>

#include "pneumid/common/check.hpp"
#include "pneumid/control/controller_factory.hpp"
#include "pneumid/control/dmc.hpp"
#include "pneumid/control/gpc.hpp"
#include "pneumid/control/mpc.hpp"
#include "pneumid/control/tuning.hpp"
#include "pneumid/lti/conversion.hpp"
#include "pneumid/models/model_file.hpp"

namespace pneumid {
namespace {

constexpr double kTs = 0.01;

TransferFunction PaperFopdt() { return TransferFunction::Fopdt(1.6, 0.245, 0.001); }

TEST(PredictionModelTest, FopdtStepResponseIsTheSampledClosedForm) {
  // Sampled step response of K exp(-theta s)/(tau s + 1) under a zoh:
  // s_i = K (1 - exp(-(i Ts - theta)/tau)) for i Ts >= theta (exact).
  const Eigen::VectorXd s = PredictionModel(PaperFopdt(), kTs).StepResponse(200);
  ASSERT_EQ(s.size(), 201);
  EXPECT_NEAR(s(0), 0.0, 1e-12);
  for (int i = 1; i <= 200; ++i) {
    const double expected = 1.6 * (1.0 - std::exp(-(i * kTs - 0.001) / 0.245));
    EXPECT_NEAR(s(i), expected, 1e-10) << "i = " << i;
  }
}

TEST(PredictionModelTest, DiscreteArxUsesItsDifferenceEquation) {
  // Paper Eq. 5: y = (b1 q^-1 + b2 q^-2 + b3 q^-3) / (1 + a1 q^-1 + ...) u.
  const TransferFunction arx = PaperArxModel();
  const Eigen::VectorXd s = PredictionModel(arx, kTs).StepResponse(400);
  EXPECT_NEAR(s(0), 0.0, 1e-15);
  EXPECT_NEAR(s(1), 0.03938, 1e-12);                                // b1
  EXPECT_NEAR(s(2), 0.03938 + 0.04506 + 0.60870 * 0.03938, 1e-12);  // b1 + b2 - a1 s1
  EXPECT_NEAR(s(400), 1.59796, 1e-4);  // static gain, docs/paper.md, reference value 2
  EXPECT_THROW(PredictionModel(arx, 0.02), InvalidArgument);
}

TEST(DynamicMatrixTest, LowerTriangularToeplitzOfStepResponse) {
  Eigen::VectorXd s(5);
  s << 0, 1, 3, 6, 10;
  const Eigen::MatrixXd A = DynamicMatrix(s, 6, 3);
  Eigen::MatrixXd expected(6, 3);
  expected << 1, 0, 0, 3, 1, 0, 6, 3, 1, 10, 6, 3, 10, 10, 6, 10, 10, 10;
  EXPECT_EQ(A, expected);
  EXPECT_THROW(DynamicMatrix(s, 2, 3), InvalidArgument);
}

TEST(PredictionModelTest, DynamicMatrixOfThePaperTuning) {
  const PredictionModel pm(PaperFopdt(), kTs);
  const Eigen::MatrixXd A = pm.DynamicMatrix(126, 5);
  EXPECT_EQ(A, DynamicMatrix(pm.StepResponse(126), 126, 5));
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(A.transpose() * A,
                                                           Eigen::EigenvaluesOnly);
  EXPECT_NEAR(eig.eigenvalues().maxCoeff() / 500.0, 2.250797, 1e-5);  // gen_dmc_reference.py
  EXPECT_THAT([&] { pm.DynamicMatrix(4, 5); },
              ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr("1 <= M <= P")));
}

TEST(PredictionModelTest, DiscreteModelIsUsedAtItsOwnSampleTime) {
  const PredictionModel pm(PaperArxModel(), kTs);
  EXPECT_EQ(pm.sampled().num(), PaperArxModel().num());
  EXPECT_EQ(pm.sampled().den(), PaperArxModel().den());
  EXPECT_THAT([] { PredictionModel(PaperArxModel(), 0.02); },
              ::testing::ThrowsMessage<InvalidArgument>(
                  ::testing::HasSubstr("the controller runs at Ts = 0.02 s")));
  EXPECT_THAT([] { PredictionModel(PaperFopdt(), -1.0); },
              ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr("Ts = -1")));
}

TEST(PredictionModelTest, SettlingHorizonRejectsUnstableModels) {
  const PredictionModel unstable(TransferFunction::Continuous({1.0}, {1.0, -1.0}), kTs);
  EXPECT_FALSE(unstable.IsStable());
  EXPECT_THAT([&] { unstable.SettlingHorizon(); },
              ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr("not stable")));
  const PredictionModel pm(PaperFopdt(), kTs);
  const int N = pm.SettlingHorizon();
  const Eigen::VectorXd s = pm.StepResponse(N);
  EXPECT_LE(std::abs(s(N) - 1.6), 1e-9 * 1.6);
  EXPECT_GT(std::abs(pm.StepResponse(N - 1)(N - 1) - 1.6), 1e-9 * 1.6);
}

// One design, one sampled model: tuning, DMC and GPC built from the same
// PredictionModel give exactly what each gave when it sampled the model
// itself (the paper's P = 126, lambda = 2.2508).
TEST(PredictionModelTest, OneSampledModelServesTuningDmcAndGpc) {
  const PredictionModel pm(PaperFopdt(), kTs);
  TuningOptions to;
  to.M = 5;
  const TuningResult shared = Tune(pm, to);
  const TuningResult own = Tune(PaperFopdt(), kTs, to);
  EXPECT_EQ(shared.P, 126);
  EXPECT_NEAR(shared.lambda, 2.2508, 5e-5);
  EXPECT_EQ(shared.P, own.P);
  EXPECT_EQ(shared.lambda, own.lambda);
  EXPECT_EQ(shared.Ts, kTs);

  DmcOptions d;
  d.P = shared.P;
  d.M = shared.M;
  d.lambda = shared.lambda;
  const DmcController dmc_shared(pm, d);
  const DmcController dmc_own(PaperFopdt(), kTs, d);
  const DmcController dmc_sampled(pm.sampled(), kTs, d);  // discrete: used as is
  EXPECT_EQ(dmc_shared.step_coefficients(), dmc_own.step_coefficients());
  EXPECT_EQ(dmc_shared.step_coefficients(), dmc_sampled.step_coefficients());
  EXPECT_EQ(dmc_shared.gain(), dmc_own.gain());
  EXPECT_EQ(dmc_shared.dynamic_matrix(), pm.DynamicMatrix(d.P, d.M));
  EXPECT_EQ(dmc_shared.Ts(), kTs);

  GpcOptions g;
  g.N2 = shared.P;
  g.Nu = shared.M;
  g.lambda = shared.lambda;
  const GpcController gpc(pm, g);
  EXPECT_LT((gpc.dynamic_matrix() - pm.DynamicMatrix(g.N2, g.Nu)).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((gpc.gain() - dmc_shared.gain()).cwiseAbs().maxCoeff(), 1e-9);
  const CarimaModel c = ToCarima(pm);
  EXPECT_EQ(c.Ts, kTs);
  EXPECT_EQ(c.A, ToCarima(PaperFopdt(), kTs).A);
}

TEST(PredictionModelTest, FactoryDesignsFromOneSampledModel) {
  const PredictionModel pm(PaperFopdt(), kTs);
  for (ControllerType type : {ControllerType::kDmc, ControllerType::kGpc}) {
    ControllerSpec spec;
    spec.type = type;
    spec.tuning.M = 5;
    const BuiltController shared = MakeController(pm, spec);
    const BuiltController own = MakeController(PaperFopdt(), kTs, spec);
    EXPECT_EQ(shared.tuning.P, 126);
    EXPECT_EQ(shared.tuning.lambda, own.tuning.lambda);
    EXPECT_EQ(shared.controller->Describe(), own.controller->Describe());
    EXPECT_EQ(shared.controller->Ts(), kTs);
  }
  ControllerSpec pid;
  pid.type = ControllerType::kPid;
  const BuiltController p = MakeController(pm, pid);
  EXPECT_EQ(p.fopdt.method, "exact");
  EXPECT_NEAR(p.fopdt.tau, 0.245, 1e-12);
}

// The one discretization of a design: the sampled state space is the zoh
// discretization of the model's realization, its transfer function is
// sampled() and, with the delay as states, it is the MPC's model
// (SampledStateSpace), all to the last bit: a continuous model with a
// fractional and with a whole-sample delay, and a discrete ARX with delay.
TEST(PredictionModelTest, SampledStateSpaceIsTheOneDiscretization) {
  const TransferFunction models[] = {
      PaperFopdt(), TransferFunction::Sopdt(2.0, 0.4, 0.15, 0.03),
      TransferFunction::Discrete({0.0, 0.1, 0.05}, {1.0, -1.2, 0.35}, kTs, 2)};
  for (const TransferFunction& g : models) {
    SCOPED_TRACE(g.ToString());
    const PredictionModel pm(g, kTs);
    const StateSpace& ss = pm.sampled_state_space();
    EXPECT_EQ(ss.Ts(), kTs);
    EXPECT_EQ(ss.delay(), pm.sampled().delay());
    const TransferFunction expected_tf =
        g.IsContinuous() ? C2D(g, kTs, DiscretizationMethod::kZoh) : g;
    EXPECT_EQ(pm.sampled().num(), expected_tf.num());
    EXPECT_EQ(pm.sampled().den(), expected_tf.den());
    const StateSpace with_delay = DelayAsStates(ss);
    const StateSpace mpc_model = SampledStateSpace(g, kTs);
    EXPECT_EQ(with_delay.A(), mpc_model.A());
    EXPECT_EQ(with_delay.B(), mpc_model.B());
    EXPECT_EQ(with_delay.C(), mpc_model.C());
    EXPECT_EQ(with_delay.D(), mpc_model.D());
    EXPECT_EQ(with_delay.delay(), 0.0);
    // The state space and the transfer function describe one model.
    EXPECT_NEAR(ss.DcGain()(0, 0), pm.sampled().DcGain(), 1e-9 * std::abs(pm.sampled().DcGain()));
  }
}

}  // namespace
}  // namespace pneumid
