// Preparation shared by the graphical methods: step, baseline, final value,
// noise, and the refusals of bad data (no step, step too small, not settled,
// NaN, several steps).
#include "pneumid/identify/step/step_analysis.hpp"

#include <cmath>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "step_test_util.hpp"

namespace pneumid {
namespace {

using ::testing::HasSubstr;
using ::testing::ThrowsMessage;

const TransferFunction kPlant = TransferFunction::Fopdt(2.0, 0.5, 0.1);

TEST(StepAnalysisTest, BaselineFinalValueNoise) {
  const Dataset d = testing::MakeStepData(kPlant, 0.01, 100, 600, 5.0, 15.0, 0.2, 3, 40.0);
  const StepAnalysis s = AnalyzeStep(d);
  EXPECT_EQ(s.step_index, 100);
  EXPECT_NEAR(s.step_time, 1.0, 1e-12);
  EXPECT_DOUBLE_EQ(s.u0, 5.0);
  EXPECT_DOUBLE_EQ(s.u1, 15.0);
  // 100 baseline samples of std 0.2: mean within 4 standard errors.
  EXPECT_NEAR(s.y0, 40.0, 4 * 0.2 / 10);
  EXPECT_NEAR(s.y_final, 60.0, 4 * s.y_final_std + 1e-3);
  EXPECT_GT(s.y_final_std, 0.0);
  EXPECT_NEAR(s.noise_std, 0.2, 0.05);
  EXPECT_NEAR(s.gain, 2.0, 0.02);
  EXPECT_NEAR(s.departure_time, 0.1, 0.03);
  EXPECT_THAT(s.BriefReport(), HasSubstr("step at t = 1 s"));
}

TEST(StepAnalysisTest, NoStep) {
  Dataset d = Dataset::FromUniform(0.01, Eigen::VectorXd::Constant(300, 2.0),
                                   Eigen::VectorXd::LinSpaced(300, 0.0, 1.0));
  d.set_source("flat.csv");
  EXPECT_THAT([&] { AnalyzeStep(d); },
              ThrowsMessage<DataError>(AllOf(HasSubstr("flat.csv"), HasSubstr("no step"))));
}

TEST(StepAnalysisTest, StepTooSmallAgainstNoise) {
  const Dataset d = testing::MakeStepData(kPlant, 0.01, 100, 600, 5.0, 5.1, 0.2, 3);
  EXPECT_THAT([&] { AnalyzeStep(d); }, ThrowsMessage<DataError>(HasSubstr("too small")));
}

TEST(StepAnalysisTest, NotSettled) {
  // tau = 5 s recorded for 3 s after the step.
  const Dataset d =
      testing::MakeStepData(TransferFunction::Fopdt(1.0, 5.0, 0.0), 0.01, 50, 350, 0.0, 1.0, 0.001);
  EXPECT_THAT([&] { AnalyzeStep(d); }, ThrowsMessage<DataError>(HasSubstr("not settled")));
}

TEST(StepAnalysisTest, SeveralSteps) {
  Eigen::VectorXd u = Eigen::VectorXd::Zero(400), y = Eigen::VectorXd::Zero(400);
  u.segment(100, 100).setConstant(1.0);
  u.tail(200).setConstant(2.0);
  y = u;
  EXPECT_THAT([&] { AnalyzeStep(Dataset::FromUniform(0.01, u, y)); },
              ThrowsMessage<DataError>(HasSubstr("not a single step")));
}

TEST(StepAnalysisTest, NanSample) {
  // A Dataset refuses non-finite values already; the analysis never sees one.
  Eigen::VectorXd u = Eigen::VectorXd::Zero(300), y = Eigen::VectorXd::Zero(300);
  u.tail(200).setConstant(1.0);
  y[150] = std::nan("");
  EXPECT_ANY_THROW(AnalyzeStep(Dataset::FromUniform(0.01, u, y)));
}

TEST(StepAnalysisTest, InvalidOptions) {
  StepAnalysisOptions o;
  o.tail_fraction = 0.7;
  std::string why;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_THAT(why, HasSubstr("tail_fraction"));
  const Dataset d = testing::MakeStepData(kPlant, 0.01, 100, 600, 5.0, 15.0);
  EXPECT_THROW(AnalyzeStep(d, 0, 0, o), InvalidArgument);
  EXPECT_THROW(AnalyzeStep(d, 1, 0), InvalidArgument);
}

}  // namespace
}  // namespace pneumid
