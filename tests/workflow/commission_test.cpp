// Commission (workflow/commission.hpp) on plants whose answers are known in
// closed form: a first-order plant with dead time (the probe's estimates),
// plants that cannot be commissioned (no response, integrating, a range out
// of reach, a budget too short) and a stop request.
#include "pneumid/workflow/commission.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <tuple>
#include <vector>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/plant/plant_factory.hpp"

namespace pneumid {
namespace {

using ::testing::Contains;
using ::testing::HasSubstr;
using ::testing::Not;

std::string TempDir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("pneumid_commission_" + name);
  std::filesystem::create_directories(dir);
  return dir.string();
}

CommissionOptions Options(const std::string& name) {
  CommissionOptions o;
  o.directory = TempDir(name);
  o.u_min = 0.0;
  o.u_max = 10.0;
  o.budget = 60.0;
  o.methods = {"arx", "oe"};
  return o;
}

// x(k+1) = a x(k) + b u(k), y = x: a constant sensor (a = 1, b = 0), an
// integrator (a = 1, b = k Ts), unstable for a > 1; or n first-order lags of
// time constant T in series (exact discretisation, stable for any n) behind
// a dead time.
class TestPlant : public Plant {
 public:
  TestPlant(double a, double b) : a_(a), b_(b), delay_(0), x_(1, 0.0) {}
  TestPlant(int n, double T, double dead_time)
      : a_(std::exp(-0.01 / T)),
        b_(1.0 - a_),
        delay_(static_cast<std::size_t>(std::lround(dead_time / 0.01))),
        x_(static_cast<std::size_t>(n), 0.0) {}
  void Reset() override { std::fill(x_.begin(), x_.end(), 0.0), u_.clear(), t_ = 0.0; }
  double Measure() override { return x_.back(); }
  void Advance(double u) override {
    u_.push_back(u);
    double in = u_.size() > delay_ ? u_[u_.size() - 1 - delay_] : 0.0;
    for (double& x : x_) in = x = a_ * x + b_ * in;
    t_ += Ts();
  }
  double Ts() const override { return 0.01; }
  double time() const override { return t_; }
  std::string Describe() const override { return "test plant"; }

