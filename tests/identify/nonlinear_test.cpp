// The nonlinear methods through the identification entry point: dispatch by
// name, not in `all`, the model file round trip (maps and NARX terms), the
// simulation used by validate, and the errors for unsuitable data.
#include "pneumid/identify/nonlinear/nonlinear.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/data/load.hpp"
#include "pneumid/identify/evaluation/model_evaluation.hpp"
#include "pneumid/identify/identified_model_io.hpp"
#include "pneumid/identify/identify.hpp"
#include "step_test_util.hpp"

namespace pneumid {
namespace {

using ::testing::Contains;
using ::testing::HasSubstr;
using ::testing::Not;
using ::testing::ThrowsMessage;

Dataset Recorded(const std::string& name) {
  return LoadDataset(std::string(PNEUMID_SOURCE_DIR) + "/tests/identify/data/" + name + ".csv");
}

TEST(NonlinearMethodsTest, AreIdentifyMethodsButNotInAll) {
  for (const std::string& m : NonlinearMethodNames()) {
    EXPECT_TRUE(IsIdentifyMethod(m)) << m;
    EXPECT_THAT(ParseMethodList("all"), Not(Contains(m)));
  }
  EXPECT_THAT(ParseMethodList("arx,hammerstein"), ::testing::ElementsAre("arx", "hammerstein"));
  EXPECT_THAT(
      [] { ParseMethodList("hammerstien"); },
      ThrowsMessage<InvalidArgument>(HasSubstr("spa, static-map, hammerstein, wiener, hw, narx")));
}

TEST(NonlinearMethodsTest, ModelsRoundTripThroughTheModelFile) {
  const Dataset h = Recorded("hammerstein");
  IdentifyRequest r;
  r.na = 2;
  r.nb = 2;
  r.nk = 1;
  IdentifyOptions o;
  o.nonlinear.block.num_knots = 6;  // the true knots 0, 20, .., 100
  for (const std::string method : {"hammerstein", "wiener", "hw", "narx"}) {
    SCOPED_TRACE(method);
    const IdentifiedModel m = Identify(method, h, r, o);
    EXPECT_EQ(m.method, method);
    const IdentifiedModel back = IdentifiedModelFromJson(nlohmann::json::parse(ToJson(m).dump()));
    EXPECT_TRUE(IsNonlinearModel(back));
    EXPECT_EQ(back.input_map, m.input_map);
    EXPECT_EQ(back.output_map, m.output_map);
    ASSERT_EQ(back.narx.has_value(), m.narx.has_value());
    const Eigen::VectorXd y1 = SimulateModel(m, h), y2 = SimulateModel(back, h);
    EXPECT_LT((y1 - y2).cwiseAbs().maxCoeff(), 1e-6 * (1.0 + y1.cwiseAbs().maxCoeff()));
    EXPECT_NEAR(EvaluateModel(back, h).fit_percent, m.fit_percent, 1e-6);
    EXPECT_FALSE(m.notes.empty());
  }
  const IdentifiedModel ham = Identify("hammerstein", h, r, o);
  EXPECT_EQ(ham.structure, "Hammerstein");
  ASSERT_TRUE(ham.input_map.has_value());
  EXPECT_GT(ham.fit_percent, 98.0);  // noise std 0.2 on a 10..128 output
  EXPECT_THAT(ham.notes[0], HasSubstr("input map f(u): monotone increasing, 6 knots"));
  // The estimated initial state is the least-squares best one, so it fits at
  // least as well as the start at rest at u(0).
  EXPECT_GE(
      ScoreSimulation(h, 0, SimulateModel(ham, h, 0, 0, InitialCondition::kEstimate)).fit_percent,
      ham.fit_percent - 1e-9);
  const IdentifiedModel hw = Identify("hw", Recorded("hw"), r, o);
  EXPECT_EQ(hw.structure, "Hammerstein-Wiener");
  ASSERT_TRUE(hw.input_map.has_value() && hw.output_map.has_value());
  EXPECT_GT(hw.fit_percent, 98.0);
  EXPECT_THAT(hw.notes[0], HasSubstr("input map f(u): monotone increasing, 6 knots"));
  EXPECT_THAT(hw.notes[1], HasSubstr("output map g(x): monotone increasing, 6 knots"));
  const IdentifiedModel narx = Identify("narx", Recorded("narx"), r, o);
  EXPECT_THAT(narx.notes[0], HasSubstr("selected terms: "));
}

// A Wiener model whose output map turns (end knots that the data barely
// visit) starts at rest at the first measured output all the same: the
// preimage of y(0) nearest the rest at the first input. Closed form: G(z) =
// 0.2 z^-1 / (1 - 0.8 z^-1) (gain 1) from rest at x = 10 with u = 40 gives
// x(t) = 10 + 30 (1 - 0.8^t), and f(x) = x on [0, 100]; f also reaches 10
// at x = -3.33, farther from the rest at the first input (x = 40).
TEST(NonlinearMethodsTest, AWienerModelWhoseOutputMapTurnsStartsAtTheFirstMeasuredOutput) {
  const double Ts = 0.01;
  IdentifiedModel w;
  w.method = "wiener";
  w.discrete = TransferFunction(Eigen::Vector2d(0.0, 0.2), Eigen::Vector2d(1.0, -0.8), Ts);
  w.output_map = StaticMap({-10, 0, 50, 100, 120}, {30, 0, 50, 100, 80});
  ASSERT_FALSE(w.output_map->IsMonotone());
  const Eigen::Index n = 60;
  const Eigen::VectorXd u = Eigen::VectorXd::Constant(n, 40.0);
  Eigen::VectorXd y(n);
  for (Eigen::Index t = 0; t < n; ++t)
    y[t] = 10.0 + 30.0 * (1.0 - std::pow(0.8, static_cast<double>(t)));
  const Eigen::VectorXd yhat = SimulateNonlinear(w, Dataset::FromUniform(Ts, u, y), 0, 0);
  ASSERT_EQ(yhat.size(), n);
  EXPECT_LT((yhat - y).cwiseAbs().maxCoeff(), 1e-9);
  // A first output the map never reaches (150): the state of the knot whose
  // value is nearest it, x = 100 with g = 100 (before: at rest at the first
  // input, g(40) = 40, 110 away; a record 0.01 below the lowest value by
  // noise so started at the rest of the first input). Without a measured
  // output: at rest at the first input.
  const Dataset beyond = Dataset::FromUniform(Ts, u, Eigen::VectorXd::Constant(n, 150.0));
  EXPECT_NEAR(SimulateNonlinear(w, beyond, 0, 0)[0], 100.0, 1e-9);
  EXPECT_NEAR(SimulateNonlinear(w, beyond, 0, -1)[0], 40.0, 1e-9);
  EXPECT_EQ(w.output_map->NearestPreimageOrEnd(150.0, 40.0), 100.0);
  EXPECT_EQ(w.output_map->NearestPreimageOrEnd(-5.0, 40.0), 0.0);
  EXPECT_EQ(w.output_map->NearestPreimageOrEnd(25.0, 40.0), 25.0);  // a preimage
}

TEST(NonlinearMethodsTest, StaticMapOfAStaircaseAndErrorsOnAStepTest) {
  Eigen::VectorXd u(1000);
  for (Eigen::Index k = 0; k < 1000; ++k) u[k] = 10.0 * static_cast<double>(k / 200);
  const Eigen::VectorXd y = (2.0 * u.array() + 1.0).matrix();
  const IdentifiedModel m = Identify("static-map", Dataset::FromUniform(0.01, u, y));
  ASSERT_TRUE(m.input_map.has_value());
  EXPECT_EQ(m.input_map->u(), (std::vector<double>{0, 10, 20, 30, 40}));
  EXPECT_NEAR(m.fit_percent, 100.0, 1e-9);  // a static plant is its map
  // One step: two levels, a map of two knots; a constant input: an error.
  const Dataset flat =
      Dataset::FromUniform(0.01, Eigen::VectorXd::Constant(300, 5.0), Eigen::VectorXd::Ones(300));
  EXPECT_THAT([&] { Identify("static-map", flat); },
              ThrowsMessage<InvalidArgument>(HasSubstr("never leaves one operating point")));
  EXPECT_THAT([&] { Identify("hammerstein", flat); },
              ThrowsMessage<InvalidArgument>(HasSubstr("never leaves one operating point")));
  // `all` on a plain step test runs no nonlinear method.
  const IdentificationSummary s =
      IdentifyModels(ParseMethodList("all"), testing::LoadSynthetic("fopdt"));
  for (const IdentifiedModel& model : s.models) EXPECT_FALSE(IsNonlinearModel(model));
}

}  // namespace
}  // namespace pneumid
