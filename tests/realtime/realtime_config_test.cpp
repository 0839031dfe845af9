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

namespace pneumid {
namespace {

TEST(RealtimeConfig, TheControllerSectionHoldsAController) {
  const RealtimeConfig c = ParseRealtimeConfig(
      "[controller]\nmodel = \"fopdt:K=1,tau=1,theta=0.1\"\ntype = \"mpc\"\nrule = \"auto\"\n"
      "aggressiveness = 0.25\nP = 40\nu_min = 0\nu_max = 100\ninput_gaps = \"0:15,85:100\"\n",
      "c.toml");
  ASSERT_TRUE(c.controller.has_value());
  EXPECT_EQ(c.controller->model, "fopdt:K=1,tau=1,theta=0.1");
  EXPECT_EQ(c.controller->settings.controller, "mpc");
  EXPECT_EQ(c.controller->settings.rule, "auto");
  EXPECT_DOUBLE_EQ(c.controller->settings.aggressiveness, 0.25);
  EXPECT_EQ(c.controller->settings.P, 40);
  EXPECT_DOUBLE_EQ(c.controller->settings.limits.u_max, 100.0);
  EXPECT_EQ(c.controller->settings.input_gaps, "0:15,85:100");
  EXPECT_EQ(c.controller->keys.size(), 8u);
  EXPECT_FALSE(ParseRealtimeConfig("[loop]\nperiod = 0.01\n", "n.toml").controller.has_value());
}

TEST(RealtimeConfig, ControllerSectionErrorsNameTheLine) {
  auto message = [](const std::string& text) { return ParseError(text, "c.toml"); };
  EXPECT_THAT(message("[controller]\ntype = \"fuzzy\"\n"), HasSubstr("c.toml:2:"));
  EXPECT_THAT(message("[controller]\ninput_gaps = \"15:0\"\n"), HasSubstr("c.toml:2:"));
  EXPECT_THAT(message("[controller]\nhorizon = 3\n"), HasSubstr("unknown key 'horizon'"));
  EXPECT_THAT(message("[controller]\nP = \"ten\"\n"), HasSubstr("must be an integer"));
}

}  // namespace
}  // namespace pneumid
