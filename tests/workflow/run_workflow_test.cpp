// RunRealtimeWorkflow (workflow/run_workflow.hpp) on the simulator, as fast as
// possible: the keys and values `run --json` prints, the offline comparison,
// the model documents held in memory, and the checks that name the flags.
#include <cstdio>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "gain_map_model.hpp"
#include "pneumid/common/check.hpp"
#include "pneumid/models/model_file.hpp"
#include "pneumid/workflow/run_workflow.hpp"

namespace pneumid {
namespace {

// The simulator as fast as possible for `duration` s (`run --fast --duration`).
RealtimeConfig FastSim(double duration) {
  RealtimeConfig c;
  c.io = "sim";
  c.loop.duration = duration;
  c.loop.fast = true;
  return c;
}

std::set<std::string> Keys(const nlohmann::json& j) {
  std::set<std::string> keys;
  for (const auto& [key, value] : j.items()) keys.insert(key);
  return keys;
}

std::string ErrorOf(const auto& call) {
  try {
    call();
  } catch (const InvalidArgument& e) {
    return e.what();
  }
  return "";
}

// The keys of `run --json` (users' scripts read them).
const std::set<std::string> kRunKeys = {"compute_max_us",
                                        "compute_mean_us",
                                        "compute_p50_us",
                                        "compute_p99_us",
                                        "controller",
                                        "fault",
                                        "io",
                                        "jitter_max_us",
                                        "jitter_mean_us",
                                        "jitter_p50_us",
                                        "jitter_p99_us",
                                        "log",
                                        "log_dropped",
                                        "log_rows",
                                        "message",
                                        "metrics",
                                        "overruns",
                                        "period_us",
                                        "safe_state",
                                        "samples",
                                        "scheduling",
                                        "termination",
                                        "wall_time"};

TEST(RunWorkflow, ASetPointBeyondTheModelsReachIsReportedBeforeTheLoop) {
  // gain_map_model.hpp: the model reaches 0..120 with the duty in 0..100 %.
  RunWorkflowOptions o;
  o.model = testing_models::kGainMapModel;
  o.controller.input_map = testing_models::WriteGainMapFile("pneumid_run_workflow_reach");
  o.controller.input_gaps = "plant";  // resolved against the backend's plant, not by the warning
  o.setpoint = "staircase:levels=50 150,dwell=0.5";
  std::vector<std::string> warnings;
  o.warn = [&](const std::string& w) { warnings.push_back(w); };
  const RunWorkflowResult r = RunRealtimeWorkflow(o, FastSim(1.0));
  EXPECT_EQ(r.summary.termination, Termination::kSuccess);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("the set-point reaches [50, 150], beyond the steady outputs [0, 120]"),
            std::string::npos)
      << warnings[0];
  warnings.clear();
  o.setpoint = "staircase:levels=50 110,dwell=0.5";
  RunRealtimeWorkflow(o, FastSim(1.0));
  EXPECT_TRUE(warnings.empty());
}

TEST(RunWorkflow, ASimulatorRunGivesTheKeysOfRunJson) {
  const RunWorkflowResult r = RunRealtimeWorkflow(RunWorkflowOptions{}, FastSim(1.0));
  EXPECT_EQ(r.summary.termination, Termination::kSuccess);
  const nlohmann::json j = r.ToJson();
  EXPECT_EQ(Keys(j), kRunKeys);
  EXPECT_EQ(j["termination"], "success");
  EXPECT_EQ(j["samples"], 100);
  EXPECT_EQ(j["log"], "");
  EXPECT_EQ(j["log_rows"], 100);
  EXPECT_EQ(j["controller"], "dmc P=126 M=5 lambda=2.2508 N=508");
  EXPECT_EQ(j["io"], r.io);
  ASSERT_TRUE(j["metrics"].is_object());
  // The default clamp is the IPA's input range, 0..100 % duty.
  EXPECT_EQ(j["metrics"]["u_min"], 0.0);
  EXPECT_EQ(j["metrics"]["u_max"], 100.0);
  EXPECT_TRUE(r.offline.is_null());
}

TEST(RunWorkflow, OfflineAddsTheMetricsOfTheSameScenarioSimulated) {
  RunWorkflowOptions o;
  o.controller.controller = "pid";
  o.load_steps = {{0.6, -5.0}};
  o.offline = true;
  o.safety.u_min = 5.0;
  o.safety.u_max = 90.0;
  const nlohmann::json j = RunRealtimeWorkflow(o, FastSim(1.0)).ToJson();
  std::set<std::string> keys = kRunKeys;
  keys.insert("offline_metrics");
  EXPECT_EQ(Keys(j), keys);
  ASSERT_TRUE(j["metrics"].is_object());
  EXPECT_EQ(j["metrics"]["u_max"], 90.0);
  EXPECT_EQ(Keys(j["offline_metrics"]), Keys(j["metrics"]));
  // The sim backend and the offline simulation run the same plant and load step.
  EXPECT_NEAR(j["offline_metrics"]["iae"].get<double>(), j["metrics"]["iae"].get<double>(),
              1e-6 * j["metrics"]["iae"].get<double>());
  EXPECT_TRUE(j["metrics"]["load_peak_deviation"].is_number());
}

TEST(RunWorkflow, TheJsonIsWhatTheCommandLinePrints) {
  const std::filesystem::path cli = std::filesystem::path(PNEUMID_BINARY_DIR) / "pneumid";
  if (!std::filesystem::exists(cli)) GTEST_SKIP() << "no " << cli;
  const std::string command = cli.string() + " run --fast --duration 1 --json";
  std::FILE* pipe = popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  std::string text;
  char buffer[4096];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof(buffer), pipe)) > 0;)
    text.append(buffer, n);
  ASSERT_EQ(pclose(pipe), 0) << text;
  const nlohmann::json printed = nlohmann::json::parse(text);
  const nlohmann::json j = RunRealtimeWorkflow(RunWorkflowOptions{}, FastSim(1.0)).ToJson();
  EXPECT_EQ(Keys(printed), Keys(j));
  // Everything but the timing statistics of this machine.
  for (const char* key : {"controller", "io", "fault", "log", "log_rows", "message", "metrics",
                          "period_us", "safe_state", "samples", "scheduling", "termination"})
    EXPECT_EQ(printed[key], j[key]) << key;
}

