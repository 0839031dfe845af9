// NarxLinearizingController: on a plant that is its input-affine NARX model
// (a chamber that fills faster than it vents, behind a valve map with a dead
// band) the loop seen by the inner controller is the reference model H at
// every operating point, sample by sample; limits hold with anti-windup
// through the linearization; the factory builds it from a model file; and
// models it cannot linearize are refused with the reason.
#include "pneumid/control/narx_linearizing_controller.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "chamber_narx.hpp"

#include "pneumid/common/check.hpp"
#include "pneumid/control/controller_factory.hpp"
#include "pneumid/models/model_file.hpp"

namespace pneumid {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

constexpr double kTs = 0.01;

NarxModel Chamber() { return testing_models::ChamberNarx(kTs); }
double TrueNext(double y, double v) {
  const double z = y / 200.0;
  return 200.0 * (z - 0.03 * z - 0.02 * z * z + v * (0.12 - 0.05 * z));
}
StaticMap Valve() { return testing_models::ChamberValve(); }

// An inner controller that asks a fixed w and records what it is told.
class Fixed : public Controller {
 public:
  explicit Fixed(double w) : w_(w) {}
  void DoReset(double, double) override {}
  double DoUpdate(double, double) override { return w_; }
  void DoApplied(double v) override { applied.push_back(v); }
  double Ts() const override { return kTs; }
  std::string Describe() const override { return "fixed"; }
  double w_;
  std::vector<double> applied;
};

TEST(InputAffineNarxTest, ReadsDriftAndGainOffTheTerms) {
  const InputAffineNarx m(Chamber(), Valve());
  for (double y : {0.0, 40.0, 120.0, 180.0})
    for (double v : {0.0, 0.3, 1.0})
      EXPECT_NEAR(m.Drift(y) + m.Gain(y) * v, TrueNext(y, v), 1e-9) << y << " " << v;
  EXPECT_DOUBLE_EQ(m.Map(50), 0.6);
  // The inverse uses the monotone envelope: the dip at 10 % is flattened.
  EXPECT_NEAR(m.InverseMap(0.4), 10.0 + 40.0 * 0.4 / 0.6, 1e-9);
  EXPECT_NEAR(m.InverseMap(0.0), 10.0, 1e-9);  // edge of the flat run (dead band)
  // Steady state: a(z) + v b(z) = 0.
  const double ys = m.SteadyOutput(100.0);
  EXPECT_NEAR(TrueNext(ys, 1.0), ys, 1e-6);
  EXPECT_GT(ys, 100.0);
}

TEST(NarxLinearizingControllerTest, ThePlantSeenInsideIsTheReferenceModel) {
  const double tau = 0.1;
  const double p = std::exp(-kTs / tau);
  auto fixed = std::make_unique<Fixed>(90.0);
  Fixed* inner = fixed.get();
  InputLimits limits;
  limits.u_min = 0.0;
  limits.u_max = 100.0;
  NarxLinearizingController c(std::move(fixed), InputAffineNarx(Chamber(), Valve()), tau, limits);
  double y = 10.0, y_ref = 10.0;
  c.Reset(20.0, y);
  for (int k = 0; k < 300; ++k) {
    const double u = c.Update(0.0, y);
    y = TrueNext(y, Valve().Evaluate(u));
    y_ref = p * y_ref + (1.0 - p) * 90.0;
    ASSERT_NEAR(y, y_ref, 1e-7) << "sample " << k;
  }
  EXPECT_TRUE(inner->applied.empty());  // never clipped: nothing to report
  EXPECT_NEAR(c.time_constant(), tau, 0.0);
}

TEST(NarxLinearizingControllerTest, ClippedInputIsReportedAsTheWItGives) {
  auto fixed = std::make_unique<Fixed>(1000.0);  // far beyond what u = 100 % reaches
  Fixed* inner = fixed.get();
  InputLimits limits;
  limits.u_min = 0.0;
  limits.u_max = 100.0;
  const InputAffineNarx model(Chamber(), Valve());
  NarxLinearizingController c(std::move(fixed), model, 0.1, limits);
  c.Reset(0.0, 50.0);
  EXPECT_DOUBLE_EQ(c.Update(0.0, 50.0), 100.0);
  ASSERT_EQ(inner->applied.size(), 1u);
  const double p = std::exp(-kTs / 0.1);
  EXPECT_NEAR(inner->applied[0], (TrueNext(50.0, 1.0) - p * 50.0) / (1.0 - p), 1e-9);
  // Inner limits: the model's steady outputs over the input range.
  const InputLimits w = NarxInnerLimits(model, limits);
  EXPECT_NEAR(w.u_min, model.SteadyOutput(0.0), 1e-9);
  EXPECT_NEAR(w.u_max, model.SteadyOutput(100.0), 1e-9);
}

TEST(NarxLinearizingControllerTest, FactoryBuildsItFromAModelFile) {
  const std::string path = ::testing::TempDir() + "narx_linearizing_model.json";
  {
    nlohmann::json m = {
        {"method", "affine-narx"}, {"narx", ToJson(Chamber())}, {"input_map", ToJson(Valve())}};
    std::ofstream(path) << nlohmann::json{{"models", {m}}}.dump();
  }
  ControllerSettings s;
  s.controller = "mpc";
  s.rule = "auto";
  s.limits.u_min = 0.0;
  s.limits.u_max = 100.0;
  const ControllerSpec spec = WithModelInputMap(ToControllerSpec(s), path + "#affine-narx");
  ASSERT_TRUE(spec.narx_model.has_value());
  EXPECT_FALSE(spec.input_map.has_value());
  const TransferFunction nominal = ParseControllerModel(path + "#affine-narx");
  EXPECT_GT(nominal.DcGain(), 0.0);
  const BuiltController b = MakeController(nominal, kTs, spec);
  EXPECT_THAT(b.controller->Describe(), HasSubstr("behind a NARX linearization (tau = "));
  // The tau of the model's typical speed, and --rule auto aims at it.
  const double tau = ReferenceTimeConstant(*spec.narx_model, s.limits);
  EXPECT_THAT(b.tuning.formula, HasSubstr(fmt::format("rise time of {:.4g} s", tau)));
  // The model file's NARX is not a linear model nor a static map.
  EXPECT_THAT([&] { ParseModelSpec(path + "#affine-narx"); },
              ThrowsMessage<DataError>(HasSubstr(": the model 'affine-narx' is a NARX model")));
  EXPECT_THAT([&] { ReadStaticMap(path + "#affine-narx"); },
              ThrowsMessage<DataError>(HasSubstr("is not the plant's static map")));
  ControllerSettings with_map = s;
  with_map.input_map = path + "#affine-narx";
  EXPECT_ANY_THROW(WithModelInputMap(ToControllerSpec(with_map), path + "#affine-narx"));
  std::remove(path.c_str());
}

TEST(NarxLinearizingControllerTest, RefusesWhatItCannotLinearize) {
  NarxModel two = Chamber();
  two.ny = 2;
  EXPECT_THAT([&] { InputAffineNarx(two, std::nullopt); },
              ThrowsMessage<InvalidArgument>(HasSubstr("ny = 2, nu = 1, nk = 1")));
  NarxModel square = Chamber();
  square.terms.push_back({1, 1});
  square.theta.push_back(0.1);
  EXPECT_THAT([&] { InputAffineNarx(square, std::nullopt); },
              ThrowsMessage<InvalidArgument>(HasSubstr("holds the input 2 times")));
  EXPECT_THAT(
      [&] {
        InputAffineNarx(Chamber(), StaticMap({0, 100}, {1, 0}));
      },
      ThrowsMessage<InvalidArgument>(HasSubstr("does not increase anywhere")));
  const InputAffineNarx m(Chamber(), Valve());
  EXPECT_THAT([&] { NarxLinearizingController(nullptr, m, 0.1); },
              ThrowsMessage<InvalidArgument>(HasSubstr("needs a controller, got null")));
  class Slow : public Fixed {
   public:
    Slow() : Fixed(0) {}
    double Ts() const override { return 0.02; }
  };
  EXPECT_THAT([&] { NarxLinearizingController(std::make_unique<Slow>(), m, 0.1); },
              ThrowsMessage<InvalidArgument>(HasSubstr("sample time 0.02 s differs")));
  EXPECT_THAT([&] { NarxLinearizingController(std::make_unique<Fixed>(0), m, -1.0); },
              ThrowsMessage<InvalidArgument>(HasSubstr("must be positive, got -1")));
}

}  // namespace
}  // namespace pneumid
