#include "output_options.hpp"

#include <cmath>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/report/plot.hpp"

namespace pneumid::cli {

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

}  // namespace pneumid::cli
