// The one entry point of identification: every method by name, as used by
// `pneumid identify --method`, `pneumid report`, `pneumid paper` and the
// Python function identify().
//
//   names                                   area header
//   reaction-curve tangent smith sundaresan step_methods.hpp (step-response
//   broida sopdt ptn strejc areas           methods on one analyzed step)
//   fit-p1d fit-p2d fit-p2du fit-p3d        step_methods.hpp (process models
//   fit-p1di                                fitted by Ceres, any input)
//   arx armax oe bj iv4 n4sid cra spa       parametric.hpp (black-box)
//
// Every method returns an IdentifiedModel (identified_model.hpp) scored on the
// data it was identified from (fit_percent, iae).
#pragma once

#include <string>
#include <vector>

#include "pneumid/data/dataset.hpp"
#include "pneumid/identify/identified_model.hpp"
#include "pneumid/identify/step_methods.hpp"

namespace pneumid {

/// Settings of the methods beyond IdentifyRequest (channels and orders).
struct IdentifyOptions {
  /// Step analysis, tangent and fit-* settings of the step-response methods
  /// (the parametric methods take their orders from the request only).
  StepMethodOptions step;
  bool IsValid(std::string* error) const;
};

/// Every method name, step-response methods first, in the order of the table
/// above (the order `all` expands to).
const std::vector<std::string>& IdentifyMethodNames();

/// True when `name` is one of IdentifyMethodNames().
bool IsIdentifyMethod(const std::string& name);

/// Method names from a comma-separated list such as "arx, ptn" or "all"
/// (every method). Blanks around names are ignored; a repeated name is kept
/// once, at its first position.
/// @throws InvalidArgument naming an unknown method, or for an empty list.
std::vector<std::string> ParseMethodList(const std::string& list);

/// Identifies the input column request.input -> output column request.output
/// of `data` with one method and scores the model on the data.
/// @throws InvalidArgument for an unknown method (listing the valid names),
///         an invalid request or options;
///         DataError when the data do not suit the method (no step, too short,
///         not uniformly sampled, ...).
IdentifiedModel Identify(const std::string& method, const Dataset& data,
                         const IdentifyRequest& request = {}, const IdentifyOptions& options = {});

}  // namespace pneumid
