// Two-point, three-point SOPDT, tangent, Strejc and area methods on exact
// (noise-free, finely sampled) responses, against closed forms.
#include <cmath>
#include <numbers>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/identify/step/areas.hpp"
#include "pneumid/identify/step/sopdt.hpp"
#include "pneumid/identify/step/strejc.hpp"
#include "pneumid/identify/step/tangent.hpp"
#include "pneumid/identify/step/two_point.hpp"
#include "pneumid/lti/conversion.hpp"
#include "pneumid/models/model_file.hpp"
#include "step_test_util.hpp"

namespace pneumid {
namespace {

constexpr double kTau = 1.0, kTheta = 0.2, kK = 3.0, kTs = 0.001;

StepAnalysis ExactFopdt() {
  return AnalyzeStep(
      testing::MakeStepData(TransferFunction::Fopdt(kK, kTau, kTheta), kTs, 100, 12000, 0.0, 1.0));
}

// Time at which an exact FOPDT reaches fraction p: theta - tau ln(1 - p).
double T(double p) { return kTheta - kTau * std::log(1.0 - p); }

TEST(TwoPointTest, ClosedFormsOnExactFopdt) {
  const StepAnalysis s = ExactFopdt();
  EXPECT_NEAR(s.CrossingTime(0.5), T(0.5), 5e-5);
  // Each method's formula applied to the exact crossing times (Seborg et al. Table 7.1).
  const FopdtParams smith = TwoPoint(s, TwoPointMethod::kSmith);
  EXPECT_NEAR(smith.tau, 1.5 * (T(0.632) - T(0.283)), 1e-4);
  EXPECT_NEAR(smith.theta, T(0.632) - 1.5 * (T(0.632) - T(0.283)), 1e-4);
  const FopdtParams sk = TwoPoint(s, TwoPointMethod::kSundaresanKrishnaswamy);
  EXPECT_NEAR(sk.tau, 0.67 * (T(0.853) - T(0.353)), 1e-4);
  EXPECT_NEAR(sk.theta, 1.3 * T(0.353) - 0.29 * T(0.853), 1e-4);
  const FopdtParams broida = TwoPoint(s, TwoPointMethod::kBroida);
  EXPECT_NEAR(broida.tau, 5.5 * (T(0.40) - T(0.28)), 1e-4);
  EXPECT_NEAR(broida.theta, 2.8 * T(0.28) - 1.8 * T(0.40), 1e-4);
  // ... and all of them are close to the truth on a true FOPDT.
  for (const FopdtParams& p : {smith, sk, broida}) {
    EXPECT_NEAR(p.K, kK, 1e-4);
    EXPECT_NEAR(p.tau, kTau, 0.01 * kTau);
    EXPECT_NEAR(p.theta, kTheta, 0.015 * kTau);  // S-K: 0.01 (tau + theta) high
  }
  EXPECT_EQ(TwoPointMethodFromString("broida"), TwoPointMethod::kBroida);
  EXPECT_THROW(TwoPointMethodFromString("smyth"), InvalidArgument);
}

TEST(ThreePointSopdtTest, RecoversExactSopdt) {
  const StepAnalysis s = AnalyzeStep(testing::MakeStepData(
      TransferFunction::Sopdt(1.5, 2.0, 0.7, 0.5), 0.005, 100, 5000, 1.0, 2.0));
  const ThreePointSopdtResult r = ThreePointSopdt(s);
  EXPECT_FALSE(r.clamped);
  EXPECT_NEAR(r.params.K, 1.5, 1e-4);
  EXPECT_NEAR(r.params.tau1, 2.0, 0.005 * 2.0);
  EXPECT_NEAR(r.params.tau2, 0.7, 0.01 * 0.7);
  EXPECT_NEAR(r.params.theta, 0.5, 0.005);
  // Equal lags and first order are the ends of the ratio range.
  EXPECT_NEAR(SopdtNormalizedStep(1.0, 1.6783), 0.5, 1e-4);  // 1 - (1 + x) e^-x
  EXPECT_NEAR(SopdtNormalizedTime(0.0, 0.5), std::log(2.0), 1e-12);
  EXPECT_NEAR(SopdtNormalizedStep(0.3, SopdtNormalizedTime(0.3, 0.8)), 0.8, 1e-12);
}

TEST(TangentTest, ExactFopdtTangentIsTheModel) {
  // For an FOPDT the steepest point is the departure: L = theta, T = tau.
  TangentOptions o;
  o.half_width = 2;
  const TangentResult t = InflectionTangent(ExactFopdt(), o);
  EXPECT_NEAR(t.L, kTheta, 3 * kTs);
  EXPECT_NEAR(t.T, kTau, 0.03 * kTau);
}

TEST(TangentTest, PaperArxModel) {
  // References from gen_tangent_reference.py (scipy). The model's continuous
  // equivalent, sampled at 0.5 ms: L = 0.00512 s, T = 0.21877 s.
  const TransferFunction ct = D2C(PaperArxModel());
  TangentOptions o;
  o.half_width = 1;
  const TangentResult c =
      InflectionTangent(AnalyzeStep(testing::MakeStepData(ct, 0.0005, 100, 8000, 0.0, 1.0)), o);
  EXPECT_NEAR(c.L, 0.00512, 0.0002);
  EXPECT_NEAR(c.T, 0.21877, 0.002);
  // The ARX model's own step at Ts = 0.01 s. Its samples r_k are exact (the
  // difference equation), so the construction has a closed form: with m = 1
  // the Savitzky-Golay slope is the central difference
  // c_k = (r_{k+1} - r_{k-1}) / (2 Ts); the largest, c_2, and its neighbours
  // (3.392149, 4.210046, 3.955791 /s) give the parabola's vertex
  // S = 4.247086 /s at t_i = 0.0226286 s, r_i = 0.0788334, so
  // L = t_i - r_i / S = 0.00406679 s and T = 1 / S = 0.2354556 s (computed
  // with numpy from scipy.signal.lfilter's step of Eq. 5, the record of
  // gen_tangent_reference.py). Only rounding separates the method from that.
  const TangentResult d = InflectionTangent(
      AnalyzeStep(testing::MakeStepData(PaperArxModel(), 0.01, 50, 400, 0.0, 1.0)), o);
  EXPECT_NEAR(d.L, 0.00406679, 1e-7);
  EXPECT_NEAR(d.T, 0.2354556, 1e-6);
  // docs/paper.md, reference value 4, reads the tangent off the steepest
  // sample-to-sample segment, s_1 = 4.319911 /s: L = 0.0043 s, T = 0.2315 s.
  // A central difference averages that segment with a neighbour
  // (s_2 = 4.100182 /s), so the method's slope lies between (s_1 + s_2) / 2
  // and s_1: T between 0.2315 s and 1 / 4.210046 = 0.2375 s (at most 2.6 %
  // longer). L = t_i - r_i T moves with T by r_i times its change
  // (0.079 x 6 ms = 0.5 ms at most) and with the tangent point inside the
  // segment: within a tenth of a sample (1 ms) of the reference.
  EXPECT_GE(d.T, 0.2315 * (1.0 - 1e-4));
  EXPECT_LE(d.T, 0.2375);
  EXPECT_NEAR(d.L, 0.0043, 0.1 * 0.01);
}

TEST(StrejcTest, ClassicalTable) {
  // Tu/Tn of n equal lags (Strejc 1959; Unbehauen sec. 3.3).
  const double ratio[] = {0.0, 0.0, 0.104, 0.218, 0.319, 0.410, 0.493};
  const double tn[] = {0.0, 1.0, 2.718, 3.695, 4.463, 5.119, 5.699};
  for (int n = 1; n <= 6; ++n) {
    const auto [tu_T, tn_T] = StrejcTable(n);
    EXPECT_NEAR(tu_T / tn_T, ratio[n], 1.5e-3) << n;
    EXPECT_NEAR(tn_T, tn[n], 1.5e-3) << n;
  }
  EXPECT_THROW(StrejcTable(0), InvalidArgument);
}

TEST(StrejcTest, ThreeEqualLagsWithDelay) {
  const TransferFunction g = TransferFunction::Continuous({2.0}, {1.0, 3.0, 3.0, 1.0}, 0.2);
  const StepAnalysis s = AnalyzeStep(testing::MakeStepData(g, 0.002, 100, 10000, 0.0, 1.0));
  const StrejcResult r = Strejc(InflectionTangent(s), s.gain);
  EXPECT_EQ(r.n, 3);
  EXPECT_NEAR(r.K, 2.0, 1e-4);
  EXPECT_NEAR(r.T, 1.0, 0.01);
  EXPECT_NEAR(r.Td, 0.2, 0.02);
}

TEST(AreasTest, FopdtMoments) {
  // G = K exp(-theta s) / (tau s + 1) = A0 - A1 s + A2 s^2 - A3 s^3 + ...
  const AreaResult a = CharacteristicAreas(ExactFopdt());
  const double th = kTheta, ta = kTau;
  EXPECT_NEAR(a.A0, kK, 1e-4);
  EXPECT_NEAR(a.T_ar, th + ta, 3e-4);  // record of 11.9 tau, trapezoidal rule
  EXPECT_NEAR(a.A1, kK * (th + ta), 1e-3 * kK);
  EXPECT_NEAR(a.A2, kK * (th * th / 2 + th * ta + ta * ta), 5e-3 * a.A2);
  EXPECT_NEAR(a.A3, kK * (std::pow(th, 3) / 6 + th * th * ta / 2 + th * ta * ta + std::pow(ta, 3)),
              0.01 * a.A3);
  // Astrom-Hagglund area method is exact for an FOPDT.
  EXPECT_NEAR(a.fopdt.tau, kTau, 1e-3);
  EXPECT_NEAR(a.fopdt.theta, kTheta, 1e-3);
}

}  // namespace
}  // namespace pneumid
