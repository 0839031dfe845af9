// Tuning rules: the paper's P = 126 and lambda = 2.25 (M = 5) from the
// Shridhar-Cooper rule (docs/paper.md, reference value 6; lambda_max(A'A)/500 =
// 2.250797 from gen_dmc_reference.py), the modified settings, and errors.
#include "pneumid/control/tuning.hpp"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "pneumid/common/check.hpp"
#include "pneumid/models/model_file.hpp"

namespace pneumid {
namespace {

constexpr double kTs = 0.01;

TEST(TuningTest, ShridharCooperReproducesPaperConventionalSettings) {
  TuningOptions o;
  o.rule = TuningRule::kShridharCooper;
  o.M = 5;
  const TuningResult r = Tune(TransferFunction::Fopdt(1.6, 0.245, 0.001), kTs, o);
  EXPECT_EQ(r.fopdt.method, "exact");
  EXPECT_NEAR(r.fopdt.tau, 0.245, 1e-12);
  EXPECT_NEAR(r.tau_used, 0.25, 1e-12);
  EXPECT_NEAR(r.P_unrounded, 126.1, 1e-9);  // 5 * 25 + 0.1 + 1
  EXPECT_EQ(r.P, 126);
  EXPECT_EQ(r.M, 5);
  EXPECT_NEAR(r.lambda_condition, 2.250797, 1e-5);  // gen_dmc_reference.py
  EXPECT_NEAR(r.lambda_formula, 2.24, 1e-9);        // (5/500) 1.6^2 (87.5 + 2 - 2)
  EXPECT_NEAR(r.lambda, r.lambda_condition, 0.0);
  EXPECT_NEAR(std::round(r.lambda * 100) / 100, 2.25, 1e-12);  // the paper's value
  EXPECT_THAT(r.formula, ::testing::HasSubstr("lambda_max(A'A)/500"));
}

TEST(TuningTest, WithoutRoundingTheHorizonIs124) {
  TuningOptions o;
  o.tau_significant_digits = 0;
  const TuningResult r = Tune(PaperFopdtModel(), kTs, o);
  EXPECT_NEAR(r.P_unrounded, 123.6, 1e-9);
  EXPECT_EQ(r.P, 124);
  EXPECT_NEAR(r.lambda_formula, 5.0 / 500 * 2.56 * (85.75 + 2 - 2), 1e-9);
}

TEST(TuningTest, ShridharCooperForM10IsNotThePapersModifiedLambda) {
  TuningOptions o;
  o.M = 10;
  const TuningResult r = Tune(PaperFopdtModel(), kTs, o);
  EXPECT_NEAR(r.lambda_condition, 4.370324, 1e-5);  // gen_dmc_reference.py
  EXPECT_GT(std::abs(r.lambda - 1.92), 2.0);
}

TEST(TuningTest, PaperModifiedAndExplicit) {
  TuningOptions o;
  o.rule = TuningRuleFromString("paper-modified");
  TuningResult r = Tune(PaperFopdtModel(), kTs, o);
  EXPECT_EQ(r.P, 126);
  EXPECT_EQ(r.M, 10);
  EXPECT_EQ(r.lambda, 1.92);
  EXPECT_THAT(r.formula, ::testing::HasSubstr("not published"));
  TuningOptions e;
  e.rule = TuningRule::kExplicit;
  e.P = 50;
  e.M = 3;
  e.lambda = 0.7;
  r = Tune(PaperArxModel(), kTs, e);
  EXPECT_EQ(r.P, 50);
  EXPECT_EQ(r.M, 3);
  EXPECT_EQ(r.lambda, 0.7);
}

TEST(TuningTest, FopdtFromHigherOrderModelByTwoPointMethod) {
  // A pure first-order lag sampled finely: the two-point method returns it.
  const FopdtEstimate exact = FopdtFromModel(TransferFunction::Fopdt(2.0, 0.5, 0.1));
  EXPECT_EQ(exact.method, "exact");
  EXPECT_NEAR(exact.theta, 0.1, 1e-12);
  // ARX model: the paper's FOPDT has K ~ 1.6 and tau ~ 0.23-0.25 s.
  const FopdtEstimate arx = FopdtFromModel(PaperArxModel());
  EXPECT_EQ(arx.method, "two-point");
  EXPECT_NEAR(arx.K, 1.59796, 1e-4);
  EXPECT_NEAR(arx.tau + arx.theta, 0.2306, 0.01);  // t63 of the ARX step (docs/paper.md, reference 4)
  const TuningResult r = Tune(PaperArxModel(), kTs, TuningOptions{});
  EXPECT_GT(r.P, 110);
  EXPECT_LT(r.P, 130);
}

TEST(TuningTest, Names) {
  for (TuningRule rule :
       {TuningRule::kShridharCooper, TuningRule::kPaperModified, TuningRule::kExplicit}) {
    EXPECT_EQ(TuningRuleFromString(ToString(rule)), rule);
  }
  EXPECT_EQ(TuningRuleFromString("conventional"), TuningRule::kShridharCooper);
  EXPECT_THAT([] { TuningRuleFromString("ziegler"); },
              ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr("shridhar-cooper")));
  EXPECT_NEAR(RoundSignificant(0.245, 2), 0.25, 1e-15);
  EXPECT_NEAR(RoundSignificant(123.4, 2), 120.0, 1e-12);
  EXPECT_NEAR(RoundSignificant(-0.0345, 2), -0.035, 1e-15);
}

TEST(TuningTest, RejectsBadInput) {
  TuningOptions e;
  e.rule = TuningRule::kExplicit;
  EXPECT_THAT([&] { Tune(PaperFopdtModel(), kTs, e); },
              ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr("needs P, M")));
  EXPECT_THROW(Tune(PaperFopdtModel(), 0.0, TuningOptions{}), InvalidArgument);
  const TransferFunction unstable = TransferFunction::Continuous({1.0}, {1.0, -2.0});
  EXPECT_THROW(Tune(unstable, kTs, TuningOptions{}), InvalidArgument);
}