TEST(RunWorkflow, AModelDocumentIsReadFromMemoryForTheRun) {
  RunWorkflowOptions o;
  o.model = "pneumid-run-workflow-model.json";
  o.model_document = nlohmann::json::parse(R"({"models": [
    {"method": "fit-p1d", "tf": {"num": [0.9], "den": [0.15, 1], "Ts": 0, "delay": 0.03}}]})");
  o.controller.controller = "pid";
  const RunWorkflowResult r = RunRealtimeWorkflow(o, FastSim(0.5));
  EXPECT_EQ(r.summary.termination, Termination::kSuccess);
  EXPECT_EQ(r.controller.rfind("pid", 0), 0u) << r.controller;
  // Held for the run only: no such file afterwards.
  EXPECT_ANY_THROW(ParseModelSpec(o.model));
}

TEST(RunWorkflow, InvalidOptionsNameTheFlag) {
  RunWorkflowOptions o;
  std::string why;
  EXPECT_TRUE(o.IsValid(&why)) << why;
  o.safety.u_min = 50.0;
  o.safety.u_max = 20.0;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("--u-min 50"), std::string::npos) << why;
  EXPECT_NE(ErrorOf([&] { RunRealtimeWorkflow(o, FastSim(0.1)); }).find("--u-min"),
            std::string::npos);
  o.safety = {};
  o.safety.rate_max = -1.0;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("--rate-max"), std::string::npos) << why;
  o.safety = {};
  o.safety.frozen_samples = -3;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("--frozen-samples"), std::string::npos) << why;
  o.safety = {};
  o.load_steps = {{-1.0, 2.0}};
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("--load-step"), std::string::npos) << why;
  o.load_steps.clear();
  o.setpoint.clear();
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("--setpoint"), std::string::npos) << why;
  o = {};
  o.plant_options.noise_sigma = -1.0;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("--noise"), std::string::npos) << why;
  // One limit given against the configuration's other one.
  o = {};
  o.safety.u_min = 150.0;
  EXPECT_TRUE(o.IsValid(&why));
  EXPECT_NE(ErrorOf([&] {
              RunRealtimeWorkflow(o, FastSim(0.1));
            }).find("invalid safety settings: output clamp"),
            std::string::npos);
}

}  // namespace
}  // namespace pneumid
