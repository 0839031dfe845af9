// InverseMapController: a linear controller behind the inverse of a static
// map turns a Hammerstein plant y = G f(u) back into G (exact linearization,
// checked sample by sample against the linear loop), compensates the dead
// zone, keeps the input limits with anti-windup through the map, and refuses
// a map it cannot invert.
#include "pneumid/control/inverse_map_controller.hpp"

#include <cmath>
#include <memory>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/control/duty_modulator.hpp"
#include "pneumid/control/mpc.hpp"
#include "pneumid/lti/transfer_function.hpp"

namespace pneumid {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

constexpr double kTs = 0.01;
constexpr double kA = 0.96;  // G(z) = (1 - a) z^-1 / (1 - a z^-1), unit static gain

TransferFunction UnitGainLag() {
  Eigen::VectorXd num(2), den(2);
  num << 0.0, 1.0 - kA;
  den << 1.0, -kA;
  return TransferFunction(num, den, kTs);
}

// An S-shaped actuator: dead zone up to 10 %, steep in the middle, saturating
// from 90 % (force in N against duty in %).
StaticMap SMap() {
  return StaticMap({0, 10, 20, 30, 40, 50, 60, 70, 80, 90, 100},
                   {0, 0, 3, 11, 26, 50, 79, 107, 126, 136, 136});
}

std::unique_ptr<MpcController> Mpc(const InputLimits& v_limits) {
  MpcOptions o;
  o.P = 60;
  o.M = 4;
  o.lambda = 0.5;
  o.limits = v_limits;
  o.disturbance = DisturbanceModel::kOutput;
  return std::make_unique<MpcController>(UnitGainLag(), kTs, o);
}

struct Lag {  // x+ = a x + (1 - a) v, y = x
  double x = 0.0;
  double Output() const { return x; }
  void Advance(double v) { x = kA * x + (1.0 - kA) * v; }
};

TEST(InverseMapControllerTest, HammersteinPlantBehindTheInverseIsTheLinearLoop) {
  // The inner controller's input held within the map's output range [0, 136]
  // (InnerLimits of the duty range), where f(f^-1(v)) = v, also on the dead
  // zone (f^-1(0) = 10 %) and the saturation (f^-1(136) = 90 %): every sample
  // equals the linear loop's, the requests that saturate included.
  const std::vector<double> r = {20.0, 60.0, 130.0, 40.0};
  InputLimits duty;
  duty.u_min = 0.0;
  duty.u_max = 100.0;
  const InputLimits v_lim = InnerLimits(SMap(), duty);
  InverseMapController c(Mpc(v_lim), SMap(), duty);
  auto linear = Mpc(v_lim);
  const StaticMap f = SMap();
  c.Reset(f.Inverse(20.0), 20.0);
  linear->Reset(20.0, 20.0);
  Lag ham{20.0}, lin{20.0};
  double max_diff = 0.0;
  bool saturated = false;
  for (int k = 0; k < 800; ++k) {
    const double rk = r[static_cast<std::size_t>(k / 200)];
    const double u = c.Update(rk, ham.Output());
    const double v = linear->Update(rk, lin.Output());
    ham.Advance(f.Evaluate(u));
    lin.Advance(v);
    max_diff = std::max(max_diff, std::abs(ham.Output() - lin.Output()));
    ASSERT_NEAR(f.Evaluate(u), v, 1e-9 * (1.0 + std::abs(v))) << "k = " << k;
    if (v >= 136.0 - 1e-9) saturated = true;
  }
  EXPECT_TRUE(saturated);  // the 130 N step asks for the whole range
  EXPECT_LT(max_diff, 1e-9);
  EXPECT_NEAR(ham.Output(), 40.0, 1e-3);
}

TEST(InverseMapControllerTest, DeadZoneRequestGoesToItsEdgeAndTheControllerIsTold) {
  // A request for 0 N (the dead zone's level) is the dead zone's upper edge,
  // 10 %, where the force starts to move; a request below the map's range
  // the same.
  InverseMapController c(Mpc({}), SMap());
  c.Reset(10.0, 0.0);
  const double u = c.Update(0.0, 0.0);
  EXPECT_DOUBLE_EQ(u, 10.0);
  EXPECT_THAT(c.Describe(), HasSubstr("with inverse map (11 knots, u in [0, 100])"));
}

TEST(InverseMapControllerTest, InputLimitsHoldAndTheInnerControllerFollowsTheAppliedInput) {
  InputLimits lim;
  lim.u_min = 0.0;
  lim.u_max = 60.0;  // f(60) = 79 N: a set-point of 120 N cannot be reached
  const InputLimits v_lim = InnerLimits(SMap(), lim);
  EXPECT_DOUBLE_EQ(v_lim.u_min, 0.0);
  EXPECT_DOUBLE_EQ(v_lim.u_max, 79.0);
  InverseMapController c(Mpc({}), SMap(), lim);  // inner unbounded: the wrapper clips
  const StaticMap f = SMap();
  c.Reset(40.0, 26.0);
  Lag p{26.0};
  for (int k = 0; k < 300; ++k) {
    const double u = c.Update(120.0, p.Output());
    ASSERT_GE(u, 0.0);
    ASSERT_LE(u, 60.0);
    p.Advance(f.Evaluate(u));
  }
  EXPECT_NEAR(p.Output(), 79.0, 0.05);
  // Anti-windup: back to a reachable set-point without a wound-up delay. The
  // MPC's prediction follows the applied input, so the output leaves the
  // limit within a few samples.
  int k_left = -1;
  for (int k = 0; k < 300; ++k) {
    const double u = c.Update(50.0, p.Output());
    p.Advance(f.Evaluate(u));
    if (k_left < 0 && u < 60.0) k_left = k;
  }
  EXPECT_GE(k_left, 0);
  EXPECT_LE(k_left, 2);
  EXPECT_NEAR(p.Output(), 50.0, 1e-3);
}

TEST(InverseMapControllerTest, RateLimitMapsByTheSteepestSlope) {
  InputLimits lim;
  lim.du_max = 2.0;  // % per sample
  const InputLimits v = InnerLimits(SMap(), lim);
  EXPECT_DOUBLE_EQ(v.du_max, 2.0 * 2.9);  // steepest segment 50 -> 60 %: 2.9 N/%
  EXPECT_DOUBLE_EQ(v.u_min, 0.0);         // the whole map's range
  EXPECT_DOUBLE_EQ(v.u_max, 136.0);
  InverseMapController c(Mpc({}), SMap(), lim);
  c.Reset(40.0, 26.0);
  double u_prev = 40.0;
  for (int k = 0; k < 20; ++k) {
    const double u = c.Update(100.0, 26.0);
    EXPECT_LE(std::abs(u - u_prev), 2.0 + 1e-12);
    u_prev = u;
  }
}

TEST(InverseMapControllerTest, RejectsAMapWithoutInverseAndBadArguments) {
  const StaticMap not_monotone({0, 50, 100}, {0, 80, 40});
  EXPECT_THAT([&] { InverseMapController c(Mpc({}), not_monotone); },
              ThrowsMessage<InvalidArgument>(HasSubstr("not monotone")));
  EXPECT_THAT([&] { InnerLimits(not_monotone, {}); },
              ThrowsMessage<InvalidArgument>(HasSubstr("not monotone")));
  const StaticMap constant({0, 100}, {5, 5});
  EXPECT_THROW(InverseMapController(Mpc({}), constant), InvalidArgument);
  EXPECT_THAT([&] { InverseMapController c(nullptr, SMap()); },
              ThrowsMessage<InvalidArgument>(HasSubstr("null")));
  InputLimits bad;
  bad.u_min = 10.0;
  bad.u_max = 0.0;
  EXPECT_THROW(InverseMapController(Mpc({}), SMap(), bad), InvalidArgument);
}

TEST(OutputMapControllerTest, WienerPlantThroughTheInverseIsTheLinearLoop) {
  // Plant y = g(x), x = G u, with an increasing output map g (x in input
  // units, y in N); the inner MPC on G sees x = g^-1(y) and the set point
  // g^-1(r): every sample equals the linear loop's on x.
  const StaticMap g({0, 25, 50, 75, 100}, {0, 10, 50, 110, 140});
  OutputMapController c(Mpc({}), g);
  auto linear = Mpc({});
  c.Reset(20.0, g.Evaluate(20.0));
  linear->Reset(20.0, 20.0);
  Lag wie{20.0}, lin{20.0};
  const std::vector<double> r = {30.0, 120.0, 60.0};
  for (int k = 0; k < 600; ++k) {
    const double rk = r[static_cast<std::size_t>(k / 200)];
    const double u = c.Update(rk, g.Evaluate(wie.Output()));
    const double v = linear->Update(g.Inverse(rk), lin.Output());
    ASSERT_NEAR(u, v, 1e-9 * (1.0 + std::abs(v))) << "k = " << k;
    wie.Advance(u);
    lin.Advance(v);
  }
  EXPECT_NEAR(g.Evaluate(wie.Output()), 60.0, 1e-3);
  EXPECT_THAT(c.Describe(), HasSubstr("on the inverse output map (5 knots)"));
}

TEST(OutputMapControllerTest, InvertsTheMonotoneEnvelopeAndRefusesAFlatMap) {
  // A dip (fitted maps have them) is flattened: 8 N maps to the dip's start.
  const StaticMap dip({0, 10, 20, 100}, {10, 8, 12, 100});
  OutputMapController c(Mpc({}), dip);
  EXPECT_NEAR(c.map().Inverse(10.0), 10.0, 1e-12);
  EXPECT_DOUBLE_EQ(c.map().Evaluate(10.0), 10.0);
  EXPECT_THAT(
      [] {
        OutputMapController(Mpc({}), StaticMap({0, 100}, {5, 1}));
      },
      ThrowsMessage<InvalidArgument>(HasSubstr("output map")));
  EXPECT_THAT(
      [] {
        OutputMapController(nullptr, StaticMap({0, 100}, {0, 1}));
      },
      ThrowsMessage<InvalidArgument>(HasSubstr("got null")));
}

// A fitted map that dips by a little in its saturation (as the Hammerstein
// estimate of the IPA's staircase: 194.12 N at 87 % then 193.97 N at 95 %),
// or by a few percent between many closely spaced knots (3.1 N of 150 N on
// a 38-knot map of a twin with a chamber lag), is inverted through its
// monotone envelope; a map that turns by more than 5 % of its range is
// refused with the drop.
TEST(InvertibleInputMapTest, SmallDipsUseTheEnvelopeLargeTurnsAreRefused) {
  const StaticMap dip({15, 55, 87, 95}, {14.3, 67.0, 194.12, 193.97});
  const StaticMap inv = InvertibleInputMap(dip);
  EXPECT_TRUE(inv.IsMonotone());
  EXPECT_EQ(inv.y(), (std::vector<double>{14.3, 67.0, 194.12, 194.12}));
  EXPECT_DOUBLE_EQ(inv.Inverse(194.12), 87.0);
  // A dip of 4 % of the range (4 of 100) between two knots.
  const StaticMap wiggle({0, 40, 45, 100}, {0, 60, 56, 100});
  EXPECT_EQ(InvertibleInputMap(wiggle).y(), (std::vector<double>{0, 60, 60, 100}));
  const StaticMap monotone({0, 50, 100}, {0, 80, 90});
  EXPECT_EQ(InvertibleInputMap(monotone), monotone);
  EXPECT_THAT(
      [] {
        InvertibleInputMap(StaticMap({0, 50, 100}, {0, 80, 40}));
      },
      ThrowsMessage<InvalidArgument>(HasSubstr("falls by 40 after rising, more than 5 %")));
  EXPECT_THAT(
      [] {
        InvertibleInputMap(StaticMap({0, 40, 45, 100}, {0, 60, 54, 100}));
      },
      ThrowsMessage<InvalidArgument>(HasSubstr("falls by 6 after rising, more than 5 %")));
}

}  // namespace
}  // namespace pneumid

