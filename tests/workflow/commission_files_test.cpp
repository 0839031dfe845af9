// WriteCommissionFiles (workflow/commission_files.hpp): the files of a
// commissioning run on a first-order plant, the controller configuration
// read back as `pneumid control|run|codegen --config` read it, and a run
// without a controller (only its data).
#include "pneumid/workflow/commission_files.hpp"

#include <algorithm>
#include <filesystem>

#include <gtest/gtest.h>

#include "pneumid/common/check.hpp"
#include "pneumid/plant/actuator.hpp"
#include "pneumid/plant/plant_factory.hpp"
#include "pneumid/realtime/realtime_config.hpp"

namespace pneumid {
namespace {

std::string FreshDir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("pneumid_commission_files_" + name);
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

CommissionOptions FopdtOptions(const std::string& dir) {
  CommissionOptions o;
  o.directory = dir;
  o.u_min = 0.0;
  o.u_max = 10.0;
  o.budget = 160.0;  // the experiment, and a verification run of 12 levels of 8 s
  o.methods = {"arx", "oe"};
  o.settling = 2.0;
  return o;
}

TEST(CommissionFiles, TheControllerConfigurationLoadsAsTheCommandsReadIt) {
  const std::string spec = "fopdt:K=2,tau=0.5,theta=0.1";
  auto plant = MakePlant(spec, 0.01);
  const std::string dir = FreshDir("fopdt");
  const CommissionResult r = Commission(*plant, FopdtOptions(dir));
  ASSERT_EQ(r.termination, Termination::kSuccess) << r.message;
  CommissionFilesOptions fo;
  fo.directory = dir;
  fo.Ts = 0.01;
  fo.plant = spec;
  fo.plant_description = plant->Describe();
  fo.report = true;
  const CommissionFiles files = WriteCommissionFiles(r, PlantActuator(*plant), fo);
  namespace fs = std::filesystem;
  for (const char* name :
       {"data.csv", "experiment.png", "validation.png", "verification.csv", "controller.toml",
        "verification.png", "report.html", "c/pneumid_ctrl.c", "c/pneumid_ctrl.h"}) {
    const std::string path = (fs::path(dir) / name).string();
    EXPECT_TRUE(fs::is_regular_file(path)) << name;
    EXPECT_NE(std::find(files.written.begin(), files.written.end(), path), files.written.end())
        << name << " not listed";
  }
  EXPECT_EQ(files.c_module, (fs::path(dir) / "c").string());
  const RealtimeConfig config = LoadRealtimeConfig((fs::path(dir) / "controller.toml").string());
  ASSERT_TRUE(config.controller.has_value());
  EXPECT_EQ(config.controller->model, fs::absolute(r.controller_model).string());
  EXPECT_EQ(config.controller->settings.controller, "mpc");
  EXPECT_DOUBLE_EQ(config.controller->settings.aggressiveness, r.settings.aggressiveness);
  EXPECT_DOUBLE_EQ(config.controller->settings.limits.u_max, 10.0);
  EXPECT_EQ(config.io, "sim");
  EXPECT_EQ(config.plant, spec);
  EXPECT_DOUBLE_EQ(config.loop.period, 0.01);
  // Safety: the reachable range 0..20 widened by half its span.
  EXPECT_NEAR(config.safety.y_min, -10.0, 0.1);
  EXPECT_NEAR(config.safety.y_max, 30.0, 0.1);
  EXPECT_EQ(files.ToJson()["written"].size(), files.written.size());
}

TEST(CommissionFiles, ARunWithoutAControllerWritesItsDataOnly) {
  auto plant = MakePlant("fopdt:K=2,tau=0.5,theta=0.1", 0.01);
  const std::string dir = FreshDir("unreachable");
  CommissionOptions o = FopdtOptions(dir);
  o.range_min = 5.0;
  o.range_max = 400.0;  // beyond the 20 the plant reaches
  const CommissionResult r = Commission(*plant, o);
  ASSERT_EQ(r.termination, Termination::kFailure);
  CommissionFilesOptions fo;
  fo.directory = dir;
  fo.plant = "fopdt:K=2,tau=0.5,theta=0.1";
  const CommissionFiles files = WriteCommissionFiles(r, PlantActuator(*plant), fo);
  EXPECT_EQ(files.written,
            std::vector<std::string>{(std::filesystem::path(dir) / "data.csv").string()});
  EXPECT_FALSE(std::filesystem::exists(std::filesystem::path(dir) / "controller.toml"));
  EXPECT_TRUE(files.c_module.empty());
}

TEST(CommissionFiles, InvalidOptionsNameTheField) {
  CommissionResult r;
  CommissionFilesOptions fo;
  fo.Ts = 0.0;
  std::string error;
  EXPECT_FALSE(fo.IsValid(&error));
  EXPECT_NE(error.find("Ts"), std::string::npos) << error;
  EXPECT_THROW(WriteCommissionFiles(r, Actuator{}, fo), InvalidArgument);
  fo.Ts = 0.01;
  fo.plant.clear();
  EXPECT_FALSE(fo.IsValid(&error));
  EXPECT_NE(error.find("plant"), std::string::npos) << error;
}

}  // namespace
}  // namespace pneumid
