// The identification entry point: method names (those of `pneumid identify
// --method`), list parsing and dispatch by name to the step-response and the
// parametric methods.
#include "pneumid/identify/identify.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/identify/parametric/parametric.hpp"
#include "step_test_util.hpp"

namespace pneumid {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

TEST(IdentifyTest, MethodNamesAreTheCommandLineNames) {
  const std::vector<std::string> expected = {
      "reaction-curve", "tangent", "smith",    "sundaresan", "broida", "sopdt", "ptn",
      "strejc",         "areas",   "fit-p1d",  "fit-p2d",    "fit-p2du", "fit-p3d", "fit-p1di",
      "arx",            "iv4",     "armax",    "oe",         "bj",     "n4sid", "cra",
      "spa"};
  EXPECT_EQ(IdentifyMethodNames(), expected);
  for (const auto& m : expected) EXPECT_TRUE(IsIdentifyMethod(m)) << m;
  EXPECT_FALSE(IsIdentifyMethod("all"));
  EXPECT_FALSE(IsIdentifyMethod("ARX"));
}

TEST(IdentifyTest, ParsesMethodLists) {
  EXPECT_THAT(ParseMethodList(" arx, ptn ,arx,,reaction-curve"),
              ElementsAre("arx", "ptn", "reaction-curve"));
  EXPECT_EQ(ParseMethodList("all"), IdentifyMethodNames());
  EXPECT_EQ(ParseMethodList("spa,all").front(), "spa");
  EXPECT_EQ(ParseMethodList("spa,all").size(), IdentifyMethodNames().size());
  EXPECT_THAT([] { ParseMethodList("arx,bogus"); },
              ThrowsMessage<InvalidArgument>(HasSubstr("unknown method 'bogus' (valid: "
                                                       "reaction-curve, tangent")));
  EXPECT_THAT([] { ParseMethodList(" , "); },
              ThrowsMessage<InvalidArgument>(HasSubstr("at least one method")));
}

TEST(IdentifyTest, DispatchesToBothKindsOfMethod) {
  const Dataset d = testing::LoadSynthetic("fopdt");
  const IdentifiedModel rc = Identify("reaction-curve", d);
  EXPECT_EQ(rc.method, "reaction-curve");
  EXPECT_EQ(rc.structure, "FOPDT");
  EXPECT_NEAR(rc.tf.DcGain(), 2.5, 0.1);  // true plant 2.5 exp(-0.413 s) / (1.5 s + 1)
  const IdentifiedModel arx = Identify("arx", d);
  EXPECT_EQ(arx.structure, "ARX");
  ASSERT_TRUE(arx.discrete.has_value());
  EXPECT_EQ(arx.fit_percent, IdentifyParametric("arx", d, {}).fit_percent);
}

TEST(IdentifyTest, OptionsReachTheStepMethods) {
  const Dataset d = testing::LoadSynthetic("fopdt");
  IdentifyOptions options;
  options.step.step.min_snr = 1e9;  // no step is large enough against the noise
  EXPECT_THROW(Identify("reaction-curve", d, {}, options), DataError);
  options.step.step.tail_fraction = -1.0;
  std::string why;
  EXPECT_FALSE(options.IsValid(&why));
  EXPECT_THAT(why, HasSubstr("tail_fraction"));
  EXPECT_THROW(Identify("reaction-curve", d, {}, options), InvalidArgument);
}

TEST(IdentifyTest, UnknownMethodListsTheValidNames) {
  const Dataset d = testing::LoadSynthetic("fopdt");
  EXPECT_THAT([&] { Identify("bogus", d); },
              ThrowsMessage<InvalidArgument>(HasSubstr("unknown method 'bogus' (valid: "
                                                       "reaction-curve")));
}

}  // namespace
}  // namespace pneumid
