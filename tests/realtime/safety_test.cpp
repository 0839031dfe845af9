#include "pneumid/realtime/safety.hpp"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"

namespace pneumid {
namespace {

TEST(SafetyMonitor, ClampsIndependentlyOfTheController) {
  SafetyMonitor s(SafetyOptions{});
  unsigned flags = 0;
  EXPECT_EQ(s.LimitOutput(150.0, 0.01, &flags), 100.0);
  EXPECT_EQ(flags, 1u);
  EXPECT_EQ(s.LimitOutput(-3.0, 0.01, &flags), 0.0);
  EXPECT_EQ(flags, 1u);
  EXPECT_EQ(s.LimitOutput(42.0, 0.01, &flags), 42.0);
  EXPECT_EQ(flags, 0u);
}

TEST(SafetyMonitor, RateLimitsTheOutput) {
  SafetyOptions o;
  o.rate_max = 500.0;  // % per s: 5 % per 10-ms period
  SafetyMonitor s(o);
  s.Reset(0.0);
  unsigned flags = 0;
  EXPECT_DOUBLE_EQ(s.LimitOutput(80.0, 0.01, &flags), 5.0);
  EXPECT_EQ(flags, 2u);
  EXPECT_DOUBLE_EQ(s.LimitOutput(80.0, 0.01, &flags), 10.0);
  EXPECT_DOUBLE_EQ(s.LimitOutput(12.0, 0.01, &flags), 12.0);
  EXPECT_EQ(flags, 0u);
  EXPECT_DOUBLE_EQ(s.LimitOutput(-50.0, 0.01, &flags), 7.0);  // clamped to 0, then rate
  EXPECT_EQ(flags, 3u);
}

TEST(SafetyMonitor, DetectsSensorFaults) {
  SafetyOptions o;
  o.y_min = -10.0;
  o.y_max = 200.0;
  o.frozen_samples = 3;
  o.frozen_tolerance = 1e-9;
  SafetyMonitor s(o);
  EXPECT_EQ(s.CheckMeasurement(IoStatus::kOk, std::nan("")), Fault::kSensorNaN);
  EXPECT_EQ(s.CheckMeasurement(IoStatus::kOk, INFINITY), Fault::kSensorNaN);
  EXPECT_EQ(s.CheckMeasurement(IoStatus::kOk, 201.0), Fault::kSensorOutOfRange);
  EXPECT_EQ(s.CheckMeasurement(IoStatus::kOk, -11.0), Fault::kSensorOutOfRange);
  EXPECT_EQ(s.CheckMeasurement(IoStatus::kOutOfRange, 1.0), Fault::kSensorOutOfRange);
  EXPECT_EQ(s.CheckMeasurement(IoStatus::kError, 1.0), Fault::kIoError);
  EXPECT_EQ(s.CheckMeasurement(IoStatus::kTimeout, 1.0), Fault::kTimeout);
  EXPECT_EQ(s.CheckMeasurement(IoStatus::kStale, 1.0), Fault::kNone);
  s.Reset();
  EXPECT_EQ(s.CheckMeasurement(IoStatus::kOk, 5.0), Fault::kNone);
  EXPECT_EQ(s.CheckMeasurement(IoStatus::kOk, 5.0), Fault::kNone);
  EXPECT_EQ(s.CheckMeasurement(IoStatus::kOk, 5.1), Fault::kNone);  // changed: count restarts
  EXPECT_EQ(s.CheckMeasurement(IoStatus::kOk, 5.1), Fault::kNone);
  EXPECT_EQ(s.CheckMeasurement(IoStatus::kOk, 5.1), Fault::kSensorFrozen);  // 3 equal samples
}

TEST(SafetyMonitor, CountsOverrunsAgainstTheLimit) {
  SafetyOptions o;
  o.max_overruns = 2;
  SafetyMonitor s(o);
  EXPECT_EQ(s.OnOverrun(), Fault::kNone);
  EXPECT_EQ(s.OnOverrun(), Fault::kNone);
  EXPECT_EQ(s.OnOverrun(), Fault::kDeadlineOverruns);
  o.max_overruns = -1;
  SafetyMonitor never(o);
  for (int i = 0; i < 100; ++i) EXPECT_EQ(never.OnOverrun(), Fault::kNone);
}

TEST(SafetyOptions, InvalidOptionsAreRejectedWithTheValues) {
  SafetyOptions o;
  o.u_min = 10;
  o.u_max = 5;
  std::string error;
  EXPECT_FALSE(o.IsValid(&error));
  EXPECT_THAT(error, ::testing::HasSubstr("[10, 5]"));
  EXPECT_THROW(SafetyMonitor{o}, InvalidArgument);
  o = SafetyOptions{};
  o.frozen_samples = -1;
  EXPECT_FALSE(o.IsValid(&error));
}

TEST(SafetyEnums, StringsRoundTrip) {
  for (Fault f :
       {Fault::kNone, Fault::kSensorNaN, Fault::kSensorOutOfRange, Fault::kSensorFrozen,
        Fault::kIoError, Fault::kTimeout, Fault::kDeadlineOverruns, Fault::kControllerError})
    EXPECT_EQ(FaultFromString(ToString(f)), f);
  EXPECT_EQ(SafeStateFromString("exhaust-open"), SafeState::kRelease);
  EXPECT_EQ(SafeStateFromString("valves-closed"), SafeState::kHold);
  EXPECT_THROW(SafeStateFromString("open"), InvalidArgument);
  EXPECT_THROW(FaultFromString("boom"), InvalidArgument);
}

// The safe states are generic (hold, release); the plant names them: the IPA's
// names are accepted on input and used in messages of IPA backends.
TEST(SafetyEnums, GenericSafeStatesNamedByTheActuator) {
  EXPECT_STREQ(ToString(SafeState::kHold), "hold");
  EXPECT_STREQ(ToString(SafeState::kRelease), "release");
  EXPECT_EQ(SafeStateFromString("hold"), SafeState::kHold);
  EXPECT_EQ(SafeStateFromString("release"), SafeState::kRelease);
  EXPECT_THAT([] { SafeStateFromString("vent"); },
              ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr(
                  "valid: hold, release; the IPA's valves-closed, exhaust-open")));
  const Actuator ipa = IpaActuator();
  EXPECT_EQ(SafeStateName(ipa, SafeState::kHold), "valves-closed");
  EXPECT_EQ(SafeStateName(ipa, SafeState::kRelease), "exhaust-open");
  EXPECT_THAT(SafeStateMeaning(ipa, SafeState::kRelease), ::testing::HasSubstr("exhaust open"));
  EXPECT_EQ(ipa.input.unit, "%");
  EXPECT_EQ(ipa.u_max, 100.0);
  const Actuator generic;
  EXPECT_EQ(SafeStateName(generic, SafeState::kHold), "hold");
  EXPECT_EQ(SafeStateName(generic, SafeState::kRelease), "release");
}

}  // namespace
}  // namespace pneumid
