#include "pneumid/identify/identified_model.hpp"

#include <fmt/format.h>

#include "pneumid/lti/model_io.hpp"

namespace pneumid {

nlohmann::json IdentifiedModel::ToJson() const {
  nlohmann::json j;
  j["method"] = method;
  j["structure"] = structure;
  j["params"] = params;
  if (!param_std.empty()) j["param_std"] = param_std;
  j["tf"] = pneumid::ToJson(tf);
  if (discrete) j["discrete"] = pneumid::ToJson(*discrete);
  j["fit_percent"] = fit_percent;
  j["iae"] = iae;
  if (!notes.empty()) j["notes"] = notes;
  return j;
}

bool IdentifyRequest::IsValid(std::string* error) const {
  auto fail = [&](const std::string& m) {
    if (error) *error = m;
    return false;
  };
  if (input < 0) return fail(fmt::format("input column must be >= 0, got {}", input));
  if (output < 0) return fail(fmt::format("output column must be >= 0, got {}", output));
  if (order < 1 || order > 20) return fail(fmt::format("order must be in 1..20, got {}", order));
  if (na < 0 || na > 50) return fail(fmt::format("na must be in 0..50, got {}", na));
  if (nb < 1 || nb > 50) return fail(fmt::format("nb must be in 1..50, got {}", nb));
  if (nk < 0 || nk > 1000) return fail(fmt::format("nk must be in 0..1000, got {}", nk));
  if (nc < 0 || nc > 50) return fail(fmt::format("nc must be in 0..50, got {}", nc));
  if (nd < 0 || nd > 50) return fail(fmt::format("nd must be in 0..50, got {}", nd));
  if (nf < 0 || nf > 50) return fail(fmt::format("nf must be in 0..50, got {}", nf));
  return true;
}

}  // namespace pneumid
