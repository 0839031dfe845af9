// Closed-loop metrics on logs with closed-form answers, and the loop itself.
#include "pneumid/control/closed_loop.hpp"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "pneumid/common/check.hpp"
#include "pneumid/control/dmc.hpp"
#include "pneumid/control/gpc.hpp"
#include "pneumid/control/pid.hpp"
#include "pneumid/models/model_file.hpp"
#include "pneumid/plant/ipa_simulator.hpp"
#include "pneumid/plant/linear_plant.hpp"
#include "pneumid/plant/signal.hpp"

namespace pneumid {
namespace {

TEST(ClosedLoopMetricsTest, FirstOrderResponseClosedForms) {
  // y = 1 - exp(-t/tau) after a unit set-point step at t = 0:
  // rise 10-90 % = tau ln 9, settling 2 % = tau ln 50, overshoot 0,
  // IAE = sum exp(-t/tau) Ts ~ tau, ISE ~ tau/2, ITAE ~ tau^2.
  const double tau = 0.2, Ts = 1e-3;
  const int n = 5000;
  Eigen::VectorXd t(n), r(n), y(n), u(n);
  for (int k = 0; k < n; ++k) {
    t(k) = k * Ts;
    r(k) = 1.0;
    y(k) = 1.0 - std::exp(-t(k) / tau);
    u(k) = k < 10 ? 2.0 : 1.0;
  }
  ClosedLoopOptions o;
  const ClosedLoopMetrics m = ComputeClosedLoopMetrics(t, r, y, u, 0.0, 0.0, o);
  EXPECT_NEAR(m.rise_time, tau * std::log(9.0), Ts);
  EXPECT_NEAR(m.settling_time, tau * std::log(50.0), Ts);
  EXPECT_NEAR(m.overshoot_percent, 0.0, 1e-12);
  EXPECT_NEAR(m.iae, tau, 1e-3);  // geometric sum tau (1 + Ts/(2 tau))
  EXPECT_NEAR(m.ise, tau / 2.0, 1e-3);
  EXPECT_NEAR(m.itae, tau * tau, 1e-3);
  EXPECT_NEAR(m.first_move, 2.0, 0.0);
  EXPECT_NEAR(m.tv_u, 3.0, 1e-12);  // 0 -> 2 -> 1
  EXPECT_EQ(m.u_min, 1.0);
  EXPECT_EQ(m.u_max, 2.0);
  EXPECT_NEAR(m.steady_state_error, std::exp(-4.975 / tau), 1e-9);
  ASSERT_EQ(m.steps.size(), 1u);
}

// A level held by modulation wanders slowly: y = 1 - exp(-t/tau) plus a
// 0.06 sine of period 0.5 s after a unit step. Four consecutive samples
// (1 ms apart) see almost none of it, so the band stays 2 % of the step and
// the response never settles; with a floor of 0.07 at the set-point (what
// commission passes from its open-loop levels) it settles when the
// exponential has decayed below 0.07 - 0.06, near tau ln(1 / 0.01).
TEST(ClosedLoopMetricsTest, ASettlingBandFloorWidensTheBandForASlowWander) {
  const double tau = 0.1, Ts = 1e-3, a = 0.06;
  const int n = 3000;
  Eigen::VectorXd t(n), r = Eigen::VectorXd::Ones(n), y(n), u = Eigen::VectorXd::Zero(n);
  for (int k = 0; k < n; ++k) {
    t(k) = k * Ts;
    y(k) = 1.0 - std::exp(-t(k) / tau) + a * std::sin(2.0 * M_PI * t(k) / 0.5);
  }
  ClosedLoopOptions o;
  ClosedLoopMetrics m = ComputeClosedLoopMetrics(t, r, y, u, 0.0, 0.0, o);
  ASSERT_EQ(m.steps.size(), 1u);
  EXPECT_FALSE(m.steps[0].settled);
  EXPECT_NEAR(m.steps[0].settling_band, 0.02, 1e-3);
  o.settling_band_floor = [](double to) { return to == 1.0 ? 0.07 : 0.0; };
  m = ComputeClosedLoopMetrics(t, r, y, u, 0.0, 0.0, o);
  EXPECT_TRUE(m.steps[0].settled);
  EXPECT_DOUBLE_EQ(m.steps[0].settling_band, 0.07);
  EXPECT_GT(m.steps[0].settling_time, tau * std::log(1.0 / 0.07));
  EXPECT_LT(m.steps[0].settling_time, tau * std::log(1.0 / 0.01) + 0.5);
}

TEST(ClosedLoopMetricsTest, LoadStepPeakAndRecovery) {
  // After a load of -1 at t = 1: deviation -exp(-(t-1)/0.1); band 2 % of 1:
  // recovery when exp(-s/0.1) = 0.02, s = 0.1 ln 50.
  const double Ts = 1e-3;
  const int n = 3000;
  Eigen::VectorXd t(n), r = Eigen::VectorXd::Zero(n), y(n), u = Eigen::VectorXd::Zero(n);
  for (int k = 0; k < n; ++k) {
    t(k) = k * Ts;
    y(k) = t(k) < 1.0 - 1e-12 ? 0.0 : -std::exp(-(t(k) - 1.0) / 0.1);
  }
  ClosedLoopOptions o;
  o.load_steps = {{1.0, -1.0}};
  const ClosedLoopMetrics m = ComputeClosedLoopMetrics(t, r, y, u, 0.0, 0.0, o);
  EXPECT_NEAR(m.load_peak_deviation, -1.0, 1e-12);
  EXPECT_NEAR(m.load_recovery_time, 0.1 * std::log(50.0), Ts);
  EXPECT_TRUE(m.steps.empty());
  EXPECT_TRUE(std::isnan(m.rise_time));
}

TEST(ClosedLoopTest, SetpointsOutsideThePlantsOutputRangeAreRefused) {
  // The position twin's output range is its stroke, 0..0.1 m.
  IpaParameters p = DefaultIpaParameters(IpaMode::kPosition);
  IpaSimulator plant(p, 0.01);
  PidOptions po;
  po.gains.Kc = 3000.0;
  PidController pid(0.01, po);
  ClosedLoopOptions o;
  o.duration = 0.5;
  auto outside = ParseSignal("step:from=0.05,to=0.12,at=0.3");
  EXPECT_THAT([&] { SimulateClosedLoop(pid, plant, *outside, o); },
              ::testing::ThrowsMessage<InvalidArgument>(
                  ::testing::AllOf(::testing::HasSubstr("set-point 0.12 m at t = 0.3 s"),
                                   ::testing::HasSubstr("position range 0 .. 0.1 m"))));
  auto inside = ParseSignal("step:from=0.05,to=0.06,at=0.3");
  EXPECT_NO_THROW(SimulateClosedLoop(pid, plant, *inside, o));
  o.plant_range = false;  // the caller's own limits only
  EXPECT_NO_THROW(SimulateClosedLoop(pid, plant, *outside, o));
}

TEST(ClosedLoopTest, ActuatorLimitsAndNoise) {
  DmcOptions d;
  d.P = 126;
  d.M = 5;
  d.lambda = 2.25;
  DmcController dmc(PaperFopdtModel(), 0.01, d);
  LinearPlant plant(PaperFopdtModel(), 0.01);
  auto sp = ParseSignal("step:from=0,to=1,at=0.2");
  ClosedLoopOptions o;
  o.duration = 2.0;
  o.noise_std = 0.01;
  o.actuator.u_max = 0.8;
  const auto r = SimulateClosedLoop(dmc, plant, *sp, o);
  EXPECT_EQ(r.t.size(), 200);
  EXPECT_LE(r.u.maxCoeff(), 0.8);
  EXPECT_GT((r.y_meas - r.y).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_NEAR((r.y_meas - r.y).array().square().mean(), 1e-4, 3e-5);  // noise variance
  EXPECT_NEAR(r.metrics.steady_state_error, 0.0, 0.01);
  ClosedLoopOptions bad;
  bad.duration = -1;
  EXPECT_THROW(SimulateClosedLoop(dmc, plant, *sp, bad), InvalidArgument);
  LinearPlant other(PaperFopdtModel(), 0.02);
  EXPECT_THAT([&] { SimulateClosedLoop(dmc, other, *sp, o); },
              ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr("Ts = 0.02")));
}

// The metric keys of `pneumid control --json` and `pneumid run --json` (a
// contract), in order; a metric that does not exist in the run is null.
TEST(ClosedLoopMetricsTest, ToJsonKeepsTheCommandLineKeys) {
  ClosedLoopMetrics m;
  m.rise_time = 0.1;
  m.iae = 2.0;
  StepMetrics s;
  s.time = 1.0;
  s.to = 5.0;
  s.settling_time = 0.3;
  m.steps.push_back(s);
  const nlohmann::ordered_json j = m.ToJson();
  std::vector<std::string> keys;
  for (const auto& [key, value] : j.items()) keys.push_back(key);
  EXPECT_THAT(keys,
              ::testing::ElementsAre(
                  "rise_time", "overshoot_percent", "settling_time", "steady_state_error",
                  "first_move", "settling_band", "settled", "worst_overshoot_step",
                  "overshoot_beyond_ripple_percent", "worst_settling_step",
                  "worst_steady_state_error", "worst_steady_state_error_step", "iae", "ise", "itae",
                  "tv_u", "u_min", "u_max", "load_peak_deviation", "load_recovery_time", "steps"));
  EXPECT_EQ(j["rise_time"], 0.1);
  EXPECT_TRUE(j["overshoot_percent"].is_null());
  EXPECT_TRUE(j["load_recovery_time"].is_null());
  EXPECT_EQ(j["iae"], 2.0);
  ASSERT_EQ(j["steps"].size(), 1u);
  keys.clear();
  for (const auto& [key, value] : j["steps"][0].items()) keys.push_back(key);
  EXPECT_THAT(keys, ::testing::ElementsAre("time", "from", "to", "rise_time", "overshoot_percent",
                                           "settling_time", "steady_state_error", "first_move",
                                           "settling_band", "settled", "ripple", "steady_input",
                                           "overshoot_beyond_ripple_percent"));
  EXPECT_EQ(j["steps"][0]["settling_time"], 0.3);
  EXPECT_TRUE(j["steps"][0]["first_move"].is_null());
}

// Three set-point steps whose responses are written in closed form: the
// summary takes the worst overshoot and the longest settling time, steps[0]
// keeps the first step's, and a step that never settles makes the summary
// unsettled.
TEST(ClosedLoopMetricsTest, SummaryTakesTheWorstStep) {
  // Step k (from r_k to r_k+1 at t_k) answers with the underdamped
  // second-order response 1 - exp(-z w t) (cos(wd t) + z/sqrt(1-z^2) sin(wd t)),
  // whose overshoot is 100 exp(-pi z / sqrt(1 - z^2)) %.
  const double Ts = 1e-3, w = 20.0, dwell = 2.0;
  const double levels[] = {0.0, 10.0, 30.0, 20.0};
  const double zetas[] = {0.9, 0.35, 0.6};  // overshoot 0.15 %, 30.9 %, 9.48 %
  const int per = static_cast<int>(dwell / Ts);
  const int n = 3 * per;
  Eigen::VectorXd t(n), r(n), y(n), u = Eigen::VectorXd::Zero(n);
  for (int k = 0; k < n; ++k) {
    const int s = k / per;
    const double z = zetas[s], wd = w * std::sqrt(1 - z * z), tt = (k - s * per) * Ts;
    const double unit = 1 - std::exp(-z * w * tt) *
                                (std::cos(wd * tt) + z / std::sqrt(1 - z * z) * std::sin(wd * tt));
    t(k) = k * Ts;
    r(k) = levels[s + 1];
    y(k) = levels[s] + (levels[s + 1] - levels[s]) * unit;
  }
  ClosedLoopOptions o;
  const ClosedLoopMetrics m = ComputeClosedLoopMetrics(t, r, y, u, 0.0, 0.0, o);
  ASSERT_EQ(m.steps.size(), 3u);
  auto overshoot = [](double z) { return 100.0 * std::exp(-M_PI * z / std::sqrt(1 - z * z)); };
  EXPECT_NEAR(m.steps[0].overshoot_percent, overshoot(0.9), 0.01);
  EXPECT_NEAR(m.steps[1].overshoot_percent, overshoot(0.35), 0.05);
  EXPECT_NEAR(m.steps[2].overshoot_percent, overshoot(0.6), 0.05);
  EXPECT_NEAR(m.overshoot_percent, overshoot(0.35), 0.05);
  EXPECT_EQ(m.worst_overshoot_step, 1);
  // The lightly damped step settles last (about 4 / (z w) for a 2 % band).
  EXPECT_TRUE(m.settled);
  EXPECT_EQ(m.worst_settling_step, 1);
  EXPECT_EQ(m.settling_time, m.steps[1].settling_time);
  EXPECT_GT(m.settling_time, m.steps[0].settling_time);
  EXPECT_GT(m.settling_time, m.steps[2].settling_time);
  EXPECT_NEAR(m.settling_time, 4.0 / (0.35 * w), 0.1);
  EXPECT_EQ(m.settling_band, m.steps[1].settling_band);
  EXPECT_EQ(m.rise_time, m.steps[0].rise_time);
  const nlohmann::ordered_json j = m.ToJson();
  EXPECT_EQ(j["worst_overshoot_step"], 1);
  EXPECT_EQ(j["steps"][0]["overshoot_percent"], m.steps[0].overshoot_percent);

  // The last step now never reaches its set-point (it stops 10 % short):
  // the summary is unsettled, with no settling time, and names that step.
  Eigen::VectorXd y_short = y;
  for (int k = 2 * per; k < n; ++k) y_short(k) = 30.0 + (y(k) - 30.0) * 0.9;
  const ClosedLoopMetrics bad = ComputeClosedLoopMetrics(t, r, y_short, u, 0.0, 0.0, o);
  EXPECT_FALSE(bad.settled);
  EXPECT_TRUE(std::isnan(bad.settling_time));
  EXPECT_EQ(bad.worst_settling_step, 2);
  EXPECT_TRUE(bad.steps[1].settled);
  // It ends at 21 for 20: r - y = -1 there, the summary's worst steady-state
  // error (the others are the ~1e-6 tails of decaying responses).
  EXPECT_NEAR(bad.steps[2].steady_state_error, -1.0, 1e-3);
  EXPECT_EQ(bad.worst_steady_state_error, bad.steps[2].steady_state_error);
  EXPECT_EQ(bad.worst_steady_state_error_step, 2);
  EXPECT_LT(std::abs(m.worst_steady_state_error), 1e-3);
}

// A load step inside a set-point segment ends the step's window: the dip it
// causes is the load response, not overshoot of the set-point step.
TEST(ClosedLoopMetricsTest, LoadStepEndsTheStepWindow) {
  const int n = 400;
  Eigen::VectorXd t(n), r = Eigen::VectorXd::Constant(n, 100.0), y(n), u = Eigen::VectorXd::Zero(n);
  for (int k = 0; k < n; ++k) {
    t[k] = 0.01 * k;
    y[k] = 100.0 * (1.0 - std::exp(-t[k] / 0.1)) -
           (t[k] >= 2.0 ? 30.0 * std::exp(-(t[k] - 2.0) / 0.1) : 0.0);
  }
  ClosedLoopOptions o;
  o.duration = 4.0;
  o.load_steps.push_back({2.0, -30.0});
  const ClosedLoopMetrics m = ComputeClosedLoopMetrics(t, r, y, u, 0.0, 0.0, o);
  ASSERT_EQ(m.steps.size(), 1u);
  EXPECT_NEAR(m.overshoot_percent, 0.0, 1e-9);
  EXPECT_NEAR(m.settling_time, 0.1 * std::log(50.0), 0.01);
  EXPECT_NEAR(m.load_peak_deviation, -30.0, 0.5);
  // Not told of the load step, the dip counts against the step's settling.
  o.load_steps.clear();
  EXPECT_GT(ComputeClosedLoopMetrics(t, r, y, u, 0.0, 0.0, o).settling_time, 2.0);
}

// The plant's input range applies by default, and a controller clipped by it
// behaves exactly as one given the same limits itself: Applied() makes its
// internal state (DMC prediction, GPC filtered moves, PID integral) follow the
// applied input. The requested input is kept beside the applied one.
TEST(ClosedLoopTest, PlantRangeAppliesByDefaultWithoutWindup) {
  const double Ts = 0.01;
  const TransferFunction model = TransferFunction::Fopdt(1.6, 0.245, 0.001);
  const auto sp = ParseSignal("staircase:levels=20 130 40,dwell=1.5");
  ClosedLoopOptions o;
  o.duration = 4.5;
  InputLimits duty;
  duty.u_min = 0.0;
  duty.u_max = 100.0;
  auto run = [&](Controller& c) {
    IpaSimulator ipa(IpaParameters{}, Ts, 1);
    return SimulateClosedLoop(c, ipa, *sp, o);
  };
  for (const std::string kind : {"dmc", "gpc", "pid"}) {
    std::unique_ptr<Controller> free, limited;
    if (kind == "dmc") {
      DmcOptions d;
      free = std::make_unique<DmcController>(model, Ts, d);
      d.limits = duty;
      limited = std::make_unique<DmcController>(model, Ts, d);
    } else if (kind == "gpc") {
      GpcOptions g;
      free = std::make_unique<GpcController>(model, Ts, g);
      g.limits = duty;
      limited = std::make_unique<GpcController>(model, Ts, g);
    } else {
      PidOptions p;
      p.gains = {2.0, 0.25, 0.0};
      free = std::make_unique<PidController>(Ts, p);
      p.limits = duty;
      limited = std::make_unique<PidController>(Ts, p);
    }
    const ClosedLoopResult a = run(*free);
    const ClosedLoopResult b = run(*limited);
    EXPECT_GE(a.u.minCoeff(), 0.0) << kind;
    EXPECT_LE(a.u.maxCoeff(), 100.0) << kind;
    EXPECT_GT(a.u_requested.maxCoeff(), 100.0) << kind << ": the 130 N step asks for more";
    EXPECT_LT((a.u - b.u).cwiseAbs().maxCoeff(), 1e-9) << kind;
    EXPECT_LT((a.y - b.y).cwiseAbs().maxCoeff(), 1e-9) << kind;
  }
  // Without the plant range the request is applied as it is.
  o.plant_range = false;
  DmcController unlimited(model, Ts, DmcOptions{});
  EXPECT_GT(run(unlimited).u.maxCoeff(), 100.0);
}

// Settling against a band of max(2 % of the step, the measured ripple): a
// response with a +-3 N alternating ripple (6 N peak to peak, wider than 2 % of
// a 100 N step) settles, with the band widened to the ripple; a slow +-10 N
// oscillation does not (4 consecutive samples see little of it, the band
// stays 2 N).
TEST(ClosedLoopMetricsTest, SettlingBandWidensToTheMeasuredRippleOnly) {
  const int n = 400;
  const double Ts = 0.01;
  Eigen::VectorXd t(n), r(n), u = Eigen::VectorXd::Zero(n), ripple(n), slow(n);
  for (int k = 0; k < n; ++k) {
    t[k] = k * Ts;
    r[k] = 100.0;
    const double approach = 100.0 * (1.0 - std::exp(-t[k] / 0.1));
    ripple[k] = approach + (k % 2 == 0 ? 3.0 : -3.0);
    slow[k] = approach + 10.0 * std::sin(2.0 * M_PI * t[k] / 0.8);
  }
  ClosedLoopOptions o;
  o.duration = n * Ts;
  const ClosedLoopMetrics a = ComputeClosedLoopMetrics(t, r, ripple, u, 0.0, 0.0, o);
  ASSERT_EQ(a.steps.size(), 1u);
  EXPECT_NEAR(a.steps[0].ripple, 6.0, 0.01);  // the approach adds < 0.01 N in the tail
  EXPECT_NEAR(a.settling_band, a.steps[0].ripple, 1e-12);
  EXPECT_TRUE(a.settled);
  // |y - r| = 100 exp(-t/0.1) + 3 <= 6 from t = 0.1 ln(100/3) = 0.351 s on.
  EXPECT_NEAR(a.settling_time, 0.1 * std::log(100.0 / 3.0), 0.011);
  const ClosedLoopMetrics b = ComputeClosedLoopMetrics(t, r, slow, u, 0.0, 0.0, o);
  EXPECT_LT(b.settling_band, 2.5);  // 4 samples see 20 sin(3 pi / 160) = 1.2 N of it
  EXPECT_FALSE(b.settled);
  EXPECT_TRUE(std::isnan(b.settling_time));
  // Without ripple the band is 2 % of the step.
  Eigen::VectorXd clean(n);
  for (int k = 0; k < n; ++k) clean[k] = 100.0 * (1.0 - std::exp(-t[k] / 0.1));
  const ClosedLoopMetrics c = ComputeClosedLoopMetrics(t, r, clean, u, 0.0, 0.0, o);
  EXPECT_NEAR(c.settling_band, 2.0, 1e-9);
  EXPECT_TRUE(c.settled);
  EXPECT_NEAR(c.settling_time, 0.1 * std::log(50.0), 0.01);
}

// The overshoot beyond the ripple: a response that reaches 100 N without
// overshoot and then ripples by +-3 N (6 N peak to peak) peaks 3 % above the
// step but 0 % beyond half its ripple; with a bump of 8 N at 0.5 s on top
// (the response alone, without the ripple, overshoots by 8 - 100 exp(-5) =
// 7.33 %), the part beyond the ripple is the response's overshoot.
TEST(ClosedLoopMetricsTest, OvershootBeyondRippleIsTheResponsesOwnOvershoot) {
  const int n = 400;
  const double Ts = 0.01;
  Eigen::VectorXd t(n), r(n), u = Eigen::VectorXd::Zero(n), flat(n), bump(n), clean(n);
  for (int k = 0; k < n; ++k) {
    t[k] = k * Ts;
    r[k] = 100.0;
    const double approach = 100.0 * (1.0 - std::exp(-t[k] / 0.1));
    const double ripple = k % 2 == 0 ? 3.0 : -3.0;
    flat[k] = approach + ripple;
    clean[k] = approach + 8.0 * std::exp(-std::pow((t[k] - 0.5) / 0.05, 2));
    bump[k] = clean[k] + ripple;
  }
  ClosedLoopOptions o;
  o.duration = n * Ts;
  const ClosedLoopMetrics a = ComputeClosedLoopMetrics(t, r, flat, u, 0.0, 0.0, o);
  ASSERT_EQ(a.steps.size(), 1u);
  EXPECT_NEAR(a.steps[0].overshoot_percent, 3.0, 1e-6);
  EXPECT_NEAR(a.steps[0].overshoot_beyond_ripple_percent, 0.0, 0.01);
  const ClosedLoopMetrics b = ComputeClosedLoopMetrics(t, r, bump, u, 0.0, 0.0, o);
  const ClosedLoopMetrics c = ComputeClosedLoopMetrics(t, r, clean, u, 0.0, 0.0, o);
  ASSERT_EQ(b.steps.size(), 1u);
  EXPECT_NEAR(c.overshoot_percent, 8.0 - 100.0 * std::exp(-5.0), 0.01);
  EXPECT_NEAR(b.overshoot_percent, c.overshoot_percent + 3.0, 0.01);
  EXPECT_NEAR(b.steps[0].overshoot_beyond_ripple_percent, c.overshoot_percent, 0.02);
  EXPECT_NEAR(b.overshoot_beyond_ripple_percent, b.steps[0].overshoot_beyond_ripple_percent, 1e-12);
  // A hold too short for a ripple window (10 samples): the overshoot itself.
  const int m = 10;
  Eigen::VectorXd ts(m), rs = Eigen::VectorXd::Constant(m, 100.0), us = Eigen::VectorXd::Zero(m);
  Eigen::VectorXd ys(m);
  ys << 40, 80, 105, 102, 100, 100, 100, 100, 100, 100;
  for (int k = 0; k < m; ++k) ts[k] = k * Ts;
  o.duration = m * Ts;
  const ClosedLoopMetrics d = ComputeClosedLoopMetrics(ts, rs, ys, us, 0.0, 0.0, o);
  ASSERT_EQ(d.steps.size(), 1u);
  EXPECT_TRUE(std::isnan(d.steps[0].ripple));
  EXPECT_NEAR(d.steps[0].overshoot_percent, 5.0, 1e-9);
  EXPECT_NEAR(d.steps[0].overshoot_beyond_ripple_percent, 5.0, 1e-9);
}

// The input that holds a level is the mean input over the ripple's window,
// the last quarter of the hold ending at a load step inside it: with u = 10
// until 2 s, alternating 80/100 (mean 90) over [2, 3.2) and 50 after a load
// step at 3.2 s, the 0..4 s hold ends at 3.2 s and its window is [2.4, 3.2):
// steady_input 90 (the whole hold's mean would be 38.75). A 6-sample hold
// has none.
TEST(ClosedLoopMetricsTest, SteadyInputIsTheMeanInputOverTheRippleWindow) {
  const int n = 406;
  const double Ts = 0.01;
  Eigen::VectorXd t(n), r(n), y = Eigen::VectorXd::Zero(n), u(n);
  for (int k = 0; k < n; ++k) {
    t[k] = k * Ts;
    r[k] = k < 400 ? 100.0 : 50.0;
    u[k] = k < 200 ? 10.0 : k < 320 ? (k % 2 == 0 ? 80.0 : 100.0) : 50.0;
  }
  ClosedLoopOptions o;
  o.duration = n * Ts;
  o.load_steps.push_back(LoadStep{3.2, -15.0});
  const ClosedLoopMetrics m = ComputeClosedLoopMetrics(t, r, y, u, 0.0, 0.0, o);
  ASSERT_EQ(m.steps.size(), 2u);
  EXPECT_NEAR(m.steps[0].steady_input, 90.0, 1e-12);
  EXPECT_TRUE(std::isnan(m.steps[1].steady_input));
  EXPECT_TRUE(m.steps[1].ToJson()["steady_input"].is_null());
  EXPECT_EQ(m.steps[0].ToJson()["steady_input"], 90.0);
}

}  // namespace
}  // namespace pneumid

namespace pneumid {
namespace {

// A stop flag ends the simulation at the next sample with Cancelled (a
// server whose client left); unset or false, it changes nothing.
TEST(ClosedLoopTest, AStopFlagCancelsAtTheNextSample) {
  LinearPlant plant(PaperFopdtModel(), 0.01);
  PidOptions po;
  po.gains = {1.0, 0.5, 0.0};
  PidController pid(0.01, po);
  const auto sp = ParseSignal("step:to=1");
  ClosedLoopOptions o;
  o.duration = 1.0;
  std::atomic<bool> stop{false};
  o.stop = &stop;
  const auto running = SimulateClosedLoop(pid, plant, *sp, o);
  EXPECT_EQ(running.t.size(), 100);
  stop = true;
  EXPECT_THAT([&] { SimulateClosedLoop(pid, plant, *sp, o); },
              ::testing::ThrowsMessage<Cancelled>(::testing::HasSubstr("stopped on request")));
}

}  // namespace
}  // namespace pneumid
