#include "pneumid/control/controller.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"

namespace pneumid {

std::string ToString(ControllerType type) {
  switch (type) {
    case ControllerType::kDmc:
      return "dmc";
    case ControllerType::kGpc:
      return "gpc";
    case ControllerType::kPid:
      return "pid";
  }
  return "unknown";
}

ControllerType ControllerTypeFromString(const std::string& name) {
  for (ControllerType t : {ControllerType::kDmc, ControllerType::kGpc, ControllerType::kPid}) {
    if (ToString(t) == name) return t;
  }
  PNEUMID_CHECK(false, "unknown controller '{}'; valid: dmc, gpc, pid", name);
  return ControllerType::kDmc;
}

bool InputLimits::IsValid(std::string* error) const {
  if (std::isnan(u_min) || std::isnan(u_max) || std::isnan(du_max)) {
    if (error) *error = "input limits must not be NaN";
    return false;
  }
  if (u_min > u_max) {
    if (error)
      *error = fmt::format("need u_min <= u_max, got u_min = {}, u_max = {}", u_min, u_max);
    return false;
  }
  if (!(du_max > 0.0)) {
    if (error) *error = fmt::format("du_max must be positive, got {}", du_max);
    return false;
  }
  return true;
}

double InputLimits::Clip(double u, double u_prev) const {
  if (std::isfinite(du_max)) u = std::clamp(u, u_prev - du_max, u_prev + du_max);
  return std::clamp(u, u_min, u_max);
}

}  // namespace pneumid
