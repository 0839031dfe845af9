// State-space MPC (mpc.hpp): agreement with an independent numpy/scipy
// computation (tests/control/gen_mpc_reference.py: Kalman DARE and gain,
// unconstrained first-move gain, constrained steps by SLSQP + KKT), offset-
// free tracking under model error and an output disturbance, the sampled
// transfer-function path, input limits on the IPA simulator, and bad input.
#include <algorithm>
#include <cmath>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/control/mpc.hpp"
#include "pneumid/models/model_file.hpp"
#include "pneumid/plant/linear_plant.hpp"
#include "pneumid/plant/plant_factory.hpp"
#include "pneumid/plant/signal.hpp"

namespace pneumid {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

constexpr double kTs = 0.01;

Eigen::VectorXd Vec(std::initializer_list<double> v) {
  Eigen::VectorXd x(static_cast<Eigen::Index>(v.size()));
  int i = 0;
  for (double e : v) x(i++) = e;
  return x;
}

void ExpectNearRel(const Eigen::VectorXd& actual, const Eigen::VectorXd& expected, double rel,
                   const char* what) {
  ASSERT_EQ(actual.size(), expected.size()) << what;
  EXPECT_LE((actual - expected).norm(), rel * expected.norm())
      << what << "\n actual   " << actual.transpose() << "\n expected " << expected.transpose();
}

// The paper's FOPDT 1.6 exp(-0.001 s)/(0.245 s + 1) sampled at 0.01 s in the
// closed form of gen_mpc_reference.py (modified z-transform), states [y, u(k-1)].
StateSpace PaperFopdtStateSpace() {
  const double K = 1.6, tau = 0.245, theta = 0.001;
  const double a = std::exp(-kTs / tau);
  const double b0 = K * (1.0 - std::exp(-(kTs - theta) / tau));
  const double b1 = K * std::exp(-(kTs - theta) / tau) * (1.0 - std::exp(-theta / tau));
  Eigen::MatrixXd A(2, 2), B(2, 1), C(1, 2);
  A << a, b1, 0.0, 0.0;
  B << b0, 1.0;
  C << 1.0, 0.0;
  return StateSpace(A, B, C, Eigen::MatrixXd::Zero(1, 1), kTs);
}

MpcOptions FopdtOptions() {
  MpcOptions o;  // the reference case "fopdt"
  o.P = 126;
  o.M = 5;
  o.lambda = 2.25;
  o.output_weight = 1.0;
  o.measurement_noise = 1.0;
  o.state_noise = 0.01;
  o.disturbance_noise = 1.0;
  o.disturbance = DisturbanceModel::kOutput;
  return o;
}

TEST(MpcTest, FopdtGainsMatchScipyReference) {
  const MpcController c(PaperFopdtStateSpace(), FopdtOptions());
  // gen_mpc_reference.py, case fopdt
  EXPECT_NEAR(c.static_gain(), 1.6, 1e-12);
  const Eigen::VectorXd X = Vec({0.1272829854721152, 5.294741255407081e-18, -0.11922812853402176,
                                 5.294741255407081e-18, 0.01, 8.5770116713974251e-17,
                                 -0.11922812853402176, 8.5770116713974251e-17, 1.7408585743307168});
  const Eigen::MatrixXd Xm = c.estimator_covariance().transpose();  // row-major
  ExpectNearRel(Eigen::Map<const Eigen::VectorXd>(Xm.data(), Xm.size()), X, 1e-10, "X");
  ExpectNearRel(c.kalman_gain(),
                Vec({0.0030630497610176556, 3.4629564942495891e-17, 0.6166633110472387}), 1e-10,
                "L");
  const MpcGain& k = c.gain();
  EXPECT_NEAR(k.K_r, 0.67205850213187857, 1e-10);
  EXPECT_NEAR(k.K_s, 0.0, 1e-14);
  EXPECT_NEAR(k.K_u, 0.26775774087719079, 1e-10);
  ExpectNearRel(k.K_z.transpose(),
                Vec({0.5026540720680821, 0.0032893472248819449, 0.67205850213187857}), 1e-10,
                "K_z");
  EXPECT_EQ(c.dare_summary().status, DareStatus::kConverged);
  EXPECT_EQ(c.Describe(), "mpc P=126 M=5 lambda=2.25 disturbance=output");
  EXPECT_FALSE(c.constrained());
}

TEST(MpcTest, SecondOrderInputDisturbanceWithDelayMatchesScipyReference) {
  // x+ = [1.6 -0.64; 1 0] x + [1; 0] u(k-2), y = [0.1 0.08] x: delay as two states.
  Eigen::MatrixXd A(2, 2), B(2, 1), C(1, 2);
  A << 1.6, -0.64, 1.0, 0.0;
  B << 1.0, 0.0;
  C << 0.1, 0.08;
  const StateSpace model(A, B, C, Eigen::MatrixXd::Zero(1, 1), 0.05, 0.1);
  MpcOptions o;
  o.P = 30;
  o.M = 4;
  o.lambda = 0.5;
  o.output_weight = 2.0;
  o.input_weight = 0.1;
  o.disturbance = DisturbanceModel::kInput;
  o.measurement_noise = 0.1;
  o.state_noise = 0.01;
  o.disturbance_noise = 0.5;
  const MpcController c(model, o);
  ASSERT_EQ(c.Az().rows(), 5);
  EXPECT_NEAR(c.static_gain(), 4.5000000000000089, 1e-12);
  const Eigen::MatrixXd Xm = c.estimator_covariance().transpose();
  ExpectNearRel(Eigen::Map<const Eigen::VectorXd>(Xm.data(), Xm.size()),
                Vec({11.208616168940035, 5.7958610711578178, 3.1184040580370955, 3.1184040580370969,
                     3.1184040580370951, 5.7958610711578178, 3.5537386511973827, 1.160742504327839,
                     1.1607425043278394, 1.1607425043278385, 3.1184040580370955, 1.160742504327839,
                     2.3210089801901406, 1.8210089801901397, 2.3210089801901406, 3.1184040580370969,
                     1.1607425043278394, 1.8210089801901397, 1.8210089801901392, 1.8210089801901397,
                     3.1184040580370951, 1.1607425043278385, 2.3210089801901406, 1.8210089801901397,
                     2.8210089801901397}),
                1e-9, "X");
  ExpectNearRel(c.kalman_gain(),
                Vec({4.8373177450546514, 2.6373030983086081, 1.2354836656748032, 1.2354836656748034,
                     1.2354836656748027}),
                1e-9, "L");
  EXPECT_NEAR(c.gain().K_r, 1.0503321468952587, 1e-9);
  EXPECT_NEAR(c.gain().K_s, 0.014227507129199509, 1e-11);
  EXPECT_NEAR(c.gain().K_u, 0.73384591457135162, 1e-9);
  ExpectNearRel(c.gain().K_z.transpose(),
                Vec({0.37898769769590002, -0.24963317305144841, 0.38296130458236921,
                     0.39005183289288947, 0.71961840744206051}),
                1e-9, "K_z");
}

struct ConstrainedCase {
  double y_max;
  std::vector<double> moves;
};

class MpcConstrainedStepTest : public ::testing::TestWithParam<ConstrainedCase> {};

TEST_P(MpcConstrainedStepTest, MatchesIndependentQpSolution) {
  MpcOptions o = FopdtOptions();
  o.limits.u_min = 0.0;
  o.limits.u_max = 0.9;
  o.limits.du_max = 0.25;
  o.y_max = GetParam().y_max;
  MpcController c(PaperFopdtStateSpace(), o);
  EXPECT_TRUE(c.constrained());
  c.Reset(0.1, 0.2);
  const double u = c.Update(1.0, 0.25);
  const std::vector<double>& m = GetParam().moves;
  EXPECT_TRUE(c.last_step_constrained());
  EXPECT_EQ(c.last_qp_summary().status, QpStatus::kSolved);
  EXPECT_NEAR(u, 0.1 + m[0], 1e-10);
  for (int j = 0; j < 5; ++j) EXPECT_NEAR(c.planned_moves()(j), m[j], 1e-9) << "move " << j;
}

// gen_mpc_reference.py: SLSQP, active set refined to a KKT point.
INSTANTIATE_TEST_SUITE_P(
    Reference, MpcConstrainedStepTest,
    ::testing::Values(
        ConstrainedCase{std::numeric_limits<double>::infinity(),
                        {0.24999999999999981, 0.25000000000000006, 0.21896207371702206,
                         0.0090266596967056734, -0.18957856207747131}},
        ConstrainedCase{0.8,
                        {0.24999999999999969, 0.25000000000000006, 0.20559931485703978,
                         -0.097944214355748155, -0.25000000000000649}}));

struct Loop {
  std::vector<double> r, y, u;
};

// The sampled loop of controller.hpp: y_k = Measure(), u_k = Update(r_k, y_k),
// Advance(u_k), with an output (load) disturbance of `load` from t = load_at.
Loop RunLoop(Controller& c, Plant& plant, const Signal& setpoint, double duration, double load,
             double load_at) {
  plant.Reset();
  const int n = static_cast<int>(std::lround(duration / plant.Ts()));
  Loop loop;
  c.Reset(0.0, plant.Measure());
  for (int k = 0; k < n; ++k) {
    const double t = k * plant.Ts();
    plant.SetLoadDisturbance(t >= load_at - 1e-12 ? load : 0.0);
    const double y = plant.Measure();
    const double r = setpoint(t);
    const double u = c.Update(r, y);
    plant.Advance(u);
    loop.r.push_back(r);
    loop.y.push_back(y);
    loop.u.push_back(u);
  }
  return loop;
}

// Steady-state |r - y| over the last 0.5 s of a run where the plant has 20 %
// more gain than the model and a constant output disturbance of 0.3 from 1 s.
double OffsetWithModelError(DisturbanceModel dm, bool constrained) {
  const TransferFunction model = TransferFunction::Fopdt(1.6, 0.245, 0.001);
  const TransferFunction plant_tf = TransferFunction::Fopdt(1.6 * 1.2, 0.245, 0.001);
  LinearPlant plant(plant_tf, kTs);
  MpcOptions o;
  o.disturbance = dm;
  if (constrained) {
    o.limits.u_min = -5.0;
    o.limits.u_max = 5.0;
    o.limits.du_max = 0.5;
  }
  MpcController c(model, kTs, o);
  EXPECT_EQ(c.constrained(), constrained);
  const auto sp = ParseSignal("step:from=0,to=1,at=0.2");
  const Loop r = RunLoop(c, plant, *sp, 8.0, 0.3, 1.0);
  double worst = 0.0;
  for (std::size_t k = r.y.size() - 50; k < r.y.size(); ++k)
    worst = std::max(worst, std::abs(r.r[k] - r.y[k]));
  return worst;
}

TEST(MpcTest, OffsetFreeWithOutputDisturbanceModel) {
  EXPECT_LT(OffsetWithModelError(DisturbanceModel::kOutput, false), 1e-6);
  EXPECT_LT(OffsetWithModelError(DisturbanceModel::kOutput, true), 1e-6);
}

TEST(MpcTest, OffsetFreeWithInputDisturbanceModel) {
  EXPECT_LT(OffsetWithModelError(DisturbanceModel::kInput, false), 1e-6);
  EXPECT_LT(OffsetWithModelError(DisturbanceModel::kInput, true), 1e-6);
}

TEST(MpcTest, OffsetWithoutDisturbanceModel) {
  EXPECT_GT(OffsetWithModelError(DisturbanceModel::kNone, false), 1e-3);
}

// An integrating plant y(k+1) = y(k) + K Ts (u(k) + d) with a constant input
// disturbance d (a friction force, in input units): its only steady state on
// the set-point has u = -d. The input disturbance model gets there (u_s =
// -d^, d^ -> d); without a disturbance model (u_s = 0) an offset remains.
struct IntegratorRun {
  double error = 0.0, u = 0.0, d_hat = 0.0;
};
IntegratorRun RunIntegrator(DisturbanceModel dm, double d) {
  const double K = 0.004;  // m/s per %
  MpcOptions o;
  o.P = 40;
  o.M = 5;
  o.lambda = 1e-5;
  o.disturbance = dm;
  o.measurement_noise = 1e-10;
  o.state_noise = dm == DisturbanceModel::kNone ? 1e-6 : 0.0;
  MpcController c(TransferFunction::Continuous({K}, {1.0, 0.0}), kTs, o);
  EXPECT_TRUE(c.integrating());
  EXPECT_TRUE(std::isinf(c.static_gain()));
  double y = 0.05, u = 0.0;
  c.Reset(0.0, y);
  for (int k = 0; k < 3000; ++k) {
    u = c.Update(0.07, y);
    y += K * kTs * (u + d);
  }
  return {0.07 - y, u, c.disturbance_estimate()};
}

TEST(MpcTest, IntegratingModelIsOffsetFreeWithTheInputDisturbanceModel) {
  const IntegratorRun with = RunIntegrator(DisturbanceModel::kInput, 2.0);
  EXPECT_NEAR(with.error, 0.0, 1e-9);
  EXPECT_NEAR(with.u, -2.0, 1e-6);
  EXPECT_NEAR(with.d_hat, 2.0, 1e-6);
  // No disturbance: the plant's integrator alone removes the offset.
  const IntegratorRun none_clean = RunIntegrator(DisturbanceModel::kNone, 0.0);
  EXPECT_NEAR(none_clean.error, 0.0, 1e-9);
  EXPECT_NEAR(none_clean.u, 0.0, 1e-6);
  // With the disturbance and no model of it, the state feedback holds an offset.
  EXPECT_GT(std::abs(RunIntegrator(DisturbanceModel::kNone, 2.0).error), 1e-5);
}

TEST(MpcTest, TransferFunctionPathEqualsExplicitStateSpace) {
  // With no state noise the filter, and hence the loop, does not depend on
  // the realization: zoh with the fractional delay (C2D) equals the closed form.
  MpcOptions o = FopdtOptions();
  o.state_noise = 0.0;
  MpcController a(TransferFunction::Fopdt(1.6, 0.245, 0.001), kTs, o);
  MpcController b(PaperFopdtStateSpace(), o);
  EXPECT_NEAR(a.static_gain(), 1.6, 1e-12);
  a.Reset(0.1, 0.3);
  b.Reset(0.1, 0.3);
  double y = 0.3, max_diff = 0.0;
  for (int k = 0; k < 300; ++k) {
    const double r = k < 150 ? 1.0 : -0.5;
    const double ua = a.Update(r, y), ub = b.Update(r, y);
    max_diff = std::max(max_diff, std::abs(ua - ub));
    y = 0.95 * y + 0.09 * ua;  // a plant other than the model
  }
  EXPECT_LT(max_diff, 1e-9);
}

// An MPC from a design's sampled model (PredictionModel) is the MPC that
// samples the transfer function itself: same matrices, same moves, for a
// continuous model with a fractional delay and a discrete one with delay,
// constrained and not.
TEST(MpcTest, FromThePredictionModelEqualsFromTheTransferFunction) {
  const TransferFunction models[] = {TransferFunction::Fopdt(1.6, 0.245, 0.001),
                                     TransferFunction::Discrete({0.0, 0.1}, {1.0, -0.9}, kTs, 2)};
  for (const TransferFunction& g : models) {
    for (bool limited : {false, true}) {
      SCOPED_TRACE(g.ToString() + (limited ? " limited" : ""));
      MpcOptions o;
      o.P = 60;
      o.lambda = 0.5;
      o.state_noise = 0.01;
      if (limited) {
        o.limits.u_min = -0.5;
        o.limits.u_max = 0.8;
      }
      MpcController own(g, kTs, o);
      MpcController shared(PredictionModel(g, kTs), o);
      EXPECT_EQ(own.Az(), shared.Az());
      EXPECT_EQ(own.Bz(), shared.Bz());
      EXPECT_EQ(own.Cz(), shared.Cz());
      EXPECT_EQ(own.kalman_gain(), shared.kalman_gain());
      EXPECT_EQ(own.hessian(), shared.hessian());
      EXPECT_EQ(own.constrained(), shared.constrained());
      own.Reset(0.0, 0.0);
      shared.Reset(0.0, 0.0);
      double y = 0.0;
      for (int k = 0; k < 200; ++k) {
        const double r = k < 100 ? 1.0 : -0.3;
        const double u_own = own.Update(r, y);
        ASSERT_EQ(u_own, shared.Update(r, y)) << "k = " << k;
        y = 0.93 * y + 0.1 * u_own;  // a plant other than the model
      }
    }
  }
}

TEST(MpcTest, DiscreteTransferFunctionWithDelay) {
  // y(k) = 0.9 y(k-1) + 0.1 u(k-3): static gain 1, 3 samples of delay.
  const TransferFunction g = TransferFunction::Discrete({0.0, 0.1}, {1.0, -0.9}, kTs, 2);
  const StateSpace ss = SampledStateSpace(g, kTs);
  EXPECT_EQ(ss.delay(), 0.0);
  EXPECT_NEAR(ss.DcGain()(0, 0), 1.0, 1e-12);
  MpcController c(g, kTs, MpcOptions{});
  EXPECT_NEAR(c.static_gain(), 1.0, 1e-12);
  // Unit step response of the realization: zero for 3 samples, then 0.1, 0.19.
  Eigen::VectorXd x = Eigen::VectorXd::Zero(ss.num_states());
  std::vector<double> y;
  for (int k = 0; k < 6; ++k) {
    y.push_back(ss.C().row(0).dot(x));
    x = ss.A() * x + ss.B().col(0);
  }
  EXPECT_NEAR(y[2], 0.0, 1e-15);
  EXPECT_NEAR(y[3], 0.1, 1e-12);
  EXPECT_NEAR(y[4], 0.19, 1e-12);
  EXPECT_THROW(MpcController(g, 0.02, MpcOptions{}), InvalidArgument);
}

TEST(MpcTest, ResetStartsAtTheOperatingPoint) {
  for (DisturbanceModel dm :
       {DisturbanceModel::kOutput, DisturbanceModel::kInput, DisturbanceModel::kNone}) {
    MpcOptions o;
    o.disturbance = dm;
    MpcController c(TransferFunction::Fopdt(1.6, 0.245, 0.001), kTs, o);
    const double y0 = dm == DisturbanceModel::kNone ? 1.6 * 30.0 : 50.0;
    c.Reset(30.0, y0);
    // At rest on the set-point the controller holds its input.
    for (int k = 0; k < 20; ++k) EXPECT_NEAR(c.Update(y0, y0), 30.0, 1e-9) << ToString(dm);
  }
}

TEST(MpcTest, IpaLargeStepStaysWithinDutyLimits) {
  MpcOptions o;
  o.limits.u_min = 0.0;
  o.limits.u_max = 100.0;
  MpcController c(PaperFopdtModel(), kTs, o);
  auto plant = MakePlant("ipa", kTs);
  const auto sp = ParseSignal("step:from=20,to=100,at=0.5");
  const Loop r = RunLoop(c, *plant, *sp, 4.0, 0.0, 0.0);
  const auto [u_lo, u_hi] = std::minmax_element(r.u.begin(), r.u.end());
  EXPECT_GE(*u_lo, 0.0);
  EXPECT_LE(*u_hi, 100.0);
  EXPECT_GT(*u_hi, 50.0);
  EXPECT_EQ(c.qp_failures(), 0);
  // Mean error over the last second within the PWM ripple.
  double err = 0.0;
  for (std::size_t k = r.y.size() - 100; k < r.y.size(); ++k) err += r.r[k] - r.y[k];
  EXPECT_LT(std::abs(err / 100.0), 1.0);
}

TEST(MpcTest, AppliedInputIsWhatTheObserverPredictsWith) {
  // After Applied(v), measuring exactly the model's output for v leaves the
  // disturbance estimate unchanged (zero innovation).
  MpcController c(PaperFopdtModel(), kTs, MpcOptions{});
  c.Reset(10.0, 16.0);
  const double u = c.Update(40.0, 16.0);
  const double v = 0.5 * (u + 10.0);
  c.Applied(v);
  const Eigen::VectorXd z_next = c.Az() * c.state_estimate() + c.Bz() * v;
  const double d = z_next(z_next.size() - 1);
  c.Update(40.0, c.Cz().dot(z_next));
  EXPECT_NEAR(c.disturbance_estimate(), d, 1e-12);
}

TEST(MpcTest, SoftOutputBoundHoldsTheOutputBelowIt) {
  // Plant = model, set-point 1 above the soft bound y_max = 0.9: the exact
  // penalty (rho1 = 1e4 exceeds the tracking cost's gradient) keeps the slack
  // at zero, so the output approaches the bound and never crosses it; without
  // the bound it reaches the set-point.
  auto run = [](double y_max) {
    MpcOptions o;
    o.y_max = y_max;
    const TransferFunction g = TransferFunction::Fopdt(1.6, 0.245, 0.001);
    MpcController c(g, kTs, o);
    LinearPlant plant(g, kTs);
    const auto sp = ParseSignal("step:from=0,to=1,at=0.1");
    return RunLoop(c, plant, *sp, 4.0, 0.0, 0.0).y;
  };
  const std::vector<double> bounded = run(0.9);
  EXPECT_LE(*std::max_element(bounded.begin(), bounded.end()), 0.9 + 1e-9);
  EXPECT_NEAR(bounded.back(), 0.9, 1e-3);
  const std::vector<double> free = run(std::numeric_limits<double>::infinity());
  EXPECT_NEAR(free.back(), 1.0, 1e-6);
}

TEST(MpcTest, DisturbanceModelNamesRoundTrip) {
  for (DisturbanceModel d :
       {DisturbanceModel::kOutput, DisturbanceModel::kInput, DisturbanceModel::kNone})
    EXPECT_EQ(DisturbanceModelFromString(ToString(d)), d);
  EXPECT_THAT([] { DisturbanceModelFromString("state"); },
              ThrowsMessage<InvalidArgument>(HasSubstr("output, input, none")));
}

TEST(MpcTest, BadInputThrows) {
  const TransferFunction fopdt = PaperFopdtModel();
  MpcOptions ok;
  // Unstable model.
  EXPECT_THAT(
      [&] {
        MpcController(TransferFunction::Continuous({1.0}, {1.0, -1.0}), kTs, ok);
      },
      ThrowsMessage<InvalidArgument>(HasSubstr("stable")));
  // A double integrator (two poles at z = 1) is refused; one integrator is
  // accepted, but not with the output disturbance model (not detectable), nor
  // without a disturbance model and without state noise.
  EXPECT_THAT(
      [&] {
        MpcController(TransferFunction::Continuous({1.0}, {1.0, 0.0, 0.0}), kTs, ok);
      },
      ThrowsMessage<InvalidArgument>(HasSubstr("2 poles at z = 1")));
  const TransferFunction integrator = TransferFunction::Continuous({1.0}, {1.0, 0.0});
  EXPECT_TRUE(MpcController(integrator, kTs, ok).integrating());
  MpcOptions output_model;
  output_model.disturbance = DisturbanceModel::kOutput;
  EXPECT_THAT([&] { MpcController(integrator, kTs, output_model); },
              ThrowsMessage<InvalidArgument>(HasSubstr("not detectable")));
  // A pole at z = 1 cancelled by a zero (least squares on noise-free data):
  // 0.04 z^-2 (1 - z^-1) / ((1 - z^-1)(1 - 0.98 z^-1)) is no integrator.
  const TransferFunction cancelled((Eigen::VectorXd(4) << 0.0, 0.0, 0.04, -0.04).finished(),
                                   (Eigen::VectorXd(4) << 1.0, -1.98, 0.98, 0.0).finished(), kTs);
  EXPECT_THAT([&] { MpcController(cancelled, kTs, ok); },
              ThrowsMessage<InvalidArgument>(HasSubstr("cancelled by a zero")));
  MpcOptions none;
  none.disturbance = DisturbanceModel::kNone;
  EXPECT_THAT([&] { MpcController(integrator, kTs, none); },
              ThrowsMessage<InvalidArgument>(HasSubstr("state_noise > 0")));
  // Not SISO.
  const StateSpace two_out(Eigen::MatrixXd::Constant(1, 1, 0.5), Eigen::MatrixXd::Ones(1, 1),
                           Eigen::MatrixXd::Ones(2, 1), Eigen::MatrixXd::Zero(2, 1), kTs);
  EXPECT_THAT([&] { MpcController(two_out, ok); },
              ThrowsMessage<InvalidArgument>(HasSubstr("single-input single-output")));
  // Continuous state space.
  const StateSpace cont(Eigen::MatrixXd::Constant(1, 1, -1.0), Eigen::MatrixXd::Ones(1, 1),
                        Eigen::MatrixXd::Ones(1, 1), Eigen::MatrixXd::Zero(1, 1));
  EXPECT_THAT([&] { MpcController(cont, ok); },
              ThrowsMessage<InvalidArgument>(HasSubstr("discrete")));
  // Direct feedthrough.
  const StateSpace feed(Eigen::MatrixXd::Constant(1, 1, 0.5), Eigen::MatrixXd::Ones(1, 1),
                        Eigen::MatrixXd::Ones(1, 1), Eigen::MatrixXd::Ones(1, 1), kTs);
  EXPECT_THAT([&] { MpcController(feed, ok); },
              ThrowsMessage<InvalidArgument>(HasSubstr("strictly proper")));
  // Zero static gain (a zero at z = 1).
  const TransferFunction zero_dc = TransferFunction::Discrete({0.0, 1.0, -1.0}, {1.0, -0.5}, kTs);
  EXPECT_THAT([&] { MpcController(zero_dc, kTs, ok); },
              ThrowsMessage<InvalidArgument>(HasSubstr("nonzero static gain")));
  // Horizons.
  MpcOptions o = ok;
  o.P = 5;
  o.M = 10;
  EXPECT_THAT([&] { MpcController(fopdt, kTs, o); },
              ThrowsMessage<InvalidArgument>(HasSubstr("1 <= M <= P")));
  // Contradictory limits.
  o = ok;
  o.limits.u_min = 10.0;
  o.limits.u_max = 0.0;
  EXPECT_THAT([&] { MpcController(fopdt, kTs, o); },
              ThrowsMessage<InvalidArgument>(HasSubstr("u_min <= u_max")));
  o = ok;
  o.limits.du_max = 0.0;
  EXPECT_THAT([&] { MpcController(fopdt, kTs, o); },
              ThrowsMessage<InvalidArgument>(HasSubstr("du_max must be positive")));
  o = ok;
  o.y_min = 2.0;
  o.y_max = 1.0;
  EXPECT_THAT([&] { MpcController(fopdt, kTs, o); },
              ThrowsMessage<InvalidArgument>(HasSubstr("y_min <= y_max")));
  // Noise covariances and weights.
  o = ok;
  o.measurement_noise = 0.0;
  EXPECT_THAT([&] { MpcController(fopdt, kTs, o); },
              ThrowsMessage<InvalidArgument>(HasSubstr("measurement noise")));
  o = ok;
  o.disturbance_noise = 0.0;
  EXPECT_THAT([&] { MpcController(fopdt, kTs, o); },
              ThrowsMessage<InvalidArgument>(HasSubstr("disturbance noise")));
  o = ok;
  o.output_weight = -1.0;
  EXPECT_THAT([&] { MpcController(fopdt, kTs, o); },
              ThrowsMessage<InvalidArgument>(HasSubstr("output weight")));
  // Dead time beyond the horizon with lambda = 0: singular Hessian.
  o = ok;
  o.P = 3;
  o.M = 3;
  o.lambda = 0.0;
  EXPECT_THAT([&] { MpcController(TransferFunction::Fopdt(1.0, 0.1, 0.1), kTs, o); },
              ThrowsMessage<InvalidArgument>(HasSubstr("singular")));
}

TEST(MpcTest, InfeasibleStartFallsBackToClippedMove) {
  // Starting far outside [0, 1] with du_max 0.01 the first QPs are infeasible;
  // the controller counts them and still returns a clipped input.
  MpcOptions o;
  o.limits.u_min = 0.0;
  o.limits.u_max = 1.0;
  o.limits.du_max = 0.01;
  MpcController c(PaperFopdtModel(), kTs, o);
  c.Reset(5.0, 8.0);
  const double u = c.Update(1.0, 8.0);
  EXPECT_GT(c.qp_failures(), 0);
  EXPECT_GE(u, 0.0);
  EXPECT_LE(u, 1.0);
}

}  // namespace
}  // namespace pneumid
