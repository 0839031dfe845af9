// Reading an identified model (identify/identified_model.hpp, with its
// parameters, operating point and covariance) from a --model spec, for the
// commands that need more than its transfer function (validate; the
// confidence bands of step, bode).
#pragma once

#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "pneumid/identify/identified_model.hpp"

namespace pneumid::cli {

/// The identified model inside a JSON file written by `pneumid identify --json`
/// or `-o` (first model, or FILE.json#method), or nothing when `spec` is not a
/// JSON file (a model spec such as arx-paper or tf:...) or the JSON holds a
/// plain transfer function.
/// @throws DataError for an unreadable file, invalid JSON or a missing method.
std::optional<IdentifiedModel> ReadIdentified(const std::string& spec);

/// Adds --confidence K (standard deviations, > 0; 0 = not given) of the
/// confidence bands drawn on `what`.
CLI::Option* AddConfidenceOption(CLI::App& app, double& k, const std::string& what);

/// The identified model of `spec` for a band of `k` standard deviations
/// (nothing when k = 0).
/// @throws InvalidArgument when k > 0 and spec is not a model of an identify
///         file, or that model has no parameter covariance (naming its method).
std::optional<IdentifiedModel> ModelForConfidence(const std::string& spec, double k);

}  // namespace pneumid::cli
