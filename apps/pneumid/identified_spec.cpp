#include "identified_spec.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "pneumid/common/check.hpp"
#include "pneumid/identify/identified_model_io.hpp"
#include "pneumid/identify/evaluation/model_uncertainty.hpp"
#include "validators.hpp"

namespace pneumid::cli {

std::optional<IdentifiedModel> ReadIdentified(const std::string& spec) {
  return LoadIdentifiedModel(spec);
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
