// The paper's reaction-curve FOPDT (Eq. 2) on its own ARX model (Eq. 5).
// Golden values: docs/paper.md, reference values 2 and 4: static
// gain 1.59796, 63.2 % time of the ARX unit step t63 = 0.2306 s; K = 1.6 within
// 1 % and tau within one sample (Ts = 0.01 s) of t63.
#include "pneumid/identify/step/reaction_curve.hpp"

#include <gtest/gtest.h>

#include "pneumid/models/model_file.hpp"
#include "step_test_util.hpp"

namespace pneumid {
namespace {

constexpr double kTs = 0.01;
constexpr double kT63 = 0.2306;  // docs/paper.md, reference value 4

Dataset PaperStep(double noise, unsigned seed = 7) {
  // Duty cycle stepped 0.61 -> 82 % after 0.5 s, 4 s of data (paper section 4).
  return testing::MakeStepData(PaperArxModel(), kTs, 50, 400, 0.61, 82.0, noise, seed);
}

TEST(ReactionCurveTest, PaperArxNoiseFree) {
  const StepAnalysis s = AnalyzeStep(PaperStep(0.0));
  EXPECT_NEAR(s.step_time, 0.5, 1e-12);
  EXPECT_NEAR(s.du, 82.0 - 0.61, 1e-12);
  EXPECT_NEAR(s.gain, 1.59796, 1.59796 * 1e-4);
  const FopdtParams p = ReactionCurve(s);
  EXPECT_NEAR(p.K, 1.6, 0.016);
  EXPECT_NEAR(p.tau, kT63, kTs);
  EXPECT_GE(p.theta, 0.0);
  EXPECT_LT(p.theta, kTs);
  EXPECT_NEAR(s.CrossingTime(0.632), kT63, 0.5 * kTs);
}

TEST(ReactionCurveTest, PaperArxWithNoise) {
  // Noise std 1.3 N, 1 % of the 130 N force change; several seeds.
  for (unsigned seed : {1u, 2u, 3u, 4u, 5u}) {
    const StepAnalysis s = AnalyzeStep(PaperStep(1.3, seed));
    const FopdtParams p = ReactionCurve(s);
    EXPECT_NEAR(p.K, 1.6, 0.016) << "seed " << seed;
    EXPECT_NEAR(p.tau, kT63, kTs) << "seed " << seed;
    EXPECT_GE(p.theta, 0.0);
    EXPECT_LT(p.theta, 2 * kTs) << "seed " << seed;
    EXPECT_NEAR(s.noise_std, 1.3, 0.4);
  }
}

TEST(ReactionCurveTest, FopdtClosedForm) {
  // Exact FOPDT: t63 = theta + tau; the departure is read within a sample.
  const double K = 2.0, tau = 0.8, theta = 0.23, Ts = 0.01;
  const Dataset d =
      testing::MakeStepData(TransferFunction::Fopdt(K, tau, theta), Ts, 20, 800, 1.0, 3.0);
  const FopdtParams p = ReactionCurve(AnalyzeStep(d));
  EXPECT_NEAR(p.K, K, 1e-3 * K);
  EXPECT_NEAR(p.theta, theta, Ts);
  EXPECT_NEAR(p.tau + p.theta, tau + theta, 0.5 * Ts);
  // A falling response (negative step) gives the same model.
  const Dataset down = testing::MakeStepData(TransferFunction::Fopdt(K, tau, theta), Ts, 20, 800,
                                             3.0, 1.0, 0.0, 1, 10.0);
  const FopdtParams q = ReactionCurve(AnalyzeStep(down));
  EXPECT_NEAR(q.K, K, 1e-3 * K);
  EXPECT_NEAR(q.tau, p.tau, 1e-9);
}

}  // namespace
}  // namespace pneumid
