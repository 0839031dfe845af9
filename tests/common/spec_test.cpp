#include "pneumid/common/spec.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/common/enum_names.hpp"
#include "pneumid/common/strings.hpp"
#include "pneumid/common/termination.hpp"

namespace pneumid {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

TEST(StringsTest, ShellQuoteGivesOneShellWord) {
  EXPECT_EQ(ShellQuote("data/step_1.csv"), "data/step_1.csv");
  EXPECT_EQ(ShellQuote("models.json#arx"), "models.json#arx");  // '#' inside a word
  EXPECT_EQ(ShellQuote("step:from=0.61,to=82"), "step:from=0.61,to=82");
  EXPECT_EQ(ShellQuote("#arx"), "'#arx'");  // would start a comment
  EXPECT_EQ(ShellQuote(""), "''");
  EXPECT_EQ(ShellQuote("a b"), "'a b'");
  EXPECT_EQ(ShellQuote("it's"), "'it'\\''s'");
  EXPECT_EQ(ShellQuote("$HOME;rm"), "'$HOME;rm'");
}

TEST(StringsTest, TrimSplitParse) {
  EXPECT_EQ(Trim(" \t a b \r\n"), "a b");
  EXPECT_EQ(Trim("   "), "");
  EXPECT_THAT(Split(" a, b,,c ", ','), ElementsAre("a", "b", "", "c"));
  EXPECT_TRUE(Split("", ',').empty());
  EXPECT_EQ(ParseDouble(" +1.5 "), 1.5);
  EXPECT_EQ(ParseDouble("-2e3"), -2000.0);
  EXPECT_FALSE(ParseDouble("1.5x"));
  EXPECT_FALSE(ParseDouble("++1"));
  EXPECT_FALSE(ParseDouble(""));
  EXPECT_FALSE(ParseDouble("72e377"));  // out of range of double
  EXPECT_EQ(ToLower("PRBS"), "prbs");
}

TEST(SpecTest, KindKeysAndLists) {
  Spec s("model spec", " TF:num=1 2,den=1;3;2 ,Ts=0.01 ");
  EXPECT_EQ(s.kind(), "tf");
  EXPECT_THAT(s.List("num"), ElementsAre(1.0, 2.0));
  EXPECT_THAT(s.List("den"), ElementsAre(1.0, 3.0, 2.0));
  EXPECT_DOUBLE_EQ(s.Number("Ts", 0.0), 0.01);
  EXPECT_DOUBLE_EQ(s.Number("delay", 0.5), 0.5);
  EXPECT_NO_THROW(s.Finish());
}

TEST(SpecTest, CommasContinueTheListOfThePreviousKey) {
  Spec s("model spec", "tf:num=1,den=1,-1");
  EXPECT_THAT(s.List("num"), ElementsAre(1.0));
  EXPECT_THAT(s.List("den"), ElementsAre(1.0, -1.0));
  Spec t("model spec", "tf:num=1,2,den=1,3,2,Ts=0.1");
  EXPECT_THAT(t.List("num"), ElementsAre(1.0, 2.0));
  EXPECT_THAT(t.List("den"), ElementsAre(1.0, 3.0, 2.0));
  EXPECT_DOUBLE_EQ(t.Number("Ts"), 0.1);
}

TEST(SpecTest, AmbiguousCommasSayHowToWriteIt) {
  Spec s("model spec", "fopdt:K=1,2,tau=1");
  EXPECT_THAT([&] { s.Number("K"); },
              ThrowsMessage<InvalidArgument>(HasSubstr("key 'K' takes one number, got '1,2'")));
  EXPECT_THAT([] { Spec("signal", "step:to=1,at"); },
              ThrowsMessage<InvalidArgument>(HasSubstr("expected key=value, got 'at'")));
  EXPECT_THAT([] { Spec("signal", "step:1,to=1"); },
              ThrowsMessage<InvalidArgument>(HasSubstr("expected key=value, got '1'")));
}

TEST(SpecTest, ErrorsNameTheSpecAndKey) {
  EXPECT_THAT(
      [] { Spec("signal", "step:to=1,to=2"); },
      ThrowsMessage<InvalidArgument>(HasSubstr("signal 'step:to=1,to=2': key 'to' given twice")));
  EXPECT_THAT([] { Spec("signal", "step:=1"); },
              ThrowsMessage<InvalidArgument>(HasSubstr("empty key")));
  Spec s("signal", "step:to=x,speed=2");
  EXPECT_THAT([&] { s.Number("from"); },
              ThrowsMessage<InvalidArgument>(HasSubstr("missing key 'from' (step needs 'from=')")));
  EXPECT_THAT([&] { s.Number("to"); },
              ThrowsMessage<InvalidArgument>(HasSubstr("key 'to': not a finite number: 'x'")));
  EXPECT_THAT(
      [&] { s.Finish(); },
      ThrowsMessage<InvalidArgument>(HasSubstr("unknown key 'speed' for step (valid: from, to)")));
  Spec e("model spec", "tf:num=1,den=");
  EXPECT_THAT([&] { e.List("den"); },
              ThrowsMessage<InvalidArgument>(HasSubstr("key 'den' has no values")));
}

TEST(SpecTest, HeadBoundsAndNoKind) {
  Spec f("signal", "file:data.csv,col=u,max=inf", {.has_kind = true, .has_head = true});
  EXPECT_EQ(f.kind(), "file");
  EXPECT_EQ(f.head(), "data.csv");
  EXPECT_EQ(f.Text("col"), "u");
  EXPECT_EQ(f.Bound("max", 0.0), std::numeric_limits<double>::infinity());
  EXPECT_EQ(f.Bound("min", -1.0), -1.0);
  Spec l("--load-step", "at=1,size=-2", {.has_kind = false});
  EXPECT_EQ(l.kind(), "");
  EXPECT_DOUBLE_EQ(l.Number("size"), -2.0);
}

enum class Color { kRed, kGreen };
constexpr EnumName<Color> kColorNames[] = {
    {Color::kRed, "red"}, {Color::kGreen, "green"}, {Color::kGreen, "lime"}};

TEST(EnumNamesTest, ToStringFromStringAliasesAndErrors) {
  static_assert(EnumToString(kColorNames, Color::kGreen) == "green");
  EXPECT_EQ(EnumFromString(kColorNames, "lime", "color"), Color::kGreen);
  EXPECT_EQ(EnumFromString(kColorNames, "RED", "color", true), Color::kRed);
  EXPECT_THAT(
      [] { EnumFromString(kColorNames, "RED", "color"); },
      ThrowsMessage<InvalidArgument>(HasSubstr("unknown color 'RED' (valid: red, green, lime)")));
  const std::string huge(100000, 'x');
  try {
    EnumFromString(kColorNames, huge, "color");
    FAIL();
  } catch (const InvalidArgument& e) {
    EXPECT_LT(std::string(e.what()).size(), 200u);
  }
}

TEST(TerminationTest, OneVocabulary) {
  for (Termination t : {Termination::kConvergence, Termination::kNoConvergence,
                        Termination::kRankDeficient, Termination::kSuccess, Termination::kPartial,
                        Termination::kStopped, Termination::kFailure}) {
    EXPECT_EQ(TerminationFromString(ToString(t)), t);
  }
  EXPECT_EQ(ToString(Termination::kNoConvergence), "no_convergence");
  EXPECT_EQ(TerminationFromString("CONVERGENCE"), Termination::kConvergence);
  EXPECT_EQ(TerminationFromString("completed"), Termination::kSuccess);
  EXPECT_THAT([] { TerminationFromString("done"); },
              ThrowsMessage<InvalidArgument>(HasSubstr("unknown termination 'done'")));
  EXPECT_TRUE(IsSuccess(Termination::kSuccess));
  EXPECT_FALSE(IsSuccess(Termination::kPartial));
}

}  // namespace
}  // namespace pneumid
