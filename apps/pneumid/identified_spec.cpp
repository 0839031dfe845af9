#include "identified_spec.hpp"

#include <fstream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "pneumid/common/check.hpp"
#include "pneumid/identify/identified_model_io.hpp"
#include "pneumid/identify/model_uncertainty.hpp"
#include "validators.hpp"

namespace pneumid::cli {

std::optional<IdentifiedModel> ReadIdentified(const std::string& spec) {
  std::string path = spec, method;
  const auto hash = spec.rfind('#');
  if (hash != std::string::npos) {
    path = spec.substr(0, hash);
    method = spec.substr(hash + 1);
  }
  if (path.size() < 5 || path.substr(path.size() - 5) != ".json") return std::nullopt;
  std::ifstream f(path);
  if (!f) throw DataError(fmt::format("{}: cannot open model file", path));
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(f);
  } catch (const nlohmann::json::parse_error& e) {
    throw DataError(fmt::format("{}: not valid JSON: {}", path, e.what()));
  }
  nlohmann::json m = j;
  if (j.is_object() && j.contains("models")) {
    PNEUMID_CHECK(j["models"].is_array() && !j["models"].empty(), "{}: 'models' is empty", path);
    m = j["models"][0];
    if (!method.empty()) {
      bool found = false;
      for (const auto& x : j["models"])
        if (x.is_object() && x.value("method", "") == method) {
          m = x;
          found = true;
          break;
        }
      PNEUMID_CHECK(found, "{}: no model with method '{}'", path, method);
    }
  }
  if (!m.is_object() || !m.contains("params") || !m.contains("tf")) return std::nullopt;
  try {
    return IdentifiedModelFromJson(m);
  } catch (const InvalidArgument& e) {
    throw DataError(fmt::format("{}: {}", path, e.what()));
  }
}

CLI::Option* AddConfidenceOption(CLI::App& app, double& k, const std::string& what) {
  return app
      .add_option("--confidence", k,
                  fmt::format("Draw a band of +-K standard deviations around {} (first-order "
                              "propagation of the parameter covariance of a model from "
                              "`pneumid identify -o FILE.json`, as MATLAB's showConfidence)",
                              what))
      ->type_name("K")
      ->check(Positive());
}

std::optional<IdentifiedModel> ModelForConfidence(const std::string& spec, double k) {
  if (k == 0.0) return std::nullopt;
  std::optional<IdentifiedModel> m = spec.empty() ? std::nullopt : ReadIdentified(spec);
  PNEUMID_CHECK(m.has_value(),
                "--confidence needs a model of a file written by `pneumid identify -o "
                "FILE.json` (--model FILE.json#method), got {}",
                spec.empty() ? std::string("--num/--den") : "'" + spec + "'");
  PNEUMID_CHECK(HasCovariance(*m),
                "--confidence: the '{}' model of '{}' has no parameter covariance (only "
                "arx, armax, oe, bj, iv4 and fit-* models have one)",
                m->method, spec);
  return m;
}

}  // namespace pneumid::cli
