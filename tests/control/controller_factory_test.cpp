// Controller settings as users give them: the inferred tuning rule (shared by
// `pneumid control`, `pneumid run` and the bindings), parsing errors naming
// the setting, and what a design reports about itself.
#include "pneumid/control/controller_factory.hpp"

#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "pneumid/common/check.hpp"
#include "pneumid/control/closed_loop.hpp"
#include "pneumid/models/model_file.hpp"
#include "pneumid/plant/linear_plant.hpp"
#include "pneumid/plant/signal.hpp"

namespace pneumid {
namespace {

constexpr double kTs = 0.01;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

TEST(InferTuningRuleTest, NamedRuleWinsElseExplicitOnlyWithAllThreeSettings) {
  EXPECT_EQ(InferTuningRule("", 0, 0, kNaN), TuningRule::kShridharCooper);
  EXPECT_EQ(InferTuningRule("", 100, 5, 1.0), TuningRule::kExplicit);
  // Any one of P, M, lambda missing: the default rule, with the others as overrides.
  EXPECT_EQ(InferTuningRule("", 100, 5, kNaN), TuningRule::kShridharCooper);
  EXPECT_EQ(InferTuningRule("", 0, 5, 1.0), TuningRule::kShridharCooper);
  EXPECT_EQ(InferTuningRule("", 100, 0, 1.0), TuningRule::kShridharCooper);
  EXPECT_EQ(InferTuningRule("", 100, 5, std::numeric_limits<double>::infinity()),
            TuningRule::kShridharCooper);
  EXPECT_EQ(InferTuningRule("modified", 100, 5, 1.0), TuningRule::kPaperModified);
  EXPECT_EQ(InferTuningRule("conventional", 0, 0, kNaN), TuningRule::kShridharCooper);
  EXPECT_THAT([] { InferTuningRule("fast", 0, 0, kNaN); },
              ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr("'fast'")));
}

TEST(ControllerSettingsTest, ToSpecParsesNamesAndKeepsOverrides) {
  ControllerSettings s;
  s.controller = "gpc";
  s.P = 80;
  s.lambda = 3.0;
  s.limits.u_min = 0.0;
  s.limits.u_max = 100.0;
  s.t_filter = "A";
  s.pid_rule = "imc";
  const ControllerSpec spec = ToControllerSpec(s);
  EXPECT_EQ(spec.type, ControllerType::kGpc);
  EXPECT_EQ(spec.tuning.rule, TuningRule::kShridharCooper);
  EXPECT_EQ(spec.tuning.P, 80);
  EXPECT_EQ(spec.tuning.M, 0);
  EXPECT_EQ(spec.tuning.lambda, 3.0);
  EXPECT_EQ(spec.limits.u_max, 100.0);
  EXPECT_EQ(spec.t_filter, "A");
  EXPECT_EQ(spec.pid_rule, PidTuningRule::kImc);

  s.controller = "lqg";
  EXPECT_THAT([&] { ToControllerSpec(s); },
              ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr("'lqg'")));
  s.controller = "pid";
  s.pid_rule = "zn";
  EXPECT_THAT([&] { ToControllerSpec(s); },
              ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr("'zn'")));
}

TEST(ControllerSettingsTest, MpcTakesHorizonsFromTheRuleAndLimits) {
  ControllerSettings s;
  s.controller = "mpc";
  s.rule = "shridhar-cooper";
  s.limits.u_min = 0.0;
  s.limits.u_max = 100.0;
  const ControllerSpec spec = ToControllerSpec(s);
  EXPECT_EQ(spec.type, ControllerType::kMpc);
  const BuiltController b = MakeController(PaperFopdtModel(), kTs, spec);
  // The same P, M, lambda as the DMC the rule designs (tuning_test: 126, 5, 2.25).
  EXPECT_EQ(b.tuning.P, 126);
  EXPECT_EQ(b.tuning.M, 5);
  EXPECT_EQ(
      b.controller->Describe(),
      fmt::format("mpc P=126 M=5 lambda={:g} disturbance=input constrained", b.tuning.lambda));
  EXPECT_EQ(b.Label(), "shridhar-cooper");
  EXPECT_EQ(ToString(ControllerType::kMpc), "mpc");
  EXPECT_EQ(ControllerTypeFromString("mpc"), ControllerType::kMpc);
  s.limits = InputLimits{};
  const BuiltController u = MakeController(PaperFopdtModel(), kTs, ToControllerSpec(s));
  EXPECT_THAT(u.controller->Describe(), ::testing::Not(::testing::HasSubstr("constrained")));
}

