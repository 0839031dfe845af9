// RunIdentifyWorkflow and RunTuneWorkflow (workflow/identify_workflow.hpp,
// workflow/tune_workflow.hpp): the model file of a step test, the preprocessing
// record on the models, the checks that name the flags, and the tuning of a
// rule and of auto as the control area computes it.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/data/load.hpp"
#include "pneumid/models/model_file.hpp"
#include "pneumid/workflow/identify_workflow.hpp"
#include "pneumid/workflow/tune_workflow.hpp"

namespace pneumid {
namespace {

Dataset StepData() {
  return LoadDataset(std::string(PNEUMID_SOURCE_DIR) + "/tests/identify/data/fopdt.csv");
}

std::string ErrorOf(const auto& call) {
  try {
    call();
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  return "";
}

TEST(IdentifyWorkflow, RanksTheModelsAndWritesTheModelFile) {
  IdentifyWorkflowOptions o;
  o.methods = "reaction-curve,fit-p1d";
  const IdentifyWorkflowResult r = RunIdentifyWorkflow(o, StepData());
  ASSERT_EQ(r.summary.models.size(), 2u);
  const nlohmann::json j = r.ToJson();
  EXPECT_EQ(j["best"], r.summary.models.front().method);
  EXPECT_EQ(j["best"], "fit-p1d");
  EXPECT_EQ(j["ranked_by"], "fit_percent");
  EXPECT_EQ(j["models"].size(), 2u);
  EXPECT_TRUE(j["models"][0].contains("rank_reason"));
  EXPECT_EQ(j["failures"], nlohmann::json::array());
  EXPECT_EQ(j["termination"], "success");
  EXPECT_FALSE(r.summary.models.front().preprocessing.has_value());  // no preprocessing
}

TEST(IdentifyWorkflow, ThePreprocessingIsRecordedOnEveryModel) {
  IdentifyWorkflowOptions o;
  o.methods = "fit-p1d";
  o.preprocess.window = "0.2:";
  const IdentifyWorkflowResult r = RunIdentifyWorkflow(o, StepData());
  ASSERT_FALSE(r.summary.models.empty());
  EXPECT_TRUE(r.summary.models.front().preprocessing.has_value());
  EXPECT_TRUE(r.ToJson()["models"][0].contains("preprocessing"));
  EXPECT_LT(r.data.size(), StepData().size());
}

TEST(IdentifyWorkflow, NoModelIsAnEmptySummaryAndNullJson) {
  // A constant input has no step: both step methods fail.
  const Dataset step = StepData();
  Eigen::MatrixXd u = Eigen::MatrixXd::Ones(step.size(), 1);
  const Dataset flat(step.time(), u, step.outputs());
  IdentifyWorkflowOptions o;
  o.methods = "reaction-curve,tangent";
  const IdentifyWorkflowResult r = RunIdentifyWorkflow(o, flat);
  EXPECT_TRUE(r.summary.models.empty());
  EXPECT_EQ(r.summary.failures.size(), 2u);
  EXPECT_TRUE(r.ToJson().is_null());
}

TEST(IdentifyWorkflow, AutoTakesTheReactionCurveForAStepTestOnly) {
  // The default: the paper's method on a step test, no warning.
  IdentifyWorkflowOptions o;
  ASSERT_EQ(o.methods, "auto");
  const IdentifyWorkflowResult step = RunIdentifyWorkflow(o, StepData());
  ASSERT_EQ(step.summary.models.size(), 1u);
  EXPECT_EQ(step.summary.models.front().method, "reaction-curve");
  EXPECT_TRUE(step.summary.warnings.empty());
  // The cascaded-tanks benchmark's estimation record (a multisine input): the
  // methods for general inputs, and a warning that gives the reason.
  const Dataset tanks = LoadDataset(std::string(PNEUMID_SOURCE_DIR) + "/data/tanks/estimation.csv");
  const IdentifyWorkflowResult general = RunIdentifyWorkflow(o, tanks);
  EXPECT_EQ(general.summary.models.size() + general.summary.failures.size(), 5u);
  EXPECT_GE(general.summary.models.size(), 4u);
  ASSERT_FALSE(general.summary.warnings.empty());
  EXPECT_NE(general.summary.warnings.front().find("the input is not a single step"),
            std::string::npos)
      << general.summary.warnings.front();
  EXPECT_NE(general.summary.warnings.front().find("fit-p1d, arx, oe, bj, iv4"), std::string::npos);
  EXPECT_GT(general.summary.models.front().fit_percent, 70.0);
}

TEST(IdentifyWorkflow, InvalidOptionsNameTheFlag) {
  const Dataset data = StepData();
  IdentifyWorkflowOptions o;
  o.split = 1.0;
  EXPECT_NE(ErrorOf([&] { RunIdentifyWorkflow(o, data); }).find("--split"), std::string::npos);
  o.split = 0.5;
  EXPECT_NE(ErrorOf([&] { RunIdentifyWorkflow(o, data, &data); }).find("exclude each other"),
            std::string::npos);
  o = {};
  o.preprocess.remove_initial = true;
  o.preprocess.detrend = "constant";
  EXPECT_NE(ErrorOf([&] { RunIdentifyWorkflow(o, data); }).find("--remove-initial"),
            std::string::npos);
  o = {};
  o.methods = "bogus";
  EXPECT_NE(ErrorOf([&] { RunIdentifyWorkflow(o, data); }).find("unknown method 'bogus'"),
            std::string::npos);
}

TEST(TuneWorkflow, ARuleGivesTheControlAreasTuning) {
  TuneWorkflowOptions o;
  o.model = "fopdt:K=1.6,tau=0.245,theta=0.001";
  o.Ts = 0.01;
  o.M = 5;
  const TuneWorkflowResult r = RunTuneWorkflow(o);
  ASSERT_TRUE(r.tuning.has_value());
  EXPECT_FALSE(r.automatic.has_value());
  EXPECT_EQ(r.tuning->P, 126);
  TuningOptions t;
  t.M = 5;
  EXPECT_EQ(r.ToJson(), Tune(ParseModelSpec(o.model), o.Ts, t).ToJson());
  // The model given directly gives the same.
  EXPECT_EQ(RunTuneWorkflow(o, ParseModelSpec(o.model)).ToJson(), r.ToJson());
}

TEST(TuneWorkflow, AutoDesignsToTheSpecification) {
  TuneWorkflowOptions o;
  o.model = "fopdt-paper";
  o.Ts = 0.01;
  o.rule = "auto";
  o.controller = "pid";
  o.aggressiveness = 0.2;
  const TuneWorkflowResult r = RunTuneWorkflow(o);
  ASSERT_TRUE(r.automatic.has_value());
  EXPECT_FALSE(r.tuning.has_value());
  const nlohmann::ordered_json j = r.ToJson();
  EXPECT_EQ(j["rule"], "auto");
  EXPECT_EQ(j["controller"], "pid");
}

TEST(TuneWorkflow, InvalidOptionsNameTheFlag) {
  TuneWorkflowOptions o;
  o.model = "fopdt-paper";
  EXPECT_NE(ErrorOf([&] { RunTuneWorkflow(o); }).find("--Ts must be positive"), std::string::npos);
  o.Ts = 0.01;
  o.overshoot = 3.0;
  EXPECT_NE(ErrorOf([&] { RunTuneWorkflow(o); }).find("apply to --rule auto only"),
            std::string::npos);
  o.rule = "auto";
  o.P = 20;
  EXPECT_NE(ErrorOf([&] { RunTuneWorkflow(o); }).find("drop --P/--lambda"), std::string::npos);
}

}  // namespace
}  // namespace pneumid
