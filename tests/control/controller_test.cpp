// The guard every controller has in front of its control law (controller.hpp,
// MeasurementGuard): NaN and infinite measurements and set-points, and
// measurements outside the valid range, never reach the state; the output
// holds the last valid input (or the safe input), the fault is reported, and
// control resumes on the next valid sample. Tested on DMC, QDMC, GPC, PID and
// MPC (unconstrained and constrained) and on a controller behind an input map,
// in closed loop with the paper's FOPDT model (K = 1.6, tau = 0.245 s) in N.
#include "pneumid/control/controller.hpp"

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/control/controller_factory.hpp"
#include "pneumid/plant/linear_plant.hpp"

namespace pneumid {
namespace {

constexpr double kTs = 0.01;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

TransferFunction PaperFopdt() { return TransferFunction::Fopdt(1.6, 0.245, 0.001); }

struct GuardCase {
  std::string name;
  std::string controller;
  bool constrained = false;
  double du_max = kInf;
  bool input_map = false;
};

std::ostream& operator<<(std::ostream& os, const GuardCase& c) { return os << c.name; }

BuiltController Build(const GuardCase& c, const MeasurementGuard& guard = {}) {
  ControllerSettings s;
  s.controller = c.controller;
  s.limits.u_min = 0.0;
  s.limits.u_max = 100.0;
  s.limits.du_max = c.du_max;
  s.constrained = c.constrained;
  ControllerSpec spec = ToControllerSpec(s);
  spec.guard = guard;
  if (c.input_map)  // a valve-like map: dead band to 10 %, then 1.6 N per %
    spec.input_map = StaticMap({0, 10, 100}, {0, 0, 144});
  return MakeController(c.input_map ? TransferFunction::Fopdt(1.0, 0.245, 0.001) : PaperFopdt(),
                        kTs, spec);
}

struct Trace {
  std::vector<double> y, u;
  std::vector<ControllerFault> fault;
};

// 6 s at a set-point of 60 N (from 30 N at rest); the measurement of samples
// [k0, k1) is replaced by `bad`.
Trace RunLoop(Controller& c, int k0, int k1, double bad, bool bad_setpoint = false) {
  LinearPlant plant(PaperFopdt(), kTs);
  plant.Reset();
  Trace t;
  // Start at rest at 30 N: u = 30 / 1.6.
  const double u0 = 30.0 / 1.6;
  for (int k = 0; k < 500; ++k) {
    plant.Measure();
    plant.Advance(u0);
  }
  c.Reset(u0, 30.0);
  for (int k = 0; k < 600; ++k) {
    double y = plant.Measure();
    double r = 60.0;
    const bool faulty = k >= k0 && k < k1;
    if (faulty && !bad_setpoint) y = bad;
    if (faulty && bad_setpoint) r = bad;
    const double u = c.Update(r, y);
    t.y.push_back(plant.Measure());
    t.u.push_back(u);
    t.fault.push_back(c.last_fault());
    plant.Advance(u);
  }
  return t;
}

class ControllerGuardTest : public ::testing::TestWithParam<GuardCase> {};

TEST_P(ControllerGuardTest, NonFiniteMeasurementsHoldTheInputAndControlResumes) {
  for (const double bad : {kNaN, kInf, -kInf}) {
    SCOPED_TRACE(bad);
    BuiltController b = Build(GetParam());
    Controller& c = *b.controller;
    // Faults at samples 150..159 (1.5 s, during the response to the step).
    const int k0 = 150, k1 = 160;
    const Trace t = RunLoop(c, k0, k1, bad);
    for (int k = 0; k < 600; ++k) {
      ASSERT_TRUE(std::isfinite(t.u[k])) << "sample " << k;
      ASSERT_GE(t.u[k], 0.0) << "sample " << k;
      ASSERT_LE(t.u[k], 100.0) << "sample " << k;
    }
    for (int k = k0; k < k1; ++k) {
      EXPECT_EQ(t.fault[k], ControllerFault::kMeasurementNotFinite) << "sample " << k;
      EXPECT_EQ(t.u[k], t.u[k0 - 1]) << "the input is held at sample " << k;
    }
    EXPECT_EQ(t.fault[k1], ControllerFault::kNone);
    EXPECT_EQ(c.fault_count(), k1 - k0);
    // Back within 0.5 N of the set-point within 0.5 s of the valid samples'
    // return, and it stays there.
    for (int k = k1 + 50; k < 600; ++k) EXPECT_NEAR(t.y[k], 60.0, 0.5) << "sample " << k;
    // Reset clears the fault state.
    c.Reset();
    EXPECT_EQ(c.fault_count(), 0);
    EXPECT_EQ(c.last_fault(), ControllerFault::kNone);
  }
}

// A finite reading so large that the law overflows (1.7e308 into the
// proportional term, the prediction's bias, the observer) gave a clipped,
// finite input and left the state at +-inf or NaN: the PID held 0 or 100 %
// for good and the MPC's QP threw. Now the law's non-finite input is a fault
// (output-not-finite), the law restarts at the held input, and control resumes.
TEST_P(ControllerGuardTest, AnOverflowingReadingIsAFaultAndControlResumes) {
  for (const double bad : {1.7e308, -1.7e308}) {
    SCOPED_TRACE(bad);
    BuiltController b = Build(GetParam());
    Controller& c = *b.controller;
    const int k0 = 150;
    Trace t;
    ASSERT_NO_THROW(t = RunLoop(c, k0, k0 + 1, bad));
    for (int k = 0; k < 600; ++k) {
      ASSERT_TRUE(std::isfinite(t.u[k])) << "sample " << k;
      ASSERT_GE(t.u[k], 0.0) << "sample " << k;
      ASSERT_LE(t.u[k], 100.0) << "sample " << k;
    }
    // The faulty sample itself, or the next one when the overflow shows only
    // in the state, is the fault; no other sample is.
    int faults = 0;
    for (int k = 0; k < 600; ++k) {
      if (t.fault[k] == ControllerFault::kNone) continue;
      EXPECT_EQ(t.fault[k], ControllerFault::kOutputNotFinite) << "sample " << k;
      EXPECT_TRUE(k == k0 || k == k0 + 1) << "sample " << k;
      ++faults;
    }
    for (int k = k0 + 150; k < 600; ++k) EXPECT_NEAR(t.y[k], 60.0, 0.5) << "sample " << k;
  }
}

TEST_P(ControllerGuardTest, OutOfRangeMeasurementsAndBadSetpointsAreFaults) {
  MeasurementGuard g;
  g.y_min = -5.0;
  g.y_max = 250.0;
  BuiltController b = Build(GetParam(), g);
  Controller& c = *b.controller;
  // A disconnected sensor reads 0 V -> far below the range, here -1000 N.
  const Trace t = RunLoop(c, 200, 230, -1000.0);
  for (int k = 200; k < 230; ++k) {
    EXPECT_EQ(t.fault[k], ControllerFault::kMeasurementOutOfRange) << "sample " << k;
    EXPECT_EQ(t.u[k], t.u[199]);
  }
  for (int k = 280; k < 600; ++k) EXPECT_NEAR(t.y[k], 60.0, 0.5) << "sample " << k;

  BuiltController b2 = Build(GetParam());
  const Trace s = RunLoop(*b2.controller, 200, 210, kNaN, /*bad_setpoint=*/true);
  for (int k = 200; k < 210; ++k)
    EXPECT_EQ(s.fault[k], ControllerFault::kSetpointNotFinite) << "sample " << k;
  EXPECT_EQ(b2.controller->fault_count(), 10);
  for (int k = 260; k < 600; ++k) EXPECT_NEAR(s.y[k], 60.0, 0.5) << "sample " << k;
}

TEST_P(ControllerGuardTest, SafeInputIsAppliedAndTakenAsTheControllersOwn) {
  MeasurementGuard g;
  g.safe_input = 0.0;  // vent
  BuiltController b = Build(GetParam(), g);
  Controller& c = *b.controller;
  const Trace t = RunLoop(c, 300, 320, kNaN);
  for (int k = 300; k < 320; ++k) EXPECT_EQ(t.u[k], 0.0) << "sample " << k;
  EXPECT_DOUBLE_EQ(c.last_input(), t.u.back());
  // The controller resumed from the vented state (no bump from a stale
  // input memory) and tracks again.
  for (int k = 400; k < 600; ++k) EXPECT_NEAR(t.y[k], 60.0, 0.5) << "sample " << k;
}

TEST_P(ControllerGuardTest, AFaultFreeRunIsUnchangedByTheGuard) {
  BuiltController a = Build(GetParam());
  MeasurementGuard g;
  g.y_min = -1e6;
  g.y_max = 1e6;
  BuiltController b = Build(GetParam(), g);
  const Trace ta = RunLoop(*a.controller, -1, -1, 0.0);
  const Trace tb = RunLoop(*b.controller, -1, -1, 0.0);
  EXPECT_EQ(ta.u, tb.u);
  EXPECT_EQ(a.controller->fault_count(), 0);
}

INSTANTIATE_TEST_SUITE_P(Controllers, ControllerGuardTest,
                         ::testing::Values(GuardCase{"dmc", "dmc"},
                                           GuardCase{"qdmc", "dmc", true, 5.0},
                                           GuardCase{"gpc", "gpc"}, GuardCase{"pid", "pid"},
                                           GuardCase{"mpc", "mpc"},
                                           GuardCase{"mpc_rate", "mpc", false, 5.0},
                                           GuardCase{"mpc_input_map", "mpc", false, kInf, true},
                                           GuardCase{"dmc_input_map", "dmc", false, kInf, true}),
                         [](const auto& info) { return info.param.name; });

TEST(MeasurementGuardTest, ValidityAndChecksInOrder) {
  MeasurementGuard g;
  std::string error;
  EXPECT_TRUE(g.IsValid(&error));
  EXPECT_EQ(g.Check(1.0, 2.0), ControllerFault::kNone);
  EXPECT_EQ(g.Check(kNaN, kNaN), ControllerFault::kMeasurementNotFinite);
  EXPECT_EQ(g.Check(kNaN, 2.0), ControllerFault::kSetpointNotFinite);
  g.y_min = 0.0;
  g.y_max = 10.0;
  EXPECT_EQ(g.Check(kInf, 11.0), ControllerFault::kMeasurementOutOfRange);
  EXPECT_EQ(g.Check(1.0, 10.0), ControllerFault::kNone);
  g.y_min = 20.0;
  EXPECT_FALSE(g.IsValid(&error));
  EXPECT_THAT(error, ::testing::HasSubstr("y_min <= y_max, got [20, 10]"));
  g = MeasurementGuard{};
  g.safe_input = kInf;
  EXPECT_FALSE(g.IsValid(&error));
  EXPECT_THAT(error, ::testing::HasSubstr("safe input must be finite"));
  BuiltController b = Build(GuardCase{"pid", "pid"});
  EXPECT_THROW(b.controller->SetMeasurementGuard(g), InvalidArgument);
}

TEST(ControllerFaultTest, NamesRoundTrip) {
  for (ControllerFault f : {ControllerFault::kNone, ControllerFault::kMeasurementNotFinite,
                            ControllerFault::kMeasurementOutOfRange,
                            ControllerFault::kSetpointNotFinite, ControllerFault::kOutputNotFinite})
    EXPECT_EQ(ControllerFaultFromString(ToString(f)), f);
  EXPECT_EQ(ToString(ControllerFault::kMeasurementNotFinite), "measurement-not-finite");
  EXPECT_THROW(ControllerFaultFromString("nan"), InvalidArgument);
}

TEST(ControllerSettingsTest, GuardFromSettings) {
  ControllerSettings s;
  s.y_valid_min = 0.0;
  s.y_valid_max = 250.0;
  s.safe_input = 0.0;
  const ControllerSpec spec = ToControllerSpec(s);
  EXPECT_EQ(spec.guard.y_min, 0.0);
  EXPECT_EQ(spec.guard.y_max, 250.0);
  EXPECT_EQ(spec.guard.safe_input, 0.0);
  const BuiltController b = MakeController(PaperFopdt(), kTs, spec);
  EXPECT_EQ(b.controller->measurement_guard().y_max, 250.0);
  s.y_valid_min = 300.0;
  EXPECT_THAT([&] { ToControllerSpec(s); },
              ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr("y_min <= y_max")));
  // A safe input beyond the limits would be applied as it is.
  s.y_valid_min = 0.0;
  s.limits.u_min = 0.0;
  s.limits.u_max = 100.0;
  s.safe_input = 150.0;
  EXPECT_THAT([&] { ToControllerSpec(s); },
              ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr(
                  "the safe input 150 lies outside the input limits [0, 100]")));
}

}  // namespace
}  // namespace pneumid
