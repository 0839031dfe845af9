// RunControlScenario (workflow/control_scenario.hpp): the steady outputs a
// controller's model reaches within its input limits, in closed form for a
// static map behind a gain and through an output map, the fixed points of an
// input-affine NARX, and the warning of a
// scenario whose set-point lies beyond them.
#include "pneumid/workflow/control_scenario.hpp"

#include <cmath>
#include <limits>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "../control/chamber_narx.hpp"
#include "gain_map_model.hpp"
#include "pneumid/control/narx_linearizing_controller.hpp"
#include "pneumid/lti/transfer_function.hpp"
#include "pneumid/models/static_map.hpp"

namespace pneumid {
namespace {

using ::testing::AllOf;
using ::testing::HasSubstr;

// f: 0 -> 0, 50 -> 40, 100 -> 60 (piecewise linear), behind G(1) = 2.
ControllerSpec MapSpec() {
  ControllerSpec spec;
  spec.input_map = StaticMap({0.0, 50.0, 100.0}, {0.0, 40.0, 60.0});
  return spec;
}

TEST(ControlScenarioTest, SteadyOutputRangeIsTheGainTimesTheMapOverTheInputLimits) {
  const TransferFunction g = TransferFunction::Fopdt(2.0, 0.2, 0.0);
  const ControllerSpec spec = MapSpec();
  const auto full = SteadyOutputRange(g, spec, 0.0, 100.0);
  ASSERT_TRUE(full.has_value());
  EXPECT_NEAR(full->first, 0.0, 1e-9);
  EXPECT_NEAR(full->second, 120.0, 1e-9);
  // Limits 20..75: f(20) = 16, f(75) = 50, times 2.
  const auto part = SteadyOutputRange(g, spec, 20.0, 75.0);
  ASSERT_TRUE(part.has_value());
  EXPECT_NEAR(part->first, 32.0, 1e-9);
  EXPECT_NEAR(part->second, 100.0, 1e-9);
  // Through a decreasing output map g(x) = -x / 2 on 0..120.
  ControllerSpec wiener = spec;
  wiener.output_map = StaticMap({0.0, 120.0}, {0.0, -60.0});
  const auto out = SteadyOutputRange(g, wiener, 0.0, 100.0);
  ASSERT_TRUE(out.has_value());
  EXPECT_NEAR(out->first, -60.0, 1e-9);
  EXPECT_NEAR(out->second, 0.0, 1e-9);
  // No map (a linear model's operating point is unknown) or open limits: none.
  EXPECT_FALSE(SteadyOutputRange(g, ControllerSpec{}, 0.0, 100.0).has_value());
  EXPECT_FALSE(SteadyOutputRange(g, spec, 0.0, std::numeric_limits<double>::infinity()));
}

TEST(ControlScenarioTest, SteadyOutputRangeOfAnInputAffineNarxIsItsFixedPoints) {
  // chamber_narx.hpp: 0 = -0.03 z - 0.02 z^2 + v (0.12 - 0.05 z), z = y / 200.
  // v = 1 (u = 100): z^2 + 4 z - 6 = 0, z = sqrt(10) - 2; the map's least
  // value, v = -0.01 at u = 5: 0.02 z^2 + 0.0295 z + 0.0012 = 0.
  ControllerSpec spec;
  spec.narx_model =
      InputAffineNarx(testing_models::ChamberNarx(0.01), testing_models::ChamberValve());
  const auto range = SteadyOutputRange(TransferFunction::Fopdt(1.0, 0.1, 0.0), spec, 0.0, 100.0);
  ASSERT_TRUE(range.has_value());
  const double z_low = (-0.0295 + std::sqrt(0.0295 * 0.0295 - 4 * 0.02 * 0.0012)) / 0.04;
  EXPECT_NEAR(range->first, 200.0 * z_low, 1e-3);
  EXPECT_NEAR(range->second, 200.0 * (std::sqrt(10.0) - 2.0), 1e-3);
}

TEST(ControlScenarioTest, ASetPointBeyondTheModelsReachIsAWarning) {
  ControlScenarioOptions o;
  o.model = testing_models::kGainMapModel;
  o.controller.input_map = testing_models::WriteGainMapFile("pneumid_control_scenario");
  o.controller.limits.u_min = 0.0;
  o.controller.limits.u_max = 100.0;
  o.Ts = 0.01;
  o.duration = 2.0;
  o.setpoint = "staircase:levels=50 150,dwell=1";
  const ControlScenarioResult beyond = RunControlScenario(o);
  ASSERT_EQ(beyond.warnings.size(), 1u);
  EXPECT_THAT(beyond.warnings[0],
              AllOf(HasSubstr("the set-point reaches [50, 150]"),
                    HasSubstr("beyond the steady outputs [0, 120]"),
                    HasSubstr("input within its limits [0, 100] (100 of 200 samples)")));
  // Within 1 % of the range beyond its end: no warning.
  o.setpoint = "staircase:levels=50 121,dwell=1";
  EXPECT_TRUE(RunControlScenario(o).warnings.empty());
}

}  // namespace
}  // namespace pneumid
