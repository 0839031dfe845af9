#include "pneumid/realtime/realtime_config.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"

namespace pneumid {
namespace {

using ::testing::HasSubstr;

TEST(RealtimeConfig, TheExampleFileLoads) {
  const RealtimeConfig c =
      LoadRealtimeConfig(std::string(PNEUMID_SOURCE_DIR) + "/config/realtime_example.toml");
  EXPECT_DOUBLE_EQ(c.loop.period, 0.01);
  EXPECT_EQ(c.io, "sim");
  EXPECT_EQ(c.safety.safe_state, SafeState::kHold);
  EXPECT_DOUBLE_EQ(c.safety.y_max, 400.0);
  EXPECT_EQ(c.comedi.ai_aref, AnalogReference::kDiff);
  EXPECT_DOUBLE_EQ(c.comedi.force_offset, 294.0);
  EXPECT_EQ(c.udp.max_missed, 3);
}

TEST(RealtimeConfig, OverridesDefaults) {
  const RealtimeConfig c = ParseRealtimeConfig(
      "[loop]\nperiod = 0.001\n[safety]\nsafe_state = \"exhaust-open\"\nmax_overruns = -1\n"
      "[io]\nbackend = \"udp://127.0.0.1:6000\"\n[comedi]\ndevice = \"/dev/comedi3\"\n",
      "t.toml");
  EXPECT_DOUBLE_EQ(c.loop.period, 0.001);
  EXPECT_EQ(c.safety.safe_state, SafeState::kRelease);
  EXPECT_EQ(c.safety.max_overruns, -1);
  EXPECT_EQ(c.io, "udp://127.0.0.1:6000");
  EXPECT_EQ(c.comedi.device, "/dev/comedi3");
  EXPECT_DOUBLE_EQ(c.safety.u_max, 100.0);  // untouched default
}

/// The DataError message of parsing `text` as `source`, or "no error".
std::string ParseError(const std::string& text, const std::string& source) {
  try {
    ParseRealtimeConfig(text, source);
  } catch (const DataError& e) {
    return e.what();
  }
  return "no error";
}

TEST(RealtimeConfig, ErrorsNameFileLineAndColumn) {
  auto message = [](const std::string& text) { return ParseError(text, "rt.toml"); };
  EXPECT_THAT(message("[loop]\nperiod = \"fast\"\n"), HasSubstr("rt.toml:2:"));
  EXPECT_THAT(message("[loop]\nperiod = \"fast\"\n"), HasSubstr("must be a number"));
  EXPECT_THAT(message("[loop]\nperiodd = 1\n"), HasSubstr("unknown key 'periodd'"));
  EXPECT_THAT(message("[loops]\n"), HasSubstr("unknown section [loops]"));
  EXPECT_THAT(message("[safety]\nsafe_state = \"open\"\n"), HasSubstr("rt.toml:2:"));
  EXPECT_THAT(message("[io]\nbackend = \"serial\"\n"), HasSubstr("unknown backend"));
  EXPECT_THAT(message("[loop]\nperiod = -1\n"), HasSubstr("[loop] period"));
  EXPECT_THAT(message("[loop\n"), HasSubstr("rt.toml:1:"));
  EXPECT_THROW(LoadRealtimeConfig("/nonexistent/rt.toml"), DataError);
}

TEST(RealtimeConfig, IntegersOutOfRangeAreRejectedNotWrapped) {
  auto message = [](const std::string& text) { return ParseError(text, "rt.toml"); };
  // 4294967376 = 2^32 + 80 wrapped to a valid priority of 80 before.
  EXPECT_THAT(message("[loop]\npriority = 4294967376\n"),
              HasSubstr("rt.toml:2:12: [loop] priority = 4294967376 is out of range"));
  EXPECT_THAT(message("[loop]\ncpu = -9223372036854775807\n"),
              HasSubstr("[loop] cpu = -9223372036854775807 is out of range"));
  EXPECT_THAT(message("[loop]\npriority = 80\ncpu = 1\n"), "no error");
}

}  // namespace
}  // namespace pneumid
