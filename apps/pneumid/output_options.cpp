#include "output_options.hpp"

#include <cmath>
#include <fstream>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/report/plot.hpp"

namespace pneumid::cli {
namespace {

template <typename Json>
void WriteJson(const Json& j, const std::string& path) {
  std::ofstream f(path);
  if (!f) throw DataError(fmt::format("{}: cannot open for writing", path));
  f << j.dump(2) << "\n";
  if (!f) throw DataError(fmt::format("{}: write failed", path));
}

}  // namespace

CLI::Option* AddPlotOption(CLI::App& app, std::string& path, const std::string& what) {
  return app
      .add_option("--plot", path, "Write a figure of " + what + " (.png or .svg by extension)")
      ->check(CLI::Validator(
          [](std::string& file) -> std::string {
            try {
              ImageFormatFromPath(file);
              return "";
            } catch (const std::exception& e) {
              return e.what();
            }
          },
          "FILE.png|svg"));
}

nlohmann::json JsonNumber(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

nlohmann::json JsonNumbers(const Eigen::VectorXd& v) {
  nlohmann::json a = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) a.push_back(JsonNumber(v[i]));
  return a;
}

void WriteJsonFile(const nlohmann::json& j, const std::string& path) { WriteJson(j, path); }
void WriteJsonFile(const nlohmann::ordered_json& j, const std::string& path) { WriteJson(j, path); }

}  // namespace pneumid::cli
