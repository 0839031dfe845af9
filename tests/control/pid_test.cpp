// PID: SIMC and IMC gains against their closed forms, offset-free control of
// the paper's plant, and the anti-windup under input saturation.
#include "pneumid/control/pid.hpp"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/control/closed_loop.hpp"
#include "pneumid/models/model_file.hpp"
#include "pneumid/plant/linear_plant.hpp"
#include "pneumid/plant/signal.hpp"

namespace pneumid {
namespace {

constexpr double kTs = 0.01;

TEST(PidTuningTest, SimcClosedForm) {
  // Skogestad 2003 eq. (18)-(19) with theta_eff = 0.001 + 0.005 and tau_c = 0.05:
  // Kc = 0.245 / (1.6 * 0.056), Ti = min(0.245, 4 * 0.056) = 0.224.
  const PidGains g = TunePid(1.6, 0.245, 0.001, kTs, PidTuningRule::kSimc, 0.05);
  EXPECT_NEAR(g.Kc, 0.245 / (1.6 * 0.056), 1e-12);
  EXPECT_NEAR(g.Ti, 0.224, 1e-12);
  EXPECT_EQ(g.Td, 0.0);
  const PidGains tight = TunePid(1.6, 0.245, 0.001, kTs, PidTuningRule::kSimc);
  EXPECT_NEAR(tight.Kc, 0.245 / (1.6 * 0.012), 1e-12);  // tau_c = theta_eff
}

TEST(PidTuningTest, ImcClosedForm) {
  // Rivera, Morari, Skogestad 1986: Kc K = (2 tau + theta)/(2 tau_c + theta),
  // Ti = tau + theta/2, Td = tau theta/(2 tau + theta), theta = 0.006.
  const PidGains g = TunePid(1.6, 0.245, 0.001, kTs, PidTuningRule::kImc, 0.05);
  EXPECT_NEAR(g.Kc, (0.49 + 0.006) / (1.6 * (0.1 + 0.006)), 1e-12);
  EXPECT_NEAR(g.Ti, 0.245 + 0.003, 1e-12);
  EXPECT_NEAR(g.Td, 0.245 * 0.006 / 0.496, 1e-12);
  EXPECT_EQ(PidTuningRuleFromString("imc"), PidTuningRule::kImc);
  EXPECT_THROW(PidTuningRuleFromString("zn"), InvalidArgument);
  EXPECT_THROW(TunePid(0.0, 0.245, 0.001, kTs, PidTuningRule::kImc), InvalidArgument);
  EXPECT_THROW(TunePid(1.6, -1.0, 0.001, kTs, PidTuningRule::kImc), InvalidArgument);
}

TEST(PidControllerTest, TracksArxPlantWithoutOffset) {
  PidOptions o;
  o.gains = TunePid(1.6, 0.245, 0.001, kTs, PidTuningRule::kImc, 0.05);
  PidController pid(kTs, o);
  LinearPlant plant(PaperArxModel(), kTs);
  auto sp = ParseSignal("step:from=0,to=40,at=0.1");
  ClosedLoopOptions cl;
  cl.duration = 3.0;
  cl.load_steps = {{1.5, -5.0}};
  const auto r = SimulateClosedLoop(pid, plant, *sp, cl);
  EXPECT_NEAR(r.metrics.steady_state_error, 0.0, 1e-3);
  EXPECT_LT(r.metrics.rise_time, 0.3);
  EXPECT_LT(r.metrics.load_recovery_time, 1.0);
}

TEST(PidControllerTest, AntiWindupShortensSaturatedOvershoot) {
  // Set-point beyond what u_max reaches for a while, then back within reach:
  // with back-calculation the integrator does not wind up.
  PidOptions o;
  o.gains = TunePid(1.6, 0.245, 0.001, kTs, PidTuningRule::kSimc, 0.05);
  o.limits.u_min = 0.0;
  o.limits.u_max = 1.0;
  PidOptions no_aw = o;
  no_aw.tracking_time = 1e9;  // Ts/Tt ~ 0: practically no back-calculation
  PidController with(kTs, o), without(kTs, no_aw);
  LinearPlant p1(PaperFopdtModel(), kTs), p2(PaperFopdtModel(), kTs);
  auto sp = ParseSignal("staircase:levels=0 2 1,dwell=1");
  ClosedLoopOptions cl;
  cl.duration = 4.0;
  const auto r1 = SimulateClosedLoop(with, p1, *sp, cl);
  const auto r2 = SimulateClosedLoop(without, p2, *sp, cl);
  EXPECT_LE(r1.metrics.u_max, 1.0);
  EXPECT_GE(r1.metrics.u_min, 0.0);
  ASSERT_EQ(r1.metrics.steps.size(), 2u);
  EXPECT_LT(r1.metrics.iae, 0.8 * r2.metrics.iae);
  EXPECT_NEAR(r1.metrics.steps[1].steady_state_error, 0.0, 1e-3);
}

}  // namespace
}  // namespace pneumid
