// The loop with the toolkit's own plants and controllers: the IPA simulator as
// the sim backend and a DMC designed from the paper's FOPDT, checked for
// allocation on the loop thread and for the closed-loop result.
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "pneumid/control/dmc.hpp"
#include "pneumid/control/pid.hpp"
#include "pneumid/models/model_file.hpp"
#include "pneumid/plant/plant_factory.hpp"
#include "pneumid/realtime/controller_adapter.hpp"
#include "pneumid/realtime/realtime_session.hpp"
#include "pneumid/realtime/sim_backend.hpp"
#include "test_support.hpp"

namespace pneumid {
namespace {

TEST(Integration, DmcOnTheIpaSimulatorTracks) {
  DmcOptions d;  // the paper's conventional tuning P = 126, M = 5, lambda = 2.25
  d.limits.u_min = 0.0;
  d.limits.u_max = 100.0;
  ControllerAdapter dmc(std::make_unique<DmcController>(PaperFopdtModel(), 0.01, d));
  SimBackend io(MakePlant("ipa", 0.01));
  SafetyMonitor safety(SafetyOptions{});
  LogWriterOptions lo;
  lo.keep_in_memory = true;
  LogWriter log("", {}, lo);
  LoopOptions o;
  o.duration = 2.0;
  o.fast = true;
  const LoopSummary s = RunLoop(o, io, dmc, std::vector<double>(200, 80.0), safety, &log);
  log.Close();
  EXPECT_EQ(s.termination, Termination::kSuccess) << s.message;
  EXPECT_EQ(s.samples, 200);
  ASSERT_EQ(log.records().size(), 200u);
  // 80 N reached by the end (DMC's bias correction removes the offset): the mean over the
  // last 0.5 s (25 PWM periods of ripple) within 2 %.
  double mean = 0.0;
  for (std::size_t k = 150; k < 200; ++k) mean += log.records()[k].y / 50.0;
  EXPECT_NEAR(mean, 80.0, 0.02 * 80.0);
  EXPECT_TRUE(io.in_safe_state());
  // The IPA backend reports the chamber pressure (absolute, Pa) as the auxiliary channel.
  EXPECT_GT(log.records().back().aux, 1e5);
}

// The safety layer's range clips a controller that has no limits of its own;
// the loop tells it the applied input (anti-windup), so it acts exactly as a
// controller given the same limits: identical inputs and outputs.
TEST(Integration, SafetyClippedControllerFollowsTheAppliedInput) {
  std::vector<std::vector<double>> u(2), y(2);
  for (int limited = 0; limited < 2; ++limited) {
    DmcOptions d;
    if (limited) {
      d.limits.u_min = 0.0;
      d.limits.u_max = 100.0;
    }
    ControllerAdapter dmc(std::make_unique<DmcController>(PaperFopdtModel(), 0.01, d));
    SimBackend io(MakePlant("ipa", 0.01));
    SafetyOptions so;  // duty 0..100 % by default
    SafetyMonitor safety(so);
    LogWriterOptions lo;
    lo.keep_in_memory = true;
    LogWriter log("", {}, lo);
    LoopOptions o;
    o.duration = 2.0;
    o.fast = true;
    std::vector<double> r(200, 20.0);
    for (int k = 50; k < 200; ++k) r[k] = 150.0;  // beyond what 100 % duty can hold quickly
    const LoopSummary s = RunLoop(o, io, dmc, r, safety, &log);
    log.Close();
    ASSERT_EQ(s.termination, Termination::kSuccess) << s.message;
    for (const auto& rec : log.records()) {
      u[limited].push_back(rec.u);
      y[limited].push_back(rec.y);
    }
  }
  ASSERT_EQ(u[0].size(), u[1].size());
  double top = 0.0;
  for (std::size_t k = 0; k < u[0].size(); ++k) {
    EXPECT_NEAR(u[0][k], u[1][k], 1e-9) << k;
    EXPECT_NEAR(y[0][k], y[1][k], 1e-9) << k;
    top = std::max(top, u[0][k]);
  }
  EXPECT_EQ(top, 100.0);  // the limit was reached
}

// The loop speaks of hold and release; the plant behind the backend names them
// (the IPA: valves-closed, exhaust-open) and states its units.
TEST(Integration, SafeStateNamedByThePlantBehindTheBackend) {
  LoopOptions o;
  o.duration = 0.1;
  o.fast = true;
  SafetyOptions so;
  so.safe_state = SafeState::kRelease;
  for (const bool ipa : {true, false}) {
    SimBackend io(ipa ? MakePlant("ipa", 0.01)
                      : std::unique_ptr<Plant>(
                            std::make_unique<testing::FirstOrderPlant>(0.01, 0.96, 0.064)));
    EXPECT_EQ(io.actuator().input.unit, ipa ? "%" : "");
    OpenLoopInput hold(std::vector<double>(10, 50.0), "open loop");
    SafetyMonitor safety(so);
    const LoopSummary s = RunLoop(o, io, hold, std::vector<double>(10, 0.0), safety, nullptr);
    EXPECT_EQ(s.safe_state, SafeState::kRelease);
    EXPECT_EQ(s.safe_state_name, ipa ? "exhaust-open" : "release");
    EXPECT_THAT(s.message, ::testing::HasSubstr(ipa ? "outputs set to exhaust-open"
                                                    : "outputs set to release"));
    EXPECT_EQ(s.ToJson()["safe_state"], s.safe_state_name);
    EXPECT_THAT(DescribeSafety(so, io.actuator()),
                ::testing::HasSubstr(ipa ? "u in [0, 100] %, " : "u in [0, 100], "));
  }
}

}  // namespace
}  // namespace pneumid

namespace pneumid {
namespace {

// Which part allocates: each of the toolkit's pieces alone on the loop thread
// (the loop itself is checked in realtime_loop_test.cpp).
TEST(Integration, IpaSimulatorAloneOnTheLoopThread) {
  testing::CountingPi pi(0.5, 5.0, 0.01);
  SimBackend io(MakePlant("ipa", 0.01));
  SafetyMonitor safety(SafetyOptions{});
  LoopOptions o;
  o.duration = 2.0;
  o.fast = true;
  RunLoop(o, io, pi, {80.0}, safety);
  EXPECT_EQ(pi.allocations_during_run(), 0);
}

TEST(Integration, DmcAloneOnTheLoopThread) {
  DmcOptions d;
  d.limits.u_min = 0.0;
  d.limits.u_max = 100.0;
  ControllerAdapter dmc(std::make_unique<DmcController>(PaperFopdtModel(), 0.01, d));
  testing::CountingWrapper counted(dmc);
  SimBackend io(std::make_unique<testing::FirstOrderPlant>(0.01, 0.96, 0.064));
  SafetyMonitor safety(SafetyOptions{});
  LoopOptions o;
  o.duration = 2.0;
  o.fast = true;
  RunLoop(o, io, counted, {80.0}, safety);
  EXPECT_EQ(counted.allocations_during_run(), 0);
}

}  // namespace
}  // namespace pneumid