TEST(BuiltControllerTest, LabelSummaryAndSettingsJson) {
  ControllerSettings s;
  s.M = 5;
  const BuiltController dmc = MakeController(PaperFopdtModel(), kTs, ToControllerSpec(s));
  EXPECT_EQ(dmc.Label(), "shridhar-cooper");
  EXPECT_THAT(dmc.Summary(), ::testing::StartsWith("shridhar-cooper: P=126 M=5 lambda=2.25"));
  const nlohmann::ordered_json j = dmc.SettingsToJson();
  std::vector<std::string> keys;
  for (const auto& [key, value] : j.items()) keys.push_back(key);
  EXPECT_THAT(keys, ::testing::ElementsAre("rule", "P", "M", "lambda", "formula"));
  EXPECT_EQ(j["P"], 126);

  s.controller = "pid";
  const BuiltController pid = MakeController(PaperFopdtModel(), kTs, ToControllerSpec(s));
  EXPECT_EQ(pid.Label(), "pid");
  EXPECT_THAT(pid.Summary(), ::testing::StartsWith("pid simc from FOPDT K=1.6 tau=0.245"));
  const nlohmann::ordered_json p = pid.SettingsToJson();
  keys.clear();
  for (const auto& [key, value] : p.items()) keys.push_back(key);
  EXPECT_THAT(keys, ::testing::ElementsAre("Kc", "Ti", "Td", "Kff", "rule", "b", "N"));
  EXPECT_EQ(p["b"], 1.0);  // the set-point weight, chosen by the rule auto only
  EXPECT_EQ(p["Kff"], 0.0);  // a stable model: no feed-forward unless asked
  EXPECT_EQ(p["rule"], "simc");
}

// The rule auto deploys the controller its tuner evaluated, from settings as
// `pneumid control` gives them: a dmc with input limits is the QDMC the
// tuner checked (constrained without --constrained, and its formula says
// why), and the mpc's Kalman noises (--measurement-noise ...) are those the
// tuner's candidates had, so they change the tuned lambda.
TEST(ControllerFactoryTest, RuleAutoDeploysTheControllerItsTunerEvaluated) {
  ControllerSettings s;
  s.controller = "dmc";
  s.rule = "auto";
  s.limits.u_min = 0.0;
  s.limits.u_max = 100.0;
  const BuiltController qdmc = MakeController(PaperFopdtModel(), kTs, ToControllerSpec(s));
  EXPECT_EQ(qdmc.controller->Describe(),
            fmt::format("dmc P=126 M=5 lambda={:g} N=508 constrained", qdmc.tuning.lambda));
  EXPECT_THAT(qdmc.Summary(),
              ::testing::HasSubstr("QDMC (moves optimized under the input limits)"));
  EXPECT_THAT(qdmc.SettingsToJson()["formula"].get<std::string>(), ::testing::HasSubstr("QDMC"));
  // Asked for, it is the same controller; its formula needs no explanation.
  s.constrained = true;
  const BuiltController asked = MakeController(PaperFopdtModel(), kTs, ToControllerSpec(s));
  EXPECT_EQ(asked.controller->Describe(), qdmc.controller->Describe());
  EXPECT_THAT(asked.tuning.formula, ::testing::Not(::testing::HasSubstr("QDMC")));
  // Without limits the dmc clips nothing and stays unconstrained.
  s.constrained = false;
  s.limits = InputLimits{};
  const BuiltController free = MakeController(PaperFopdtModel(), kTs, ToControllerSpec(s));
  EXPECT_THAT(free.controller->Describe(), ::testing::Not(::testing::HasSubstr("constrained")));
  EXPECT_THAT(free.tuning.formula, ::testing::Not(::testing::HasSubstr("QDMC")));

  s.controller = "mpc";
  const BuiltController r1 = MakeController(PaperFopdtModel(), kTs, ToControllerSpec(s));
  s.measurement_noise = 0.003;
  s.disturbance_noise = 0.5;
  const BuiltController r3 = MakeController(PaperFopdtModel(), kTs, ToControllerSpec(s));
  AutoTuneOptions o;
  o.measurement_noise = 0.003;
  o.disturbance_noise = 0.5;
  const AutoTuneResult tuned = AutoTune(PaperFopdtModel(), kTs, o);
  EXPECT_EQ(r3.tuning.lambda, tuned.lambda);
  EXPECT_EQ(r3.auto_summary, tuned.message);
  EXPECT_NE(r3.tuning.lambda, r1.tuning.lambda);
  // Noises the MPC rejects are rejected before the tuner runs, naming them.
  s.measurement_noise = 0.0;
  EXPECT_THAT([&] { MakeController(PaperFopdtModel(), kTs, ToControllerSpec(s)); },
              ::testing::ThrowsMessage<InvalidArgument>(
                  ::testing::HasSubstr("auto-tuning options: measurement noise")));
}