 private:
  double a_, b_;
  std::size_t delay_;
  std::vector<double> x_, u_;
  double t_ = 0.0;
};

TEST(Commission, TheProbeMeasuresAFirstOrderPlantWithDeadTime) {
  // K = 2, tau = 0.5 s, theta = 0.1 s: the two-point method is exact on a
  // FOPDT up to the sampling (one sample, 0.01 s).
  auto plant = MakePlant("fopdt:K=2,tau=0.5,theta=0.1", 0.01);
  CommissionOptions o = Options("fopdt");
  o.range_min = 2.0;
  o.range_max = 18.0;
  o.settling = 2.0;  // tau = 0.5 s, theta = 0.1 s: about 4 (tau + theta)
  o.budget = 160.0;  // the experiment, and a verification run of 12 levels of 4 s
  const CommissionResult r = Commission(*plant, o);
  EXPECT_NEAR(r.experiment.gain, 2.0, 0.01);
  EXPECT_NEAR(r.experiment.time_constant, 0.5, 0.015);
  EXPECT_NEAR(r.experiment.dead_time, 0.1, 0.015);
  EXPECT_NEAR(r.experiment.reachable_min, 0.0, 1e-6);
  EXPECT_NEAR(r.experiment.reachable_max, 20.0, 0.1);
  EXPECT_LE(r.experiment.duration, o.budget + 0.02);
  EXPECT_GT(r.experiment.estimation.size(), 0);
  EXPECT_GT(r.experiment.validation.size(), 0);
  // A linear plant: the linear models fit the held-out part almost exactly
  // (up to its start, 4 tau + theta after the last estimation level's step:
  // e^-4 = 1.8 % of that step is left), and the loop meets the specification.
  ASSERT_FALSE(r.identification.models.empty());
  EXPECT_GT(r.identification.models.front().validation_fit_percent, 98.5);
  ASSERT_FALSE(r.attempts.empty());
  EXPECT_EQ(r.termination, Termination::kSuccess) << r.message;
  EXPECT_LE(r.attempts.back().result.metrics.overshoot_percent, 5.0);
  EXPECT_TRUE(std::filesystem::exists(r.model_file));
  const auto j = r.ToJson();
  EXPECT_EQ(j["termination"], "success");
  EXPECT_TRUE(j["verification"].contains("steps"));
  EXPECT_TRUE(j["experiment"].contains("duration"));
}

TEST(Commission, TheMpcWeighsTheMeasurementByTheNoiseMeasuredAtRest) {
  // A noisy linear plant: the Kalman filter's measurement variance is the
  // square of the output's standard deviation at rest, not the default 1.
  PlantOptions po;
  po.noise_sigma = 0.05;
  auto plant = MakePlant("fopdt:K=2,tau=0.5,theta=0.1", 0.01, po);
  CommissionOptions o = Options("fopdt-noise");
  o.range_min = 2.0;
  o.range_max = 18.0;
  o.settling = 2.0;
  o.budget = 160.0;  // the experiment, and a verification run of 12 levels of 8 s
  o.controller = "mpc";
  const CommissionResult r = Commission(*plant, o);
  EXPECT_NEAR(r.experiment.noise_std, 0.05, 0.015);
  EXPECT_NEAR(r.settings.measurement_noise, r.experiment.noise_std * r.experiment.noise_std, 1e-12);
  EXPECT_DOUBLE_EQ(r.ToJson()["experiment"]["noise_std"].get<double>(), r.experiment.noise_std);
}

TEST(Commission, ThePwmLoopPeriodIsAWholeNumberOfPwmPeriodsOfAtLeast3Ms) {
  EXPECT_DOUBLE_EQ(PwmLoopPeriod(300.0), 1.0 / 300.0);  // the IPA: one period
  EXPECT_DOUBLE_EQ(PwmLoopPeriod(50.0), 0.02);
  EXPECT_NEAR(PwmLoopPeriod(1000.0), 0.003, 1e-15);  // three periods
  EXPECT_NEAR(PwmLoopPeriod(400.0), 0.005, 1e-15);   // two periods of 2.5 ms
  EXPECT_THROW(PwmLoopPeriod(0.0), InvalidArgument);
  EXPECT_THROW(PwmLoopPeriod(std::nan("")), InvalidArgument);
}

// The command and the app take the loop period from one place: the IPA
// simulator's PWM period (300 Hz on the default twin, 50 Hz on the slow-valve
// twin), any other plant the caller's fallback.
TEST(Commission, TheDefaultLoopPeriodIsThePwmPeriodOnTheIpaOnly) {
  EXPECT_DOUBLE_EQ(DefaultLoopPeriod(*MakePlant("ipa", 0.01), 0.01), 1.0 / 300.0);
  const std::string slow = std::string(PNEUMID_SOURCE_DIR) + "/config/ipa_slow_valves.toml";
  EXPECT_DOUBLE_EQ(DefaultLoopPeriod(*MakePlant("ipa:config=" + slow, 0.01), 0.01), 0.02);
  EXPECT_DOUBLE_EQ(DefaultLoopPeriod(*MakePlant("fopdt-paper", 0.01), 0.01), 0.01);
  EXPECT_DOUBLE_EQ(DefaultLoopPeriod(*MakePlant("fopdt-paper", 0.05), 0.05), 0.05);
}

TEST(Commission, TheCommissionPlantRunsAtTheGivenOrTheDefaultPeriod) {
  const CommissionPlant ipa = MakeCommissionPlant("ipa", std::nullopt, PlantOptions{});
  EXPECT_DOUBLE_EQ(ipa.Ts, 1.0 / 300.0);
  EXPECT_DOUBLE_EQ(ipa.plant->Ts(), 1.0 / 300.0);
  const CommissionPlant given = MakeCommissionPlant("ipa", 0.01, PlantOptions{});
  EXPECT_DOUBLE_EQ(given.Ts, 0.01);
  EXPECT_DOUBLE_EQ(given.plant->Ts(), 0.01);
  const CommissionPlant linear =
      MakeCommissionPlant("fopdt-paper", std::nullopt, PlantOptions{}, 0.05);
  EXPECT_DOUBLE_EQ(linear.Ts, 0.05);
  EXPECT_DOUBLE_EQ(linear.plant->Ts(), 0.05);
  EXPECT_THROW(MakeCommissionPlant("ipa", -0.01, PlantOptions{}), InvalidArgument);
  EXPECT_THROW(MakeCommissionPlant("ipa", std::nullopt, PlantOptions{}, 0.0), InvalidArgument);
}

TEST(Commission, APlantThatDoesNotRespondIsNamed) {
  TestPlant plant(1.0, 0.0);
  const CommissionResult r = Commission(plant, Options("dead"));
  EXPECT_EQ(r.termination, Termination::kFailure);
  EXPECT_THAT(r.message, HasSubstr("does not respond"));
  EXPECT_GT(r.experiment.data.size(), 0);  // the data so far are kept
}

TEST(Commission, AnIntegratingPlantDoesNotSettle) {
  TestPlant plant(1.0, 0.01);  // y += u Ts
  const CommissionResult r = Commission(plant, Options("integrating"));
  EXPECT_EQ(r.termination, Termination::kFailure);
  EXPECT_THAT(r.message, HasSubstr("did not settle"));
  EXPECT_LE(r.plant_time, 0.25 * 60.0 + 2.0);
}

TEST(Commission, AnUnstablePlantIsStoppedWhenItsOutputDiverges) {
  // exp(2 t): the probe sees the change per 0.5 s grow 2.7-fold again and
  // again and stops within seconds, not at the cap (15 s of a 60 s budget).
  TestPlant plant(std::exp(0.02), 0.01);
  const CommissionResult r = Commission(plant, Options("unstable"));
  EXPECT_EQ(r.termination, Termination::kFailure);
  EXPECT_THAT(r.message, HasSubstr("the output diverges after an input step from 0 to 5"));
  EXPECT_THAT(r.message, HasSubstr("2.72-fold"));
  EXPECT_LE(r.plant_time, 6.0);
  ASSERT_GT(r.experiment.data.size(), 0);             // the data so far are kept
  EXPECT_EQ(r.experiment.data.u(0).tail(1)[0], 0.0);  // the plant is left at the lowest input
  // Slower divergence, exp(0.5 t): 16 s after the step, before the cap of a 120 s budget.
  TestPlant slower(std::exp(0.005), 0.01);
  CommissionOptions o = Options("unstable-slow");
  o.budget = 120.0;
  const CommissionResult s = Commission(slower, o);
  EXPECT_THAT(s.message, HasSubstr("the output diverges"));
  EXPECT_LE(s.plant_time, 20.0);
}

TEST(Commission, SlowHighOrderPlantsAreNotMistakenForUnstableOnes) {
  // PT8 of T = 4 s behind 5 s of dead time, PT12 of T = 2 s: their slopes
  // grow for a long time after the step, at ratios that keep falling.
  for (const auto& [n, T, dead] :
       {std::tuple{8, 4.0, 5.0}, std::tuple{12, 2.0, 0.0}, std::tuple{3, 10.0, 10.0}}) {
    TestPlant plant(n, T, dead);
    const CommissionResult r = Commission(plant, Options("slow-pt" + std::to_string(n)));
    EXPECT_EQ(r.termination, Termination::kFailure);
    EXPECT_THAT(r.message, Not(HasSubstr("diverges"))) << "PT" << n << ": " << r.message;
  }
}

// The default specification follows the actuator: the force loop's 5 % and
// 0.5 s, a positioning drive's 2 % and 1 s (docs/position.md), whichever it
// was before.
TEST(Commission, TheDefaultSpecificationFollowsTheActuator) {
  CommissionOptions o;
  SetDefaultSpecification(o, PlantActuator(*MakePlant("ipa-position", 1.0 / 300.0)));
  EXPECT_EQ(o.overshoot, 2.0);
  EXPECT_EQ(o.settling, 1.0);
  SetDefaultSpecification(o, PlantActuator(*MakePlant("ipa", 1.0 / 300.0)));
  EXPECT_EQ(o.overshoot, 5.0);
  EXPECT_EQ(o.settling, 0.5);
  Actuator integrator;  // a generic one that integrates
  integrator.integrating = true;
  SetDefaultSpecification(o, integrator);
  EXPECT_EQ(o.overshoot, 2.0);
}

// The IPA's position twin integrates its input: the pulses measure its
// velocity gain (the rig's nominal 0.004 m/s per %, within the coasting
// after each pulse), the PD follows the design rule Kc Ki = 3 / tau, Kc Ki Td
// = 1 with tau = settling / 8, and the verification passes at 0.1 mm.
TEST(Commission, APositioningDriveGetsAPdFromItsVelocityGain) {
  auto plant = MakePlant("ipa-position", 1.0 / 300.0);
  CommissionOptions o;
  o.directory = TempDir("position");
  o.overshoot = 2.0;
  o.settling = 1.0;
  const CommissionResult r = Commission(*plant, o);
  ASSERT_EQ(r.termination, Termination::kSuccess) << r.message;
  const double Ki = r.experiment.gain;
  EXPECT_NEAR(Ki, 0.004, 0.0006);
  EXPECT_LE(r.experiment.duration, 10.0);
  EXPECT_EQ(r.settings.controller, "pid");
  const double tau = 1.0 / 8.0;
  EXPECT_NEAR(r.settings.pid_kc * Ki * tau, 3.0, 1e-9);
  EXPECT_NEAR(r.settings.pid_td, tau / 3.0, 1e-12);
  EXPECT_EQ(r.controller_model, fmt::format("tf:num={:.6g},den=1 0", Ki));
  for (const StepMetrics& s : r.attempts.back().result.metrics.steps)
    if (s.time > 0.0) EXPECT_LE(std::abs(s.steady_state_error), 1e-4) << s.time;
}

TEST(Commission, ARangeOutOfReachNamesTheReachableRange) {
  auto plant = MakePlant("fopdt:K=2,tau=0.5,theta=0.1", 0.01);
  CommissionOptions o = Options("range");
  o.range_min = 5.0;
  o.range_max = 50.0;
  const CommissionResult r = Commission(*plant, o);
  EXPECT_EQ(r.termination, Termination::kFailure);
  EXPECT_THAT(r.message, HasSubstr("cannot be reached"));
  EXPECT_THAT(r.message, HasSubstr("reaches 0..19.9"));  // up to K u_max = 20 after theta + 6 tau
}

TEST(Commission, ABudgetTooShortForTheTimeScaleSaysWhatItNeeds) {
  auto plant = MakePlant("fopdt:K=2,tau=0.5,theta=0.1", 0.01);
  CommissionOptions o = Options("budget");
  o.budget = 12.0;
  const CommissionResult r = Commission(*plant, o);
  EXPECT_EQ(r.termination, Termination::kFailure);
  EXPECT_THAT(r.message, HasSubstr("too short"));
}

TEST(Commission, AStopRequestEndsAtTheSafeInputWithTheData) {
  auto plant = MakePlant("fopdt:K=2,tau=0.5,theta=0.1", 0.01);
  CommissionOptions o = Options("stop");
  std::atomic<bool> stop{false};
  o.stop = &stop;
  o.progress = [&](const std::string& stage, double) {
    if (stage == "sweep") stop = true;
  };
  const CommissionResult r = Commission(*plant, o);
  EXPECT_EQ(r.termination, Termination::kStopped);
  EXPECT_GT(r.experiment.data.size(), 0);
  EXPECT_TRUE(r.attempts.empty());
}

// A plant that cannot be reset (as one behind an I/O backend) and raises a
// stop flag at its first measurement once armed.
class NoResetPlant : public Plant {
 public:
  NoResetPlant(std::unique_ptr<Plant> inner, std::atomic<bool>* stop)
      : inner_(std::move(inner)), stop_(stop) {}
  void Reset() override { inner_->Reset(); }
  bool can_reset() const override { return false; }
  double Measure() override {
    if (armed) {
      stop_->store(true);
      ++measured_armed;
    }
    return inner_->Measure();
  }
  void Advance(double u) override {
    inner_->Advance(u);
    if (armed) last_u = u;
  }
  double Ts() const override { return inner_->Ts(); }
  double time() const override { return inner_->time(); }
  std::string Describe() const override { return "no-reset " + inner_->Describe(); }
  bool armed = false;
  int measured_armed = 0;
  double last_u = std::nan("");

