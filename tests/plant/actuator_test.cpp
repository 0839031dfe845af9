// The actuator a plant describes for the layers that drive it generically
// (real-time loop, safety, logs): the IPA's duty %, force N or position m,
// 0..100 % range and its names for the hold and release safe states; the
// generic description for any other plant.
#include "pneumid/plant/actuator.hpp"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/plant/plant_factory.hpp"

namespace pneumid {
namespace {

TEST(ActuatorTest, TheIpaNamesItsSafeStatesAndUnits) {
  const auto force = MakePlant("ipa", 0.01);
  const Actuator a = PlantActuator(*force);
  EXPECT_EQ(a.input.name, "u");
  EXPECT_EQ(a.input.unit, "%");
  EXPECT_EQ(a.output.unit, "N");
  EXPECT_EQ(a.input_label, "duty");
  EXPECT_EQ(a.output_label, "force");
  EXPECT_EQ(a.u_min, 0.0);
  EXPECT_EQ(a.u_max, 100.0);
  EXPECT_EQ(a.hold_name, "valves-closed");
  EXPECT_EQ(a.release_name, "exhaust-open");
  EXPECT_THAT(a.hold_meaning, ::testing::HasSubstr("pressure held"));
  const auto position = MakePlant("ipa-position", 0.01);
  EXPECT_EQ(PlantActuator(*position).output.unit, "m");
  EXPECT_EQ(PlantActuator(*position).output_label, "position");
  // Position integrates the command; force settles at each duty.
  EXPECT_TRUE(position->actuator().integrating);
  EXPECT_FALSE(a.integrating);
  // PlantActuator is the plant's own description.
  EXPECT_EQ(PlantActuator(*position).input_gaps, position->actuator().input_gaps);
  // The channels of the plant factory are the actuator's.
  EXPECT_EQ(PlantInputChannel(*force).unit, a.input.unit);
  EXPECT_EQ(PlantOutputChannel(*position).unit, "m");
}

TEST(ActuatorTest, OtherPlantsAreDescribedGenerically) {
  const auto linear = MakePlant("fopdt-paper", 0.01);
  const Actuator a = PlantActuator(*linear);
  EXPECT_EQ(a.input.unit, "");
  EXPECT_EQ(a.hold_name, "hold");
  EXPECT_EQ(a.release_name, "release");
  EXPECT_TRUE(std::isinf(a.u_min) && a.u_min < 0.0);
  EXPECT_TRUE(std::isinf(a.u_max) && a.u_max > 0.0);
  EXPECT_FALSE(a.integrating);
  EXPECT_TRUE(linear->actuator().input_gaps.empty());
}

}  // namespace
}  // namespace pneumid