namespace pneumid {
namespace {

// Inside an input gap the modulator alternates between the gap's ends, so
// the actuator's mean output is the chord of f between them: MapThroughGaps
// must equal the mean of f over the modulated inputs, for a map whose knots
// inside the gaps are anything (here a smooth fit over a jump).
TEST(MapThroughGapsTest, IsTheMeanOfTheMapOverTheModulatedInputs) {
  const StaticMap f({0.8, 10.4, 20.0, 50.0, 80.5, 90.1, 99.6},
                    {0.15, 8.8, 17.8, 57.2, 130.0, 170.0, 193.0});
  const std::vector<InputGap> gaps = {{0.0, 15.0}, {85.0, 100.0}};
  const StaticMap g = MapThroughGaps(f, gaps);
  // Knots: the gap ends replace 0.8, 10.4, 90.1 and 99.6.
  EXPECT_EQ(g.u(), (std::vector<double>{0.0, 15.0, 20.0, 50.0, 80.5, 85.0, 100.0}));
  EXPECT_DOUBLE_EQ(g.Evaluate(0.0), 0.15);  // clamped below the first knot
  EXPECT_DOUBLE_EQ(g.Evaluate(100.0), 193.0);
  EXPECT_DOUBLE_EQ(g.Evaluate(50.0), 57.2);  // unchanged between the gaps
  // Requests within half a gap of its middle make the modulator apply only
  // the gap's ends (or the range's end): the chord is exact. Further out it
  // also applies inputs beyond the gap, where f bends, and the chord is
  // close (Jensen's gap of the piecewise-linear f).
  auto mean_of_f = [&](double request) {
    DutyModulator m(gaps, 0.0, 100.0);
    double mean = 0.0;
    const int n = 6000;
    for (int k = 0; k < n; ++k) mean += f.Evaluate(m.Next(request));
    return mean / n;
  };
  for (double request : {3.0, 5.0, 7.5, 92.5, 95.0, 99.0})
    EXPECT_NEAR(g.Evaluate(request), mean_of_f(request), 0.02) << "request " << request;
  for (double request : {12.0, 86.0})
    EXPECT_NEAR(g.Evaluate(request), mean_of_f(request), 1.0) << "request " << request;
  EXPECT_EQ(MapThroughGaps(f, {}).u(), f.u());
}

}  // namespace
}  // namespace pneumid