// A static input map puts every controller behind its inverse, designed on
// the linear part with the map's image of the limits.
TEST(ControllerFactoryTest, InputMapPutsEachControllerBehindTheInverse) {
  const TransferFunction unit_gain(Eigen::VectorXd::Constant(1, 1.0), Eigen::Vector2d(0.2, 1.0));
  const StaticMap map({0, 10, 50, 90, 100}, {0, 0, 60, 140, 140});
  for (const char* type : {"dmc", "gpc", "pid", "mpc"}) {
    ControllerSettings s;
    s.controller = type;
    s.limits.u_min = 0.0;
    s.limits.u_max = 100.0;
    ControllerSpec spec = ToControllerSpec(s);
    spec.input_map = map;
    const BuiltController b = MakeController(unit_gain, kTs, spec);
    EXPECT_THAT(b.controller->Describe(), ::testing::HasSubstr("with inverse map (5 knots"))
        << type;
    b.controller->Reset(10.0, 0.0);
    // 100 N needs f^-1(100) = 70 % at steady state; the input stays in 0..100 %.
    double y = 0.0, x = 0.0, u = 0.0;
    for (int k = 0; k < 600; ++k) {
      u = b.controller->Update(100.0, y);
      ASSERT_GE(u, 0.0) << type;
      ASSERT_LE(u, 100.0) << type;
      x += (kTs / 0.2) * (map.Evaluate(u) - x);  // Euler step of 1/(0.2 s + 1)
      y = x;
    }
    EXPECT_NEAR(u, 70.0, 0.5) << type;
    EXPECT_NEAR(y, 100.0, 0.5) << type;
  }
}

}  // namespace
}  // namespace pneumid

namespace pneumid {
namespace {

// Explicit PID gains replace the rule's, each alone. A proportional-only PID
// (Ti = inf) on a FOPDT of gain K leaves the closed-form steady-state error
// r / (1 + K Kc).
TEST(ControllerFactoryTest, ExplicitPidGainsReplaceTheRulesAndPOnlyLeavesItsOffset) {
  ControllerSettings s;
  s.controller = "pid";
  const BuiltController rule = MakeController(PaperFopdtModel(), kTs, ToControllerSpec(s));
  s.pid_td = 0.02;
  const BuiltController td = MakeController(PaperFopdtModel(), kTs, ToControllerSpec(s));
  EXPECT_DOUBLE_EQ(td.pid_gains.Td, 0.02);
  EXPECT_DOUBLE_EQ(td.pid_gains.Kc, rule.pid_gains.Kc);
  EXPECT_DOUBLE_EQ(td.pid_gains.Ti, rule.pid_gains.Ti);
  EXPECT_TRUE(td.pid_explicit);
  EXPECT_FALSE(rule.pid_explicit);
  EXPECT_THAT(td.Summary(), ::testing::HasSubstr("gains given"));
  EXPECT_EQ(td.SettingsToJson()["rule"], "explicit");

  s.pid_td = kNaN;
  s.pid_kc = 0.5;
  s.pid_ti = std::numeric_limits<double>::infinity();
  const BuiltController p = MakeController(PaperFopdtModel(), kTs, ToControllerSpec(s));
  const double K = PaperFopdtModel().DcGain();
  LinearPlant plant(PaperFopdtModel(), kTs);
  const auto sp = ParseSignal("step:from=0,to=40,at=0.1");
  ClosedLoopOptions o;
  o.duration = 20.0;
  const auto r = SimulateClosedLoop(*p.controller, plant, *sp, o);
  const double expected_error = 40.0 / (1.0 + K * 0.5);
  EXPECT_NEAR(r.r(r.r.size() - 1) - r.y(r.y.size() - 1), expected_error, 1e-3 * expected_error);

  s.pid_ti = -1.0;
  EXPECT_THROW(MakeController(PaperFopdtModel(), kTs, ToControllerSpec(s)), InvalidArgument);
  s.pid_ti = kNaN;
  s.rule = "auto";
  EXPECT_THAT([&] { MakeController(PaperFopdtModel(), kTs, ToControllerSpec(s)); },
              ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr("rule auto")));
}

TEST(ControllerFactoryTest, IntegratingModelsTakeTheirPidGainsFromTheSettings) {
  // A positioning cylinder: y' = K u (m/s per %), sampled with a zero-order
  // hold, y(k+1) = y(k) + K Ts u(k). No FOPDT description: the PID needs Kc.
  const TransferFunction integrator(Eigen::VectorXd::Constant(1, 0.004),
                                    (Eigen::VectorXd(2) << 1.0, 0.0).finished());
  ControllerSettings s;
  s.controller = "pid";
  EXPECT_THAT([&] { MakeController(integrator, kTs, ToControllerSpec(s)); },
              ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr("give the gains")));
  s.pid_kc = 1000.0;
  s.pid_kff = 0.0;  // no velocity feed-forward: the closed form below is P control's
  const BuiltController p = MakeController(integrator, kTs, ToControllerSpec(s));
  EXPECT_DOUBLE_EQ(p.pid_gains.Kc, 1000.0);
  EXPECT_TRUE(std::isinf(p.pid_gains.Ti));
  EXPECT_EQ(p.pid_gains.Td, 0.0);
  // P control of the integrator: e(k+1) = (1 - Kc K Ts) e(k), no offset.
  LinearPlant plant(integrator, kTs);
  const auto sp = ParseSignal("step:from=0,to=0.02,at=0.1");
  ClosedLoopOptions o;
  o.duration = 1.0;
  const auto r = SimulateClosedLoop(*p.controller, plant, *sp, o);
  for (int n : {1, 5, 40, 80}) {
    const double expected = 0.02 * std::pow(1.0 - 1000.0 * 0.004 * kTs, n);
    EXPECT_NEAR(r.r(10 + n) - r.y(10 + n), expected, 1e-9 + 1e-6 * expected) << n;
  }
}

