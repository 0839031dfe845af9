// Step, impulse and lsim responses, and step-response metrics.
#include "pneumid/lti/response.hpp"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/lti/conversion.hpp"
#include "pneumid/models/model_file.hpp"

namespace pneumid {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

TEST(ResponseTest, FopdtStepIsExactAtTheSamples) {
  // y(t) = K (1 - exp(-(t - theta)/tau)) for t >= theta, 0 before.
  const double K = 1.6, tau = 0.245;
  for (const double theta : {0.001, 0.0237, 0.05}) {
    for (const double dt : {0.001, 0.01}) {
      const TimeResponse r = Step(TransferFunction::Fopdt(K, tau, theta), 1.0, dt);
      ASSERT_EQ(r.t.size(), static_cast<Eigen::Index>(std::lround(1.0 / dt)) + 1);
      EXPECT_NEAR(r.t[r.t.size() - 1], 1.0, 1e-12);
      double worst = 0.0;
      for (Eigen::Index k = 0; k < r.t.size(); ++k) {
        const double t = r.t[k];
        const double exact = t >= theta ? K * (1.0 - std::exp(-(t - theta) / tau)) : 0.0;
        worst = std::max(worst, std::abs(r.y[k] - exact));
      }
      EXPECT_LT(worst, 1e-12) << "theta " << theta << " dt " << dt;
    }
  }
}

TEST(ResponseTest, DefaultGridCoversTheTransient) {
  const TimeResponse r = Step(PaperFopdtModel());
  EXPECT_NEAR(r.t[1] - r.t[0], 0.245 / 200, 1e-12);
  EXPECT_GE(r.t[r.t.size() - 1], 7 * 0.245);
  EXPECT_NEAR(r.y[r.y.size() - 1], 1.6, 1.6 * 2e-3);
  const TimeResponse d = Step(PaperArxModel());
  EXPECT_DOUBLE_EQ(d.t[1], 0.01);
}

TEST(ResponseTest, PaperArxStepT63) {
  // docs/paper.md, reference value 4: the ARX model's own unit step gives t63 = 0.2306 s.
  const TimeResponse r = Step(PaperArxModel(), 2.0);
  const double target = 0.632 * PaperArxModel().DcGain();
  double t63 = NAN;
  for (Eigen::Index k = 1; k < r.y.size(); ++k) {
    if (r.y[k] >= target) {
      t63 = r.t[k - 1] + (target - r.y[k - 1]) / (r.y[k] - r.y[k - 1]) * 0.01;
      break;
    }
  }
  EXPECT_NEAR(t63, 0.2306, 0.01);  // within one sample
  // The continuous equivalent (Eq. 6) agrees with the ARX model at the samples.
  const TimeResponse c = Step(D2C(PaperArxModel()), 2.0, 0.01);
  EXPECT_LT((c.y - r.y).cwiseAbs().maxCoeff(), 1e-9);
}

TEST(ResponseTest, DiscreteLsimIsTheDifferenceEquation) {
  const TransferFunction g = PaperArxModel().WithDelay(0.02);
  const int N = 200;
  Eigen::VectorXd u(N);
  for (int k = 0; k < N; ++k) u[k] = std::sin(0.1 * k) + (k % 17 == 0 ? 1.0 : 0.0);
  const Eigen::VectorXd y = Lsim(g, u, 0.01);
  // A(q) y = B(q) q^-2 u
  const double a[] = {1.0, -0.60870, -0.27020, -0.06021};
  const double b[] = {0.0, 0.03938, 0.04506, 0.01286};
  Eigen::VectorXd ref = Eigen::VectorXd::Zero(N);
  for (int k = 0; k < N; ++k) {
    double acc = 0.0;
    for (int i = 0; i < 4; ++i) {
      if (k - i - 2 >= 0) acc += b[i] * u[k - i - 2];
      if (i > 0 && k - i >= 0) acc -= a[i] * ref[k - i];
    }
    ref[k] = acc;
  }
  EXPECT_LT((y - ref).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_THAT([&] { Lsim(g, u, 0.02); },
              ThrowsMessage<InvalidArgument>(HasSubstr("own sample time Ts = 0.01")));
}

TEST(ResponseTest, ImpulseClosedForms) {
  // 2/(s + 1): h(t) = 2 exp(-(t - 0.3)) after the delay 0.3.
  const TimeResponse r = Impulse(TransferFunction::Continuous({2.0}, {1.0, 1.0}, 0.3), 3.0, 0.01);
  for (Eigen::Index k = 0; k < r.t.size(); ++k) {
    const double exact = r.t[k] >= 0.3 - 1e-12 ? 2.0 * std::exp(-(r.t[k] - 0.3)) : 0.0;
    ASSERT_NEAR(r.y[k], exact, 1e-10) << "t = " << r.t[k];
  }
  // Biproper (s + 3)/(s + 1) = 1 + 2/(s + 1): the D delta(t) part is dropped.
  const TimeResponse b = Impulse(TransferFunction::Continuous({1.0, 3.0}, {1.0, 1.0}), 1.0, 0.1);
  EXPECT_NEAR(b.y[5], 2.0 * std::exp(-0.5), 1e-12);
  // Discrete: h[k] = 0.5^(k-1) for b z^-1/(1 - 0.5 z^-1) with b = 1.
  const TimeResponse d = Impulse(TransferFunction::Discrete({0.0, 1.0}, {1.0, -0.5}, 0.1), 1.0);
  EXPECT_EQ(d.y[0], 0.0);
  EXPECT_NEAR(d.y[4], std::pow(0.5, 3), 1e-15);
}

TEST(ResponseTest, StateSpaceLsimWithInitialState) {
  // dx/dt = -2 x, y = x, x0 = 3: free response 3 exp(-2 t).
  Eigen::MatrixXd A(1, 1), B(1, 1), C(1, 1), D(1, 1);
  A << -2;
  B << 1;
  C << 1;
  D << 0;
  const StateSpace g(A, B, C, D);
  Eigen::VectorXd x0(1);
  x0 << 3.0;
  const Eigen::MatrixXd y = Lsim(g, Eigen::MatrixXd::Zero(50, 1), 0.02, x0);
  for (int k = 0; k < 50; ++k) ASSERT_NEAR(y(k, 0), 3.0 * std::exp(-2.0 * 0.02 * k), 1e-13);
  // Two inputs, two outputs: outputs are independent first-order lags.
  Eigen::MatrixXd A2(2, 2), B2 = Eigen::MatrixXd::Identity(2, 2),
                            C2 = Eigen::MatrixXd::Identity(2, 2);
  A2 << -1, 0, 0, -4;
  const StateSpace g2(A2, B2, C2, Eigen::MatrixXd::Zero(2, 2));
  Eigen::MatrixXd u = Eigen::MatrixXd::Zero(30, 2);
  u.col(1).setOnes();
  const Eigen::MatrixXd y2 = Lsim(g2, u, 0.1);
  EXPECT_EQ(y2.col(0).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_NEAR(y2(20, 1), (1 - std::exp(-4 * 2.0)) / 4, 1e-13);
  EXPECT_THAT([&] { Lsim(g, Eigen::MatrixXd::Zero(5, 2), 0.1); },
              ThrowsMessage<InvalidArgument>(HasSubstr("nu = 1 columns")));
  EXPECT_THAT([&] { Lsim(g, Eigen::MatrixXd::Zero(5, 1), 0.1, Eigen::VectorXd::Ones(2)); },
              ThrowsMessage<InvalidArgument>(HasSubstr("x0 must have nx = 1")));
  EXPECT_THAT([&] { Lsim(g, Eigen::MatrixXd::Zero(5, 1), -0.1); },
              ThrowsMessage<InvalidArgument>(HasSubstr("dt must be > 0")));
  // A NaN initial state is refused as a NaN input is (it gave NaN outputs).
  EXPECT_THAT(
      [&] { Lsim(g, Eigen::MatrixXd::Zero(5, 1), 0.1, Eigen::VectorXd::Constant(1, NAN)); },
      ThrowsMessage<InvalidArgument>(HasSubstr("x0 contains NaN")));
}

TEST(FirstCrossingTest, InterpolatesBetweenSamples) {
  Eigen::VectorXd t(4), x(4);
  t << 0.0, 1.0, 2.0, 3.0;
  x << 0.0, 0.2, 0.6, 1.0;
  Eigen::Index k = -1;
  EXPECT_DOUBLE_EQ(FirstCrossing(t, x, 0.4, 0, &k), 1.5);  // 1 + (0.4 - 0.2) / 0.4
  EXPECT_EQ(k, 2);
  EXPECT_DOUBLE_EQ(FirstCrossing(t, x, 0.0), 0.0);  // already at the level
  EXPECT_DOUBLE_EQ(FirstCrossing(t, x, 0.1, 2), 2.0);  // search starts at t = 2
  EXPECT_TRUE(std::isnan(FirstCrossing(t, x, 1.5, 0, &k)));
  EXPECT_EQ(k, 4);
  EXPECT_THROW(FirstCrossing(t, x.head(3), 0.5), InvalidArgument);
}

TEST(StepInfoTest, MatlabDocumentationExample) {
  // MATLAB documentation, "Numeric Values of Time-Domain System Characteristics":
  // H = tf([8 18 32],[1 6 14 24]); stepinfo(H) gives RiseTime 0.2087,
  // SettlingTime 3.4972, SettlingMin 1.1956, SettlingMax 1.6871,
  // Overshoot 26.5302, Undershoot 0, Peak 1.6871, PeakTime 0.5987, and with
  // SettlingTimeThreshold 0.005 a settling time of 4.8896.
  // MATLAB reads the peak on its own grid (here about 0.06 s apart), so the
  // peak is compared to 1e-3 relative and times to a fraction of that grid.
  const TransferFunction H = TransferFunction::Continuous({8, 18, 32}, {1, 6, 14, 24});
  const StepInfo s = ComputeStepInfo(H);
  EXPECT_NEAR(s.rise_time, 0.2087, 1e-3);
  EXPECT_NEAR(s.settling_time, 3.4972, 2e-3);
  EXPECT_NEAR(s.settling_min, 1.1956, 1e-3);
  EXPECT_NEAR(s.settling_max / 1.6871, 1.0, 1e-3);
  EXPECT_NEAR(s.overshoot, 26.5302, 0.05);
  EXPECT_EQ(s.undershoot, 0.0);
  EXPECT_NEAR(s.peak / 1.6871, 1.0, 1e-3);
  EXPECT_NEAR(s.peak_time, 0.5987, 0.02);
  EXPECT_NEAR(s.steady_state, 32.0 / 24.0, 1e-15);
  StepInfoOptions o;
  o.settling_threshold = 0.005;
  EXPECT_NEAR(ComputeStepInfo(H, o).settling_time, 4.8896, 2e-3);
}

TEST(StepInfoTest, SecondOrderClosedForms) {
  // wn^2 / (s^2 + 2 zeta wn s + wn^2): overshoot 100 exp(-zeta pi / sqrt(1 - zeta^2)),
  // peak time pi / wd.
  for (const double zeta : {0.2, 0.5, 0.7}) {
    const double wn = 3.0, wd = wn * std::sqrt(1 - zeta * zeta);
    const TransferFunction g = TransferFunction::Continuous({wn * wn}, {1, 2 * zeta * wn, wn * wn});
    const TimeResponse r = Step(g, 10.0, 1e-4);
    const StepInfo s = ComputeStepInfo(r.t, r.y, {.y_initial = 0.0, .y_final = 1.0});
    EXPECT_NEAR(s.overshoot, 100 * std::exp(-zeta * M_PI / std::sqrt(1 - zeta * zeta)), 1e-4);
    EXPECT_NEAR(s.peak_time, M_PI / wd, 1e-4);
    EXPECT_NEAR(s.peak, 1 + std::exp(-zeta * M_PI / std::sqrt(1 - zeta * zeta)), 1e-7);
  }
  // First order 1/(tau s + 1): rise time tau ln 9, settling time tau ln 50.
  const double tau = 0.245;
  const StepInfo f = ComputeStepInfo(TransferFunction::Fopdt(1.0, tau, 0.0));
  EXPECT_NEAR(f.rise_time, tau * std::log(9.0), tau / 200);
  EXPECT_NEAR(f.settling_time, tau * std::log(50.0), tau / 200);
  EXPECT_EQ(f.overshoot, 0.0);
}

TEST(StepInfoTest, UndershootAndNegativeStep) {
  // (1 - s)/(s + 1)^2: non-minimum phase, dips below 0 first.
  const TransferFunction g = TransferFunction::Continuous({-1, 1}, {1, 2, 1});
  const TimeResponse r = Step(g, 15.0, 1e-3);
  // y(t) = 1 - exp(-t) - 2 t exp(-t): minimum at t = 1/2, y = 1 - 2 exp(-1/2).
  const StepInfo s = ComputeStepInfo(r.t, r.y);
  EXPECT_NEAR(s.undershoot, 100 * (2 * std::exp(-0.5) - 1), 1e-3);
  // Negated response: same metrics.
  const StepInfo n = ComputeStepInfo(r.t, Eigen::VectorXd(-r.y));
  EXPECT_NEAR(n.undershoot, s.undershoot, 1e-12);
  EXPECT_NEAR(n.rise_time, s.rise_time, 1e-12);
  EXPECT_NEAR(n.settling_time, s.settling_time, 1e-12);
}

TEST(StepInfoTest, UnstableModelGivesNaN) {
  const StepInfo s = ComputeStepInfo(TransferFunction::Continuous({1}, {1, -1}));
  EXPECT_TRUE(std::isnan(s.rise_time));
  EXPECT_TRUE(std::isnan(s.settling_time));
}

TEST(StepInfoTest, BadArgumentsThrow) {
  Eigen::VectorXd t(3), y(3);
  t << 0, 1, 1;
  y << 0, 1, 1;
  EXPECT_THAT([&] { ComputeStepInfo(t, y); },
              ThrowsMessage<InvalidArgument>(HasSubstr("strictly increasing")));
  EXPECT_THAT([&] { ComputeStepInfo(t, Eigen::VectorXd(2)); },
              ThrowsMessage<InvalidArgument>(HasSubstr("t has 3 samples but y has 2")));
  t << 0, 1, 2;
  y << 0, NAN, 1;
  EXPECT_THAT([&] { ComputeStepInfo(t, y); }, ThrowsMessage<InvalidArgument>(HasSubstr("NaN")));
  StepInfoOptions o;
  o.rise_low = 0.95;
  std::string error;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_THAT(error, HasSubstr("rise_low < rise_high"));
  y << 0, 1, 1;
  EXPECT_THAT([&] { ComputeStepInfo(t, y, o); },
              ThrowsMessage<InvalidArgument>(HasSubstr("invalid options")));
  EXPECT_THAT([] { Step(PaperFopdtModel(), -1.0); },
              ThrowsMessage<InvalidArgument>(HasSubstr("t_final must be >= 0")));
}

}  // namespace
}  // namespace pneumid
