// A controller model of known steady outputs, shared by the tests of the
// unreachable set-point warning (control_scenario_test, run_workflow_test):
// the static map f (0 -> 0, 50 -> 40, 100 -> 60, piecewise linear) behind the
// FOPDT G with G(1) = 2, which reaches 0..120 with its input in 0..100.
#pragma once

#include <filesystem>
#include <fstream>
#include <string>

namespace pneumid::testing_models {

inline constexpr const char* kGainMapModel = "fopdt:K=2,tau=0.2,theta=0";

// Writes f as a {"u", "y"} map file in a folder of the temporary directory
// named `folder`; its path (ControllerSettings::input_map).
inline std::string WriteGainMapFile(const std::string& folder) {
  const auto dir = std::filesystem::temp_directory_path() / folder;
  std::filesystem::create_directories(dir);
  const std::string map = (dir / "map.json").string();
  std::ofstream(map) << R"({"u": [0, 50, 100], "y": [0, 40, 60]})";
  return map;
}

}  // namespace pneumid::testing_models