// A sample time far below the plant's time scale gives a horizon of 1.25e9
// samples (beyond an int, and gigabytes of dynamic matrix): an error naming
// P and the shortest sample time that works, (5 tau + theta)/(Pmax - 1),
// not an overflow or an allocation failure. Explicit horizons are bounded too.
TEST(TuningTest, AHorizonBeyondTheLargestTakenIsAnError) {
  EXPECT_THAT([] { Tune(PaperFopdtModel(), 1e-9, TuningOptions{}); },
              ::testing::ThrowsMessage<InvalidArgument>(::testing::AllOf(
                  ::testing::HasSubstr("P = 5 tau/Ts + theta/Ts + 1 = 1.251e+09"),
                  ::testing::HasSubstr("at least 1.25e-05 s"))));
  // Just above the bound's sample time the rule works: P <= kMaxPredictionHorizon.
  const TuningResult r = Tune(PaperFopdtModel(), 1.26e-5, TuningOptions{});
  EXPECT_LE(r.P, kMaxPredictionHorizon);
  EXPECT_GT(r.P, kMaxPredictionHorizon - 1000);
  TuningOptions e;
  e.rule = TuningRule::kExplicit;
  e.P = 100000;
  e.M = 50000;
  e.lambda = 1.0;
  EXPECT_THAT([&] { Tune(PaperFopdtModel(), kTs, e); },
              ::testing::ThrowsMessage<InvalidArgument>(::testing::HasSubstr("M = 1000")));
}

// The keys of `pneumid tune --json` (a contract), in order; NaN as null.
TEST(TuningTest, ToJsonKeepsTheCommandLineKeys) {
  TuningOptions o;
  o.M = 5;
  const nlohmann::ordered_json j = Tune(PaperFopdtModel(), kTs, o).ToJson();
  std::vector<std::string> keys;
  for (const auto& [key, value] : j.items()) keys.push_back(key);
  EXPECT_THAT(keys, ::testing::ElementsAre("rule", "P", "M", "lambda", "lambda_source",
                                           "lambda_condition", "lambda_formula", "P_unrounded",
                                           "tau_used", "fopdt", "Ts", "formula"));
  EXPECT_EQ(j["rule"], "shridhar-cooper");
  EXPECT_EQ(j["P"], 126);
  EXPECT_NEAR(j["lambda"].get<double>(), 2.250797, 1e-5);
  EXPECT_EQ(j["lambda_source"], "lambda_condition");
  EXPECT_EQ(j["fopdt"]["method"], "exact");
  EXPECT_EQ(j["Ts"], kTs);
  o.lambda = 3.0;
  EXPECT_EQ(Tune(PaperFopdtModel(), kTs, o).ToJson()["lambda_source"], "explicit");

  TuningOptions m;
  m.rule = TuningRule::kPaperModified;
  const nlohmann::ordered_json jm = Tune(PaperFopdtModel(), kTs, m).ToJson();
  keys.clear();
  for (const auto& [key, value] : jm.items()) keys.push_back(key);
  EXPECT_THAT(keys, ::testing::ElementsAre("rule", "P", "M", "lambda", "Ts", "formula"));
}

}  // namespace
}  // namespace pneumid
