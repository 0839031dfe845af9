// Nonlinear identification of the IPA twin (force mode, switching PWM, the
// default twin, as `pneumid simulate --plant ipa`): models identified from one
// 60 s experiment (30 s staircase 0..100 % duty in steps of 5 %, then 30 s
// multi-level PRBS) are validated on a different experiment (other staircase
// levels, another PRBS seed and level set). The actuator's S-shaped steady map (dead band,
// saturation) limits every linear model; the nonlinear ones follow it. The
// static map from the staircase is checked against the steady states of
// single steps from rest.
#include <cmath>
#include <iostream>
#include <memory>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "pneumid/identify/identify.hpp"
#include "pneumid/identify/evaluation/model_evaluation.hpp"
#include "pneumid/plant/plant_factory.hpp"
#include "pneumid/plant/signal.hpp"

namespace pneumid {
namespace {

constexpr double kTs = 0.01;

// Drives a fresh twin with `first` before t_switch and `second` after.
Dataset RunTwin(const std::string& first, const std::string& second, double t_switch,
                double duration) {
  const auto a = ParseSignal(first);
  const auto b = ParseSignal(second);
  auto plant = MakePlant("ipa", kTs);
  const auto n = static_cast<Eigen::Index>(std::lround(duration / kTs));
  Eigen::VectorXd u(n), y(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) * kTs;
    u[k] = t < t_switch - 1e-9 ? (*a)(t) : (*b)(t);
    y[k] = plant->Measure();
    plant->Advance(u[k]);
  }
  return Dataset::FromUniform(kTs, u, y);
}

const Dataset& Estimation() {
  static const Dataset d = RunTwin(
      "staircase:levels=0 5 10 15 20 25 30 35 40 45 50 55 60 65 70 75 80 85 90 95 100,dwell=1.4",
      "prbs-levels:low=10,high=90,levels=5,clock=0.3,seed=1,at=30", 30.0, 60.0);
  return d;
}

const Dataset& Validation() {
  static const Dataset d =
      RunTwin("staircase:levels=0 25 55 85 45 15 65 95 35 5,dwell=2",
              "prbs-levels:low=5,high=95,levels=7,clock=0.4,seed=7,at=20", 20.0, 50.0);
  return d;
}

double ValidationFit(const std::string& method, const IdentifyRequest& request,
                     const IdentifyOptions& options = {}) {
  const IdentifiedModel m = Identify(method, Estimation(), request, options);
  const double fit = EvaluateModel(m, Validation()).fit_percent;
  std::cout << fmt::format("{:<12} estimation fit {:7.2f} %  validation fit {:7.2f} %\n", method,
                           m.fit_percent, fit);
  return fit;
}

TEST(IpaNonlinearTest, NonlinearModelsValidateWhereLinearOnesCannot) {
  IdentifyRequest linear;
  linear.na = 2;
  linear.nb = 2;
  linear.nk = 1;
  linear.nf = 2;
  const double arx = ValidationFit("arx", linear);
  const double oe = ValidationFit("oe", linear);
  const double p1d = ValidationFit("fit-p1d", linear);
  const double best_linear = std::max({arx, oe, p1d});
  IdentifyRequest block = linear;
  block.na = 3;
  block.nb = 3;
  IdentifyOptions o;
  o.nonlinear.block.num_knots = 21;  // one per 5 % of duty, as the staircase
  o.nonlinear.narx.degree = 2;
  o.nonlinear.narx.max_terms = 15;
  o.nonlinear.narx.err_tolerance = 1e-9;  // stop by max_terms
  const double hammerstein = ValidationFit("hammerstein", block, o);
  IdentifyOptions mo = o;
  mo.nonlinear.block.monotone_map = true;
  const IdentifiedModel monotone = Identify("hammerstein", Estimation(), block, mo);
  ASSERT_TRUE(monotone.input_map.has_value());
  EXPECT_TRUE(monotone.input_map->IsMonotone());
  const double monotone_fit = EvaluateModel(monotone, Validation()).fit_percent;
  std::cout << fmt::format("hammerstein with a monotone map: validation fit {:.2f} %\n",
                           monotone_fit);
  EXPECT_GE(monotone_fit, 86.0);  // measured 88.0 %: the constraint costs little
  const double wiener = ValidationFit("wiener", linear, o);
  const double narx = ValidationFit("narx", linear, o);
  const double best_nonlinear = std::max({hammerstein, wiener, narx});
  std::cout << fmt::format("best linear {:.2f} %, best nonlinear {:.2f} %\n", best_linear,
                           best_nonlinear);
  // Measured (the default twin, seeded noise): arx 65.9, oe 69.5, fit-p1d
  // 72.5 %; hammerstein 88.3, wiener 84.7, narx 86.4 %. The remaining error
  // is the actuator's direction-dependent dynamics (it fills faster than it
  // vents), which no single static map plus one linear part can follow.
  EXPECT_LE(best_linear, 80.0);
  EXPECT_GE(best_nonlinear, 86.0);
  EXPECT_GE(best_nonlinear - best_linear, 12.0);
  EXPECT_GE(hammerstein, 86.0);
}

TEST(IpaNonlinearTest, StaticMapAgreesWithSingleStepsWithinTwoNewtons) {
  IdentifyOptions o;
  o.nonlinear.static_map.min_segment_duration = 1.2;  // the staircase's 1.4 s levels only
  const IdentifiedModel m = Identify("static-map", Estimation(), {}, o);
  ASSERT_TRUE(m.input_map.has_value());
  const StaticMap& f = *m.input_map;
  EXPECT_TRUE(f.IsMonotone());
  EXPECT_EQ(f.size(), 21u);
  for (const double duty : {15.0, 20.0, 35.0, 50.0, 65.0, 80.0, 95.0}) {
    // A single step from rest, steady state = mean over its last second.
    const Dataset d = RunTwin(fmt::format("step:from=0,to={},at=0.5", duty), "step:to=0", 1e9, 5.0);
    const double steady = d.y().tail(100).mean();
    std::cout << fmt::format("duty {:5.1f} %: step steady state {:7.2f} N, map {:7.2f} N\n", duty,
                             steady, f.Evaluate(duty));
    EXPECT_NEAR(f.Evaluate(duty), steady, 2.0) << "duty " << duty;
  }
  // The inverse gives back the duty of a force inside the range.
  EXPECT_NEAR(f.Evaluate(f.Inverse(60.0)), 60.0, 1e-9);
}

}  // namespace
}  // namespace pneumid
