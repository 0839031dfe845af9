#include "pneumid/identify/identify.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/common/strings.hpp"
#include "pneumid/identify/parametric.hpp"

namespace pneumid {

bool IdentifyOptions::IsValid(std::string* error) const { return step.IsValid(error); }

const std::vector<std::string>& IdentifyMethodNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> all = StepMethodNames();
    for (const std::string& m : ParametricMethodNames()) all.push_back(m);
    return all;
  }();
  return names;
}

bool IsIdentifyMethod(const std::string& name) {
  const auto& names = IdentifyMethodNames();
  return std::find(names.begin(), names.end(), name) != names.end();
}

std::vector<std::string> ParseMethodList(const std::string& list) {
  std::vector<std::string> out;
  auto add = [&out](const std::string& m) {
    if (std::find(out.begin(), out.end(), m) == out.end()) out.push_back(m);
  };
  for (const std::string& item : Split(list, ',')) {
    if (item.empty()) continue;
    if (item == "all") {
      for (const std::string& m : IdentifyMethodNames()) add(m);
      continue;
    }
    PNEUMID_CHECK(IsIdentifyMethod(item), "unknown method '{}' (valid: {}, or all)", item,
                  fmt::join(IdentifyMethodNames(), ", "));
    add(item);
  }
  PNEUMID_CHECK(!out.empty(), "the method list needs at least one method name, got '{}'", list);
  return out;
}

IdentifiedModel Identify(const std::string& method, const Dataset& data,
                         const IdentifyRequest& request, const IdentifyOptions& options) {
  data.RequireNumericScale();
  if (IsStepMethod(method)) return IdentifyStepMethod(method, data, request, options.step);
  if (IsParametricMethod(method)) return IdentifyParametric(method, data, request);
  PNEUMID_CHECK(false, "unknown method '{}' (valid: {})", method,
                fmt::join(IdentifyMethodNames(), ", "));
  return {};
}

}  // namespace pneumid