 private:
  std::unique_ptr<Plant> inner_;
  std::atomic<bool>* stop_;
};

// Over a plant that cannot be reset, the rest before a verification run
// (the safe input held, not recorded) honours a stop request at its next
// sample, as the experiment does, and leaves the plant at the safe input.
TEST(Commission, AStopRequestDuringTheRestBeforeAVerificationRunEndsThere) {
  std::atomic<bool> stop{false};
  NoResetPlant plant(MakePlant("fopdt:K=2,tau=0.5,theta=0.1", 0.01), &stop);
  CommissionOptions o = Options("rest_stop");
  o.range_min = 2.0;
  o.range_max = 18.0;
  o.settling = 2.0;
  o.budget = 160.0;  // the experiment, and a verification run of 12 levels of 8 s
  o.stop = &stop;
  o.progress = [&](const std::string& stage, double) {
    if (stage == "verify") plant.armed = true;
  };
  const CommissionResult r = Commission(plant, o);
  EXPECT_EQ(r.termination, Termination::kStopped);
  EXPECT_THAT(r.message, HasSubstr("before a verification run: stopped on request"));
  EXPECT_TRUE(r.attempts.empty());
  EXPECT_EQ(plant.measured_armed, 1);  // the hold's first sample; the second sees the stop
  EXPECT_EQ(plant.last_u, 0.0);        // u_min: the safe input
}

// Commission on the IPA twin of `po` with the default specification and the
// plant's input gaps, as `pneumid commission --plant ipa` does.
CommissionResult CommissionIpa(const PlantOptions& po, CommissionOptions o) {
  CommissionPlant made = MakeCommissionPlant("ipa", std::nullopt, po);
  SetDefaultSpecification(o, PlantActuator(*made.plant));
  SetInputGaps(o, *made.plant, "plant");
  return Commission(*made.plant, o);
}

TEST(Commission, ARippleInsideAValveGapNamesTheSetPointsAndTheGap) {
  // Without a sensor filter the default twin's fast chamber shows the
  // modulation across the exhaust valve's gap (duty 85..100 % at 300 Hz, no
  // exhaust pulse of the minimum width): the forces there (135-193 N) ripple
  // by tens of newtons, and the diagnosis names those set-points and the gap.
  const std::string config = TempDir("ipa-no-filter") + "/ipa.toml";
  {
    std::ofstream f(config);
    f << "[sensors]\npressure_filter_time_constant = 0.0\n";
  }
  PlantOptions po;
  po.config_path = config;
  CommissionOptions o;
  o.directory = TempDir("ipa-no-filter");
  const CommissionResult r = CommissionIpa(po, o);
  EXPECT_FALSE(r.passed());
  EXPECT_THAT(r.limits,
              Contains(AllOf(HasSubstr("need a mean input inside the actuator's input gaps"),
                             HasSubstr("gap 85..100"))));
  EXPECT_THAT(r.limits, Not(Contains(HasSubstr("the loop cycles at some levels"))));
}

TEST(Commission, AnOvershootAtAValveGapNamesTheStepAndTheGap) {
  // The GPC over 20..150 N on the default twin undershoots the step down
  // from 150 N (held inside the exhaust valve's gap, duty 85..100 %) to
  // 134.4 N (duty 84.4 %, at the gap's edge) by 6.9 % at every
  // aggressiveness: the diagnosis names the step and the gap, says the
  // softer designs were tried, and does not call it a model error.
  CommissionOptions o;
  o.directory = TempDir("ipa-gpc-gap");
  o.controller = "gpc";
  o.range_min = 20.0;
  o.range_max = 150.0;
  const CommissionResult r = CommissionIpa(PlantOptions{}, o);
  ASSERT_FALSE(r.passed());
  EXPECT_THAT(r.limits,
              Contains(AllOf(HasSubstr("overshoot at the actuator's input gaps"),
                             HasSubstr("150 -> 134.4 (input 84"), HasSubstr("gap 85..100"))));
  EXPECT_THAT(r.limits, Not(Contains(HasSubstr("model error"))));
  EXPECT_THAT(r.suggestions,
              Contains(HasSubstr("softer designs (down to aggressiveness 0.125) did not pass")));
  EXPECT_THAT(r.suggestions, Not(Contains(HasSubstr("a lower --aggressiveness"))));
}

TEST(Commission, InvalidOptionsNameTheField) {
  auto plant = MakePlant("fopdt:K=2,tau=0.5,theta=0.1", 0.01);
  CommissionOptions o = Options("invalid");
  o.budget = -1.0;
  EXPECT_THROW(Commission(*plant, o), InvalidArgument);
  o = Options("invalid");
  o.controller = "fuzzy";
  try {
    Commission(*plant, o);
    FAIL();
  } catch (const InvalidArgument& e) {
    EXPECT_THAT(e.what(), HasSubstr("fuzzy"));
  }
  o = Options("invalid");
  o.u_min = o.u_max = std::numeric_limits<double>::quiet_NaN();  // a linear plant has no range
  EXPECT_THROW(Commission(*plant, o), InvalidArgument);
}

}  // namespace
}  // namespace pneumid
