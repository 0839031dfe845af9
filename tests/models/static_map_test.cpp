// Piecewise-linear static maps: evaluation, inverse with dead zone and
// saturation, descriptions, JSON and bad input. Golden values from numpy
// (gen_static_map_cases.py beside this file).
#include "pneumid/models/static_map.hpp"

#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"

namespace pneumid {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

struct MapCase {
  std::string name;
  std::vector<double> u, y, qu, fu, qy, inverse;
};

const std::vector<MapCase>& Cases() {
  static const std::vector<MapCase> cases = {
#include "static_map_cases.inc"
  };
  return cases;
}

TEST(StaticMapTest, EvaluatesAndInvertsAsNumpy) {
  ASSERT_EQ(Cases().size(), 4u);
  for (const MapCase& c : Cases()) {
    SCOPED_TRACE(c.name);
    const StaticMap m(c.u, c.y);
    ASSERT_TRUE(m.IsMonotone());
    for (std::size_t k = 0; k < c.qu.size(); ++k)
      EXPECT_NEAR(m.Evaluate(c.qu[k]), c.fu[k], 1e-12 * (1.0 + std::abs(c.fu[k]))) << c.qu[k];
    for (std::size_t k = 0; k < c.qy.size(); ++k)
      EXPECT_NEAR(m.Inverse(c.qy[k]), c.inverse[k], 1e-12 * (1.0 + std::abs(c.inverse[k])))
          << c.qy[k];
  }
}

TEST(StaticMapTest, InverseReturnsTheEdgesOfDeadZoneAndSaturation) {
  // Dead zone u in [0, 10] at y = 0, saturation y = 193.2 from u = 88.
  const StaticMap m({0, 10, 20, 88, 100}, {0, 0, 18.7, 193.2, 193.2});
  EXPECT_EQ(m.Inverse(0.0), 10.0);    // upper edge of the dead zone
  EXPECT_EQ(m.Inverse(-50.0), 10.0);  // below the range: clamped to the same edge
  EXPECT_EQ(m.Inverse(193.2), 88.0);  // lower edge of the saturation
  EXPECT_EQ(m.Inverse(1e9), 88.0);
  EXPECT_NEAR(m.Inverse(9.35), 15.0, 1e-12);  // half-way up the segment [10, 20]
  EXPECT_EQ(m.Direction(), Monotonicity::kIncreasing);
  EXPECT_EQ(m.DeadZone(), (FlatSegment{0, 10, 0}));
  EXPECT_EQ(m.Saturation(), (FlatSegment{88, 100, 193.2}));
  EXPECT_THAT(m.Describe(), HasSubstr("dead zone u in [0, 10] (y = 0), saturation from u = 88"));
  // Within a tolerance of 20 N, the first segment counts as flat too.
  EXPECT_EQ(m.DeadZone(20.0)->u_to, 20.0);
  const StaticMap strict({0, 1, 2}, {0, 1, 3});
  EXPECT_FALSE(strict.DeadZone().has_value());
  EXPECT_FALSE(strict.Saturation().has_value());
}

TEST(StaticMapTest, ExtrapolatesLinearlyOnRequest) {
  const StaticMap m({0, 1, 2}, {1, 3, 4}, StaticMapExtrapolation::kLinear);
  EXPECT_DOUBLE_EQ(m.Evaluate(-1.0), -1.0);
  EXPECT_DOUBLE_EQ(m.Evaluate(4.0), 6.0);
  EXPECT_DOUBLE_EQ(m.Slope(-1.0), 2.0);
  EXPECT_DOUBLE_EQ(m.Slope(1.0), 1.0);  // the right segment at a knot
  const StaticMap c({0, 1, 2}, {1, 3, 4});
  EXPECT_DOUBLE_EQ(c.Evaluate(-1.0), 1.0);
  EXPECT_DOUBLE_EQ(c.Slope(5.0), 0.0);
  EXPECT_TRUE(std::isnan(c.Evaluate(std::numeric_limits<double>::quiet_NaN())));
  // The inverse clamps to the knots whatever the extrapolation.
  EXPECT_DOUBLE_EQ(m.Inverse(10.0), 2.0);
}

TEST(StaticMapTest, RoundTripsThroughJson) {
  const StaticMap m({0, 10, 20}, {0, 0, 18.7}, StaticMapExtrapolation::kLinear);
  const nlohmann::json j = ToJson(m);
  EXPECT_EQ(j.at("extrapolation"), "linear");
  EXPECT_EQ(StaticMapFromJson(j), m);
  EXPECT_EQ(
      StaticMapFromJson(nlohmann::json::parse(R"({"u": [0, 1], "y": [2, 3]})")).extrapolation(),
      StaticMapExtrapolation::kClamp);
  EXPECT_THAT([] { StaticMapFromJson(nlohmann::json::parse(R"({"u": [0, 1]})")); },
              ThrowsMessage<InvalidArgument>(HasSubstr("'y' must be an array")));
  EXPECT_THAT([] { StaticMapFromJson(nlohmann::json::parse(R"({"u": [0, "a"], "y": [1, 2]})")); },
              ThrowsMessage<InvalidArgument>(HasSubstr("'u' must hold numbers, got \"a\"")));
}

TEST(StaticMapTest, RejectsBadKnotsAndNonMonotoneInverse) {
  EXPECT_THAT(
      [] {
        StaticMap({0, 2, 1}, {0, 1, 2});
      },
      ThrowsMessage<InvalidArgument>(HasSubstr("got u[2] = 1 after u[1] = 2")));
  EXPECT_THAT([] { StaticMap({0}, {0}); },
              ThrowsMessage<InvalidArgument>(HasSubstr("at least 2 knots, got 1")));
  EXPECT_THAT(
      [] {
        StaticMap({0, 1}, {0, 1, 2});
      },
      ThrowsMessage<InvalidArgument>(HasSubstr("got 2 and 3")));
  EXPECT_THAT(
      [] {
        StaticMap({0, 1}, {0, std::nan("")});
      },
      ThrowsMessage<InvalidArgument>(HasSubstr("knot 1 is not finite")));
  const StaticMap bump({0, 1, 2, 3}, {0, 2, 1, 3});
  EXPECT_EQ(bump.Direction(), Monotonicity::kNone);
  EXPECT_FALSE(bump.IsMonotone());
  EXPECT_DOUBLE_EQ(bump.Evaluate(1.5), 1.5);  // evaluation needs no monotonicity
  EXPECT_THAT([&] { bump.Inverse(1.0); },
              ThrowsMessage<InvalidArgument>(
                  HasSubstr("not monotone, so it has no inverse: y = 0, 2, 1 at u = 0, 1, 2")));
  const StaticMap flat({0, 1}, {5, 5});
  EXPECT_THAT([&] { flat.Inverse(5.0); },
              ThrowsMessage<InvalidArgument>(HasSubstr("constant static map (y = 5")));
}

// NearestPreimage by its definition: every input of [u_0, u_n-1] where f
// takes the value, the nearest to u_near chosen.
TEST(StaticMapTest, NearestPreimageIsTheClosestInputWithThatOutput) {
  // Turns at u = 1 and u = 2: y = 1.5 is reached at u = 0.75, 1.5 and 2.25.
  const StaticMap bump({0, 1, 2, 3}, {0, 2, 1, 3});
  for (const auto& [u_near, want] :
       std::vector<std::pair<double, double>>{{-5, 0.75}, {1.0, 0.75}, {1.2, 1.5}, {1.9, 2.25}}) {
    const std::optional<double> u = bump.NearestPreimage(1.5, u_near);
    ASSERT_TRUE(u.has_value()) << "u_near = " << u_near;
    EXPECT_DOUBLE_EQ(*u, want) << "u_near = " << u_near;
    EXPECT_DOUBLE_EQ(bump.Evaluate(*u), 1.5);
  }
  // Outside the knot values' range there is none; at its ends the knot.
  EXPECT_FALSE(bump.NearestPreimage(3.5, 1.0).has_value());
  EXPECT_FALSE(bump.NearestPreimage(-0.1, 1.0).has_value());
  EXPECT_DOUBLE_EQ(*bump.NearestPreimage(3.0, 0.0), 3.0);
  // A monotone map has one preimage: Inverse's.
  const StaticMap ramp({0, 10, 20}, {-4, 6, 26});
  for (const double y : {-4.0, 0.0, 6.0, 17.0, 26.0})
    EXPECT_DOUBLE_EQ(*ramp.NearestPreimage(y, 100.0), ramp.Inverse(y)) << "y = " << y;
  // On a flat segment at y, u_near clamped to it.
  const StaticMap dead({0, 1, 2, 4}, {0, 0, 0, 2});
  EXPECT_DOUBLE_EQ(*dead.NearestPreimage(0.0, 1.4), 1.4);
  EXPECT_DOUBLE_EQ(*dead.NearestPreimage(0.0, 7.0), 2.0);
  EXPECT_THAT([&] { bump.NearestPreimage(std::nan(""), 0.0); },
              ThrowsMessage<InvalidArgument>(HasSubstr("NaN")));
}

}  // namespace
}  // namespace pneumid
