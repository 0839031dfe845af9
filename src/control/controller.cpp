#include "pneumid/control/controller.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "pneumid/common/check.hpp"
#include "pneumid/common/enum_names.hpp"

namespace pneumid {

namespace {
constexpr EnumName<ControllerType> kControllerTypeNames[] = {
    {ControllerType::kDmc, "dmc"},
    {ControllerType::kGpc, "gpc"},
    {ControllerType::kPid, "pid"},
    {ControllerType::kMpc, "mpc"},
};
}  // namespace

std::string ToString(ControllerType v) {
  return std::string(EnumToString(kControllerTypeNames, v));
}

ControllerType ControllerTypeFromString(const std::string& name) {
  return EnumFromString(kControllerTypeNames, name, "controller");
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