// The velocity feed-forward of an integrating model: by default Kff = 1/Ki +
// Kc Td (Ki the model's velocity gain, continuous or discrete). On the plant
// y(k+1) = y(k) + Ki Ts u(k) and a ramp r = a t, the PD's derivative on y
// settles at -Kc Td a, so without feed-forward the loop lags by
// a (1/Ki + Kc Td) / Kc; with it, e(k+1) = (1 - Kc Ki Ts) e(k) -> 0.
TEST(ControllerFactoryTest, IntegratingModelsFeedTheSetpointRateForward) {
  const double Ki = 0.004, Kc = 1000.0, Td = 0.05, a = 0.02;  // m/s per %, %/m, s, m/s
  const TransferFunction integrator(Eigen::VectorXd::Constant(1, Ki),
                                    (Eigen::VectorXd(2) << 1.0, 0.0).finished());
  // The same integrator sampled with a zero-order hold: (Ki Ts z^-1) / (1 - z^-1).
  const TransferFunction sampled((Eigen::VectorXd(2) << 0.0, Ki * kTs).finished(),
                                 (Eigen::VectorXd(2) << 1.0, -1.0).finished(), kTs);
  ControllerSettings s;
  s.controller = "pid";
  s.pid_kc = Kc;
  s.pid_td = Td;
  for (const TransferFunction& model : {integrator, sampled}) {
    const BuiltController b = MakeController(model, kTs, ToControllerSpec(s));
    EXPECT_NEAR(b.pid_kff, 1.0 / Ki + Kc * Td, 1e-9 * b.pid_kff) << model.ToString();
    EXPECT_NEAR(b.SettingsToJson()["Kff"].get<double>(), b.pid_kff, 1e-12);
    EXPECT_THAT(b.Summary(), ::testing::HasSubstr("Kff="));
  }
  auto final_error = [&](double kff) {
    ControllerSettings t = s;
    t.pid_kff = kff;
    const BuiltController b = MakeController(integrator, kTs, ToControllerSpec(t));
    LinearPlant plant(integrator, kTs);
    const auto sp = ParseSignal(fmt::format("ramp:from=0,to={},at=0.1,duration=10", 10.0 * a));
    ClosedLoopOptions o;
    o.duration = 6.0;
    const auto r = SimulateClosedLoop(*b.controller, plant, *sp, o);
    const Eigen::Index n = r.r.size() - 1;
    return r.r(n) - r.y(n);
  };
  const double lag = a * (1.0 / Ki + Kc * Td) / Kc;
  EXPECT_NEAR(final_error(0.0), lag, 1e-3 * lag);
  EXPECT_NEAR(final_error(1.0 / Ki + Kc * Td), 0.0, 1e-6 * lag);
  // Half the feed-forward leaves half the lag.
  EXPECT_NEAR(final_error(0.5 * (1.0 / Ki + Kc * Td)), 0.5 * lag, 1e-3 * lag);
  // A stable model gets none unless it is asked for.
  s.pid_kc = kNaN;
  s.pid_td = kNaN;
  EXPECT_EQ(MakeController(PaperFopdtModel(), kTs, ToControllerSpec(s)).pid_kff, 0.0);
  s.pid_kff = std::numeric_limits<double>::infinity();
  EXPECT_THROW(MakeController(PaperFopdtModel(), kTs, ToControllerSpec(s)), InvalidArgument);
}

}  // namespace
}  // namespace pneumid
