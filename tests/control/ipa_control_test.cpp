// Predictive control of the nonlinear IPA simulator (force mode, switching
// PWM, the default twin) with a DMC designed from the paper's FOPDT (Eq. 2):
// it tracks a force staircase with zero mean steady-state error, keeps the
// duty cycle within 0..100 %, and rejects a load step. The PWM makes the force
// ripple (the default twin's 300 Hz by a fraction of a newton at Ts = 0.01 s,
// the slow variant's 50 Hz by about +-2 N), so steady-state errors are
// averaged over the last 0.5 s of each segment.
#include <cmath>

#include <gtest/gtest.h>

#include "pneumid/control/closed_loop.hpp"
#include "pneumid/control/dmc.hpp"
#include "pneumid/models/model_file.hpp"
#include "pneumid/plant/plant_factory.hpp"
#include "pneumid/plant/signal.hpp"

namespace pneumid {
namespace {

double MeanError(const ClosedLoopResult& r, double from, double to) {
  double acc = 0.0;
  int n = 0;
  for (Eigen::Index k = 0; k < r.t.size(); ++k) {
    if (r.t(k) >= from - 1e-9 && r.t(k) < to - 1e-9) {
      acc += r.r(k) - r.y(k);
      ++n;
    }
  }
  return acc / n;
}

class IpaControlTest : public ::testing::TestWithParam<bool> {};

TEST_P(IpaControlTest, TracksStaircaseWithinDutyBoundsAndRejectsLoad) {
  const bool constrained = GetParam();
  DmcOptions o;
  o.P = 126;
  o.M = 5;
  o.lambda = 2.25;
  o.limits.u_min = 0.0;
  o.limits.u_max = 100.0;
  o.constrained = constrained;
  DmcController dmc(PaperFopdtModel(), 0.01, o);
  auto plant = MakePlant("ipa", 0.01);
  auto sp = ParseSignal("staircase:levels=0 40 80 40,dwell=2");
  ClosedLoopOptions cl;
  cl.duration = 8.0;
  cl.load_steps = {{7.0, -10.0}};
  const ClosedLoopResult r = SimulateClosedLoop(dmc, *plant, *sp, cl);
  // Duty cycle within its bounds at every sample.
  EXPECT_GE(r.u.minCoeff(), 0.0);
  EXPECT_LE(r.u.maxCoeff(), 100.0);
  // The controller reached the force levels: 80 N needs about 60 % duty.
  EXPECT_GT(r.u.maxCoeff(), 50.0);
  // Zero steady-state error (mean over the last 0.5 s of each level).
  EXPECT_NEAR(MeanError(r, 3.5, 4.0), 0.0, 0.5);  // 40 N
  EXPECT_NEAR(MeanError(r, 5.5, 6.0), 0.0, 0.5);  // 80 N
  EXPECT_NEAR(MeanError(r, 6.5, 7.0), 0.0, 0.5);  // back to 40 N
  // Load step of -10 N at 7 s: felt, then rejected.
  EXPECT_LT(r.metrics.load_peak_deviation, -5.0);
  EXPECT_NEAR(MeanError(r, 7.5, 8.0), 0.0, 0.5);
  ASSERT_EQ(r.metrics.steps.size(), 3u);
  EXPECT_LT(r.metrics.steps[0].rise_time, 0.3);
  if (constrained) EXPECT_EQ(dmc.qp_failures(), 0);
}

INSTANTIATE_TEST_SUITE_P(ClippedAndQdmc, IpaControlTest, ::testing::Bool());

}  // namespace
}  // namespace pneumid
